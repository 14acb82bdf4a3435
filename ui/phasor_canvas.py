"""The paintable slice view of the Phasor Infill dock.

`PhasorCanvas` draws one axis-aligned slice through the fields' box: an RGB
picture (pattern, painted field or singularity heat map), the part's outline,
D glyphs, an optional colour scale and the brush under the mouse.  It only
turns gestures into signals in slice millimetres (u, v): a left drag is one
stroke (``strokeBegan``, ``strokeMoved``..., ``strokeEnded``), Escape or
``abort_stroke`` abandons it (``strokeAborted``).  What a stroke does is
the panel's business.

Picture convention (``engine.phasor.preview``): image row i runs along +v,
column j along +u; on screen +u points right and +v up, so row 0 is drawn
at the bottom.  The picture keeps the slice's aspect ratio in mm.
"""

from __future__ import annotations

import numpy as np
from PySide6 import QtCore, QtGui, QtWidgets

from .canvas_paint import PaintingToggle, begin_paint

MARGIN = 6           # px around the picture
SCALE_BAR_H = 30     # px reserved below the picture for a colour scale
NAN_RGB = (128, 128, 128)


def colour_lut(name: str, n: int = 256) -> np.ndarray:
    """(n, 3) uint8 RGB samples of a matplotlib colour map."""
    from matplotlib import colormaps

    rgba = colormaps[name](np.linspace(0.0, 1.0, n))
    return np.clip(np.rint(rgba[:, :3] * 255), 0, 255).astype(np.uint8)


def apply_lut(values, vmin: float, vmax: float, lut: np.ndarray) -> np.ndarray:
    """(..., 3) uint8: ``values`` mapped linearly from [vmin, vmax] onto ``lut``.

    Values beyond the range take the end colours (+inf the top one); NaN is grey.
    """
    v = np.asarray(values, dtype=np.float64)
    span = vmax - vmin if vmax > vmin else 1.0
    t = np.clip((np.where(np.isposinf(v), vmax, v) - vmin) / span, 0.0, 1.0)
    t = np.where(np.isneginf(v), 0.0, t)
    idx = np.rint(np.nan_to_num(t) * (len(lut) - 1)).astype(np.int64)
    out = lut[idx]
    out[np.isnan(v)] = NAN_RGB
    return out


def _qimage(rgb: np.ndarray) -> QtGui.QImage:
    """An RGB888 QImage of (h, w, 3) uint8, row 0 at the top (a copy)."""
    rgb = np.ascontiguousarray(rgb, dtype=np.uint8)
    h, w, _ = rgb.shape
    return QtGui.QImage(rgb.data, w, h, 3 * w, QtGui.QImage.Format.Format_RGB888).copy()


