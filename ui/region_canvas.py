"""The tiling picture of the Virtual Growth dock, and painting hint regions on it.

`RegionCanvas` draws a grid picture (a 2D tiling or one layer of a 3D one)
scaled to fit, marks defect cells red and lays the painted label map over it
translucently. With painting enabled a mouse drag is one stroke (napari's
begin / commit / abort): the overlay follows the drag live, the release
emits `strokeFinished` with the whole new map once (the panel turns it into
one undo item), Escape abandons the stroke. The left button
paints the chosen label, the right button erases (label 0).

Cell coordinates follow ``engine.growth.regions``: ``(x, y)`` in cells, cell
``[i, j]`` covering ``[j, j + 1) x [i, i + 1)``.
"""

from __future__ import annotations

import colorsys

import numpy as np
from PySide6 import QtCore, QtGui, QtWidgets

from engine.growth import DEFECT
from engine.growth.regions import N_LABELS, densify_stroke, paint_disc

from .canvas_paint import PaintingToggle, begin_paint

DEFECT_COLOUR = QtGui.QColor(220, 40, 40)
LABEL_ALPHA = 120
_BASE_COLOURS = ((0, 0, 0), (31, 119, 255), (255, 127, 14), (44, 190, 44), (214, 39, 40),
                 (148, 103, 189), (23, 190, 207), (227, 119, 194), (188, 189, 34), (140, 86, 75))


def label_rgb(label: int) -> tuple:
    """Display colour of a painted label (label 0, the base hints, is never drawn)."""
    label = int(label)
    if label < len(_BASE_COLOURS):
        return _BASE_COLOURS[label]
    r, g, b = colorsys.hsv_to_rgb(((label - 10) * 0.381966) % 1.0, 0.75, 0.95)
    return int(255 * r), int(255 * g), int(255 * b)


def _label_lut() -> np.ndarray:
    lut = np.zeros((N_LABELS, 4), np.uint8)   # B, G, R, A: Format_ARGB32 on little-endian
    for k in range(1, N_LABELS):
        r, g, b = label_rgb(k)
        lut[k] = (b, g, r, LABEL_ALPHA)
    return lut


_LUT = _label_lut()


def overlay_image(labels: np.ndarray) -> QtGui.QImage:
    """(ny, nx) labels -> an nx x ny translucent image, one pixel per cell, label 0 clear."""
    lab = np.clip(np.asarray(labels, dtype=np.int64), 0, N_LABELS - 1)
    bgra = np.ascontiguousarray(_LUT[lab])
    ny, nx = lab.shape
    return QtGui.QImage(bgra.data, nx, ny, 4 * nx, QtGui.QImage.Format.Format_ARGB32).copy()


