"""Live reaction/diffusion growth off the GUI thread, on the one `TaskRunner`.

What grows is the RDGrow node's own `engine.nodes.rd_session.RDGrowthSession`
(built by the dock from the node's parameters, input and seed), so a live
growth run to the end is the node's growth.  `LiveGrowthWorker` submits one
task that advances the session ``every`` steps per direction at a time and
publishes a frame after each round (coalesced by the runner: a slow redraw
never piles up a backlog):

* ``pause()`` cancels the task; the kernel stops after its last complete
  step and the session keeps that state, so ``resume()`` (the task
  submitted again) continues exactly;
* ``cancel()`` stops the same way and ends the run, keeping the last
  complete step on screen;
* the run ends by itself once every direction converged (G^t < eps) or
  reached ``max_steps``; the node's value (`RDGrowthSession.apply`: the
  brush edits applied by local regrowth) is then made in the same thread,
  so the dock can hand it to the window's evaluator without regrowing.

The document is never touched here.
"""

from __future__ import annotations

from PySide6 import QtCore

from engine.graph.errors import NodeInputError
from engine.nodes.rd_session import RDGrowthFrame, RDGrowthSession

from .task_runner import Task, TaskRunner

LiveFrame = RDGrowthFrame      # one picture of a live growth (the session's frame)


class LiveGrowthWorker(QtCore.QObject):
    """Runs one `RDGrowthSession` at a time, with pause / resume / cancel.

    Signals
    -------
    frame(LiveFrame) : the newest state (at most one waiting at a time)
    stopped(str) : "done", "paused" or "cancelled"; the last frame was sent before
    failed(str) : the engine refused or raised; the message says why
    running_changed(bool)
    """

    frame = QtCore.Signal(object)
    stopped = QtCore.Signal(str)
    failed = QtCore.Signal(str)
    running_changed = QtCore.Signal(bool)

    def __init__(self, parent=None):
        super().__init__(parent)
        self.session: RDGrowthSession | None = None
        self.every = 100
        self.status = "idle"               # "idle", "running", "paused", "cancelled", "done", "failed"
        self.last_frame: LiveFrame | None = None
        self._task: Task | None = None
        self._stop_as = "cancelled"        # what a cancelled task means: "paused" or "cancelled"
        self.runner = TaskRunner(self)
        self.runner.published.connect(self._on_published)
        self.runner.finished.connect(self._on_finished)
        self.runner.cancelled.connect(self._on_cancelled)
        self.runner.failed.connect(self._on_failed)

    @property
    def job(self) -> RDGrowthSession | None:
        """The session growing (older name)."""
        return self.session

    @property
    def is_running(self) -> bool:
        return self._task is not None

    @property
    def can_resume(self) -> bool:
        return self.status == "paused" and self._task is None and self.session is not None

    def start(self, session: RDGrowthSession, every: int = 100) -> None:
        """Grow ``session`` from its seeds, a frame every ``every`` steps (a running growth is stopped first)."""
        self.shutdown()
        self.session, self.every = session, max(1, int(every))
        session.start()
        self.last_frame = None
        self._launch()

    def resume(self) -> bool:
        """Continue a paused growth from the session's states; False if there is none."""
        if not self.can_resume:
            return False
        self._launch()
        return True

    def pause(self) -> None:
        self._stop("paused")

    def cancel(self) -> None:
        """Stop and keep the last complete step; a paused growth is ended too."""
        if self._task is None and self.status == "paused":
            self.status = "cancelled"
            self.stopped.emit("cancelled")
            return
        self._stop("cancelled")

    def _stop(self, status: str) -> None:
        if self._task is not None:
            self._stop_as = status
            self.runner.cancel()

    def _launch(self) -> None:
        session, every = self.session, self.every

        def grow(task: Task):
            while not session.advance(every, task.progress):   # Cancelled when paused or cancelled
                task.publish(session.frame("running"))
            try:
                session.apply(task.progress)   # kept as session.value; Cancelled like the growth
            except NodeInputError:
                pass   # an edit the node refuses: the evaluation reports it (session.value stays None)
            return session.frame("done")

        self._stop_as = "cancelled"
        self.status = "running"
        self._task = self.runner.submit(grow, data=session)
        self.running_changed.emit(True)

    def _show(self, frame: LiveFrame) -> None:
        self.last_frame = frame
        self.frame.emit(frame)

    def _end(self, task: Task, status: str) -> bool:
        """Forget ``task`` (False when it is not ours: a stale signal)."""
        if task is not self._task:
            return False
        self._task = None
        self.status = status
        self.running_changed.emit(False)
        return True

    def _on_published(self, task: Task, frame) -> None:
        if task is self._task:
            self._show(frame)

    def _on_finished(self, task: Task, frame) -> None:
        if task is self._task:
            self._show(frame)
            self._end(task, "done")
            self.stopped.emit("done")

    def _on_cancelled(self, task: Task) -> None:
        if task is self._task:
            status = self._stop_as
            # the thread has ended: the session holds the last complete step
            self._show(self.session.frame(status))
            self._end(task, status)
            self.stopped.emit(status)

    def _on_failed(self, task: Task, message: str) -> None:
        if self._end(task, "failed"):
            self.failed.emit(message)

    def wait_stopped(self, timeout_ms: int = 60000) -> bool:
        """Process events until no growth runs (tests, shutdown)."""
        self.runner.wait_idle(timeout_ms)
        return self._task is None

    def shutdown(self, timeout_ms: int = 10000) -> None:
        """Stop the growth and join its thread without emitting anything (the dock is closing)."""
        if self._task is None:
            return
        self._task = None
        self.runner.shutdown(timeout_ms)
        self.status = "cancelled"
