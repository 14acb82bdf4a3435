"""The RD dock's brush: a drag on the picture becomes ONE edit of the document.

`RDBrushTool` binds the brush settings (`ui.rd_canvas.BrushBox`) and the
canvas's stroke signals: erase or draw appends one edit ``{mode, centres,
radius}`` in growth-grid cells to the RDGrow node's ``edits``; mark solid
appends one stroke of stamps ``{centre, radius, value}`` in field cells to
the RDFields node's ``gamma_c``; each is one ``SetParam`` on the undo stack
(through the dock's ``_push``).  The node's own parameter check refuses bad
brush settings before anything is painted.
"""

from __future__ import annotations

import numpy as np
from PySide6 import QtCore

from engine.rd.preview import slice_point, stroke_centres

MIN_STEP_PX = 2.0        # a drag records a point after moving this many screen pixels
MAX_MARKS = 600          # stamps outlined on the picture at most


class RDBrushTool(QtCore.QObject):
    """Strokes on ``panel.canvas`` with the settings of ``panel.brush``.

    panel : the RD dock (its chain's nodes, grids, slice, canvas, message line, ``_push``)
    """

    def __init__(self, panel):
        super().__init__(panel)
        self.panel = panel
        self._stroke: list | None = None
        canvas = panel.canvas
        canvas.strokeBegan.connect(self._on_began)
        canvas.strokeMoved.connect(self._on_moved)
        canvas.strokeEnded.connect(self._on_ended)
        canvas.strokeAborted.connect(self._on_aborted)
        panel.brush.changed.connect(self.on_brush_changed)

    @property
    def brush_mode(self) -> str:
        return self.panel.brush.mode

    def target(self) -> tuple:
        """(node kind, parameter) a stroke of the current mode appends to."""
        return ("RDFields", "gamma_c") if self.brush_mode == "solid" else ("RDGrow", "edits")

    def _cells_per_view(self) -> np.ndarray:
        """(d,) factors from view-grid cells to the brush target's cells, (x, y[, z]) order."""
        grid = np.array(self.panel.view_grid()[::-1], float)
        if self.brush_mode != "solid":
            return np.ones_like(grid)
        return np.array(self.panel.fields.grid_shape[::-1], float) / grid

    def brush_error(self) -> str | None:
        """The node's refusal of the current brush settings (as an item it would store), or None."""
        from engine.graph.errors import ParamError
        from engine.graph.node import node_type

        kind, name = self.target()
        r = self.panel.radius_spin.value()
        d = len(self.panel.view_grid() or (0, 0))
        if self.brush_mode == "solid":
            item = [[{"centre": [0.5] * d, "radius": r, "value": self.panel.value_spin.value()}]]
        else:
            item = [{"mode": self.brush_mode, "centre": [0.5] * d, "radius": r}]
        try:
            node_type(kind).param(name).coerce(item)
        except (ParamError, ValueError) as exc:
            return str(exc)
        return None

    def paint_block_reason(self) -> str | None:
        """Why painting is off now, or None when it is on."""
        kind, _ = self.target()
        if self.panel.undo is None:
            return "painting is off: the dock has no undo history to record strokes"
        if self.panel.node_of(kind) is None:
            return f"no {kind} node in this chain to paint on"
        if self.panel.view_grid() is None or self.panel.fields is None:
            return "painting needs evaluated RD fields: evaluate the graph"
        return None

    def on_brush_changed(self) -> None:
        self.panel.canvas.brush_mode = self.brush_mode
        r = self.panel.radius_spin.value()
        if self.brush_mode == "solid" and self.panel.fields is not None and self.panel.view_grid() is not None:
            r = r / float(self._cells_per_view()[0])
        self.panel.canvas.brush_radius = max(r, 0.0)
        error = self.brush_error() if self.panel.view_grid() is not None else None
        self.panel.message.setText("" if error is None else f"<span style='color:#c0392b'>{error}</span>")
        if self.panel.view_grid() is not None:
            reason = self.paint_block_reason()
            self.panel.canvas.set_painting(reason is None)
            self.panel.canvas.setToolTip(reason or "")
        self.update_marks()

    def _view_point(self, u: float, v: float) -> np.ndarray:
        """(x, y[, z]) in view-grid cells of the in-plane point (u, v) of the current slice."""
        return slice_point(u, v, self.panel.axis, self.panel.index)

    def _on_began(self, u: float, v: float) -> None:
        error = self.brush_error() or self.paint_block_reason()
        if error is not None:
            self.panel.message.setText(f"<span style='color:#c0392b'>not painted: {error}</span>")
            self._stroke = None
            self.panel.canvas.abort_stroke()
            return
        self._stroke = [(u, v)]
        self.panel.canvas.set_trail(np.array(self._stroke))

    def _on_moved(self, u: float, v: float) -> None:
        if self._stroke is None:
            return
        lu, lv = self._stroke[-1]
        if np.hypot(u - lu, v - lv) * self.panel.canvas._px_per_mm() < MIN_STEP_PX:
            return
        self._stroke.append((u, v))
        self.panel.canvas.set_trail(stroke_centres(self._stroke, max(self.panel.canvas.brush_radius, 1e-3)))

    def _on_aborted(self) -> None:
        self._stroke = None
        self.panel.canvas.set_trail(None)
        self.panel.redraw()

    def _on_ended(self, u: float, v: float) -> None:
        points, self._stroke = self._stroke, None
        self.panel.canvas.set_trail(None)
        if points is None:
            return
        if (u, v) != points[-1]:
            points.append((u, v))
        kind, name = self.target()
        node = self.panel.node_of(kind)
        r = float(self.panel.radius_spin.value())
        cells = np.array([self._view_point(pu, pv) for pu, pv in points]) * self._cells_per_view()
        centres = np.round(stroke_centres(cells, r), 4).tolist()
        old = list(node.params.get(name, []))
        if self.brush_mode == "solid":
            level = float(self.panel.value_spin.value())
            value = old + [[{"centre": c, "radius": r, "value": level} for c in centres]]
        else:
            value = old + [{"mode": self.brush_mode, "centres": centres, "radius": r}]
        before = self.panel.data()
        if not self.panel.push_param(node.id, name, value):
            self.panel.redraw()
            return
        self.panel.before = before
        what = "solid region marked" if self.brush_mode == "solid" else f"{self.brush_mode} stroke added"
        self.panel.message.setText(f"{what} ({len(centres)} stamps); evaluate to regrow")
        self.panel.redraw()

    def update_marks(self) -> None:
        """Outline the stamps in the document (view-grid cells) where they cross the slice."""
        grid = self.panel.view_grid()
        if grid is None or self.panel.fields is None:
            self.panel.canvas.set_marks([])
            return
        grow, fnode = self.panel.node_of("RDGrow"), self.panel.node_of("RDFields")
        to_view = np.array(grid[::-1], float) / np.array(self.panel.fields.grid_shape[::-1], float)
        items = []
        for e in grow.params.get("edits", []) if grow is not None else ():
            items += [(p, float(e["radius"]), e["mode"]) for p in ([e["centre"]] if "centre" in e else e["centres"])]
        for stroke in fnode.params.get("gamma_c", []) if fnode is not None else ():
            items += [(np.asarray(st["centre"]) * to_view, float(st["radius"]) * to_view[0], "solid")
                      for st in stroke if len(st["centre"]) == len(grid)]
        self.panel.canvas.set_stamps(items[-MAX_MARKS:], self.panel.axis, self.panel.index)
