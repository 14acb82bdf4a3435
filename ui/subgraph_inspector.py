"""The panel of the current frame or subgraph (`NodeFrames.current`).

A frame: its title and comment.  A subgraph: its name, its exposed
parameters -- each with the inspector's editor for its kind, so ranges,
units, tooltips and refusals at the field are the inspector's -- and which
member parameters can be exposed.  Every edit is an engine command
(`EditFrame`, `RenameSubgraph`, `SetSubgraphParam`, `ExposeParam`,
`UnexposeParam`, `Ungroup`); the panel is redrawn from document events, so
undo and redo show here too.
"""

from __future__ import annotations

import time
from typing import Any

from PySide6 import QtCore, QtWidgets

from engine.graph import (EditFrame, ExposeParam, GraphDocument, GraphError, RenameSubgraph, SetSubgraphParam,
                          UndoStack, UnexposeParam, Ungroup, node_type)

from .field_message import FieldMessage, refusal_text
from .param_form import EDITORS
from .node_frames import NodeFrames
from .param_editors import ParamEditor

MERGE_SECONDS = 1.0


class SubgraphPanel(QtWidgets.QWidget):
    """Name / title and exposed parameters of the frame or subgraph `frames` makes current."""

    message = QtCore.Signal(str, str)

    def __init__(self, doc: GraphDocument, undo: UndoStack, frames: NodeFrames, parent=None):
        super().__init__(parent)
        self.doc, self.undo, self.frames = doc, undo, frames
        self.current: tuple[str, str] | None = None
        self.editors: dict[tuple[str, str], ParamEditor] = {}
        self.messages: dict[tuple[str, str], FieldMessage] = {}
        self._last_edit: tuple[tuple[str, str], float] | None = None

        outer = QtWidgets.QVBoxLayout(self)
        outer.setContentsMargins(6, 6, 6, 6)
        self.title = QtWidgets.QLabel()
        self.title.setWordWrap(True)
        outer.addWidget(self.title)

        self.frame_box = QtWidgets.QGroupBox("Frame")
        form = QtWidgets.QFormLayout(self.frame_box)
        self.frame_title = QtWidgets.QLineEdit()
        self.frame_title.editingFinished.connect(lambda: self._edit_frame(title=self.frame_title.text()))
        self.frame_comment = QtWidgets.QPlainTextEdit()
        self.frame_comment.setPlaceholderText("comment (kept when the field loses focus)")
        self.frame_comment.setMaximumHeight(90)
        self.frame_comment.installEventFilter(self)
        remove = QtWidgets.QPushButton("Remove frame")
        remove.clicked.connect(self.frames.remove_current_frame)
        form.addRow("title", self.frame_title)
        form.addRow("comment", self.frame_comment)
        form.addRow(remove)
        outer.addWidget(self.frame_box)

        self.sub_box = QtWidgets.QGroupBox("Subgraph")
        sub = QtWidgets.QVBoxLayout(self.sub_box)
        name_row = QtWidgets.QFormLayout()
        self.name_edit = QtWidgets.QLineEdit()
        self.name_edit.editingFinished.connect(self._rename)
        self.name_message = FieldMessage([self.name_edit])
        name_row.addRow("name", self.name_edit)
        name_row.addRow(self.name_message)
        sub.addLayout(name_row)
        self.collapsed_box = QtWidgets.QCheckBox("collapsed into one node")
        self.collapsed_box.setToolTip("draw the subgraph as one node with its boundary ports (saved in the project)")
        self.collapsed_box.toggled.connect(self._set_collapsed)
        sub.addWidget(self.collapsed_box)
        self.params_box = QtWidgets.QGroupBox("Exposed parameters")
        self.form = QtWidgets.QFormLayout(self.params_box)
        sub.addWidget(self.params_box)
        expose_row = QtWidgets.QHBoxLayout()
        self.expose_choice = QtWidgets.QComboBox()
        self.expose_choice.setToolTip("a member node's parameter to show on the subgraph")
        self.expose_button = QtWidgets.QPushButton("Expose")
        self.expose_button.clicked.connect(self._expose_chosen)
        expose_row.addWidget(self.expose_choice, 1)
        expose_row.addWidget(self.expose_button)
        sub.addLayout(expose_row)
        ungroup = QtWidgets.QPushButton("Ungroup")
        ungroup.clicked.connect(self.frames.ungroup)
        sub.addWidget(ungroup)
        outer.addWidget(self.sub_box)
        outer.addStretch(1)

        frames.current_changed.connect(self.show_item)
        doc.subscribe(self._on_doc_event)
        self.show_item(frames.current)

    def detach(self) -> None:
        self.doc.unsubscribe(self._on_doc_event)

    # -- content ------------------------------------------------------------------
    def show_item(self, current) -> None:
        """Show a frame or subgraph: ("frame" | "subgraph", id), or None."""
        ann = self.doc.annotations
        if current is not None and current[1] not in (ann.frames if current[0] == "frame" else ann.subgraphs):
            current = None
        self.current = current
        self._clear_form()
        self.frame_box.setVisible(current is not None and current[0] == "frame")
        self.sub_box.setVisible(current is not None and current[0] == "subgraph")
        if current is None:
            self.title.setText("No frame or subgraph selected. Select nodes and press Ctrl+G to group them.")
            return
        if current[0] == "frame":
            frame = ann.frames[current[1]]
            self.title.setText(f"<b>Frame</b> {current[1]}")
            self.frame_title.setText(frame.title)
            if self.frame_comment.toPlainText() != frame.comment:
                self.frame_comment.setPlainText(frame.comment)
            return
        sub = ann.subgraphs[current[1]]
        self.title.setText(f"<b>Subgraph</b> {sub.id}: {len(sub.members)} nodes ({', '.join(sub.members)})")
        self.name_edit.setText(sub.name)
        self.collapsed_box.blockSignals(True)
        self.collapsed_box.setChecked(sub.collapsed)
        self.collapsed_box.blockSignals(False)
        for e in sub.exposed:
            self._add_row(e.node_id, e.param, e.label)
        self.params_box.setVisible(bool(sub.exposed))
        self.expose_choice.clear()
        shown = {(e.node_id, e.param) for e in sub.exposed}
        for nid in sub.members:
            for p in node_type(self.doc.nodes[nid].type_name).params:
                if (nid, p.name) not in shown:
                    self.expose_choice.addItem(f"{nid}.{p.name}", f"{nid}.{p.name}")  # ids hold no "."
        self.expose_button.setEnabled(self.expose_choice.count() > 0)

    def _add_row(self, node_id: str, name: str, label: str) -> None:
        param = next(p for p in node_type(self.doc.nodes[node_id].type_name).params if p.name == name)
        editor = EDITORS[param.kind](param, self)
        editor.set_value(self.doc.nodes[node_id].params.get(name, param.default))
        editor.edited.connect(lambda value, _k=(node_id, name): self.commit(_k[0], _k[1], value))
        row = QtWidgets.QWidget()
        lay = QtWidgets.QHBoxLayout(row)
        lay.setContentsMargins(0, 0, 0, 0)
        lay.addWidget(editor.widget, 1)
        drop = QtWidgets.QToolButton()
        drop.setText("×")
        drop.setToolTip(f"stop exposing {node_id}.{name}")
        drop.clicked.connect(lambda _c=False: self.unexpose(node_id, name))
        lay.addWidget(drop)
        text = QtWidgets.QLabel(label or f"{node_id}.{param.label or name}")
        text.setToolTip(f"{node_id}.{name}\n{editor.tooltip}")
        self.form.addRow(text, row)
        message = FieldMessage(editor.inputs())
        self.form.addRow(message)
        self.editors[(node_id, name)] = editor
        self.messages[(node_id, name)] = message

    def _clear_form(self) -> None:
        while self.form.rowCount():
            self.form.removeRow(0)
        for e in self.editors.values():
            e.deleteLater()
        self.editors, self.messages = {}, {}
        self.name_message.clear()

    def editor_widget(self, node_id: str, name: str) -> QtWidgets.QWidget:
        """The input widget of an exposed parameter (tests drive it like a user would)."""
        editor = self.editors[(node_id, name)]
        return getattr(editor, "box", None) or getattr(editor, "table", None) or editor.widget

    # -- edits ----------------------------------------------------------------------
    def _push(self, command, merge: bool = False) -> bool:
        try:
            self.undo.push(command, merge=merge)
        except GraphError as exc:
            self.message.emit("error", f"refused: {exc}")
            return False
        return True

    def commit(self, node_id: str, name: str, value: Any) -> bool:
        """Set an exposed parameter (a SetParam of the inner node); a refused value is
        shown at its field and changes nothing.  Quick repeats merge into one undo item."""
        if self.current is None or self.current[0] != "subgraph":
            return False
        key, now = (node_id, name), time.monotonic()
        message = self.messages.get(key)
        stored = self.doc.nodes[node_id].params.get(name)
        if type(value) is type(stored) and value == stored:
            return True
        merge = (self._last_edit is not None and self._last_edit[0] == key and now - self._last_edit[1] < MERGE_SECONDS
                 and self.undo.undo_text() == f"set {node_id}.{name}")
        try:
            self.undo.push(SetSubgraphParam(self.current[1], node_id, name, value), merge=merge)
        except GraphError as exc:
            self._last_edit = None
            editor = self.editors.get(key)
            if editor is not None:
                editor.set_value(stored)
                if message is not None:
                    message.refuse(refusal_text(editor.param, exc, stored))
            self.message.emit("error", f"refused: {exc}")
            return False
        self._last_edit = (key, now)
        if message is not None:
            message.clear()
        return True

    def expose(self, node_id: str, name: str, label: str = "") -> bool:
        if self.current is None or self.current[0] != "subgraph":
            return False
        return self._push(ExposeParam(self.current[1], node_id, name, label))

    def unexpose(self, node_id: str, name: str) -> bool:
        if self.current is None or self.current[0] != "subgraph":
            return False
        return self._push(UnexposeParam(self.current[1], node_id, name))

    def _expose_chosen(self) -> None:
        data = self.expose_choice.currentData()
        if data:
            self.expose(*data.split(".", 1))

    def _set_collapsed(self, on: bool) -> None:
        if self.current is not None and self.current[0] == "subgraph":
            self.frames.set_collapsed(self.current[1], bool(on))

    def _rename(self) -> None:
        if self.current is None or self.current[0] != "subgraph":
            return
        text = self.name_edit.text().strip()
        sub = self.doc.annotations.subgraphs[self.current[1]]
        if text == sub.name:
            return
        try:
            self.undo.push(RenameSubgraph(sub.id, text))
        except GraphError as exc:
            self.name_message.refuse(f"name {text!r} refused: {exc}")
            self.name_edit.setText(sub.name)
            self.message.emit("error", f"refused: {exc}")
            return
        self.name_message.clear()

    def _edit_frame(self, **changes) -> None:
        if self.current is None or self.current[0] != "frame":
            return
        frame = self.doc.annotations.frames[self.current[1]]
        if any(getattr(frame, k) != v for k, v in changes.items()):
            self._push(EditFrame(frame.id, **changes))

    def eventFilter(self, watched, event) -> bool:
        if watched is self.frame_comment and event.type() == QtCore.QEvent.Type.FocusOut:
            self._edit_frame(comment=self.frame_comment.toPlainText())
        return super().eventFilter(watched, event)

    def _on_doc_event(self, event: str, payload) -> None:
        if self.current is None:
            return
        if event == "param_changed":
            editor = self.editors.get(tuple(payload))
            if editor is not None:
                editor.set_value(self.doc.nodes[payload[0]].params[payload[1]])
                self.messages[tuple(payload)].clear()
        elif event == "annotation_changed" and tuple(payload) == self.current:
            self.show_item(self.current)
        elif event == "reset":
            self.show_item(None)
