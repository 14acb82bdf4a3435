"""The paintable picture of the RD dock: one 2D field or one slice of a 3D one.

`RDCanvas` is the Phasor Infill canvas (`ui.phasor_canvas.PhasorCanvas`:
picture, colour scale, axis names, brush under the mouse, a left drag as
one stroke with Escape to abandon it) working in grid cells instead of
millimetres: its extent is the slice of the growth grid, ``(0, n_u)`` by
``(0, n_v)`` cells, ``+u`` to the right and ``+v`` up (image row 0 at the
bottom, as ``[y, x]`` grids are stored). On top of that it draws

* coloured line segments (principal-direction glyphs) and polylines
  (streamlines), in the same cell units;
* a before / after comparison: the picture of the structure before the last
  edit shown instead of the current one ("before") or on the left of a
  vertical split line ("split");
* the brush coloured by its mode, the stamps of the stroke being dragged and
  faint outlines of the stamps already in the document.

It turns gestures into signals only; what a stroke means is the panel's
business.
"""

from __future__ import annotations

import numpy as np
from PySide6 import QtCore, QtGui, QtWidgets

from engine.nodes.rd_brush import BRUSH_RADIUS, SOLID_VALUE, brush_check
from engine.rd.preview import PLANE_AXES

from .canvas_paint import begin_paint
from .phasor_canvas import PhasorCanvas, _qimage
from .tool_number import ToolNumber

COMPARE_MODES = ("now", "before", "split")
BRUSH_MODES = (("erase", "Erase structure"), ("draw", "Draw structure"), ("solid", "Mark solid (Gamma_c)"))
BRUSH_RGB = {"erase": (220, 50, 47), "draw": (38, 139, 210), "solid": (230, 140, 30)}


