"""Phasor slice evaluation off the GUI thread.

A `SliceJob` is plain data: which pattern to show on which slice plane (and
which rectangle of it), the kernels, fields and filter options, and an
optional ``prepare(progress)`` step that runs first in the thread (the local
kernel update after a brush stroke).  `SliceWorker` runs one job at a time
in a `QThread`; a new request replaces the queued one and, unless it asks
not to, cancels the running one through its progress callback (the engine
stops within ~100 ms).  Signals reach the GUI thread as queued connections.
Nothing is drawn here: rendering stays on the GUI thread.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

from PySide6 import QtCore

from .qt_wait import process_events_until

from engine.geometry.cancel import Cancelled
from engine.phasor.preview import pattern_slice, sub_plane


@dataclass
class SliceJob:
    """One pattern image to compute.

    show : "diamonds" | "p_v" | "singularity"
    plane : SlicePlane of the whole view
    infill : PhasorInfill to evaluate, or the one ``prepare`` starts from
    rect : (r0, r1, c0, c1) pixels of ``plane`` to compute, or None for all
    prepare : callable(progress) -> (PhasorInfill, rect or None), or None; runs first,
        in the thread (the local kernel update after a brush stroke); a None rect
        means nothing visible changed
    engine : "gpu" | "numpy" asked for; after the run, what ran
    view : int, the view generation (axis / position / display) it belongs to
    purpose, fields : the caller's notes (e.g. "stroke" and the painted fields)
    serial : int, set by the worker: request order
    """

    show: str
    plane: Any
    infill: Any
    rect: tuple | None = None
    engine: str = "gpu"
    prepare: Callable | None = None
    view: int = 0
    purpose: str = ""
    fields: Any = None
    serial: int = 0
    result: Any = field(default=None, repr=False)


class _SliceThread(QtCore.QThread):
    done = QtCore.Signal(object)
    failed = QtCore.Signal(object, str)
    cancelled = QtCore.Signal(object)
    progress = QtCore.Signal(int, int)

    def __init__(self, job: SliceJob, parent=None):
        super().__init__(parent)
        self.job = job
        self.stop_requested = False

    def _progress(self, done, total) -> bool:
        self.progress.emit(int(done), int(total))
        return not self.stop_requested

    def run(self) -> None:
        job = self.job
        try:
            if job.prepare is not None:
                job.infill, job.rect = job.prepare(self._progress)
                if job.rect is None:  # nothing visible changed
                    self.done.emit(job)
                    return
            if self.stop_requested:
                raise Cancelled("superseded")
            plane = job.plane if job.rect is None else sub_plane(job.plane, job.rect[:2], job.rect[2:])
            job.result, job.engine = pattern_slice(job.infill, plane, job.show, engine=job.engine,
                                                   progress=self._progress)
        except Cancelled:
            self.cancelled.emit(job)
            return
        except Exception as exc:  # reported in the dock, never raised into Qt
            self.failed.emit(job, f"{type(exc).__name__}: {exc}")
            return
        self.done.emit(job)


class SliceWorker(QtCore.QObject):
    """Runs the newest `SliceJob`; a newer request supersedes an older one.

    Signals
    -------
    finished(job) : ``job.result`` (h, w) float64 holds the pattern of ``job.rect`` (None
        when ``prepare`` found nothing visible changed), ``job.engine`` what made it
    failed(job, message)
    progress(done, total)
    busy_changed(bool)
    """

    finished = QtCore.Signal(object)
    failed = QtCore.Signal(object, str)
    progress = QtCore.Signal(int, int)
    busy_changed = QtCore.Signal(bool)

    def __init__(self, parent=None):
        super().__init__(parent)
        self._thread: _SliceThread | None = None
        self._pending: SliceJob | None = None
        self._serial = 0

    @property
    def is_busy(self) -> bool:
        return self._thread is not None or self._pending is not None

    @property
    def running_job(self) -> SliceJob | None:
        return None if self._thread is None else self._thread.job

    def request(self, job: SliceJob, *, cancel_running: bool = True) -> SliceJob:
        """Queue ``job`` in place of any queued one; stop the running one unless
        ``cancel_running`` is False (a painting update lets the previous one land)."""
        self._serial += 1
        job.serial = self._serial
        self._pending = job
        if self._thread is None:
            self.busy_changed.emit(True)
            self._start_pending()
        elif cancel_running:
            self._thread.stop_requested = True
        return job

    def cancel(self) -> None:
        """Drop the queued job and stop the running one."""
        self._pending = None
        if self._thread is not None:
            self._thread.stop_requested = True

    def _start_pending(self) -> None:
        job, self._pending = self._pending, None
        if job is None:
            if self._thread is None:
                self.busy_changed.emit(False)
            return
        thread = _SliceThread(job, self)
        thread.done.connect(self._on_done)
        thread.failed.connect(self._on_failed)
        thread.cancelled.connect(self._on_cancelled)
        thread.progress.connect(self.progress)
        thread.finished.connect(thread.deleteLater)
        self._thread = thread
        thread.start()

    def _join(self) -> None:
        thread, self._thread = self._thread, None
        if thread is not None:
            thread.wait()  # run() has returned; this joins the OS thread

    @QtCore.Slot(object)
    def _on_done(self, job) -> None:
        self._join()
        self.finished.emit(job)
        self._start_pending()

    @QtCore.Slot(object, str)
    def _on_failed(self, job, message) -> None:
        self._join()
        self.failed.emit(job, message)
        self._start_pending()

    @QtCore.Slot(object)
    def _on_cancelled(self, _job) -> None:
        self._join()
        self._start_pending()

    def wait_idle(self, timeout_ms: int = 30000) -> bool:
        """Process events until nothing runs or is queued (tests, shutdown)."""
        return process_events_until(lambda: not self.is_busy, lambda: self._thread, timeout_ms=timeout_ms)

    def shutdown(self, timeout_ms: int = 10000) -> None:
        """Stop everything and join the thread (the dock is closing)."""
        self.cancel()
        thread, self._thread = self._thread, None
        if thread is not None:
            for sig, slot in ((thread.done, self._on_done), (thread.failed, self._on_failed),
                              (thread.cancelled, self._on_cancelled)):
                try:
                    sig.disconnect(slot)
                except (RuntimeError, TypeError):
                    pass
            thread.wait(timeout_ms)


class TaskThread(QtCore.QThread):
    """A long engine call ``task(progress)`` in its own thread (the G-code export).

    ``cancel()`` makes the next ``progress`` call return False; the engine then
    raises :class:`Cancelled` and ``cancelled`` is emitted.  Signals: ``done(result)``,
    ``failed(message)``, ``cancelled()``, ``progress(done, total)``.
    """

    done = QtCore.Signal(object)
    failed = QtCore.Signal(str)
    cancelled = QtCore.Signal()
    progress = QtCore.Signal(int, int)

    def __init__(self, task: Callable, parent=None):
        super().__init__(parent)
        self._task = task
        self.stop_requested = False

    def cancel(self) -> None:
        self.stop_requested = True

    def _progress(self, done, total) -> bool:
        self.progress.emit(int(done), int(total))
        return not self.stop_requested

    def run(self) -> None:
        try:
            result = self._task(self._progress)
        except Cancelled:
            self.cancelled.emit()
            return
        except Exception as exc:  # reported in the dock
            self.failed.emit(f"{type(exc).__name__}: {exc}")
            return
        self.done.emit(result)
