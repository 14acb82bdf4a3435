"""The node editor: a NodeGraphQt scene that is a *view* of a GraphDocument.

The document is the source of truth.  User gestures in the scene (create a
node from the tab search or the context menu, connect, disconnect, slice,
move, delete, rename) are translated into engine commands pushed on the
`UndoStack`; the scene is then brought in line with the document from its
events.  NodeGraphQt draws some changes before telling us (a dragged pipe is
already detached, a moved node already sits at its new place); after every
gesture `sync_edges` reconciles the scene with the document, which also
reverts whatever the engine refused.  NodeGraphQt's own undo stack is never
used.  The NodeGraphQt classes (node items, the gesture-forwarding graph)
live in `ui.node_scene`, the "Arrange nodes" layout in `ui.node_layout`; Tab search
in `ui.node_search`, copy / paste in `ui.node_clipboard`, minimap and hint in `ui.node_minimap`.
"""

from __future__ import annotations

from typing import Any

from NodeGraphQt import BaseNode
from NodeGraphQt.base.commands import PortConnectedCmd, PortDisconnectedCmd
from NodeGraphQt.constants import PortTypeEnum
from PySide6 import QtCore, QtWidgets

from engine.graph import (AddNode, Connect, Disconnect, Edge, GraphDocument, GraphError, Macro, MoveNode,
                          RemoveNode, SetLabel, UndoStack, all_node_types)

from .colours import family_shade
from .node_layout import arrange_positions
from .node_clipboard import NodeClipboard
from .node_frames import NodeFrames
from .node_minimap import NodeMinimap
from .node_scene import DocumentNodeGraph, make_node_classes
from .node_search import NodeSearch
from .rich_text import doc_to_html

FAMILY_ORDER = ("topology", "skeleton", "transform", "solid", "property")

