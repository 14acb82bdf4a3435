"""Incremental evaluation of a graph snapshot.

Each node's outputs are cached under a key made of its type name and version,
its canonical parameters, the node seed (for random nodes) and the keys of
its inputs in connection order.  Editing one parameter changes the key of
that node and of everything downstream, and nothing else, so only those
re-run.  A failing node records its error; nodes below it are blocked; caches
above it stay.

Stateful nodes (``NodeType.stateful``) also keep their last result, which the
next evaluation hands them as ``ctx.previous``.  `export_state` encodes those
results for the project file and `import_state` takes them back: a stored
result whose key equals the node's key now is used as the node's output (no
re-evaluation); one whose key differs is still offered as ``ctx.previous``.

A result computed outside an evaluation (a dock's live run of the node's own
session) can be `adopt`-ed: stored under the key evaluation would compute for
that snapshot, as if the node had evaluated, so the next evaluation serves it
as cached and only what is downstream runs.  `queue_adoption` defers that to
the start of the next evaluation, on the evaluating thread.
"""

from __future__ import annotations

import hashlib
import json
import logging
import threading
import time
from collections import OrderedDict
from dataclasses import dataclass, field
from typing import Any, Callable

from .document import Edge, GraphDocument, GraphSnapshot, topological_order
from .errors import GraphError
from .node import Cancelled, CancelToken, EvalContext, node_seed, node_type
from .node_state import StoredState, parse_state_entry

log = logging.getLogger(__name__)

# Node statuses in a report.
EVALUATED, CACHED, FAILED, BLOCKED, CANCELLED = "evaluated", "cached", "failed", "blocked", "cancelled"


@dataclass
class NodeResult:
    node_id: str
    status: str
    seconds: float = 0.0
    error: str = ""
    where: str = ""
    key: str = ""
    warning: str = ""  # e.g. a stored state that could not be restored (the node still ran)


@dataclass
class EvalReport:
    results: dict[str, NodeResult] = field(default_factory=dict)
    outputs: dict[str, dict[str, Any]] = field(default_factory=dict)
    seconds: float = 0.0
    cancelled: bool = False
    # set by front ends: which request this answers, whether a newer one replaced it,
    # and an unexpected exception outside any node (a bug, reported rather than raised)
    tag: Any = None
    superseded: bool = False
    internal_error: str = ""

    @property
    def ok(self) -> bool:
        return not self.cancelled and all(r.status in (EVALUATED, CACHED) for r in self.results.values())

    @property
    def cache_hits(self) -> int:
        return sum(r.status == CACHED for r in self.results.values())

    @property
    def errors(self) -> dict[str, str]:
        return {n: r.error for n, r in self.results.items() if r.status == FAILED}

    @property
    def warnings(self) -> dict[str, str]:
        return {n: r.warning for n, r in self.results.items() if r.warning}

    def output(self, node_id: str, port: str | None = None) -> Any:
        outs = self.outputs[node_id]
        if port is None:
            (port,) = outs.keys() if len(outs) == 1 else (next(iter(outs)),)
        return outs[port]


def _canonical(obj: Any) -> str:
    # sorted keys, fixed separators and repr-exact floats: the same text (and
    # so the same sha256) in every process, whatever PYTHONHASHSEED is
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), allow_nan=False)


_Missing = object()  # an upstream result without the port an edge names


@dataclass
class _Held:
    """A stateful node's last result (what ``ctx.previous`` is built from)."""

    type_name: str
    key: str
    params: dict
    seed: int
    outputs: dict
    blob: dict | None = None  # encode_state(outputs), made once when first exported


def incoming_edges(snapshot: GraphSnapshot) -> dict[str, dict[str, list[Edge]]]:
    """``{node_id: {input port: [edges in connection order]}}`` of a snapshot,
    made in one pass over its edges (nodes and ports without edges are absent)."""
    index: dict[str, dict[str, list[Edge]]] = {}
    for e in snapshot.edges:
        index.setdefault(e.dst, {}).setdefault(e.dst_port, []).append(e)
    return index


