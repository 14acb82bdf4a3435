"""Plots of the Surfaces dock, drawn with matplotlib inside the window.

* :class:`ConvergenceChart` -- a Surface solve's energy after each step
  (``SurfaceReport.details["energy_history"]``);
* :class:`LoopSchematic` -- the boundary loop projected on its best-fit
  plane: sliding segments dashed, fixed ones solid, loop vertices labelled
  with their chain and vertex, a vertex an error names ringed in red.

What is drawn comes from the engine (the report, ``boundary_schematic``);
this module only lays it out.  Both are `ui.lazy_plot.LazyPlot`: a new value
is kept at once (``history``, ``points2d``, ...) but the figure is drawn only
while the widget is visible, once per change, off the GUI thread (a hidden
dock's plots cost nothing; showing it draws what changed meanwhile).
"""

from __future__ import annotations

import numpy as np
from matplotlib.lines import Line2D

from .lazy_plot import LazyPlot, PlotKey

SEGMENT_COLOURS = ("#4e79a7", "#f28e2b", "#59a14f", "#e15759", "#b07aa1", "#76b7b2", "#edc948",
                   "#ff9da7", "#9c755f", "#bab0ac")
ERROR_COLOUR = "#e04040"
# What each solver's energy is (SurfaceReport.energy), as the chart's y label.
ENERGY_LABELS = {"direct": "shell energy", "mixed_minimal": "area (cell²)",
                 "conjugate": "contour energy (best)"}
STEP_LABELS = {"direct": "L-BFGS iteration", "mixed_minimal": "flow step",
               "conjugate": "energy evaluation"}


def plane_projection(points) -> np.ndarray:
    """(k, 2) coordinates of (k, 3) ``points`` in their best-fit plane (principal axes,
    centred on the centroid; the first axis along the largest spread)."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if len(p) == 0:
        return np.zeros((0, 2))
    c = p - p.mean(axis=0)
    _, _, vt = np.linalg.svd(c, full_matrices=False)
    axes = np.zeros((2, 3))
    axes[: min(2, len(vt))] = vt[:2]
    return c @ axes.T


class ConvergenceChart(LazyPlot):
    """Energy per solver step of one Surface solve; call :meth:`set_history`."""

    def __init__(self, parent=None):
        super().__init__(180, parent)
        self.history = np.zeros(0)
        self.set_history(None)

    def set_history(self, values, solver: str = "", *, note: str = "") -> None:
        """Show ``values`` (one energy per step) or, when None / empty, ``note``."""
        self.history = np.zeros(0) if values is None else np.asarray(values, dtype=np.float64).ravel()
        self._changed(PlotKey(self.history, solver, note), (self.history, solver, note))

    @staticmethod
    def _lay_out(ax, state) -> None:
        history, solver, note = state
        if history.size == 0:
            ax.set_axis_off()
            ax.text(0.5, 0.5, note or "no solve to show", ha="center", va="center",
                    transform=ax.transAxes, color="#888888", wrap=True)
        else:
            ax.set_axis_on()
            ax.plot(np.arange(history.size), history, "-", color=SEGMENT_COLOURS[0], lw=1.4)
            ax.plot([history.size - 1], [history[-1]], "o", color=SEGMENT_COLOURS[1], ms=5)
            positive = bool(np.all(history > 0))
            if positive and history.max() > 20.0 * history.min():
                ax.set_yscale("log")
            ax.set_xlabel(STEP_LABELS.get(solver, "step"))
            ax.set_ylabel(ENERGY_LABELS.get(solver, "energy"))
            ax.grid(True, alpha=0.3)


class LoopSchematic(LazyPlot):
    """The boundary loop of a Surface node in its best-fit plane; call :meth:`set_loop`."""

    def __init__(self, parent=None):
        super().__init__(200, parent)
        self.points2d = np.zeros((0, 2))
        self.sliding = np.zeros(0, dtype=bool)
        self.labels: list[str] = []
        self.marked: int | None = None
        self.set_loop(None)

    def set_loop(self, points, sliding=None, labels=None, segment_chain=None, *, marked=None,
                 note: str = "") -> None:
        """Draw the closed loop through ``points`` ((k, 3)).

        sliding : (k,) bool, segment i (vertex i to i + 1) slides
        labels : k vertex labels; segment_chain : (k,) int, colours segments by chain
        marked : loop vertex to ring in red (the one an error names), or None
        note : shown instead when ``points`` is None
        """
        if points is None or len(points) < 2:
            self.points2d, self.sliding, self.labels, self.marked = np.zeros((0, 2)), np.zeros(0, bool), [], None
            self._changed(PlotKey(None, note), (self.points2d, self.sliding, [], None, np.zeros(0, int), note))
            return
        q = plane_projection(points)
        k = len(q)
        self.points2d = q
        self.sliding = np.zeros(k, bool) if sliding is None else np.asarray(sliding, bool)
        self.labels = [str(i) for i in range(k)] if labels is None else list(labels)
        self.marked = marked if marked is not None and 0 <= marked < k else None
        chain = np.zeros(k, int) if segment_chain is None else np.asarray(segment_chain, int)
        self._changed(PlotKey(q, self.sliding, tuple(self.labels), self.marked, chain),
                      (q, self.sliding, self.labels, self.marked, chain, note))

    @staticmethod
    def _lay_out(ax, state) -> None:
        q, sliding, labels, marked, chain, note = state
        ax.set_axis_off()
        if len(q) < 2:
            ax.text(0.5, 0.5, note or "no boundary loop", ha="center", va="center",
                    transform=ax.transAxes, color="#888888", wrap=True)
            return
        k = len(q)
        for i in range(k):
            a, b = q[i], q[(i + 1) % k]
            ax.plot([a[0], b[0]], [a[1], b[1]], "--" if sliding[i] else "-",
                    color=SEGMENT_COLOURS[chain[i] % len(SEGMENT_COLOURS)], lw=2.0)
        ax.plot(q[:, 0], q[:, 1], "o", color="#333333", ms=4)
        centre = q.mean(axis=0)
        span = float(np.ptp(q, axis=0).max()) or 1.0
        for i, (p, text) in enumerate(zip(q, labels)):
            out = p - centre
            n = np.linalg.norm(out)
            d = out / n if n > 0 else np.array([0.0, 1.0])
            ax.text(*(p + d * 0.05 * span), text, fontsize=8,
                    ha="left" if d[0] > 0.3 else "right" if d[0] < -0.3 else "center",
                    va="bottom" if d[1] > 0.3 else "top" if d[1] < -0.3 else "center",
                    color=ERROR_COLOUR if i == marked else "#222222")
        if marked is not None:
            ax.plot([q[marked, 0]], [q[marked, 1]], "o", ms=13, mfc="none", mec=ERROR_COLOUR, mew=2)
        ax.set_aspect("equal", adjustable="datalim")
        ax.margins(0.22)
        ax.legend(handles=[Line2D([], [], ls="-", color="#555555", label="fixed"),
                           Line2D([], [], ls="--", color="#555555", label="sliding")],
                  loc="lower right", fontsize=7, frameon=False)
