"""A collapsed subgraph drawn as one node: its name and its boundary ports.

While a subgraph is collapsed (`Subgraph.collapsed`, saved in the project)
its member nodes and their pipes are hidden and a `ProxyItem` stands in
their place: one input row per member input an outside edge feeds, one
output row per member output that feeds an outside node
(`engine.graph.annotations.boundary_ports`), with wires to those outside
ports.  Evaluation is unchanged -- the members are still ordinary nodes.
Dragging the proxy moves the members; a double click expands it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6 import QtCore, QtGui, QtWidgets

from engine.graph.annotations import boundary_ports

from .frame_items import TITLE_HEIGHT, BoxItem

if TYPE_CHECKING:
    from .node_editor import NodeEditor

ROW = 20.0
WIDTH = 220.0
PORT_R = 5.0
PROXY_COLOUR = (120, 95, 45)
WIRE_COLOUR = QtGui.QColor(190, 170, 120)


class ProxyItem(BoxItem):
    """The collapsed subgraph: a node-like box the whole of which takes the mouse."""

    def __init__(self, owner, item_id: str):
        super().__init__(owner, "subgraph", item_id)
        self.colour = QtGui.QColor(*PROXY_COLOUR)
        self.inputs: list[tuple[str, str]] = []
        self.outputs: list[tuple[str, str]] = []
        self.members: tuple[str, ...] = ()  # the node items it hides
        self.setZValue(1.5)  # with the nodes, above pipes
        self.wires = QtWidgets.QGraphicsPathItem()
        self.wires.setPen(QtGui.QPen(WIRE_COLOUR, 2.0))
        self.wires.setZValue(-1.0)

    def shape(self) -> QtGui.QPainterPath:
        path = QtGui.QPainterPath()
        path.addRect(self.rect)
        return path

    def port_pos(self, side: str, k: int) -> QtCore.QPointF:
        x = self.rect.left() if side == "in" else self.rect.right()
        return QtCore.QPointF(x, self.rect.top() + TITLE_HEIGHT + ROW * (k + 0.5) + 4)

    def paint(self, painter, option, widget=None):
        painter.save()
        fill = QtGui.QColor(self.colour)
        painter.setPen(QtGui.QPen(QtGui.QColor(240, 200, 80) if self.current else self.colour.lighter(150), 2.0))
        painter.setBrush(fill.darker(130))
        painter.drawRoundedRect(self.rect, 6, 6)
        painter.setBrush(fill)
        painter.setPen(QtCore.Qt.PenStyle.NoPen)
        painter.drawRoundedRect(self.title_rect(), 6, 6)
        painter.setPen(QtGui.QColor(245, 245, 245))
        font = painter.font()
        font.setBold(True)
        painter.setFont(font)
        painter.drawText(self.title_rect().adjusted(8, 0, -8, 0),
                         QtCore.Qt.AlignmentFlag.AlignVCenter | QtCore.Qt.AlignmentFlag.AlignLeft, self.title)
        font.setBold(False)
        painter.setFont(font)
        for side, ports in (("in", self.inputs), ("out", self.outputs)):
            for k, (nid, port) in enumerate(ports):
                p = self.port_pos(side, k)
                painter.setBrush(WIRE_COLOUR)
                painter.setPen(QtCore.Qt.PenStyle.NoPen)
                painter.drawEllipse(p, PORT_R, PORT_R)
                painter.setPen(QtGui.QColor(225, 225, 225))
                text = QtCore.QRectF(p.x() + 10, p.y() - ROW / 2, WIDTH / 2 - 12, ROW) if side == "in" else \
                    QtCore.QRectF(p.x() - WIDTH / 2 - 2, p.y() - ROW / 2, WIDTH / 2 - 10, ROW)
                align = QtCore.Qt.AlignmentFlag.AlignLeft if side == "in" else QtCore.Qt.AlignmentFlag.AlignRight
                painter.drawText(text, align | QtCore.Qt.AlignmentFlag.AlignVCenter, f"{nid}.{port}")
        painter.restore()

    def mouseDoubleClickEvent(self, event):
        self.owner.set_collapsed(self.item_id, False)
        event.accept()


def show_members(editor: "NodeEditor", members, visible: bool) -> None:
    """Show or hide member node items and the pipes touching them (pipes hide
    themselves when an end's node is hidden, once redrawn)."""
    for nid in members:
        node = editor.scene_node(nid)
        if node is None:
            continue
        node.view.visible = visible
        if not visible:
            node.view.setSelected(False)
    for nid in members:
        node = editor.scene_node(nid)
        if node is None:
            continue
        for port in [*node.input_ports(), *node.output_ports()]:
            for pipe in list(port.view.connected_pipes):
                if pipe.input_port is not None and pipe.output_port is not None:
                    pipe.draw_path(pipe.input_port, pipe.output_port)


def update_proxy(editor: "NodeEditor", proxy: ProxyItem, sub, rect: QtCore.QRectF) -> None:
    """Lay the proxy out at `rect`'s top-left with the subgraph's boundary ports and wires."""
    proxy.inputs, proxy.outputs = boundary_ports(editor.doc, sub.members)
    rows = max(len(proxy.inputs), len(proxy.outputs), 1)
    proxy.title = f"▸ {sub.name}  ·  {len(sub.members)} nodes"
    proxy.set_geometry(QtCore.QRectF(rect.x(), rect.y(), WIDTH, TITLE_HEIGHT + ROW * rows + 8))
    path = QtGui.QPainterPath()
    inside = set(sub.members)
    for k, (nid, port) in enumerate(proxy.inputs):
        for e in editor.doc.inputs_of(nid, port):
            if e.src not in inside:
                _wire(path, _port_centre(editor, e.src, e.src_port, "out"), proxy.port_pos("in", k))
    for k, (nid, port) in enumerate(proxy.outputs):
        for e in editor.doc.outputs_of(nid):
            if e.src_port == port and e.dst not in inside:
                _wire(path, proxy.port_pos("out", k), _port_centre(editor, e.dst, e.dst_port, "in"))
    proxy.wires.setPath(path)


def _port_centre(editor: "NodeEditor", nid: str, port: str, side: str) -> QtCore.QPointF | None:
    node = editor.scene_node(nid)
    if node is None or not node.view.isVisible():
        return None
    item = (node.outputs() if side == "out" else node.inputs()).get(port)
    if item is None:
        return None
    return item.view.sceneBoundingRect().center()


def _wire(path: QtGui.QPainterPath, a: QtCore.QPointF | None, b: QtCore.QPointF | None) -> None:
    if a is None or b is None:
        return
    dx = max(40.0, abs(b.x() - a.x()) / 2)
    path.moveTo(a)
    path.cubicTo(QtCore.QPointF(a.x() + dx, a.y()), QtCore.QPointF(b.x() - dx, b.y()), b)
