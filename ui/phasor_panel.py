"""The "Phasor Infill" dock: paint D, F and Gamma on a slice, watch the pattern follow.

The dock shows the PhasorFields node that is selected (or feeds the selected
PhasorNoise / PhasorSlice, or is the only one) and the PhasorNoise fed by it,
from the latest evaluation outputs.  One axis-aligned slice through the
fields' box is drawn (axis and a scrub slider for the position) as

* the black diamond cells or the p_v sawtooth of the infill,
* the painted field (F, Gamma as colour with a scale; D as hue of its
  in-plane angle with line glyphs on a coarse grid),
* the singularity measure S as a heat map,

with the part's outline over it.  Pattern images are computed by a
`SliceWorker` thread (GPU shader, numpy fallback); a newer request
supersedes an older one, a progress bar with Cancel shows after 0.3 s.

A left drag on the slice is one brush stroke (napari's begin / commit /
abort).  While dragging, the stroke so far is applied to the fields locally
(``engine.phasor.strokes.apply_stroke``) and only the pixels whose samples
read a changed cell are redrawn; the pattern is updated in the rectangle
where the locally resampled and re-aligned kernels
(``engine.phasor.incremental.update_infill``) reach.  The release pushes
ONE ``SetParam(fields_node, "strokes", old + [stroke])``; Escape abandons
the stroke.  The dock then shows the next evaluation's outputs.
"""

from __future__ import annotations

import math

import numpy as np
from PySide6 import QtCore, QtWidgets

from engine.graph import SetParam
from engine.phasor.fields import MAX_SPREAD, PhasorFields
from engine.phasor.incremental import affected_box, changed_cells, is_empty, update_infill
from engine.phasor.preview import (AXES, axis_span, direction_glyphs, direction_hue, domain_slice,
                                   field_slice, mask_outline, plane_extent, region_pixel_rect,
                                   slice_plane, sub_plane, view_pixels)
from engine.phasor.strokes import FALLOFFS, FIELDS, PLANE_AXES, Stroke, apply_stroke

from .phasor_canvas import PhasorCanvas, apply_lut, colour_lut
from .phasor_print import PrintBox
from .phasor_worker import SliceJob, SliceWorker

DISPLAYS = (("diamonds", "Diamond cells"), ("p_v", "p_v sawtooth"), ("field", "Painted field"),
            ("singularity", "Singularity S"))
POSITION_STEPS = 200
PROGRESS_DELAY_MS = 300
S_SHOWN = (0.0, 4.0)        # heat-map range of S; the paper's threshold q = 2 sits mid-scale
GLYPHS = 16                 # D glyphs along the longer side
MIN_STEP_PX = 3.0           # a drag adds a point after moving this many screen pixels
DIAMOND_RGB = np.array([[238, 236, 228], [38, 40, 48]], np.uint8)
OUTSIDE_DIM = 0.45          # pattern pixels outside the part are blended towards grey
NO_FIELDS = "select a Phasor Fields node (or evaluate a graph with one)"
FIELD_TEXT = {"D": "direction D", "F": "frequency F (cells/mm)", "Gamma": "spread Gamma (deg)"}


def fields_of(value):
    """(PhasorFields, domain) of a "fields" output (PhasorFieldsValue or bare fields), or (None, None)."""
    if isinstance(value, PhasorFields):
        return value, None
    fields = getattr(value, "fields", None)
    return (fields, getattr(value, "domain", None)) if isinstance(fields, PhasorFields) else (None, None)


def infill_of(value):
    """The PhasorInfill of an "infill" output, or None."""
    return value if hasattr(value, "kernels") and isinstance(getattr(value, "fields", None), PhasorFields) \
        else None


def _type_of(doc, node_id):
    node = doc.nodes.get(node_id) if doc is not None and node_id else None
    return None if node is None else node.type_name


def _upstream(doc, node_id, port):
    edges = doc.inputs_of(node_id, port)
    return edges[0].src if edges else None


