"""A matplotlib figure a dock shows without drawing it on the GUI thread.

:class:`LazyPlot` keeps what it should show (a *state*, captured when it
changes) and draws it

* only while the widget is visible (a hidden dock's plot costs nothing; it is
  drawn when it is shown, if it changed meanwhile),
* only when the state changed (a *key* compared by value) or the widget's size did,
* off the GUI thread: a `ui.task_runner.TaskRunner` task lays the figure out
  and renders it with matplotlib's Agg canvas into an image, which the widget
  then paints (a burst of changes draws only the last: a waiting draw is
  replaced by a newer one).

``draws`` counts the draws asked for because the state changed, ``size_draws``
those for a new size only, ``drawn`` those that landed; ``figure`` and
``axes`` are the latest finished figure's (read them after :meth:`ensure_drawn`).
Subclasses implement ``_lay_out(ax, state)``, run in the worker thread on a
figure nobody else touches.
"""

from __future__ import annotations

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from PySide6 import QtCore, QtGui, QtWidgets

from .task_runner import TaskRunner

DPI = 100.0


def _same(a, b) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return a is b or (a is not None and b is not None and np.shape(a) == np.shape(b)
                          and np.array_equal(a, b))
    return a == b


class PlotKey:
    """What a plot shows, compared by value (arrays with numpy)."""

    def __init__(self, *parts):
        self.parts = parts

    def __eq__(self, other):
        return (isinstance(other, PlotKey) and len(other.parts) == len(self.parts)
                and all(_same(a, b) for a, b in zip(self.parts, other.parts)))

    __hash__ = None


def render_figure(lay_out, state, width: int, height: int, ratio: float):
    """(figure, axes, RGBA bytes, pixel width, pixel height): `lay_out(ax, state)` on a new
    constrained-layout figure of `width` x `height` logical pixels, rendered by Agg."""
    figure = Figure(figsize=(width / DPI, height / DPI), dpi=DPI * ratio, layout="constrained")
    canvas = FigureCanvasAgg(figure)
    axes = figure.add_subplot(111)
    lay_out(axes, state)
    canvas.draw()
    w, h = canvas.get_width_height(physical=True)
    return figure, axes, bytes(canvas.buffer_rgba()), w, h


class LazyPlot(QtWidgets.QWidget):
    """Shows a figure drawn off the GUI thread, only while visible and after a change."""

    def __init__(self, min_height: int, parent=None):
        super().__init__(parent)
        self.setMinimumSize(220, min_height)
        self.setSizePolicy(QtWidgets.QSizePolicy.Policy.Expanding, QtWidgets.QSizePolicy.Policy.Expanding)
        self.draws = 0
        self.size_draws = 0
        self.drawn = 0
        self.figure = Figure(figsize=(4, 3))
        self.axes = self.figure.add_subplot(111)
        self.image: QtGui.QImage | None = None
        self._key = None
        self._state = None
        self._dirty = False
        self._drawn_size: tuple[int, int] | None = None
        self._latest = None                 # the newest draw task: older results are dropped
        self.runner = TaskRunner(self)
        self.runner.finished.connect(self._on_drawn)
        self._soon = QtCore.QTimer(self)    # a shown / resized widget draws once its layout settled
        self._soon.setSingleShot(True)
        self._soon.setInterval(0)
        self._soon.timeout.connect(self._draw_if_needed)

    # -- changes --------------------------------------------------------------------------------
    def _changed(self, key, state) -> None:
        """Show `state` (drawn by `_lay_out`), named by `key` (equal key: nothing to redraw)."""
        if key == self._key and self._state is not None:
            return
        self._key, self._state, self._dirty = key, state, True
        if self.isVisible():
            self._soon.start()

    def _lay_out(self, ax, state) -> None:  # pragma: no cover - subclasses
        raise NotImplementedError

    def _draw_if_needed(self) -> None:
        if self.isVisible() and (self._dirty or (self._state is not None and self._drawn_size != self._size())):
            self._draw()

    def _draw(self) -> None:
        if self._dirty:
            self.draws += 1
        else:
            self.size_draws += 1
        self._dirty = False
        size = self._drawn_size = self._size()
        ratio = float(self.devicePixelRatioF()) or 1.0
        lay_out, state = self._lay_out, self._state
        self._latest = self.runner.submit(
            lambda task: render_figure(lay_out, state, size[0], size[1], ratio), data=ratio)

    def _on_drawn(self, task, result) -> None:
        if task is not self._latest:
            return                          # a newer draw follows
        figure, axes, data, w, h = result
        image = QtGui.QImage(data, w, h, 4 * w, QtGui.QImage.Format.Format_RGBA8888).copy()
        image.setDevicePixelRatio(task.data)
        self.figure, self.axes, self.image = figure, axes, image
        self.drawn += 1
        self.update()

    def ensure_drawn(self, timeout_ms: int = 30000) -> None:
        """Draw now if a change waits (even hidden), and wait for the draw to land."""
        self._soon.stop()
        if self._dirty:
            self._draw()
        self.runner.wait_idle(timeout_ms)
        QtCore.QCoreApplication.sendPostedEvents()
        QtWidgets.QApplication.processEvents()

    def shutdown(self) -> None:
        self._soon.stop()
        self.runner.shutdown()

    # -- Qt ----------------------------------------------------------------------------------------
    def showEvent(self, event: QtGui.QShowEvent) -> None:
        super().showEvent(event)
        self._soon.start()

    def resizeEvent(self, event: QtGui.QResizeEvent) -> None:
        super().resizeEvent(event)
        if self.isVisible():
            self._soon.start()

    def _size(self) -> tuple[int, int]:
        return (max(self.width(), 50), max(self.height(), 50))

    def paintEvent(self, event: QtGui.QPaintEvent) -> None:
        painter = QtGui.QPainter(self)
        painter.fillRect(self.rect(), QtGui.QColor("white"))
        if self.image is not None:
            painter.drawImage(QtCore.QRectF(self.rect()), self.image)
        painter.end()
