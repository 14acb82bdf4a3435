"""The inspector: edits the selected node's parameters from its schema.

Every edit becomes a `SetParam` pushed on the undo stack (successive edits of
one parameter within a second merge into one undo item, as when holding a
spin box arrow; `ui.param_push`).  A typed value is never clamped: one the
schema refuses (out of range, not a number) is refused at its field -- a red
frame and a message under it naming the parameter, the value typed and what
is allowed -- and the editor goes back to the document's value; the document
and the undo stack are unchanged.
Widgets are refreshed from document events, so undo/redo shows up here too.
When the node's latest evaluation produced a `Stiffness`, a `StiffnessPanel`
shows it under the parameters.  One editor class per parameter kind lives in
`ui.param_editors` / `ui.structured_editors`.
"""

from __future__ import annotations

from typing import Any

from PySide6 import QtCore, QtWidgets

from engine.graph import GraphDocument, GraphError, SetLabel, UndoStack, all_node_types
from engine.physics.values import Stiffness

from .colours import STATUS_COLOURS, family_colour
from .field_message import FieldMessage
from .param_form import EDITORS, ParamForm
from .rich_text import doc_to_html
from .stiffness_panel import StiffnessPanel

__all__ = ["Inspector", "EDITORS"]


class Inspector(QtWidgets.QWidget):
    """Parameters, label and evaluation status of one node."""

    message = QtCore.Signal(str, str)

    def __init__(self, doc: GraphDocument, undo: UndoStack, parent=None):
        super().__init__(parent)
        self.doc = doc
        self.undo = undo
        self.node_id: str | None = None
        self._results: dict = {}
        self._outputs: dict = {}

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
        self.description.setTextFormat(QtCore.Qt.TextFormat.RichText)
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
        self.label_message = FieldMessage([self.label_edit])
        ident.addRow(self.label_message)
        self.ident_box = QtWidgets.QWidget()
        self.ident_box.setLayout(ident)
        outer.addWidget(self.ident_box)

        self.params_box = QtWidgets.QGroupBox("Parameters")
        self.form = QtWidgets.QFormLayout(self.params_box)
        self.param_form = ParamForm(doc, undo, self.form, self)
        self.param_form.message.connect(self.message.emit)
        self.form.setFieldGrowthPolicy(QtWidgets.QFormLayout.FieldGrowthPolicy.AllNonFixedFieldsGrow)
        outer.addWidget(self.params_box)

        self.stiffness_panel = StiffnessPanel()
        self.stiffness_panel.hide()
        outer.addWidget(self.stiffness_panel)

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
        if node_id is None:
            self.param_form.show_node(None)
        self.label_message.clear()
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
        r, g, b = family_colour(cls.family, (150, 150, 150))
        self.title.setText(f"<span style='color: rgb({r},{g},{b})'>■</span> {cls.title or inst.type_name}"
                           f" <span style='color:#9aa0a6; font-weight:normal'>({cls.family})</span>")
        self.description.setText(doc_to_html(cls.__doc__))      # ``code``, *emph*, lists as rich text
        self.id_label.setText(node_id)
        self.label_edit.setText(inst.label)
        self.param_form.show_node(node_id, cls.params)
        self.params_box.setVisible(bool(cls.params))
        self._show_status()

    # -- the parameters' form (ui.param_form) ---------------------------------------
    @property
    def editors(self) -> dict:
        return self.param_form.editors

    @property
    def messages(self) -> dict[str, FieldMessage]:
        """The refusal message under each field."""
        return self.param_form.messages

    def editor_widget(self, name: str) -> QtWidgets.QWidget:
        """The input widget of parameter `name` (tests drive it like a user would)."""
        return self.param_form.editor_widget(name)

    @property
    def error_label(self) -> QtWidgets.QLabel:
        """The message of the latest refusal, under its field (a hidden label when none)."""
        return self.param_form.error_label

    def commit(self, name: str, value: Any) -> bool:
        """Push SetParam for the shown node (nothing when `value` is the stored one);
        a refused value is shown at its field and changes nothing."""
        return self.param_form.commit(name, value)

    def refuse(self, name: str, exc: GraphError) -> None:
        """Show why `name`'s new value was refused, at its field and in the log."""
        self.param_form.refuse(name, exc)

    def _commit_label(self) -> None:
        if self.node_id is None:
            return
        text = self.label_edit.text().strip()
        if text != self.doc.nodes[self.node_id].label:
            try:
                self.undo.push(SetLabel(self.node_id, text))
            except GraphError as exc:
                self.label_message.refuse(f"label {text!r} refused: {exc}")
                self.label_edit.setText(self.doc.nodes[self.node_id].label)
                self.message.emit("error", f"refused: {exc}")
                return
        self.label_message.clear()

    def _on_doc_event(self, event: str, payload) -> None:
        if self.node_id is None:
            return
        if event == "param_changed":
            self.param_form.on_param_changed(*payload)  # an undo / redo also makes a refusal stale
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
