"""Pieces of the "Tile Sets" dock: block pictures (QPainter, 3D blocks as an
isometric view of their beams), the click grid and the add-block dialog."""

from __future__ import annotations

import math
import zlib
from typing import Callable

from PySide6 import QtCore, QtGui, QtWidgets

from engine.growth.tileset_edit import (TileSetEditError, connectors_from_geometry, parse_point,
                                        parse_polylines)
from engine.nodes.growth_tools import BLOCK_WEIGHT, block_weight_check

from .tool_number import ToolNumber

ICON_PX = 84
GRID_DIVISIONS = 8          # the add-block canvas snaps clicks to 1/8 of the cell
ERROR_STYLE = "color: #c03030;"
LABEL_COLOURS = ("#4e79a7", "#f28e2b", "#59a14f", "#e15759", "#b07aa1", "#76b7b2", "#edc948")


def _button(text: str, slot, row: QtWidgets.QBoxLayout) -> QtWidgets.QPushButton:
    button = QtWidgets.QPushButton(text)
    button.clicked.connect(lambda *_: slot())
    row.addWidget(button)
    return button


def _error_label() -> QtWidgets.QLabel:
    label = QtWidgets.QLabel("")
    label.setWordWrap(True)
    label.setStyleSheet(ERROR_STYLE)
    return label


def _weight_box() -> ToolNumber:
    """A block's weight: the tile-set loader's rule (engine.nodes.growth_tools), never clamped
    or rounded (a QDoubleSpinBox kept 3 decimals and a maximum)."""
    return ToolNumber(BLOCK_WEIGHT, check=block_weight_check)


def _set_items(box: QtWidgets.QComboBox, items: list) -> None:
    """Replace a combo box's items (keeping the choice) only when they differ."""
    if [box.itemText(i) for i in range(box.count())] != items:
        box.blockSignals(True)
        box.clear()
        box.addItems(items)
        box.blockSignals(False)


def label_colour(label: str) -> QtGui.QColor:
    """A stable colour per connector label ("0", no member, is grey)."""
    if label == "0":
        return QtGui.QColor("#9a9a9a")
    return QtGui.QColor(LABEL_COLOURS[zlib.crc32(label.encode()) % len(LABEL_COLOURS)])


def _project(p, ndim: int):
    """Unit-cell point -> (u, v) in [0, 1]: 2D as in an image (+y down); 3D an
    orthographic view turned 30° about z and tilted 30°, so no two axes overlap."""
    if ndim == 2:
        return p[0], p[1]
    qx, qy, qz = (float(v) - 0.5 for v in p)
    a, b = math.radians(30), math.radians(30)
    x1 = qx * math.cos(a) - qy * math.sin(a)
    y1 = qx * math.sin(a) + qy * math.cos(a)
    return 0.5 + 0.56 * x1, 0.5 - 0.56 * (qz * math.cos(b) - y1 * math.sin(b))


def draw_block(painter: QtGui.QPainter, rect: QtCore.QRectF, polylines, connectors, faces,
               ndim: int, *, background: bool = True) -> None:
    """Draw one tile's members and connector labels into ``rect``."""
    def pt(p):
        u, v = _project(p, ndim)
        return QtCore.QPointF(rect.left() + u * rect.width(), rect.top() + v * rect.height())

    painter.setRenderHint(QtGui.QPainter.RenderHint.Antialiasing)
    if background:
        painter.fillRect(rect, QtGui.QColor("#fbfbf8"))
    frame = QtGui.QPen(QtGui.QColor("#b8b8b0"), 1)
    painter.setPen(frame)
    if ndim == 2:
        painter.drawRect(rect)
    else:
        corners = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
        for a in corners:
            for b in corners:
                if a < b and sum(i != j for i, j in zip(a, b)) == 1:
                    painter.drawLine(pt(a), pt(b))
    member = QtGui.QPen(QtGui.QColor("#282c34"), min(6.0, max(2.0, rect.width() / 18)))
    member.setCapStyle(QtCore.Qt.PenCapStyle.RoundCap)
    painter.setPen(member)
    for poly in polylines:
        painter.drawPolyline([pt(p) for p in poly])
    r = min(6.0, max(2.5, rect.width() / 22))
    font = painter.font()
    px = max(8, min(14, int(rect.width() / 9)))
    font.setPixelSize(px)
    painter.setFont(font)
    for d, face in enumerate(faces):
        centre = [0.5] * ndim
        axis = "xyz".index(face[1])
        centre[axis] = 1.0 if face[0] == "+" else 0.0
        inner = list(centre)
        inner[axis] = 0.5 + (0.38 if face[0] == "+" else -0.38)
        colour = label_colour(str(connectors[d]))
        painter.setPen(QtGui.QPen(colour.darker(130), 1))
        painter.setBrush(colour)
        painter.drawEllipse(pt(centre), r, r)
        q = pt(inner)
        painter.drawText(QtCore.QRectF(q.x() - 1.5 * px, q.y() - px, 3 * px, 2 * px),
                         QtCore.Qt.AlignmentFlag.AlignCenter, str(connectors[d]))
    painter.setBrush(QtCore.Qt.BrushStyle.NoBrush)


