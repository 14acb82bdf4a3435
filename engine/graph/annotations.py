"""Frames (titled comment boxes) and subgraphs (named groups of nodes with
exposed parameters) of a graph document.

Plain data beside the nodes: evaluation never reads them (a subgraph's
members are ordinary nodes of the document).  `Annotations` is held by the
document as ``doc.annotations``; the undoable commands in
`engine.graph.annotation_commands` call its ``_raw_*`` mutators, which check
first and change nothing when they refuse, and emit
``("annotation_changed", (kind, id))`` through the document (kind is
"frame" or "subgraph") so views update.

A node removed from the document leaves its subgraph (and the exposed
parameters of it); the removal is remembered on the removed `NodeInstance`,
so adding that same instance back (undoing the removal) restores the
membership and the exposures in place.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

from .errors import GraphError
from .node import node_type

if TYPE_CHECKING:
    from .document import GraphDocument, NodeInstance

FRAME_COLOUR = (70, 90, 120)
_ID_RE = re.compile(r"^[A-Za-z_][A-Za-z0-9_\-]*$")
_MEMBERSHIP = "_annotation_membership"  # attribute a removed NodeInstance keeps its membership in


@dataclass(frozen=True)
class Frame:
    """A titled box with a comment, drawn behind nodes.

    rect : (x, y, width, height), scene coordinates of the node editor; width, height > 0.
    colour : (r, g, b), each 0..255.
    """

    id: str
    title: str = "Frame"
    comment: str = ""
    rect: tuple[float, float, float, float] = (0.0, 0.0, 300.0, 200.0)
    colour: tuple[int, int, int] = FRAME_COLOUR


@dataclass(frozen=True)
class ExposedParam:
    """A member node's parameter shown (under `label`) on its subgraph."""

    node_id: str
    param: str
    label: str = ""


@dataclass(frozen=True)
class Subgraph:
    """A named group of nodes with the parameters it exposes.

    members : node ids, in the order they were grouped; a node is a member of at most one subgraph.
    exposed : parameters of members shown on the subgraph, in order.
    collapsed : drawn as one node with its boundary ports (editor only).
    """

    id: str
    name: str = "Subgraph"
    members: tuple[str, ...] = ()
    exposed: tuple[ExposedParam, ...] = ()
    collapsed: bool = False


def check_frame(frame: Frame) -> Frame:
    """`frame` with its fields normalised; GraphError naming the field otherwise."""
    _check_id(frame.id, "frame")
    if not isinstance(frame.title, str):
        raise GraphError(f"frame {frame.id!r}: title {frame.title!r} is not text", where="title")
    if not isinstance(frame.comment, str):
        raise GraphError(f"frame {frame.id!r}: comment {frame.comment!r} is not text", where="comment")
    rect = tuple(frame.rect) if isinstance(frame.rect, (list, tuple)) else ()
    if len(rect) != 4 or not all(_finite(v) for v in rect) or not (rect[2] > 0 and rect[3] > 0):
        raise GraphError(f"frame {frame.id!r}: rect {frame.rect!r} is invalid: expected [x, y, width, height], "
                         f"four finite numbers with width > 0 and height > 0", where="rect")
    colour = tuple(frame.colour) if isinstance(frame.colour, (list, tuple)) else ()
    if len(colour) != 3 or not all(isinstance(c, int) and not isinstance(c, bool) and 0 <= c <= 255
                                   for c in colour):
        raise GraphError(f"frame {frame.id!r}: colour {frame.colour!r} is invalid: expected [r, g, b], "
                         f"three integers in [0, 255]", where="colour")
    return replace(frame, rect=tuple(float(v) for v in rect), colour=colour)


