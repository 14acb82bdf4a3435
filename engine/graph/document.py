"""The graph document: nodes, edges, seed.  Plain data plus listeners.

All edits go through the undoable commands in `commands.py`, which call the
``_raw_*`` mutators here; those validate first and change nothing when they
refuse.  Views subscribe with `subscribe(callback)` and receive
``(event_name, payload)`` tuples.
"""

from __future__ import annotations

import copy
import heapq
import math
import re
from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

from .annotations import Annotations
from .errors import GraphError
from .node import node_type
from .schema import ports_compatible


@dataclass
class NodeInstance:
    id: str
    type_name: str
    params: dict[str, Any]
    position: tuple[float, float] = (0.0, 0.0)
    label: str = ""


@dataclass(frozen=True)
class Edge:
    src: str
    src_port: str
    dst: str
    dst_port: str


@dataclass(frozen=True)
class GraphSnapshot:
    """An immutable copy of the document for evaluation off the GUI thread."""

    seed: int
    nodes: dict[str, tuple[str, dict]]  # id -> (type_name, params)
    edges: tuple[Edge, ...]
    order: tuple[str, ...] = field(default=())

    def inputs_of(self, node_id: str, port: str) -> list[Edge]:
        return [e for e in self.edges if e.dst == node_id and e.dst_port == port]


_ID_RE = re.compile(r"^[A-Za-z_][A-Za-z0-9_\-]*$")


