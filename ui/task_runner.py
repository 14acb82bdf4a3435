"""The one way a dock runs engine work off the GUI thread.

A `TaskRunner` runs one `Task` at a time in a `QThread`.  A task is a plain
callable ``fn(task)`` that does engine work and returns a result; it reports
through ``task.progress(done, total)`` (returns False once the task should
stop: pass it to any kernel's ``progress=``), may hand intermediate results
to the GUI with ``task.publish(obj)`` (live frames; only the newest waiting
one is delivered), and stops by raising :class:`engine.progress.Cancelled`
(kernels do that themselves when ``progress`` returns False; the graph
evaluator watches ``task.token``).

Policies, chosen per request:

* **coalesce** — at most one task waits: a new request replaces the waiting
  one, so a burst of edits computes only the last.
* **supersede** (default) — a new request also stops the running task; with
  ``supersede=False`` the running task finishes first (a painting update
  lets the previous frame land).
* **cancel()** drops the waiting task and stops the running one.

Signals always arrive on the GUI thread (queued connections), so slots may
draw.  Nothing here knows a method: docks submit the engine object's calls.
"""

from __future__ import annotations

import threading
import time
from typing import Any, Callable

from PySide6 import QtCore

from .qt_wait import process_events_until

from engine.graph import CancelToken
from engine.progress import Cancelled

# progress signals are throttled to this interval (s); the final one always passes
PROGRESS_INTERVAL = 0.05


class Task:
    """One unit of work and its channel to the GUI.

    fn : callable(task) -> result, run in the worker thread
    data : anything the caller wants back with the signals (e.g. the request's view generation)
    serial : request order, set by the runner
    token : CancelToken; ``cancel()`` sets it and ``progress`` then returns False
    """

    def __init__(self, fn: Callable[["Task"], Any], data: Any = None):
        self.fn = fn
        self.data = data
        self.serial = 0
        self.token = CancelToken()
        self.result: Any = None
        self._runner: "TaskRunner | None" = None
        self._frame_lock = threading.Lock()
        self._frame: Any = None
        self._has_frame = False
        self._last_progress = 0.0

    # -- called from the worker thread -----------------------------------------------------
    @property
    def stop_requested(self) -> bool:
        return self.token.cancelled

    def cancel(self) -> None:
        self.token.cancel()

    def check(self) -> None:
        """Raise Cancelled if the task should stop."""
        if self.token.cancelled:
            raise Cancelled("task cancelled")

    def progress(self, done: float, total: float) -> bool:
        """Kernel progress callback: forwards (throttled) to the GUI; False = stop."""
        now = time.perf_counter()
        runner = self._runner
        if runner is not None and (now - self._last_progress >= PROGRESS_INTERVAL or done >= total):
            self._last_progress = now
            runner._thread_progress.emit(self, float(done), float(total))
        return not self.token.cancelled

    def publish(self, obj: Any) -> None:
        """Hand an intermediate result to the GUI; an undelivered older one is replaced."""
        with self._frame_lock:
            first = not self._has_frame
            self._frame, self._has_frame = obj, True
        runner = self._runner
        if first and runner is not None:
            runner._thread_frame.emit(self)

    def take_frame(self) -> tuple[bool, Any]:
        with self._frame_lock:
            had, obj = self._has_frame, self._frame
            self._frame, self._has_frame = None, False
        return had, obj


class _TaskThread(QtCore.QThread):
    outcome = QtCore.Signal(object, str, object)   # task, "done" | "failed" | "cancelled", payload

    def __init__(self, task: Task, parent=None):
        super().__init__(parent)
        self.task = task

    def run(self) -> None:
        task = self.task
        try:
            task.check()
            task.result = task.fn(task)
        except Cancelled:
            self.outcome.emit(task, "cancelled", None)
            return
        except Exception as exc:  # reported by the dock, never raised into Qt
            self.outcome.emit(task, "failed", f"{type(exc).__name__}: {exc}")
            return
        self.outcome.emit(task, "done", task.result)