def _finite(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _check_id(value: Any, kind: str) -> None:
    if not isinstance(value, str) or not _ID_RE.match(value):
        raise GraphError(f"{kind} id {value!r} is not a valid identifier", where="id")


class Annotations:
    """The frames and subgraphs of one document, in insertion order."""

    def __init__(self, doc: "GraphDocument"):
        self.doc = doc
        self.frames: dict[str, Frame] = {}
        self.subgraphs: dict[str, Subgraph] = {}

    def __bool__(self) -> bool:
        return bool(self.frames or self.subgraphs)

    # -- queries ------------------------------------------------------------
    def frame(self, frame_id: str) -> Frame:
        try:
            return self.frames[frame_id]
        except KeyError:
            raise GraphError(f"no frame with id {frame_id!r}", where="frame") from None

    def subgraph(self, subgraph_id: str) -> Subgraph:
        try:
            return self.subgraphs[subgraph_id]
        except KeyError:
            raise GraphError(f"no subgraph with id {subgraph_id!r}", where="subgraph") from None

    def subgraph_of(self, node_id: str) -> Subgraph | None:
        """The subgraph `node_id` belongs to, or None."""
        for sub in self.subgraphs.values():
            if node_id in sub.members:
                return sub
        return None

    def new_id(self, kind: str) -> str:
        """A free id, ``frame1`` / ``sub1`` ... (asking changes nothing)."""
        prefix = "frame" if kind == "frame" else "sub"
        taken = self.frames if kind == "frame" else self.subgraphs
        k = len(taken) + 1
        while f"{prefix}{k}" in taken:
            k += 1
        return f"{prefix}{k}"

    # -- raw mutators (commands call these) ----------------------------------
    def _raw_add_frame(self, frame: Frame, index: int | None = None) -> None:
        frame = check_frame(frame)
        if frame.id in self.frames:
            raise GraphError(f"a frame with id {frame.id!r} already exists", where="id")
        self.frames = _inserted(self.frames, frame.id, frame, index)
        self._emit("frame", frame.id)

    def _raw_remove_frame(self, frame_id: str) -> tuple[Frame, int]:
        frame = self.frame(frame_id)
        index = list(self.frames).index(frame_id)
        del self.frames[frame_id]
        self._emit("frame", frame_id)
        return frame, index

    def _raw_update_frame(self, frame_id: str, **changes: Any) -> Frame:
        """Change some fields of a frame; returns the frame as it was."""
        old = self.frame(frame_id)
        unknown = set(changes) - {"title", "comment", "rect", "colour"}
        if unknown:
            raise GraphError(f"frame {frame_id!r}: no field(s) {sorted(unknown)}; "
                             f"expected title, comment, rect or colour", where=sorted(unknown)[0])
        self.frames[frame_id] = check_frame(replace(old, **changes))
        self._emit("frame", frame_id)
        return old

    def _raw_add_subgraph(self, sub: Subgraph, index: int | None = None) -> None:
        sub = self.check_subgraph(sub)
        if sub.id in self.subgraphs:
            raise GraphError(f"a subgraph with id {sub.id!r} already exists", where="id")
        self.subgraphs = _inserted(self.subgraphs, sub.id, sub, index)
        self._emit("subgraph", sub.id)

    def _raw_remove_subgraph(self, subgraph_id: str) -> tuple[Subgraph, int]:
        sub = self.subgraph(subgraph_id)
        index = list(self.subgraphs).index(subgraph_id)
        del self.subgraphs[subgraph_id]
        self._emit("subgraph", subgraph_id)
        return sub, index

    def _raw_update_subgraph(self, subgraph_id: str, **changes: Any) -> Subgraph:
        """Replace fields of a subgraph (name, members, exposed, collapsed); returns the old one."""
        old = self.subgraph(subgraph_id)
        unknown = set(changes) - {"name", "members", "exposed", "collapsed"}
        if unknown:
            raise GraphError(f"subgraph {subgraph_id!r}: no field(s) {sorted(unknown)}", where=sorted(unknown)[0])
        self.subgraphs[subgraph_id] = self.check_subgraph(replace(old, **changes))
        self._emit("subgraph", subgraph_id)
        return old

    def check_subgraph(self, sub: Subgraph) -> Subgraph:
        """`sub` normalised; GraphError naming the field when its members or exposed
        parameters do not exist or a member already belongs to another subgraph."""
        _check_id(sub.id, "subgraph")
        if not isinstance(sub.name, str) or not sub.name.strip():
            raise GraphError(f"subgraph {sub.id!r}: name {sub.name!r} is invalid: expected non-empty text",
                             where="name")
        if not isinstance(sub.collapsed, bool):
            raise GraphError(f"subgraph {sub.id!r}: collapsed {sub.collapsed!r} is not true or false",
                             where="collapsed")
        members = tuple(sub.members)
        for nid in members:
            if nid not in self.doc.nodes:
                raise GraphError(f"subgraph {sub.id!r}: no node with id {nid!r}", node=nid, where="members")
            other = self.subgraph_of(nid)
            if other is not None and other.id != sub.id:
                raise GraphError(f"node {nid!r} already belongs to subgraph {other.id!r} ({other.name})",
                                 node=nid, where="members")
        if len(set(members)) != len(members):
            raise GraphError(f"subgraph {sub.id!r}: a node is listed twice in {list(members)}", where="members")
        exposed = tuple(sub.exposed)
        seen = set()
        for e in exposed:
            if e.node_id not in members:
                raise GraphError(f"subgraph {sub.id!r}: exposed parameter {e.node_id}.{e.param}: "
                                 f"node {e.node_id!r} is not a member", node=e.node_id, where="exposed")
            names = [p.name for p in node_type(self.doc.nodes[e.node_id].type_name).params]
            if e.param not in names:
                raise GraphError(f"subgraph {sub.id!r}: node {e.node_id!r} has no parameter {e.param!r} "
                                 f"(it has {names})", node=e.node_id, where="exposed")
            if not isinstance(e.label, str):
                raise GraphError(f"subgraph {sub.id!r}: label {e.label!r} of {e.node_id}.{e.param} is not text",
                                 where="exposed")
            if (e.node_id, e.param) in seen:
                raise GraphError(f"subgraph {sub.id!r}: {e.node_id}.{e.param} is exposed twice", where="exposed")
            seen.add((e.node_id, e.param))
        return replace(sub, members=members, exposed=exposed)

    # -- membership of removed nodes (the document calls these) ----------------
    def _node_removed(self, node: "NodeInstance") -> None:
        """Take a removed node out of its subgraph; remember where on the instance."""
        sub = self.subgraph_of(node.id)
        if sub is None:
            return
        member_at = sub.members.index(node.id)
        exposed_at = [(i, e) for i, e in enumerate(sub.exposed) if e.node_id == node.id]
        setattr(node, _MEMBERSHIP, (sub.id, member_at, exposed_at))
        self.subgraphs[sub.id] = replace(
            sub, members=tuple(m for m in sub.members if m != node.id),
            exposed=tuple(e for e in sub.exposed if e.node_id != node.id))
        self._emit("subgraph", sub.id)

    def _node_restored(self, node: "NodeInstance") -> None:
        """Put a node added back (undo of its removal) into the subgraph it left."""
        record = node.__dict__.pop(_MEMBERSHIP, None)
        if record is None:
            return
        sub_id, member_at, exposed_at = record
        sub = self.subgraphs.get(sub_id)
        if sub is None or self.subgraph_of(node.id) is not None:
            return  # the subgraph went since (or the node is grouped anew): nothing to restore into
        members = list(sub.members)
        members.insert(member_at, node.id)
        exposed = list(sub.exposed)
        for i, e in exposed_at:
            exposed.insert(i, e)
        self.subgraphs[sub_id] = replace(sub, members=tuple(members), exposed=tuple(exposed))
        self._emit("subgraph", sub_id)

    def _emit(self, kind: str, item_id: str) -> None:
        self.doc.emit("annotation_changed", (kind, item_id))


def boundary_ports(doc: "GraphDocument", members) -> tuple[list[tuple[str, str]], list[tuple[str, str]]]:
    """The ports of `members` that edges cross: ([(node, input port)], [(node, output port)]),
    each once, in edge order -- what a collapsed subgraph shows as its own ports."""
    inside = set(members)
    inputs = list(dict.fromkeys((e.dst, e.dst_port) for e in doc.edges if e.dst in inside and e.src not in inside))
    outputs = list(dict.fromkeys((e.src, e.src_port) for e in doc.edges if e.src in inside and e.dst not in inside))
    return inputs, outputs


def _inserted(items: dict, key: str, value: Any, index: int | None) -> dict:
    if index is None or index >= len(items):
        items[key] = value
        return items
    pairs = list(items.items())
    pairs.insert(index, (key, value))
    return dict(pairs)


__all__ = ["Annotations", "ExposedParam", "FRAME_COLOUR", "Frame", "Subgraph", "boundary_ports", "check_frame"]