def block_pixmap(tile, faces, ndim: int, size: int = ICON_PX) -> QtGui.QPixmap:
    pix = QtGui.QPixmap(size, size)
    pix.fill(QtGui.QColor("white"))
    painter = QtGui.QPainter(pix)
    try:
        draw_block(painter, QtCore.QRectF(4, 4, size - 8, size - 8), tile.polylines,
                   tile.connectors, faces, ndim)
    finally:
        painter.end()
    return pix


# ------------------------------------------------------------------ add-block dialog

class GridCanvas(QtWidgets.QWidget):
    """Click to add a point (snapped to 1/8 of the cell) to the current
    polyline; right-click ends it so the next click starts a new one."""

    point_clicked = QtCore.Signal(float, float)
    polyline_ended = QtCore.Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        self.polylines: list = []
        self.connectors: list = ["?"] * 4
        self.setMinimumSize(180, 180)
        self.setToolTip("Left-click: add a point (snapped to 1/8); right-click: end the polyline")

    def _cell(self) -> QtCore.QRectF:
        side = min(self.width(), self.height()) - 16
        return QtCore.QRectF(8, 8, side, side)

    def paintEvent(self, event):
        painter = QtGui.QPainter(self)
        cell = self._cell()
        painter.fillRect(self.rect(), QtGui.QColor("white"))
        painter.fillRect(cell, QtGui.QColor("#fbfbf8"))
        painter.setPen(QtGui.QPen(QtGui.QColor("#e2e2dc"), 1))
        for k in range(GRID_DIVISIONS + 1):
            t = k / GRID_DIVISIONS
            painter.drawLine(QtCore.QPointF(cell.left() + t * cell.width(), cell.top()),
                             QtCore.QPointF(cell.left() + t * cell.width(), cell.bottom()))
            painter.drawLine(QtCore.QPointF(cell.left(), cell.top() + t * cell.height()),
                             QtCore.QPointF(cell.right(), cell.top() + t * cell.height()))
        draw_block(painter, cell, self.polylines, self.connectors, ("+x", "+y", "-x", "-y"), 2,
                   background=False)
        painter.end()

    def mousePressEvent(self, event):
        if event.button() == QtCore.Qt.MouseButton.RightButton:
            self.polyline_ended.emit()
            return
        cell = self._cell()
        pos = event.position()
        snap = [round(min(1.0, max(0.0, v)) * GRID_DIVISIONS) / GRID_DIVISIONS
                for v in ((pos.x() - cell.left()) / cell.width(), (pos.y() - cell.top()) / cell.height())]
        self.point_clicked.emit(*snap)


