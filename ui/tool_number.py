"""A dock's number field that never changes what was typed: a `NumberBox` and its
`FieldMessage`, configured by an engine `Param`.

Qt's QSpinBox / QDoubleSpinBox clamp a typed value to their range, round it to
their decimals and hold only 32-bit integers, so a brush radius typed as 600
in a box limited to 512 silently became 60.  `ToolNumber` hands what was
typed to the parameter's schema (`Param.coerce`: kind and range) and then to
an optional `check` for rules a range cannot say (``> 0``); a refused value is
shown under the field with the allowed range and the kept value, and the
value held stays what it was.  The range, unit, default and doc live once in
the engine, beside what consumes the value; the tooltip is made from them.

The API is the small part of QSpinBox the docks use: ``value()``,
``setValue(v)`` (as if typed: refused values are refused at the field),
``valueChanged`` (accepted values only), ``setRange`` (a range that depends on
the data), and a ``special`` value shown as words ("= radius", "group mean").
"""

from __future__ import annotations

import dataclasses
from typing import Any, Callable

from PySide6 import QtCore, QtWidgets

from engine.graph import Param, ParamError

from .field_message import FieldMessage, param_tooltip, refusal_text, shown
from .number_box import NumberBox

Check = Callable[[Any], Any]


class _SpecialBox(NumberBox):
    """A NumberBox showing one sentinel value as words, and stepping over the values
    its owner refuses (``accepts``)."""

    special: tuple | None = None          # (value, text)
    accepts: Callable[[Any], bool] | None = None

    def format(self, value):
        if self.special is not None and value == self.special[0]:
            return self.special[1]
        return super().format(value)

    def parse(self, text: str):
        if self.special is not None and text.strip() == self.special[1]:
            return self.special[0]
        return super().parse(text)

    def _commit(self) -> None:
        value = self.current()
        if self.property("refused") and value == self._value:
            self.committed.emit(value)          # the held value typed again: the refusal goes
            return
        super()._commit()

    def stepBy(self, steps: int) -> None:
        # an integer step onto a refused value (resolution 1 between "default" 0 and 2) goes on
        start, found = self._value, False
        blocked = self.blockSignals(True)
        try:
            for _ in range(16):
                before = self._value
                NumberBox.stepBy(self, steps)
                if self._value == before:
                    break                                     # the end of the range
                if not self.integer or self.accepts is None or self.accepts(self._value):
                    found = True
                    break
        finally:
            self.blockSignals(blocked)
        target = self._value
        self.show_value(start)
        if found:
            self.setValue(target)
            self.selectAll()


class ToolNumber(QtWidgets.QWidget):
    """One number setting of a dock: the field and, under it, the refusal of a bad value.

    param : the setting's schema (kind ``int`` or ``float``, range, unit, default, doc);
        the value starts at its default.
    check : callable(value) raising ValueError (whose text says what is allowed) for
        what the range cannot say; not called for the ``special`` value.
    rule : words for the tooltip saying what ``check`` wants (``"> 0"``).
    special : ``(value, text)``: the value shown as ``text`` (within the range).

    Signals
    -------
    valueChanged(object) : an accepted new value (typed, stepped or set)
    """

    valueChanged = QtCore.Signal(object)

    def __init__(self, param: Param, *, check: Check | None = None, rule: str = "",
                 special: tuple | None = None, parent=None):
        super().__init__(parent)
        if param.kind not in ("int", "float"):
            raise ValueError(f"ToolNumber: {param.name!r} is a {param.kind!r} parameter, not a number")
        self.box = _SpecialBox(param.kind == "int", param.minimum, param.maximum, param.unit)
        self.box.special = special
        self.box.accepts = lambda v: self._refusal(v) is None
        self.message = FieldMessage([self.box])
        lay = QtWidgets.QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.setSpacing(1)
        lay.addWidget(self.box)
        lay.addWidget(self.message)
        self.setFocusProxy(self.box)
        self.param, self.check, self.rule = param, check, rule
        self._value = param.coerce(param.default)
        self.box.show_value(self._value)
        self._show_tooltip()
        self.box.committed.connect(self._on_committed)

    # -- the schema ---------------------------------------------------------------------------
    def set_param(self, param: Param, *, check: Check | None = None, rule: str = "",
                  value: Any = None) -> None:
        """Edit another setting in the same field (the brush's value box: F or Gamma),
        showing ``value`` (default: the parameter's default) without emitting."""
        self.param, self.check, self.rule = param, check, rule
        self.box.integer = param.kind == "int"
        self.box._min, self.box._max, self.box.unit = param.minimum, param.maximum, param.unit
        self._show_tooltip()
        self.message.clear()
        self._value = param.coerce(param.default if value is None else value)
        self.box.show_value(self._value)

    def setRange(self, minimum, maximum) -> None:
        """A new range (one that depends on the data); a held value now outside it goes
        back to the parameter's default, which must lie in every range."""
        self.set_param(dataclasses.replace(self.param, minimum=minimum, maximum=maximum),
                       check=self.check, rule=self.rule,
                       value=self._value if _within(self._value, minimum, maximum) else None)

    def minimum(self):
        return self.param.minimum

    def maximum(self):
        return self.param.maximum

    def _show_tooltip(self) -> None:
        tip = param_tooltip(self.param)
        if self.rule:           # "allowed: a finite number in [0, inf] mm, > 0"
            tip = "\n".join(f"{line}, {self.rule}" if line.startswith("allowed:") else line
                            for line in tip.split("\n"))
        if self.box.special is not None:
            tip += f"\n{shown(self.box.special[0])}: {self.box.special[1]}"
        self.tooltip = tip
        self.setToolTip(tip)
        self.box.setToolTip(tip)
        if self.message.refused:
            self.message.refuse(self.message.text())

    # -- the value ----------------------------------------------------------------------------
    def value(self):
        """The setting's value: the default or the last accepted one."""
        return self._value

    def setValue(self, value) -> bool:
        """Take ``value`` as if typed: accepted (``valueChanged`` when it differs) or refused
        at the field (the value held unchanged).  True when accepted."""
        return self._on_committed(value)

    def show_value(self, value) -> None:
        """Show a value read from the document (valid by construction) without emitting."""
        self._value = self.param.coerce(value)
        self.message.clear()
        self.box.show_value(self._value)

    def setKeyboardTracking(self, _on: bool) -> None:
        """Typed text is always taken on Enter or focus loss (QSpinBox compatibility)."""

    def lineEdit(self) -> QtWidgets.QLineEdit:
        return self.box.lineEdit()

    @property
    def refused(self) -> bool:
        return self.message.refused

    def _refusal(self, value) -> str | None:
        """Why ``value`` is refused (the field's message), or None."""
        try:
            v = self.param.coerce(value)
        except ParamError as exc:
            return refusal_text(self.param, exc, self._value)
        special = self.box.special
        if self.check is not None and not (special is not None and v == special[0]):
            try:
                self.check(v)
            except ValueError as exc:
                return f"{self.param.name} = {shown(value)} refused: {exc}; kept {shown(self._value)}"
        return None

    def _on_committed(self, value) -> bool:
        text = self._refusal(value)
        if text is not None:
            self.box.show_value(self._value)
            self.message.refuse(text)
            return False
        v = self.param.coerce(value)
        self.message.clear()
        changed = v != self._value or type(v) is not type(self._value)
        self._value = v
        self.box.show_value(v)
        if changed:
            self.valueChanged.emit(v)
        return True


def _within(value, lo, hi) -> bool:
    return (lo is None or value >= lo) and (hi is None or value <= hi)
