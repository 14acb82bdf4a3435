"""Painting a Scalar Field node in the Implicit Media dock.

`FieldPaintBox` shows one layer of the node's evaluated field (`engine.geometry.scalar_field.
nearest_layer`: axis and a position slider over the layers) as a grey or colour picture on
the slice canvas the Phasor dock uses too (`ui.phasor_canvas.PhasorCanvas`, over
`ui.canvas_paint`), with the brush (value, radius, strength, falloff, depth).

A left drag is one stroke (napari's begin / commit / abort): while dragging, the stroke so far
is painted on the shown layer only (`paint_strokes` on that one layer of cells, the brush's
footprint), and the release pushes ONE ``SetParam(node, "strokes", old + [stroke])`` on the
document's undo stack.  The window's evaluation worker then rebuilds the field; the box shows
the painted layer until the evaluated field lands (`set_field`).  Escape abandons the stroke.
"""

from __future__ import annotations

import math

import numpy as np
from PySide6 import QtCore, QtWidgets

from engine.geometry.plane_brush import FALLOFFS, PLANE_AXES
from engine.geometry.scalar_field import AXES, FieldStroke, nearest_layer, paint_strokes
from engine.graph import SetParam
from engine.nodes.scalar_field import paint_check, paint_param, paint_rule

from .phasor_canvas import PhasorCanvas, apply_lut, colour_lut
from .tool_number import ToolNumber

MIN_STEP_PX = 3.0            # a drag adds a point after moving this many screen pixels
SLIDER_STEPS = 1000          # the position slider runs over the box in this many steps
COLOUR_MAPS = (("grey", "gray"), ("viridis", "viridis"), ("magma", "magma"))
PAINTABLE = frozenset({"ScalarField"})


def scale_range(field, params: dict) -> tuple:
    """(vmin, vmax) of the colour scale: the clamp range when the node clamps, else the field's
    own range (one value: a unit span around it), so every layer reads on one scale."""
    if params.get("clamp") and params.get("clamp_lo", 0.0) < params.get("clamp_hi", 1.0):
        return float(params["clamp_lo"]), float(params["clamp_hi"])
    lo, hi = float(np.min(field.values)), float(np.max(field.values))
    return (lo, hi) if hi > lo else (lo - 0.5, hi + 0.5)


