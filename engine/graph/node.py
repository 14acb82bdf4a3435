"""Node types, their registry and the evaluation context handed to them."""

from __future__ import annotations

import threading
import time
import zlib
from dataclasses import dataclass
from typing import Any, Callable, ClassVar

import numpy as np

from engine.progress import Cancelled  # one cancellation exception for kernels and nodes

from .codec import decode_outputs, encode_outputs, has_codecs
from .errors import ParamError
from .schema import Param, Port


class CancelToken:
    """Thread-safe cancellation flag shared by the UI and a running evaluation."""

    def __init__(self):
        self._event = threading.Event()

    def cancel(self) -> None:
        self._event.set()

    @property
    def cancelled(self) -> bool:
        return self._event.is_set()


class EvalContext:
    """What a node's evaluate receives besides inputs and parameters.

    rng : numpy.random.Generator seeded from the document seed and node id.
    progress(done, total) -> bool : reports progress; False means stop.
    check() : raises Cancelled if the user cancelled.
    """

    def __init__(
        self,
        node_id: str,
        seed: int,
        *,
        cancel: CancelToken | None = None,
        report: Callable[[str, float], None] | None = None,
    ):
        self.node_id = node_id
        self.seed = node_seed(seed, node_id)
        self.rng = np.random.default_rng(self.seed)
        self._cancel = cancel
        self._report = report
        self._last = 0.0
        # for stateful nodes: outputs, params and seed of this node's last evaluation
        self.previous: dict | None = None
        self.previous_params: dict | None = None
        self.previous_seed: int | None = None

    def check(self) -> None:
        if self._cancel is not None and self._cancel.cancelled:
            raise Cancelled(f"cancelled while evaluating node {self.node_id!r}")

    def progress(self, done: float, total: float) -> bool:
        """Kernel progress callback: returns False once cancelled."""
        if self._report is not None:
            now = time.perf_counter()
            if now - self._last > 0.05 or done >= total:
                self._last = now
                self._report(self.node_id, min(1.0, max(0.0, float(done) / max(float(total), 1e-12))))
        return not (self._cancel is not None and self._cancel.cancelled)


def node_seed(document_seed: int, node_id: str) -> int:
    """Deterministic per-node seed: document seed mixed with the node id."""
    return (int(document_seed) * 1_000_003 + zlib.crc32(node_id.encode("utf-8"))) % (2**63)


@dataclass(frozen=True)
class NodeInfo:
    """Static description of a node type for UIs and documentation."""

    type_name: str
    title: str
    code: str
    family: str
    inputs: tuple[Port, ...]
    outputs: tuple[Port, ...]
    params: tuple[Param, ...]
    doc: str