class NodeEditor(QtWidgets.QWidget):
    """Node editor widget over a document and its undo stack.

    Signals
    -------
    selection_changed(object) : the selected engine node id, or None.
    message(str, str) : (level, text) for the log; level is "info" or "error".
    """

    selection_changed = QtCore.Signal(object)
    message = QtCore.Signal(str, str)

    def __init__(self, doc: GraphDocument, undo: UndoStack, parent=None):
        super().__init__(parent)
        self.doc = doc
        self.undo = undo
        self.menu_scene_pos: tuple[float, float] | None = None
        self._node_classes = make_node_classes()
        self._engine_type_of = {cls.type_: name for name, cls in self._node_classes.items()}
        self._by_id: dict[str, BaseNode] = {}   # engine id -> scene node
        self._id_of: dict[str, str] = {}        # scene node id -> engine id
        self._statuses: dict[str, Any] = {}
        self.scene_rebuilds = 0                  # whole-scene rebuilds (a document reset), for tests
        self._selected: str | None = None

        self.graph = DocumentNodeGraph(self)
        self.graph.set_background_color(34, 36, 40)
        self.graph.set_grid_color(48, 51, 56)
        self.graph.set_acyclic(True)
        self.graph.register_nodes(list(self._node_classes.values()))
        self._disable_own_undo()
        self._build_context_menu()
        self.graph.node_selection_changed.connect(self._on_selection_changed)
        self.graph.node_selected.connect(lambda _n: self._on_selection_changed([], []))

        layout = QtWidgets.QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.graph.widget)

        # Tab opens node search.  An event filter on the viewer rather than a QShortcut
        # child of NodeGraphQt's widget: destroying that shortcut's wrapper with the
        # window crashed PySide 6.11 now and then (Shiboken releaseWrapper, seen in the
        # window tests); the filter is removed in detach(), before the window goes.
        self._tab_target = self.graph.viewer()
        self._tab_target.installEventFilter(self)

        doc.subscribe(self._on_doc_event)
        self.rebuild()
        self.frames = NodeFrames(self)  # frames and subgraph boxes (ui.node_frames)
        self.search = NodeSearch(self)  # Tab: search-to-add (ui.node_search)
        self.clipboard = NodeClipboard(self)  # copy / paste / duplicate (ui.node_clipboard)
        self.minimap = NodeMinimap(self)  # minimap and empty-editor hint (ui.node_minimap)

    # -- setup ------------------------------------------------------------
    def _disable_own_undo(self) -> None:
        # NodeGraphQt binds Ctrl+Z to its private QUndoStack inside the viewer;
        # that would shadow the window's (engine) undo, so those actions go.
        viewer = self.graph.viewer()
        for name in ("_undo_action", "_redo_action"):
            action = getattr(viewer, name, None)
            if action is not None:
                action.setShortcuts([])
                action.setEnabled(False)
                action.setVisible(False)

    def _build_context_menu(self) -> None:
        menu = self.graph.get_context_menu("graph")
        add = menu.add_menu("Add node")
        types = all_node_types()
        for family in FAMILY_ORDER:
            names = [n for n, c in types.items() if c.family == family]
            if not names:
                continue
            sub = add.add_menu(family.capitalize())
            for name in sorted(names, key=lambda n: types[n].title or n):
                sub.add_command(types[name].title or name,
                                lambda _graph, _name=name: self.create_node(_name, self.menu_scene_pos))
        menu.add_separator()
        menu.add_command("Copy", lambda _graph: self.clipboard.copy())
        menu.add_command("Paste", lambda _graph: self.clipboard.paste(self.menu_scene_pos))
        menu.add_command("Duplicate", lambda _graph: self.clipboard.duplicate())
        menu.add_command("Delete selected", lambda _graph: self.delete_selected())
        menu.add_command("Arrange nodes", lambda _graph: self.arrange_nodes())
        menu.add_command("Fit view", lambda _graph: self.fit_view())

    def detach(self) -> None:
        """Stop listening to the document and to Tab (window closing)."""
        self.doc.unsubscribe(self._on_doc_event)
        self.frames.detach()
        self.minimap.detach()
        self.search.detach()
        if self._tab_target is not None:
            self._tab_target.removeEventFilter(self)
            self._tab_target = None

    def eventFilter(self, watched, event) -> bool:
        """Tab in the graph view opens the node search (search-to-add)."""
        if (watched is self._tab_target and event.type() == QtCore.QEvent.Type.KeyPress
                and event.key() == QtCore.Qt.Key.Key_Tab
                and event.modifiers() == QtCore.Qt.KeyboardModifier.NoModifier):
            self.search.toggle_at_cursor()
            return True
        return super().eventFilter(watched, event)

    # -- queries (also used by tests) -----------------------------------------
    def scene_node(self, node_id: str) -> BaseNode | None:
        return self._by_id.get(node_id)

    def scene_node_ids(self) -> set[str]:
        return set(self._by_id)

    def scene_edges(self) -> set[Edge]:
        """Connections as the scene draws them (model and pipes must agree)."""
        edges = set()
        for nid, node in self._by_id.items():
            for port in node.input_ports():
                for other in port.connected_ports():
                    src = self._id_of.get(other.node().id)
                    if src is not None:
                        edges.add(Edge(src, other.name(), nid, port.name()))
        return edges

    def scene_pipe_count(self) -> int:
        return sum(len(p.view.connected_pipes) for n in self._by_id.values() for p in n.input_ports())

    def selected_ids(self) -> list[str]:
        return [self._id_of[n.id] for n in self.graph.selected_nodes() if n.id in self._id_of]

    # -- document -> scene ------------------------------------------------
    def _display_name(self, node_id: str) -> str:
        inst = self.doc.nodes[node_id]
        cls = all_node_types()[inst.type_name]
        return f"{inst.label or cls.title or inst.type_name}  ·  {node_id}"

    def _on_doc_event(self, event: str, payload) -> None:
        if event == "node_added":
            self._add_scene_node(payload)
        elif event == "node_removed":
            self._remove_scene_node(payload)
        elif event in ("edge_added", "edge_removed"):
            self.sync_edges()
        elif event == "node_moved":
            self._move_scene_node(payload)
        elif event == "label_changed":
            node = self._by_id.get(payload)
            if node is not None:
                node.set_property("name", self._display_name(payload), push_undo=False)
        elif event == "param_changed":
            self._update_tooltip(payload[0])
        elif event == "reset":
            self.rebuild()

    def rebuild(self) -> None:
        """Drop the whole scene and draw the document anew: the view is not repainted
        while the nodes go and come, only once at the end (``scene_rebuilds`` counts)."""
        viewer = self.graph.viewer()
        was_enabled = viewer.updatesEnabled()
        viewer.setUpdatesEnabled(False)
        try:
            for nid in list(self._by_id):
                self._remove_scene_node(nid)
            self._statuses.clear()
            for nid in self.doc.nodes:
                self._add_scene_node(nid)
            self.sync_edges()
        finally:
            viewer.setUpdatesEnabled(was_enabled)
        self.scene_rebuilds += 1
        viewer.viewport().update()
        self._emit_selection()

    def _add_scene_node(self, node_id: str) -> None:
        if node_id in self._by_id:
            return
        inst = self.doc.nodes[node_id]
        cls = self._node_classes[inst.type_name]
        family = all_node_types()[inst.type_name].family
        # colours given at creation: the item is laid out and drawn once, not once per colour
        node = self.graph.create_node(cls.type_, name=self._display_name(node_id), selected=False,
                                      color=(*family_shade(family, 0.62), 255),
                                      text_color=(245, 245, 245, 255),
                                      pos=list(inst.position), push_undo=False)
        node.set_property("border_color", (*family_shade(family, 1.0), 255), push_undo=False)
        self._by_id[node_id] = node
        self._id_of[node.id] = node_id
        self._update_tooltip(node_id)

    def _remove_scene_node(self, node_id: str) -> None:
        node = self._by_id.pop(node_id, None)
        if node is None:
            return
        self._id_of.pop(node.id, None)
        self._statuses.pop(node_id, None)
        self.graph.remove_node(node, push_undo=False)
        if self._selected == node_id:
            self._emit_selection()

    def _move_scene_node(self, node_id: str) -> None:
        node = self._by_id.get(node_id)
        if node is None:
            return
        x, y = self.doc.nodes[node_id].position
        # NodeGraphQt's model and item both hold a position; a drag moved only the item.
        node.model.pos = [x, y]
        if list(node.view.xy_pos) != [x, y]:
            node.view.xy_pos = [x, y]

    def sync_edges(self) -> None:
        """Make the scene's connections (model and drawn pipes) equal the document's."""
        want = {e for e in self.doc.edges if e.src in self._by_id and e.dst in self._by_id}
        have = self.scene_edges()
        for e in have - want:
            inp, out = self._ports(e)
            PortDisconnectedCmd(inp, out, False).redo()
        for e in want - have:
            inp, out = self._ports(e)
            if inp is not None and out is not None:
                PortConnectedCmd(inp, out, False).redo()
        # A pipe dragged off a port is already gone from the scene while
        # NodeGraphQt's model still holds it; redraw missing pipes, drop extra ones.
        for nid, node in self._by_id.items():
            for port in node.input_ports():
                model_peers = {p.view for p in port.connected_ports()}
                drawn_peers = {pipe.output_port for pipe in port.view.connected_pipes}
                for peer in model_peers - drawn_peers:
                    port.view.connect_to(peer)
                for peer in drawn_peers - model_peers:
                    port.view.disconnect_from(peer)

    def _ports(self, edge: Edge):
        src, dst = self._by_id.get(edge.src), self._by_id.get(edge.dst)
        out = src.outputs().get(edge.src_port) if src is not None else None
        inp = dst.inputs().get(edge.dst_port) if dst is not None else None
        return inp, out

    def _update_tooltip(self, node_id: str) -> None:
        node = self._by_id.get(node_id)
        inst = self.doc.nodes.get(node_id)
        if node is None or inst is None:
            return
        cls = all_node_types()[inst.type_name]
        lines = [f"<b>{cls.title or inst.type_name}</b> ({node_id}) — {cls.family}"]
        doc = doc_to_html(cls.__doc__)
        if doc:
            lines.append(doc)
        result = self._statuses.get(node_id)
        if result is not None:
            lines.append(f"status: <b>{result.status}</b> ({result.seconds:.2f} s)")
            if result.error:
                lines.append(f"<span style='color:#e04040'>{_html_escape(result.error)}</span>")
        node.view.setToolTip("<br/>".join(lines))

    # -- evaluation status --------------------------------------------------
    def set_results(self, results: dict) -> None:
        """Mark nodes by their latest `NodeResult` (failed: red outline and tooltip)."""
        self._statuses = dict(results)
        for nid, node in self._by_id.items():
            result = results.get(nid)
            node.view.status = result.status if result is not None else ""
            self._update_tooltip(nid)
            node.view.update()

    def node_status(self, node_id: str) -> str:
        node = self._by_id.get(node_id)
        return node.view.status if node is not None else ""

    # -- selection ------------------------------------------------------------
    def _on_selection_changed(self, _selected, _deselected) -> None:
        self._emit_selection()

    def _emit_selection(self) -> None:
        ids = self.selected_ids()
        current = ids[0] if ids else None
        if current != self._selected:
            self._selected = current
            self.selection_changed.emit(current)

    def select(self, node_id: str | None) -> None:
        for node in self.graph.selected_nodes():
            node.set_property("selected", False, push_undo=False)
        node = self._by_id.get(node_id) if node_id else None
        if node is not None:
            node.set_property("selected", True, push_undo=False)
        self._emit_selection()

    def fit_view(self, margin: float = 40.0) -> None:
        """Zoom to show every node, frame and collapsed subgraph (however many: no lower
        zoom limit leaves any out), never closer than 1:1."""
        views = [n.view for n in self._by_id.values() if n.view.isVisible()] + self.frames.items()
        viewer = self.graph.viewer()
        if not views:
            return
        rect = views[0].sceneBoundingRect()
        for v in views[1:]:
            rect = rect.united(v.sceneBoundingRect())
        rect = rect.adjusted(-margin, -margin, margin, margin)
        size = viewer.viewport().size()
        w, h = max(size.width(), 50), max(size.height(), 50)
        scale = min(1.0, w / rect.width(), h / rect.height())
        centre = rect.center()
        rect = QtCore.QRectF(0, 0, w / scale, h / scale)
        rect.moveCenter(centre)
        # NodeGraphQt keeps its zoom as a scene range fitted into the view.
        viewer._scene_range = rect
        viewer._update_scene()
        self.minimap.refresh()

    def arrange_nodes(self, *, column_width: float | None = None,
                      row_height: float | None = None) -> bool:
        """Lay the graph out in readable columns (depth from the sources, rows ordered to
        cross fewer edges, spacing from the largest node), wrapped into bands that fit the
        editor's view best; one undoable "arrange nodes" step, then the view fits the
        graph.  False if nothing moved."""
        rects = [n.view.boundingRect() for n in self._by_id.values()]
        if column_width is None:
            column_width = max([240.0] + [r.width() + 70.0 for r in rects])
        if row_height is None:
            row_height = max([110.0] + [r.height() + 30.0 for r in rects])
        size = self.graph.viewer().viewport().size()
        node_size = (max([180.0] + [r.width() for r in rects]), max([80.0] + [r.height() for r in rects]))
        positions = arrange_positions(self.doc, column_width=column_width, row_height=row_height,
                                      view=(max(size.width(), 200), max(size.height(), 200)), node_size=node_size)
        moves = [MoveNode(nid, pos) for nid, pos in positions.items()
                 if tuple(self.doc.nodes[nid].position) != pos]
        if not moves:
            return False
        ok = self._push(Macro("arrange nodes", moves))
        self.fit_view()
        return ok

    # -- gestures -> commands ---------------------------------------------------
    def _push(self, command) -> bool:
        try:
            self.undo.push(command)
        except (GraphError, KeyError) as exc:
            msg = exc.args[0] if isinstance(exc, KeyError) else str(exc)
            self.message.emit("error", f"refused: {msg}")
            return False
        return True

    def _edge_from_views(self, a, b) -> Edge | None:
        out, inp = (a, b) if a.port_type == PortTypeEnum.OUT.value else (b, a)
        src, dst = self._id_of.get(out.node.id), self._id_of.get(inp.node.id)
        if src is None or dst is None:
            return None
        return Edge(src, out.name, dst, inp.name)

    def gesture_connections(self, disconnected, connected) -> None:
        commands = []
        for a, b in disconnected:
            e = self._edge_from_views(a, b)
            if e is not None and e in self.doc.edges:
                commands.append(Disconnect(e.src, e.src_port, e.dst, e.dst_port))
        for a, b in connected:
            e = self._edge_from_views(a, b)
            if e is not None:
                commands.append(Connect(e.src, e.src_port, e.dst, e.dst_port))
        if commands:
            cmd = commands[0] if len(commands) == 1 else Macro(
                "connect" if any(isinstance(c, Connect) for c in commands) else "disconnect", commands)
            self._push(cmd)
        self.sync_edges()

    def connect_ports(self, src: str, src_port: str, dst: str, dst_port: str) -> bool:
        """The same path as dragging a pipe from src.src_port to dst.dst_port."""
        s, d = self._by_id[src], self._by_id[dst]
        out, inp = s.outputs().get(src_port), d.inputs().get(dst_port)
        if out is None or inp is None:
            self.message.emit("error", f"refused: no port {src}.{src_port} or {dst}.{dst_port}")
            return False
        before = len(self.doc.edges)
        displaced = [(inp.view, p.view) for p in inp.connected_ports()] if not inp.view.multi_connection else []
        self.gesture_connections(displaced, [(out.view, inp.view)])
        return len(self.doc.edges) >= before and Edge(src, src_port, dst, dst_port) in self.doc.edges

    def gesture_moved(self, node_data: dict) -> None:
        commands = []
        for view, _prev in node_data.items():
            nid = self._id_of.get(view.id)
            if nid is None or nid not in self.doc.nodes:
                continue
            x, y = view.xy_pos
            if tuple(self.doc.nodes[nid].position) != (float(x), float(y)):
                commands.append(MoveNode(nid, (x, y)))
        if commands:
            self._push(commands[0] if len(commands) == 1 else Macro("move nodes", commands))

    def gesture_create(self, scene_type: str, pos) -> None:
        type_name = self._engine_type_of.get(scene_type)
        if type_name is not None:
            self.create_node(type_name, pos)

    def create_node(self, type_name: str, pos=None) -> str | None:
        """Add a node of `type_name` at scene position `pos`; returns its id."""
        if pos is None:
            pos = self.graph.cursor_pos()
        cmd = AddNode(type_name, {}, position=(float(pos[0]), float(pos[1])))
        if self._push(cmd):
            self.select(cmd.node_id)
            return cmd.node_id
        return None

    def gesture_rename(self, scene_id: str, name: str) -> None:
        nid = self._id_of.get(scene_id)
        if nid is None:
            return
        label = name.split("  ·  ")[0].strip()
        cls = all_node_types()[self.doc.nodes[nid].type_name]
        if label == (cls.title or cls.type_name):
            label = ""
        if label != self.doc.nodes[nid].label:
            self._push(SetLabel(nid, label))
        node = self._by_id[nid]
        node.set_property("name", self._display_name(nid), push_undo=False)

    def gesture_delete(self, scene_ids: list[str]) -> None:
        ids = [self._id_of[s] for s in scene_ids if s in self._id_of]
        self.delete_nodes(ids)

    def delete_nodes(self, node_ids: list[str]) -> None:
        ids = [n for n in node_ids if n in self.doc.nodes]
        if not ids:
            return
        commands = [RemoveNode(n) for n in ids]
        self._push(commands[0] if len(commands) == 1 else Macro(f"remove {len(ids)} nodes", commands))

    def delete_selected(self) -> None:
        self.delete_nodes(self.selected_ids())


def _html_escape(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