class GraphDocument:
    """Nodes with stable ids, ordered edges, a document seed."""

    def __init__(self, seed: int = 0):
        self.seed = int(seed)
        self.nodes: dict[str, NodeInstance] = {}
        self.edges: list[Edge] = []
        self.meta: dict[str, Any] = {}
        # stored results of stateful nodes, {node id: entry} (engine.graph.node_state);
        # whoever saves fills it from Evaluator.export_state, whoever opens imports it
        self.node_state: dict[str, dict] = {}
        self.load_warnings: list[str] = []  # what loading the project file dropped, and why
        self.annotations = Annotations(self)  # frames and subgraphs (engine.graph.annotations)
        self._listeners: list[Callable[[str, Any], None]] = []
        self._counters: dict[str, int] = {}

    # -- events ---------------------------------------------------------
    def subscribe(self, callback: Callable[[str, Any], None]) -> None:
        self._listeners.append(callback)

    def unsubscribe(self, callback: Callable[[str, Any], None]) -> None:
        if callback in self._listeners:
            self._listeners.remove(callback)

    def emit(self, event: str, payload: Any = None) -> None:
        for cb in list(self._listeners):
            cb(event, payload)

    # -- queries --------------------------------------------------------
    def node(self, node_id: str) -> NodeInstance:
        try:
            return self.nodes[node_id]
        except KeyError:
            raise GraphError(f"no node with id {node_id!r}", node=node_id) from None

    def new_id(self, type_name: str) -> str:
        """A fresh stable id: the node type's short code and a counter."""
        code = node_type(type_name).code or type_name.lower()
        k = self._counters.get(code, 0)
        while True:
            k += 1
            candidate = f"{code}{k}"
            if candidate not in self.nodes:
                self._counters[code] = k
                return candidate

    def inputs_of(self, node_id: str, port: str | None = None) -> list[Edge]:
        return [e for e in self.edges if e.dst == node_id and (port is None or e.dst_port == port)]

    def outputs_of(self, node_id: str) -> list[Edge]:
        return [e for e in self.edges if e.src == node_id]

    def downstream(self, node_id: str) -> set[str]:
        """All nodes reachable from `node_id` (excluding itself)."""
        succ: dict[str, list[str]] = {}
        for e in self.edges:
            succ.setdefault(e.src, []).append(e.dst)
        seen: set[str] = set()
        stack = [node_id]
        while stack:
            for m in succ.get(stack.pop(), ()):
                if m not in seen:
                    seen.add(m)
                    stack.append(m)
        return seen

    def topological_order(self) -> list[str]:
        return topological_order(list(self.nodes), self.edges)

    def snapshot(self) -> GraphSnapshot:
        nodes = {nid: (n.type_name, copy.deepcopy(n.params)) for nid, n in self.nodes.items()}
        return GraphSnapshot(self.seed, nodes, tuple(self.edges), tuple(self.topological_order()))

    # -- raw mutators (commands call these) -----------------------------
    def _raw_add_node(self, node: NodeInstance, index: int | None = None) -> None:
        if not _ID_RE.match(node.id):
            raise GraphError(f"node id {node.id!r} is not a valid identifier", node=node.id, where="id")
        if node.id in self.nodes:
            raise GraphError(f"a node with id {node.id!r} already exists", node=node.id, where="id")
        cls = node_type(node.type_name)
        node.params = cls.validate_params(node.params, node.id)
        if cls.max_per_graph is not None:
            same = [n for n, inst in self.nodes.items() if inst.type_name == node.type_name]
            if len(same) >= cls.max_per_graph:
                raise GraphError(f"a graph holds at most {cls.max_per_graph} {node.type_name} node(s); "
                                 f"it already has {same}", node=node.id, where="type")
        if index is None or index >= len(self.nodes):
            self.nodes[node.id] = node  # appending keeps loading a project linear
        else:
            items = list(self.nodes.items())
            items.insert(index, (node.id, node))
            self.nodes = dict(items)
        self.emit("node_added", node.id)
        self.annotations._node_restored(node)  # undoing a removal puts it back in its subgraph

    def _raw_remove_node(self, node_id: str) -> tuple[NodeInstance, int]:
        node = self.node(node_id)
        if any(e.src == node_id or e.dst == node_id for e in self.edges):
            raise GraphError(f"node {node_id!r} still has connections", node=node_id)
        index = list(self.nodes).index(node_id)
        del self.nodes[node_id]
        self.node_state.pop(node_id, None)
        self.annotations._node_removed(node)
        self.emit("node_removed", node_id)
        return node, index

    def check_connection(self, edge: Edge) -> None:
        """Raise GraphError if `edge` may not be added; names node and port."""
        in_port = self._connection_port(edge)
        if edge in self.edges:
            raise _already_connected(edge)
        if not in_port.multi and self.inputs_of(edge.dst, edge.dst_port):
            raise _input_taken(edge)
        if edge.src == edge.dst or edge.src in self.downstream(edge.dst):
            raise _cycle(edge)

    def _connection_port(self, edge: Edge):
        """The input port `edge` would feed; GraphError if a node or port is
        missing or the port types do not match."""
        src = self.node(edge.src)
        dst = self.node(edge.dst)
        try:
            out_port = node_type(src.type_name).output_port(edge.src_port)
        except KeyError as exc:
            raise GraphError(str(exc.args[0]), node=edge.src, where=edge.src_port) from None
        try:
            in_port = node_type(dst.type_name).input_port(edge.dst_port)
        except KeyError as exc:
            raise GraphError(str(exc.args[0]), node=edge.dst, where=edge.dst_port) from None
        if not ports_compatible(out_port.type, in_port.type):
            raise GraphError(
                f"cannot connect {edge.src}.{edge.src_port} ({out_port.type}) to "
                f"{edge.dst}.{edge.dst_port}, which takes {in_port.type}",
                node=edge.dst, where=edge.dst_port)
        return in_port

    def _raw_connect(self, edge: Edge, index: int | None = None) -> None:
        self.check_connection(edge)
        if index is None:
            self.edges.append(edge)
        else:
            self.edges.insert(index, edge)
        self.emit("edge_added", edge)

    def _raw_connect_all(self, edges: Sequence[Edge]) -> None:
        """Append `edges` in order, each checked as `check_connection` checks it
        after the ones before it, in O(V + E) overall (loading a project).

        All or nothing: when an edge is refused the document is unchanged and
        the GraphError's ``index`` is that edge's position in `edges`.
        """
        present = set(self.edges)
        taken = {(e.dst, e.dst_port) for e in self.edges}
        accepted: list[Edge] = []
        refused: GraphError | None = None
        for i, edge in enumerate(edges):
            try:
                in_port = self._connection_port(edge)
                if edge in present:
                    raise _already_connected(edge)
                if not in_port.multi and (edge.dst, edge.dst_port) in taken:
                    raise _input_taken(edge)
                if edge.src == edge.dst:
                    raise _cycle(edge)
            except GraphError as exc:
                exc.index, refused = i, exc
                break
            present.add(edge)
            taken.add((edge.dst, edge.dst_port))
            accepted.append(edge)
        closing = _first_cycle_closing(list(self.nodes), self.edges, accepted)
        if closing is not None:
            err = _cycle(accepted[closing])
            err.index = closing
            raise err
        if refused is not None:
            raise refused
        for edge in accepted:
            self.edges.append(edge)
            self.emit("edge_added", edge)

    def _raw_disconnect(self, edge: Edge) -> int:
        try:
            index = self.edges.index(edge)
        except ValueError:
            raise GraphError(f"{edge.src}.{edge.src_port} is not connected to {edge.dst}.{edge.dst_port}",
                             node=edge.dst, where=edge.dst_port) from None
        del self.edges[index]
        self.emit("edge_removed", edge)
        return index

    def _raw_set_param(self, node_id: str, name: str, value: Any) -> Any:
        node = self.node(node_id)
        cls = node_type(node.type_name)
        new = cls.validate_params({**node.params, name: value}, node_id)
        old = node.params.get(name)
        node.params = new
        self.emit("param_changed", (node_id, name))
        return old

    def _raw_move(self, node_id: str, position: tuple[float, float]) -> tuple[float, float]:
        node = self.node(node_id)
        x, y = float(position[0]), float(position[1])
        if not (math.isfinite(x) and math.isfinite(y)):  # a project file cannot hold it
            raise GraphError(f"node {node_id!r}: editor position {position!r} is not two finite numbers",
                             node=node_id, where="position")
        old = node.position
        node.position = (x, y)
        self.emit("node_moved", node_id)
        return old

    def _raw_set_label(self, node_id: str, label: str) -> str:
        node = self.node(node_id)
        old = node.label
        node.label = str(label)
        self.emit("label_changed", node_id)
        return old

    def _raw_set_seed(self, seed: int) -> int:
        if int(seed) < 0:  # a project file holds non-negative seeds only
            raise GraphError(f"seed {seed!r} is invalid: expected a non-negative integer", where="seed")
        old = self.seed
        self.seed = int(seed)
        self.emit("seed_changed", seed)
        return old

    def replace_with(self, other: "GraphDocument") -> None:
        """Take over another document's content (open file); listeners stay."""
        self.seed = other.seed
        self.nodes = other.nodes
        self.edges = other.edges
        self.meta = other.meta
        self.node_state = other.node_state
        self.load_warnings = other.load_warnings
        self.annotations = other.annotations
        self.annotations.doc = self
        self._counters = {}
        self.emit("reset", None)