class TaskRunner(QtCore.QObject):
    """Runs the newest requested task, one at a time.

    Signals
    -------
    started(task)
    progress(task, done, total)
    published(task, obj) : an intermediate result (``task.publish``)
    finished(task, result)
    failed(task, message)
    cancelled(task) : stopped by ``cancel()`` or superseded
    busy_changed(bool) : something runs or waits
    """

    started = QtCore.Signal(object)
    progress = QtCore.Signal(object, float, float)
    published = QtCore.Signal(object, object)
    finished = QtCore.Signal(object, object)
    failed = QtCore.Signal(object, str)
    cancelled = QtCore.Signal(object)
    busy_changed = QtCore.Signal(bool)

    _thread_progress = QtCore.Signal(object, float, float)
    _thread_frame = QtCore.Signal(object)

    def __init__(self, parent=None):
        super().__init__(parent)
        self._thread: _TaskThread | None = None
        self._pending: Task | None = None
        self._serial = 0
        self._thread_progress.connect(self._on_progress, QtCore.Qt.ConnectionType.QueuedConnection)
        self._thread_frame.connect(self._on_frame, QtCore.Qt.ConnectionType.QueuedConnection)

    # -- state ------------------------------------------------------------------------------
    @property
    def is_running(self) -> bool:
        return self._thread is not None

    @property
    def is_busy(self) -> bool:
        return self._thread is not None or self._pending is not None

    @property
    def running(self) -> Task | None:
        return None if self._thread is None else self._thread.task

    @property
    def pending(self) -> Task | None:
        return self._pending

    # -- requests ---------------------------------------------------------------------------
    def submit(self, fn: Callable[[Task], Any] | Task, *, data: Any = None, supersede: bool = True) -> Task:
        """Run ``fn(task)`` after the running task (stopped first unless ``supersede`` is
        False), in place of any waiting one.  Returns the Task."""
        task = fn if isinstance(fn, Task) else Task(fn, data)
        self._serial += 1
        task.serial = self._serial
        task._runner = self
        dropped, self._pending = self._pending, task
        if dropped is not None:
            self.cancelled.emit(dropped)
        if self._thread is None:
            self.busy_changed.emit(True)
            self._start_pending()
        elif supersede:
            self._thread.task.cancel()
        return task

    def cancel(self) -> None:
        """Drop the waiting task and stop the running one."""
        dropped, self._pending = self._pending, None
        if dropped is not None:
            self.cancelled.emit(dropped)
        if self._thread is not None:
            self._thread.task.cancel()

    # -- thread management -----------------------------------------------------------------
    def _start_pending(self) -> None:
        task, self._pending = self._pending, None
        if task is None:
            self.busy_changed.emit(False)
            return
        thread = _TaskThread(task, self)
        thread.outcome.connect(self._on_outcome)
        thread.finished.connect(thread.deleteLater)
        self._thread = thread
        self.started.emit(task)
        thread.start()

    def _join(self) -> None:
        thread, self._thread = self._thread, None
        if thread is not None:
            thread.wait()  # run() has returned; this joins the OS thread

    @QtCore.Slot(object, float, float)
    def _on_progress(self, task, done, total) -> None:
        self.progress.emit(task, done, total)

    @QtCore.Slot(object)
    def _on_frame(self, task) -> None:
        had, obj = task.take_frame()
        if had:
            self.published.emit(task, obj)

    @QtCore.Slot(object, str, object)
    def _on_outcome(self, task, kind, payload) -> None:
        self._join()
        self._on_frame(task)             # the last frame lands before the result
        if kind == "done":
            self.finished.emit(task, payload)
        elif kind == "failed":
            self.failed.emit(task, payload)
        else:
            self.cancelled.emit(task)
        self._start_pending()

    def wait_idle(self, timeout_ms: int = 30000) -> bool:
        """Process events until nothing runs or waits (tests, shutdown)."""
        return process_events_until(lambda: not self.is_busy, lambda: self._thread, timeout_ms=timeout_ms)

    def shutdown(self, timeout_ms: int = 10000) -> None:
        """Stop everything and join the thread (the dock is closing); no more signals."""
        self._pending = None
        thread, self._thread = self._thread, None
        if thread is not None:
            thread.task.cancel()
            try:
                thread.outcome.disconnect(self._on_outcome)
            except (RuntimeError, TypeError):
                pass
            thread.wait(timeout_ms)
