"""Waiting on the GUI thread for a worker thread to finish, events still flowing."""

from __future__ import annotations

from typing import Callable

from PySide6 import QtCore


def process_events_until(done: Callable[[], bool], thread: Callable[[], QtCore.QThread | None], *,
                         timeout_ms: int, slice_ms: int = 20) -> bool:
    """Process events (so queued signals from the worker arrive) until ``done()``
    or ``timeout_ms`` passes; between rounds, briefly join ``thread()`` if any.
    Returns ``done()``."""
    timer = QtCore.QElapsedTimer()
    timer.start()
    app = QtCore.QCoreApplication.instance()
    while not done() and timer.elapsed() < timeout_ms:
        if app is not None:
            app.processEvents(QtCore.QEventLoop.ProcessEventsFlag.AllEvents, slice_ms)
        t = thread()
        if t is not None:
            t.wait(max(1, slice_ms // 2))
    return done()
