"""The three figures of a property study, laid out off the GUI thread.

Each is a `ui.lazy_plot.LazyPlot`: a new set of groups is kept at once but
drawn only while its tab is visible, once per change, in a worker thread
(the window's Studies dock costs nothing until it is looked at).

* :class:`ScatterFigure` -- ``E_avg/E_s`` against ``nu_avg``, one colour per
  hint group, the group means as large crosses (the paper's Figs. 3B and 4A);
* :class:`PiesFigure` -- per group a pie of the requested block hints beside
  a pie of the realised block probabilities (mean over the group's samples),
  and the realised against the requested probability of every block (fig. S3A);
* :class:`PolarFigure` -- the in-plane ``E(theta)/E_s`` of one sample, or the
  mean curve of a group, on polar axes.

Every artist a test reads back carries a gid (``points:k``, ``mean:k``,
``requested:k``, ``realised:k``, ``polar``), so what is read is what was drawn.
"""

from __future__ import annotations

import numpy as np
from matplotlib.patches import Patch

from engine.batch.study_summary import directional_modulus, group_directional_modulus

from .lazy_plot import LazyPlot, PlotKey

GROUP_COLOURS = ("#4e79a7", "#f28e2b", "#59a14f", "#e15759", "#b07aa1", "#76b7b2", "#edc948",
                 "#ff9da7", "#9c755f", "#bab0ac")
MAX_PIE_GROUPS = 6      # more groups (a sweep) show the first few pies; fig. S3A shows them all
MAX_LEGEND_GROUPS = 10
N_ANGLES = 180
MIN_HEIGHT = 200
NO_ROWS = "no study rows yet"


def group_colour(k: int) -> str:
    return GROUP_COLOURS[k % len(GROUP_COLOURS)]


def group_label(group) -> str:
    return f"{group.set + 1}: {group.hints_text or 'uniform'}"


class StudyFigure(LazyPlot):
    """A study figure: `set_state(key, state)` (a new key draws `state`); `artists(gid)`
    reads the drawn figure."""

    def __init__(self, parent=None):
        super().__init__(MIN_HEIGHT, parent)

    def set_state(self, key: tuple, state) -> None:
        self._changed(PlotKey(*key), state)

    def artists(self, gid: str) -> list:
        """The artists of the latest drawn figure named `gid` (drawn now if a change waits)."""
        self.ensure_drawn()
        return self.figure.findobj(lambda a: a.get_gid() == gid)


class ScatterFigure(StudyFigure):
    """State: the study's groups (``engine.batch.study_summary.group_study``)."""

    @staticmethod
    def _lay_out(ax, groups) -> None:
        for k, g in enumerate(groups):
            c = group_colour(k)
            pts = ax.scatter(g.E, g.nu, s=14, alpha=0.65, color=c, linewidths=0,
                             label=f"{group_label(g)} ({g.n_ok})")
            pts.set_gid(f"points:{k}")
            if g.n_ok:
                mean = ax.scatter([g.E_mean], [g.nu_mean], s=110, marker="X", color=c,
                                  edgecolors="black", linewidths=0.8, zorder=3)
                mean.set_gid(f"mean:{k}")
        ax.set_xlabel(r"$E_{avg}/E_s$")
        ax.set_ylabel(r"$\nu_{avg}$")
        ax.grid(True, alpha=0.3)
        if not groups:
            ax.text(0.5, 0.5, NO_ROWS, ha="center", va="center", transform=ax.transAxes, color="grey")
        elif len(groups) <= MAX_LEGEND_GROUPS:
            ax.legend(fontsize="x-small", title="group: hints (ok samples); X = mean",
                      title_fontsize="x-small")


class PiesFigure(StudyFigure):
    """State: the study's groups; the first `MAX_PIE_GROUPS` get pies."""

    @staticmethod
    def _lay_out(ax, groups) -> None:
        fig = ax.figure
        shown = groups[:MAX_PIE_GROUPS]
        if not shown:
            ax.set_axis_off()
            ax.text(0.5, 0.5, NO_ROWS, ha="center", va="center", color="grey")
            return
        fig.delaxes(ax)
        blocks = shown[0].blocks
        colours = [GROUP_COLOURS[b % len(GROUP_COLOURS)] for b in range(len(blocks))]
        grid = fig.add_gridspec(len(shown), 3, width_ratios=(1, 1, 2))
        wedge_style = {"linewidth": 0.5, "edgecolor": "white"}
        for row, g in enumerate(shown):
            req_ax, real_ax = fig.add_subplot(grid[row, 0]), fig.add_subplot(grid[row, 1])
            req, _ = req_ax.pie(g.requested, colors=colours, startangle=90, counterclock=False,
                                wedgeprops=wedge_style)
            for w in req:
                w.set_gid(f"requested:{row}")
            req_ax.set_title(f"{g.set + 1}: requested", fontsize="x-small")
            if np.all(np.isfinite(g.realised)):
                real, _ = real_ax.pie(g.realised, colors=colours, startangle=90, counterclock=False,
                                      wedgeprops=wedge_style)
                for w in real:
                    w.set_gid(f"realised:{row}")
                real_ax.set_title(f"realised (n={g.count('ok') + g.count('singular')})", fontsize="x-small")
            else:
                real_ax.set_axis_off()
                real_ax.text(0.5, 0.5, "no samples", ha="center", va="center", color="grey",
                             fontsize="x-small")
        _realised_vs_requested(fig.add_subplot(grid[:, 2]), groups, blocks, colours)
        fig.legend(handles=[Patch(facecolor=c) for c in colours], labels=list(blocks),
                   loc="outside lower center", ncols=min(len(blocks), 8), fontsize="x-small",
                   frameon=False)
        if len(groups) > len(shown):
            fig.suptitle(f"pies of the first {len(shown)} of {len(groups)} groups", fontsize="x-small")


def _realised_vs_requested(ax, groups, blocks, colours) -> None:
    """fig. S3A: every group's realised against requested probability, per block."""
    req = np.array([g.requested for g in groups])
    real = np.array([g.realised for g in groups])
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


class PolarFigure(StudyFigure):
    """State: (group or None, its index, sample index or -1 for the group mean)."""

    @staticmethod
    def _lay_out(ax, state) -> None:
        g, k, i = state
        fig = ax.figure
        fig.delaxes(ax)
        ax = fig.add_subplot(projection="polar")
        if g is None:
            ax.set_title(NO_ROWS, fontsize="small", color="grey")
            return
        if i < 0:
            theta, e = group_directional_modulus(g, n=N_ANGLES)
            what = f"group {group_label(g)}: mean of {g.n_ok} samples"
        else:
            row = g.rows[min(i, g.n_samples - 1)]
            theta, e = directional_modulus(row, n=N_ANGLES)
            what = f"group {g.set + 1}, sample {row['index']} ({row['status']})"
        if np.all(np.isfinite(e)):
            (line,) = ax.plot(np.append(theta, theta[0]), np.append(e, e[0]), color=group_colour(k), lw=1.6)
            line.set_gid("polar")
            ax.set_rlim(0, 1.08 * float(np.max(e)))
        else:
            ax.text(0.5, 0.5, "no stiffness (a mechanism, a failure or no samples yet)",
                    ha="center", va="center", transform=ax.transAxes, color="grey", fontsize="x-small")
        ax.set_title(r"$E(\theta)/E_s$, " + what, fontsize="x-small")
        ax.tick_params(labelsize="x-small")