def topological_order(node_ids: list[str], edges) -> list[str]:
    """Kahn's algorithm; ties broken by document order.  Raises on a cycle.

    O((V + E) log V): the ready nodes wait in a heap keyed on document position.
    """
    position = {n: i for i, n in enumerate(node_ids)}
    indeg = dict.fromkeys(node_ids, 0)
    succ: dict[str, list[str]] = {n: [] for n in node_ids}
    for e in edges:
        if e.src in indeg and e.dst in indeg:
            indeg[e.dst] += 1
            succ[e.src].append(e.dst)
    ready = [position[n] for n, d in indeg.items() if d == 0]
    heapq.heapify(ready)
    out = []
    while ready:
        n = node_ids[heapq.heappop(ready)]
        out.append(n)
        for m in succ[n]:
            indeg[m] -= 1
            if indeg[m] == 0:
                heapq.heappush(ready, position[m])
    if len(out) != len(node_ids):
        stuck = sorted(set(node_ids) - set(out), key=position.get)
        raise GraphError(f"the graph has a cycle through nodes {stuck}", node=stuck[0])
    return out


def _has_cycle(node_ids: list[str], edges: Sequence[Edge]) -> bool:
    """Whether `edges` between `node_ids` close a directed cycle; O(V + E)."""
    indeg = dict.fromkeys(node_ids, 0)
    succ: dict[str, list[str]] = {}
    for e in edges:
        indeg[e.dst] += 1
        succ.setdefault(e.src, []).append(e.dst)
    ready = [n for n, d in indeg.items() if d == 0]
    done = 0
    while ready:
        n = ready.pop()
        done += 1
        for m in succ.get(n, ()):
            indeg[m] -= 1
            if indeg[m] == 0:
                ready.append(m)
    return done != len(indeg)


def _first_cycle_closing(node_ids: list[str], existing: list[Edge], added: list[Edge]) -> int | None:
    """Index of the first edge of `added` that closes a cycle when they are
    appended to the acyclic `existing` one by one, or None.

    One O(V + E) check when there is no cycle (the usual case); a binary
    search over prefixes, O((V + E) log E), when there is.
    """
    if not _has_cycle(node_ids, existing + added):
        return None
    lo, hi = 0, len(added) - 1  # the prefix ending at hi has a cycle
    while lo < hi:
        mid = (lo + hi) // 2
        if _has_cycle(node_ids, existing + added[: mid + 1]):
            hi = mid
        else:
            lo = mid + 1
    return lo


def _already_connected(edge: Edge) -> GraphError:
    return GraphError(f"{edge.src}.{edge.src_port} is already connected to {edge.dst}.{edge.dst_port}",
                      node=edge.dst, where=edge.dst_port)


def _input_taken(edge: Edge) -> GraphError:
    return GraphError(f"input {edge.dst}.{edge.dst_port} takes one connection and already has one",
                      node=edge.dst, where=edge.dst_port)


def _cycle(edge: Edge) -> GraphError:
    return GraphError(f"connecting {edge.src} to {edge.dst} would create a cycle",
                      node=edge.dst, where=edge.dst_port)
