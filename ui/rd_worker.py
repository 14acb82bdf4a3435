"""Reaction/diffusion growth off the GUI thread, shown live.

A `LiveGrowth` is plain data: the growth-grid inputs and the options of
``engine.rd.growth.grow`` for each principal direction to grow, as the
RDGrow node would use them. `LiveGrowthWorker` advances every direction
by ``every`` steps in turn (``grow`` resumed from its own state, which
the engine guarantees to be bit-for-bit the uninterrupted run) and hands
the GUI a `LiveFrame` after each round:

* ``pause()`` stops within one progress call (~40 ms) after the last
  complete step; the states are kept and ``resume()`` continues from them,
  so a paused-and-resumed growth equals an uninterrupted one exactly;
* ``cancel()`` stops the same way and ends the run, keeping the last
  complete step on screen;
* the run ends by itself once every direction converged (G^t < eps) or
  reached ``max_steps``.

Frames are coalesced: the thread keeps only the newest one and signals the
GUI when none is waiting, so a slow redraw never piles up a backlog.
`LiveGrowthBox` holds the dock's buttons, progress and G^t plot over the
worker. The document is never touched here.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field

import numpy as np
from PySide6 import QtCore, QtWidgets

from engine.rd.growth import grow

from .qt_wait import process_events_until
from .rd_canvas import GrowthPlot


@dataclass
class LiveGrowth:
    """What to grow: one ``grow`` call per direction, resumed every ``every`` steps.

    rho, rotation, gamma_map : growth-grid inputs ([y, x] / [z, y, x]; rotation grid + (d, d))
    directions : tuple of int, principal directions, one structure each
    options : dict of ``grow`` keywords shared by the directions (iso, params, seeds,
        seed_radius, eps, max_steps, ...), as ``engine.nodes.rd_state.growth_options`` gives them
    every : int, steps between two frames
    """

    rho: np.ndarray
    rotation: np.ndarray
    gamma_map: np.ndarray | None
    directions: tuple
    options: dict
    every: int = 100

    @property
    def max_steps(self) -> int:
        return int(self.options.get("max_steps", 200_000))

    def advance(self, k: int, state, progress):
        """Grow direction ``k`` by up to ``every`` steps from ``state`` (None: from its seeds)."""
        opts = dict(self.options)
        start = 0 if state is None else int(state.step)
        opts["max_steps"] = min(self.max_steps, start + int(self.every))
        if state is not None:   # a resumed growth keeps its seeds and resolved parameters
            for key in ("seeds", "seed_radius", "seed_spacing", "params", "rng"):
                opts.pop(key, None)
        return grow(self.rho, self.rotation, direction=int(self.directions[k]), gamma_map=self.gamma_map,
                    progress=progress, state=state, **opts)


def live_growth(fields, params: dict, *, seed: int, every: int = 100) -> LiveGrowth:
    """The growth an RDGrow node with ``params`` (its full parameter dict) and node seed
    ``seed`` runs on the input ``fields`` (RDFieldsValue), from its seeds; the node's
    brush edits are not part of it (they regrow locally after a growth).

    Raises ValueError (the node's message) for parameters the node refuses.
    """
    from engine.nodes.rd import growth_fields, growth_shape, selected_directions
    from engine.nodes.rd_state import growth_options

    grid = growth_fields(fields, growth_shape(params["resolution"], fields))
    directions = selected_directions(params["directions"], fields.ndim)
    options = growth_options(grid, params, seed)
    return LiveGrowth(np.asarray(grid.rho), np.asarray(grid.rotation), np.asarray(grid.gamma),
                      tuple(directions), options, every=int(every))


@dataclass
class LiveFrame:
    """One picture of a live growth.

    s : (n,) + grid float32, ``1 - u`` per direction (a copy)
    directions : tuple of int, the principal direction of each structure
    steps : tuple of int, steps taken per direction
    g_history : tuple of (m, 2) float64, (step, G^t) per direction
    stop_reasons : tuple of str, "" while a direction still grows
    states : tuple of RDState (None before a direction's first round)
    status : "running", "paused", "cancelled", "done"
    """

    s: np.ndarray
    directions: tuple
    steps: tuple
    g_history: tuple
    stop_reasons: tuple
    states: tuple = field(repr=False, default=())
    status: str = "running"

    @property
    def last_g(self) -> tuple:
        return tuple(float(h[-1, 1]) if len(h) else float("nan") for h in self.g_history)


def _frame(job: LiveGrowth, results: list, status: str) -> LiveFrame:
    shape = np.shape(job.rho)
    s = np.zeros((len(job.directions),) + shape, np.float32)
    steps, hist, reasons, states = [], [], [], []
    for k, r in enumerate(results):
        if r is None:
            steps.append(0)
            hist.append(np.zeros((0, 2)))
            reasons.append("")
            states.append(None)
            continue
        s[k] = 1.0 - r.u
        steps.append(int(r.steps))
        hist.append(np.array(r.history, np.float64).reshape(-1, 2))
        reasons.append(r.stop_reason if _finished(job, r) else "")
        states.append(r.state)
    return LiveFrame(s, tuple(job.directions), tuple(steps), tuple(hist), tuple(reasons), tuple(states), status)


def _finished(job: LiveGrowth, result) -> bool:
    return result is not None and (result.stop_reason == "converged" or result.steps >= job.max_steps)


class _GrowThread(QtCore.QThread):
    frame_ready = QtCore.Signal()
    stopped = QtCore.Signal(str)          # "done", "paused", "cancelled"
    failed = QtCore.Signal(str)

    def __init__(self, job: LiveGrowth, results: list, parent=None):
        super().__init__(parent)
        self.job = job
        self.results = list(results)
        self.stop_mode = ""               # "", "pause" or "cancel": asked by the GUI
        self._lock = threading.Lock()
        self._latest: LiveFrame | None = None
        self._waiting = False             # a frame_ready is on its way to the GUI

    def _progress(self, _done, _total) -> bool:
        return not self.stop_mode

    def take_frame(self) -> LiveFrame | None:
        with self._lock:
            frame, self._latest, self._waiting = self._latest, None, False
        return frame

    def _publish(self, status: str) -> None:
        frame = _frame(self.job, self.results, status)
        with self._lock:
            self._latest = frame
            notify = not self._waiting
            self._waiting = True
        if notify:
            self.frame_ready.emit()

    def run(self) -> None:
        job = self.job
        try:
            while True:
                todo = [k for k, r in enumerate(self.results) if not _finished(job, r)]
                if not todo:
                    self._publish("done")
                    self.stopped.emit("done")
                    return
                for k in todo:
                    if self.stop_mode:
                        break
                    prev = self.results[k]
                    # a stop request ends this call after its last complete step: keep that state
                    self.results[k] = job.advance(k, None if prev is None else prev.state, self._progress)
                if self.stop_mode:
                    status = "paused" if self.stop_mode == "pause" else "cancelled"
                    self._publish(status)
                    self.stopped.emit(status)
                    return
                self._publish("running")
        except Exception as exc:   # reported in the dock, never raised into Qt
            self.failed.emit(f"{type(exc).__name__}: {exc}")


class LiveGrowthWorker(QtCore.QObject):
    """Runs one `LiveGrowth` at a time, with pause / resume / cancel.

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
        self.job: LiveGrowth | None = None
        self.results: list = []            # per direction: the last RDResult, None before any
        self.status = "idle"               # "idle", "running", "paused", "cancelled", "done", "failed"
        self.last_frame: LiveFrame | None = None
        self._thread: _GrowThread | None = None

    @property
    def is_running(self) -> bool:
        return self._thread is not None

    @property
    def can_resume(self) -> bool:
        return self.status == "paused" and self._thread is None and self.job is not None

    def start(self, job: LiveGrowth) -> None:
        """Grow ``job`` from its seeds (a running growth is cancelled first)."""
        self.shutdown()
        self.job = job
        self.results = [None] * len(job.directions)
        self.last_frame = None
        self._launch()

    def resume(self) -> bool:
        """Continue a paused growth from its states; False if there is none."""
        if not self.can_resume:
            return False
        self._launch()
        return True

    def pause(self) -> None:
        if self._thread is not None:
            self._thread.stop_mode = "pause"

    def cancel(self) -> None:
        """Stop and keep the last complete step; a paused growth is ended too."""
        if self._thread is not None:
            self._thread.stop_mode = "cancel"
        elif self.status == "paused":
            self.status = "cancelled"
            self.stopped.emit("cancelled")

    def _launch(self) -> None:
        thread = _GrowThread(self.job, self.results, self)
        thread.frame_ready.connect(self._on_frame_ready)
        thread.stopped.connect(self._on_stopped)
        thread.failed.connect(self._on_failed)
        self._thread = thread
        self.status = "running"
        self.running_changed.emit(True)
        thread.start()

    def _join(self) -> _GrowThread | None:
        thread, self._thread = self._thread, None
        if thread is not None:
            thread.wait()
            self.results = thread.results
            thread.deleteLater()
        return thread

    @QtCore.Slot()
    def _on_frame_ready(self) -> None:
        # only one thread runs at a time; a late notice of a finished one finds nothing
        frame = self._thread.take_frame() if self._thread is not None else None
        if frame is not None:
            self.last_frame = frame
            self.frame.emit(frame)

    @QtCore.Slot(str)
    def _on_stopped(self, status: str) -> None:
        thread = self._join()
        frame = thread.take_frame() if thread is not None else None
        if frame is not None:
            self.last_frame = frame
            self.frame.emit(frame)
        self.status = status
        self.running_changed.emit(False)
        self.stopped.emit(status)

    @QtCore.Slot(str)
    def _on_failed(self, message: str) -> None:
        self._join()
        self.status = "failed"
        self.running_changed.emit(False)
        self.failed.emit(message)

    def wait_stopped(self, timeout_ms: int = 60000) -> bool:
        """Process events until no growth runs (tests, shutdown)."""
        return process_events_until(lambda: self._thread is None, lambda: self._thread, timeout_ms=timeout_ms)

    def shutdown(self, timeout_ms: int = 10000) -> None:
        """Stop the growth and join its thread without emitting anything (the dock is closing)."""
        thread, self._thread = self._thread, None
        if thread is None:
            return
        thread.stop_mode = "cancel"
        for sig, slot in ((thread.frame_ready, self._on_frame_ready), (thread.stopped, self._on_stopped),
                          (thread.failed, self._on_failed)):
            try:
                sig.disconnect(slot)
            except (RuntimeError, TypeError):
                pass
        thread.wait(timeout_ms)
        self.results = thread.results
        thread.deleteLater()
        self.status = "cancelled"


class LiveGrowthBox(QtWidgets.QGroupBox):
    """The dock's "Live growth" controls over a `LiveGrowthWorker`: Grow live, Pause / Resume,
    Cancel, Apply, the frame interval, a progress bar, the step and G^t, a G^t plot.

    ``job_factory()`` (set by the owner) returns the `LiveGrowth` to run or raises
    ValueError saying why there is none.

    Signals
    -------
    frame(LiveFrame) : a new state to draw
    apply_requested() : the user asked for the normal evaluation
    message(str) : something to tell the user
    """

    frame = QtCore.Signal(object)
    apply_requested = QtCore.Signal()
    message = QtCore.Signal(str)

    def __init__(self, parent=None):
        super().__init__("Live growth", parent)
        self.job_factory = None
        self.worker = LiveGrowthWorker(self)
        self.worker.frame.connect(self._on_frame)
        self.worker.stopped.connect(self._on_stopped)
        self.worker.failed.connect(self._on_failed)
        v = QtWidgets.QVBoxLayout(self)
        row = QtWidgets.QHBoxLayout()
        self.grow_button = QtWidgets.QPushButton("Grow live")
        self.grow_button.clicked.connect(self.start)
        self.pause_button = QtWidgets.QPushButton("Pause")
        self.pause_button.clicked.connect(self._on_pause_clicked)
        self.cancel_button = QtWidgets.QPushButton("Cancel")
        self.cancel_button.clicked.connect(self.cancel)
        self.apply_button = QtWidgets.QPushButton("Apply")
        self.apply_button.setToolTip("evaluate the document: the RDGrow node grows the same structure "
                                     "the normal way (the live run never changes the document)")
        self.apply_button.clicked.connect(self.apply)
        for b in (self.grow_button, self.pause_button, self.cancel_button, self.apply_button):
            row.addWidget(b)
        row.addWidget(QtWidgets.QLabel("every"))
        self.every_spin = QtWidgets.QSpinBox()
        self.every_spin.setRange(1, 100000)
        self.every_spin.setValue(100)
        self.every_spin.setSuffix(" steps")
        row.addWidget(self.every_spin)
        v.addLayout(row)
        self.bar = QtWidgets.QProgressBar()
        self.bar.setRange(0, 1)
        self.bar.setValue(0)
        v.addWidget(self.bar)
        self.label = QtWidgets.QLabel("")
        self.label.setWordWrap(True)
        v.addWidget(self.label)
        self.plot = GrowthPlot()
        v.addWidget(self.plot)
        self.update_buttons(False)

    def start(self) -> bool:
        """Start a growth from ``job_factory``; False (with a message) when there is none."""
        try:
            job = self.job_factory(self.every_spin.value()) if self.job_factory else None
        except ValueError as exc:
            self.message.emit(f"<span style='color:#c0392b'>cannot grow: {exc}</span>")
            return False
        if job is None:
            self.message.emit("live growth needs an RDGrow node fed by evaluated RD fields")
            return False
        self.worker.start(job)
        self.bar.setRange(0, max(1, job.max_steps * len(job.directions)))
        self.bar.setValue(0)
        self.plot.set_curves([])
        self.update_buttons(True)
        return True

    def pause(self) -> None:
        self.worker.pause()

    def resume(self) -> bool:
        ok = self.worker.resume()
        self.update_buttons(True)
        return ok

    def cancel(self) -> None:
        self.worker.cancel()
        self.update_buttons(True)

    def apply(self) -> None:
        self.apply_requested.emit()

    def _on_pause_clicked(self) -> None:
        if self.worker.is_running:
            self.pause()
        elif self.worker.can_resume:
            self.resume()

    def update_buttons(self, can_grow: bool) -> None:
        w = self.worker
        self.grow_button.setEnabled(bool(can_grow) and not w.is_running)
        self.pause_button.setEnabled(w.is_running or w.can_resume)
        self.pause_button.setText("Resume" if w.can_resume else "Pause")
        self.cancel_button.setEnabled(w.is_running or w.can_resume)
        self.apply_button.setEnabled(not w.is_running and w.status in ("done", "cancelled"))

    def _on_frame(self, frame: LiveFrame) -> None:
        job = self.worker.job
        self.bar.setValue(int(sum(frame.steps)))
        gs = ", ".join(f"{g:.3g}" for g in frame.last_g)
        steps = ", ".join(str(s) for s in frame.steps)
        self.label.setText(f"{frame.status}: step {steps} of {job.max_steps}, G^t = {gs}")
        self.plot.set_curves([(h[:, 0], h[:, 1]) for h in frame.g_history],
                             eps=float(job.options.get("eps", 0.0)) or None)
        self.frame.emit(frame)

    def _on_stopped(self, status: str) -> None:
        frame = self.worker.last_frame
        if frame is not None:
            reasons = ", ".join(r or "stopped" for r in frame.stop_reasons)
            text = {"done": f"finished ({reasons})", "paused": "paused: Resume continues exactly",
                    "cancelled": "cancelled: the last complete step is shown"}[status]
            self.label.setText(f"{text}; step {', '.join(str(s) for s in frame.steps)}")
        self.update_buttons(True)

    def _on_failed(self, message: str) -> None:
        self.message.emit(f"<span style='color:#c0392b'>live growth failed: {message}</span>")
        self.update_buttons(True)

    def shutdown(self) -> None:
        self.worker.shutdown()
        self.update_buttons(False)
