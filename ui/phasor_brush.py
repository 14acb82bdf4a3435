"""The brush of the Phasor Infill dock: which field it paints and how.

`BrushControls` binds the brush widgets (field, radius, strength, falloff,
value, tilt, heading, depth) to one thing: the `engine.phasor.strokes.Stroke`
a drag along some points makes (`make_stroke`).  Bad settings are not
checked here: `error` reports the engine's own refusal, with the value as
entered in degrees where the widget shows degrees.
"""

from __future__ import annotations

import math

import numpy as np
from PySide6 import QtCore, QtWidgets

from engine.phasor.fields import MAX_SPREAD
from engine.phasor.strokes import FALLOFFS, FIELDS, Stroke

FIELD_TEXT = {"D": "direction D", "F": "frequency F (cells/mm)", "Gamma": "spread Gamma (deg)"}
VALUE_START = {"F": 1.0, "Gamma": 30.0}   # what the value box shows for a field not edited yet


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
        self.radius_spin = self._spin(0.0, 1e4, 2.0, 0.25, suffix=" mm")
        form.addRow("Radius", self.radius_spin)
        self.strength_spin = self._spin(0.0, 1.0, 1.0, 0.05, decimals=2)
        form.addRow("Strength", self.strength_spin)
        self.falloff_box = QtWidgets.QComboBox()
        for name in FALLOFFS:
            self.falloff_box.addItem(name, name)
        self.falloff_box.currentIndexChanged.connect(lambda _i: self._on_changed())
        form.addRow("Falloff", self.falloff_box)
        # wide ranges on purpose: a bad value is refused with the engine's message
        self.value_spin = self._spin(-1e4, 1e4, 1.0, 0.1, decimals=4)
        self.value_label = QtWidgets.QLabel("Value")
        form.addRow(self.value_label, self.value_spin)
        self.tilt_spin = self._spin(-360.0, 360.0, 0.0, 5.0, decimals=1, suffix="°")
        self.tilt_spin.setToolTip("D: tilt out of the slice plane, towards +normal")
        form.addRow("Tilt", self.tilt_spin)
        heading = QtWidgets.QHBoxLayout()
        self.heading_check = QtWidgets.QCheckBox("fixed")
        self.heading_check.setToolTip("D: paint one in-plane heading instead of the drag direction")
        self.heading_check.toggled.connect(lambda _b: self._on_changed())
        self.heading_spin = self._spin(-360.0, 360.0, 0.0, 15.0, decimals=1, suffix="°")
        heading.addWidget(self.heading_check)
        heading.addWidget(self.heading_spin, 1)
        form.addRow("Heading", heading)
        self.depth_spin = self._spin(0.0, 1e4, 0.0, 0.25, suffix=" mm")
        self.depth_spin.setSpecialValueText("= radius")
        self.depth_spin.setToolTip("how far the brush reaches out of the slice plane")
        form.addRow("Depth", self.depth_spin)
        self._show_field()

    def _spin(self, lo, hi, value, step, decimals=3, suffix=""):
        s = QtWidgets.QDoubleSpinBox()
        s.setRange(lo, hi)
        s.setDecimals(decimals)
        s.setSingleStep(step)
        s.setValue(value)
        s.setSuffix(suffix)
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
        """Label, unit and remembered value of the value box for the current field."""
        name = self.field
        self.value_spin.blockSignals(True)
        if name in VALUE_START:
            self.value_label.setText("F (cells/mm)" if name == "F" else "Gamma")
            self.value_spin.setSuffix("" if name == "F" else "°")
            self.value_spin.setValue(self.value_spin.property(name) or VALUE_START[name])
        self.value_spin.blockSignals(False)
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
            self.value_spin.setProperty(self.field, self.value_spin.value())
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
        except ValueError as exc:
            text = str(exc)
            if self.field == "Gamma":
                text += f" (entered {self.value_spin.value():g}°, allowed 0..{math.degrees(MAX_SPREAD):g}°)"
            elif self.field == "D" and "tilt" in text:
                text += f" (entered {self.tilt_spin.value():g}°, allowed -90..90°)"
            return text
        return None
