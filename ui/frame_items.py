"""The graphics items of frames and subgraphs in the node editor (`ui.node_frames` drives them).

`BoxItem` is a box with a title bar behind the nodes; only its title bar
(and a resize corner) takes the mouse, handing presses and drags to its
owner, so a rubber band or a click on a node inside a frame works as
anywhere else.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6 import QtCore, QtGui, QtWidgets

if TYPE_CHECKING:
    from .node_frames import NodeFrames

TITLE_HEIGHT = 24.0
SIZER = 14.0
MARGIN = 24.0  # around the nodes a new frame or a subgraph box encloses
MIN_SIZE = (80.0, 50.0)
Z_FRAME = -3.0  # behind NodeGraphQt's pipes (-1) and backdrops (-2)
SUBGRAPH_COLOUR = (150, 120, 60)
CURRENT_PEN = QtGui.QColor(240, 200, 80)


class BoxItem(QtWidgets.QGraphicsItem):
    """A box with a title bar; only the title bar (and a resize corner) takes the mouse."""

    resizable = False

    def __init__(self, owner: "NodeFrames", kind: str, item_id: str):
        super().__init__()
        self.owner, self.kind, self.item_id = owner, kind, item_id
        self.rect = QtCore.QRectF(0, 0, 100, 60)
        self.title, self.comment = "", ""
        self.colour = QtGui.QColor(70, 90, 120)
        self.dashed = False
        self.current = False
        self._drag: tuple[str, QtCore.QPointF, QtCore.QRectF] | None = None
        self.setZValue(Z_FRAME)
        self.setAcceptHoverEvents(True)

    def set_geometry(self, rect: QtCore.QRectF) -> None:
        self.prepareGeometryChange()
        self.rect = QtCore.QRectF(rect)
        self.update()

    def boundingRect(self) -> QtCore.QRectF:
        return self.rect.adjusted(-2, -2, 2, 2)

    def title_rect(self) -> QtCore.QRectF:
        return QtCore.QRectF(self.rect.x(), self.rect.y(), self.rect.width(), TITLE_HEIGHT)

    def sizer_rect(self) -> QtCore.QRectF:
        r = self.rect
        return QtCore.QRectF(r.right() - SIZER, r.bottom() - SIZER, SIZER, SIZER)

    def shape(self) -> QtGui.QPainterPath:
        path = QtGui.QPainterPath()
        path.addRect(self.title_rect())
        if self.resizable:
            path.addRect(self.sizer_rect())
        return path

    def paint(self, painter, option, widget=None):
        painter.save()
        fill = QtGui.QColor(self.colour)
        fill.setAlpha(60)
        pen = QtGui.QPen(CURRENT_PEN if self.current else self.colour.lighter(140), 2.0 if self.current else 1.2)
        if self.dashed:
            pen.setStyle(QtCore.Qt.PenStyle.DashLine)
        painter.setPen(pen)
        painter.setBrush(fill)
        painter.drawRoundedRect(self.rect, 6, 6)
        bar = QtGui.QColor(self.colour)
        bar.setAlpha(200)
        painter.setPen(QtCore.Qt.PenStyle.NoPen)
        painter.setBrush(bar)
        painter.drawRoundedRect(self.title_rect(), 6, 6)
        painter.setPen(QtGui.QColor(240, 240, 240))
        font = painter.font()
        font.setBold(True)
        painter.setFont(font)
        painter.drawText(self.title_rect().adjusted(8, 0, -8, 0),
                         QtCore.Qt.AlignmentFlag.AlignVCenter | QtCore.Qt.AlignmentFlag.AlignLeft, self.title)
        if self.comment:
            font.setBold(False)
            painter.setFont(font)
            painter.setPen(QtGui.QColor(210, 210, 210))
            body = self.rect.adjusted(8, TITLE_HEIGHT + 4, -8, -4)
            painter.drawText(body, QtCore.Qt.TextFlag.TextWordWrap | QtCore.Qt.AlignmentFlag.AlignTop, self.comment)
        if self.resizable:
            painter.setPen(QtGui.QPen(self.colour.lighter(160), 1.5))
            s = self.sizer_rect()
            for k in (4, 8, 12):
                painter.drawLine(QtCore.QPointF(s.right() - k, s.bottom() - 1),
                                 QtCore.QPointF(s.right() - 1, s.bottom() - k))
        painter.restore()

    # -- gestures -------------------------------------------------------------
    def mousePressEvent(self, event):
        if event.button() != QtCore.Qt.MouseButton.LeftButton:
            event.ignore()
            return
        mode = "resize" if self.resizable and self.sizer_rect().contains(event.pos()) else "move"
        self._drag = (mode, event.scenePos(), QtCore.QRectF(self.rect))
        self.owner.item_pressed(self)
        event.accept()

    def mouseMoveEvent(self, event):
        if self._drag is None:
            return
        mode, start, rect = self._drag
        d = event.scenePos() - start
        if mode == "move":
            self.owner.item_dragged(self, rect.translated(d))
        else:
            self.owner.item_dragged(self, QtCore.QRectF(rect.x(), rect.y(), max(MIN_SIZE[0], rect.width() + d.x()),
                                                        max(MIN_SIZE[1], rect.height() + d.y())))

    def mouseReleaseEvent(self, event):
        if self._drag is not None:
            self._drag = None
            self.owner.item_released(self)
        event.accept()

    def hoverMoveEvent(self, event):
        shape = QtCore.Qt.CursorShape
        in_sizer = self.resizable and self.sizer_rect().contains(event.pos())
        self.setCursor(shape.SizeFDiagCursor if in_sizer else shape.OpenHandCursor)


class FrameItem(BoxItem):
    resizable = True


class SubgraphItem(BoxItem):
    pass