class NodeType:
    """Base class of all node types.

    Subclasses set the class attributes and implement `evaluate`, which must
    be pure: same inputs and params (and ctx.rng) give the same outputs.
    ``version`` is part of the cache key; bump it when results change.
    """

    type_name: ClassVar[str] = ""
    title: ClassVar[str] = ""
    code: ClassVar[str] = ""
    family: ClassVar[str] = "topology"
    version: ClassVar[int] = 1
    inputs: ClassVar[tuple[Port, ...]] = ()
    outputs: ClassVar[tuple[Port, ...]] = ()
    params: ClassVar[tuple[Param, ...]] = ()
    uses_rng: ClassVar[bool] = False
    # stateful nodes receive their previous result (ctx.previous) and may resume
    # from it after a local edit (regrowth) instead of starting over; when the
    # output ports' types have codecs (engine.graph.codec, used by the default
    # encode_state / decode_state) that result is also kept in the project file
    stateful: ClassVar[bool] = False
    max_per_graph: ClassVar[int | None] = None
    # the parameter that sets the size of the work: what to lower when the
    # memory estimate exceeds the budget (see memory_estimate)
    memory_param: ClassVar[str] = ""

    def evaluate(self, inputs: dict[str, Any], params: dict[str, Any], ctx: EvalContext) -> dict[str, Any]:
        raise NotImplementedError

    @classmethod
    def source_token(cls, params: dict[str, Any]) -> str:
        """A digest of outside content the node reads (a file's bytes), part of
        its cache key so that editing that file on disk re-evaluates the node;
        "" when the node reads nothing outside the graph (or it is unreadable:
        evaluate() then reports the problem)."""
        return ""

    # -- memory -------------------------------------------------------------
    @classmethod
    def memory_estimate(cls, params: dict[str, Any], inputs_shape_info: dict[str, Any] | None = None) -> int:
        """Peak bytes an evaluation with these (validated) parameters allocates.

        ``inputs_shape_info`` is the dict of input values when the inputs are
        known (the evaluator passes them), None before anything is evaluated
        (the command line checks a graph up front): an estimate that needs an
        input's size then counts only what the parameters tell.  Must be cheap
        (no allocation proportional to the estimate).  0 = negligible.
        """
        return 0

    @classmethod
    def check_memory(cls, params: dict[str, Any], inputs_shape_info: dict[str, Any] | None = None) -> int:
        """``memory_estimate``, refused with ``engine.memory.MemoryLimitError``
        (naming ``memory_param`` and its value) when it exceeds the budget."""
        from engine.memory import check_budget

        need = int(cls.memory_estimate(params, inputs_shape_info))
        if need <= 0:
            return 0
        name = cls.memory_param
        what = f"{name} = {params.get(name)!r}" if name else "this evaluation"
        return check_budget(need, what=what, lower=name, where=name)

    # -- stored state (stateful nodes) ------------------------------------
    def encode_state(self, outputs: dict[str, Any]) -> dict | None:
        """The outputs as a JSON-able dict for the project file, or None when
        this node type cannot store them (its history is then not kept).

        By default the registered codecs of the output ports' types encode
        them (`engine.graph.codec.encode_outputs`); None when a type has none."""
        return encode_outputs(outputs, self.outputs)

    def decode_state(self, blob: dict, inputs: dict[str, Any]) -> dict[str, Any]:
        """Outputs rebuilt from `encode_state`'s dict against the node's current
        inputs; raise ValueError when the blob is malformed or does not fit them.

        By default the output ports' codecs decode it
        (`engine.graph.codec.decode_outputs`)."""
        if not has_codecs(self.outputs):
            raise ValueError(f"node type {self.type_name!r} cannot restore a stored state")
        return decode_outputs(blob, inputs, self.outputs)

    # -- schema helpers -------------------------------------------------
    @classmethod
    def param(cls, name: str) -> Param:
        for p in cls.params:
            if p.name == name:
                return p
        raise KeyError(f"node type {cls.type_name!r} has no parameter {name!r}")

    @classmethod
    def input_port(cls, name: str) -> Port:
        for p in cls.inputs:
            if p.name == name:
                return p
        raise KeyError(f"node type {cls.type_name!r} has no input port {name!r}")

    @classmethod
    def output_port(cls, name: str) -> Port:
        for p in cls.outputs:
            if p.name == name:
                return p
        raise KeyError(f"node type {cls.type_name!r} has no output port {name!r}")

    @classmethod
    def default_params(cls) -> dict[str, Any]:
        return {p.name: p.coerce(p.default) for p in cls.params}

    @classmethod
    def validate_params(cls, params: dict[str, Any], node_id: str | None = None) -> dict[str, Any]:
        """Full, canonical parameter dict: defaults filled in, unknown names refused."""
        out = cls.default_params()
        for name, value in params.items():
            try:
                p = cls.param(name)
            except KeyError:
                known = ", ".join(q.name for q in cls.params) or "none"
                raise ParamError(name, value, f"a parameter of {cls.type_name} (known: {known})", node=node_id) from None
            try:
                out[name] = p.coerce(value)
            except ParamError as exc:
                raise exc.on_node(node_id) if node_id else exc
        return out

    @classmethod
    def info(cls) -> NodeInfo:
        return NodeInfo(cls.type_name, cls.title or cls.type_name, cls.code, cls.family,
                        cls.inputs, cls.outputs, cls.params, (cls.__doc__ or "").strip())


_REGISTRY: dict[str, type[NodeType]] = {}


def register(cls: type[NodeType]) -> type[NodeType]:
    """Class decorator adding a node type to the registry."""
    if not cls.type_name:
        raise ValueError(f"{cls.__name__} has no type_name")
    if cls.type_name in _REGISTRY and _REGISTRY[cls.type_name] is not cls:
        raise ValueError(f"node type {cls.type_name!r} registered twice")
    _REGISTRY[cls.type_name] = cls
    return cls


def node_type(type_name: str) -> type[NodeType]:
    _ensure_builtin_nodes()
    try:
        return _REGISTRY[type_name]
    except KeyError:
        raise KeyError(f"unknown node type {type_name!r} (known: {', '.join(sorted(_REGISTRY))})") from None


def all_node_types() -> dict[str, type[NodeType]]:
    _ensure_builtin_nodes()
    return dict(_REGISTRY)


def _ensure_builtin_nodes() -> None:
    # The node modules register themselves on import; importing lazily keeps
    # engine.graph free of a hard dependency on engine.nodes at import time.
    import engine.nodes  # noqa: F401
