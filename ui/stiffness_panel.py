"""Read-only display of a homogenized `Stiffness` (Material Matrix node, paper 6.6).

The 6x6 tensor (or its compliance) as a table in the usual printed form: one
power of ten for the whole matrix and three decimals, so the largest entry
has four significant digits and six columns fit a narrow dock (tooltips hold
the exact values).  Below it the engineering constants in a compact
two-column grid and what the solve reports about itself: density, symmetry,
Zener ratio, dropped islands, iterations, resolution.  "Copy as JSON" puts
``Stiffness.summary()`` on the clipboard.
"""

from __future__ import annotations

import json
import math

import numpy as np
from PySide6 import QtCore, QtGui, QtWidgets

from engine.physics.values import Stiffness
from engine.physics.elastic import compliance

VOIGT_LABELS = ("xx", "yy", "zz", "yz", "xz", "xy")
PLANE_LABELS = ("xx", "yy", "xy")
VOIGT_TIP = ("Voigt notation, order xx, yy, zz, yz, xz, xy.\n"
             "Shear strains are engineering strains (γ_yz = 2 ε_yz, …), so σ = C ε "
             "with no factors of 2 inside C; S = C⁻¹.")
# Left column: moduli; right column: the Poisson ratios and Reuss averages beside them.
CONSTANT_ROWS = (
    ("E_x", "nu_xy"), ("E_y", "nu_yx"), ("E_z", "nu_yz"),
    ("G_xy", "nu_zy"), ("G_yz", "nu_xz"), ("G_xz", "nu_zx"),
    ("E_avg", "nu_avg"), ("K_voigt", "K_reuss"), ("G_voigt", "G_reuss"),
)
TABLE_DECIMALS = 3  # after scaling the largest entry into [1, 10)
DROPPED_COLOUR = "#e0a030"
SINGULAR_NOTE = ("C is singular: the cell is a mechanism (it carries no load in some direction), "
                 "so it has no compliance, engineering constants or material sphere.")


def format_number(x: float, digits: int = 4) -> str:
    """`digits` significant digits, scientific outside [1e-4, 1e4) with a short exponent."""
    x = float(x)
    if not math.isfinite(x):
        return str(x)
    if x == 0.0:
        return "0"
    text = f"{x:.{digits}g}"
    if "e" in text:
        mantissa, exponent = text.split("e")
        text = f"{mantissa}e{int(exponent)}"
    return text


def format_entry(x: float, decimals: int = TABLE_DECIMALS) -> str:
    """A scaled matrix entry with fixed decimals; "0" when it rounds to zero."""
    text = f"{x:.{decimals}f}"
    return "0" if float(text) == 0.0 else text


def common_exponent(m: np.ndarray) -> int:
    """Power of ten that brings the largest entry of `m` into [1, 10) (0 for a zero matrix)."""
    peak = float(np.abs(m).max())
    return int(math.floor(math.log10(peak))) if peak > 0 and math.isfinite(peak) else 0


