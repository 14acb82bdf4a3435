"""The RD dock's "Live growth" box: buttons, progress and the G^t plot over a `LiveGrowthWorker`."""

from __future__ import annotations

from PySide6 import QtCore, QtWidgets

from engine.nodes.rd_brush import LIVE_EVERY

from .rd_canvas import GrowthPlot
from .tool_number import ToolNumber
from .rd_worker import LiveFrame, LiveGrowthWorker


class LiveGrowthBox(QtWidgets.QGroupBox):
    """Grow live, Pause / Resume, Cancel, Apply, the frame interval, a progress bar,
    the step and G^t, a G^t plot.

    ``session_factory()`` (set by the owner) returns the RDGrowNode's
    `RDGrowthSession` to run, None when there is none, or raises ValueError
    saying why the node refuses.  ``adopt_result(node_id, outputs, inputs)``
    (set by the owner: the window's, `ui.window_evaluation`; or None) takes a
    finished growth as the node's result (`adopt`).

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
        self.session_factory = None
        self.adopt_result = None
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
        self.apply_button.setToolTip("evaluate the document; a growth run to the end with the node's "
                                     "parameters is taken as the RDGrow node's result, so only what "
                                     "follows it evaluates (the live run never changes the document)")
        self.apply_button.clicked.connect(self.apply)
        for b in (self.grow_button, self.pause_button, self.cancel_button, self.apply_button):
            row.addWidget(b)
        row.addWidget(QtWidgets.QLabel("every"))
        self.every_spin = ToolNumber(LIVE_EVERY)
        row.addWidget(self.every_spin, 0, QtCore.Qt.AlignmentFlag.AlignTop)
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
        """Start a growth from ``session_factory``; False (with a message) when there is none."""
        try:
            session = self.session_factory() if self.session_factory else None
        except ValueError as exc:
            self.message.emit(f"<span style='color:#c0392b'>cannot grow: {exc}</span>")
            return False
        if session is None:
            self.message.emit("live growth needs an RDGrow node fed by evaluated RD fields")
            return False
        self.worker.start(session, every=self.every_spin.value())
        self.bar.setRange(0, max(1, session.max_steps * len(session.directions)))
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

    def finished_value(self, params: dict, seed: int):
        """The RDGrow node's value (brush edits applied) of a growth run to the end with the
        node parameters ``params`` and node seed ``seed``; None for any other growth."""
        w, session = self.worker, self.worker.session
        if session is None or w.status != "done" or session.value is None:
            return None
        return session.value if session.params == dict(params) and session.seed == int(seed) else None

    def adopt(self, grow, doc) -> bool:
        """Hand the growth to ``adopt_result`` as RDGrow node ``grow``'s result in ``doc`` when it ran
        to the end with the node's parameters and seed now, with the fields it grew from (the
        evaluator takes it only if they are its cached input of the node).  False when not handed."""
        from engine.graph.node import node_seed

        value = None if grow is None else self.finished_value(grow.params, node_seed(doc.seed, grow.id))
        if value is None or self.adopt_result is None:
            return False
        return bool(self.adopt_result(grow.id, {"structures": value}, {"rdfields": value.fields.source_of()}))

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
        session = self.worker.session
        self.bar.setValue(int(sum(frame.steps)))
        gs = ", ".join(f"{g:.3g}" for g in frame.last_g)
        steps = ", ".join(str(s) for s in frame.steps)
        self.label.setText(f"{frame.status}: step {steps} of {session.max_steps}, G^t = {gs}")
        self.plot.set_curves([(h[:, 0], h[:, 1]) for h in frame.g_history], eps=session.eps or None)
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
