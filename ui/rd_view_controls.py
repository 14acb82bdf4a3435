"""The RD dock's small control rows: the problem source, what to show, the before / after comparison.

Each row is one binding: widgets and the signal the dock listens to; the
dock decides what a change means.
"""

from __future__ import annotations

from PySide6 import QtCore, QtWidgets

from .rd_canvas import COMPARE_MODES

COMPARE_TEXT = {"now": "Now", "before": "Before last edit", "split": "Split: before | now"}
ORDINAL = ("1st", "2nd", "3rd")


def view_keys(d: int) -> list:
    """The views of a ``d``-dimensional chain: inputs, tensor directions, structures, the result."""
    return ["rho", "gamma"] + [f"tensor{i}" for i in range(d)] + [f"s{i}" for i in range(d)] + ["combined"]


def view_text(key: str) -> str:
    """The label of view ``key``."""
    fixed = {"rho": "Infill space rho", "gamma": "Infill map Gamma", "combined": "Combined result"}
    if key in fixed:
        return fixed[key]
    i = int(key[-1])
    return (f"Tensor field: {ORDINAL[i]} principal direction" if key.startswith("tensor")
            else f"Structure s_{i + 1} (⟂ {ORDINAL[i]} direction)")


class SourceRow(QtWidgets.QWidget):
    """The TopOpt node's preset and "Import fields…" into the RDFields node.

    Signals: preset_chosen(str) (the user picked a preset), import_clicked()."""

    preset_chosen = QtCore.Signal(str)
    import_clicked = QtCore.Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        row = QtWidgets.QHBoxLayout(self)
        row.setContentsMargins(0, 0, 0, 0)
        row.addWidget(QtWidgets.QLabel("Preset"))
        self.preset_box = QtWidgets.QComboBox()
        self.preset_box.setToolTip("the TopOpt node's problem (the paper's presets)")
        self.preset_box.activated.connect(lambda _i: self.preset_chosen.emit(self.preset_box.currentData()))
        row.addWidget(self.preset_box, 1)
        self.import_button = QtWidgets.QPushButton("Import fields…")
        self.import_button.setToolTip("read rho, sigma or R (and Gamma) from an .npz or .vti file "
                                      "into the RDFields node")
        self.import_button.clicked.connect(self.import_clicked.emit)
        row.addWidget(self.import_button)

    def sync(self, topopt, can_import: bool) -> None:
        """Show ``topopt``'s preset (a Node or None); import enabled when ``can_import``."""
        from engine.graph.node import node_type

        box = self.preset_box
        box.blockSignals(True)
        if box.count() == 0 and topopt is not None:
            for name in node_type("TopOpt").param("preset").choices:
                box.addItem(name, name)
        if topopt is not None:
            box.setCurrentIndex(max(0, box.findData(topopt.params.get("preset"))))
        box.blockSignals(False)
        box.setEnabled(topopt is not None)
        self.import_button.setEnabled(bool(can_import))


class ViewRow(QtWidgets.QWidget):
    """"Show" (which view) and the principal directions' drawing style. Signal: changed()."""

    changed = QtCore.Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        row = QtWidgets.QHBoxLayout(self)
        row.setContentsMargins(0, 0, 0, 0)
        row.addWidget(QtWidgets.QLabel("Show"))
        self.view_box = QtWidgets.QComboBox()
        self.view_box.currentIndexChanged.connect(lambda _i: self.changed.emit())
        row.addWidget(self.view_box, 1)
        self.style_box = QtWidgets.QComboBox()
        self.style_box.addItem("glyphs", "glyphs")
        self.style_box.addItem("streamlines", "streamlines")
        self.style_box.setToolTip("how the principal directions are drawn")
        self.style_box.currentIndexChanged.connect(lambda _i: self.changed.emit())
        row.addWidget(self.style_box)
        self.fill(2)

    def fill(self, d: int) -> None:
        """The views of a ``d``-dimensional chain, keeping the current one if it is still there."""
        keys = view_keys(d)
        box = self.view_box
        if [box.itemData(i) for i in range(box.count())] == keys:
            return
        current = box.currentData()
        box.blockSignals(True)
        box.clear()
        for key in keys:
            box.addItem(view_text(key), key)
        box.setCurrentIndex(keys.index(current) if current in keys else 0)
        box.blockSignals(False)

    @property
    def view(self) -> str:
        return self.view_box.currentData() or "rho"

    def set_view(self, key: str) -> None:
        keys = [self.view_box.itemData(i) for i in range(self.view_box.count())]
        self.view_box.setCurrentIndex(keys.index(key))

    @property
    def style(self) -> str:
        """"glyphs" or "streamlines"."""
        return self.style_box.currentData()


class CompareRow(QtWidgets.QWidget):
    """Before / after: now, before the last edit, or split at a slider position. Signal: changed()."""

    changed = QtCore.Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        row = QtWidgets.QHBoxLayout(self)
        row.setContentsMargins(0, 0, 0, 0)
        row.addWidget(QtWidgets.QLabel("Compare"))
        self.compare_box = QtWidgets.QComboBox()
        for key in COMPARE_MODES:
            self.compare_box.addItem(COMPARE_TEXT[key], key)
        self.compare_box.currentIndexChanged.connect(lambda _i: self.changed.emit())
        row.addWidget(self.compare_box, 1)
        self.split_slider = QtWidgets.QSlider(QtCore.Qt.Orientation.Horizontal)
        self.split_slider.setRange(0, 100)
        self.split_slider.setValue(50)
        self.split_slider.valueChanged.connect(lambda _v: self.changed.emit())
        row.addWidget(self.split_slider, 1)

    @property
    def mode(self) -> str:
        return self.compare_box.currentData()

    @property
    def split(self) -> float:
        """Where the split runs, 0 (left) to 1 (right)."""
        return self.split_slider.value() / 100.0
