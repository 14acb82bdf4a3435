"""The Implicit Media dock's particle size histogram (a `LazyPlot`: drawn off the GUI thread,
only while shown and only when the sizes changed)."""

from __future__ import annotations

import numpy as np

from .lazy_plot import LazyPlot, PlotKey

BINS = 30


class SizeHistogram(LazyPlot):
    """Particle sizes (mm) of the suspension shown; call :meth:`set_sizes`."""

    def __init__(self, parent=None):
        super().__init__(150, parent)
        self.sizes = np.zeros(0)
        self.set_sizes(None)

    def set_sizes(self, sizes, note: str = "") -> None:
        """Show a histogram of `sizes`, or `note` when there are none."""
        self.sizes = np.zeros(0) if sizes is None else np.asarray(sizes, dtype=np.float64).ravel()
        self._changed(PlotKey(self.sizes, note), (self.sizes, note))

    @staticmethod
    def _lay_out(ax, state) -> None:
        sizes, note = state
        if sizes.size == 0:
            ax.set_axis_off()
            ax.text(0.5, 0.5, note or "no particles in the view box", ha="center", va="center",
                    transform=ax.transAxes, color="#888888", wrap=True)
            return
        ax.hist(sizes, bins=BINS, color="#d08850", edgecolor="#7a4a25", linewidth=0.5)
        ax.axvline(float(sizes.mean()), color="#444444", lw=1.0, ls="--")
        ax.set_xlabel(f"particle size (mm) · {sizes.size} particles · mean {sizes.mean():.4g}")
        ax.set_ylabel("count")
        ax.grid(True, alpha=0.3)
