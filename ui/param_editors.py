"""Editors of one node parameter each, chosen by the parameter's kind.

An editor's ``widget`` is what goes in a form; ``edited(value)`` fires when
the user changed the value, ``set_value`` shows the document's value without
emitting.  Ranges, units and tooltips come from the `Param` schema.
"""

from __future__ import annotations

import math
from typing import Any, Callable

from PySide6 import QtCore, QtGui, QtWidgets

from engine.graph import Param

_BIG = 1e15


class SciSpinBox(QtWidgets.QDoubleSpinBox):
    """A float spin box that shows values with 6 significant digits, so both
    1e-4 and 2e11 read well, and steps by a tenth of the value's magnitude."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setDecimals(15)
        self.setKeyboardTracking(False)
        self.setRange(-_BIG, _BIG)
        self.setAccelerated(True)

    def textFromValue(self, value: float) -> str:
        return f"{value:.6g}"

    def valueFromText(self, text: str) -> float:
        try:
            return float(self._strip(text))
        except ValueError:
            return self.value()

    def validate(self, text: str, pos: int):
        body = self._strip(text)
        try:
            float(body)
            return QtGui.QValidator.State.Acceptable, text, pos
        except ValueError:
            ok = all(c in "0123456789+-.eE" for c in body)
            state = QtGui.QValidator.State.Intermediate if ok else QtGui.QValidator.State.Invalid
            return state, text, pos

    def _strip(self, text: str) -> str:
        body = text.strip()
        if self.suffix() and body.endswith(self.suffix().strip()):
            body = body[: -len(self.suffix().strip())]
        return body.strip()

    def stepBy(self, steps: int) -> None:
        a = abs(self.value())
        step = 0.01 if a < 1e-12 else 10.0 ** (math.floor(math.log10(a)) - 1)
        self.setValue(self.value() + steps * step)


def float_box(param: Param) -> SciSpinBox:
    """A SciSpinBox over the parameter's range, with its unit as suffix."""
    box = SciSpinBox()
    box.setRange(-_BIG if param.minimum is None else param.minimum, _BIG if param.maximum is None else param.maximum)
    if param.unit:
        box.setSuffix(f" {param.unit}")
    return box


class ParamEditor(QtCore.QObject):
    """Edits one parameter.  `edited(value)` when the user changed it; `set_value` never emits."""

    edited = QtCore.Signal(object)

    def __init__(self, param: Param, parent=None):
        super().__init__(parent)
        self.param = param
        self.widget = self._build()
        tip = param.doc
        rng = self._range_text()
        self.widget.setToolTip("\n".join(t for t in (tip, rng) if t))

    def _range_text(self) -> str:
        lo, hi = self.param.minimum, self.param.maximum
        if lo is None and hi is None:
            return ""
        unit = f" {self.param.unit}" if self.param.unit else ""
        return f"range [{'-inf' if lo is None else f'{lo:g}'}, {'inf' if hi is None else f'{hi:g}'}]{unit}"

    def _build(self) -> QtWidgets.QWidget:  # pragma: no cover - overridden
        raise NotImplementedError

    def set_value(self, value: Any) -> None:  # pragma: no cover - overridden
        raise NotImplementedError

    def _blocked(self, widgets, fn: Callable[[], None]) -> None:
        old = [w.blockSignals(True) for w in widgets]
        try:
            fn()
        finally:
            for w, o in zip(widgets, old):
                w.blockSignals(o)


class FloatEditor(ParamEditor):
    def _build(self):
        self.box = float_box(self.param)
        self.box.valueChanged.connect(lambda v: self.edited.emit(float(v)))
        return self.box

    def set_value(self, value):
        self._blocked([self.box], lambda: self.box.setValue(float(value)))


class IntEditor(ParamEditor):
    def _build(self):
        self.box = QtWidgets.QSpinBox()
        # a QSpinBox holds 32-bit integers: wider schema ranges are cut to what it can show
        lo = max(-(2**31 - 1), -(2**31 - 1) if self.param.minimum is None else int(self.param.minimum))
        hi = min(2**31 - 1, 2**31 - 1 if self.param.maximum is None else int(self.param.maximum))
        self.box.setRange(lo, hi)
        self.box.setKeyboardTracking(False)
        self.box.setAccelerated(True)
        if self.param.unit:
            self.box.setSuffix(f" {self.param.unit}")
        self.box.valueChanged.connect(lambda v: self.edited.emit(int(v)))
        return self.box

    def set_value(self, value):
        self._blocked([self.box], lambda: self.box.setValue(int(value)))


class BoolEditor(ParamEditor):
    def _build(self):
        self.box = QtWidgets.QCheckBox()
        self.box.toggled.connect(lambda v: self.edited.emit(bool(v)))
        return self.box

    def set_value(self, value):
        self._blocked([self.box], lambda: self.box.setChecked(bool(value)))


class EnumEditor(ParamEditor):
    def _build(self):
        self.box = QtWidgets.QComboBox()
        for choice in self.param.choices:
            self.box.addItem(str(choice), choice)
        self.box.currentIndexChanged.connect(lambda i: self.edited.emit(self.box.itemData(i)))
        return self.box

    def set_value(self, value):
        self._blocked([self.box], lambda: self.box.setCurrentIndex(max(0, self.box.findData(value))))


class StrEditor(ParamEditor):
    def _build(self):
        self.box = QtWidgets.QLineEdit()
        self.box.editingFinished.connect(lambda: self.edited.emit(self.box.text()))
        return self.box

    def set_value(self, value):
        self._blocked([self.box], lambda: self.box.setText(str(value)))


class Vec3Editor(ParamEditor):
    def _build(self):
        w = QtWidgets.QWidget()
        lay = QtWidgets.QHBoxLayout(w)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.setSpacing(2)
        self.boxes = []
        for axis in "xyz":
            box = float_box(Param(self.param.name, "float", 0.0, self.param.minimum, self.param.maximum))
            box.setToolTip(axis)
            box.setMinimumWidth(56)
            box.valueChanged.connect(lambda _v: self.edited.emit([b.value() for b in self.boxes]))
            lay.addWidget(box)
            self.boxes.append(box)
        return w

    def set_value(self, value):
        def apply():
            for box, v in zip(self.boxes, value):
                box.setValue(float(v))
        self._blocked(self.boxes, apply)


class IntListEditor(ParamEditor):
    """Integers as text: ``0, 1, 2`` (empty for an empty list)."""

    def _build(self):
        self.box = QtWidgets.QLineEdit()
        self.box.setPlaceholderText("e.g. 0, 1, 2")
        self.box.editingFinished.connect(self._commit)
        return self.box

    def _commit(self):
        text = self.box.text().strip()
        parts = [p for p in text.replace(";", ",").replace(" ", ",").split(",") if p]
        try:
            self.edited.emit([int(p) for p in parts])
        except ValueError:
            self.edited.emit(text)  # refused by the schema with a message naming the parameter

    def set_value(self, value):
        self._blocked([self.box], lambda: self.box.setText(", ".join(str(v) for v in value)))