def check_required_inputs(snapshot: GraphSnapshot, node_id: str,
                          incoming: dict[str, dict[str, list[Edge]]] | None = None) -> None:
    """GraphError naming the first required input port of ``node_id`` with no
    edge; ``incoming`` (from `incoming_edges`) saves a scan of every edge."""
    type_name, _ = snapshot.nodes[node_id]
    cls = node_type(type_name)
    ports = incoming.get(node_id, {}) if incoming is not None else None
    for port in cls.inputs:
        connected = ports.get(port.name) if ports is not None else snapshot.inputs_of(node_id, port.name)
        if port.required and not connected:
            raise GraphError(f"node {node_id!r} ({type_name}): required input {port.name!r} "
                             f"({port.type}) is not connected", node=node_id, where=port.name)


def _checked(snapshot: GraphSnapshot, node_id: str,
             incoming: dict[str, dict[str, list[Edge]]]) -> tuple[type, dict]:
    """(node type class, validated parameters) of ``node_id``; GraphError for a
    refused parameter or a missing required input, KeyError for an unknown type."""
    type_name, params = snapshot.nodes[node_id]
    cls = node_type(type_name)
    params = cls.validate_params(params, node_id)
    check_required_inputs(snapshot, node_id, incoming)
    return cls, params


def _cache_key(snapshot: GraphSnapshot, node_id: str, cls: type, params: dict,
               ports: dict[str, list[Edge]], keys: dict[str, str]) -> tuple[dict[str, list[Edge]], str]:
    """({input port: edges in connection order}, cache key) of ``node_id``.

    The key is the sha256 of its type name and version, its validated
    ``params``, the keys of its inputs (``keys`` must hold every upstream
    node's), its source token and, for random nodes, the document seed and
    node id.  The one computation of a key: evaluation and `Evaluator.adopt`
    both call it."""
    edges_by_port = {p.name: ports.get(p.name, []) for p in cls.inputs}
    key_src = {
        "t": snapshot.nodes[node_id][0], "v": cls.version, "p": params,
        "in": {port: [[keys[e.src], e.src_port] for e in es] for port, es in edges_by_port.items()},
    }
    token = cls.source_token(params)
    if token:
        key_src["source"] = token
    if cls.uses_rng:
        key_src["seed"] = [snapshot.seed, node_id]
    return edges_by_port, hashlib.sha256(_canonical(key_src).encode()).hexdigest()


