"""The inspector: edits the selected node's parameters from its schema.

Every edit becomes a `SetParam` pushed on the undo stack (successive edits of
one parameter within a second merge into one undo item, as when holding a
spin box arrow).  A value the engine refuses is shown inline and the editor
goes back to the document's value; the document is unchanged.  Widgets are
refreshed from document events, so undo/redo shows up here too.  When the
node's latest evaluation produced a `Stiffness`, a `StiffnessPanel` shows it
under the parameters.
"""

from __future__ import annotations

import json

import math
import time
from typing import Any, Callable

from PySide6 import QtCore, QtGui, QtWidgets

from engine.graph import FAMILY_COLOURS, GraphDocument, GraphError, Param, SetLabel, SetParam, UndoStack, all_node_types
from engine.graph.values import Stiffness

from .stiffness_panel import StiffnessPanel

MERGE_SECONDS = 1.0


class MergingParamPush:
    """Pushes SetParam on an undo stack; quick repeats of the same parameter
    (a spin box being scrolled) merge into one undo item."""

    def __init__(self, undo):
        self.undo = undo
        self._last: tuple[tuple[str, str], float] | None = None

    def reset(self) -> None:
        self._last = None

    def push(self, node_id: str, name: str, value: Any) -> None:
        """Push the edit; a refused value raises GraphError and ends the merge run."""
        key, now = (node_id, name), time.monotonic()
        merge = (self._last is not None and self._last[0] == key and now - self._last[1] < MERGE_SECONDS
                 and self.undo.undo_text() == f"set {node_id}.{name}")
        try:
            self.undo.push(SetParam(node_id, name, value), merge=merge)
        except GraphError:
            self._last = None
            raise
        self._last = (key, now)
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


def _float_box(param: Param) -> SciSpinBox:
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
        return f"range [{'-inf' if lo is None else lo:g}, {'inf' if hi is None else hi:g}]{unit}"

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
        self.box = _float_box(self.param)
        self.box.valueChanged.connect(lambda v: self.edited.emit(float(v)))
        return self.box

    def set_value(self, value):
        self._blocked([self.box], lambda: self.box.setValue(float(value)))


class IntEditor(ParamEditor):
    def _build(self):
        self.box = QtWidgets.QSpinBox()
        lo = -(2**31 - 1) if self.param.minimum is None else int(self.param.minimum)
        hi = 2**31 - 1 if self.param.maximum is None else int(self.param.maximum)
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
            box = _float_box(Param(self.param.name, "float", 0.0, self.param.minimum, self.param.maximum))
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
        out = []
        for r in range(self.table.rowCount()):
            cells = []
            for c in range(2):
                item = self.table.item(r, c)
                text = item.text().strip() if item is not None else ""
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
        def apply():
            # Items are updated in place: this may run inside the table's own
            # cellChanged emission, when replacing the edited item is unsafe.
            self.table.setRowCount(len(value))
            for r, pair in enumerate(value):
                for c, x in enumerate(pair):
                    item = self.table.item(r, c)
                    if item is None:
                        self.table.setItem(r, c, QtWidgets.QTableWidgetItem(f"{x:.6g}"))
                    else:
                        item.setText(f"{x:.6g}")
        self._blocked([self.table], apply)


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


EDITORS = {
    "float": FloatEditor, "int": IntEditor, "bool": BoolEditor, "enum": EnumEditor, "str": StrEditor,
    "vec3": Vec3Editor, "int_list": IntListEditor, "samples": SamplesEditor, "json": JsonEditor,
}

STATUS_COLOURS = {"evaluated": "#5cb85c", "cached": "#5bc0de", "failed": "#e04040",
                  "blocked": "#e0a030", "cancelled": "#999999"}


