"""Plots of a property study in the window: three tabs of `ui.study_figures`.

* Properties -- ``E_avg/E_s`` against ``nu_avg`` per hint group (Figs. 3B, 4A);
* Probabilities -- requested against realised block probabilities (fig. S3A);
* Directional E -- ``E(theta)/E_s`` of one sample or a group's mean, with the
  group and sample chosen above the plot.

The figures are drawn off the GUI thread and only while their tab shows
(`ui.lazy_plot`); the read-back methods (tests) draw what waits and read the
drawn artists.  What is drawn comes from ``engine.batch.study_summary``.
"""

from __future__ import annotations

import numpy as np
from PySide6 import QtCore, QtWidgets

from engine.batch.study_params import SAMPLE
from engine.batch.study_summary import group_study

from .study_figures import MAX_PIE_GROUPS, PiesFigure, PolarFigure, ScatterFigure, group_label
from .tool_number import ToolNumber


class StudyPlots(QtWidgets.QWidget):
    """Scatter, pies and polar plot of a study's rows; call :meth:`show_rows`."""

    def __init__(self, parent: QtWidgets.QWidget | None = None):
        super().__init__(parent)
        self.groups: list = []
        self._version = 0             # one per `show_rows`: what every figure's key starts with

        self.tabs = QtWidgets.QTabWidget()
        self.scatter_canvas, self.pies_canvas, self.polar_canvas = ScatterFigure(), PiesFigure(), PolarFigure()
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
        self._version += 1
        self.scatter_canvas.set_state((self._version,), self.groups)
        self.pies_canvas.set_state((self._version,), self.groups)
        self._draw_polar()

    # ------------------------------------------------------------ read back

    def scatter_points(self) -> list:
        """``(label, (n, 2) [E_avg/E_s, nu_avg])`` of each group, as drawn."""
        return [(group_label(g), _offsets(self.scatter_canvas.artists(f"points:{k}")))
                for k, g in enumerate(self.groups)]

    def scatter_means(self) -> list:
        """``(label, (1, 2) mean)`` of each group with ok samples, as drawn."""
        means = [(group_label(g), self.scatter_canvas.artists(f"mean:{k}")) for k, g in enumerate(self.groups)]
        return [(label, _offsets(found)) for label, found in means if found]

    def pie_fractions(self) -> list:
        """``(label, requested, realised)`` fractions of each pie, from its wedges' angles
        (realised is None for a group with no grown sample yet)."""
        def frac(name: str):
            wedges = self.pies_canvas.artists(name)
            return np.array([(w.theta2 - w.theta1) / 360.0 for w in wedges]) if wedges else None
        return [(group_label(g), frac(f"requested:{k}"), frac(f"realised:{k}"))
                for k, g in enumerate(self.groups[:MAX_PIE_GROUPS])]

    def polar_curve(self):
        """``(theta, E/E_s)`` of the drawn polar curve (closed: the first point repeated),
        or None."""
        found = self.polar_canvas.artists("polar")
        if not found:
            return None
        t, r = found[0].get_data()
        return np.asarray(t, dtype=float), np.asarray(r, dtype=float)

    # ------------------------------------------------------------ drawing

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
        k, i = self.group_box.currentIndex(), self.sample_spin.value()
        self.polar_canvas.set_state((self._version, k, i), (self._current_group(), k, i))

    def shutdown(self) -> None:
        """Stop the figures' draw threads (the window is closing)."""
        for canvas in (self.scatter_canvas, self.pies_canvas, self.polar_canvas):
            canvas.shutdown()


def _offsets(collections: list) -> np.ndarray:
    """(n, 2) points of the first of `collections` (empty if none)."""
    if not collections:
        return np.zeros((0, 2))
    return np.asarray(collections[0].get_offsets(), dtype=float).reshape(-1, 2)
