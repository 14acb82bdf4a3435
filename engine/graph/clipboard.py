"""Copy and paste of part of a graph: fragments and the undoable paste.

A *fragment* is plain JSON data in the project file's encoding (see
`engine.graph.project.document_to_dict`)::

    {"format": "mesoforge-fragment", "version": 1,
     "nodes": [{"id", "type", "params", "position", "label"?}, ...],
     "edges": [{"from": [node, port], "to": [node, port]}, ...],   # among those nodes only
     "node_state": {node id: stored result}}                       # stateful nodes, if stored

`fragment_of` cuts one out of a document; `PasteFragment` is the undo command
that adds a copy under fresh ids (existing nodes are never touched) with its
inner edges as one undo step. Every refusal (not a fragment, unknown node type,
parameters the schema refuses, an edge to a missing node or port, more nodes of
a type than a graph may hold) is raised before the document changes.
"""

from __future__ import annotations

import copy
import json
from typing import Any

from .commands import Command
from .document import Edge, GraphDocument, NodeInstance
from .errors import GraphError
from .node import node_type
from .node_state import parse_state_entry
from .project import InvalidProject, check_json_values, parse_json

__all__ = ["FRAGMENT_FORMAT", "FRAGMENT_VERSION", "PasteFragment", "fragment_from_text",
           "fragment_of", "fragment_origin", "fragment_to_text"]

FRAGMENT_FORMAT = "mesoforge-fragment"
FRAGMENT_VERSION = 1


def fragment_of(doc: GraphDocument, node_ids, *, node_state: dict | None = None) -> dict[str, Any]:
    """The fragment holding ``node_ids`` of ``doc`` (in document order) and the
    edges among them. ``node_state`` ({id: entry}, default ``doc.node_state``)
    supplies stored results of stateful nodes. GraphError for an unknown id."""
    wanted = list(node_ids)
    for nid in wanted:
        doc.node(nid)  # GraphError naming the id
    keep = set(wanted)
    states = doc.node_state if node_state is None else node_state
    nodes, stored = [], {}
    for nid, n in doc.nodes.items():
        if nid not in keep:
            continue
        entry = {"id": nid, "type": n.type_name, "params": copy.deepcopy(n.params),
                 "position": [float(n.position[0]), float(n.position[1])]}
        if n.label:
            entry["label"] = n.label
        nodes.append(entry)
        if nid in states and node_type(n.type_name).stateful:
            stored[nid] = copy.deepcopy(states[nid])
    edges = [{"from": [e.src, e.src_port], "to": [e.dst, e.dst_port]}
             for e in doc.edges if e.src in keep and e.dst in keep]
    return {"format": FRAGMENT_FORMAT, "version": FRAGMENT_VERSION, "nodes": nodes,
            "edges": edges, "node_state": stored}


def fragment_to_text(fragment: dict) -> str:
    """JSON text of a fragment (what goes on the system clipboard)."""
    return json.dumps(fragment, allow_nan=False)


def fragment_from_text(text: str) -> dict[str, Any]:
    """Parse clipboard text; GraphError unless it is a well-formed fragment."""
    try:
        data = parse_json(text)
    except InvalidProject as exc:
        raise GraphError(f"clipboard text is not a Mesoforge fragment: {exc}") from None
    _check_structure(data)
    return data


def fragment_origin(fragment: dict) -> tuple[float, float]:
    """Top-left corner of the fragment's node positions ((0, 0) when empty)."""
    xs = [float(n["position"][0]) for n in fragment["nodes"]]
    ys = [float(n["position"][1]) for n in fragment["nodes"]]
    return (min(xs), min(ys)) if xs else (0.0, 0.0)