class Inspector(QtWidgets.QWidget):
    """Parameters, label and evaluation status of one node."""

    message = QtCore.Signal(str, str)

    def __init__(self, doc: GraphDocument, undo: UndoStack, parent=None):
        super().__init__(parent)
        self.doc = doc
        self.undo = undo
        self.node_id: str | None = None
        self.editors: dict[str, ParamEditor] = {}
        self._results: dict = {}
        self._outputs: dict = {}
        self._edits = MergingParamPush(undo)

        outer = QtWidgets.QVBoxLayout(self)
        outer.setContentsMargins(6, 6, 6, 6)
        self.title = QtWidgets.QLabel("No node selected")
        font = self.title.font()
        font.setPointSizeF(font.pointSizeF() * 1.2)
        font.setBold(True)
        self.title.setFont(font)
        outer.addWidget(self.title)
        self.description = QtWidgets.QLabel("Select a node in the editor to edit its parameters.")
        self.description.setWordWrap(True)
        self.description.setStyleSheet("color: #9aa0a6;")
        outer.addWidget(self.description)

        ident = QtWidgets.QFormLayout()
        self.id_label = QtWidgets.QLabel("")
        self.id_label.setTextInteractionFlags(QtCore.Qt.TextInteractionFlag.TextSelectableByMouse)
        self.label_edit = QtWidgets.QLineEdit()
        self.label_edit.setPlaceholderText("(no label)")
        self.label_edit.editingFinished.connect(self._commit_label)
        ident.addRow("id", self.id_label)
        ident.addRow("label", self.label_edit)
        self.ident_box = QtWidgets.QWidget()
        self.ident_box.setLayout(ident)
        outer.addWidget(self.ident_box)

        self.params_box = QtWidgets.QGroupBox("Parameters")
        self.form = QtWidgets.QFormLayout(self.params_box)
        self.form.setFieldGrowthPolicy(QtWidgets.QFormLayout.FieldGrowthPolicy.AllNonFixedFieldsGrow)
        outer.addWidget(self.params_box)

        self.stiffness_panel = StiffnessPanel()
        self.stiffness_panel.hide()
        outer.addWidget(self.stiffness_panel)

        self.error_label = QtWidgets.QLabel("")
        self.error_label.setWordWrap(True)
        self.error_label.setStyleSheet("color: #e04040;")
        self.error_label.setTextInteractionFlags(QtCore.Qt.TextInteractionFlag.TextSelectableByMouse)
        self.error_label.hide()
        outer.addWidget(self.error_label)

        self.status_box = QtWidgets.QGroupBox("Evaluation")
        sl = QtWidgets.QVBoxLayout(self.status_box)
        self.status_label = QtWidgets.QLabel("not evaluated")
        self.status_label.setWordWrap(True)
        self.status_label.setTextInteractionFlags(QtCore.Qt.TextInteractionFlag.TextSelectableByMouse)
        sl.addWidget(self.status_label)
        outer.addWidget(self.status_box)
        outer.addStretch(1)

        doc.subscribe(self._on_doc_event)
        self.set_node(None)

    def detach(self) -> None:
        self.doc.unsubscribe(self._on_doc_event)

    # -- content ----------------------------------------------------------------
    def set_node(self, node_id: str | None) -> None:
        if node_id is not None and node_id not in self.doc.nodes:
            node_id = None
        self.node_id = node_id
        self._edits.reset()
        self._clear_form()
        self.error_label.hide()
        has = node_id is not None
        for w in (self.ident_box, self.params_box, self.status_box):
            w.setVisible(has)
        self._show_stiffness()
        if not has:
            self.title.setText("No node selected")
            self.description.setText("Select a node in the editor to edit its parameters.")
            return
        inst = self.doc.nodes[node_id]
        cls = all_node_types()[inst.type_name]
        r, g, b = FAMILY_COLOURS.get(cls.family, (150, 150, 150))
        self.title.setText(f"<span style='color: rgb({r},{g},{b})'>■</span> {cls.title or inst.type_name}"
                           f" <span style='color:#9aa0a6; font-weight:normal'>({cls.family})</span>")
        self.description.setText(" ".join((cls.__doc__ or "").split()))
        self.id_label.setText(node_id)
        self.label_edit.setText(inst.label)
        for param in cls.params:
            editor = EDITORS[param.kind](param, self)
            editor.set_value(inst.params.get(param.name, param.default))
            editor.edited.connect(lambda value, _name=param.name: self.commit(_name, value))
            label = param.label or param.name.replace("_", " ")
            self.form.addRow(label, editor.widget)
            self.editors[param.name] = editor
        self.params_box.setVisible(bool(cls.params))
        self._show_status()

    def _clear_form(self) -> None:
        while self.form.rowCount():
            self.form.removeRow(0)
        for e in self.editors.values():
            e.deleteLater()
        self.editors = {}

    def editor_widget(self, name: str) -> QtWidgets.QWidget:
        """The input widget of parameter `name` (tests drive it like a user would)."""
        editor = self.editors[name]
        return getattr(editor, "box", None) or getattr(editor, "table", None) or editor.widget

    # -- edits ------------------------------------------------------------------
    def commit(self, name: str, value: Any) -> bool:
        """Push SetParam for the shown node; show a refusal inline."""
        if self.node_id is None:
            return False
        try:
            self._edits.push(self.node_id, name, value)
        except GraphError as exc:
            self.error_label.setText(str(exc))
            self.error_label.show()
            self.message.emit("error", f"refused: {exc}")
            self._refresh_values()
            return False
        self.error_label.hide()
        return True

    def _commit_label(self) -> None:
        if self.node_id is None:
            return
        text = self.label_edit.text().strip()
        if text != self.doc.nodes[self.node_id].label:
            try:
                self.undo.push(SetLabel(self.node_id, text))
            except GraphError as exc:
                self.message.emit("error", f"refused: {exc}")

    def _refresh_values(self) -> None:
        if self.node_id is None or self.node_id not in self.doc.nodes:
            return
        params = self.doc.nodes[self.node_id].params
        for name, editor in self.editors.items():
            if name in params:
                editor.set_value(params[name])

    def _on_doc_event(self, event: str, payload) -> None:
        if self.node_id is None:
            return
        if event == "param_changed" and payload[0] == self.node_id:
            editor = self.editors.get(payload[1])
            if editor is not None:
                editor.set_value(self.doc.nodes[self.node_id].params[payload[1]])
        elif event == "label_changed" and payload == self.node_id:
            self.label_edit.setText(self.doc.nodes[self.node_id].label)
        elif (event == "node_removed" and payload == self.node_id) or event == "reset":
            self.set_node(None)

    # -- status -----------------------------------------------------------------
    def set_results(self, results: dict, outputs: dict | None = None) -> None:
        """Statuses (and, when given, output values) of the latest evaluation."""
        self._results = dict(results)
        self._outputs = dict(outputs or {})
        self._show_status()
        self._show_stiffness()

    def shown_stiffness(self) -> Stiffness | None:
        """The Stiffness the selected node produced in the latest evaluation, if any."""
        if self.node_id is None:
            return None
        for value in self._outputs.get(self.node_id, {}).values():
            if isinstance(value, Stiffness):
                return value
        return None

    def _show_stiffness(self) -> None:
        stiffness = self.shown_stiffness()
        if stiffness is not self.stiffness_panel.stiffness:
            self.stiffness_panel.set_stiffness(stiffness)
        self.stiffness_panel.setVisible(stiffness is not None)

    def _show_status(self) -> None:
        if self.node_id is None:
            return
        r = self._results.get(self.node_id)
        if r is None:
            self.status_label.setText("not evaluated yet")
            return
        colour = STATUS_COLOURS.get(r.status, "#cccccc")
        text = f"<b style='color:{colour}'>{r.status}</b>"
        if r.status == "evaluated":
            text += f" in {r.seconds:.3f} s"
        if r.error:
            where = f" (at {r.where})" if r.where else ""
            text += f"<br/><span style='color:#e04040'>{_escape(r.error)}{_escape(where)}</span>"
        self.status_label.setText(text)

    def status_text(self) -> str:
        return self.status_label.text()


def _escape(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
