"""What the Phasor Infill dock's canvas shows, and the slice requests behind it.

`SliceView` turns the dock's state (the fields and infill shown, the slice
controls, the brush's field) into the canvas's picture: the painted field
drawn at once on the GUI thread (a sample of the fields is cheap), the
pattern images (diamonds, p_v, singularity) computed by a `SliceRunner`
(``PhasorInfillSession.slice``) and drawn when they land, whole or in the
pixel rectangle a local update changed.  It holds no method logic: the
session computes, the canvas draws.
"""

from __future__ import annotations

import numpy as np
from PySide6 import QtCore

from engine.phasor.preview import (direction_glyphs, direction_hue, domain_slice, field_slice, mask_outline,
                                   plane_extent, region_pixel_rect, slice_plane, sub_plane, view_pixels)
from engine.phasor.strokes import PLANE_AXES

from .phasor_canvas import apply_lut, colour_lut
from .phasor_controls import DISPLAYS
from .phasor_worker import SliceJob, SliceRunner

S_SHOWN = (0.0, 4.0)        # heat-map range of S; the paper's threshold q = 2 sits mid-scale
GLYPHS = 16                 # D glyphs along the longer side
DIAMOND_RGB = np.array([[238, 236, 228], [38, 40, 48]], np.uint8)
OUTSIDE_DIM = 0.45          # pattern pixels outside the part are blended towards grey


