"""Editors of one node parameter each, chosen by the parameter's kind.

An editor's ``widget`` is what goes in a form; ``edited(value)`` fires when
the user changed the value, ``set_value`` shows the document's value without
emitting.  A typed value is handed over as typed -- never clamped to the
range, rounded or dropped -- so the schema (`Param.coerce`, through
`SetParam`) refuses it with a message the owner shows at the field.  Ranges,
units and tooltips come from the `Param` schema.
"""

from __future__ import annotations

from typing import Any, Callable

from PySide6 import QtCore, QtWidgets

from engine.graph import Param

from .field_message import param_tooltip
from .number_box import NumberBox


def number_box(param: Param, integer: bool = False) -> NumberBox:
    """A NumberBox stepping within the parameter's range, with its unit; typed
    values are not limited by it (the schema refuses them with a message)."""
    return NumberBox(integer, param.minimum, param.maximum, param.unit)


class ParamEditor(QtCore.QObject):
    """Edits one parameter.  `edited(value)` when the user changed it (the value
    as typed: out of range or not a number, for the schema to refuse);
    `set_value` never emits.  Every input's tooltip gives the parameter's doc,
    allowed range, unit and default."""

    edited = QtCore.Signal(object)

    def __init__(self, param: Param, parent=None):
        super().__init__(parent)
        self.param = param
        self.widget = self._build()
        self.tooltip = param_tooltip(param)
        self.widget.setToolTip(self.tooltip)
        for w in self.inputs():
            if w is not self.widget:
                w.setToolTip(self.tooltip if not w.toolTip() else f"{w.toolTip()}: {self.tooltip}")

    def inputs(self) -> list[QtWidgets.QWidget]:
        """The widgets a user types or clicks in (framed red on a refusal)."""
        box = getattr(self, "box", None) or getattr(self, "table", None)
        return [box] if box is not None else [self.widget]

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
        self.box = number_box(self.param)
        self.box.committed.connect(self.edited.emit)
        return self.box

    def set_value(self, value):
        self._blocked([self.box], lambda: self.box.show_value(float(value)))


class IntEditor(ParamEditor):
    """Any Python int (64-bit seeds too): no 32-bit QSpinBox."""

    def _build(self):
        self.box = number_box(self.param, integer=True)
        self.box.committed.connect(self.edited.emit)
        return self.box

    def set_value(self, value):
        self._blocked([self.box], lambda: self.box.show_value(int(value)))


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
            box = number_box(self.param)
            box.setToolTip(axis)
            box.setMinimumWidth(56)
            # the untouched components keep their exact values (not the 6 digits shown)
            box.committed.connect(lambda _v: self.edited.emit([b.current() for b in self.boxes]))
            lay.addWidget(box)
            self.boxes.append(box)
        return w

    def inputs(self):
        return list(self.boxes)

    def set_value(self, value):
        def apply():
            for box, v in zip(self.boxes, value):
                box.show_value(float(v))
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
