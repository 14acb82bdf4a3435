"""The growth replay of the Virtual Growth dock: controls and their controller.

The replay reveals the cells in the order growth decided them, from the grid
as it was before the growth. What to replay comes from the Grow node's plan
(``engine.nodes.growth_plan.GrowthPlan.replay``): the steps recorded with the
tiling (a local regrowth replays as one) at once, else a growth of the
node's parameters with its steps recorded, run in a `TaskRunner` (off the
GUI thread). A `ReplayCursor` holds the position; a QTimer on the GUI thread
moves it; the controller only hands grids to draw (`frame`).
"""

from __future__ import annotations

from typing import Callable

from PySide6 import QtCore, QtWidgets

from engine.nodes.growth_plan import GrowthReplay, ReplayCursor, recorded_history

from .task_runner import TaskRunner

TICK_MS = 20


class ReplayControls(QtWidgets.QWidget):
    """Play / pause button, speed slider (steps per second) and the step label."""

    def __init__(self, parent=None):
        super().__init__(parent)
        v = QtWidgets.QVBoxLayout(self)
        v.setContentsMargins(0, 0, 0, 0)
        row = QtWidgets.QHBoxLayout()
        self.play_button = QtWidgets.QPushButton("Play")
        self.play_button.setCheckable(True)
        self.speed = QtWidgets.QSlider(QtCore.Qt.Orientation.Horizontal)
        self.speed.setRange(1, 2000)
        self.speed.setValue(60)
        self.speed_label = QtWidgets.QLabel()
        self.speed.valueChanged.connect(lambda value: self.speed_label.setText(f"{value} steps/s"))
        self.speed_label.setText(f"{self.speed.value()} steps/s")
        row.addWidget(self.play_button)
        row.addWidget(self.speed, 1)
        row.addWidget(self.speed_label)
        v.addLayout(row)
        self.label = QtWidgets.QLabel("")
        self.label.setWordWrap(True)
        v.addWidget(self.label)
        self.set_enabled(False)

    def set_enabled(self, on: bool) -> None:
        self.play_button.setEnabled(on)
        self.speed.setEnabled(on)


class ReplayController(QtCore.QObject):
    """Steps a replay of the shown tiling and emits the grid to draw.

    `set_source(value, plan_of)`: ``value`` the shown TilingValue, ``plan_of``
    a callable giving the Grow node's GrowthPlan for it (ValueError when the
    parameters are not known). `frame(grid)` after each move; `counted()` asks
    the panel how many cells it shows as decided (for the label)."""

    frame = QtCore.Signal(object)

    def __init__(self, controls: ReplayControls, counted: Callable[[], int], parent=None):
        super().__init__(parent)
        self.controls = controls
        self._counted = counted
        self.value = None
        self._plan_of: Callable | None = None
        self.cursor: ReplayCursor | None = None
        self.error = ""
        self._play_when_ready = False
        self._carry = 0.0
        self.timer = QtCore.QTimer(self)
        self.timer.setInterval(TICK_MS)
        self.timer.timeout.connect(self.tick)
        self.runner = TaskRunner(self)
        self.runner.finished.connect(self._on_grown)
        self.runner.failed.connect(self._on_failed)
        controls.play_button.toggled.connect(self._on_play_toggled)

    # -- source ---------------------------------------------------------------------------------
    def set_source(self, value, plan_of: Callable | None) -> None:
        """Replay ``value`` from now on (stops a running replay)."""
        self.pause()
        self.runner.cancel()
        self.value, self._plan_of = value, plan_of
        self.cursor, self.error, self._play_when_ready = None, "", False
        self.controls.set_enabled(value is not None)
        self.controls.label.setText("")

    @property
    def pos(self) -> int:
        return 0 if self.cursor is None else self.cursor.pos

    @property
    def n_steps(self) -> int:
        return 0 if self.cursor is None else self.cursor.n_steps

    @property
    def note(self) -> str:
        return "" if self.cursor is None else self.cursor.replay.note

    def prepare(self) -> bool:
        """True when the replay is ready; else it is being grown (or cannot be: the label says)."""
        if self.cursor is not None:
            return True
        if self.value is None:
            return False
        recorded = recorded_history(self.value)
        if recorded is not None:
            self.cursor = ReplayCursor(recorded)
            return True
        if self.runner.is_busy:
            return False
        try:
            plan = self._plan_of(self.value) if self._plan_of is not None else None
        except ValueError:
            plan = None
        if plan is None:
            return self._cannot("the growth parameters are not known")
        value = self.value
        self.runner.submit(lambda task: plan.replay(value), data=value)
        self.controls.label.setText("growing the replay...")
        return False

    def _cannot(self, why: str) -> bool:
        self.error = f"cannot replay: {why}"
        self.controls.label.setText(self.error)
        return False

    def _on_grown(self, task, replay: GrowthReplay) -> None:
        if task.data is not self.value:
            return
        self.cursor = ReplayCursor(replay)
        if self._play_when_ready:
            self.play()
        else:
            self.restart()

    def _on_failed(self, task, message: str) -> None:
        if task.data is self.value:
            self._play_when_ready = False
            self._cannot(message)
            self._set_checked(False)

    # -- moving ----------------------------------------------------------------------------------
    def restart(self) -> None:
        """Back to the grid before the growth."""
        if self.prepare():
            self.frame.emit(self.cursor.restart())
            self.update_label()

    def step(self, n: int = 1) -> None:
        """Reveal the next ``n`` growth events."""
        if not self.prepare():
            return
        if self.cursor.step(n):
            self.frame.emit(self.cursor.grid)
        self.update_label()

    def update_label(self) -> None:
        text = f"growth step {self.pos} / {self.n_steps}, {self._counted()} cells assigned"
        if self.note:
            text += f" ({self.note})"
        self.controls.label.setText(text)

    @property
    def playing(self) -> bool:
        return self.timer.isActive()

    def play(self) -> None:
        if not self.prepare():
            self._play_when_ready = self.runner.is_busy
            self._set_checked(self._play_when_ready)
            return
        self._play_when_ready = False
        if self.cursor.pos == 0 or self.cursor.done:
            self.restart()  # start from the grid before the growth
        self._carry = 0.0
        self.timer.start()
        self._set_checked(True)
        self.controls.play_button.setText("Pause")

    def pause(self) -> None:
        self.timer.stop()
        self._play_when_ready = False
        self._set_checked(False)
        self.controls.play_button.setText("Play")

    def _set_checked(self, on: bool) -> None:
        button = self.controls.play_button
        if button.isChecked() != on:
            button.blockSignals(True)
            button.setChecked(on)
            button.blockSignals(False)

    def _on_play_toggled(self, on: bool) -> None:
        if on and not self.playing:
            self.play()
        elif not on and (self.playing or self._play_when_ready):
            self.pause()

    def tick(self) -> None:
        self._carry += self.controls.speed.value() * TICK_MS / 1000.0
        n = int(self._carry)
        self._carry -= n
        if n:
            self.step(n)
        if self.cursor is None or self.cursor.done:
            self.pause()

    def shutdown(self) -> None:
        self.pause()
        self.runner.shutdown()