class FieldPaintBox(QtWidgets.QGroupBox):
    """The paint canvas and brush of a Scalar Field node.

    Parameters
    ----------
    doc : GraphDocument; undo : UndoStack over it (strokes are pushed there)

    Signals
    -------
    message(str, str) : (level, text) for the log
    """

    message = QtCore.Signal(str, str)

    def __init__(self, doc, undo, parent=None):
        super().__init__("Paint the field", parent)
        self.doc, self.undo = doc, undo
        self.node_id: str | None = None
        self.field = None                 # the evaluated Field shown
        self.params: dict = {}
        self.layer: np.ndarray | None = None   # (nv, nu) values drawn now (painted preview included)
        self.layer_index = 0
        self.points: list | None = None   # the drag in progress, in-plane mm
        self.vrange = (0.0, 1.0)
        self._build()

    # -- layout ---------------------------------------------------------------------------------
    def _build(self) -> None:
        lay = QtWidgets.QVBoxLayout(self)
        row = QtWidgets.QHBoxLayout()
        self.axis_box = QtWidgets.QComboBox()
        for a in AXES:
            self.axis_box.addItem(f"{a} slice", a)
        self.axis_box.setCurrentIndex(2)
        self.axis_box.currentIndexChanged.connect(lambda _i: self.redraw())
        self.position_slider = QtWidgets.QSlider(QtCore.Qt.Orientation.Horizontal)
        self.position_slider.setRange(0, SLIDER_STEPS)
        self.position_slider.setValue(SLIDER_STEPS // 2)
        self.position_slider.valueChanged.connect(lambda _v: self.redraw())
        self.colour_box = QtWidgets.QComboBox()
        for text, name in COLOUR_MAPS:
            self.colour_box.addItem(text, name)
        self.colour_box.currentIndexChanged.connect(lambda _i: self.redraw())
        row.addWidget(self.axis_box)
        row.addWidget(self.position_slider, 1)
        row.addWidget(self.colour_box)
        lay.addLayout(row)
        self.position_label = QtWidgets.QLabel("")
        lay.addWidget(self.position_label)
        self.canvas = PhasorCanvas(self)
        self.canvas.placeholder = "no field yet (evaluate the graph)"
        self.canvas.setMinimumSize(220, 220)
        self.canvas.strokeBegan.connect(self._began)
        self.canvas.strokeMoved.connect(self._moved)
        self.canvas.strokeEnded.connect(self._ended)
        self.canvas.strokeAborted.connect(self._aborted)
        lay.addWidget(self.canvas, 1)
        brush = QtWidgets.QFormLayout()
        self.value_spin = self._number("value")
        brush.addRow("Value", self.value_spin)
        self.radius_spin = self._number("radius")
        brush.addRow("Radius", self.radius_spin)
        self.strength_spin = self._number("strength")
        brush.addRow("Strength", self.strength_spin)
        self.falloff_box = QtWidgets.QComboBox()
        for name in FALLOFFS:
            self.falloff_box.addItem(name, name)
        brush.addRow("Falloff", self.falloff_box)
        self.depth_spin = self._number("depth", special=(0.0, "= radius"))
        brush.addRow("Depth", self.depth_spin)
        lay.addLayout(brush)
        self.status = QtWidgets.QLabel("")
        self.status.setWordWrap(True)
        lay.addWidget(self.status)

    def _number(self, name: str, special=None) -> ToolNumber:
        box = ToolNumber(paint_param(name), check=paint_check(name), rule=paint_rule(name), special=special)
        box.valueChanged.connect(lambda _v: self._on_brush_changed())
        return box

    def _on_brush_changed(self) -> None:
        self.canvas.brush_radius = self.radius_spin.value()
        self.canvas.update()

    # -- what is shown --------------------------------------------------------------------------
    @property
    def axis(self) -> str:
        return self.axis_box.currentData()

    @property
    def position(self) -> float:
        """mm along `axis`: the centre of the layer shown."""
        if self.field is None:
            return 0.0
        n = PLANE_AXES[self.axis][2]
        return float(self.field.lo[n] + (self.layer_index + 0.5) * self.field.spacing[n])

    def set_field(self, node_id, field, params: dict) -> None:
        """Show ``field`` (a scalar Field, or None before an evaluation) of node ``node_id``."""
        if node_id != self.node_id:
            self.canvas.abort_stroke()
        self.node_id, self.field, self.params = node_id, field, dict(params or {})
        ok = field is not None and getattr(field, "kind", "") == "scalar" and field.ndim == 3
        if not ok:
            self.field = None
        self.canvas.set_painting(self.field is not None and self.undo is not None)
        n = len(self.params.get("strokes", []))
        self.status.setText("" if self.field is None else
                            f"{n} stroke{'' if n == 1 else 's'} · values {np.min(self.field.values):.4g} "
                            f"to {np.max(self.field.values):.4g} · drag on the slice to paint")
        self.redraw()

    def redraw(self) -> None:
        """The layer under the slider from the evaluated field (plus the drag in progress)."""
        f = self.field
        if f is None:
            self.layer = None
            self.canvas.set_image(None)
            self.canvas.set_scale(None)
            self.position_label.setText("")
            return
        axis = self.axis
        u, v, n = PLANE_AXES[axis]
        t = self.position_slider.value() / SLIDER_STEPS
        along = f.lo[n] + t * (f.hi[n] - f.lo[n])
        image, extent, self.layer_index = nearest_layer(f, axis, along)
        self.layer = np.array(image, dtype=np.float64)
        self.vrange = scale_range(f, self.params)
        count = f.grid_shape[2 - n]
        self.position_label.setText(f"{axis} = {self.position:.4g} mm (layer {self.layer_index + 1} of {count})")
        self.canvas.axis_names = ("xyz"[u], "xyz"[v])
        if self.points:
            self._paint_preview()
        self._show_layer(extent)

    def _show_layer(self, extent=None) -> None:
        lut = colour_lut(self.colour_box.currentData())
        vmin, vmax = self.vrange
        self.canvas.set_image(apply_lut(self.layer, vmin, vmax, lut), extent)
        self.canvas.set_scale(lut, vmin, vmax, self.params.get("mode", ""))

    # -- the stroke -----------------------------------------------------------------------------
    def make_stroke(self, points) -> FieldStroke:
        """The brush's stroke along ``points`` (k, 2) in-plane mm on the layer shown;
        ValueError (the engine's message) for bad settings."""
        return FieldStroke(self.axis, self.position, np.asarray(points, float), self.radius_spin.value(),
                           self.value_spin.value(), strength=self.strength_spin.value(),
                           falloff=self.falloff_box.currentData(), depth=self.depth_spin.value() or None)

    def _paint_preview(self) -> None:
        """Paint the drag so far onto ``self.layer``: the layer as a grid one cell thick along
        the normal (its own corner, the field's spacing), so only its cells are computed."""
        try:
            stroke = self.make_stroke(self.points)
        except ValueError:
            return
        f, n = self.field, PLANE_AXES[self.axis][2]
        lo = np.array(f.lo, dtype=np.float64)
        lo[n] += self.layer_index * f.spacing[n]
        block = np.expand_dims(self.layer, 2 - n)          # back to [z, y, x], 1 along the normal
        self.layer = np.squeeze(paint_strokes(block, lo, f.spacing, [stroke]), axis=2 - n)

    def _block_reason(self) -> str | None:
        if self.field is None:
            return "painting needs an evaluated field"
        if self.undo is None or self.node_id not in self.doc.nodes:
            return "the Scalar Field node is gone"
        try:
            self.make_stroke([[0.0, 0.0]])
        except ValueError as exc:
            return str(exc)
        return None

    def _began(self, u: float, v: float) -> None:
        reason = self._block_reason()
        if reason is not None:
            self.status.setText(f"not painted: {reason}")
            self.canvas.abort_stroke()
            return
        self.points = [(u, v)]
        self.redraw()

    def _moved(self, u: float, v: float) -> None:
        if not self.points:
            return
        lu, lv = self.points[-1]
        if math.hypot(u - lu, v - lv) < MIN_STEP_PX / max(self.canvas._px_per_mm(), 1e-9):
            return
        self.points.append((u, v))
        self.redraw()

    def _ended(self, u: float, v: float) -> None:
        points, self.points = self.points, None
        if not points:
            return
        if (u, v) != points[-1]:
            points.append((u, v))
        try:
            stroke = self.make_stroke(points)
            old = list(self.doc.nodes[self.node_id].params.get("strokes", []))
            self.undo.push(SetParam(self.node_id, "strokes", old + [stroke.to_dict()]))
        except Exception as exc:          # refused by the stroke or the document: nothing changed
            self.status.setText(f"not painted: {exc}")
            self.message.emit("warning", f"Scalar Field: stroke not painted: {exc}")
            self.redraw()
            return
        self.status.setText(f"{len(old) + 1} stroke{'s' if old else ''} · evaluating…")
        self.points = points              # keep the painted layer until the field is evaluated
        self.redraw()
        self.points = None

    def _aborted(self) -> None:
        if self.points is not None:
            self.points = None
            self.redraw()
