"""The parameter rows of one node in a form: an editor per parameter, its refusal under it.

One class shared by every place that edits a node's parameters (the
inspector, the Surfaces dock): each edit is one ``SetParam`` on the undo
stack (quick repeats of one parameter merge, `MergingParamPush`); a value
the schema refuses changes nothing and is shown at its field with the
allowed range (`FieldMessage`, `refusal_text`); the editors follow the
document's ``param_changed`` events, so undo / redo shows up here too.
"""

from __future__ import annotations

from typing import Any, Sequence

from PySide6 import QtCore, QtWidgets

from engine.graph import GraphError, Param

from .field_message import FieldMessage, refusal_text
from .param_editors import (BoolEditor, EnumEditor, FloatEditor, IntEditor, IntListEditor, StrEditor,
                            Vec3Editor)
from .param_push import MergingParamPush
from .structured_editors import JsonEditor, SamplesEditor

EDITORS = {
    "float": FloatEditor, "int": IntEditor, "bool": BoolEditor, "enum": EnumEditor, "str": StrEditor,
    "vec3": Vec3Editor, "int_list": IntListEditor, "samples": SamplesEditor, "json": JsonEditor,
}
"""The editor class of each parameter kind (``Param.kind``)."""


class ParamForm(QtCore.QObject):
    """Rows ``label | editor`` plus a refusal message row per parameter, in `form`.

    Signals: ``message(level, text)`` for the log (a refusal).
    """

    message = QtCore.Signal(str, str)

    def __init__(self, doc, undo, form: QtWidgets.QFormLayout, parent=None):
        super().__init__(parent)
        self.doc, self.form = doc, form
        self.node_id: str | None = None
        self.editors: dict = {}
        self.messages: dict[str, FieldMessage] = {}
        self._refused: FieldMessage | None = None       # the latest refusal shown
        self._no_refusal = FieldMessage([])
        self._edits = MergingParamPush(undo)
        self._shown: tuple = ()                          # the params the rows are for

    # -- rows -----------------------------------------------------------------------------------
    def show_node(self, node_id: str | None, params: Sequence[Param] = ()) -> None:
        """Rows for `params` of `node_id` (none when None), showing the document's values.
        The rows of the same parameters (another node of the same type) are kept and only
        their values change: selecting along a row of like nodes rebuilds no widgets."""
        params = tuple(params)
        if node_id is not None and self.editors and params == self._shown:
            self._edits.reset()
            self.node_id = node_id
            stored = self.doc.nodes[node_id].params
            for name, editor in self.editors.items():
                editor.set_value(stored.get(name, editor.param.default))
            for message in self.messages.values():
                message.clear()
                self.form.setRowVisible(message, False)
            self._refused = None
            return
        self.clear()
        self.node_id = node_id
        if node_id is None:
            return
        self._shown = params
        stored = self.doc.nodes[node_id].params
        parent = self.form.parentWidget()
        for param in params:
            editor = EDITORS[param.kind](param, parent)
            editor.set_value(stored.get(param.name, param.default))
            editor.edited.connect(lambda value, _name=param.name: self.commit(_name, value))
            label = QtWidgets.QLabel(param.label or param.name.replace("_", " "))
            label.setToolTip(editor.tooltip)
            self.form.addRow(label, editor.widget)
            message = FieldMessage(editor.inputs())
            self.form.addRow(message)
            self.editors[param.name] = editor
            self.messages[param.name] = message

    def clear(self) -> None:
        while self.form.rowCount():
            self.form.removeRow(0)
        for editor in self.editors.values():
            editor.deleteLater()
        self.editors, self.messages, self._refused = {}, {}, None
        self._shown: tuple = ()
        self._edits.reset()

    def set_row_visible(self, name: str, shown: bool) -> None:
        """Show or hide parameter `name`'s row (its refusal row goes with it)."""
        editor = self.editors[name]
        self.form.setRowVisible(editor.widget, shown)
        message = self.messages[name]
        self.form.setRowVisible(message, shown and message.refused)

    def is_row_visible(self, name: str) -> bool:
        return self.form.isRowVisible(self.editors[name].widget)

    def editor_widget(self, name: str) -> QtWidgets.QWidget:
        """The input widget of parameter `name` (tests drive it like a user would)."""
        editor = self.editors[name]
        return getattr(editor, "box", None) or getattr(editor, "table", None) or editor.widget

    @property
    def error_label(self) -> QtWidgets.QLabel:
        """The message of the latest refusal, under its field (a hidden label when none)."""
        return self._refused if self._refused is not None else self._no_refusal

    # -- edits ----------------------------------------------------------------------------------
    def commit(self, name: str, value: Any) -> bool:
        """Push SetParam for the shown node (nothing when `value` is the stored one);
        a refused value is shown at its field and changes nothing."""
        if self.node_id is None or self.node_id not in self.doc.nodes:
            return False
        params = self.doc.nodes[self.node_id].params
        message = self.messages.get(name)
        if name in params and same_value(value, params[name]):
            self.refresh()                               # e.g. "32" retyped: no undo item
            if message is not None:
                message.clear()
            return True
        try:
            self._edits.push(self.node_id, name, value)
        except GraphError as exc:
            self.refresh()
            self.refuse(name, exc)
            return False
        if message is not None:
            message.clear()
        return True

    def refuse(self, name: str, exc: GraphError) -> None:
        """Show why `name`'s new value was refused, at its field and in the log."""
        param = self.editors[name].param if name in self.editors else None
        params = self.doc.nodes[self.node_id].params if self.node_id in self.doc.nodes else {}
        text = refusal_text(param, exc, params.get(name)) if param is not None else str(exc)
        message = self.messages.get(name)
        if message is not None:
            message.refuse(text)
            self.form.setRowVisible(message, True)
            self._refused = message
        self.message.emit("error", f"refused: {exc}")

    def refresh(self) -> None:
        """Every editor shows the document's value again."""
        if self.node_id is None or self.node_id not in self.doc.nodes:
            return
        params = self.doc.nodes[self.node_id].params
        for name, editor in self.editors.items():
            if name in params:
                editor.set_value(params[name])

    def on_param_changed(self, node_id: str, name: str) -> None:
        """A document ``param_changed`` event: show the new value; a refusal shown is stale."""
        if node_id != self.node_id or node_id not in self.doc.nodes:
            return
        editor = self.editors.get(name)
        if editor is not None:
            editor.set_value(self.doc.nodes[node_id].params[name])
            self.messages[name].clear()


def same_value(value: Any, stored: Any) -> bool:
    """Whether an edit would store what is stored already (same type and value)."""
    if isinstance(value, (list, tuple)) and isinstance(stored, (list, tuple)):
        return len(value) == len(stored) and all(same_value(a, b) for a, b in zip(value, stored))
    return type(value) is type(stored) and value == stored
