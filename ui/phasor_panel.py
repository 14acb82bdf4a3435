"""The "Phasor Infill" dock: paint D, F and Gamma on a slice, watch the pattern follow.

The dock shows the PhasorFields / PhasorNoise chain around the selection
(``engine.graph.query.chain_around``), from the latest evaluation outputs,
as a `PhasorInfillSession`.  One axis-aligned slice through the fields' box
is drawn (`SliceControls`: axis, a scrub slider for the position, display,
evaluator) by a `SliceView` as

* the black diamond cells or the p_v sawtooth of the infill,
* the painted field (F, Gamma as colour with a scale; D as hue of its
  in-plane angle with line glyphs on a coarse grid),
* the singularity measure S as a heat map,

with the part's outline over it.  Pattern images are computed off the GUI
thread (a `SliceRunner`; a newer request supersedes an older one); a
progress bar with Cancel shows after 0.3 s (`ProgressRow`).

A left drag on the slice is one brush stroke (`StrokeController`, with the
`BrushControls`' settings): painted locally through the session while
dragging, pushed as ONE ``SetParam(fields_node, "strokes", old + [stroke])``
on release.  The dock then shows the next evaluation's outputs; until then
what was painted here is ``pending``.  The print box (`PrintBox`) exports
and previews G-code.
"""

from __future__ import annotations

import numpy as np
from PySide6 import QtCore, QtWidgets

from engine.graph import SetParam
from engine.graph.query import chain_around
from engine.nodes.phasor_session import PhasorInfillSession
from engine.phasor.fields import PhasorFields

from .phasor_brush import BrushControls
from .phasor_canvas import PhasorCanvas
from .phasor_controls import ProgressRow, SliceControls
from .phasor_print import PrintBox
from .phasor_stroke import StrokeController
from .phasor_view import SliceView

CHAIN = ("PhasorFields", "PhasorNoise", "PhasorSlice")
NO_FIELDS = "select a Phasor Fields node (or evaluate a graph with one)"


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


