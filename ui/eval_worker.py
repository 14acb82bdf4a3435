"""Evaluation off the GUI thread.

`EvalWorker` owns the window's single `Evaluator` (its cache lives as long as
the window) and runs it on a snapshot in a `QThread`.  Requests made while an
evaluation runs cancel it; once it has stopped, the newest snapshot is
evaluated.  Signals cross back to the GUI thread as queued connections, so
slots connected to them always run on the GUI thread.
"""

from __future__ import annotations

from PySide6 import QtCore

from .qt_wait import process_events_until

from engine.graph import CancelToken, EvalReport, Evaluator, GraphSnapshot


class _EvalThread(QtCore.QThread):
    """One evaluation of one snapshot.  The QThread object lives in the GUI
    thread, so signals emitted from `run` are queued to GUI-thread slots."""

    progress = QtCore.Signal(str, float)
    node_done = QtCore.Signal(object)
    report_ready = QtCore.Signal(object)

    def __init__(self, evaluator: Evaluator, snapshot: GraphSnapshot, token: CancelToken, tag=None, parent=None):
        super().__init__(parent)
        self._evaluator = evaluator
        self._snapshot = snapshot
        self.token = token
        self.tag = tag

    def run(self) -> None:
        try:
            report = self._evaluator.evaluate(
                self._snapshot, cancel=self.token,
                on_progress=lambda nid, frac: self.progress.emit(nid, float(frac)),
                on_node_done=self.node_done.emit)
        except Exception as exc:  # the evaluator records node failures itself; this guards bugs
            report = EvalReport(cancelled=True)
            report.internal_error = f"{type(exc).__name__}: {exc}"
        self.report_ready.emit(report)


class EvalWorker(QtCore.QObject):
    """Evaluates the newest requested snapshot, one evaluation at a time.

    Signals
    -------
    started(int) : an evaluation with this request number began.
    progress(str, float) : node id, fraction done in [0, 1].
    node_done(object) : a `NodeResult`.
    finished(object) : the `EvalReport` (``report.cancelled`` if cancelled or superseded).
    busy_changed(bool) : whether an evaluation is running.
    """

    started = QtCore.Signal(int)
    progress = QtCore.Signal(str, float)
    node_done = QtCore.Signal(object)
    finished = QtCore.Signal(object)
    busy_changed = QtCore.Signal(bool)

    def __init__(self, evaluator: Evaluator | None = None, parent=None):
        super().__init__(parent)
        self.evaluator = evaluator or Evaluator()
        self._thread: _EvalThread | None = None
        self._pending: tuple[GraphSnapshot, object] | None = None
        self._request_no = 0
        self.last_report: EvalReport | None = None
        self.superseded = False  # the running evaluation was cancelled by a newer request

    @property
    def is_running(self) -> bool:
        return self._thread is not None

    @property
    def is_busy(self) -> bool:
        return self._thread is not None or self._pending is not None

    def request(self, snapshot: GraphSnapshot, tag=None) -> None:
        """Evaluate `snapshot`; a running evaluation is cancelled and this one follows it.

        `tag` comes back as ``report.tag`` (the window uses it to drop reports
        of a document it has since replaced)."""
        self._pending = (snapshot, tag)
        if self._thread is not None:
            self.superseded = True
            self._thread.token.cancel()
        else:
            self._start_pending()

    def cancel(self) -> None:
        """Stop the running evaluation and drop any queued one."""
        self._pending = None
        if self._thread is not None:
            self.superseded = False
            self._thread.token.cancel()

    def _start_pending(self) -> None:
        pending, self._pending = self._pending, None
        if pending is None:
            self.busy_changed.emit(False)
            return
        snapshot, tag = pending
        self._request_no += 1
        self.superseded = False
        thread = _EvalThread(self.evaluator, snapshot, CancelToken(), tag, self)
        thread.progress.connect(self.progress)
        thread.node_done.connect(self.node_done)
        thread.report_ready.connect(self._on_report)
        thread.finished.connect(thread.deleteLater)
        self._thread = thread
        self.busy_changed.emit(True)
        self.started.emit(self._request_no)
        thread.start()

    @QtCore.Slot(object)
    def _on_report(self, report: EvalReport) -> None:
        thread, self._thread = self._thread, None
        if thread is not None:
            thread.wait()  # run() has returned; this only joins the OS thread
        report.tag = thread.tag if thread is not None else None
        report.superseded = bool(report.cancelled and self.superseded and self._pending is not None)
        self.last_report = report
        self.finished.emit(report)
        self._start_pending()

    def wait_idle(self, timeout_ms: int = 30000) -> bool:
        """Process events until nothing runs or is queued; for shutdown and tests."""
        return process_events_until(lambda: not self.is_busy, lambda: self._thread,
                                    timeout_ms=timeout_ms, slice_ms=50)

    def shutdown(self, timeout_ms: int = 10000) -> None:
        """Cancel everything and join the thread (window close)."""
        self.cancel()
        thread = self._thread
        if thread is not None:
            thread.wait(timeout_ms)
            try:
                thread.report_ready.disconnect(self._on_report)
            except (RuntimeError, TypeError):
                pass
            self._thread = None
        self.busy_changed.emit(False)