class AddBlockDialog(QtWidgets.QDialog):
    """Name, weight, symmetry, arms, polylines (typed or clicked), connectors.

    ``submit(spec) -> str`` adds the block and returns "" or the refusal,
    which is shown here while the dialog stays open with everything typed.
    """

    def __init__(self, ndim: int, faces, submit: Callable[[dict], str], parent=None):
        super().__init__(parent)
        self.setWindowTitle("Add block")
        self.ndim, self.faces, self.submit = ndim, tuple(faces), submit
        self._end_polyline = True
        form = QtWidgets.QFormLayout()
        self.name_edit = QtWidgets.QLineEdit()
        self.weight_box = _weight_box()
        self.weight_box.setValue(1.0)
        self.symmetry_box = QtWidgets.QComboBox()
        self.symmetry_box.addItems(["full", "rotations", "none"])
        self.symmetry_box.setToolTip("which rotations/reflections give the block's orientations")
        arms_row = QtWidgets.QHBoxLayout()
        self.arm_boxes = {}
        for f in self.faces:
            self.arm_boxes[f] = box = QtWidgets.QCheckBox(f)
            arms_row.addWidget(box)
        self.junction_edit = QtWidgets.QLineEdit()
        self.junction_edit.setPlaceholderText("block centre")
        self.poly_edit = QtWidgets.QPlainTextEdit()
        self.poly_edit.setPlaceholderText("one polyline per line, points separated by ';'\n"
                                          + ("0.5 0.5; 1 0.5" if ndim == 2 else "0.5 0.5 0.5; 1 0.5 0.5"))
        self.poly_edit.setFixedHeight(70)
        conn_row = QtWidgets.QHBoxLayout()
        self.connector_edits = {}
        for f in self.faces:
            self.connector_edits[f] = edit = QtWidgets.QLineEdit()
            edit.setPlaceholderText("auto")
            edit.setMaximumWidth(60)
            conn_row.addWidget(QtWidgets.QLabel(f))
            conn_row.addWidget(edit)
        for label, field in (("Name", self.name_edit), ("Weight", self.weight_box),
                             ("Symmetry", self.symmetry_box), ("Arms (centre → face)", arms_row),
                             ("Junction", self.junction_edit), ("Polylines", self.poly_edit),
                             ("Connectors", conn_row)):
            form.addRow(label, field)
        outer = QtWidgets.QVBoxLayout(self)
        outer.addLayout(form)
        self.canvas = None
        if ndim == 2:
            self.canvas = GridCanvas()
            self.canvas.point_clicked.connect(self.add_point)
            self.canvas.polyline_ended.connect(self.end_polyline)
            edits = [self.poly_edit, self.junction_edit, *self.connector_edits.values()]
            for signal in [e.textChanged for e in edits] + [b.toggled for b in self.arm_boxes.values()]:
                signal.connect(self._update_canvas)
            self._update_canvas()
            outer.addWidget(self.canvas, 1)
        self.error_label = _error_label()
        outer.addWidget(self.error_label)
        buttons = QtWidgets.QDialogButtonBox()
        self.add_button = buttons.addButton("Add", QtWidgets.QDialogButtonBox.ButtonRole.AcceptRole)
        buttons.addButton(QtWidgets.QDialogButtonBox.StandardButton.Cancel)
        buttons.accepted.connect(self.try_add)
        buttons.rejected.connect(self.reject)
        outer.addWidget(buttons)

    def add_point(self, x: float, y: float) -> None:
        text = self.poly_edit.toPlainText().rstrip("\n")
        point = f"{x:g} {y:g}"
        if self._end_polyline or not text.strip():
            text = f"{text}\n{point}" if text.strip() else point
        else:
            text = f"{text}; {point}"
        self._end_polyline = False
        self.poly_edit.setPlainText(text)

    def end_polyline(self) -> None:
        self._end_polyline = True

    def _update_canvas(self) -> None:
        """Show the typed members and arms with the connector labels they would get."""
        try:
            spec = self.spec()
        except TileSetEditError:
            return
        centres = {"+x": (1.0, 0.5), "+y": (0.5, 1.0), "-x": (0.0, 0.5), "-y": (0.5, 0.0)}
        j = spec["junction"] or [0.5, 0.5]
        self.canvas.polylines = [[j, centres[f]] for f in spec["arms"]] + spec["polylines"]
        given = spec["connectors"] or {}
        derived = connectors_from_geometry(2, polylines=self.canvas.polylines, off_centre="?")
        self.canvas.connectors = [given.get(f, derived[f]) for f in self.faces]
        self.canvas.update()

    def spec(self) -> dict:
        """The block as `add_block` keywords; raises TileSetEditError on bad text."""
        junction = self.junction_edit.text().strip()
        connectors = {f: e.text().strip() for f, e in self.connector_edits.items() if e.text().strip()}
        return dict(name=self.name_edit.text().strip(),
                    arms=[f for f, box in self.arm_boxes.items() if box.isChecked()],
                    junction=parse_point(junction, self.ndim, "junction") if junction else None,
                    polylines=parse_polylines(self.poly_edit.toPlainText(), self.ndim),
                    connectors=connectors or None, weight=self.weight_box.value(),
                    symmetry=self.symmetry_box.currentText())

    def try_add(self) -> None:
        try:
            error = self.submit(self.spec())
        except TileSetEditError as exc:
            error = str(exc)
        self.error_label.setText(error)
        if not error:
            self.accept()


# ------------------------------------------------------------------ the editor
