"""The "Adjacency" tab of the Tile Sets dock: which blocks may sit next to which.

A matrix per face (rows: block, columns: the block across that face) counts
the allowed orientation pairs; clicking a cell lists each pair and the rule
or connector label that decides it (``engine.growth.tileset_edit``).
"""

from __future__ import annotations

from PySide6 import QtCore, QtGui, QtWidgets

from engine.growth.tileset_edit import block_adjacency, explain_adjacency

from .tileset_widgets import _set_items

CELL_COLOURS = {"all": "#cfe8c8", "some": "#f3e1b0", "none": "#f0c4c4"}


class AdjacencyView(QtWidgets.QWidget):
    """Face chooser, block adjacency matrix and the pairs of the clicked cell."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.tileset = None
        lay = QtWidgets.QVBoxLayout(self)
        row = QtWidgets.QHBoxLayout()
        row.addWidget(QtWidgets.QLabel("Column block across face"))
        self.face_box = QtWidgets.QComboBox()
        self.face_box.currentIndexChanged.connect(lambda *_: self.show_matrix())
        row.addWidget(self.face_box)
        row.addWidget(QtWidgets.QLabel("of row block: allowed / orientation pairs"))
        row.addStretch(1)
        lay.addLayout(row)
        self.matrix = QtWidgets.QTableWidget()
        self.matrix.setEditTriggers(QtWidgets.QAbstractItemView.EditTrigger.NoEditTriggers)
        self.matrix.currentCellChanged.connect(lambda *_: self.show_pairs())
        lay.addWidget(self.matrix, 2)
        self.pair_list = QtWidgets.QListWidget()
        lay.addWidget(self.pair_list, 1)

    def set_tileset(self, ts) -> None:
        """Show the adjacency of ``ts`` (None clears)."""
        self.tileset = ts
        self.face_box.blockSignals(True)
        _set_items(self.face_box, list(ts.faces) if ts is not None else [])
        self.face_box.blockSignals(False)
        self.show_matrix()

    def show_matrix(self) -> None:
        ts = self.tileset
        face = self.face_box.currentText()
        if ts is None or not face:
            self.matrix.setRowCount(0)
            self.matrix.setColumnCount(0)
            self.pair_list.clear()
            return
        allowed, total = block_adjacency(ts, face)
        names = list(ts.block_names)
        self.matrix.blockSignals(True)
        self.matrix.setRowCount(len(names))
        self.matrix.setColumnCount(len(names))
        self.matrix.setVerticalHeaderLabels(names)
        self.matrix.setHorizontalHeaderLabels(names)
        for i in range(len(names)):
            for j in range(len(names)):
                k, n = int(allowed[i, j]), int(total[i, j])
                cell = QtWidgets.QTableWidgetItem(f"{k}/{n}")
                cell.setTextAlignment(QtCore.Qt.AlignmentFlag.AlignCenter)
                level = "all" if k == n else ("none" if k == 0 else "some")
                cell.setBackground(QtGui.QColor(CELL_COLOURS[level]))
                cell.setToolTip(f"{names[j]} across {face} of {names[i]}: {k} of {n} "
                                f"orientation pairs allowed")
                self.matrix.setItem(i, j, cell)
        self.matrix.resizeColumnsToContents()
        self.matrix.blockSignals(False)
        self.show_pairs()

    def show_pairs(self) -> None:
        self.pair_list.clear()
        ts = self.tileset
        i, j = self.matrix.currentRow(), self.matrix.currentColumn()
        if ts is None or i < 0 or j < 0 or not self.face_box.currentText():
            self.pair_list.addItem("Click a cell to see each orientation pair and why.")
            return
        for v in explain_adjacency(ts, ts.block_names[i], ts.block_names[j],
                                   self.face_box.currentText()):
            item = QtWidgets.QListWidgetItem(f"{v.b} across {v.face} of {v.a}: {v.reason}")
            item.setToolTip(item.text())
            item.setForeground(QtGui.QBrush(QtGui.QColor("#2a7a2a" if v.allowed else "#b03030")))
            self.pair_list.addItem(item)
