"""Plots of a property study, drawn with matplotlib inside the window.

Three tabs, each a ``FigureCanvasQTAgg``:

* Properties -- ``E_avg/E_s`` against ``nu_avg``, one colour per hint group,
  with the group means as large crosses (the paper's Figs. 3B and 4A);
* Probabilities -- per group a pie of the requested block hints beside a pie of
  the realised block probabilities (mean over the group's samples), and the
  realised against the requested probability of every block (fig. S3A);
* Directional E -- the in-plane ``E(theta)/E_s`` of one sample, or the mean
  curve of a group, on polar axes.

What is drawn comes from ``engine.batch.study_summary``; this module only
lays it out.
"""

from __future__ import annotations

import numpy as np
from matplotlib.backends.backend_qtagg import FigureCanvasQTAgg
from matplotlib.figure import Figure
from matplotlib.patches import Patch
from PySide6 import QtCore, QtWidgets

from engine.batch.study_params import SAMPLE
from engine.batch.study_summary import directional_modulus, group_directional_modulus, group_study

from .tool_number import ToolNumber

GROUP_COLOURS = ("#4e79a7", "#f28e2b", "#59a14f", "#e15759", "#b07aa1", "#76b7b2", "#edc948",
                 "#ff9da7", "#9c755f", "#bab0ac")
MAX_PIE_GROUPS = 6      # more groups (a sweep) show the first few pies; fig. S3A shows them all
MAX_LEGEND_GROUPS = 10
N_ANGLES = 180


def group_colour(k: int) -> str:
    return GROUP_COLOURS[k % len(GROUP_COLOURS)]


def group_label(group) -> str:
    return f"{group.set + 1}: {group.hints_text or 'uniform'}"


def _canvas() -> FigureCanvasQTAgg:
    canvas = FigureCanvasQTAgg(Figure(figsize=(5, 4), layout="constrained"))
    canvas.setMinimumSize(240, 200)
    return canvas


