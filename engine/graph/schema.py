"""Port and parameter schemas of node types.

A node type declares its ports (typed, possibly multi-input) and a parameter
schema (kind, range, default, unit).  Parameter values are validated here, at
the boundary, with messages that name the parameter, the value and what was
expected; the evaluator and the undo commands both go through `Param.coerce`.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from typing import Any, Callable

from .errors import ParamError

# Port types are registered by the node layer (engine/nodes/port_types.py), so
# the graph core names no family's values.
_PORT_TYPES: set[str] = set()


def register_port_types(*names: str) -> None:
    """Declare value types ports may carry (idempotent)."""
    _PORT_TYPES.update(names)


def port_types() -> frozenset[str]:
    """Every registered port type (the node layer's, loaded on first use)."""
    _ensure_builtin_port_types()
    return frozenset(_PORT_TYPES)


def _ensure_builtin_port_types() -> None:
    # loaded lazily, like the node types: engine.graph imports no node module at import time
    import engine.nodes.port_types  # noqa: F401


PARAM_KINDS = ("float", "int", "bool", "enum", "vec3", "str", "samples", "int_list", "json")

# Longest text of a refused "json" value quoted in an error message.
_JSON_SHOWN = 120


def ports_compatible(source_type: str, target_type: str) -> bool:
    """Whether an output of `source_type` may feed an input of `target_type`."""
    return source_type == target_type


@dataclass(frozen=True)
class Port:
    """A typed input or output of a node type.

    ``multi`` inputs accept several connections; their order is the order of
    connection and is meaningful (e.g. the vertex order of an edge chain).
    """

    name: str
    type: str
    required: bool = True
    multi: bool = False
    doc: str = ""

    def __post_init__(self):
        if self.type not in _PORT_TYPES:
            _ensure_builtin_port_types()
        if self.type not in _PORT_TYPES:
            raise ValueError(f"port {self.name!r}: unknown port type {self.type!r}")


def _shown(value: Any) -> Any:
    """A refused value as quoted in a message: long data is cut short."""
    text = repr(value)
    return value if len(text) <= _JSON_SHOWN else f"{text[:_JSON_SHOWN]}... ({len(text)} characters)"


def _finite(name: str, value: Any) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ParamError(name, value, "a number") from None
    if not math.isfinite(x):
        raise ParamError(name, value, "a finite number")
    return x


@dataclass(frozen=True)
class Param:
    """One parameter of a node type.

    kind : one of PARAM_KINDS.
        ``samples`` is a list of ``[t, value]`` pairs with t in [0, 1] (sparse
        thickness profile); ``int_list`` a list of integers; ``vec3`` three floats;
        ``json`` any JSON data (objects, lists, strings, finite numbers, true /
        false, null), e.g. a list of brush strokes.
    minimum, maximum : inclusive range for float / int / vec3 components and
        for the values of ``samples``.
    check : for ``json``: callable(data) -> canonical data, raising ValueError
        (whose message says what was expected) when the data is refused.
    active : callable(params) -> bool, whether the parameter takes effect given the
        node's other parameters (e.g. a ramp's end only when the ramp is on); None:
        always.  What chooses parameters to vary (fits, explorations) skips the
        inactive ones.
    """

    name: str
    kind: str
    default: Any
    minimum: float | None = None
    maximum: float | None = None
    unit: str = ""
    choices: tuple = ()
    doc: str = ""
    label: str = field(default="")
    check: Callable[[Any], Any] | None = field(default=None, compare=False, repr=False)
    active: Callable[[dict], bool] | None = field(default=None, compare=False, repr=False)

    def is_active(self, params: dict) -> bool:
        """Whether this parameter takes effect under `params` (see `active`)."""
        return self.active is None or bool(self.active(params))

    def __post_init__(self):
        if self.kind not in PARAM_KINDS:
            raise ValueError(f"parameter {self.name!r}: unknown kind {self.kind!r}")
        if self.check is not None and self.kind != "json":
            raise ValueError(f"parameter {self.name!r}: only 'json' parameters take a check")

    # -- validation -----------------------------------------------------
    def _check_range(self, value: float, shown: Any = None) -> None:
        lo, hi = self.minimum, self.maximum
        if (lo is not None and value < lo) or (hi is not None and value > hi):
            rng = f"[{'-inf' if lo is None else lo}, {'inf' if hi is None else hi}]"
            raise ParamError(self.name, value if shown is None else shown, f"a value in {rng}")

    def coerce(self, value: Any) -> Any:
        """Return the canonical JSON-able form of `value` or raise ParamError."""
        k = self.kind
        if k == "float":
            x = _finite(self.name, value)
            self._check_range(x)
            return x
        if k == "int":
            if isinstance(value, bool) or not isinstance(value, (int, float)) or (
                    isinstance(value, float) and not (math.isfinite(value) and value.is_integer())):
                raise ParamError(self.name, value, "an integer")
            x = int(value)
            self._check_range(x)
            return x
        if k == "bool":
            if not isinstance(value, bool):
                raise ParamError(self.name, value, "true or false")
            return value
        if k == "enum":
            if value not in self.choices:
                raise ParamError(self.name, value, f"one of {list(self.choices)}")
            return value
        if k == "str":
            if not isinstance(value, str):
                raise ParamError(self.name, value, "a string")
            return value
        if k == "vec3":
            if not isinstance(value, (list, tuple)) or len(value) != 3:
                raise ParamError(self.name, value, "a list of three numbers")
            out = [_finite(self.name, v) for v in value]
            for v in out:
                self._check_range(v, value)
            return out
        if k == "int_list":
            if not isinstance(value, (list, tuple)):
                raise ParamError(self.name, value, "a list of integers")
            out = []
            for v in value:
                if isinstance(v, bool) or not isinstance(v, (int, float)) or (
                        isinstance(v, float) and not (math.isfinite(v) and v.is_integer())):
                    raise ParamError(self.name, value, "a list of integers")
                out.append(int(v))
                self._check_range(int(v), value)
            return out
        if k == "samples":
            if not isinstance(value, (list, tuple)) or len(value) == 0:
                raise ParamError(self.name, value, "a non-empty list of [t, value] pairs")
            out = []
            for pair in value:
                if not isinstance(pair, (list, tuple)) or len(pair) != 2:
                    raise ParamError(self.name, value, "a list of [t, value] pairs")
                t = _finite(self.name, pair[0])
                v = _finite(self.name, pair[1])
                if not 0.0 <= t <= 1.0:
                    raise ParamError(self.name, value, "sample positions t in [0, 1]")
                self._check_range(v, value)
                out.append([t, v])
            out.sort(key=lambda p: p[0])
            return out
        if k == "json":
            return self._coerce_json(value)
        raise AssertionError(k)

    def _coerce_json(self, value: Any) -> Any:
        try:
            # a round trip gives plain lists / dicts (no tuples, no shared objects)
            text = json.dumps(value, allow_nan=False, sort_keys=True)
        except (TypeError, ValueError):
            raise ParamError(self.name, _shown(value), "JSON data (objects, lists, strings, "
                             "finite numbers, true, false, null)") from None
        data = json.loads(text)
        if self.check is None:
            return data
        try:
            return self.check(data)
        except ValueError as exc:
            raise ParamError(self.name, _shown(value), str(exc)) from None

    def allowed(self) -> str:
        """What `coerce` accepts, in words for messages: ``"[0.01, 0.99]"``,
        ``"integers in [2, 4096]"``, ``"one of x, y, z"``..."""
        def bound(v, none):
            if v is None:
                return none
            return str(int(v)) if self.kind in ("int", "int_list") and float(v).is_integer() else f"{v:g}"
        lo, hi = bound(self.minimum, "-inf"), bound(self.maximum, "inf")
        rng = f"[{lo}, {hi}]"
        return {"float": f"a finite number in {rng}", "int": f"an integer in {rng}",
                "bool": "true or false", "enum": "one of " + ", ".join(map(str, self.choices)),
                "str": "text", "vec3": f"three numbers in {rng}", "int_list": f"integers in {rng}",
                "samples": f"[t, value] pairs, t in [0, 1], value in {rng}",
                "json": "JSON data"}[self.kind]

    def to_dict(self) -> dict:
        """Describe the parameter for UIs and documentation."""
        return {
            "name": self.name,
            "label": self.label or self.name.replace("_", " "),
            "kind": self.kind,
            "default": self.default,
            "min": self.minimum,
            "max": self.maximum,
            "unit": self.unit,
            "choices": list(self.choices),
            "doc": self.doc,
        }
