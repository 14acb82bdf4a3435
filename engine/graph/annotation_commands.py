"""Undoable edits of a document's frames and subgraphs (`engine.graph.annotations`).

Each is a `Command` pushed on the document's `UndoStack` like the node
commands: ``do`` refuses (GraphError naming what was wrong, nothing changed)
or changes the document; ``undo`` puts it back.  Dragging or resizing a frame
pushes `EditFrame` with ``merge=True`` and the steps merge into one undo item
as node moves do.  `SetSubgraphParam` is a `SetParam` of the inner node: the
same validation, refusal, evaluation and merging.
"""

from __future__ import annotations

from typing import Any, Sequence

from .annotations import FRAME_COLOUR, ExposedParam, Frame, Subgraph
from .commands import Command, SetParam
from .document import GraphDocument
from .errors import GraphError


class AddFrame(Command):
    """A new frame; ``frame_id`` is chosen on first ``do`` when not given.

    rect : (x, y, width, height) in editor scene coordinates.
    """

    def __init__(self, rect, title: str = "Frame", comment: str = "", colour=FRAME_COLOUR,
                 frame_id: str | None = None):
        self.rect = tuple(rect)
        self.title, self.comment, self.colour = title, comment, tuple(colour)
        self.frame_id = frame_id
        self.text = f"add frame {title!r}"

    def do(self, doc: GraphDocument) -> None:
        frame_id = self.frame_id or doc.annotations.new_id("frame")
        doc.annotations._raw_add_frame(Frame(frame_id, self.title, self.comment, self.rect, self.colour))
        self.frame_id = frame_id  # only once accepted: a refused command names no frame

    def undo(self, doc: GraphDocument) -> None:
        doc.annotations._raw_remove_frame(self.frame_id)


class RemoveFrame(Command):
    def __init__(self, frame_id: str):
        self.frame_id = frame_id
        self.text = f"remove frame {frame_id}"
        self._frame: Frame | None = None
        self._index = 0

    def do(self, doc):
        self._frame, self._index = doc.annotations._raw_remove_frame(self.frame_id)

    def undo(self, doc):
        doc.annotations._raw_add_frame(self._frame, self._index)


class EditFrame(Command):
    """Changes some of a frame's title, comment, rect, colour.  Successive edits of
    the same frame (a drag, a resize) merge into one undo item when pushed with merge=True."""

    def __init__(self, frame_id: str, **changes: Any):
        self.frame_id = frame_id
        self.changes = {k: (tuple(v) if isinstance(v, list) else v) for k, v in changes.items()}
        what = "move" if set(changes) == {"rect"} else "edit"
        self.text = f"{what} frame {frame_id}"
        self._old: Frame | None = None

    def do(self, doc):
        self._old = doc.annotations._raw_update_frame(self.frame_id, **self.changes)

    def undo(self, doc):
        old = self._old
        doc.annotations._raw_update_frame(self.frame_id, title=old.title, comment=old.comment, rect=old.rect,
                                          colour=old.colour)

    def merge_with(self, other):
        if isinstance(other, EditFrame) and other.frame_id == self.frame_id and set(other.changes) <= {"rect"} \
                and set(self.changes) <= {"rect"}:
            self.changes.update(other.changes)
            return True
        return False


class MakeSubgraph(Command):
    """Groups `node_ids` into a new subgraph; refused when one is missing or already grouped."""

    def __init__(self, node_ids: Sequence[str], name: str = "Subgraph", subgraph_id: str | None = None,
                 exposed: Sequence[ExposedParam] = ()):
        self.node_ids = tuple(dict.fromkeys(node_ids))
        self.name = name
        self.subgraph_id = subgraph_id
        self.exposed = tuple(exposed)
        self.text = f"make subgraph {name!r}"

    def do(self, doc):
        if not self.node_ids:
            raise GraphError("make subgraph: no nodes selected; select the nodes to group first",
                             where="members")
        subgraph_id = self.subgraph_id or doc.annotations.new_id("subgraph")
        doc.annotations._raw_add_subgraph(Subgraph(subgraph_id, self.name, self.node_ids, self.exposed))
        self.subgraph_id = subgraph_id

    def undo(self, doc):
        doc.annotations._raw_remove_subgraph(self.subgraph_id)