def pick_phasor_nodes(doc, selected, previous=None):
    """(fields node id, noise node id) of the chain around ``selected`` (engine.graph.query's rule)."""
    chain = chain_around(doc, selected, CHAIN, previous=previous)
    return chain["PhasorFields"], chain["PhasorNoise"]


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
        self.session: PhasorInfillSession | None = None   # from the outputs
        self.pending: PhasorInfillSession | None = None   # painted here, not evaluated yet
        self._outputs_key = None
        self._own_push = False
        self._build()
        if doc is not None:
            doc.subscribe(self._on_doc_event)
        self._on_brush_changed()
        self._on_field_changed()

    # -- widgets ------------------------------------------------------------------------------
    def _build(self) -> None:
        lay = QtWidgets.QVBoxLayout(self)
        lay.setContentsMargins(4, 4, 4, 4)
        self.caption = QtWidgets.QLabel(NO_FIELDS)
        self.caption.setWordWrap(True)
        lay.addWidget(self.caption)
        self.controls = SliceControls()
        self.controls.view_changed.connect(self.rebuild_view)
        self.controls.engine_changed.connect(self._on_engine_changed)
        lay.addWidget(self.controls)
        self.canvas = PhasorCanvas()
        lay.addWidget(self.canvas, 3)
        self.status = QtWidgets.QLabel("")
        self.status.setWordWrap(True)
        self.brush = BrushControls()
        self.brush.changed.connect(self._on_brush_changed)
        self.brush.field_changed.connect(self._on_field_changed)
        self.view = SliceView(self.canvas, self.controls, self.brush, self.status, self)
        self.worker = self.view.worker
        self.strokes = StrokeController(self, self)
        self.view.landed.connect(self._on_landed)
        self.print_box = PrintBox()
        self.progress_row = ProgressRow(lambda: self.worker.is_busy or self.print_box.exporting)
        self.progress_row.cancel_clicked.connect(self.cancel)
        self.worker.busy_changed.connect(self.progress_row.busy)
        self.worker.progress.connect(lambda _t, done, total: self.progress_row.set_progress(done, total))
        lay.addWidget(self.progress_row)
        lay.addWidget(self.status)
        lay.addWidget(self.brush)
        self.message = QtWidgets.QLabel("")
        self.message.setWordWrap(True)
        lay.addWidget(self.message)
        self.print_box.preview_lines.connect(self.preview_lines)
        self.print_box.message.connect(self.message.setText)
        self.print_box.progress.connect(self.progress_row.set_progress)
        self.print_box.running.connect(self.progress_row.busy)
        lay.addWidget(self.print_box)
        # the widgets tests and scripts reach for
        c, b = self.controls, self.brush
        self.axis_box, self.position_slider, self.display_box, self.engine_box = \
            c.axis_box, c.position_slider, c.display_box, c.engine_box
        self.position_label = c.position_label
        self.progress, self.cancel_button = self.progress_row.progress, self.progress_row.cancel_button
        for name in ("field_box", "radius_spin", "strength_spin", "falloff_box", "value_spin", "value_label",
                     "tilt_spin", "heading_check", "heading_spin", "depth_spin"):
            setattr(self, name, getattr(b, name))

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
        old = self.fields
        same_grid = (old is not None and fields is not None and fields_id == self.fields_id
                     and fields.shape == old.shape and np.array_equal(fields.lo, old.lo)
                     and np.array_equal(fields.hi, old.hi))
        if self.strokes.active is not None and not same_grid:
            self.canvas.abort_stroke()
        self.fields_id, self.noise_id = fields_id, noise_id
        if domain is None:
            domain = getattr(infill, "domain", None)
        self.session = None if fields is None else PhasorInfillSession(fields, infill, domain)
        self.pending = None
        self.print_box.set_infill(infill, noise_id, self.controls.engine)
        self._update_caption()
        if self.strokes.active is None:
            self.rebuild_view()
        # else: the earlier strokes' evaluation arrived mid-drag; the stroke goes on over
        # the same painted fields and the next evaluation redraws everything

    @property
    def fields(self) -> PhasorFields | None:
        """The evaluated fields (None before an evaluation)."""
        return None if self.session is None else self.session.fields

    @property
    def infill(self):
        return None if self.session is None else self.session.infill

    @property
    def domain(self):
        return None if self.session is None else self.session.domain

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
                    self.rebuild_view()
                self._update_caption()
            elif event in ("node_removed", "reset") and self.fields_id not in self.doc.nodes:
                self.set_context(self.doc, {}, None)
        except RuntimeError:   # the widget is gone; the document lives on
            pass

    # -- what is shown --------------------------------------------------------------------------
    @property
    def axis(self) -> str:
        return self.controls.axis

    @property
    def display(self) -> str:
        return self.controls.display

    @property
    def brush_field(self) -> str:
        return self.brush.field

    @property
    def position(self) -> float:
        """mm along the slice normal."""
        return self.controls.position(self.fields)

    @property
    def shown_fields(self) -> PhasorFields | None:
        """The fields drawn now: the stroke in progress, else painted-but-not-evaluated, else the outputs."""
        painted = self.strokes.fields
        if painted is not None:
            return painted
        return self.pending.fields if self.pending is not None else self.fields

    @property
    def shown_infill(self):
        return self.pending.infill if self.pending is not None and self.pending.infill is not None \
            else self.infill

    def shown_session(self) -> PhasorInfillSession:
        """The session a new stroke starts from: what is drawn now."""
        return PhasorInfillSession(self.shown_fields, self.shown_infill, self.domain)

    # the view's state, for tests and scripts
    plane = property(lambda self: self.view.plane)
    view_id = property(lambda self: self.view.view_id)
    shown_values = property(lambda self: self.view.shown_values)
    pattern_engine = property(lambda self: self.view.pattern_engine)

    def set_slice(self, axis: str, position: float | None = None) -> None:
        """Show the slice normal to ``axis`` at the scrub step nearest ``position`` mm."""
        self.controls.set_slice(axis, position, self.fields)
        self.rebuild_view()

    def set_display(self, key: str) -> None:
        self.controls.set_display(key)

    def rebuild_view(self) -> None:
        """New plane (axis, position or display changed, or new outputs): redraw all of it."""
        if self.strokes.active is not None:
            self.canvas.abort_stroke()   # a stroke lives on one slice; aborting redraws
            return
        self.view.rebuild(self.shown_fields, self.shown_infill, self.domain, self.paint_block_reason())

    def _on_engine_changed(self) -> None:
        self.print_box.engine = self.controls.engine
        self.rebuild_view()

    def cancel(self) -> None:
        """Stop the running slice evaluation or export."""
        if self.worker.is_busy:
            self.status.setText("slice evaluation cancelled: the picture is out of date")
        self.worker.cancel()
        self.print_box.cancel()

    # -- brush ------------------------------------------------------------------------------------
    def _on_field_changed(self) -> None:
        if self.display == "field" or self.shown_infill is None:
            self.rebuild_view()

    def _on_brush_changed(self) -> None:
        self.canvas.brush_radius = self.brush.radius
        error = self.brush_error()
        self.message.setText("" if error is None else f"<span style='color:#c0392b'>{error}</span>")
        if (self.brush_field == "F" and error is None and self.strokes.active is None
                and self.view.plane is not None and (self.display == "field" or self.shown_infill is None)
                and self.view.f_range_stale(self.shown_fields)):
            self.rebuild_view()   # the colour scale spans the fields and the brush value

    def make_stroke(self, points):
        """The brush's Stroke along ``points`` (k, 2) in-plane mm on the current slice;
        ValueError (the engine's message) for bad brush settings."""
        return self.brush.make_stroke(points, self.axis, self.position)

    def brush_error(self) -> str | None:
        """The engine's refusal of the current brush settings, or None."""
        return self.brush.error(self.axis, self.position)

    def paint_block_reason(self) -> str | None:
        if self.fields is None:
            return "painting needs evaluated phasor fields"
        if self.undo is None:
            return "painting is off: the dock has no undo history to record strokes"
        if self.doc is None or self.fields_id not in self.doc.nodes:
            return "the Phasor Fields node is gone"
        return None

    # -- the stroke controller's calls -------------------------------------------------------------
    def say(self, text: str) -> None:
        self.message.setText(text)

    def push_stroke(self, stroke) -> bool:
        """Push ONE SetParam appending ``stroke``; False (and the message) when refused."""
        self._own_push = True
        try:
            self.undo.push(SetParam(self.fields_id, "strokes", self._strokes() + [stroke.to_dict()]))
        except Exception as exc:   # refused by the document: nothing changed
            self.say(f"<span style='color:#c0392b'>not painted: {exc}</span>")
            self.rebuild_view()
            return False
        finally:
            self._own_push = False
        return True

    def stroke_committed(self, painted: PhasorInfillSession, infill) -> None:
        """The stroke is in the document: show ``painted`` (and the latest local infill) until evaluated."""
        self.pending = PhasorInfillSession(painted.fields, infill, self.domain)
        self._update_caption()
        self.say("")

    def _on_landed(self, job) -> None:
        if job.purpose == "final" and self.pending is not None and self.pending.fields is job.fields:
            self.pending = PhasorInfillSession(job.fields, job.infill, self.domain)

    # -- G-code -----------------------------------------------------------------------------------
    def preview_gcode(self, path) -> bool:
        """Read a G-code file, show its layers and emit `preview_lines`."""
        return self.print_box.preview_gcode(path)

    def export_gcode(self, path, **options) -> None:
        """Write the evaluated infill's G-code in a thread (``settings``, ``pixel``: see PrintBox)."""
        self.print_box.export_gcode(path, **options)

    def shutdown(self) -> None:
        """Stop the threads and stop following the document (the window is closing)."""
        if self.doc is not None:
            self.doc.unsubscribe(self._on_doc_event)
        self.worker.shutdown()
        self.print_box.shutdown()
