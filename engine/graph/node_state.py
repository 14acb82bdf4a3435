"""Stored results of stateful nodes: the envelope kept in a project file.

A stateful node's result can depend on its history (a Grow node repainted
three times holds a tiling that no single growth with the final parameters
gives), so the project file keeps it::

    "node_state": {"grow1": {"key": "<sha256 hex of the node's cache key>",
                             "params": {...}, "seed": 1234,
                             "value": {...}}}

``key`` is the evaluator's cache key when the result was made (same graph
upstream and same parameters give the same key in any process); ``params``
and ``seed`` are what the node was evaluated with; ``value`` is the JSON
encoding of its outputs (``NodeType.encode_state``: by default the codecs
of its output ports' types, `engine.graph.codec`).  Only
the envelope is checked here; the value is checked when the node decodes it
against its inputs.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

__all__ = ["StoredState", "parse_state_entry"]

_HEX64 = re.compile(r"^[0-9a-f]{64}$")


@dataclass(frozen=True)
class StoredState:
    """One node's stored result.

    key : str, 64 hex digits (sha256 of the canonical cache-key source).
    params : dict, the node's full parameters when it was evaluated.
    seed : int >= 0, the node seed it was evaluated with.
    value : dict, the node type's JSON encoding of its outputs.
    """

    key: str
    params: dict
    seed: int
    value: dict

    def to_dict(self) -> dict[str, Any]:
        return {"key": self.key, "params": self.params, "seed": self.seed, "value": self.value}


def parse_state_entry(entry: Any) -> StoredState:
    """Check one ``node_state`` entry; ValueError says which field is wrong."""
    if not isinstance(entry, dict):
        raise ValueError(f"expected an object with key, params, seed and value; got {type(entry).__name__}")
    key, params, seed, value = (entry.get(k) for k in ("key", "params", "seed", "value"))
    if not isinstance(key, str) or not _HEX64.match(key):
        raise ValueError(f"'key' must be 64 hex digits; got {key!r:.80}")
    if not isinstance(params, dict):
        raise ValueError(f"'params' must be an object; got {type(params).__name__}")
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ValueError(f"'seed' must be a non-negative integer; got {seed!r:.40}")
    if not isinstance(value, dict):
        raise ValueError(f"'value' must be an object; got {type(value).__name__}")
    return StoredState(key, params, seed, value)