class RDCanvas(PhasorCanvas):
    """A grid slice in cell units with glyphs, streamlines, before/after and a brush."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.placeholder = "no reaction/diffusion fields"
        self.axis_names = ("x", "y")
        self.segments: np.ndarray | None = None      # (k, 2, 2) cells
        self.segment_rgb: np.ndarray | None = None   # (k, 3) uint8
        self.polylines: list = []
        self.before_rgb: np.ndarray | None = None
        self._before_image: QtGui.QImage | None = None
        self.compare = "now"
        self.split = 0.5                             # fraction of the width shown as "before"
        self.brush_mode = "erase"
        self.trail: np.ndarray | None = None         # (m, 2) stamp centres of the stroke so far
        self.marks: list = []                        # [(centre (2,), radius, mode)] in the document

    # -- content --------------------------------------------------------------------------------
    def set_grid_extent(self, n_u: int, n_v: int) -> None:
        """The slice is ``n_u`` by ``n_v`` cells of the growth grid."""
        self.extent = np.array([[0.0, float(n_u)], [0.0, float(n_v)]])
        self.update()

    def set_segments(self, segments, colours=None) -> None:
        """Line glyphs ``segments`` (k, 2, 2) in cells, ``colours`` (k, 3) uint8; None hides them."""
        if segments is None or len(segments) == 0:
            self.segments = self.segment_rgb = None
        else:
            self.segments = np.asarray(segments, np.float64).reshape(-1, 2, 2)
            self.segment_rgb = (None if colours is None else np.asarray(colours, np.uint8).reshape(-1, 3))
        self.update()

    def set_polylines(self, lines) -> None:
        """Streamlines as (m, 2) cell polylines; an empty list hides them."""
        self.polylines = [np.asarray(line, np.float64) for line in (lines or [])]
        self.update()

    def set_before(self, rgb) -> None:
        """The picture before the last edit (same size as the current one), or None."""
        self.before_rgb = None if rgb is None else np.array(rgb, np.uint8)
        self._before_image = None if rgb is None else _qimage(self.before_rgb[::-1])
        self.update()

    def set_compare(self, mode: str, split: float | None = None) -> None:
        if mode not in COMPARE_MODES:
            raise ValueError(f"compare mode must be one of {COMPARE_MODES}; got {mode!r}")
        self.compare = mode
        if split is not None:
            self.split = float(np.clip(split, 0.0, 1.0))
        self.update()

    def set_trail(self, centres) -> None:
        self.trail = None if centres is None or len(centres) == 0 else np.asarray(centres, np.float64)
        self.update()

    def set_marks(self, marks) -> None:
        """Outlines ``[(centre (u, v), radius, mode)]`` in cells."""
        self.marks = list(marks or [])
        self.update()

    def set_stamps(self, stamps, axis: str = "z", index: int | None = None) -> None:
        """Outline brush stamps ``[(centre (x, y[, z]) cells, radius, mode)]`` where they cross
        the shown slice (layer ``index`` normal to ``axis``; None for a 2D grid)."""
        cu, cv = PLANE_AXES[axis] if index is not None else (0, 1)
        marks = []
        for p, r, mode in stamps:
            p = np.asarray(p, np.float64)
            if index is not None:
                if len(p) != 3:
                    continue
                off = p["xyz".index(axis)] - (index + 0.5)
                if abs(off) >= r:
                    continue
                r = float(np.sqrt(r * r - off * off))    # the ball's cut through the slice
            elif len(p) != 2:
                continue
            marks.append(((p[cu], p[cv]), r, mode))
        self.set_marks(marks)

    def cell_at(self, pos) -> tuple:
        """``(u, v)`` in cells under a widget position (``mm_at`` of the base canvas)."""
        return self.mm_at(pos)

    # -- drawing --------------------------------------------------------------------------------
    def paintEvent(self, _event) -> None:
        p = begin_paint(self, self._image is not None, self.placeholder)
        if p is None:
            return
        r = self.target_rect()
        p.setRenderHint(QtGui.QPainter.RenderHint.SmoothPixmapTransform, False)
        self._draw_pictures(p, r)
        p.setRenderHint(QtGui.QPainter.RenderHint.Antialiasing)
        self._draw_outline(p)
        self._draw_segments(p)
        self._draw_polylines(p)
        self._draw_marks(p)
        self._draw_axes(p, r)
        self._draw_scale(p, r)
        self._draw_brush(p, r)
        p.end()

    def _draw_pictures(self, p: QtGui.QPainter, r: QtCore.QRectF) -> None:
        before = self._before_image if self.compare != "now" else None
        if before is None:
            p.drawImage(r, self._image)
            return
        if self.compare == "before":
            p.drawImage(r, before)
            return
        p.drawImage(r, self._image)
        cut = self.split * r.width()
        src = QtCore.QRectF(0, 0, self.split * before.width(), before.height())
        p.drawImage(QtCore.QRectF(r.left(), r.top(), cut, r.height()), before, src)
        p.setPen(QtGui.QPen(QtGui.QColor(255, 200, 0), 2.0))
        p.drawLine(QtCore.QPointF(r.left() + cut, r.top()), QtCore.QPointF(r.left() + cut, r.bottom()))
        p.drawText(QtCore.QPointF(r.left() + 4, r.bottom() - 4), "before")
        p.drawText(QtCore.QPointF(r.left() + cut + 4, r.bottom() - 4), "now")

    def _draw_segments(self, p: QtGui.QPainter) -> None:
        if self.segments is None:
            return
        for k, (a, b) in enumerate(self.segments):
            rgb = (20, 20, 20) if self.segment_rgb is None else tuple(int(c) for c in self.segment_rgb[k])
            p.setPen(QtGui.QPen(QtGui.QColor(*rgb), 1.8))
            p.drawLine(self.widget_point(*a), self.widget_point(*b))

    def _draw_polylines(self, p: QtGui.QPainter) -> None:
        if not self.polylines:
            return
        p.setPen(QtGui.QPen(QtGui.QColor(20, 20, 20, 200), 1.2))
        for line in self.polylines:
            p.drawPolyline(QtGui.QPolygonF([self.widget_point(*q) for q in line]))

    def _draw_marks(self, p: QtGui.QPainter) -> None:
        scale = self._px_per_mm()
        p.setBrush(QtCore.Qt.BrushStyle.NoBrush)
        for centre, radius, mode in self.marks:
            colour = QtGui.QColor(*BRUSH_RGB.get(mode, (128, 128, 128)), 110)
            p.setPen(QtGui.QPen(colour, 1.0, QtCore.Qt.PenStyle.DotLine))
            p.drawEllipse(self.widget_point(*centre), radius * scale, radius * scale)
        if self.trail is not None:
            colour = QtGui.QColor(*BRUSH_RGB.get(self.brush_mode, (128, 128, 128)), 70)
            p.setPen(QtCore.Qt.PenStyle.NoPen)
            p.setBrush(colour)
            radius = self.brush_radius * scale
            for c in self.trail:
                p.drawEllipse(self.widget_point(*c), radius, radius)

    def _draw_brush(self, p: QtGui.QPainter, r: QtCore.QRectF) -> None:
        if not self.painting or self._hover is None or not r.contains(self._hover):
            return
        radius = self.brush_radius * self._px_per_mm()
        p.setBrush(QtCore.Qt.BrushStyle.NoBrush)
        p.setPen(QtGui.QPen(QtGui.QColor(0, 0, 0), 3.0))
        p.drawEllipse(self._hover, radius, radius)
        p.setPen(QtGui.QPen(QtGui.QColor(*BRUSH_RGB.get(self.brush_mode, (255, 255, 255))), 1.6))
        p.drawEllipse(self._hover, radius, radius)


class GrowthPlot(QtWidgets.QWidget):
    """G^t (paper eq. 14) per direction against the step, log scale, with the stop level."""

    COLOURS = ((31, 119, 180), (214, 39, 40), (44, 160, 44))

    def __init__(self, parent=None):
        super().__init__(parent)
        self.curves: list = []        # [(steps (m,), G (m,))]
        self.eps: float | None = None
        self.setMinimumHeight(70)
        self.setSizePolicy(QtWidgets.QSizePolicy.Policy.Expanding, QtWidgets.QSizePolicy.Policy.Fixed)

    def set_curves(self, curves, eps: float | None = None) -> None:
        """``curves``: one (steps, G) pair of 1D arrays per direction; ``eps`` the stop level."""
        self.curves = [(np.asarray(s, np.float64), np.asarray(g, np.float64)) for s, g in (curves or [])]
        self.eps = eps
        self.update()

    def paintEvent(self, _event) -> None:
        p = QtGui.QPainter(self)
        p.fillRect(self.rect(), self.palette().base())
        box = QtCore.QRectF(self.rect()).adjusted(34, 6, -6, -14)
        p.setPen(self.palette().text().color())
        font = p.font()
        font.setPointSizeF(max(6.5, font.pointSizeF() * 0.8))
        p.setFont(font)
        usable = [(s, g) for s, g in self.curves if len(s) and np.any(g > 0)]
        if not usable or box.width() <= 0 or box.height() <= 0:
            p.drawText(self.rect(), QtCore.Qt.AlignmentFlag.AlignCenter, "G^t: no growth yet")
            p.end()
            return
        logs = [np.log10(np.maximum(g, 1e-300)) for _, g in usable]
        levels = np.concatenate([lg[np.isfinite(lg) & (lg > -300)] for lg in logs])
        lo, hi = float(levels.min()), float(levels.max())
        if self.eps:     # show the stop level when it is near: within two decades below the curves
            lo = min(lo, max(float(np.log10(self.eps)), lo - 2.0))
        hi = hi if hi > lo else lo + 1.0
        s_max = max(float(s[-1]) for s, _ in usable) or 1.0

        def point(step, level):
            return QtCore.QPointF(box.left() + step / s_max * box.width(),
                                  box.bottom() - (level - lo) / (hi - lo) * box.height())

        p.drawRect(box)
        p.drawText(QtCore.QPointF(2, box.top() + 8), f"{hi:.0f}")
        p.drawText(QtCore.QPointF(2, box.bottom()), f"{lo:.0f}")
        p.drawText(QtCore.QPointF(box.left(), self.height() - 2), "log10 G^t")
        steps = f"{int(s_max)} steps"
        p.drawText(QtCore.QPointF(box.right() - p.fontMetrics().horizontalAdvance(steps), self.height() - 2), steps)
        if self.eps and np.log10(self.eps) >= lo:
            p.setPen(QtGui.QPen(QtGui.QColor(120, 120, 120), 1.0, QtCore.Qt.PenStyle.DashLine))
            p.drawLine(point(0, np.log10(self.eps)), point(s_max, np.log10(self.eps)))
        p.setRenderHint(QtGui.QPainter.RenderHint.Antialiasing)
        for k, ((s, _), lg) in enumerate(zip(usable, logs)):
            p.setPen(QtGui.QPen(QtGui.QColor(*self.COLOURS[k % len(self.COLOURS)]), 1.2))
            keep = lg > -300
            p.drawPolyline(QtGui.QPolygonF([point(a, b) for a, b in zip(s[keep], lg[keep])]))
        p.end()


class BrushBox(QtWidgets.QGroupBox):
    """Brush settings: mode (erase / draw / mark solid), radius, Gamma_c value.

    The radius and value are `ToolNumber`s over `engine.nodes.rd_brush`'s schemas,
    checked by the node's own stroke check: a value a stroke could not hold is
    refused at its field, never clamped. ``changed`` fires on any edit.
    """

    changed = QtCore.Signal()

    def __init__(self, parent=None):
        super().__init__("Brush", parent)
        form = QtWidgets.QFormLayout(self)
        self.mode_box = QtWidgets.QComboBox()
        for key, text in BRUSH_MODES:
            self.mode_box.addItem(text, key)
        self.mode_box.currentIndexChanged.connect(self._on_changed)
        form.addRow("Mode", self.mode_box)
        self.radius_spin = ToolNumber(BRUSH_RADIUS, check=brush_check("radius"), rule="> 0")
        self.radius_spin.valueChanged.connect(self._on_changed)
        self.radius_label = QtWidgets.QLabel("Radius")
        form.addRow(self.radius_label, self.radius_spin)
        self.value_spin = ToolNumber(SOLID_VALUE, check=brush_check("value", solid=True))
        self.value_spin.valueChanged.connect(self._on_changed)
        form.addRow("Solid value", self.value_spin)
        self._on_changed()

    @property
    def mode(self) -> str:
        return self.mode_box.currentData()

    def _on_changed(self, *_args) -> None:
        solid = self.mode == "solid"
        self.value_spin.setEnabled(solid)
        self.radius_label.setText("Radius (field cells)" if solid else "Radius (growth cells)")
        self.changed.emit()


class SliceRow(QtWidgets.QWidget):
    """Slice normal (x / y / z) and layer of a 3D grid: a combo, a scrub slider and a label.

    ``set_grid(shape)`` (``[z, y, x]``, or None / 2D to hide) fits the slider to
    the layers along the chosen axis, keeping the layer when the size is unchanged.
    ``changed`` fires on any user change.
    """

    changed = QtCore.Signal()
    GRID_AXIS = {"z": 0, "y": 1, "x": 2}

    def __init__(self, parent=None):
        super().__init__(parent)
        self.grid: tuple | None = None
        row = QtWidgets.QHBoxLayout(self)
        row.setContentsMargins(0, 0, 0, 0)
        row.addWidget(QtWidgets.QLabel("Slice ⟂"))
        self.axis_box = QtWidgets.QComboBox()
        for a in ("x", "y", "z"):
            self.axis_box.addItem(a, a)
        self.axis_box.setCurrentIndex(2)
        self.axis_box.currentIndexChanged.connect(self._on_axis)
        row.addWidget(self.axis_box)
        self.slider = QtWidgets.QSlider(QtCore.Qt.Orientation.Horizontal)
        self.slider.setRange(0, 0)
        self.slider.valueChanged.connect(self._on_index)
        row.addWidget(self.slider, 1)
        self.label = QtWidgets.QLabel("")
        row.addWidget(self.label)
        self.hide()

    @property
    def axis(self) -> str:
        return self.axis_box.currentData() if self.grid is not None else "z"

    @property
    def index(self) -> int | None:
        return int(self.slider.value()) if self.grid is not None else None

    def set_grid(self, shape) -> None:
        self.grid = tuple(shape) if shape is not None and len(shape) == 3 else None
        self.setVisible(self.grid is not None)
        self._fit(keep=True)

    def set_slice(self, axis: str, index: int | None = None) -> None:
        self.axis_box.setCurrentIndex(("x", "y", "z").index(axis))
        if index is not None:
            self.slider.setValue(int(index))

    def _fit(self, keep: bool) -> None:
        if self.grid is None:
            return
        n = self.grid[self.GRID_AXIS[self.axis]]
        self.slider.blockSignals(True)
        same = keep and self.slider.maximum() == n - 1
        value = self.slider.value() if same or not keep else n // 2
        self.slider.setRange(0, n - 1)
        self.slider.setValue(min(value, n - 1))
        self.slider.blockSignals(False)
        self.label.setText(f"{self.axis} = {self.slider.value()} / {n - 1}")

    def _on_axis(self, _i) -> None:
        self._fit(keep=False)
        self.changed.emit()

    def _on_index(self, _v) -> None:
        self._fit(keep=False)
        self.changed.emit()
