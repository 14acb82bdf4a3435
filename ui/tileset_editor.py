"""The "Tile Sets" dock: browse tile sets, look at their blocks and adjacency,
edit blocks and rules, save a copy to the user folder, hand it to a TileSet node.

The edited document lives in an `engine.growth.tileset_edit.TileSetDraft`
(its own undo history, apart from the graph's); each gesture here is one
draft operation, and a refused one shows the engine's message inline and
changes nothing. "Use in selected TileSet node" is the only thing that
touches the graph: one command on the graph's undo stack. Blocks are drawn
with QPainter, 3D ones as an isometric view of their beams.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Callable

from PySide6 import QtCore, QtGui, QtWidgets

from engine.graph import GraphDocument, Macro, SetParam, UndoStack
from engine.growth.tileset_edit import (TileSetDraft, TileSetEditError, add_block, add_rule,
                                        describe_rule, move_rule, remove_block, remove_rule,
                                        rename_block, rules_referencing, save_path_for, set_name,
                                        set_weight, user_tileset_dir)

from .tileset_adjacency import AdjacencyView
from .tileset_browser import PATH_ROLE, TileSetBrowser
from .tileset_widgets import (ICON_PX, AddBlockDialog, _button, _error_label, _set_items,
                              _weight_box, block_pixmap)

ANY_FACE = "any face"


class TileSetEditor(QtWidgets.QWidget):
    """Tile-set browser, block pictures, adjacency matrix and rule editor.

    Parameters
    ----------
    doc, undo : the graph document and its undo stack ("Use in selected
        TileSet node" pushes one command there)
    user_folder : where saved sets go; default `user_tileset_dir()` at save time
    """

    message = QtCore.Signal(str, str)   # level, text, for the window's log

    def __init__(self, doc: GraphDocument, undo: UndoStack, parent=None, *,
                 user_folder: str | Path | None = None):
        super().__init__(parent)
        self.doc, self.undo = doc, undo
        self.user_folder = Path(user_folder) if user_folder is not None else None
        self.draft: TileSetDraft | None = None
        self.node_id: str | None = None
        self.add_dialog: AddBlockDialog | None = None
        # replaceable by tests: (title, text) -> bool and (title, label, default) -> str | None
        self.confirm: Callable[[str, str], bool] = self._confirm_dialog
        self.ask_text: Callable[[str, str, str], str | None] = self._text_dialog
        self._build()
        doc.subscribe(self._on_doc_event)
        self.refresh_browser()
        self._refresh()

    # -- construction -------------------------------------------------------------------------
    def _build(self) -> None:
        outer = QtWidgets.QVBoxLayout(self)
        outer.setContentsMargins(4, 4, 4, 4)
        split = QtWidgets.QSplitter(QtCore.Qt.Orientation.Vertical)
        outer.addWidget(split, 1)

        self.browser = TileSetBrowser()
        self.browser.currentItemChanged.connect(self._on_browse)
        split.addWidget(self.browser)

        body = QtWidgets.QWidget()
        lay = QtWidgets.QVBoxLayout(body)
        lay.setContentsMargins(0, 0, 0, 0)
        self.status_label = QtWidgets.QLabel("Choose a tile set above.")
        self.status_label.setWordWrap(True)
        lay.addWidget(self.status_label)
        self.tabs = QtWidgets.QTabWidget()
        self.tabs.addTab(self._build_blocks(), "Blocks")
        self.adjacency = AdjacencyView()
        self.face_box, self.matrix, self.pair_list = (self.adjacency.face_box, self.adjacency.matrix,
                                                      self.adjacency.pair_list)
        self.tabs.addTab(self.adjacency, "Adjacency")
        self.tabs.addTab(self._build_rules(), "Rules")
        lay.addWidget(self.tabs, 1)
        split.addWidget(body)
        split.setSizes([140, 420])

        self.error_label = _error_label()
        outer.addWidget(self.error_label)
        row = QtWidgets.QHBoxLayout()
        self.undo_button = _button("Undo", lambda: self._step(self.draft.undo), row)
        self.redo_button = _button("Redo", lambda: self._step(self.draft.redo), row)
        self.save_button = _button("Save as…", self.save_as, row)
        self.use_button = _button("Use in selected TileSet node", self.use_in_node, row)
        _button("Refresh list", self.refresh_browser, row).setToolTip("read the folders again")
        outer.addLayout(row)

    def _build_blocks(self) -> QtWidgets.QWidget:
        w = QtWidgets.QWidget()
        lay = QtWidgets.QVBoxLayout(w)
        self.block_list = QtWidgets.QListWidget()
        self.block_list.setViewMode(QtWidgets.QListView.ViewMode.IconMode)
        self.block_list.setIconSize(QtCore.QSize(ICON_PX, ICON_PX))
        self.block_list.setResizeMode(QtWidgets.QListView.ResizeMode.Adjust)
        self.block_list.setMovement(QtWidgets.QListView.Movement.Static)
        self.block_list.setGridSize(QtCore.QSize(ICON_PX + 40, ICON_PX + 44))
        self.block_list.setWordWrap(True)
        self.block_list.currentItemChanged.connect(lambda *_: self._show_block())
        lay.addWidget(self.block_list, 1)
        row = QtWidgets.QHBoxLayout()
        row.addWidget(QtWidgets.QLabel("Weight"))
        self.weight_box = _weight_box()
        self.weight_box.setKeyboardTracking(False)
        self.weight_box.valueChanged.connect(self._on_weight)
        row.addWidget(self.weight_box)
        self.rename_button = _button("Rename…", self.rename_selected_block, row)
        self.remove_button = _button("Remove", self.remove_selected_block, row)
        self.add_block_button = _button("Add block…", self.open_add_block_dialog, row)
        lay.addLayout(row)
        return w

    def _build_rules(self) -> QtWidgets.QWidget:
        w = QtWidgets.QWidget()
        lay = QtWidgets.QVBoxLayout(w)
        lay.addWidget(QtWidgets.QLabel("Applied in order after the connector labels; "
                                       "a later rule wins."))
        self.rule_list = QtWidgets.QListWidget()
        lay.addWidget(self.rule_list, 1)
        row = QtWidgets.QHBoxLayout()
        self.remove_rule_button = _button("Remove rule", self.remove_selected_rule, row)
        self.rule_up_button = _button("Up", lambda: self.move_selected_rule(-1), row)
        self.rule_down_button = _button("Down", lambda: self.move_selected_rule(+1), row)
        row.addStretch(1)
        lay.addLayout(row)
        new = QtWidgets.QHBoxLayout()
        self.kind_box = QtWidgets.QComboBox()
        self.kind_box.addItems(["forbid", "allow"])
        self.rule_a = QtWidgets.QComboBox()
        self.rule_b = QtWidgets.QComboBox()
        for box in (self.rule_a, self.rule_b):
            box.setEditable(True)
            box.setMinimumContentsLength(5)
        self.rule_face = QtWidgets.QComboBox()
        self.rule_note = QtWidgets.QLineEdit()
        self.rule_note.setPlaceholderText("why (optional)")
        for widget in (self.kind_box, self.rule_a, QtWidgets.QLabel("next to"), self.rule_b,
                       QtWidgets.QLabel("across"), self.rule_face):
            new.addWidget(widget)
        lay.addLayout(new)
        last = QtWidgets.QHBoxLayout()
        last.addWidget(self.rule_note, 1)
        self.add_rule_button = _button("Add rule", self.add_rule_from_form, last)
        lay.addLayout(last)
        return w

    # -- dialogs (replaceable) ------------------------------------------------------------------
    def detach(self) -> None:
        """Stop following the document (the window is closing)."""
        self.doc.unsubscribe(self._on_doc_event)

    def _confirm_dialog(self, title: str, text: str) -> bool:
        yes = QtWidgets.QMessageBox.StandardButton.Yes
        return QtWidgets.QMessageBox.question(self, title, text) == yes

    def _text_dialog(self, title: str, label: str, default: str) -> str | None:
        text, ok = QtWidgets.QInputDialog.getText(self, title, label, text=default)
        return text if ok else None

    # -- browsing -------------------------------------------------------------------------------
    def _folder(self) -> Path:
        return self.user_folder if self.user_folder is not None else user_tileset_dir()

    def refresh_browser(self) -> None:
        """Read the shipped and user folders again (keeps the open set selected)."""
        self.browser.refresh(self._folder(), self.draft.source if self.draft is not None else None)

    def browser_item(self, name: str) -> QtWidgets.QTreeWidgetItem | None:
        """The browser row of the set called ``name`` (shipped first)."""
        return self.browser.item_named(name)

    def _on_browse(self, item, previous) -> None:
        path = item.data(0, PATH_ROLE) if item is not None else None
        if not path or (self.draft is not None and self.draft.source == Path(path)):
            return
        if not self.open_path(path):
            self.browser.blockSignals(True)
            self.browser.setCurrentItem(previous)
            self.browser.blockSignals(False)

    def open_path(self, path) -> bool:
        """Open a tile-set file; asks first when the current one has unsaved edits."""
        if self.draft is not None and self.draft.dirty and not self.confirm(
                "Unsaved tile set", f"Discard the unsaved edits of {self.draft.name!r}?"):
            return False
        try:
            draft = TileSetDraft.open(path)
        except TileSetEditError as exc:
            self._error(str(exc))
            return False
        self.draft = draft
        draft.subscribe(self._refresh)
        self._error("")
        self._refresh()
        return True

    # -- editing --------------------------------------------------------------------------------
    @property
    def _ts(self):
        """The parsed draft, None when nothing valid is open."""
        return self.draft.tileset if self.draft is not None else None

    def _error(self, text: str) -> None:
        self.error_label.setText(text)
        if text:
            self.message.emit("error", text)

    def apply(self, text: str, op, *args, **kwargs) -> str:
        """One draft edit; returns "" or the engine's refusal (also shown inline)."""
        if self.draft is None:
            return "no tile set is open"
        try:
            self.draft.apply(text, op, *args, **kwargs)
        except TileSetEditError as exc:
            self._error(str(exc))
            return str(exc)
        self._error("")
        return ""

    def _step(self, fn) -> None:
        if self.draft is not None:
            fn()
            self._error("")

    def selected_block(self) -> str | None:
        item = self.block_list.currentItem()
        return item.data(PATH_ROLE) if item is not None else None

    def _on_weight(self, value: float) -> None:
        name = self.selected_block()
        ts = self._ts
        if name is None or ts is None:
            return
        current = float(ts.weights[ts.tiles_of(name)].sum())
        if not math.isclose(current, value, rel_tol=1e-9, abs_tol=1e-12):
            self.apply(f"weight of {name}", set_weight, name, float(value))

    def rename_selected_block(self) -> None:
        name = self.selected_block()
        if name is None:
            return
        new = self.ask_text("Rename block", f"New name for block {name!r}:", name)
        if new is not None and new.strip() != name:
            self.apply(f"rename {name} to {new.strip()}", rename_block, name, new.strip())

    def remove_selected_block(self) -> None:
        name = self.selected_block()
        if name is None or self.draft is None:
            return
        refs = rules_referencing(self.draft.data, name)
        if refs:
            listed = "\n".join(describe_rule(self.draft.data["rules"][k]) for k in refs)
            if not self.confirm("Remove block", f"Block {name!r} is named by these rules, which "
                                f"would be removed with it:\n{listed}"):
                return
        self.apply(f"remove {name}", remove_block, name, drop_rules=bool(refs))

    def open_add_block_dialog(self) -> AddBlockDialog | None:
        ts = self._ts
        if ts is None:
            self._error("open a valid tile set before adding blocks")
            return None

        def submit(spec: dict) -> str:
            return self.apply(f"add block {spec['name']}", add_block, spec.pop("name"), **spec)

        self.add_dialog = AddBlockDialog(ts.ndim, ts.faces, submit, self)
        self.add_dialog.open()
        return self.add_dialog

    def add_rule_from_form(self) -> str:
        face = self.rule_face.currentText()
        a, b = self.rule_a.currentText().strip(), self.rule_b.currentText().strip()
        kind = self.kind_box.currentText()
        return self.apply(f"{kind} {a} next to {b}", add_rule, kind, a, b,
                          face=None if face == ANY_FACE else face,
                          description=self.rule_note.text().strip())

    def remove_selected_rule(self) -> None:
        row = self.rule_list.currentRow()
        if row >= 0:
            self.apply(f"remove rule {row + 1}", remove_rule, row)

    def move_selected_rule(self, step: int) -> None:
        row = self.rule_list.currentRow()
        if row >= 0 and 0 <= row + step < self.rule_list.count():
            if not self.apply(f"move rule {row + 1}", move_rule, row, row + step):
                self.rule_list.setCurrentRow(row + step)

    def save_as(self) -> Path | None:
        """Ask a name, save to the user folder; a shipped set is saved as a copy."""
        if self.draft is None:
            return None
        default = f"{self.draft.name} copy" if self.draft.shipped else self.draft.name
        name = self.ask_text("Save tile set", f"Name (saved in {self._folder()}):", default)
        if name is None:
            return None
        name = name.strip()
        if name != self.draft.name and self.apply(f"name the set {name}", set_name, name):
            return None
        target = save_path_for(name, self._folder())
        if target.exists() and target != self.draft.source and not self.confirm(
                "Replace tile set", f"{target} already holds a set called {name!r}. Replace it?"):
            return None
        try:
            path = self.draft.save(target, overwrite=True)
        except (TileSetEditError, OSError) as exc:
            self._error(str(exc))
            return None
        self._error("")
        self.message.emit("info", f"tile set {name!r} saved to {path}")
        self.refresh_browser()
        return path

    @property
    def unsaved(self) -> bool:
        """True when the open tile set has edits not saved to a file (ask before closing)."""
        return self.draft is not None and self.draft.dirty

    # -- the graph ------------------------------------------------------------------------------
    def set_selected(self, node_id: str | None) -> None:
        self.node_id = node_id
        self._update_use_button()

    def _on_doc_event(self, event: str, payload=None) -> None:
        self._update_use_button()

    def _use_state(self) -> tuple[bool, str]:
        if self.node_id is None or self.node_id not in self.doc.nodes:
            return False, "select a TileSet node in the graph"
        if self.doc.node(self.node_id).type_name != "TileSet":
            return False, f"{self.node_id} is not a TileSet node"
        if self.draft is None or self.draft.source is None or self.draft.tileset is None:
            return False, "open a valid tile set"
        if self.draft.dirty:
            return False, "save the edited set first (Save as…)"
        return True, f"set {self.node_id} to {self.draft.source}"

    def _update_use_button(self) -> None:
        ok, why = self._use_state()
        self.use_button.setEnabled(ok)
        self.use_button.setToolTip(why)

    def use_in_node(self) -> None:
        """One undoable graph command: the selected TileSet node reads this set.

        A user file goes to the node's ``path``; an unedited shipped set is
        chosen by ``name`` (with ``path`` cleared), which keeps projects portable.
        """
        ok, why = self._use_state()
        if not ok:
            self._error(why)
            return
        nid, source = self.node_id, self.draft.source
        if self.draft.shipped:
            command = Macro(f"use tile set {self.draft.name}",
                            [SetParam(nid, "name", self.draft.name), SetParam(nid, "path", "")])
        else:
            command = SetParam(nid, "path", str(source))
        try:
            self.undo.push(command)
        except ValueError as exc:   # the document refused; nothing changed
            self._error(f"{nid}: {exc}")
            return
        self._error("")
        self.message.emit("info", f"{nid} now uses tile set {self.draft.name!r}")

    # -- drawing --------------------------------------------------------------------------------
    def _refresh(self) -> None:
        draft = self.draft
        ts = draft.tileset if draft is not None else None
        if draft is None:
            self.status_label.setText("Choose a tile set above.")
        else:
            where = "shipped, read-only: Save as… makes a copy" if draft.shipped else str(draft.source)
            shape = f"{ts.ndim}D, {ts.n_blocks} blocks, {ts.n_tiles} tiles" if ts else "invalid"
            mark = " — modified" if draft.dirty else ""
            self.status_label.setText(f"<b>{draft.name}</b> ({shape}; {where}){mark}")
            if draft.error:
                self.error_label.setText(draft.error)
        self.undo_button.setEnabled(bool(draft and draft.can_undo))
        self.redo_button.setEnabled(bool(draft and draft.can_redo))
        self.undo_button.setToolTip(f"undo {draft.undo_text()}" if draft and draft.can_undo else "")
        self.redo_button.setToolTip(f"redo {draft.redo_text()}" if draft and draft.can_redo else "")
        for w in (self.save_button, self.add_block_button, self.add_rule_button):
            w.setEnabled(ts is not None)
        self._show_blocks(ts)
        self._show_rules(ts)
        self.adjacency.set_tileset(ts)
        self._update_use_button()

    def _show_blocks(self, ts) -> None:
        selected = self.selected_block()
        self.block_list.blockSignals(True)
        self.block_list.clear()
        for name in (ts.block_names if ts is not None else ()):
            tiles = ts.tiles_of(name)
            tile = ts.tiles[int(tiles[0])]
            weight = float(ts.weights[tiles].sum())
            item = QtWidgets.QListWidgetItem(QtGui.QIcon(block_pixmap(tile, ts.faces, ts.ndim)),
                                             f"{name}\n{len(tiles)} orient. · w {weight:g}")
            item.setData(PATH_ROLE, name)
            item.setToolTip("connectors of " + tile.name + ": " + ", ".join(
                f"{f} {lab}" for f, lab in zip(ts.faces, tile.connectors)))
            self.block_list.addItem(item)
            if name == selected:
                self.block_list.setCurrentItem(item)
        if self.block_list.currentItem() is None and self.block_list.count():
            self.block_list.setCurrentRow(0)
        self.block_list.blockSignals(False)
        self._show_block()

    def _show_block(self) -> None:
        ts = self._ts
        name = self.selected_block()
        name = name if ts is not None and name in ts.block_names else None
        for w in (self.weight_box, self.rename_button, self.remove_button):
            w.setEnabled(name is not None and ts is not None)
        if name is not None and ts is not None:
            self.weight_box.blockSignals(True)
            self.weight_box.setValue(float(ts.weights[ts.tiles_of(name)].sum()))
            self.weight_box.blockSignals(False)

    def _show_rules(self, ts) -> None:
        row = self.rule_list.currentRow()
        self.rule_list.clear()
        rules = ts.rules if ts is not None else ()
        for k, rule in enumerate(rules):
            note = rule.get("description")
            self.rule_list.addItem(f"{k + 1}. {describe_rule(rule)}" + (f" — {note}" if note else ""))
        if 0 <= row < self.rule_list.count():
            self.rule_list.setCurrentRow(row)
        names = (list(ts.block_names) + list(ts.tile_names)) if ts is not None else []
        for box in (self.rule_a, self.rule_b):
            _set_items(box, names)
        faces = list(ts.faces) if ts is not None else []
        _set_items(self.rule_face, [ANY_FACE] + faces)