class PhasorCanvas(PaintingToggle, QtWidgets.QWidget):
    """A slice picture in mm with outline, glyphs, colour scale and a brush."""

    strokeBegan = QtCore.Signal(float, float)    # u, v mm
    strokeMoved = QtCore.Signal(float, float)
    strokeEnded = QtCore.Signal(float, float)
    strokeAborted = QtCore.Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        self.rgb: np.ndarray | None = None              # (H, W, 3), row i along +v
        self.extent = np.array([[0.0, 1.0], [0.0, 1.0]])  # ((u0, u1), (v0, v1)) mm
        self.axis_names = ("u", "v")
        self.outline: np.ndarray | None = None          # (m, 2, 2) mm
        self.glyphs: tuple | None = None                # (centres (k, 2), vectors (k, 2), length mm)
        self.scale: tuple | None = None                 # (lut (n, 3), vmin, vmax, text)
        self.placeholder = "no phasor fields"
        self.brush_radius = 1.0                         # mm
        self._image: QtGui.QImage | None = None
        self._painting = False
        self._in_stroke = False
        self._hover: QtCore.QPointF | None = None
        self.setMinimumSize(220, 220)
        self.setSizePolicy(QtWidgets.QSizePolicy.Policy.Expanding,
                           QtWidgets.QSizePolicy.Policy.Expanding)
        self.setMouseTracking(True)
        self.setFocusPolicy(QtCore.Qt.FocusPolicy.ClickFocus)

    # -- content ------------------------------------------------------------------------------
    def set_image(self, rgb: np.ndarray | None, extent=None) -> None:
        """Show (H, W, 3) uint8 ``rgb`` covering ``extent`` ((u0, u1), (v0, v1)) mm; None clears."""
        if extent is not None:
            self.extent = np.array(extent, dtype=np.float64)
        self.rgb = None if rgb is None else np.array(rgb, dtype=np.uint8)
        self._refresh_image()

    def update_region(self, rgb: np.ndarray, r0: int, c0: int) -> None:
        """Replace the pixels from row ``r0``, column ``c0`` by ``rgb`` (h, w, 3)."""
        if self.rgb is None:
            return
        h, w = rgb.shape[:2]
        self.rgb[r0:r0 + h, c0:c0 + w] = rgb
        self._refresh_image()

    def _refresh_image(self) -> None:
        self._image = None if self.rgb is None else _qimage(self.rgb[::-1])
        self.update()

    def set_outline(self, segments) -> None:
        """The part's outline as (m, 2, 2) in-plane mm segments, or None."""
        self.outline = None if segments is None or len(segments) == 0 else np.asarray(segments, float)
        self.update()

    def set_glyphs(self, centres, vectors, length: float) -> None:
        """Short lines at ``centres`` (k, 2) mm along ``vectors`` (k, 2) (in-plane part of a
        unit vector, drawn ``length`` mm long at full length); None hides them."""
        self.glyphs = None if centres is None else (np.asarray(centres, float),
                                                     np.asarray(vectors, float), float(length))
        self.update()

    def set_scale(self, lut, vmin: float = 0.0, vmax: float = 1.0, text: str = "") -> None:
        """A colour scale below the picture (``lut`` (n, 3) uint8), or None for none."""
        self.scale = None if lut is None else (np.asarray(lut, np.uint8), float(vmin), float(vmax), text)
        self.update()

    @property
    def in_stroke(self) -> bool:
        return self._in_stroke

    # -- geometry -----------------------------------------------------------------------------
    def target_rect(self) -> QtCore.QRectF:
        """Where the slice is drawn, in widget pixels (empty without a picture)."""
        if self.rgb is None:
            return QtCore.QRectF()
        ext_u = self.extent[0, 1] - self.extent[0, 0]
        ext_v = self.extent[1, 1] - self.extent[1, 0]
        avail_w = self.width() - 2 * MARGIN
        avail_h = self.height() - 2 * MARGIN - (SCALE_BAR_H if self.scale is not None else 0)
        s = max(min(avail_w / ext_u, avail_h / ext_v), 1e-6)
        w, h = ext_u * s, ext_v * s
        return QtCore.QRectF(MARGIN + (avail_w - w) / 2, MARGIN + (avail_h - h) / 2, w, h)

    def mm_at(self, pos) -> tuple:
        """In-plane (u, v) mm under a widget position."""
        r = self.target_rect()
        (u0, u1), (v0, v1) = self.extent
        return (u0 + (pos.x() - r.left()) / r.width() * (u1 - u0),
                v1 - (pos.y() - r.top()) / r.height() * (v1 - v0))

    def widget_point(self, u: float, v: float) -> QtCore.QPointF:
        """Widget position of in-plane (u, v) mm (inverse of `mm_at`)."""
        r = self.target_rect()
        (u0, u1), (v0, v1) = self.extent
        return QtCore.QPointF(r.left() + (u - u0) / (u1 - u0) * r.width(),
                              r.top() + (v1 - v) / (v1 - v0) * r.height())

    def _px_per_mm(self) -> float:
        r = self.target_rect()
        return r.width() / (self.extent[0, 1] - self.extent[0, 0]) if r.width() > 0 else 0.0

    # -- stroke -------------------------------------------------------------------------------
    def abort_stroke(self) -> None:
        if self._in_stroke:
            self._in_stroke = False
            self.strokeAborted.emit()
            self.update()

    def mousePressEvent(self, event) -> None:
        if (event.button() == QtCore.Qt.MouseButton.LeftButton and self._painting and not self._in_stroke
                and self.rgb is not None and self.target_rect().contains(event.position())):
            self._in_stroke = True
            self.strokeBegan.emit(*self.mm_at(event.position()))
            event.accept()
            return
        super().mousePressEvent(event)

    def mouseMoveEvent(self, event) -> None:
        self._hover = event.position()
        if self._in_stroke:
            self.strokeMoved.emit(*self.mm_at(event.position()))
        self.update()
        super().mouseMoveEvent(event)

    def mouseReleaseEvent(self, event) -> None:
        if self._in_stroke and event.button() == QtCore.Qt.MouseButton.LeftButton:
            self._in_stroke = False
            self.strokeEnded.emit(*self.mm_at(event.position()))
            event.accept()
            return
        super().mouseReleaseEvent(event)

    def keyPressEvent(self, event) -> None:
        if event.key() == QtCore.Qt.Key.Key_Escape and self._in_stroke:
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
        p = begin_paint(self, self._image is not None, self.placeholder)
        if p is None:
            return
        r = self.target_rect()
        p.setRenderHint(QtGui.QPainter.RenderHint.SmoothPixmapTransform, False)
        p.drawImage(r, self._image)
        p.setRenderHint(QtGui.QPainter.RenderHint.Antialiasing)
        self._draw_outline(p)
        self._draw_glyphs(p)
        self._draw_axes(p, r)
        self._draw_scale(p, r)
        self._draw_brush(p, r)
        p.end()

    def _lines(self, p: QtGui.QPainter, a: np.ndarray, b: np.ndarray) -> None:
        lines = [QtCore.QLineF(self.widget_point(*s), self.widget_point(*e)) for s, e in zip(a, b)]
        p.drawLines(lines)

    def _draw_outline(self, p: QtGui.QPainter) -> None:
        if self.outline is None:
            return
        p.setPen(QtGui.QPen(QtGui.QColor(255, 64, 160), 1.6))
        self._lines(p, self.outline[:, 0], self.outline[:, 1])

    def _draw_glyphs(self, p: QtGui.QPainter) -> None:
        if self.glyphs is None:
            return
        centres, vectors, length = self.glyphs
        half = 0.5 * length * vectors
        p.setPen(QtGui.QPen(QtGui.QColor(20, 20, 20), 1.4))
        self._lines(p, centres - half, centres + half)
        # a dot at the head: D is a direction, not an axis
        p.setBrush(QtGui.QColor(20, 20, 20))
        for c in centres + half:
            p.drawEllipse(self.widget_point(*c), 1.6, 1.6)

    def _draw_axes(self, p: QtGui.QPainter, r: QtCore.QRectF) -> None:
        p.setPen(self.palette().text().color())
        font = p.font()
        font.setPointSizeF(max(7.0, font.pointSizeF() * 0.85))
        p.setFont(font)
        p.drawText(QtCore.QPointF(r.right() - 12, r.bottom() - 3), self.axis_names[0] + "→")
        p.drawText(QtCore.QPointF(r.left() + 3, r.top() + 12), "↑" + self.axis_names[1])

    def _draw_scale(self, p: QtGui.QPainter, r: QtCore.QRectF) -> None:
        if self.scale is None:
            return
        lut, vmin, vmax, text = self.scale
        bar = QtCore.QRectF(r.left(), r.bottom() + 6, max(r.width(), 60.0), 8)
        strip = _qimage(lut[None, :, :])
        p.drawImage(bar, strip)
        p.setPen(self.palette().text().color())
        y = bar.bottom() + 12
        p.drawText(QtCore.QPointF(bar.left(), y), f"{vmin:.3g}")
        label = f"{vmax:.3g}"
        p.drawText(QtCore.QPointF(bar.right() - p.fontMetrics().horizontalAdvance(label), y), label)
        if text:
            half = p.fontMetrics().horizontalAdvance(text) / 2
            p.drawText(QtCore.QPointF(bar.center().x() - half, y), text)

    def _draw_brush(self, p: QtGui.QPainter, r: QtCore.QRectF) -> None:
        if not self._painting or self._hover is None or not r.contains(self._hover):
            return
        radius = self.brush_radius * self._px_per_mm()
        p.setPen(QtGui.QPen(QtGui.QColor(255, 255, 255), 2.5))
        p.setBrush(QtCore.Qt.BrushStyle.NoBrush)
        p.drawEllipse(self._hover, radius, radius)
        p.setPen(QtGui.QPen(QtGui.QColor(0, 0, 0), 1.0))
        p.drawEllipse(self._hover, radius, radius)