def pick_phasor_nodes(doc, selected, previous=None):
    """(fields node id, noise node id): the selected PhasorFields, the one feeding the
    selected PhasorNoise / PhasorSlice, the previous choice, or the only one."""
    fields_id = noise_id = None
    kind = _type_of(doc, selected)
    if kind == "PhasorFields":
        fields_id = selected
    elif kind == "PhasorNoise":
        noise_id, fields_id = selected, _upstream(doc, selected, "fields")
    elif kind == "PhasorSlice":
        noise_id = _upstream(doc, selected, "infill")
        fields_id = _upstream(doc, noise_id, "fields") if noise_id else None
    if fields_id is None and doc is not None:
        if _type_of(doc, previous) == "PhasorFields":
            fields_id = previous
        else:
            found = [n for n, node in doc.nodes.items() if node.type_name == "PhasorFields"]
            fields_id = found[0] if len(found) == 1 else None
    if fields_id is not None and _type_of(doc, noise_id) != "PhasorNoise":
        below = [e.dst for e in doc.outputs_of(fields_id) if _type_of(doc, e.dst) == "PhasorNoise"]
        noise_id = below[0] if below else None
    return fields_id, noise_id


class PhasorPanel(QtWidgets.QWidget):
    """Dock content: a paintable slice of the phasor fields and infill, G-code preview/export.

    Parameters
    ----------
    doc : GraphDocument, undo : UndoStack over it (strokes are pushed there)

    Signals
    -------
    preview_lines(points (n, 3) float64 mm, segments (m, 2) int64, colours (m, 3) uint8)
        toolpaths of a G-code file, for the 3D viewport
    """

    preview_lines = QtCore.Signal(object, object, object)

    def __init__(self, doc, undo, parent=None):
        super().__init__(parent)
        self.doc, self.undo = doc, undo
        self.fields_id: str | None = None
        self.noise_id: str | None = None
        self.fields: PhasorFields | None = None     # from the outputs
        self.domain = None
        self.infill = None
        self._outputs_key = None
        self.pending = None          # (fields, infill) painted here, not evaluated yet
        self.plane = None
        self.view_id = 0
        self.shown_values: np.ndarray | None = None   # what the picture shows, (H, W[, 3])
        self.pattern_engine = ""
        self._inside: np.ndarray | None = None
        self._f_range = (0.0, 1.0)
        self._view_ready = False     # the pattern of this view has arrived once
        self._stroke = None          # dict while dragging: base fields / infill, points, result
        self._own_push = False

        self.worker = SliceWorker(self)
        self.worker.finished.connect(self._on_pattern)
        self.worker.failed.connect(self._on_pattern_failed)
        self.worker.progress.connect(self._on_progress)
        self.worker.busy_changed.connect(self._on_busy)
        self._progress_timer = QtCore.QTimer(self)
        self._progress_timer.setSingleShot(True)
        self._progress_timer.timeout.connect(self._show_progress)
        self._build()
        if doc is not None:
            doc.subscribe(self._on_doc_event)
        self._on_field_changed()

    # -- widgets ------------------------------------------------------------------------------
    def _build(self) -> None:
        lay = QtWidgets.QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 4)
        self.caption = QtWidgets.QLabel(NO_FIELDS)
        self.caption.setWordWrap(True)
        lay.addWidget(self.caption)

        row = QtWidgets.QHBoxLayout()
        row.addWidget(QtWidgets.QLabel("Slice ⟂"))
        self.axis_box = QtWidgets.QComboBox()
        for a in AXES:
            self.axis_box.addItem(a, a)
        self.axis_box.setCurrentIndex(2)
        self.axis_box.currentIndexChanged.connect(lambda _i: self._rebuild_view())
        row.addWidget(self.axis_box)
        self.position_slider = QtWidgets.QSlider(QtCore.Qt.Orientation.Horizontal)
        self.position_slider.setRange(0, POSITION_STEPS - 1)
        self.position_slider.setValue(POSITION_STEPS // 2)
        self.position_slider.valueChanged.connect(lambda _v: self._rebuild_view())
        row.addWidget(self.position_slider, 1)
        self.position_label = QtWidgets.QLabel("")
        row.addWidget(self.position_label)
        lay.addLayout(row)

        row = QtWidgets.QHBoxLayout()
        row.addWidget(QtWidgets.QLabel("Show"))
        self.display_box = QtWidgets.QComboBox()
        for key, text in DISPLAYS:
            self.display_box.addItem(text, key)
        self.display_box.currentIndexChanged.connect(lambda _i: self._rebuild_view())
        row.addWidget(self.display_box, 1)
        self.engine_box = QtWidgets.QComboBox()
        self.engine_box.addItem("GPU", "gpu")
        self.engine_box.addItem("numpy", "numpy")
        self.engine_box.setToolTip("pattern evaluator (GPU falls back to numpy without EGL)")
        self.engine_box.currentIndexChanged.connect(self._on_engine_changed)
        row.addWidget(self.engine_box)
        lay.addLayout(row)

        self.canvas = PhasorCanvas()
        self.canvas.strokeBegan.connect(self._on_stroke_began)
        self.canvas.strokeMoved.connect(self._on_stroke_moved)
        self.canvas.strokeEnded.connect(self._on_stroke_ended)
        self.canvas.strokeAborted.connect(self._on_stroke_aborted)
        lay.addWidget(self.canvas, 3)

        row = QtWidgets.QHBoxLayout()
        self.progress = QtWidgets.QProgressBar()
        self.progress.setTextVisible(True)
        self.cancel_button = QtWidgets.QPushButton("Cancel")
        self.cancel_button.clicked.connect(self.cancel)
        row.addWidget(self.progress, 1)
        row.addWidget(self.cancel_button)
        self.progress_row = QtWidgets.QWidget()
        self.progress_row.setLayout(row)
        self.progress_row.hide()
        lay.addWidget(self.progress_row)
        self.status = QtWidgets.QLabel("")
        self.status.setWordWrap(True)
        lay.addWidget(self.status)

        lay.addWidget(self._build_brush())
        self.message = QtWidgets.QLabel("")
        self.message.setWordWrap(True)
        lay.addWidget(self.message)
        self.print_box = PrintBox()
        self.print_box.preview_lines.connect(self.preview_lines)
        self.print_box.message.connect(self.message.setText)
        self.print_box.progress.connect(self._on_progress)
        self.print_box.running.connect(self._on_export_running)
        lay.addWidget(self.print_box)

    def _spin(self, lo, hi, value, step, decimals=3, suffix=""):
        s = QtWidgets.QDoubleSpinBox()
        s.setRange(lo, hi)
        s.setDecimals(decimals)
        s.setSingleStep(step)
        s.setValue(value)
        s.setSuffix(suffix)
        s.valueChanged.connect(lambda _v: self._on_brush_changed())
        return s

    def _build_brush(self) -> QtWidgets.QWidget:
        box = QtWidgets.QGroupBox("Brush")
        form = QtWidgets.QFormLayout(box)
        self.field_box = QtWidgets.QComboBox()
        for name in FIELDS:
            self.field_box.addItem(FIELD_TEXT[name], name)
        self.field_box.setCurrentIndex(1)
        self.field_box.currentIndexChanged.connect(self._on_field_changed)
        form.addRow("Paints", self.field_box)
        self.radius_spin = self._spin(0.0, 1e4, 2.0, 0.25, suffix=" mm")
        form.addRow("Radius", self.radius_spin)
        self.strength_spin = self._spin(0.0, 1.0, 1.0, 0.05, decimals=2)
        form.addRow("Strength", self.strength_spin)
        self.falloff_box = QtWidgets.QComboBox()
        for name in FALLOFFS:
            self.falloff_box.addItem(name, name)
        self.falloff_box.currentIndexChanged.connect(lambda _i: self._on_brush_changed())
        form.addRow("Falloff", self.falloff_box)
        # wide ranges on purpose: a bad value is refused with the engine's message
        self.value_spin = self._spin(-1e4, 1e4, 1.0, 0.1, decimals=4)
        self.value_label = QtWidgets.QLabel("Value")
        form.addRow(self.value_label, self.value_spin)
        self.tilt_spin = self._spin(-360.0, 360.0, 0.0, 5.0, decimals=1, suffix="°")
        self.tilt_spin.setToolTip("D: tilt out of the slice plane, towards +normal")
        form.addRow("Tilt", self.tilt_spin)
        heading = QtWidgets.QHBoxLayout()
        self.heading_check = QtWidgets.QCheckBox("fixed")
        self.heading_check.setToolTip("D: paint one in-plane heading instead of the drag direction")
        self.heading_check.toggled.connect(lambda _b: self._on_brush_changed())
        self.heading_spin = self._spin(-360.0, 360.0, 0.0, 15.0, decimals=1, suffix="°")
        heading.addWidget(self.heading_check)
        heading.addWidget(self.heading_spin, 1)
        form.addRow("Heading", heading)
        self.depth_spin = self._spin(0.0, 1e4, 0.0, 0.25, suffix=" mm")
        self.depth_spin.setSpecialValueText("= radius")
        self.depth_spin.setToolTip("how far the brush reaches out of the slice plane")
        form.addRow("Depth", self.depth_spin)
        return box

    # -- context ------------------------------------------------------------------------------
    def set_context(self, doc, outputs: dict, selected: str | None) -> None:
        """Pick the fields / noise to show from the latest evaluation ``outputs``
        (node id -> {port: value}) and the selection."""
        if doc is not None and doc is not self.doc:
            if self.doc is not None:
                self.doc.unsubscribe(self._on_doc_event)
            self.doc = doc
            doc.subscribe(self._on_doc_event)
        outputs = outputs or {}
        fields_id, noise_id = pick_phasor_nodes(self.doc, selected, self.fields_id)
        fields, domain = fields_of(outputs.get(fields_id, {}).get("fields"))
        infill = infill_of(outputs.get(noise_id, {}).get("infill")) if noise_id else None
        key = (fields_id, noise_id, id(fields), id(infill))
        if key == self._outputs_key:
            return
        self._outputs_key = key
        same_grid = (self.fields is not None and fields is not None and fields_id == self.fields_id
                     and fields.shape == self.fields.shape and np.array_equal(fields.lo, self.fields.lo)
                     and np.array_equal(fields.hi, self.fields.hi))
        if self._stroke is not None and not same_grid:
            self.canvas.abort_stroke()
        self.fields_id, self.noise_id = fields_id, noise_id
        self.fields, self.infill = fields, infill
        self.domain = domain if domain is not None else getattr(infill, "domain", None)
        self.pending = None
        self.print_box.set_infill(infill, noise_id, self.engine_box.currentData())
        self._update_caption()
        if self._stroke is None:
            self._rebuild_view()
        # else: the earlier strokes' evaluation arrived mid-drag; the stroke goes on over
        # the same painted fields and the next evaluation redraws everything

    def _update_caption(self) -> None:
        if self.fields is None:
            self.caption.setText(NO_FIELDS if self.fields_id is None else
                                 f"<b>{self.fields_id}</b>: no fields yet (evaluate the graph)")
            return
        f = self.fields
        size = " × ".join(f"{e:.3g}" for e in f.hi - f.lo)
        cells = " × ".join(str(n) for n in f.shape[::-1])
        n = len(self._strokes())
        noise = (f" → <b>{self.noise_id}</b>" if self.infill is not None
                 else " (no Phasor Noise below: field only)")
        self.caption.setText(f"<b>{self.fields_id}</b>{noise}: {cells} cells over {size} mm, "
                             f"{n} stroke{'s' if n != 1 else ''}")

    def _strokes(self) -> list:
        node = self.doc.nodes.get(self.fields_id) if self.doc is not None and self.fields_id else None
        return list(node.params.get("strokes", [])) if node is not None else []

    def _on_doc_event(self, event: str, payload) -> None:
        try:
            if event == "param_changed" and payload == (self.fields_id, "strokes") and not self._own_push:
                # undo / redo / an edit elsewhere: what was painted here is no longer current
                if self.pending is not None:
                    self.pending = None
                    self._rebuild_view()
                self._update_caption()
            elif event in ("node_removed", "reset") and self.fields_id not in self.doc.nodes:
                self.set_context(self.doc, {}, None)
        except RuntimeError:   # the widget is gone; the document lives on
            pass

    # -- the slice ------------------------------------------------------------------------------
    @property
    def axis(self) -> str:
        return self.axis_box.currentData()

    @property
    def display(self) -> str:
        return self.display_box.currentData()

    @property
    def brush_field(self) -> str:
        return self.field_box.currentData()

    @property
    def shown_fields(self) -> PhasorFields | None:
        """The fields drawn now: the stroke in progress, else painted-but-not-evaluated, else the outputs."""
        if self._stroke is not None and self._stroke.get("fields") is not None:
            return self._stroke["fields"]
        return self.pending[0] if self.pending is not None else self.fields

    @property
    def shown_infill(self):
        return self.pending[1] if self.pending is not None and self.pending[1] is not None else self.infill

    @property
    def position(self) -> float:
        """mm along the slice normal."""
        if self.fields is None:
            return 0.0
        a, b = axis_span(self.fields.lo, self.fields.hi, self.axis)
        return a + (self.position_slider.value() + 0.5) * (b - a) / POSITION_STEPS

    def set_slice(self, axis: str, position: float | None = None) -> None:
        """Show the slice normal to ``axis`` at the scrub step nearest ``position`` mm."""
        self.axis_box.blockSignals(True)
        self.axis_box.setCurrentIndex(AXES.index(axis))
        self.axis_box.blockSignals(False)
        if position is not None and self.fields is not None:
            a, b = axis_span(self.fields.lo, self.fields.hi, axis)
            step = int(round((position - a) / (b - a) * POSITION_STEPS - 0.5))
            self.position_slider.blockSignals(True)
            self.position_slider.setValue(int(np.clip(step, 0, POSITION_STEPS - 1)))
            self.position_slider.blockSignals(False)
        self._rebuild_view()

    def set_display(self, key: str) -> None:
        self.display_box.setCurrentIndex([k for k, _ in DISPLAYS].index(key))

    def _show_nothing(self) -> None:
        self.plane = None
        self.shown_values = None
        self.canvas.set_image(None)
        self.canvas.set_outline(None)
        self.canvas.set_glyphs(None, None, 0.0)
        self.canvas.set_scale(None)
        self.canvas.set_painting(False)
        self.position_label.setText("")

    def _rebuild_view(self) -> None:
        """New plane (axis, position or display changed, or new outputs): redraw all of it."""
        if self._stroke is not None:
            self.canvas.abort_stroke()   # a stroke lives on one slice; aborting redraws
            return
        self.view_id += 1
        self.worker.cancel()
        fields = self.shown_fields
        if fields is None:
            self._show_nothing()
            return
        axis = self.axis
        self.plane = slice_plane(fields.lo, fields.hi, axis, self.position, max_pixels=view_pixels(fields))
        u, v, _ = PLANE_AXES[axis]
        self.canvas.axis_names = ("xyz"[u], "xyz"[v])
        self.position_label.setText(f"{axis} = {self.position:.3g} mm")
        inside = domain_slice(self.domain, self.plane)
        self._inside = inside
        ext = plane_extent(self.plane)
        self.canvas.set_outline(None if inside is None else mask_outline(inside, ext))
        self.canvas.set_painting(self._paint_block_reason() is None)
        self.canvas.setToolTip(self._paint_block_reason() or "")
        self.status.setText("")
        if self.display == "field" or self.shown_infill is None:
            self._draw_field(fields, ext)
            if self.display != "field":
                self.status.setText("no Phasor Noise below these fields: showing the painted field")
            return
        self.canvas.set_glyphs(None, None, 0.0)
        self._set_pattern_scale()
        h, w = self.plane.shape
        self._view_ready = False
        if self.shown_values is None or self.shown_values.shape != (h, w) or self.canvas.rgb is None \
                or not np.allclose(self.canvas.extent, ext):
            self.shown_values = np.zeros((h, w))
            self.canvas.set_image(np.full((h, w, 3), 200, np.uint8), ext)
        # else keep the last picture until this one arrives (scrubbing does not flash grey)
        self.worker.request(SliceJob(self.display, self.plane, self.shown_infill,
                                     engine=self.engine_box.currentData(), view=self.view_id))

    # -- field display ----------------------------------------------------------------------------
    def _wanted_f_range(self, fields: PhasorFields) -> tuple:
        """F colour range: the fields' whole range and the brush value."""
        lo, hi = fields.min_frequency(), fields.max_frequency()
        value = self.value_spin.value()
        if self.brush_field == "F" and value > 0:
            lo, hi = min(lo, value), max(hi, value)
        return (lo, hi) if hi - lo > 1e-9 else (0.9 * lo, 1.1 * hi + 1e-9)

    def _field_scale(self, fields: PhasorFields) -> None:
        name = self.brush_field
        if name == "F":
            self._f_range = self._wanted_f_range(fields)
            self.canvas.set_scale(colour_lut("viridis"), *self._f_range, "F cells/mm")
        elif name == "Gamma":
            self.canvas.set_scale(colour_lut("plasma"), 0.0, 90.0, "Gamma °")
        else:
            self.canvas.set_scale(None)

    def _field_rgb(self, values: np.ndarray) -> np.ndarray:
        name = self.brush_field
        if name == "F":
            return apply_lut(values, *self._f_range, colour_lut("viridis"))
        if name == "Gamma":
            return apply_lut(np.degrees(values), 0.0, 90.0, colour_lut("plasma"))
        return direction_hue(values, self.axis)

    def _draw_field(self, fields: PhasorFields, ext) -> None:
        self._field_scale(fields)
        self.shown_values = field_slice(fields, self.brush_field, self.plane)
        self.canvas.set_image(self._field_rgb(self.shown_values), ext)
        self._draw_glyphs(fields)

    def _draw_glyphs(self, fields: PhasorFields) -> None:
        if self.brush_field != "D" or self.display != "field" and self.shown_infill is not None:
            self.canvas.set_glyphs(None, None, 0.0)
            return
        centres, vectors, _ = direction_glyphs(fields, self.axis, self.position, count=GLYPHS)
        ext = plane_extent(self.plane)
        spacing = float(np.max(ext[:, 1] - ext[:, 0])) / GLYPHS
        self.canvas.set_glyphs(centres, vectors, 0.8 * spacing)

    def _redraw_field_rect(self, fields: PhasorFields, rect) -> None:
        """Sample ``fields`` again in the pixel rectangle ``rect`` only."""
        r0, r1, c0, c1 = rect
        part = field_slice(fields, self.brush_field, sub_plane(self.plane, (r0, r1), (c0, c1)))
        self.shown_values[r0:r1, c0:c1] = part
        self.canvas.update_region(self._field_rgb(part), r0, c0)
        if self.brush_field == "D":
            self._draw_glyphs(fields)

    # -- pattern display --------------------------------------------------------------------------
    def _set_pattern_scale(self) -> None:
        if self.display == "singularity":
            self.canvas.set_scale(colour_lut("inferno"), *S_SHOWN, "S (q = 2)")
        elif self.display == "p_v":
            self.canvas.set_scale(colour_lut("gray"), 0.0, 1.0, "p_v")
        else:
            self.canvas.set_scale(None)

    def _pattern_rgb(self, values: np.ndarray, rect=None) -> np.ndarray:
        if self.display == "diamonds":
            rgb = DIAMOND_RGB[(values > 0.5).astype(np.int64)]
        elif self.display == "p_v":
            rgb = apply_lut(values, 0.0, 1.0, colour_lut("gray"))
        else:
            rgb = apply_lut(values, *S_SHOWN, colour_lut("inferno"))
        if self._inside is not None:
            r0, r1, c0, c1 = rect if rect is not None else (0, values.shape[0], 0, values.shape[1])
            out = ~self._inside[r0:r1, c0:c1]
            rgb = rgb.astype(np.float64)
            rgb[out] = (1 - OUTSIDE_DIM) * rgb[out] + OUTSIDE_DIM * 150.0
            rgb = rgb.astype(np.uint8)
        return rgb

    def _on_pattern(self, job: SliceJob) -> None:
        if job.view != self.view_id or job.show != self.display or self.shown_values is None:
            return  # an older view's answer
        if job.purpose == "stroke" and self._stroke is not None:
            self._stroke["infill"] = job.infill
        elif job.purpose == "final" and self.pending is not None and self.pending[0] is job.fields:
            self.pending = (job.fields, job.infill)
        if job.result is None:
            return
        self.pattern_engine = job.engine
        if job.rect is None or job.rect == (0, self.plane.shape[0], 0, self.plane.shape[1]):
            self._view_ready = True
            self.shown_values = np.array(job.result)
            self.canvas.update_region(self._pattern_rgb(job.result), 0, 0)
        else:
            r0, r1, c0, c1 = job.rect
            self.shown_values[r0:r1, c0:c1] = job.result
            self.canvas.update_region(self._pattern_rgb(job.result, job.rect), r0, c0)
        self.status.setText(f"{dict(DISPLAYS)[self.display]} by {job.engine}")

    def _on_pattern_failed(self, job: SliceJob, message: str) -> None:
        if job.view == self.view_id:
            what = "pattern preview while painting" if job.prepare is not None else "slice"
            self.status.setText(f"{what} failed: {message}")

    # -- progress -------------------------------------------------------------------------------
    def _on_busy(self, busy: bool) -> None:
        if busy:
            self._progress_timer.start(PROGRESS_DELAY_MS)
        elif not self.print_box.exporting:
            self._progress_timer.stop()
            self.progress_row.hide()

    def _show_progress(self) -> None:
        if self.worker.is_busy or self.print_box.exporting:
            self.progress.setRange(0, 0)
            self.progress_row.show()

    def _on_progress(self, done: int, total: int) -> None:
        if total > 0:
            self.progress.setRange(0, total)
            self.progress.setValue(min(done, total))

    def cancel(self) -> None:
        """Stop the running slice evaluation or export."""
        if self.worker.is_busy:
            self.status.setText("slice evaluation cancelled: the picture is out of date")
        self.worker.cancel()
        self.print_box.cancel()

    # -- brush ------------------------------------------------------------------------------------
    def _on_field_changed(self, *_args) -> None:
        name = self.brush_field
        self.value_spin.blockSignals(True)
        if name == "F":
            self.value_label.setText("F (cells/mm)")
            self.value_spin.setSuffix("")
            self.value_spin.setValue(self.value_spin.property("F") or 1.0)
        elif name == "Gamma":
            self.value_label.setText("Gamma")
            self.value_spin.setSuffix("°")
            self.value_spin.setValue(self.value_spin.property("Gamma") or 30.0)
        self.value_spin.blockSignals(False)
        is_d = name == "D"
        self.value_spin.setEnabled(not is_d)
        for w in (self.tilt_spin, self.heading_check, self.heading_spin):
            w.setEnabled(is_d)
        self._on_brush_changed()
        if self.display == "field" or self.shown_infill is None:
            self._rebuild_view()

    def _on_brush_changed(self) -> None:
        name = self.brush_field
        if name in ("F", "Gamma"):
            self.value_spin.setProperty(name, self.value_spin.value())
        self.canvas.brush_radius = self.radius_spin.value()
        error = self.brush_error()
        self.message.setText("" if error is None else f"<span style='color:#c0392b'>{error}</span>")
        if (name == "F" and error is None and self._stroke is None and self.plane is not None
                and (self.display == "field" or self.shown_infill is None)
                and self._wanted_f_range(self.shown_fields) != self._f_range):
            self._rebuild_view()   # the colour scale spans the fields and the brush value

    def make_stroke(self, points) -> Stroke:
        """The brush's Stroke along ``points`` (k, 2) in-plane mm on the current slice;
        ValueError (the engine's message) for bad brush settings."""
        name = self.brush_field
        value = heading = None
        tilt = 0.0
        if name == "F":
            value = self.value_spin.value()
        elif name == "Gamma":
            value = math.radians(self.value_spin.value())
        else:
            tilt = math.radians(self.tilt_spin.value())
            if self.heading_check.isChecked():
                a = math.radians(self.heading_spin.value())
                heading = [math.cos(a), math.sin(a)]
        depth = self.depth_spin.value() or None
        return Stroke(name, self.axis, self.position, np.asarray(points, float), self.radius_spin.value(),
                      strength=self.strength_spin.value(), falloff=self.falloff_box.currentData(),
                      value=value, heading=heading, tilt=tilt, depth=depth)

    def brush_error(self) -> str | None:
        """The engine's refusal of the current brush settings, or None."""
        try:
            self.make_stroke([[0.0, 0.0], [1.0, 0.0]])
        except ValueError as exc:
            text = str(exc)
            if self.brush_field == "Gamma":
                text += f" (entered {self.value_spin.value():g}°, allowed 0..{math.degrees(MAX_SPREAD):g}°)"
            elif self.brush_field == "D" and "tilt" in text:
                text += f" (entered {self.tilt_spin.value():g}°, allowed -90..90°)"
            return text
        return None

    def _paint_block_reason(self) -> str | None:
        if self.fields is None:
            return "painting needs evaluated phasor fields"
        if self.undo is None:
            return "painting is off: the dock has no undo history to record strokes"
        if self.doc is None or self.fields_id not in self.doc.nodes:
            return "the Phasor Fields node is gone"
        return None

    # -- stroke: begin / extend / commit / abort --------------------------------------------------
    def _on_stroke_began(self, u: float, v: float) -> None:
        error = self.brush_error() or self._paint_block_reason()
        if error is not None:
            self.message.setText(f"<span style='color:#c0392b'>not painted: {error}</span>")
            self._stroke = None
            self.canvas.abort_stroke()
            return
        self._stroke = {"base": self.shown_fields, "base_infill": self.shown_infill, "points": [(u, v)],
                        "fields": None, "infill": None}
        if self.brush_field != "D" or self.heading_check.isChecked():
            self._paint_so_far()

    def _on_stroke_moved(self, u: float, v: float) -> None:
        s = self._stroke
        if s is None:
            return
        lu, lv = s["points"][-1]
        step = MIN_STEP_PX / max(self.canvas._px_per_mm(), 1e-9)
        if math.hypot(u - lu, v - lv) < step:
            return
        s["points"].append((u, v))
        self._paint_so_far()

    def _paint_so_far(self) -> None:
        """Apply the stroke so far to the fields it started from; redraw what it changed."""
        s = self._stroke
        try:
            stroke = self.make_stroke(s["points"])
        except ValueError:
            return  # a D stroke that has not moved yet has no direction
        new, changed = apply_stroke(s["base"], stroke)
        s["fields"], s["stroke"] = new, stroke
        if is_empty(changed):
            return
        region = affected_box(new, changed)
        if self.display == "field" or self.shown_infill is None:
            rect = region_pixel_rect(self.plane, region)
            if rect is not None:
                self._redraw_field_rect(new, rect)
            return
        self._request_local_pattern(s["base_infill"], new)

    def _request_local_pattern(self, base_infill, new: PhasorFields, purpose: str = "stroke") -> None:
        """Resample and re-align the kernels the change reaches, then evaluate the pattern
        where they show, in the worker; a newer request replaces a queued one."""
        plane, whole = self.plane, not self._view_ready

        def prepare(progress):
            changed = changed_cells(base_infill.fields, new)
            if changed is None:
                raise ValueError("the infill was made on another grid; evaluate to see the pattern")
            infill = update_infill(base_infill, new, changed, progress=progress)
            if whole:   # the view's own picture never arrived (superseded): draw all of it
                return infill, (0, plane.shape[0], 0, plane.shape[1])
            return infill, region_pixel_rect(plane, infill.changed_region)

        self.worker.request(SliceJob(self.display, plane, base_infill, engine=self.engine_box.currentData(),
                                     prepare=prepare, view=self.view_id, purpose=purpose, fields=new),
                            cancel_running=False)

    def _on_stroke_ended(self, u: float, v: float) -> None:
        s, self._stroke = self._stroke, None
        if s is None:
            return
        if (u, v) != s["points"][-1]:
            s["points"].append((u, v))
        try:
            stroke = self.make_stroke(s["points"])
        except ValueError as exc:
            self.message.setText(f"<span style='color:#c0392b'>not painted: {exc}</span>")
            self._rebuild_view()
            return
        new, changed = apply_stroke(s["base"], stroke)
        if is_empty(changed):
            self.message.setText("the stroke touched no cell of the fields")
            self._rebuild_view()
            return
        self._own_push = True
        try:
            self.undo.push(SetParam(self.fields_id, "strokes", self._strokes() + [stroke.to_dict()]))
        except Exception as exc:   # refused by the document: nothing changed
            self.message.setText(f"<span style='color:#c0392b'>not painted: {exc}</span>")
            self._rebuild_view()
            return
        finally:
            self._own_push = False
        self.pending = (new, s["infill"])
        self._update_caption()
        self.message.setText("")
        if self.display == "field" or self.shown_infill is None:
            rect = region_pixel_rect(self.plane, affected_box(new, changed))
            if rect is not None:
                self._redraw_field_rect(new, rect)
        else:
            self._request_local_pattern(s["base_infill"], new, purpose="final")

    def _on_stroke_aborted(self) -> None:
        if self._stroke is None:
            return
        self._stroke = None
        self.worker.cancel()
        self._rebuild_view()

    def _on_engine_changed(self, _index: int) -> None:
        self.print_box.engine = self.engine_box.currentData()
        self._rebuild_view()

    # -- G-code -----------------------------------------------------------------------------------
    def preview_gcode(self, path) -> bool:
        """Read a G-code file, show its layers and emit `preview_lines`."""
        return self.print_box.preview_gcode(path)

    def export_gcode(self, path, **options) -> None:
        """Write the evaluated infill's G-code in a thread (``settings``, ``pixel``: see PrintBox)."""
        self.print_box.export_gcode(path, **options)

    def _on_export_running(self, running: bool) -> None:
        if running:
            self._progress_timer.start(PROGRESS_DELAY_MS)
        elif not self.worker.is_busy:
            self._progress_timer.stop()
            self.progress_row.hide()

    def shutdown(self) -> None:
        """Stop the threads and stop following the document (the window is closing)."""
        if self.doc is not None:
            self.doc.unsubscribe(self._on_doc_event)
        self.worker.shutdown()
        self.print_box.shutdown()
