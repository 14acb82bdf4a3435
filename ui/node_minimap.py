"""The node editor's overlays: a minimap in the bottom-right corner (every node
as a small box, the visible part of the graph as a frame; click or drag in it
to pan), shown while some node is off screen or under it, and the hint shown
while the document has no node.

Both are plain widgets over the graph view, children of the editor. They are
refreshed cheaply: the scene's ``changed`` signal and the view's repaints only
start a short single-shot timer, whose tick redraws the minimap if what it
shows (node boxes, visible rectangle) changed.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6 import QtCore, QtGui, QtWidgets

if TYPE_CHECKING:
    from .node_editor import NodeEditor

HINT_TEXT = "Right-click or press Tab to add a node  ·  File › Example Gallery…"
MINIMAP_SIZE = (190, 130)
MARGIN = 10
REFRESH_MS = 40


def _rect_tuple(r: QtCore.QRectF) -> tuple[float, float, float, float]:
    return (round(r.x(), 1), round(r.y(), 1), round(r.width(), 1), round(r.height(), 1))


class NodeMinimap(QtWidgets.QWidget):
    """Overview of the whole graph with the visible rectangle; clicking pans there."""

    def __init__(self, editor: "NodeEditor"):
        super().__init__(editor)
        self.editor = editor
        self.setAttribute(QtCore.Qt.WidgetAttribute.WA_OpaquePaintEvent)  # never repaints the view below
        self.setCursor(QtCore.Qt.CursorShape.PointingHandCursor)
        self.setToolTip("Minimap: click or drag to pan the node graph")
        self.resize(*MINIMAP_SIZE)
        self.paints = 0          # how often it redrew (tests check it stays cheap)
        self._state = None
        self._world = QtCore.QRectF()
        self._timer = QtCore.QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setInterval(REFRESH_MS)
        self._timer.timeout.connect(self.refresh)
        viewer = editor.graph.viewer()
        self._scene = viewer.scene()
        self._scene.changed.connect(self.schedule)
        self._watched = [viewer.viewport(), editor]
        for w in self._watched:
            w.installEventFilter(self)
        self.hint = EmptyHint(editor)
        self._place()

    def detach(self) -> None:
        for w in self._watched:
            w.removeEventFilter(self)
        self._watched = []
        if self._scene is not None:
            self._scene.changed.disconnect(self.schedule)
            self._scene = None
        self._timer.stop()

    # -- geometry -----------------------------------------------------------------
    def _place(self) -> None:
        area = self.editor.rect()
        w = int(min(MINIMAP_SIZE[0], area.width() * 0.4))
        h = int(min(MINIMAP_SIZE[1], area.height() * 0.25))
        self.setGeometry(area.width() - w - MARGIN, area.height() - h - MARGIN, w, h)
        self.raise_()
        self.hint.place()

    def eventFilter(self, watched, event) -> bool:
        kind = event.type()
        if watched is self.editor and kind == QtCore.QEvent.Type.Resize:
            self._place()
            self.schedule()
        elif kind in (QtCore.QEvent.Type.Paint, QtCore.QEvent.Type.Wheel, QtCore.QEvent.Type.Resize):
            self.schedule()  # the view panned, zoomed or redrew
        return False

    def schedule(self, *_args) -> None:
        if not self._timer.isActive():
            self._timer.start()

    def visible_scene_rect(self) -> QtCore.QRectF:
        viewer = self.editor.graph.viewer()
        return viewer.mapToScene(viewer.viewport().rect()).boundingRect()

    def node_rects(self) -> list[QtCore.QRectF]:
        return [n.view.sceneBoundingRect() for n in self.editor._by_id.values()]

    def refresh(self) -> None:
        """Redraw if the nodes or the visible rectangle changed; update the hint."""
        self.hint.refresh()
        nodes = self.node_rects()
        self.setVisible(bool(nodes) and not self._all_in_view(nodes))
        state = (tuple(_rect_tuple(r) for r in nodes), _rect_tuple(self.visible_scene_rect()))
        if state != self._state:
            self._state = state
            self.update()

    def _all_in_view(self, nodes: list[QtCore.QRectF]) -> bool:
        """Every node is in the view and clear of the minimap's corner: nothing to find,
        so the minimap stays out of the way (it shows as soon as a node is off screen)."""
        viewer = self.editor.graph.viewer()
        visible = self.visible_scene_rect()
        corner = QtCore.QRect(viewer.viewport().mapFrom(self.editor, self.geometry().topLeft()), self.size())
        covered = viewer.mapToScene(corner).boundingRect()
        return all(visible.contains(r) and not covered.intersects(r) for r in nodes)

    def _transform(self) -> tuple[float, float, float]:
        """(scale, dx, dy): scene -> minimap pixels, the whole graph and view fitted."""
        world = QtCore.QRectF(self.visible_scene_rect())
        for r in self.node_rects():
            world = world.united(r)
        world = world.adjusted(-40, -40, 40, 40)
        self._world = world
        inner = self.rect().adjusted(4, 4, -4, -4)
        s = min(inner.width() / max(world.width(), 1e-6), inner.height() / max(world.height(), 1e-6))
        dx = inner.x() + (inner.width() - world.width() * s) / 2 - world.x() * s
        dy = inner.y() + (inner.height() - world.height() * s) / 2 - world.y() * s
        return s, dx, dy

    def scene_point(self, p: QtCore.QPointF) -> QtCore.QPointF:
        """The scene point under minimap pixel ``p``."""
        s, dx, dy = self._transform()
        return QtCore.QPointF((p.x() - dx) / s, (p.y() - dy) / s)

    # -- drawing --------------------------------------------------------------------
    def paintEvent(self, event) -> None:
        self.paints += 1
        s, dx, dy = self._transform()
        painter = QtGui.QPainter(self)
        painter.fillRect(self.rect(), QtGui.QColor(24, 25, 28))
        painter.setPen(QtGui.QPen(QtGui.QColor(80, 84, 92), 1))
        painter.drawRect(self.rect().adjusted(0, 0, -1, -1))

        def to_map(r: QtCore.QRectF) -> QtCore.QRectF:
            return QtCore.QRectF(r.x() * s + dx, r.y() * s + dy, max(r.width() * s, 2), max(r.height() * s, 2))

        painter.setPen(QtCore.Qt.PenStyle.NoPen)
        for node in self.editor._by_id.values():
            colour = getattr(node.view, "color", None) or (120, 130, 150)
            painter.setBrush(QtGui.QColor(*colour[:3]))
            painter.drawRect(to_map(node.view.sceneBoundingRect()))
        painter.setBrush(QtCore.Qt.BrushStyle.NoBrush)
        painter.setPen(QtGui.QPen(QtGui.QColor(240, 200, 80), 1.5))
        painter.drawRect(to_map(self.visible_scene_rect()))
        painter.end()

    # -- panning ----------------------------------------------------------------------
    def mousePressEvent(self, event) -> None:
        if event.button() == QtCore.Qt.MouseButton.LeftButton:
            self.pan_to(self.scene_point(event.position()))
            event.accept()

    def mouseMoveEvent(self, event) -> None:
        if event.buttons() & QtCore.Qt.MouseButton.LeftButton:
            self.pan_to(self.scene_point(event.position()))
            event.accept()

    def pan_to(self, centre: QtCore.QPointF) -> None:
        """Centre the graph view on scene point ``centre`` (zoom unchanged)."""
        viewer = self.editor.graph.viewer()
        rect = QtCore.QRectF(viewer._scene_range)  # NodeGraphQt's view range (see NodeEditor.fit_view)
        rect.moveCenter(centre)
        viewer._scene_range = rect
        viewer._update_scene()
        self.refresh()


class EmptyHint(QtWidgets.QLabel):
    """'Right-click or press Tab to add a node' over an empty editor."""

    def __init__(self, editor: "NodeEditor"):
        super().__init__(HINT_TEXT, editor)
        self.editor = editor
        self.setObjectName("emptyEditorHint")
        self.setAlignment(QtCore.Qt.AlignmentFlag.AlignCenter)
        self.setWordWrap(True)
        self.setAttribute(QtCore.Qt.WidgetAttribute.WA_TransparentForMouseEvents)
        self.setStyleSheet("color: rgba(220, 224, 232, 150); font-size: 13pt; background: transparent;")
        self.refresh()

    def place(self) -> None:
        area = self.editor.rect()
        w = min(area.width() - 20, 520)
        self.setGeometry((area.width() - w) // 2, area.height() // 2 - 40, max(w, 10), 80)
        self.raise_()

    def refresh(self) -> None:
        empty = not self.editor.doc.nodes
        if empty == self.isHidden():
            self.setVisible(empty)
            if empty:
                self.place()
