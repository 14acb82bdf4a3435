"""Undoable edits of a GraphDocument and the undo stack.

Every user gesture becomes one command (or one macro of commands) pushed on
the `UndoStack`; ``push`` executes it and refuses, changing nothing, when the
document refuses.  Works without any window.
"""

from __future__ import annotations

from typing import Any, Callable

from .document import Edge, GraphDocument, NodeInstance


class Command:
    text = "edit"

    def do(self, doc: GraphDocument) -> None:
        raise NotImplementedError

    def undo(self, doc: GraphDocument) -> None:
        raise NotImplementedError

    def merge_with(self, other: "Command") -> bool:
        """Absorb `other` (a following command) into this one; True if merged."""
        return False


class AddNode(Command):
    def __init__(self, type_name: str, params: dict | None = None, position=(0.0, 0.0),
                 node_id: str | None = None, label: str = ""):
        self.type_name = type_name
        self.params = dict(params or {})
        self.position = tuple(position)
        self.node_id = node_id
        self.label = label
        self.text = f"add {type_name}"

    def do(self, doc):
        if self.node_id is None:
            self.node_id = doc.new_id(self.type_name)
        doc._raw_add_node(NodeInstance(self.node_id, self.type_name, dict(self.params), self.position, self.label))

    def undo(self, doc):
        doc._raw_remove_node(self.node_id)


class RemoveNode(Command):
    """Removes a node and every edge touching it; undo restores both in place."""

    def __init__(self, node_id: str):
        self.node_id = node_id
        self.text = f"remove {node_id}"
        self._edges: list[tuple[int, Edge]] = []
        self._node: NodeInstance | None = None
        self._index = 0

    def do(self, doc):
        doc.node(self.node_id)
        self._edges = [(i, e) for i, e in enumerate(doc.edges) if self.node_id in (e.src, e.dst)]
        for _, e in reversed(self._edges):
            doc._raw_disconnect(e)
        self._node, self._index = doc._raw_remove_node(self.node_id)

    def undo(self, doc):
        doc._raw_add_node(self._node, self._index)
        for i, e in self._edges:
            doc._raw_connect(e, i)


class Connect(Command):
    def __init__(self, src: str, src_port: str, dst: str, dst_port: str):
        self.edge = Edge(src, src_port, dst, dst_port)
        self.text = f"connect {src}.{src_port} -> {dst}.{dst_port}"

    def do(self, doc):
        doc._raw_connect(self.edge)

    def undo(self, doc):
        doc._raw_disconnect(self.edge)


class Disconnect(Command):
    def __init__(self, src: str, src_port: str, dst: str, dst_port: str):
        self.edge = Edge(src, src_port, dst, dst_port)
        self.text = f"disconnect {src}.{src_port} -> {dst}.{dst_port}"
        self._index = 0

    def do(self, doc):
        self._index = doc._raw_disconnect(self.edge)

    def undo(self, doc):
        doc._raw_connect(self.edge, self._index)


class SetParam(Command):
    """Sets one parameter.  Successive sets of the same parameter while
    dragging a slider merge into one undo item when pushed with merge=True."""

    def __init__(self, node_id: str, name: str, value: Any):
        self.node_id, self.name, self.value = node_id, name, value
        self.text = f"set {node_id}.{name}"
        self._old: Any = None

    def do(self, doc):
        self._old = doc._raw_set_param(self.node_id, self.name, self.value)

    def undo(self, doc):
        doc._raw_set_param(self.node_id, self.name, self._old)

    def merge_with(self, other):
        if isinstance(other, SetParam) and (other.node_id, other.name) == (self.node_id, self.name):
            self.value = other.value
            return True
        return False


class MoveNode(Command):
    def __init__(self, node_id: str, position):
        self.node_id, self.position = node_id, tuple(position)
        self.text = f"move {node_id}"
        self._old = (0.0, 0.0)

    def do(self, doc):
        self._old = doc._raw_move(self.node_id, self.position)

    def undo(self, doc):
        doc._raw_move(self.node_id, self._old)

    def merge_with(self, other):
        if isinstance(other, MoveNode) and other.node_id == self.node_id:
            self.position = other.position
            return True
        return False


class SetLabel(Command):
    def __init__(self, node_id: str, label: str):
        self.node_id, self.label = node_id, label
        self.text = f"rename {node_id}"
        self._old = ""

    def do(self, doc):
        self._old = doc._raw_set_label(self.node_id, self.label)

    def undo(self, doc):
        doc._raw_set_label(self.node_id, self._old)


class SetSeed(Command):
    def __init__(self, seed: int):
        self.seed = int(seed)
        self.text = "set seed"
        self._old = 0

    def do(self, doc):
        self._old = doc._raw_set_seed(self.seed)

    def undo(self, doc):
        doc._raw_set_seed(self._old)


class Macro(Command):
    """Several commands as one undo item; all or nothing."""

    def __init__(self, text: str, commands: list[Command]):
        self.text = text
        self.commands = list(commands)

    def do(self, doc):
        done = []
        try:
            for c in self.commands:
                c.do(doc)
                done.append(c)
        except Exception:
            for c in reversed(done):
                c.undo(doc)
            raise

    def undo(self, doc):
        for c in reversed(self.commands):
            c.undo(doc)


class UndoStack:
    """Linear undo history with a clean mark (for "unsaved changes")."""

    def __init__(self, doc: GraphDocument, limit: int = 1000):
        self.doc = doc
        self.limit = limit
        self._done: list[Command] = []
        self._undone: list[Command] = []
        self._clean_index: int | None = 0
        self._listeners: list[Callable[[], None]] = []

    def subscribe(self, cb: Callable[[], None]) -> None:
        self._listeners.append(cb)

    def _changed(self) -> None:
        for cb in list(self._listeners):
            cb()

    def push(self, command: Command, *, merge: bool = False) -> Command:
        """Execute `command` and record it.  Raises (changing nothing) if refused."""
        command.do(self.doc)
        n = len(self._done)
        if self._clean_index is not None and self._clean_index > n:
            self._clean_index = None  # the saved state lived in the redo branch we drop
        if not (merge and n and self._clean_index != n and self._done[-1].merge_with(command)):
            self._done.append(command)
            if len(self._done) > self.limit:
                self._done.pop(0)
                if self._clean_index is not None:
                    self._clean_index = self._clean_index - 1 if self._clean_index > 0 else None
        self._undone.clear()
        self._changed()
        return command

    def undo(self) -> bool:
        if not self._done:
            return False
        c = self._done.pop()
        c.undo(self.doc)
        self._undone.append(c)
        self._changed()
        return True

    def redo(self) -> bool:
        if not self._undone:
            return False
        c = self._undone.pop()
        c.do(self.doc)
        self._done.append(c)
        self._changed()
        return True

    @property
    def can_undo(self) -> bool:
        return bool(self._done)

    @property
    def can_redo(self) -> bool:
        return bool(self._undone)

    def undo_text(self) -> str:
        return self._done[-1].text if self._done else ""

    def redo_text(self) -> str:
        return self._undone[-1].text if self._undone else ""

    def set_clean(self) -> None:
        self._clean_index = len(self._done)
        self._changed()

    @property
    def is_clean(self) -> bool:
        return self._clean_index == len(self._done)

    def clear(self) -> None:
        self._done.clear()
        self._undone.clear()
        self._clean_index = 0
        self._changed()
