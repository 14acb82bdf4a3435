"""Copy / paste / duplicate of nodes in the node editor.

The copied nodes go on the system clipboard as JSON text (an
`engine.graph.clipboard` fragment, marked by its ``format``), so they paste
into another Mesoforge window too; pasting is one `PasteFragment` undo step and
selects the pasted nodes. Pasted at the mouse when it is over the graph (or at
the context menu's point), else shifted from where they were copied.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Callable

from PySide6 import QtGui, QtWidgets

from engine.graph import GraphError
from engine.graph.clipboard import (FRAGMENT_FORMAT, PasteFragment, fragment_from_text, fragment_of,
                                    fragment_origin, fragment_to_text)

if TYPE_CHECKING:
    from .node_editor import NodeEditor

PASTE_SHIFT = (40.0, 40.0)  # a paste or duplicate away from the mouse lands this far off the original


class NodeClipboard:
    """The editor's copy / paste / duplicate (keys and menu items call these)."""

    def __init__(self, editor: "NodeEditor"):
        self.editor = editor
        # Stateful nodes' stored results: where copies read them (the window's evaluator holds
        # the latest ones; the document's are those of the last save) and who takes a paste's.
        self.state_source: Callable[[], dict] = lambda: editor.doc.node_state
        self.state_sink: Callable[[dict], object] | None = None

    @staticmethod
    def _system() -> QtGui.QClipboard:
        return QtWidgets.QApplication.clipboard()

    def copy(self) -> bool:
        """Put the selected nodes (and the edges among them) on the clipboard."""
        ids = self.editor.selected_ids()
        if not ids:
            self.editor.message.emit("info", "copy: no node selected")
            return False
        self._system().setText(fragment_to_text(self._fragment(ids)))
        self.editor.message.emit("info", f"copied {len(ids)} node{'s' if len(ids) != 1 else ''}")
        return True

    def can_paste(self) -> bool:
        return FRAGMENT_FORMAT in (self._system().text() or "")

    def paste(self, at: tuple[float, float] | None = None) -> list[str]:
        """Paste the clipboard's nodes with their top-left at ``at`` (scene), at the mouse
        when it is over the graph, else shifted from where they were copied; the new ids."""
        text = self._system().text() or ""
        if FRAGMENT_FORMAT not in text:
            self.editor.message.emit("info", "paste: the clipboard holds no Mesoforge nodes")
            return []
        try:
            fragment = fragment_from_text(text)
        except GraphError as exc:
            self.editor.message.emit("error", f"refused: {exc}")
            return []
        return self._paste(fragment, at if at is not None else self._mouse_scene_pos())

    def duplicate(self) -> list[str]:
        """A copy of the selected nodes beside them (the clipboard is left alone)."""
        ids = self.editor.selected_ids()
        if not ids:
            self.editor.message.emit("info", "duplicate: no node selected")
            return []
        return self._paste(self._fragment(ids), None)

    # -- internals -----------------------------------------------------------------
    def _fragment(self, node_ids: list[str]) -> dict:
        return fragment_of(self.editor.doc, node_ids, node_state=self.state_source())

    def _paste(self, fragment: dict, at) -> list[str]:
        if not fragment["nodes"]:
            return []
        ox, oy = fragment_origin(fragment)
        offset = PASTE_SHIFT if at is None else (at[0] - ox, at[1] - oy)
        try:
            cmd = PasteFragment(fragment, offset=offset)
        except GraphError as exc:
            self.editor.message.emit("error", f"refused: {exc}")
            return []
        if not self.editor._push(cmd):
            return []
        doc = self.editor.doc
        pasted = {nid: doc.node_state[nid] for nid in cmd.new_ids if nid in doc.node_state}
        if pasted and self.state_sink is not None:
            for warning in self.state_sink(pasted) or ():
                self.editor.message.emit("warning", warning)
        self.select_many(cmd.new_ids)
        return list(cmd.new_ids)

    def select_many(self, node_ids: list[str]) -> None:
        editor = self.editor
        for node in editor.graph.selected_nodes():
            node.set_property("selected", False, push_undo=False)
        for nid in node_ids:
            node = editor.scene_node(nid)
            if node is not None:
                node.set_property("selected", True, push_undo=False)
        editor._emit_selection()

    def _mouse_scene_pos(self) -> tuple[float, float] | None:
        viewer = self.editor.graph.viewer()
        local = viewer.viewport().mapFromGlobal(QtGui.QCursor.pos())
        if not viewer.viewport().rect().contains(local):
            return None
        p = viewer.mapToScene(local)
        return (p.x(), p.y())