def _superscript(n: int) -> str:
    return str(n).translate(str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹"))


def _pretty_name(key: str) -> str:
    """``nu_xy`` -> ``ν_xy``; the subscript stays plain text so it reads in any font."""
    return key.replace("nu_", "ν_")


def _unit_of(key: str) -> str:
    return "" if key.startswith("nu") else "Pa"


class StiffnessPanel(QtWidgets.QGroupBox):
    """Shows one `Stiffness`; `set_stiffness(None)` clears it."""

    def __init__(self, parent=None):
        super().__init__("Stiffness", parent)
        self.stiffness: Stiffness | None = None
        self.compliance: np.ndarray | None = None  # None when C is singular
        self.exponent = 0  # the table shows entries / 10**exponent
        self.show_compliance = False
        outer = QtWidgets.QVBoxLayout(self)
        outer.setContentsMargins(6, 6, 6, 6)
        outer.setSpacing(4)

        head = QtWidgets.QHBoxLayout()
        self.matrix_title = QtWidgets.QLabel("C")
        self.matrix_title.setToolTip(VOIGT_TIP)
        self.compliance_toggle = QtWidgets.QPushButton("Show S")
        self.compliance_toggle.setCheckable(True)
        self.compliance_toggle.setToolTip("Show the compliance S = C⁻¹ instead of the stiffness C")
        self.compliance_toggle.toggled.connect(self.set_show_compliance)
        head.addWidget(self.matrix_title, 1)
        head.addWidget(self.compliance_toggle)
        outer.addLayout(head)

        self.table = self._build_table()
        outer.addWidget(self.table)

        self.note = QtWidgets.QLabel(SINGULAR_NOTE)
        self.note.setWordWrap(True)
        self.note.setStyleSheet(f"color: {DROPPED_COLOUR};")
        self.note.hide()
        outer.addWidget(self.note)

        self.constants_box = QtWidgets.QWidget()
        self.constants_grid = QtWidgets.QGridLayout(self.constants_box)
        self.constants_grid.setContentsMargins(0, 2, 0, 2)
        self.constants_grid.setHorizontalSpacing(8)
        self.constants_grid.setVerticalSpacing(1)
        self.values: dict[str, QtWidgets.QLabel] = {}
        for r, pair in enumerate(CONSTANT_ROWS):
            for c, key in enumerate(pair):
                name = QtWidgets.QLabel(_pretty_name(key))
                name.setStyleSheet("color: #9aa0a6;")
                value = self._value_label()
                self.constants_grid.addWidget(name, r, 2 * c)
                self.constants_grid.addWidget(value, r, 2 * c + 1)
                self.values[key] = value
        self.constants_grid.setColumnStretch(1, 1)
        self.constants_grid.setColumnStretch(3, 1)
        outer.addWidget(self.constants_box)

        info = QtWidgets.QFormLayout()
        info.setContentsMargins(0, 2, 0, 0)
        info.setVerticalSpacing(1)
        for key, text, tip in (
            ("density", "relative density", "solid volume fraction of the cell (after dropping islands)"),
            ("effective_density", "effective density", "base density ρ times the relative density (kg/m³)"),
            ("symmetry", "symmetry", "elastic symmetry class of C in the cell axes"),
            ("zener", "Zener ratio", "2 C44 / (C11 − C12); 1 for an isotropic cubic material"),
            ("dropped_fraction", "dropped islands", "fraction of the cell removed as material not "
                                                    "connected to its periodic neighbours"),
            ("iterations", "CG iterations", "conjugate-gradient iterations of the solve"),
            ("resolution", "voxel resolution", "voxels per cell edge used for the solve"),
        ):
            label = self._value_label()
            label.setToolTip(tip)
            self.values[key] = label
            info.addRow(text, label)
        self.zener_row_label = info.labelForField(self.values["zener"])
        outer.addLayout(info)

        row = QtWidgets.QHBoxLayout()
        self.copy_button = QtWidgets.QPushButton("Copy as JSON")
        self.copy_button.setToolTip("Copy the tensor, constants and solve details to the clipboard")
        self.copy_button.clicked.connect(self.copy_json)
        row.addStretch(1)
        row.addWidget(self.copy_button)
        outer.addLayout(row)
        self.set_stiffness(None)

    # -- construction -------------------------------------------------------------------------
    def _build_table(self) -> QtWidgets.QTableWidget:
        table = QtWidgets.QTableWidget(0, 0)
        table.setEditTriggers(QtWidgets.QAbstractItemView.EditTrigger.NoEditTriggers)
        table.setSelectionMode(QtWidgets.QAbstractItemView.SelectionMode.ContiguousSelection)
        table.setToolTip(VOIGT_TIP)
        font = table.font()
        font.setPointSizeF(font.pointSizeF() * 0.9)
        table.setFont(font)
        hh, vh = table.horizontalHeader(), table.verticalHeader()
        hh.setSectionResizeMode(QtWidgets.QHeaderView.ResizeMode.Stretch)
        hh.setMinimumSectionSize(20)
        vh.setSectionResizeMode(QtWidgets.QHeaderView.ResizeMode.Fixed)
        vh.setDefaultSectionSize(QtGui.QFontMetrics(font).height() + 6)
        for header in (hh, vh):
            header.setToolTip(VOIGT_TIP)
        table.setVerticalScrollBarPolicy(QtCore.Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        self._shape_table(table, VOIGT_LABELS)
        return table

    @staticmethod
    def _shape_table(table: QtWidgets.QTableWidget, labels) -> None:
        """Size the table for a 6x6 (3D) or 3x3 (2D plane stress) matrix."""
        k = len(labels)
        if table.rowCount() == k and table.horizontalHeaderItem(0) is not None \
                and table.horizontalHeaderItem(0).text() == labels[0] and table.columnCount() == k:
            return
        table.setRowCount(k)
        table.setColumnCount(k)
        table.setHorizontalHeaderLabels(labels)
        table.setVerticalHeaderLabels(labels)
        hh, vh = table.horizontalHeader(), table.verticalHeader()
        table.setFixedHeight(hh.sizeHint().height() + k * vh.defaultSectionSize() + 2 * table.frameWidth())
        for r in range(k):
            for c in range(k):
                item = QtWidgets.QTableWidgetItem("")
                item.setTextAlignment(QtCore.Qt.AlignmentFlag.AlignRight | QtCore.Qt.AlignmentFlag.AlignVCenter)
                table.setItem(r, c, item)

    @staticmethod
    def _value_label() -> QtWidgets.QLabel:
        label = QtWidgets.QLabel("")
        label.setTextInteractionFlags(QtCore.Qt.TextInteractionFlag.TextSelectableByMouse)
        return label

    # -- content ----------------------------------------------------------------------------
    def set_stiffness(self, stiffness: Stiffness | None) -> None:
        self.stiffness = stiffness
        self.compliance = None
        singular = False
        if stiffness is not None:
            try:
                self.compliance = compliance(stiffness.C)
            except ValueError:
                singular = True
        self.setEnabled(stiffness is not None)
        self.note.setVisible(singular)
        self.compliance_toggle.setEnabled(self.compliance is not None)
        if self.compliance is None and self.show_compliance:
            self.set_show_compliance(False)
        self._fill_matrix()
        self._fill_values()

    def set_show_compliance(self, on: bool) -> None:
        self.show_compliance = bool(on) and self.compliance is not None
        if self.compliance_toggle.isChecked() != self.show_compliance:
            self.compliance_toggle.setChecked(self.show_compliance)
            return  # toggled() calls back here
        self._fill_matrix()

    def matrix(self) -> np.ndarray | None:
        """The matrix currently shown (C, or S when the toggle is on)."""
        if self.stiffness is None:
            return None
        return self.compliance if self.show_compliance else np.asarray(self.stiffness.C)

    def _fill_matrix(self) -> None:
        m = self.matrix()
        name = "S" if self.show_compliance else "C"
        labels = PLANE_LABELS if m is not None and m.shape == (3, 3) else VOIGT_LABELS
        self._shape_table(self.table, labels)
        k = len(labels)
        self.exponent = common_exponent(m) if m is not None and m.shape == (k, k) else 0
        unit = "1/Pa" if self.show_compliance else "Pa"
        scaled_unit = f"×10{_superscript(self.exponent)} {unit}" if self.exponent else unit
        what = "<b>S</b> = C⁻¹" if self.show_compliance else "<b>C</b>"
        self.matrix_title.setText(f"{what} ({scaled_unit}), Voigt" + (", plane stress" if k == 3 else ""))
        self.compliance_toggle.setText("Show C" if self.show_compliance else "Show S")
        if m is None or m.shape != (k, k):
            for r in range(k):
                for c in range(k):
                    self.table.item(r, c).setText("")
                    self.table.item(r, c).setToolTip(VOIGT_TIP)
            return
        scale = 10.0 ** -self.exponent
        for r in range(k):
            for c in range(k):
                x = float(m[r, c])
                item = self.table.item(r, c)
                item.setText(format_entry(x * scale))
                item.setToolTip(f"{name}[{labels[r]}, {labels[c]}] = {x:.10g} {unit}\n\n{VOIGT_TIP}")

    def _fill_values(self) -> None:
        s = self.stiffness
        for label in self.values.values():
            label.setText("–" if s is None else "")
            label.setStyleSheet("")
        if s is None:
            self._set_zener_visible(False)
            return
        for pair in CONSTANT_ROWS:
            for key in pair:
                value = s.constants.get(key)
                unit = _unit_of(key)
                self.values[key].setText("–" if value is None else format_number(value))
                self.values[key].setToolTip(f"{key} = {value:.10g} {unit}".rstrip() if value is not None else key)
        self.values["density"].setText(format_number(s.density))
        self.values["effective_density"].setText(f"{format_number(s.effective_density)} kg/m³")
        self.values["symmetry"].setText(s.symmetry)
        self._set_zener_visible(s.zener is not None)
        if s.zener is not None:
            self.values["zener"].setText(format_number(s.zener))
        dropped = self.values["dropped_fraction"]
        dropped.setText(format_number(s.dropped_fraction))
        if s.dropped_fraction > 0:
            dropped.setStyleSheet(f"color: {DROPPED_COLOUR}; font-weight: bold;")
            dropped.setText(f"{format_number(s.dropped_fraction)} of the cell removed")
        self.values["iterations"].setText(str(s.iterations))
        grid = getattr(s, "grid_shape", None)
        self.values["resolution"].setText(f"{s.resolution}³" if grid is None else "×".join(map(str, grid)))

    def _set_zener_visible(self, on: bool) -> None:
        self.values["zener"].setVisible(on)
        if self.zener_row_label is not None:
            self.zener_row_label.setVisible(on)

    # -- reading (tests, clipboard) ----------------------------------------------------------------
    def cell_text(self, row: int, column: int) -> str:
        return self.table.item(row, column).text()

    def value_text(self, key: str) -> str:
        return self.values[key].text()

    def json_text(self) -> str:
        if self.stiffness is None:
            return ""
        return json.dumps(self.stiffness.summary(), indent=2, default=_json_default)

    def copy_json(self) -> None:
        text = self.json_text()
        if text:
            QtWidgets.QApplication.clipboard().setText(text)


def _json_default(obj):
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    raise TypeError(f"{type(obj).__name__} is not JSON serialisable")
