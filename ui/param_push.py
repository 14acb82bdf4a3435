"""Parameter edits as undo commands: one `SetParam` per edit, quick repeats merged."""

from __future__ import annotations

import time
from typing import Any

from engine.graph import GraphError, SetParam

MERGE_SECONDS = 1.0


class MergingParamPush:
    """Pushes SetParam on an undo stack; quick repeats of the same parameter
    (a spin box being scrolled) merge into one undo item."""

    def __init__(self, undo):
        self.undo = undo
        self._last: tuple[tuple[str, str], float] | None = None

    def reset(self) -> None:
        self._last = None

    def push(self, node_id: str, name: str, value: Any) -> None:
        """Push the edit; a refused value raises GraphError and ends the merge run."""
        key, now = (node_id, name), time.monotonic()
        merge = (self._last is not None and self._last[0] == key and now - self._last[1] < MERGE_SECONDS
                 and self.undo.undo_text() == f"set {node_id}.{name}")
        try:
            self.undo.push(SetParam(node_id, name, value), merge=merge)
        except GraphError:
            self._last = None
            raise
        self._last = (key, now)