class RegionCanvas(PaintingToggle, QtWidgets.QWidget):
    """A grid picture scaled to fit (nearest neighbour) with defects and painted regions."""

    strokeFinished = QtCore.Signal(object)   # (ny, nx) int64 label map after a stroke

    def __init__(self, parent=None):
        super().__init__(parent)
        self.image: QtGui.QImage | None = None
        self.grid_shape: tuple = ()
        self.defects = np.zeros((0, 2), dtype=int)   # (row, col) of defect cells
        self.labels: np.ndarray | None = None         # committed map, None = nothing to show
        self.paint_label = 1
        self.brush_radius = 1.0                       # cells
        self.overlay_visible = True
        self._painting = False
        self._stroke: np.ndarray | None = None        # map during a stroke
        self._stroke_label = 0
        self._last: np.ndarray | None = None          # last brush centre of the stroke
        self._hover: QtCore.QPointF | None = None
        self._overlay: QtGui.QImage | None = None
        self.setMinimumSize(200, 200)
        self.setSizePolicy(QtWidgets.QSizePolicy.Policy.Expanding,
                           QtWidgets.QSizePolicy.Policy.Expanding)
        self.setMouseTracking(True)
        self.setFocusPolicy(QtCore.Qt.FocusPolicy.ClickFocus)

    # -- content ------------------------------------------------------------------------------
    def set_grid(self, rgb: np.ndarray | None, tiles: np.ndarray | None) -> None:
        """Show an (h, w, 3) uint8 picture of the 2-D grid ``tiles`` (None clears)."""
        if rgb is None:
            self.image, self.grid_shape = None, ()
            self.defects = np.zeros((0, 2), dtype=int)
        else:
            h, w, _ = rgb.shape
            rgb = np.ascontiguousarray(rgb, dtype=np.uint8)
            self.image = QtGui.QImage(rgb.data, w, h, 3 * w, QtGui.QImage.Format.Format_RGB888).copy()
            self.grid_shape = tuple(np.shape(tiles))
            self.defects = np.argwhere(np.asarray(tiles) == DEFECT)
        self.update()

    def set_labels(self, labels: np.ndarray | None) -> None:
        """The committed label map (grid shape) to lay over the picture; None for none."""
        self.labels = None if labels is None else np.array(labels, dtype=np.int64)
        self._refresh_overlay()

    @property
    def in_stroke(self) -> bool:
        return self._stroke is not None

    def shown_labels(self) -> np.ndarray | None:
        """The map drawn now: the stroke in progress, else the committed one."""
        return self._stroke if self._stroke is not None else self.labels

    def set_overlay_visible(self, on: bool) -> None:
        self.overlay_visible = bool(on)
        self.update()

    def _refresh_overlay(self) -> None:
        lab = self.shown_labels()
        self._overlay = overlay_image(lab) if lab is not None and np.any(lab) else None
        self.update()

    # -- geometry -----------------------------------------------------------------------------
    def target_rect(self) -> QtCore.QRectF:
        if self.image is None:
            return QtCore.QRectF()
        iw, ih = self.image.width(), self.image.height()
        s = max(min((self.width() - 8) / iw, (self.height() - 8) / ih), 1e-3)
        w, h = iw * s, ih * s
        return QtCore.QRectF((self.width() - w) / 2, (self.height() - h) / 2, w, h)

    def cell_at(self, pos) -> np.ndarray:
        """(x, y) cell coordinates of a widget position (may lie off the grid)."""
        r = self.target_rect()
        ny, nx = self.grid_shape
        return np.array([(pos.x() - r.left()) / r.width() * nx,
                         (pos.y() - r.top()) / r.height() * ny])

    def widget_point(self, x: float, y: float) -> QtCore.QPointF:
        """Widget position of the cell coordinates (x, y) (inverse of `cell_at`)."""
        r = self.target_rect()
        ny, nx = self.grid_shape
        return QtCore.QPointF(r.left() + x * r.width() / nx, r.top() + y * r.height() / ny)

    # -- stroke -------------------------------------------------------------------------------
    def _can_paint(self) -> bool:
        return (self._painting and self.image is not None and len(self.grid_shape) == 2
                and (self.labels is None or self.labels.shape == self.grid_shape))

    def begin_stroke(self, pos, label: int) -> None:
        base = self.labels if self.labels is not None else np.zeros(self.grid_shape, np.int64)
        self._stroke_label = int(label)
        self._last = self.cell_at(pos)
        self._stroke = paint_disc(base, self._last[None, :], self.brush_radius, self._stroke_label)
        self._refresh_overlay()

    def extend_stroke(self, pos) -> None:
        here = self.cell_at(pos)
        pts = densify_stroke(np.stack([self._last, here]), spacing=max(0.25, self.brush_radius / 2))
        self._stroke = paint_disc(self._stroke, pts[1:], self.brush_radius, self._stroke_label)
        self._last = here
        self._refresh_overlay()

    def commit_stroke(self) -> None:
        stroke, self._stroke, self._last = self._stroke, None, None
        if stroke is None:
            return
        before = self.labels if self.labels is not None else np.zeros(self.grid_shape, np.int64)
        if np.array_equal(stroke, before):
            self._refresh_overlay()
            return
        self.labels = stroke
        self._refresh_overlay()
        self.strokeFinished.emit(stroke.copy())

    def abort_stroke(self) -> None:
        if self._stroke is not None:
            self._stroke, self._last = None, None
            self._refresh_overlay()

    # -- events -------------------------------------------------------------------------------
    def mousePressEvent(self, event) -> None:
        button = event.button()
        buttons = (QtCore.Qt.MouseButton.LeftButton, QtCore.Qt.MouseButton.RightButton)
        if self._stroke is None and button in buttons and self._can_paint():
            label = self.paint_label if button == QtCore.Qt.MouseButton.LeftButton else 0
            self.begin_stroke(event.position(), label)
            event.accept()
            return
        super().mousePressEvent(event)

    def mouseMoveEvent(self, event) -> None:
        self._hover = event.position()
        if self._stroke is not None:
            self.extend_stroke(event.position())
        elif self._painting:
            self.update()
        super().mouseMoveEvent(event)

    def mouseReleaseEvent(self, event) -> None:
        if self._stroke is not None:
            self.extend_stroke(event.position())
            self.commit_stroke()
            event.accept()
            return
        super().mouseReleaseEvent(event)

    def keyPressEvent(self, event) -> None:
        if event.key() == QtCore.Qt.Key.Key_Escape and self._stroke is not None:
            self.abort_stroke()
            event.accept()
            return
        super().keyPressEvent(event)

    def leaveEvent(self, event) -> None:
        self._hover = None
        self.update()
        super().leaveEvent(event)

    # -- drawing ------------------------------------------------------------------------------
    def paintEvent(self, _event) -> None:
        p = begin_paint(self, self.image is not None, "no tiling")
        if p is None:
            return
        p.setRenderHint(QtGui.QPainter.RenderHint.SmoothPixmapTransform, False)
        r = self.target_rect()
        p.drawImage(r, self.image)   # nearest neighbour: smooth transform is off
        if self.overlay_visible and self._overlay is not None:
            p.drawImage(r, self._overlay)
        self._draw_defects(p, r)
        self._draw_brush(p, r)
        p.end()

    def _draw_defects(self, p: QtGui.QPainter, r: QtCore.QRectF) -> None:
        ny, nx = self.grid_shape
        cw, ch = r.width() / nx, r.height() / ny
        p.setPen(QtGui.QPen(DEFECT_COLOUR, max(1.5, min(cw, ch) / 10)))
        p.setBrush(QtGui.QColor(220, 40, 40, 60))
        inset = 0.12
        for row, col in self.defects:
            p.drawRect(QtCore.QRectF(r.left() + (col + inset) * cw, r.top() + (row + inset) * ch,
                                     (1 - 2 * inset) * cw, (1 - 2 * inset) * ch))

    def _draw_brush(self, p: QtGui.QPainter, r: QtCore.QRectF) -> None:
        if not self._can_paint() or self._hover is None or not r.contains(self._hover):
            return
        cw = r.width() / self.grid_shape[1]
        radius = max(self.brush_radius, 0.5) * cw
        label = self._stroke_label if self._stroke is not None else self.paint_label
        colour = QtGui.QColor(*label_rgb(label)) if label else self.palette().text().color()
        p.setRenderHint(QtGui.QPainter.RenderHint.Antialiasing)
        p.setPen(QtGui.QPen(colour, 1.5, QtCore.Qt.PenStyle.DashLine if label == 0
                            else QtCore.Qt.PenStyle.SolidLine))
        p.setBrush(QtCore.Qt.BrushStyle.NoBrush)
        p.drawEllipse(self._hover, radius, radius)