class Evaluator:
    """Evaluates snapshots, reusing cached outputs across calls.

    One evaluation at a time (a lock serialises calls); the cache holds at
    most `max_entries` node results, least recently used dropped first.
    `export_state` / `import_state` never wait for a running evaluation.
    """

    def __init__(self, max_entries: int = 512):
        self._cache: OrderedDict[str, dict[str, Any]] = OrderedDict()
        self.max_entries = max_entries
        self._lock = threading.Lock()
        # Stateful nodes' results.  The evaluating thread changes these (and
        # `import_state` sets `_pending`) only under `_state_lock`.
        self._state_lock = threading.Lock()
        self._state: dict[str, _Held] = {}             # evaluated (or restored) this session
        self._stored: dict[str, StoredState] = {}      # imported, not yet taken up by its node
        self._pending: dict[str, StoredState] | None = None  # imported, applied at the next evaluate
        self._adoptions: dict[str, tuple] = {}          # queue_adoption's, taken at the next evaluate

    def clear(self) -> None:
        with self._lock, self._state_lock:
            self._cache.clear()
            self._state.clear()
            self._stored.clear()
            self._pending = None
            self._adoptions.clear()

    # -- stored state -----------------------------------------------------
    def import_state(self, states: dict[str, Any]) -> list[str]:
        """Take stateful nodes' stored results (``{node_id: entry}``, see
        `engine.graph.node_state`) in place of everything held so far.

        Applied when the next evaluation starts (a running one is not
        disturbed); the cache is emptied then too, because a restored result
        may differ from a cached one under the same key.  Malformed entries
        are dropped; the returned list says which and why.
        """
        entries: dict[str, StoredState] = {}
        warnings = []
        for nid, entry in (states or {}).items():
            try:
                entries[str(nid)] = parse_state_entry(entry)
            except ValueError as exc:
                warnings.append(f"node {nid!r}: stored state dropped: {exc}")
        with self._state_lock:
            self._pending = entries
        return warnings

    def add_state(self, states: dict[str, Any]) -> list[str]:
        """Take stored results for nodes that hold none (pasted nodes), keeping
        everything held and the cache (no other node's result can change).

        An entry for a node that already holds a result is left out, as is a
        malformed one; the returned list says which and why.
        """
        warnings = []
        with self._state_lock:
            target = self._pending if self._pending is not None else self._stored
            for nid, entry in (states or {}).items():
                nid = str(nid)
                if nid in self._state or nid in target:
                    warnings.append(f"node {nid!r}: holds a result already; stored state not taken")
                    continue
                try:
                    target[nid] = parse_state_entry(entry)
                except ValueError as exc:
                    warnings.append(f"node {nid!r}: stored state dropped: {exc}")
        return warnings

    def export_state(self) -> dict[str, dict]:
        """``{node_id: {"key", "params", "seed", "value"}}`` for every stateful
        node result held, including imported ones no evaluation has used yet.
        Nodes whose type cannot encode its outputs are left out."""
        with self._state_lock:
            if self._pending is not None:
                held, stored = {}, dict(self._pending)
            else:
                held, stored = dict(self._state), dict(self._stored)
        out = {nid: s.to_dict() for nid, s in stored.items()}
        for nid, h in held.items():
            if h.blob is None:
                try:
                    h.blob = node_type(h.type_name)().encode_state(h.outputs)
                except Exception:  # a bug in one node's encoder must not stop a save
                    log.exception("cannot encode the state of node %r (%s)", nid, h.type_name)
                    continue
            if h.blob is not None:
                out[nid] = StoredState(h.key, h.params, h.seed, h.blob).to_dict()
        return out

    def _apply_pending(self) -> None:
        with self._state_lock:
            if self._pending is None:
                return
            self._cache.clear()
            self._state, self._stored, self._pending = {}, self._pending, None

    # -- results computed outside an evaluation --------------------------------
    def adopt(self, graph: GraphDocument | GraphSnapshot, node_id: str, outputs: dict[str, Any], *,
              inputs: dict[str, Any] | None = None) -> bool:
        """Store ``outputs`` as node ``node_id``'s result for ``graph``, as if it had evaluated.

        The cache key is the one evaluation computes for that snapshot (`_cache_key`),
        so the next evaluation of it reports the node "cached" and evaluates its
        downstream nodes from ``outputs``; a stateful node's result is held for
        ``ctx.previous`` and `export_state` exactly as after an evaluation.  The
        caller vouches that ``outputs`` are what the node's ``evaluate`` returns for
        that snapshot's parameters, seed and inputs.

        inputs : {input port: value (a list for a multi port)}, optional: the values
            ``outputs`` were computed from; refused unless each is the very object
            (``is``) the cached upstream result feeds to that port.

        Returns False and stores nothing when the key cannot be computed with
        certainty: an unknown node or type, a parameter the node refuses, a
        required input unconnected, a node upstream not cached under its key for
        this snapshot (its last evaluation failed, changed or was dropped), an
        output port missing from ``outputs``, or ``inputs`` not the cached ones.
        Waits for a running evaluation (use `queue_adoption` from a GUI thread).
        """
        snap = graph.snapshot() if isinstance(graph, GraphDocument) else graph
        with self._lock:
            self._apply_pending()   # an import empties the cache: the adopted entry must come after
            return self._adopt(snap, node_id, outputs, inputs)

    def queue_adoption(self, graph: GraphDocument | GraphSnapshot, node_id: str, outputs: dict[str, Any], *,
                       inputs: dict[str, Any] | None = None) -> None:
        """`adopt` at the start of the next evaluation, on its thread (never during one).

        Returns at once, even while an evaluation runs; a newer queued adoption of
        the same node replaces this one; a refused one is logged and dropped."""
        snap = graph.snapshot() if isinstance(graph, GraphDocument) else graph
        with self._state_lock:
            self._adoptions[node_id] = (snap, outputs, inputs)

    def _apply_adoptions(self) -> None:
        with self._state_lock:
            queued, self._adoptions = self._adoptions, {}
        for node_id, (snap, outputs, inputs) in queued.items():
            if not self._adopt(snap, node_id, outputs, inputs):
                log.info("the result offered for node %r was not adopted; it evaluates", node_id)

    def _adopt(self, snap: GraphSnapshot, node_id: str, outputs: dict, inputs: dict | None) -> bool:
        """`adopt` with the evaluation lock held."""
        incoming = incoming_edges(snap)
        keys: dict[str, str] = {}
        try:
            for nid in self._needed(snap, [node_id], incoming):   # upstream first, node_id last
                cls, params = _checked(snap, nid, incoming)
                edges_by_port, keys[nid] = _cache_key(snap, nid, cls, params, incoming.get(nid, {}), keys)
                if nid != node_id and keys[nid] not in self._cache:
                    return False
        except Exception:  # no key with certainty (bad parameter, unknown type, unreadable source)
            return False
        if not isinstance(outputs, dict) or any(p.name not in outputs for p in cls.outputs):
            return False
        for port in cls.inputs if inputs is not None else ():
            fed = [self._cache[keys[e.src]].get(e.src_port, _Missing) for e in edges_by_port[port.name]]
            given = inputs.get(port.name)
            if port.multi:
                if given is None or len(given) != len(fed) or any(a is not b for a, b in zip(given, fed)):
                    return False
            elif given is not (fed[0] if fed else None):
                return False
        key = keys[node_id]
        outputs = dict(outputs)
        self._cache_put(key, outputs)
        if cls.stateful:
            self._hold(node_id, _Held(snap.nodes[node_id][0], key, params, node_seed(snap.seed, node_id), outputs))
        return True

    def _hold(self, nid: str, held: _Held) -> None:
        with self._state_lock:
            self._state[nid] = held
            self._stored.pop(nid, None)

    def _drop_stored(self, nid: str) -> None:
        with self._state_lock:
            self._stored.pop(nid, None)

    def _cache_get(self, key: str):
        v = self._cache.get(key)
        if v is not None:
            self._cache.move_to_end(key)
        return v

    def _cache_put(self, key: str, value: dict) -> None:
        self._cache[key] = value
        self._cache.move_to_end(key)
        while len(self._cache) > self.max_entries:
            self._cache.popitem(last=False)

    def evaluate(
        self,
        graph: GraphDocument | GraphSnapshot,
        *,
        targets: list[str] | None = None,
        cancel: CancelToken | None = None,
        on_progress: Callable[[str, float], None] | None = None,
        on_node_done: Callable[[NodeResult], None] | None = None,
    ) -> EvalReport:
        """Evaluate all nodes (or only what `targets` need) in topological order.

        on_progress(node_id, fraction) is called from kernels' progress;
        on_node_done(result) after each node.  Both run on the calling thread.
        """
        snap = graph.snapshot() if isinstance(graph, GraphDocument) else graph
        with self._lock:
            return self._evaluate(snap, targets, cancel, on_progress, on_node_done)

    def _needed(self, snap: GraphSnapshot, targets: list[str] | None,
                incoming: dict[str, dict[str, list[Edge]]]) -> list[str]:
        order = list(snap.order) or topological_order(list(snap.nodes), snap.edges)
        if targets is None:
            return order
        need: set[str] = set()
        stack = list(targets)
        while stack:
            n = stack.pop()
            if n in need:
                continue
            if n not in snap.nodes:
                raise GraphError(f"no node with id {n!r}", node=n)
            need.add(n)
            stack.extend(e.src for es in incoming.get(n, {}).values() for e in es)
        return [n for n in order if n in need]

    def _evaluate(self, snap, targets, cancel, on_progress, on_node_done) -> EvalReport:
        t_start = time.perf_counter()
        self._apply_pending()
        self._apply_adoptions()
        report = EvalReport()
        keys: dict[str, str] = {}
        incoming = incoming_edges(snap)  # once per evaluation, not one scan of every edge per node
        for nid in self._needed(snap, targets, incoming):
            result = self._run_node(snap, nid, keys, report, cancel, on_progress, incoming)
            report.results[nid] = result
            if on_node_done is not None:
                on_node_done(result)
            if result.status == CANCELLED:
                report.cancelled = True
                break
        report.seconds = time.perf_counter() - t_start
        return report

    def _run_node(self, snap, nid, keys, report, cancel, on_progress, incoming) -> NodeResult:
        type_name, _ = snap.nodes[nid]
        ports = incoming.get(nid, {})
        upstream = [e.src for es in ports.values() for e in es]
        bad = [u for u in upstream if u not in keys]
        if bad:
            return NodeResult(nid, BLOCKED, error=f"waiting for failed input node(s) {sorted(set(bad))}")
        try:
            cls, params = _checked(snap, nid, incoming)
        except (GraphError, KeyError) as exc:
            msg = exc.args[0] if isinstance(exc, KeyError) else str(exc)
            return NodeResult(nid, FAILED, error=msg, where=getattr(exc, "where", "") or "")
        edges_by_port, key = _cache_key(snap, nid, cls, params, ports, keys)
        cached = self._cache_get(key)
        if cached is not None:
            if cls.stateful:
                self._hold(nid, _Held(type_name, key, params, node_seed(snap.seed, nid), cached))
            keys[nid] = key
            report.outputs[nid] = cached
            return NodeResult(nid, CACHED, key=key)
        inputs: dict[str, Any] = {}
        for port in cls.inputs:
            vals = [report.outputs[e.src][e.src_port] for e in edges_by_port[port.name]]
            inputs[port.name] = vals if port.multi else (vals[0] if vals else None)
        ctx = EvalContext(nid, snap.seed, cancel=cancel, report=on_progress)
        warning = ""
        stored = self._stored.get(nid) if cls.stateful else None
        if stored is not None:
            restored, warning = self._restore(cls, nid, stored, inputs)
            if restored is not None and stored.key == key:
                self._cache_put(key, restored)
                self._hold(nid, _Held(type_name, key, params, stored.seed, restored, stored.value))
                keys[nid] = key
                report.outputs[nid] = restored
                return NodeResult(nid, CACHED, key=key)
            if restored is not None:  # the graph changed since: the node decides what to keep
                ctx.previous_params, ctx.previous_seed, ctx.previous = stored.params, stored.seed, restored
        elif cls.stateful and nid in self._state:
            held = self._state[nid]
            ctx.previous_params, ctx.previous_seed, ctx.previous = held.params, held.seed, held.outputs
        t0 = time.perf_counter()
        try:
            ctx.check()
            cls.check_memory(params, inputs)  # refused before anything is allocated
            outputs = cls().evaluate(inputs, params, ctx)
            ctx.check()
        except Cancelled as exc:
            return NodeResult(nid, CANCELLED, time.perf_counter() - t0, error=str(exc), warning=warning)
        except Exception as exc:  # a node failure is recorded, never thrown
            where = getattr(exc, "where", "") or ""
            msg = str(exc) if isinstance(exc, (GraphError, ValueError)) else f"{type(exc).__name__}: {exc}"
            if not msg.startswith("node "):
                msg = f"node {nid!r} ({type_name}): {msg}"
            return NodeResult(nid, FAILED, time.perf_counter() - t0, error=msg, where=where, warning=warning)
        missing = [p.name for p in cls.outputs if p.name not in outputs]
        if missing:
            return NodeResult(nid, FAILED, time.perf_counter() - t0,
                              error=f"node {nid!r} ({type_name}) produced no value for {missing}")
        self._cache_put(key, outputs)
        if cls.stateful:
            self._hold(nid, _Held(type_name, key, params, ctx.seed, outputs))
        keys[nid] = key
        report.outputs[nid] = outputs
        return NodeResult(nid, EVALUATED, time.perf_counter() - t0, key=key, warning=warning)

    def _restore(self, cls, nid: str, stored: StoredState, inputs: dict) -> tuple[dict | None, str]:
        """Decode a stored result against the node's inputs: (outputs, "") or,
        when it does not decode, (None, why) and the stored state is dropped."""
        try:
            outputs = cls().decode_state(stored.value, inputs)
            missing = [p.name for p in cls.outputs if p.name not in (outputs or {})]
            if missing:
                raise ValueError(f"no value for {missing}")
        except Exception as exc:  # a bad blob in a file costs the history, never the node
            self._drop_stored(nid)
            return None, (f"node {nid!r} ({cls.type_name}): the result stored in the project could not "
                          f"be restored ({exc}); evaluated from scratch")
        return outputs, ""
