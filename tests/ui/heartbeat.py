"""A GUI-thread heartbeat for the responsiveness tests: they count its ticks, never time."""

from __future__ import annotations

from PySide6 import QtCore


class Heartbeat:
    """Ticks of a 20 ms timer on the GUI thread."""

    def __init__(self):
        self.ticks = 0
        self.timer = QtCore.QTimer()
        self.timer.setInterval(20)
        self.timer.timeout.connect(self._tick)
        self.timer.start()

    def _tick(self):
        self.ticks += 1

    def stop(self):
        self.timer.stop()
