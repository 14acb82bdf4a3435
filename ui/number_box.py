"""A spin box over an unbounded Python int or float that never changes what was typed.

Qt's QSpinBox / QDoubleSpinBox clamp a typed value to their range (and hold
only 32-bit integers), so ``1000`` in a box limited to 512 silently became
``100``.  `NumberBox` holds any Python number and hands whatever was typed to
its owner, who validates it through the parameter's schema and shows a
refusal at the field.
"""

from __future__ import annotations

import math

from PySide6 import QtCore, QtGui, QtWidgets

from .field_message import REFUSED_COLOUR

_Step = QtWidgets.QAbstractSpinBox.StepEnabledFlag


class NumberBox(QtWidgets.QAbstractSpinBox):
    """Shows one number (with its unit after it); arrows, Up / Down and the wheel
    step it, typed text is handed over on Enter or focus loss.

    committed(object) : the user's new value, a stepped or typed number, or the
        typed text itself when it reads as no number (``int`` boxes hand a typed
        ``1.5`` over as a float): never clamped, never rounded; the owner
        validates it.  Not emitted when the text still shows the held value.
    integer : hold ``int`` (any size: 64-bit seeds) rather than ``float``.
    minimum, maximum : where stepping stops (None: no limit); typed values are
        not limited here.
    unit : shown after the number ("mm"); a typed unit is ignored.
    """

    committed = QtCore.Signal(object)

    def __init__(self, integer: bool = False, minimum: float | None = None, maximum: float | None = None,
                 unit: str = "", parent=None):
        super().__init__(parent)
        self.integer = integer
        self._min, self._max = minimum, maximum
        self.unit = unit
        self._value: int | float = 0 if integer else 0.0
        self.setKeyboardTracking(False)
        self.setAccelerated(True)
        self.lineEdit().setText(self.format(self._value))
        self.editingFinished.connect(self._commit)

    # -- value ----------------------------------------------------------------------------------
    def value(self) -> int | float:
        """The number held (the document's, or the last one committed)."""
        return self._value

    def minimum(self) -> float | None:
        return self._min

    def maximum(self) -> float | None:
        return self._max

    def setValue(self, value: int | float) -> None:
        """Show `value`; emits `committed` when it differs from the held one (a user's edit)."""
        changed = value != self._value
        self.show_value(value)
        if changed:
            self.committed.emit(self._value)

    def show_value(self, value: int | float) -> None:
        """Show `value` without emitting (the document's value)."""
        self._value = int(value) if self.integer else float(value)
        self.lineEdit().setText(self.format(self._value))

    def current(self):
        """What the box shows: the held number while the text is untouched, else the
        typed text parsed (a number, or the text itself)."""
        text = self.lineEdit().text()
        return self._value if text == self.format(self._value) else self.parse(text)

    # -- text -----------------------------------------------------------------------------------
    def format(self, value: int | float) -> str:
        body = str(int(value)) if self.integer else f"{float(value):.6g}"
        return f"{body} {self.unit}" if self.unit else body

    def parse(self, text: str):
        """The number `text` reads as, or the stripped text when it reads as none."""
        body = text.strip()
        if self.unit and body.endswith(self.unit):
            body = body[: -len(self.unit)].strip()
        if self.integer:
            try:
                return int(body)
            except ValueError:
                pass
        try:
            return float(body)
        except ValueError:
            return body

    def _commit(self) -> None:
        value = self.current()
        if isinstance(value, (int, float)) and not isinstance(value, bool) and value == self._value:
            self.show_value(self._value)             # e.g. "32" typed over "32 voxels": nothing changed
            return
        self.committed.emit(value)

    # -- stepping -------------------------------------------------------------------------------
    def stepBy(self, steps: int) -> None:
        base = self._value
        if self.integer:
            new = base + steps
        else:
            a = abs(base)
            step = 0.01 if a < 1e-12 else 10.0 ** (math.floor(math.log10(a)) - 1)
            new = float(f"{base + steps * step:.12g}")
        if self._max is not None and new > self._max:
            new = int(self._max) if self.integer else float(self._max)
        if self._min is not None and new < self._min:
            new = int(self._min) if self.integer else float(self._min)
        self.setValue(new)
        self.selectAll()

    def stepEnabled(self):
        flags = _Step.StepNone
        if self._max is None or self._value < self._max:
            flags |= _Step.StepUpEnabled
        if self._min is None or self._value > self._min:
            flags |= _Step.StepDownEnabled
        return flags

    # -- look -----------------------------------------------------------------------------------
    def paintEvent(self, event: QtGui.QPaintEvent) -> None:
        super().paintEvent(event)
        if self.property("refused"):            # a red frame (a style sheet would restyle the arrows)
            painter = QtGui.QPainter(self)
            painter.setPen(QtGui.QPen(QtGui.QColor(REFUSED_COLOUR), 2))
            painter.drawRect(QtCore.QRectF(self.rect()).adjusted(1, 1, -1, -1))
            painter.end()

    # -- size -----------------------------------------------------------------------------------
    def sizeHint(self) -> QtCore.QSize:
        hint = super().sizeHint()
        sample = self.format(-(10**9) if self.integer else -1.23456e-10)
        width = QtGui.QFontMetrics(self.font()).horizontalAdvance(sample) + 28
        return QtCore.QSize(max(hint.width(), min(width, 220)), hint.height())

    def minimumSizeHint(self) -> QtCore.QSize:
        hint = super().minimumSizeHint()
        return QtCore.QSize(max(hint.width(), 56), hint.height())