class StudyPlots(QtWidgets.QWidget):
    """Scatter, pies and polar plot of a study's rows; call :meth:`show_rows`."""

    def __init__(self, parent: QtWidgets.QWidget | None = None):
        super().__init__(parent)
        self.groups: list = []
        self._scatter: list = []      # (group, PathCollection of its samples, of its mean)
        self._pies: list = []         # (group, requested wedges, realised wedges)
        self._polar_line = None

        self.tabs = QtWidgets.QTabWidget()
        self.scatter_canvas, self.pies_canvas, self.polar_canvas = _canvas(), _canvas(), _canvas()
        self.tabs.addTab(self.scatter_canvas, "Properties")
        self.tabs.addTab(self.pies_canvas, "Probabilities")

        self.group_box = QtWidgets.QComboBox()
        # the range follows the group's samples; a typed index outside it is refused, not clamped
        self.sample_spin = ToolNumber(SAMPLE, special=(-1, "group mean"))
        bar = QtWidgets.QHBoxLayout()
        bar.addWidget(QtWidgets.QLabel("Group"))
        bar.addWidget(self.group_box, 1)
        bar.addWidget(QtWidgets.QLabel("Sample"))
        bar.addWidget(self.sample_spin, 0, QtCore.Qt.AlignmentFlag.AlignTop)
        polar = QtWidgets.QWidget()
        lay = QtWidgets.QVBoxLayout(polar)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addLayout(bar)
        lay.addWidget(self.polar_canvas, 1)
        self.tabs.addTab(polar, "Directional E")

        outer = QtWidgets.QVBoxLayout(self)
        outer.setContentsMargins(0, 0, 0, 0)
        outer.addWidget(self.tabs)
        self.group_box.currentIndexChanged.connect(self._group_changed)
        self.sample_spin.valueChanged.connect(lambda _v: self._draw_polar())
        self.show_rows([])

    # ------------------------------------------------------------ data in

    def show_rows(self, rows: list) -> None:
        """Redraw every plot from study rows (``engine.batch.read_study``)."""
        self.groups = group_study(rows)
        keep = self.group_box.currentIndex()
        self.group_box.blockSignals(True)
        self.group_box.clear()
        for g in self.groups:
            self.group_box.addItem(group_label(g))
        self.group_box.setCurrentIndex(min(max(keep, 0), len(self.groups) - 1))
        self.group_box.blockSignals(False)
        self._update_sample_range()
        self._draw_scatter()
        self._draw_pies()
        self._draw_polar()

    # ------------------------------------------------------------ read back

    def scatter_points(self) -> list:
        """``(label, (n, 2) [E_avg/E_s, nu_avg])`` of each group, as drawn."""
        return [(group_label(g), np.asarray(pts.get_offsets(), dtype=float).reshape(-1, 2))
                for g, pts, _mean in self._scatter]

    def scatter_means(self) -> list:
        return [(group_label(g), np.asarray(mean.get_offsets(), dtype=float).reshape(-1, 2))
                for g, _pts, mean in self._scatter if mean is not None]

    def pie_fractions(self) -> list:
        """``(label, requested, realised)`` fractions of each pie, from its wedges' angles
        (realised is None for a group with no grown sample yet)."""
        def frac(wedges):
            return None if wedges is None else \
                np.array([(w.theta2 - w.theta1) / 360.0 for w in wedges])
        return [(group_label(g), frac(req), frac(real)) for g, req, real in self._pies]

    def polar_curve(self):
        """``(theta, E/E_s)`` of the drawn polar curve (closed: the first point repeated),
        or None."""
        if self._polar_line is None:
            return None
        t, r = self._polar_line.get_data()
        return np.asarray(t, dtype=float), np.asarray(r, dtype=float)

    # ------------------------------------------------------------ drawing

    def _draw_scatter(self) -> None:
        fig = self.scatter_canvas.figure
        fig.clear()
        ax = fig.add_subplot()
        self._scatter = []
        for k, g in enumerate(self.groups):
            c = group_colour(k)
            pts = ax.scatter(g.E, g.nu, s=14, alpha=0.65, color=c, linewidths=0,
                             label=f"{group_label(g)} ({g.n_ok})")
            mean = None
            if g.n_ok:
                mean = ax.scatter([g.E_mean], [g.nu_mean], s=110, marker="X", color=c,
                                  edgecolors="black", linewidths=0.8, zorder=3)
            self._scatter.append((g, pts, mean))
        ax.set_xlabel(r"$E_{avg}/E_s$")
        ax.set_ylabel(r"$\nu_{avg}$")
        ax.grid(True, alpha=0.3)
        if not self.groups:
            ax.text(0.5, 0.5, "no study rows yet", ha="center", va="center",
                    transform=ax.transAxes, color="grey")
        elif len(self.groups) <= MAX_LEGEND_GROUPS:
            ax.legend(fontsize="x-small", title="group: hints (ok samples); X = mean",
                      title_fontsize="x-small")
        self.scatter_canvas.draw_idle()

    def _draw_pies(self) -> None:
        fig = self.pies_canvas.figure
        fig.clear()
        self._pies = []
        shown = self.groups[:MAX_PIE_GROUPS]
        if not shown:
            ax = fig.add_subplot()
            ax.set_axis_off()
            ax.text(0.5, 0.5, "no study rows yet", ha="center", va="center", color="grey")
            self.pies_canvas.draw_idle()
            return
        blocks = shown[0].blocks
        colours = [GROUP_COLOURS[b % len(GROUP_COLOURS)] for b in range(len(blocks))]
        grid = fig.add_gridspec(len(shown), 3, width_ratios=(1, 1, 2))
        for row, g in enumerate(shown):
            req_ax, real_ax = fig.add_subplot(grid[row, 0]), fig.add_subplot(grid[row, 1])
            req, _ = req_ax.pie(g.requested, colors=colours, startangle=90, counterclock=False,
                                wedgeprops={"linewidth": 0.5, "edgecolor": "white"})
            req_ax.set_title(f"{g.set + 1}: requested", fontsize="x-small")
            real = None
            if np.all(np.isfinite(g.realised)):
                real, _ = real_ax.pie(g.realised, colors=colours, startangle=90,
                                      counterclock=False,
                                      wedgeprops={"linewidth": 0.5, "edgecolor": "white"})
                real_ax.set_title(f"realised (n={g.count('ok') + g.count('singular')})",
                                  fontsize="x-small")
            else:
                real_ax.set_axis_off()
                real_ax.text(0.5, 0.5, "no samples", ha="center", va="center", color="grey",
                             fontsize="x-small")
            self._pies.append((g, req, real))
        self._draw_realised_vs_requested(fig.add_subplot(grid[:, 2]), blocks, colours)
        fig.legend(handles=[Patch(facecolor=c) for c in colours], labels=list(blocks),
                   loc="outside lower center", ncols=min(len(blocks), 8), fontsize="x-small",
                   frameon=False)
        if len(self.groups) > len(shown):
            fig.suptitle(f"pies of the first {len(shown)} of {len(self.groups)} groups",
                         fontsize="x-small")
        self.pies_canvas.draw_idle()

    def _draw_realised_vs_requested(self, ax, blocks, colours) -> None:
        """fig. S3A: every group's realised against requested probability, per block."""
        req = np.array([g.requested for g in self.groups])
        real = np.array([g.realised for g in self.groups])
        for b, name in enumerate(blocks):
            ax.scatter(req[:, b], real[:, b], s=18, color=colours[b], label=name)
        ax.plot([0, 1], [0, 1], ls="--", lw=0.8, color="grey")
        ax.set_xlim(0, 1)
        ax.set_ylim(0, 1)
        ax.set_aspect("equal")
        ax.set_xlabel("requested", fontsize="small")
        ax.set_ylabel("realised", fontsize="small")
        ax.tick_params(labelsize="x-small")
        ax.grid(True, alpha=0.3)

    def _update_sample_range(self) -> None:
        g = self._current_group()
        top = (g.n_samples - 1) if g is not None else 0
        self.sample_spin.blockSignals(True)
        self.sample_spin.setRange(-1, max(top, 0))
        self.sample_spin.blockSignals(False)

    def _current_group(self):
        k = self.group_box.currentIndex()
        return self.groups[k] if 0 <= k < len(self.groups) else None

    def _group_changed(self, _index: int) -> None:
        self.sample_spin.blockSignals(True)
        self.sample_spin.setValue(-1)
        self.sample_spin.blockSignals(False)
        self._update_sample_range()
        self._draw_polar()

    def _draw_polar(self) -> None:
        fig = self.polar_canvas.figure
        fig.clear()
        ax = fig.add_subplot(projection="polar")
        self._polar_line = None
        g = self._current_group()
        k = self.group_box.currentIndex()
        if g is None:
            ax.set_title("no study rows yet", fontsize="small", color="grey")
            self.polar_canvas.draw_idle()
            return
        i = self.sample_spin.value()
        if i < 0:
            theta, e = group_directional_modulus(g, n=N_ANGLES)
            what = f"group {group_label(g)}: mean of {g.n_ok} samples"
        else:
            row = g.rows[min(i, g.n_samples - 1)]
            theta, e = directional_modulus(row, n=N_ANGLES)
            what = f"group {g.set + 1}, sample {row['index']} ({row['status']})"
        if np.all(np.isfinite(e)):
            (self._polar_line,) = ax.plot(np.append(theta, theta[0]), np.append(e, e[0]),
                                          color=group_colour(k), lw=1.6)
            ax.set_rlim(0, 1.08 * float(np.max(e)))
        else:
            ax.text(0.5, 0.5, "no stiffness (a mechanism, a failure or no samples yet)",
                    ha="center", va="center", transform=ax.transAxes, color="grey",
                    fontsize="x-small")
        ax.set_title(r"$E(\theta)/E_s$, " + what, fontsize="x-small")
        ax.tick_params(labelsize="x-small")
        self.polar_canvas.draw_idle()
