"""Editors of structured parameters: (t, value) sample tables and JSON data."""

from __future__ import annotations

import json

from PySide6 import QtWidgets

from .param_editors import ParamEditor


class SamplesEditor(ParamEditor):
    """A table of (t, value) rows with add / remove buttons."""

    def _build(self):
        w = QtWidgets.QWidget()
        lay = QtWidgets.QVBoxLayout(w)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.setSpacing(2)
        self.table = QtWidgets.QTableWidget(0, 2)
        unit = f" ({self.param.unit})" if self.param.unit else ""
        self.table.setHorizontalHeaderLabels(["t", f"value{unit}"])
        self.table.horizontalHeader().setSectionResizeMode(QtWidgets.QHeaderView.ResizeMode.Stretch)
        self.table.verticalHeader().setVisible(False)
        self.table.setMinimumHeight(90)
        self.table.setMaximumHeight(150)
        self.table.cellChanged.connect(lambda _r, _c: self._commit())
        lay.addWidget(self.table)
        row = QtWidgets.QHBoxLayout()
        self.add_button = QtWidgets.QPushButton("+ sample")
        self.remove_button = QtWidgets.QPushButton("− sample")
        self.add_button.clicked.connect(self.add_row)
        self.remove_button.clicked.connect(self.remove_row)
        row.addWidget(self.add_button)
        row.addWidget(self.remove_button)
        row.addStretch(1)
        lay.addLayout(row)
        return w

    def rows(self) -> list:
        """The table as typed: an untouched cell keeps the document's exact value
        (not the 6 digits shown), a cell that reads as no number its text (refused
        by the schema with a message)."""
        out = []
        shown = getattr(self, "_shown", [])
        for r in range(self.table.rowCount()):
            cells = []
            for c in range(2):
                item = self.table.item(r, c)
                text = item.text().strip() if item is not None else ""
                stored = shown[r][c] if r < len(shown) and c < len(shown[r]) else None
                if stored is not None and text == _cell_text(stored):
                    cells.append(stored)
                    continue
                try:
                    cells.append(float(text))
                except ValueError:
                    cells.append(text)
            out.append(cells)
        return out

    def _commit(self):
        self.edited.emit(self.rows())

    def add_row(self):
        rows = self.rows()
        if rows and all(isinstance(v, float) for v in rows[-1]):
            t_last, v_last = rows[-1]
            if len(rows) >= 2 and isinstance(rows[-2][0], float):
                t_new = 0.5 * (rows[-2][0] + t_last)  # split the last interval
            else:
                t_new = min(1.0, t_last + 0.5)
            rows.append([t_new, v_last])
        else:
            rows.append([0.5, 0.1])
        self.edited.emit(rows)

    def remove_row(self):
        rows = self.rows()
        r = self.table.currentRow()
        if not rows:
            return
        del rows[r if 0 <= r < len(rows) else -1]
        self.edited.emit(rows)

    def set_value(self, value):
        self._shown = [list(pair) for pair in value]

        def apply():
            # Items are updated in place: this may run inside the table's own
            # cellChanged emission, when replacing the edited item is unsafe.
            self.table.setRowCount(len(value))
            for r, pair in enumerate(value):
                for c, x in enumerate(pair):
                    item = self.table.item(r, c)
                    if item is None:
                        self.table.setItem(r, c, QtWidgets.QTableWidgetItem(_cell_text(x)))
                    else:
                        item.setText(_cell_text(x))
        self._blocked([self.table], apply)


def _cell_text(x: float) -> str:
    return f"{x:.6g}"


class JsonTextDialog(QtWidgets.QDialog):
    """Edit JSON as text; malformed text is refused in the dialog, which stays
    open with everything typed."""

    def __init__(self, title: str, value, parent=None):
        super().__init__(parent)
        self.setWindowTitle(title)
        self.value = value
        lay = QtWidgets.QVBoxLayout(self)
        self.text = QtWidgets.QPlainTextEdit(json.dumps(value, indent=1))
        self.text.setMinimumSize(420, 260)
        self.error = QtWidgets.QLabel()
        self.error.setStyleSheet("color: #c03030;")
        self.error.setWordWrap(True)
        buttons = QtWidgets.QDialogButtonBox(QtWidgets.QDialogButtonBox.StandardButton.Ok
                                             | QtWidgets.QDialogButtonBox.StandardButton.Cancel)
        buttons.accepted.connect(self.try_accept)
        buttons.rejected.connect(self.reject)
        lay.addWidget(self.text, 1)
        lay.addWidget(self.error)
        lay.addWidget(buttons)

    def try_accept(self) -> bool:
        try:
            self.value = json.loads(self.text.toPlainText())
        except ValueError as exc:
            self.error.setText(f"not valid JSON: {exc}")
            return False
        self.accept()
        return True


class JsonEditor(ParamEditor):
    """Structured data (brush strokes, loads and supports...): shown as a summary,
    edited as JSON text in a dialog, or cleared, each one undoable step."""

    def _build(self):
        w = QtWidgets.QWidget()
        row = QtWidgets.QHBoxLayout(w)
        row.setContentsMargins(0, 0, 0, 0)
        self.value = None
        self.label = QtWidgets.QLabel()
        self.edit_button = QtWidgets.QPushButton("Edit…")
        self.edit_button.clicked.connect(self.open_dialog)
        self.clear_button = QtWidgets.QPushButton("Clear")
        self.clear_button.clicked.connect(lambda: self.edited.emit({} if isinstance(self.value, dict) else []))
        self.dialog: JsonTextDialog | None = None
        row.addWidget(self.label, 1)
        row.addWidget(self.edit_button)
        row.addWidget(self.clear_button)
        return w

    def open_dialog(self, *, modal: bool = True) -> JsonTextDialog:
        """The JSON text dialog; with ``modal=False`` (tests) it is shown and returned."""
        self.dialog = JsonTextDialog(f"Edit {self.param.name}", self.value, self.widget)
        self.dialog.accepted.connect(lambda: self.edited.emit(self.dialog.value))
        if modal:
            self.dialog.exec()
        else:
            self.dialog.show()
        return self.dialog

    def set_value(self, value):
        self.value = value
        if isinstance(value, list):
            self.label.setText(f"{len(value)} item{'s' if len(value) != 1 else ''}")
        else:
            text = json.dumps(value)
            self.label.setText(text if len(text) <= 60 else text[:57] + "...")
        self.clear_button.setEnabled(isinstance(value, (list, dict)) and bool(value))
