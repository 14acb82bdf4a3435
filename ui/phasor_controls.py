"""Small control bindings of the Phasor Infill dock: the slice chooser and the progress row.

`SliceControls` binds the axis box, the scrub slider, the display and the
engine boxes to the slice the dock shows (an axis, a position in mm through
the fields' box, a display, an evaluator).  `ProgressRow` is the bar with
Cancel that shows only for work lasting longer than PROGRESS_DELAY_MS.
"""

from __future__ import annotations

import numpy as np
from PySide6 import QtCore, QtWidgets

from engine.phasor.preview import AXES, axis_span

DISPLAYS = (("diamonds", "Diamond cells"), ("p_v", "p_v sawtooth"), ("field", "Painted field"),
            ("singularity", "Singularity S"))
POSITION_STEPS = 200
PROGRESS_DELAY_MS = 300


class SliceControls(QtWidgets.QWidget):
    """Axis, position, display and engine of the dock's slice.

    Signals
    -------
    view_changed() : axis, position or display changed
    engine_changed() : the evaluator changed
    """

    view_changed = QtCore.Signal()
    engine_changed = QtCore.Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        lay = QtWidgets.QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        row = QtWidgets.QHBoxLayout()
        row.addWidget(QtWidgets.QLabel("Slice ⟂"))
        self.axis_box = QtWidgets.QComboBox()
        for a in AXES:
            self.axis_box.addItem(a, a)
        self.axis_box.setCurrentIndex(2)
        self.axis_box.currentIndexChanged.connect(lambda _i: self.view_changed.emit())
        row.addWidget(self.axis_box)
        self.position_slider = QtWidgets.QSlider(QtCore.Qt.Orientation.Horizontal)
        self.position_slider.setRange(0, POSITION_STEPS - 1)
        self.position_slider.setValue(POSITION_STEPS // 2)
        self.position_slider.valueChanged.connect(lambda _v: self.view_changed.emit())
        row.addWidget(self.position_slider, 1)
        self.position_label = QtWidgets.QLabel("")
        row.addWidget(self.position_label)
        lay.addLayout(row)

        row = QtWidgets.QHBoxLayout()
        row.addWidget(QtWidgets.QLabel("Show"))
        self.display_box = QtWidgets.QComboBox()
        for key, text in DISPLAYS:
            self.display_box.addItem(text, key)
        self.display_box.currentIndexChanged.connect(lambda _i: self.view_changed.emit())
        row.addWidget(self.display_box, 1)
        self.engine_box = QtWidgets.QComboBox()
        self.engine_box.addItem("GPU", "gpu")
        self.engine_box.addItem("numpy", "numpy")
        self.engine_box.setToolTip("pattern evaluator (GPU falls back to numpy without EGL)")
        self.engine_box.currentIndexChanged.connect(lambda _i: self.engine_changed.emit())
        row.addWidget(self.engine_box)
        lay.addLayout(row)

    @property
    def axis(self) -> str:
        return self.axis_box.currentData()

    @property
    def display(self) -> str:
        return self.display_box.currentData()

    @property
    def engine(self) -> str:
        return self.engine_box.currentData()

    def position(self, fields) -> float:
        """mm along the slice normal through the box of ``fields`` (0 without fields)."""
        if fields is None:
            return 0.0
        a, b = axis_span(fields.lo, fields.hi, self.axis)
        return a + (self.position_slider.value() + 0.5) * (b - a) / POSITION_STEPS

    def set_slice(self, axis: str, position: float | None, fields) -> None:
        """Show the slice normal to ``axis`` at the scrub step nearest ``position`` mm
        (without signals: the caller redraws)."""
        self.axis_box.blockSignals(True)
        self.axis_box.setCurrentIndex(AXES.index(axis))
        self.axis_box.blockSignals(False)
        if position is not None and fields is not None:
            a, b = axis_span(fields.lo, fields.hi, axis)
            step = int(round((position - a) / (b - a) * POSITION_STEPS - 0.5))
            self.position_slider.blockSignals(True)
            self.position_slider.setValue(int(np.clip(step, 0, POSITION_STEPS - 1)))
            self.position_slider.blockSignals(False)

    def set_display(self, key: str) -> None:
        self.display_box.setCurrentIndex([k for k, _ in DISPLAYS].index(key))


class ProgressRow(QtWidgets.QWidget):
    """A progress bar with Cancel, shown once work has run for PROGRESS_DELAY_MS.

    ``is_busy`` (callable -> bool) says whether anything still runs when the delay
    has passed.  Signal ``cancel_clicked()``.
    """

    cancel_clicked = QtCore.Signal()

    def __init__(self, is_busy, parent=None):
        super().__init__(parent)
        self._is_busy = is_busy
        row = QtWidgets.QHBoxLayout(self)
        row.setContentsMargins(0, 0, 0, 0)
        self.progress = QtWidgets.QProgressBar()
        self.progress.setTextVisible(True)
        self.cancel_button = QtWidgets.QPushButton("Cancel")
        self.cancel_button.clicked.connect(self.cancel_clicked)
        row.addWidget(self.progress, 1)
        row.addWidget(self.cancel_button)
        self._timer = QtCore.QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.timeout.connect(self._show)
        self.hide()

    def busy(self, busy: bool) -> None:
        """Work started (show the row after the delay) or everything ended (hide it)."""
        if busy:
            self._timer.start(PROGRESS_DELAY_MS)
        elif not self._is_busy():
            self._timer.stop()
            self.hide()

    def _show(self) -> None:
        if self._is_busy():
            self.progress.setRange(0, 0)
            self.show()

    def set_progress(self, done: float, total: float) -> None:
        if total > 0:
            self.progress.setRange(0, int(total))
            self.progress.setValue(int(min(done, total)))
