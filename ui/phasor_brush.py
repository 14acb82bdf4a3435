"""The brush of the Phasor Infill dock: which field it paints and how.

`BrushControls` binds the brush widgets (field, radius, strength, falloff,
value, tilt, heading, depth) to one thing: the `engine.phasor.strokes.Stroke`
a drag along some points makes (`make_stroke`).  The number fields are
`ToolNumber`s over the brush's schemas (`engine.nodes.phasor_brush`, made from
the stroke's own limits): a typed value the stroke would refuse is refused at
its field with the allowed range, never clamped or rounded; `error` reports
the engine's refusal of the settings as a whole.
"""

from __future__ import annotations

import math

import numpy as np
from PySide6 import QtCore, QtWidgets

from engine.nodes.phasor_brush import brush_check, brush_param, brush_rule
from engine.phasor.strokes import FALLOFFS, FIELDS, Stroke

from .tool_number import ToolNumber

FIELD_TEXT = {"D": "direction D", "F": "frequency F (cells/mm)", "Gamma": "spread Gamma (deg)"}
VALUE_START = {name: brush_param(name).default for name in ("F", "Gamma")}   # a field not edited yet


class BrushControls(QtWidgets.QGroupBox):
    """The brush's settings.

    Signals
    -------
    changed() : a setting changed (the field included)
    field_changed() : the painted field changed (D, F or Gamma)
    """

    changed = QtCore.Signal()
    field_changed = QtCore.Signal()

    def __init__(self, parent=None):
        super().__init__("Brush", parent)
        form = QtWidgets.QFormLayout(self)
        self.field_box = QtWidgets.QComboBox()
        for name in FIELDS:
            self.field_box.addItem(FIELD_TEXT[name], name)
        self.field_box.setCurrentIndex(1)
        self.field_box.currentIndexChanged.connect(self._on_field_changed)
        form.addRow("Paints", self.field_box)
        self.radius_spin = self._number("radius")
        form.addRow("Radius", self.radius_spin)
        self.strength_spin = self._number("strength")
        form.addRow("Strength", self.strength_spin)
        self.falloff_box = QtWidgets.QComboBox()
        for name in FALLOFFS:
            self.falloff_box.addItem(name, name)
        self.falloff_box.currentIndexChanged.connect(lambda _i: self._on_changed())
        form.addRow("Falloff", self.falloff_box)
        self.value_spin = self._number("F")           # F or Gamma, as the field says
        self.value_label = QtWidgets.QLabel("Value")
        form.addRow(self.value_label, self.value_spin)
        self.tilt_spin = self._number("tilt")
        form.addRow("Tilt", self.tilt_spin)
        heading = QtWidgets.QHBoxLayout()
        self.heading_check = QtWidgets.QCheckBox("fixed")
        self.heading_check.setToolTip("D: paint one in-plane heading instead of the drag direction")
        self.heading_check.toggled.connect(lambda _b: self._on_changed())
        self.heading_spin = self._number("heading")
        heading.addWidget(self.heading_check, 0, QtCore.Qt.AlignmentFlag.AlignTop)
        heading.addWidget(self.heading_spin, 1)
        form.addRow("Heading", heading)
        self.depth_spin = self._number("depth", special=(0.0, "= radius"))
        form.addRow("Depth", self.depth_spin)
        self._remembered = dict(VALUE_START)       # the value box's value of each field
        self._show_field()

    def _number(self, name: str, special=None) -> ToolNumber:
        s = ToolNumber(brush_param(name), check=brush_check(name), rule=brush_rule(name), special=special)
        s.valueChanged.connect(lambda _v: self._on_changed())
        return s

    # -- state --------------------------------------------------------------------------------
    @property
    def field(self) -> str:
        """The painted field: "D", "F" or "Gamma"."""
        return self.field_box.currentData()

    @property
    def value(self) -> float:
        """The value box as entered (cells/mm for F, degrees for Gamma)."""
        return self.value_spin.value()

    @property
    def radius(self) -> float:
        return self.radius_spin.value()

    @property
    def follows_drag(self) -> bool:
        """A D stroke whose heading is the drag direction (it needs two points)."""
        return self.field == "D" and not self.heading_check.isChecked()

    def _show_field(self) -> None:
        """Label, schema and remembered value of the value box for the current field."""
        name = self.field
        if name in VALUE_START:
            self.value_label.setText("F (cells/mm)" if name == "F" else "Gamma")
            self.value_spin.set_param(brush_param(name), check=brush_check(name), rule=brush_rule(name),
                                      value=self._remembered[name])
        is_d = name == "D"
        self.value_spin.setEnabled(not is_d)
        for w in (self.tilt_spin, self.heading_check, self.heading_spin):
            w.setEnabled(is_d)

    def _on_field_changed(self, *_args) -> None:
        self._show_field()
        self._on_changed()
        self.field_changed.emit()

    def _on_changed(self) -> None:
        if self.field in VALUE_START:
            self._remembered[self.field] = self.value_spin.value()
        self.changed.emit()

    # -- the stroke ---------------------------------------------------------------------------
    def make_stroke(self, points, axis: str, position: float) -> Stroke:
        """The brush's Stroke along ``points`` (k, 2) in-plane mm on the slice normal to
        ``axis`` at ``position`` mm; ValueError (the engine's message) for bad settings."""
        name = self.field
        value = heading = None
        tilt = 0.0
        if name == "F":
            value = self.value_spin.value()
        elif name == "Gamma":
            value = math.radians(self.value_spin.value())
        else:
            tilt = math.radians(self.tilt_spin.value())
            if self.heading_check.isChecked():
                a = math.radians(self.heading_spin.value())
                heading = [math.cos(a), math.sin(a)]
        depth = self.depth_spin.value() or None
        return Stroke(name, axis, position, np.asarray(points, float), self.radius_spin.value(),
                      strength=self.strength_spin.value(), falloff=self.falloff_box.currentData(),
                      value=value, heading=heading, tilt=tilt, depth=depth)

    def error(self, axis: str, position: float) -> str | None:
        """The engine's refusal of the current settings, or None."""
        try:
            self.make_stroke([[0.0, 0.0], [1.0, 0.0]], axis, position)
        except ValueError as exc:       # the fields hold only values their schema allows
            return str(exc)
        return None
