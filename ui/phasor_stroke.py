"""A brush stroke on the Phasor Infill dock's canvas: begin / extend / commit / abort.

A left drag on the slice is one stroke (napari's begin / commit / abort).
While dragging, the stroke so far is painted on the session the drag started
from (``PhasorInfillSession.apply_stroke``: the fields only) and only the
pixels whose samples read a changed cell are redrawn; a pattern display is
updated where the locally resampled and re-aligned kernels reach
(``PhasorInfillSession.update``, in the dock's slice worker).  The release
pushes ONE ``SetParam(fields node, "strokes", old + [stroke])`` (the dock's
`push_stroke`); Escape abandons the stroke.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from PySide6 import QtCore

MIN_STEP_PX = 3.0           # a drag adds a point after moving this many screen pixels


@dataclass
class ActiveStroke:
    """The drag in progress: the session it started from, the points so far (in-plane
    mm), the session painted with them, and the infill the last local update gave."""

    base: object
    points: list = field(default_factory=list)
    painted: object = None
    infill: object = None


class StrokeController(QtCore.QObject):
    """Turns the canvas's stroke signals into painted previews and one undo item.

    ``dock`` provides: ``canvas``, ``brush``, ``view`` (SliceView), ``axis``,
    ``position``, ``shown_session()``, ``paint_block_reason()``, ``say(text)``,
    ``push_stroke(stroke) -> bool``, ``stroke_committed(painted, infill)`` and
    ``rebuild_view()``.
    """

    def __init__(self, dock, parent=None):
        super().__init__(parent)
        self.dock = dock
        self.active: ActiveStroke | None = None
        canvas = dock.canvas
        canvas.strokeBegan.connect(self.began)
        canvas.strokeMoved.connect(self.moved)
        canvas.strokeEnded.connect(self.ended)
        canvas.strokeAborted.connect(self.aborted)
        dock.view.landed.connect(self._on_landed)

    @property
    def fields(self):
        """The fields painted by the stroke so far, or None."""
        s = self.active
        return None if s is None or s.painted is None else s.painted.fields

    def _stroke(self, points):
        return self.dock.brush.make_stroke(points, self.dock.axis, self.dock.position)

    # -- begin / extend -----------------------------------------------------------------------
    def began(self, u: float, v: float) -> None:
        d = self.dock
        error = d.brush.error(d.axis, d.position) or d.paint_block_reason()
        if error is not None:
            d.say(f"<span style='color:#c0392b'>not painted: {error}</span>")
            self.active = None
            d.canvas.abort_stroke()
            return
        self.active = ActiveStroke(d.shown_session(), [(u, v)])
        if not d.brush.follows_drag:
            self._paint_so_far()

    def moved(self, u: float, v: float) -> None:
        s = self.active
        if s is None:
            return
        lu, lv = s.points[-1]
        step = MIN_STEP_PX / max(self.dock.canvas._px_per_mm(), 1e-9)
        if math.hypot(u - lu, v - lv) < step:
            return
        s.points.append((u, v))
        self._paint_so_far()

    def _paint_so_far(self) -> None:
        """Paint the stroke so far on the session it started from; redraw what it changed."""
        s = self.active
        try:
            stroke = self._stroke(s.points)
        except ValueError:
            return  # a D stroke that has not moved yet has no direction
        s.painted = s.base.apply_stroke(stroke)
        if not s.painted.touched:
            return
        view = self.dock.view
        if view.shows_field():
            view.redraw_field_region(s.painted.fields, s.painted.painted_region())
        else:
            view.request_local_pattern(s.painted)

    def _on_landed(self, job) -> None:
        if job.purpose == "stroke" and self.active is not None:
            self.active.infill = job.infill

    # -- commit / abort -----------------------------------------------------------------------
    def ended(self, u: float, v: float) -> None:
        s, self.active = self.active, None
        if s is None:
            return
        d = self.dock
        if (u, v) != s.points[-1]:
            s.points.append((u, v))
        try:
            stroke = self._stroke(s.points)
        except ValueError as exc:
            d.say(f"<span style='color:#c0392b'>not painted: {exc}</span>")
            d.rebuild_view()
            return
        painted = s.base.apply_stroke(stroke)
        if not painted.touched:
            d.say("the stroke touched no cell of the fields")
            d.rebuild_view()
            return
        if not d.push_stroke(stroke):
            return
        d.stroke_committed(painted, s.infill)
        if d.view.shows_field():
            d.view.redraw_field_region(painted.fields, painted.painted_region())
        else:
            d.view.request_local_pattern(painted, purpose="final")

    def aborted(self) -> None:
        if self.active is None:
            return
        self.active = None
        self.dock.view.worker.cancel()
        self.dock.rebuild_view()