class Ungroup(Command):
    """Dissolves a subgraph; its nodes stay where they are."""

    def __init__(self, subgraph_id: str):
        self.subgraph_id = subgraph_id
        self.text = f"ungroup {subgraph_id}"
        self._sub: Subgraph | None = None
        self._index = 0

    def do(self, doc):
        self._sub, self._index = doc.annotations._raw_remove_subgraph(self.subgraph_id)

    def undo(self, doc):
        doc.annotations._raw_add_subgraph(self._sub, self._index)


class _SubgraphEdit(Command):
    """Replaces fields of one subgraph; undo puts the old subgraph back."""

    def __init__(self, subgraph_id: str):
        self.subgraph_id = subgraph_id
        self._old: Subgraph | None = None

    def changes(self, sub: Subgraph) -> dict[str, Any]:  # pragma: no cover - overridden
        raise NotImplementedError

    def do(self, doc):
        sub = doc.annotations.subgraph(self.subgraph_id)
        self._old = doc.annotations._raw_update_subgraph(self.subgraph_id, **self.changes(sub))

    def undo(self, doc):
        old = self._old
        doc.annotations._raw_update_subgraph(self.subgraph_id, name=old.name, members=old.members,
                                             exposed=old.exposed, collapsed=old.collapsed)


class RenameSubgraph(_SubgraphEdit):
    def __init__(self, subgraph_id: str, name: str):
        super().__init__(subgraph_id)
        self.name = name
        self.text = f"rename subgraph {subgraph_id}"

    def changes(self, sub):
        return {"name": self.name}


class SetSubgraphCollapsed(_SubgraphEdit):
    def __init__(self, subgraph_id: str, collapsed: bool):
        super().__init__(subgraph_id)
        self.collapsed = bool(collapsed)
        self.text = f"{'collapse' if collapsed else 'expand'} subgraph {subgraph_id}"

    def changes(self, sub):
        return {"collapsed": self.collapsed}


class ExposeParam(_SubgraphEdit):
    """Shows a member's parameter on the subgraph (appended, or at `index`)."""

    def __init__(self, subgraph_id: str, node_id: str, param: str, label: str = "", index: int | None = None):
        super().__init__(subgraph_id)
        self.entry = ExposedParam(node_id, param, label)
        self.index = index
        self.text = f"expose {node_id}.{param}"

    def changes(self, sub):
        exposed = list(sub.exposed)
        exposed.insert(len(exposed) if self.index is None else self.index, self.entry)
        return {"exposed": tuple(exposed)}


class UnexposeParam(_SubgraphEdit):
    def __init__(self, subgraph_id: str, node_id: str, param: str):
        super().__init__(subgraph_id)
        self.node_id, self.param = node_id, param
        self.text = f"unexpose {node_id}.{param}"

    def changes(self, sub):
        kept = tuple(e for e in sub.exposed if (e.node_id, e.param) != (self.node_id, self.param))
        if len(kept) == len(sub.exposed):
            raise GraphError(f"subgraph {sub.id!r} does not expose {self.node_id}.{self.param}", where="exposed")
        return {"exposed": kept}


class SetSubgraphParam(SetParam):
    """Sets an exposed parameter of a subgraph: a `SetParam` of the inner node
    (same validation, refusal message, evaluation and merging), refused when
    the subgraph does not expose it."""

    def __init__(self, subgraph_id: str, node_id: str, name: str, value: Any):
        super().__init__(node_id, name, value)
        self.subgraph_id = subgraph_id

    def do(self, doc):
        sub = doc.annotations.subgraph(self.subgraph_id)
        if not any((e.node_id, e.param) == (self.node_id, self.name) for e in sub.exposed):
            raise GraphError(f"subgraph {sub.id!r} does not expose {self.node_id}.{self.name}",
                             node=self.node_id, where=self.name)
        super().do(doc)
