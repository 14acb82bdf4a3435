"""The layer chooser of the Virtual Growth dock: axis and layer of a 3D tiling."""

from __future__ import annotations

from PySide6 import QtCore, QtWidgets

from engine.growth.layers import LAYER_AXES

from .growth_images import ARM_DOWN_RGB, ARM_UP_RGB

AXIS_TEXT = {"z": "z (x-y layers)", "y": "y (x-z layers)", "x": "x (y-z layers)"}


class LayerRow(QtWidgets.QWidget):
    """Axis combo and layer slider; `changed` when either moves (after `fit`)."""

    changed = QtCore.Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        h = QtWidgets.QHBoxLayout(self)
        h.setContentsMargins(0, 0, 0, 0)
        h.addWidget(QtWidgets.QLabel("Layers along"))
        self.axis_box = QtWidgets.QComboBox()
        for axis in LAYER_AXES:
            self.axis_box.addItem(AXIS_TEXT[axis], axis)
        h.addWidget(self.axis_box)
        self.slider = QtWidgets.QSlider(QtCore.Qt.Orientation.Horizontal)
        self.slider.setRange(0, 0)
        h.addWidget(self.slider, 1)
        self.label = QtWidgets.QLabel("")
        h.addWidget(self.label)
        h.addWidget(QtWidgets.QLabel(f"<span style='color:rgb{ARM_UP_RGB}'>&#9679;</span> up "
                                     f"<span style='color:rgb{ARM_DOWN_RGB}'>&#9679;</span> down"))
        self.setToolTip("a 3D tiling is shown layer by layer: beams in the layer plane as "
                        "lines, beams to the next layer as small blue discs, to the "
                        "previous layer as larger orange discs")
        self._shape: tuple = ()
        self.axis_box.currentIndexChanged.connect(self._moved)
        self.slider.valueChanged.connect(self._moved)
        self.hide()

    @property
    def axis(self) -> str:
        return self.axis_box.currentData() or "z"

    @property
    def layer(self) -> int:
        return int(self.slider.value())

    def set_layer(self, axis: str, index: int) -> None:
        """Show layer ``index`` along ``axis`` ("z", "y" or "x")."""
        self.axis_box.setCurrentIndex(list(LAYER_AXES).index(axis))
        self.slider.setValue(int(index))

    def fit(self, shape: tuple) -> None:
        """Fit the slider to the layers of a grid of ``shape`` (nz, ny, nx)."""
        self._shape = tuple(shape)
        n = self._shape[LAYER_AXES[self.axis][0]]
        self.slider.blockSignals(True)
        self.slider.setRange(0, n - 1)
        self.slider.setValue(min(self.slider.value(), n - 1))
        self.slider.blockSignals(False)
        self.label.setText(f"{self.axis} = {self.layer} / {n - 1}")

    def _moved(self, _value=None) -> None:
        if self._shape:
            self.fit(self._shape)
            self.changed.emit()
