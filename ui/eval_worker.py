"""Evaluation off the GUI thread, on the one generic `TaskRunner`.

`EvalWorker` owns the window's single `Evaluator` (its cache lives as long as
the window) and evaluates snapshots as `TaskRunner` tasks: the evaluator
watches the task's ``token`` as its CancelToken, so a newer request (or
``cancel()``) stops the running evaluation at its next progress check and
only the newest snapshot is evaluated next.  Per-node progress and results
cross back to the GUI thread as queued signals, so connected slots always
run on the GUI thread.
"""

from __future__ import annotations

from PySide6 import QtCore

from engine.graph import EvalReport, Evaluator, GraphSnapshot

from .task_runner import Task, TaskRunner


class EvalWorker(QtCore.QObject):
    """Evaluates the newest requested snapshot, one evaluation at a time.

    Signals
    -------
    started(int) : an evaluation with this request number began.
    progress(str, float) : node id, fraction done in [0, 1].
    node_done(object) : a `NodeResult`.
    finished(object) : the `EvalReport` (``report.cancelled`` if cancelled or superseded).
    busy_changed(bool) : whether an evaluation runs or waits.
    """

    started = QtCore.Signal(int)
    progress = QtCore.Signal(str, float)
    node_done = QtCore.Signal(object)
    finished = QtCore.Signal(object)
    busy_changed = QtCore.Signal(bool)

    # emitted from the worker thread, delivered (queued) as the public signals
    _thread_progress = QtCore.Signal(str, float)
    _thread_node_done = QtCore.Signal(object)

    def __init__(self, evaluator: Evaluator | None = None, parent=None):
        super().__init__(parent)
        self.evaluator = evaluator or Evaluator()
        self.runner = TaskRunner(self)
        self._request_no = 0
        self.last_report: EvalReport | None = None
        self.superseded = False  # the running evaluation was cancelled by a newer request
        queued = QtCore.Qt.ConnectionType.QueuedConnection
        self._thread_progress.connect(self.progress, queued)
        self._thread_node_done.connect(self.node_done, queued)
        self.runner.started.connect(self._on_started)
        self.runner.finished.connect(self._on_finished)
        self.runner.busy_changed.connect(self.busy_changed)

    @property
    def is_running(self) -> bool:
        return self.runner.is_running

    @property
    def is_busy(self) -> bool:
        return self.runner.is_busy

    def request(self, snapshot: GraphSnapshot, tag=None) -> None:
        """Evaluate `snapshot`; a running evaluation is cancelled and this one follows it.

        `tag` comes back as ``report.tag`` (the window uses it to drop reports
        of a document it has since replaced)."""
        if self.runner.is_running:
            self.superseded = True
        self.runner.submit(lambda task: self._evaluate(task, snapshot), data=tag, supersede=True)

    def adopt(self, snapshot: GraphSnapshot, node_id: str, outputs: dict, inputs: dict | None = None) -> None:
        """Offer ``outputs`` as node ``node_id``'s result for ``snapshot`` (a dock's finished live run):
        the evaluator checks and stores it in the worker thread when the next evaluation starts,
        never during a running one (`Evaluator.queue_adoption`).  Returns at once."""
        self.evaluator.queue_adoption(snapshot, node_id, outputs, inputs=inputs)

    def cancel(self) -> None:
        """Stop the running evaluation and drop any queued one."""
        self.superseded = False
        self.runner.cancel()

    def _evaluate(self, task: Task, snapshot: GraphSnapshot) -> EvalReport:
        """Runs in the worker thread: the evaluator stops when ``task.token`` is cancelled."""
        try:
            return self.evaluator.evaluate(snapshot, cancel=task.token,
                                           on_progress=lambda nid, frac: self._thread_progress.emit(nid, float(frac)),
                                           on_node_done=self._thread_node_done.emit)
        except Exception as exc:  # the evaluator records node failures itself; this guards bugs
            report = EvalReport(cancelled=True)
            report.internal_error = f"{type(exc).__name__}: {exc}"
            return report

    @QtCore.Slot(object)
    def _on_started(self, _task: Task) -> None:
        self._request_no += 1
        self.superseded = False
        self.started.emit(self._request_no)

    @QtCore.Slot(object, object)
    def _on_finished(self, task: Task, report: EvalReport) -> None:
        report.tag = task.data
        report.superseded = bool(report.cancelled and self.superseded and self.runner.pending is not None)
        self.last_report = report
        self.finished.emit(report)

    def wait_idle(self, timeout_ms: int = 30000) -> bool:
        """Process events until nothing runs or is queued; for shutdown and tests."""
        return self.runner.wait_idle(timeout_ms)

    def shutdown(self, timeout_ms: int = 10000) -> None:
        """Cancel everything and join the thread (window close)."""
        self.superseded = False
        self.runner.shutdown(timeout_ms)
        self.busy_changed.emit(False)