class SliceView(QtCore.QObject):
    """The canvas's picture of one slice.

    canvas : PhasorCanvas; controls : SliceControls; brush : BrushControls;
    status : QLabel for what made the picture

    Signals
    -------
    landed(job) : a pattern job of the current view finished (``job.infill`` is
        the infill it sliced, after its ``prepare``)
    """

    landed = QtCore.Signal(object)

    def __init__(self, canvas, controls, brush, status, parent=None):
        super().__init__(parent)
        self.canvas, self.controls, self.brush, self.status = canvas, controls, brush, status
        self.worker = SliceRunner(self)
        self.worker.finished.connect(self._on_pattern)
        self.worker.failed.connect(self._on_pattern_failed)
        self.plane = None
        self.view_id = 0
        self.shown_values: np.ndarray | None = None   # what the picture shows, (H, W[, 3])
        self.pattern_engine = ""
        self.infill = None           # the infill of the current view (None: field only)
        self._inside: np.ndarray | None = None
        self._f_range = (0.0, 1.0)
        self._view_ready = False     # the pattern of this view has arrived once

    @property
    def display(self) -> str:
        return self.controls.display

    def shows_field(self) -> bool:
        """The picture is the painted field (chosen, or no infill to show a pattern of)."""
        return self.display == "field" or self.infill is None

    # -- the whole view -----------------------------------------------------------------------
    def clear(self) -> None:
        self.plane = None
        self.shown_values = None
        self.canvas.set_image(None)
        self.canvas.set_outline(None)
        self.canvas.set_glyphs(None, None, 0.0)
        self.canvas.set_scale(None)
        self.canvas.set_painting(False)
        self.controls.position_label.setText("")

    def rebuild(self, fields, infill, domain, block_reason: str | None) -> None:
        """A new plane (axis, position or display changed, or new outputs): draw all of it."""
        self.view_id += 1
        self.worker.cancel()
        self.infill = infill
        if fields is None:
            self.clear()
            return
        axis, position = self.controls.axis, self.controls.position(fields)
        self.plane = slice_plane(fields.lo, fields.hi, axis, position, max_pixels=view_pixels(fields))
        u, v, _ = PLANE_AXES[axis]
        self.canvas.axis_names = ("xyz"[u], "xyz"[v])
        self.controls.position_label.setText(f"{axis} = {position:.3g} mm")
        inside = domain_slice(domain, self.plane)
        self._inside = inside
        ext = plane_extent(self.plane)
        self.canvas.set_outline(None if inside is None else mask_outline(inside, ext))
        self.canvas.set_painting(block_reason is None)
        self.canvas.setToolTip(block_reason or "")
        self.status.setText("")
        if self.shows_field():
            self.draw_field(fields, ext)
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
        self.worker.request(SliceJob(self.display, self.plane, infill, engine=self.controls.engine,
                                     view=self.view_id))

    # -- the painted field --------------------------------------------------------------------
    def wanted_f_range(self, fields) -> tuple:
        """F colour range: the fields' whole range and the brush value."""
        lo, hi = fields.min_frequency(), fields.max_frequency()
        value = self.brush.value
        if self.brush.field == "F" and value > 0:
            lo, hi = min(lo, value), max(hi, value)
        return (lo, hi) if hi - lo > 1e-9 else (0.9 * lo, 1.1 * hi + 1e-9)

    def f_range_stale(self, fields) -> bool:
        """The F colour scale no longer spans the fields and the brush value."""
        return self.wanted_f_range(fields) != self._f_range

    def _field_scale(self, fields) -> None:
        name = self.brush.field
        if name == "F":
            self._f_range = self.wanted_f_range(fields)
            self.canvas.set_scale(colour_lut("viridis"), *self._f_range, "F cells/mm")
        elif name == "Gamma":
            self.canvas.set_scale(colour_lut("plasma"), 0.0, 90.0, "Gamma °")
        else:
            self.canvas.set_scale(None)

    def _field_rgb(self, values: np.ndarray) -> np.ndarray:
        name = self.brush.field
        if name == "F":
            return apply_lut(values, *self._f_range, colour_lut("viridis"))
        if name == "Gamma":
            return apply_lut(np.degrees(values), 0.0, 90.0, colour_lut("plasma"))
        return direction_hue(values, self.controls.axis)

    def draw_field(self, fields, ext) -> None:
        self._field_scale(fields)
        self.shown_values = field_slice(fields, self.brush.field, self.plane)
        self.canvas.set_image(self._field_rgb(self.shown_values), ext)
        self._draw_glyphs(fields)

    def _draw_glyphs(self, fields) -> None:
        if self.brush.field != "D" or self.display != "field" and self.infill is not None:
            self.canvas.set_glyphs(None, None, 0.0)
            return
        axis = self.controls.axis
        centres, vectors, _ = direction_glyphs(fields, axis, self.controls.position(fields), count=GLYPHS)
        ext = plane_extent(self.plane)
        spacing = float(np.max(ext[:, 1] - ext[:, 0])) / GLYPHS
        self.canvas.set_glyphs(centres, vectors, 0.8 * spacing)

    def redraw_field_region(self, fields, region) -> None:
        """Sample ``fields`` again where the box ``region`` ((3,), (3,) mm) meets the plane."""
        rect = region_pixel_rect(self.plane, region)
        if rect is None:
            return
        r0, r1, c0, c1 = rect
        part = field_slice(fields, self.brush.field, sub_plane(self.plane, (r0, r1), (c0, c1)))
        self.shown_values[r0:r1, c0:c1] = part
        self.canvas.update_region(self._field_rgb(part), r0, c0)
        if self.brush.field == "D":
            self._draw_glyphs(fields)

    # -- the pattern --------------------------------------------------------------------------
    def request_local_pattern(self, painted, purpose: str = "stroke") -> None:
        """Bring ``painted`` (a PhasorInfillSession whose fields were repainted) up to
        date by the local update, then evaluate the pattern where it changed, in the
        worker; a newer request replaces a waiting one but lets the running one land."""
        plane, whole = self.plane, not self._view_ready

        def prepare(progress):
            infill = painted.update(progress=progress).infill
            if whole:   # the view's own picture never arrived (superseded): draw all of it
                return infill, (0, plane.shape[0], 0, plane.shape[1])
            return infill, region_pixel_rect(plane, infill.changed_region)

        self.worker.request(SliceJob(self.display, plane, painted.infill, engine=self.controls.engine,
                                     prepare=prepare, view=self.view_id, purpose=purpose,
                                     fields=painted.fields), supersede=False)

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

    def _on_pattern(self, _task, job: SliceJob) -> None:
        if job.view != self.view_id or job.show != self.display or self.shown_values is None:
            return  # an older view's answer
        self.landed.emit(job)
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

    def _on_pattern_failed(self, task, message: str) -> None:
        job = task.data
        if job.view == self.view_id:
            what = "pattern preview while painting" if job.prepare is not None else "slice"
            self.status.setText(f"{what} failed: {message}")
