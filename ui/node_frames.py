"""Frames and subgraphs drawn in the node editor, and their gestures.

A frame is a titled box with a comment behind the nodes (`FrameItem`): drag
its title bar to move it, its bottom-right corner to resize it; each drag is
one undo item (`EditFrame` steps pushed with merge).  A subgraph is drawn as
a box around its member nodes with its name (`SubgraphItem`); dragging its
title moves the members (one "move subgraph" step).  Only the title bars and
the resize corner take the mouse, so a rubber band or a click on a node
inside a frame works as anywhere else.  A collapsed subgraph is one proxy
node with its boundary ports (`ui.subgraph_proxy`).  The items are views of
``doc.annotations``: they are redrawn from the document's events, so undo
and redo show here too.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6 import QtCore, QtGui, QtWidgets

from engine.graph import (AddFrame, EditFrame, GraphError, Macro, MakeSubgraph, MoveNode, RemoveFrame,
                          SetSubgraphCollapsed, Ungroup)

from .frame_items import MARGIN, SUBGRAPH_COLOUR, TITLE_HEIGHT, BoxItem, FrameItem, SubgraphItem
from .subgraph_proxy import ProxyItem, show_members, update_proxy

if TYPE_CHECKING:
    from .node_editor import NodeEditor


class NodeFrames(QtCore.QObject):
    """The frames and subgraph boxes of one `NodeEditor`, and the gestures that edit them.

    Signals
    -------
    current_changed(object) : ("frame", id), ("subgraph", id) or None -- what was last
        clicked, or the subgraph of the selected node.
    picked(object) : ("frame", id) or ("subgraph", id) -- the user clicked its title.
    """

    current_changed = QtCore.Signal(object)
    picked = QtCore.Signal(object)

    def __init__(self, editor: "NodeEditor"):
        super().__init__(editor)
        self.editor = editor
        self.doc = editor.doc
        self.frame_items: dict[str, FrameItem] = {}
        self.subgraph_items: dict[str, SubgraphItem] = {}
        self.proxies: dict[str, ProxyItem] = {}  # collapsed subgraphs (ui.subgraph_proxy)
        self.current: tuple[str, str] | None = None
        self._drag_started = False
        self._drag_moves: dict[str, tuple[float, float]] = {}
        self._drag_origin = QtCore.QPointF()
        self._drag_delta = (0.0, 0.0)
        self.doc.subscribe(self._on_doc_event)
        editor.selection_changed.connect(self._on_node_selected)
        self._build_context_menu()
        self.rebuild()

    def detach(self) -> None:
        self.doc.unsubscribe(self._on_doc_event)

    @property
    def scene(self) -> QtWidgets.QGraphicsScene:
        return self.editor.graph.viewer().scene()

    def _build_context_menu(self) -> None:
        menu = self.editor.graph.get_context_menu("graph")
        menu.add_separator()
        menu.add_command("Add Frame", lambda _g: self.add_frame_around_selection())
        menu.add_command("Remove Frame", lambda _g: self.remove_current_frame())
        menu.add_command("Make Subgraph", lambda _g: self.make_subgraph())
        menu.add_command("Ungroup", lambda _g: self.ungroup())
        menu.add_command("Collapse / Expand Subgraph", lambda _g: self.toggle_collapsed())

    # -- document -> items --------------------------------------------------------
    def _on_doc_event(self, event: str, payload) -> None:
        if event == "annotation_changed":
            kind, item_id = payload
            if kind == "frame":
                self._sync_frame(item_id)
            else:
                self._sync_subgraph(item_id)
        elif event == "reset":
            self.rebuild()
        elif event in ("node_moved", "node_added", "node_removed", "label_changed"):
            nid = payload
            sub = self.doc.annotations.subgraph_of(nid) if event != "node_removed" else None
            if sub is not None:
                self._sync_subgraph(sub.id)
            self._sync_proxies(except_id=sub.id if sub is not None else None)  # their wires to outside nodes
        elif event in ("edge_added", "edge_removed"):
            self._sync_proxies()

    def _sync_proxies(self, except_id: str | None = None) -> None:
        for sid in list(self.proxies):
            if sid != except_id:
                self._sync_subgraph(sid)

    def items(self) -> list[QtWidgets.QGraphicsItem]:
        """The frames, subgraph boxes and collapsed-subgraph nodes drawn (for Fit View)."""
        return [i for group in (self.frame_items, self.subgraph_items, self.proxies)
                for i in group.values() if i.isVisible()]

    def rebuild(self) -> None:
        for fid in list(self.frame_items):
            self._drop(self.frame_items, fid)
        for sid in list(self.subgraph_items):
            self._drop(self.subgraph_items, sid)
        for sid in list(self.proxies):
            self._drop(self.proxies, sid)  # a reset redrew every node shown
        for fid in self.doc.annotations.frames:
            self._sync_frame(fid)
        for sid in self.doc.annotations.subgraphs:
            self._sync_subgraph(sid)
        self._set_current(None)

    def _sync_frame(self, frame_id: str) -> None:
        frame = self.doc.annotations.frames.get(frame_id)
        item = self.frame_items.get(frame_id)
        if frame is None:
            if item is not None:
                self._drop(self.frame_items, frame_id)
            if self.current == ("frame", frame_id):
                self._set_current(None)
            return
        if item is None:
            item = self.frame_items[frame_id] = FrameItem(self, "frame", frame_id)
            self.scene.addItem(item)
        item.title, item.comment = frame.title, frame.comment
        item.colour = QtGui.QColor(*frame.colour)
        item.set_geometry(QtCore.QRectF(*frame.rect))

    def _sync_subgraph(self, subgraph_id: str) -> None:
        sub = self.doc.annotations.subgraphs.get(subgraph_id)
        rect = self.nodes_rect(sub.members) if sub is not None else None
        collapsed = rect is not None and sub.collapsed
        proxy = self.proxies.get(subgraph_id)
        hidden = set(sub.members) if collapsed else set()
        if proxy is not None:
            show_members(self.editor, [m for m in proxy.members if m not in hidden], True)
            if not collapsed:
                self._drop(self.proxies, subgraph_id)
        if collapsed:
            if proxy is None:
                proxy = self.proxies[subgraph_id] = ProxyItem(self, subgraph_id)
                proxy.current = self.current == ("subgraph", subgraph_id)
                self.scene.addItem(proxy)
                self.scene.addItem(proxy.wires)
            show_members(self.editor, sub.members, False)
            proxy.members = tuple(sub.members)
            update_proxy(self.editor, proxy, sub, rect)
        item = self.subgraph_items.get(subgraph_id)
        if rect is None or collapsed:
            if item is not None:
                self._drop(self.subgraph_items, subgraph_id)
            if sub is None and self.current == ("subgraph", subgraph_id):
                self._set_current(None)
            return
        if item is None:
            item = self.subgraph_items[subgraph_id] = SubgraphItem(self, "subgraph", subgraph_id)
            item.colour, item.dashed = QtGui.QColor(*SUBGRAPH_COLOUR), True
            item.current = self.current == ("subgraph", subgraph_id)
            self.scene.addItem(item)
        item.title = f"{sub.name}  ·  {len(sub.members)} nodes"
        item.set_geometry(rect.adjusted(0, -TITLE_HEIGHT, 0, 0))

    def _drop(self, items: dict, item_id: str) -> None:
        item = items.pop(item_id)
        self.scene.removeItem(item)
        wires = getattr(item, "wires", None)
        if wires is not None:
            self.scene.removeItem(wires)

    def nodes_rect(self, node_ids) -> QtCore.QRectF | None:
        """The scene rect around the given nodes' items plus MARGIN (None if none is drawn)."""
        rect = None
        for nid in node_ids:
            node = self.editor.scene_node(nid)
            if node is None:
                continue
            x, y = self.doc.nodes[nid].position
            r = node.view.boundingRect().translated(x, y)
            rect = r if rect is None else rect.united(r)
        return rect.adjusted(-MARGIN, -MARGIN, MARGIN, MARGIN) if rect is not None else None

    # -- current item --------------------------------------------------------------
    def _set_current(self, current) -> None:
        for kind, items in (("frame", self.frame_items), ("subgraph", self.subgraph_items),
                            ("subgraph", self.proxies)):
            for item_id, item in items.items():
                on = current == (kind, item_id)
                if item.current != on:
                    item.current = on
                    item.update()
        if current != self.current:
            self.current = current
            self.current_changed.emit(current)

    def _on_node_selected(self, node_id) -> None:
        sub = self.doc.annotations.subgraph_of(node_id) if node_id else None
        self._set_current(("subgraph", sub.id) if sub is not None else None)

    def select(self, kind: str, item_id: str) -> None:
        """Make a frame or subgraph current (as a click on its title does)."""
        if kind == "subgraph":
            sub = self.doc.annotations.subgraph(item_id)
            self.editor.select(None)
            for nid in sub.members:
                node = self.editor.scene_node(nid)
                if node is not None:
                    node.set_property("selected", True, push_undo=False)
            self.editor._emit_selection()
        else:
            self.editor.select(None)
        self._set_current((kind, item_id))

    # -- gestures -> commands -------------------------------------------------------
    def _push(self, command, merge: bool = False) -> bool:
        try:
            self.editor.undo.push(command, merge=merge)
        except GraphError as exc:
            self.editor.message.emit("error", f"refused: {exc}")
            return False
        return True

    def item_pressed(self, item: BoxItem) -> None:
        self.select(item.kind, item.item_id)
        self.picked.emit((item.kind, item.item_id))
        self._drag_started = False
        self._drag_moves = {}

    def item_dragged(self, item: BoxItem, rect: QtCore.QRectF) -> None:
        if item.kind == "frame":
            r = (rect.x(), rect.y(), rect.width(), rect.height())
            if self._push(EditFrame(item.item_id, rect=r), merge=self._drag_started):
                self._drag_started = True
            return
        # a subgraph: its nodes follow the title; the document hears of it on release
        sub = self.doc.annotations.subgraph(item.item_id)
        if not self._drag_moves:
            self._drag_moves = {nid: self.doc.nodes[nid].position for nid in sub.members}
            self._drag_origin = item.rect.topLeft()
        dx, dy = rect.x() - self._drag_origin.x(), rect.y() - self._drag_origin.y()
        for nid, (x, y) in self._drag_moves.items():
            node = self.editor.scene_node(nid)
            if node is not None:
                node.view.xy_pos = [x + dx, y + dy]
        item.set_geometry(QtCore.QRectF(rect))
        self._drag_delta = (dx, dy)

    def item_released(self, item: BoxItem) -> None:
        if item.kind == "subgraph" and self._drag_moves:
            dx, dy = self._drag_delta
            moves = [MoveNode(nid, (x + dx, y + dy)) for nid, (x, y) in self._drag_moves.items()]
            self._drag_moves = {}
            if not self._push(Macro("move subgraph", moves)):
                for nid in list(self.doc.nodes):
                    self.editor._move_scene_node(nid)
        self._drag_started = False

    def add_frame_around_selection(self, title: str = "Frame", comment: str = "") -> str | None:
        """A frame around the selected nodes (or at the view's centre); returns its id."""
        rect = self.nodes_rect(self.editor.selected_ids())
        if rect is None:
            centre = self.editor.graph.viewer().mapToScene(self.editor.graph.viewer().viewport().rect().center())
            rect = QtCore.QRectF(centre.x() - 150, centre.y() - 100, 300, 200)
        else:
            rect = rect.adjusted(0, -TITLE_HEIGHT, 0, 0)
        cmd = AddFrame((rect.x(), rect.y(), rect.width(), rect.height()), title, comment)
        if self._push(cmd):
            self._set_current(("frame", cmd.frame_id))
            return cmd.frame_id
        return None

    def remove_current_frame(self) -> bool:
        if self.current is None or self.current[0] != "frame":
            self.editor.message.emit("error", "remove frame: no frame selected; click a frame's title first")
            return False
        return self._push(RemoveFrame(self.current[1]))

    def make_subgraph(self, name: str = "Subgraph") -> str | None:
        """Group the selected nodes (Ctrl+G); returns the new subgraph's id."""
        cmd = MakeSubgraph(self.editor.selected_ids(), name)
        if self._push(cmd):
            self._set_current(("subgraph", cmd.subgraph_id))
            return cmd.subgraph_id
        return None

    def ungroup(self) -> bool:
        """Dissolve the current subgraph, or the one the selected node belongs to (Ctrl+Shift+G)."""
        sub_id = self.current_subgraph()
        if sub_id is None:
            self.editor.message.emit("error", "ungroup: no subgraph selected; select a node of one first")
            return False
        return self._push(Ungroup(sub_id))

    def set_collapsed(self, subgraph_id: str, collapsed: bool) -> bool:
        """Collapse a subgraph into one proxy node, or expand it (saved, undoable)."""
        if self.doc.annotations.subgraph(subgraph_id).collapsed == collapsed:
            return True
        return self._push(SetSubgraphCollapsed(subgraph_id, collapsed))

    def toggle_collapsed(self) -> bool:
        sub_id = self.current_subgraph()
        if sub_id is None:
            self.editor.message.emit("error", "collapse: no subgraph selected; select a node of one first")
            return False
        return self.set_collapsed(sub_id, not self.doc.annotations.subgraph(sub_id).collapsed)

    def current_subgraph(self) -> str | None:
        if self.current is not None and self.current[0] == "subgraph":
            return self.current[1]
        for nid in self.editor.selected_ids():
            sub = self.doc.annotations.subgraph_of(nid)
            if sub is not None:
                return sub.id
        return None