class PasteFragment(Command):
    """Add a copy of ``fragment`` moved by ``offset``: fresh ids, the inner edges,
    one undo step. After ``do``: ``new_ids`` (in fragment order) and ``id_map``
    ({fragment id: new id}). Redo reuses the same ids."""

    def __init__(self, fragment: dict, offset=(0.0, 0.0)):
        self.fragment = copy.deepcopy(fragment)
        _check_structure(self.fragment)
        dx, dy = (float(v) for v in offset)
        self.offset = (dx, dy)
        n = len(self.fragment["nodes"])
        self.text = f"paste {n} node{'s' if n != 1 else ''}"
        self.new_ids: list[str] = []
        self.id_map: dict[str, str] = {}
        self._edges: list[Edge] = []

    # -- Command ------------------------------------------------------------
    def do(self, doc: GraphDocument) -> None:
        nodes, edges, states = self._prepare(doc)
        added: list[str] = []
        try:
            for node in nodes:
                doc._raw_add_node(node)
                added.append(node.id)
            doc._raw_connect_all(edges)
        except Exception:  # checked beforehand; undo whatever a surprise left behind
            for nid in reversed(added):
                doc._raw_remove_node(nid)
            raise
        doc.node_state.update(states)
        self._edges = edges

    def undo(self, doc: GraphDocument) -> None:
        for e in reversed(self._edges):
            doc._raw_disconnect(e)
        for nid in reversed(self.new_ids):
            doc._raw_remove_node(nid)
            doc.node_state.pop(nid, None)

    # -- checks ----------------------------------------------------------------
    def _prepare(self, doc: GraphDocument):
        """New instances, edges and node states, every one checked; GraphError otherwise.
        Nothing of ``doc`` changes except its id counters."""
        frag = self.fragment
        reuse = bool(self.id_map) and not any(v in doc.nodes for v in self.id_map.values())
        id_map = dict(self.id_map) if reuse else {}
        counts: dict[str, int] = {}
        scratch = GraphDocument()
        nodes: list[NodeInstance] = []
        dx, dy = self.offset
        for i, n in enumerate(frag["nodes"]):
            where = f"fragment node {i} ({n['id']!r})"
            try:
                cls = node_type(n["type"])
            except KeyError:
                raise GraphError(f"{where}: unknown node type {n['type']!r}", where="type") from None
            counts[n["type"]] = counts.get(n["type"], 0) + 1
            if cls.max_per_graph is not None:
                have = sum(1 for m in doc.nodes.values() if m.type_name == n["type"])
                if have + counts[n["type"]] > cls.max_per_graph:
                    raise GraphError(f"{where}: a graph holds at most {cls.max_per_graph} "
                                     f"{n['type']} node(s); it already has {have}", where="type")
            if not reuse:
                id_map[n["id"]] = _fresh_id(doc, n["type"], set(id_map.values()))
            x, y = (float(v) for v in n["position"])
            node = NodeInstance(id_map[n["id"]], n["type"], copy.deepcopy(n["params"]),
                                (x + dx, y + dy), n.get("label") or "")
            try:
                scratch._raw_add_node(node)  # validates the parameters against the schema
            except GraphError as exc:
                raise GraphError(f"{where}: {exc}", node=n["id"], where=exc.where) from None
            except Exception as exc:  # a node type's own check failing on odd data
                raise GraphError(f"{where}: parameters refused ({type(exc).__name__}: {exc})",
                                 node=n["id"], where="params") from None
            nodes.append(NodeInstance(node.id, node.type_name, node.params, node.position, node.label))
        edges = []
        for i, e in enumerate(frag["edges"]):
            src, dst = e["from"][0], e["to"][0]
            for end in (src, dst):
                if end not in id_map:
                    raise GraphError(f"fragment edge {i}: no node {end!r} in the fragment", where="edges")
            edges.append(Edge(id_map[src], e["from"][1], id_map[dst], e["to"][1]))
        try:
            scratch._raw_connect_all(edges)
        except GraphError as exc:
            raise GraphError(f"fragment edge {exc.index}: {exc}", where="edges") from None
        states = {}
        for old, entry in frag.get("node_state", {}).items():
            if old in id_map and node_type(_type_of(frag, old)).stateful:
                try:
                    parse_state_entry(entry)
                except ValueError:
                    continue  # a malformed stored result is dropped, as on loading a project
                states[id_map[old]] = copy.deepcopy(entry)
        self.id_map = id_map
        self.new_ids = [id_map[n["id"]] for n in frag["nodes"]]
        return nodes, edges, states


def _fresh_id(doc: GraphDocument, type_name: str, taken: set[str]) -> str:
    while True:
        nid = doc.new_id(type_name)
        if nid not in taken:
            return nid


def _type_of(fragment: dict, node_id: str) -> str:
    return next(n["type"] for n in fragment["nodes"] if n["id"] == node_id)


def _check_structure(data: Any) -> None:
    """GraphError unless ``data`` has a fragment's shape (values JSON can keep)."""
    def bad(where: str, expected: str) -> GraphError:
        return GraphError(f"not a Mesoforge fragment: {where}: expected {expected}", where=where)

    if not isinstance(data, dict):
        raise bad("top level", "a JSON object")
    if data.get("format") != FRAGMENT_FORMAT:
        raise bad("format", repr(FRAGMENT_FORMAT))
    version = data.get("version")
    if not isinstance(version, int) or isinstance(version, bool) or not 1 <= version <= FRAGMENT_VERSION:
        raise bad("version", f"an integer from 1 to {FRAGMENT_VERSION}, got {version!r:.40}")
    try:
        check_json_values(data)
    except InvalidProject as exc:
        raise GraphError(f"not a Mesoforge fragment: {exc}", where=exc.where) from None
    nodes, edges = data.get("nodes"), data.get("edges", [])
    if not isinstance(nodes, list):
        raise bad("nodes", "a list")
    seen = set()
    for i, n in enumerate(nodes):
        where = f"nodes[{i}]"
        if not isinstance(n, dict) or not isinstance(n.get("id"), str) or not isinstance(n.get("type"), str):
            raise bad(where, 'an object with "id" and "type" strings')
        if n["id"] in seen:
            raise bad(f"{where}.id", f"an id not used before, got {n['id']!r} again")
        seen.add(n["id"])
        if not isinstance(n.get("params", {}), dict):
            raise bad(f"{where}.params", "an object")
        n.setdefault("params", {})
        pos = n.get("position", [0.0, 0.0])
        if not (isinstance(pos, list) and len(pos) == 2
                and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in pos)):
            raise bad(f"{where}.position", "[x, y], two numbers")
        n.setdefault("position", [0.0, 0.0])
        if not isinstance(n.get("label", ""), (str, type(None))):
            raise bad(f"{where}.label", "a string")
    if not isinstance(edges, list):
        raise bad("edges", "a list")
    for i, e in enumerate(edges):
        ok = (isinstance(e, dict) and isinstance(e.get("from"), list) and isinstance(e.get("to"), list)
              and len(e["from"]) == 2 and len(e["to"]) == 2
              and all(isinstance(v, str) for v in e["from"] + e["to"]))
        if not ok:
            raise bad(f"edges[{i}]", '{"from": [node, port], "to": [node, port]}')
    data.setdefault("edges", edges)
    if not isinstance(data.get("node_state", {}), dict):
        raise bad("node_state", "an object")
