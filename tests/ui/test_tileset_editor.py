"""The Tile Sets widget: browse, edit blocks and rules, save a copy, use it in a node."""

from __future__ import annotations

import pytest
from PySide6 import QtCore

from engine.graph import AddNode, GraphDocument, UndoStack
from engine.growth import TILESET_DIR, load_tileset
from keyboard_entry import type_into
from ui.tileset_editor import TileSetEditor

LEFT = QtCore.Qt.MouseButton.LeftButton


@pytest.fixture
def user_dir(tmp_path, monkeypatch):
    folder = tmp_path / "user_sets"
    monkeypatch.setenv("MESOFORGE_TILESET_DIR", str(folder))
    return folder


@pytest.fixture
def editor(qtbot, user_dir):
    doc = GraphDocument()
    undo = UndoStack(doc)
    w = TileSetEditor(doc, undo)
    w.asked = []
    w.confirm_answer = True
    w.confirm = lambda title, text: (w.asked.append(text), w.confirm_answer)[1]
    w.ask_text = lambda title, label, default: w.text_answer
    qtbot.addWidget(w)
    w.resize(760, 820)
    w.show()
    qtbot.waitExposed(w)
    return w


def _browse(w, name):
    item = w.browser_item(name)
    assert item is not None, name
    w.browser.setCurrentItem(item)
    assert w.draft is not None and w.draft.name == name


def _cell(w, a, b):
    names = list(w.draft.tileset.block_names)
    return w.matrix.item(names.index(a), names.index(b)).text()


def _shipped_bytes():
    return {p.name: p.read_bytes() for p in sorted(TILESET_DIR.iterdir())}


def test_browse_add_rule_save_and_use_in_node(qtbot, editor, user_dir):
    w = editor
    shipped = _shipped_bytes()
    _browse(w, "TL+-")
    assert w.block_list.count() == 4 and w.rule_list.count() == 1
    w.face_box.setCurrentText("+x")
    assert _cell(w, "L", "L") == "0/16" and _cell(w, "T", "+") == "3/4"

    w.kind_box.setCurrentText("forbid")
    w.rule_a.setEditText("T")
    w.rule_b.setEditText("+")
    w.rule_face.setCurrentText("+x")
    qtbot.mouseClick(w.add_rule_button, LEFT)
    assert w.error_label.text() == ""
    assert w.rule_list.count() == 2 and "forbid + across +x of T" in w.rule_list.item(1).text()
    assert _cell(w, "T", "+") == "0/4" and _cell(w, "+", "T") != "0/4"

    nid = w.undo.push(AddNode("TileSet")).node_id
    w.set_selected(nid)
    assert not w.use_button.isEnabled()          # unsaved edits: save first

    w.text_answer = "TL+- no T+"
    qtbot.mouseClick(w.save_button, LEFT)
    saved = user_dir / "TL_-_no_T.json"
    assert saved.is_file() and w.draft.source == saved and not w.draft.dirty
    assert _shipped_bytes() == shipped
    assert w.browser_item("TL+- no T+") is not None
    ts = load_tileset(saved)
    assert not ts.allowed[0][ts.tiles_of("T")][:, ts.tiles_of("+")].any()

    assert w.use_button.isEnabled()
    before = len(w.undo._done)
    qtbot.mouseClick(w.use_button, LEFT)
    assert len(w.undo._done) == before + 1
    assert w.undo.undo_text() == f"set {nid}.path"
    assert w.doc.node(nid).params["path"] == str(saved)
    w.undo.undo()
    assert w.doc.node(nid).params["path"] == ""


def test_shipped_set_is_used_by_name_in_one_step(qtbot, editor):
    w = editor
    _browse(w, "TL+-OV\\")
    nid = w.undo.push(AddNode("TileSet", {"path": "/somewhere/else.json"})).node_id
    w.set_selected(nid)
    before = len(w.undo._done)
    qtbot.mouseClick(w.use_button, LEFT)
    assert len(w.undo._done) == before + 1
    assert w.doc.node(nid).params["name"] == "TL+-OV\\" and w.doc.node(nid).params["path"] == ""
    w.set_selected(None)
    assert not w.use_button.isEnabled()


def test_add_block_dialog_keeps_typing_on_error_and_is_undoable(qtbot, editor):
    w = editor
    _browse(w, "TL+-")
    dialog = w.open_add_block_dialog()
    dialog.name_edit.setText("T")
    dialog.poly_edit.setPlainText("0.5 0.5; 1 0.5")
    qtbot.mouseClick(dialog.add_button, LEFT)
    assert "already a block named 'T'" in dialog.error_label.text()
    assert dialog.isVisible() and dialog.poly_edit.toPlainText() == "0.5 0.5; 1 0.5"
    assert w.block_list.count() == 4

    dialog.name_edit.setText("E")
    dialog.poly_edit.setPlainText("0.5 0.5; 1 0.25")
    qtbot.mouseClick(dialog.add_button, LEFT)
    assert "touches face +x" in dialog.error_label.text() and dialog.isVisible()
    dialog.connector_edits["+x"].setText("off")
    qtbot.mouseClick(dialog.add_button, LEFT)
    assert not dialog.isVisible() and w.block_list.count() == 5
    assert w.draft.tileset.tiles[w.draft.tileset.tiles_of("E")[0]].connectors == ("off", "0", "0", "0")

    qtbot.mouseClick(w.undo_button, LEFT)
    assert w.block_list.count() == 4 and not w.draft.dirty
    qtbot.mouseClick(w.redo_button, LEFT)
    assert w.block_list.count() == 5


def test_add_block_by_clicking_the_grid(qtbot, editor):
    w = editor
    _browse(w, "TL+-")
    dialog = w.open_add_block_dialog()
    canvas = dialog.canvas
    qtbot.waitExposed(dialog)
    cell = canvas._cell()

    def at(x, y):
        return QtCore.QPoint(round(cell.left() + x * cell.width()), round(cell.top() + y * cell.height()))

    qtbot.mouseClick(canvas, LEFT, pos=at(0.5, 0.5))
    qtbot.mouseClick(canvas, LEFT, pos=at(1.0, 0.5))
    qtbot.mouseClick(canvas, QtCore.Qt.MouseButton.RightButton, pos=at(0.5, 0.5))
    qtbot.mouseClick(canvas, LEFT, pos=at(0.5, 0.5))
    qtbot.mouseClick(canvas, LEFT, pos=at(0.5, 0.0))
    assert dialog.poly_edit.toPlainText() == "0.5 0.5; 1 0.5\n0.5 0.5; 0.5 0"
    assert len(canvas.polylines) == 2
    dialog.name_edit.setText("Lc")
    qtbot.mouseClick(dialog.add_button, LEFT)
    ts = w.draft.tileset
    # members to +x and -y midpoints: the derived labels are those of L
    assert ts.tiles[ts.tiles_of("Lc")[0]].connectors == ("1", "0", "0", "1")
    assert ts.n_orientations[ts.block_index("Lc")] == 4


def test_unsaved_edits_are_not_dropped_silently(qtbot, editor):
    w = editor
    _browse(w, "TL+-")
    w.weight_box.setValue(2.5)
    assert w.draft.dirty and w.draft.undo_text() == "weight of T"
    w.confirm_answer = False
    w.browser.setCurrentItem(w.browser_item("TL+-acute"))
    assert w.draft.name == "TL+-" and w.draft.dirty and len(w.asked) == 1
    assert w.browser.currentItem().text(0) == "TL+-"
    w.confirm_answer = True
    w.browser.setCurrentItem(w.browser_item("TL+-acute"))
    assert w.draft.name == "TL+-acute"


def test_remove_block_named_by_a_rule_asks_then_undo_restores(qtbot, editor):
    w = editor
    _browse(w, "TL+-")
    w.block_list.setCurrentRow(1)
    assert w.selected_block() == "L"
    w.confirm_answer = False
    qtbot.mouseClick(w.remove_button, LEFT)
    assert w.block_list.count() == 4 and "forbid L next to L" in w.asked[-1]
    w.confirm_answer = True
    qtbot.mouseClick(w.remove_button, LEFT)
    assert w.block_list.count() == 3 and w.rule_list.count() == 0
    qtbot.mouseClick(w.undo_button, LEFT)
    assert w.block_list.count() == 4 and w.rule_list.count() == 1


def test_rename_block_updates_rules_and_bad_rule_shows_message(qtbot, editor):
    w = editor
    _browse(w, "TL+-")
    w.block_list.setCurrentRow(1)
    w.text_answer = "Ell"
    qtbot.mouseClick(w.rename_button, LEFT)
    assert "forbid Ell next to Ell" in w.rule_list.item(0).text()
    w.rule_a.setEditText("Q")
    w.rule_b.setEditText("T")
    qtbot.mouseClick(w.add_rule_button, LEFT)
    assert "unknown block or tile 'Q'" in w.error_label.text()
    assert w.rule_a.currentText() == "Q" and w.rule_list.count() == 1


def test_3d_set_shows_blocks_and_six_faces(qtbot, editor):
    w = editor
    _browse(w, "cubic-beams")
    assert w.block_list.count() == 6
    assert not w.block_list.item(0).icon().isNull()
    assert [w.face_box.itemText(i) for i in range(w.face_box.count())] == \
        ["+x", "+y", "+z", "-x", "-y", "-z"]
    w.matrix.setCurrentCell(0, 5)
    assert w.pair_list.count() == 1 * 3 and "across +x" in w.pair_list.item(0).text()

    dialog = w.open_add_block_dialog()
    assert dialog.canvas is None and len(dialog.arm_boxes) == 6
    dialog.name_edit.setText("I3")
    dialog.arm_boxes["+z"].setChecked(True)
    dialog.poly_edit.setPlainText("0.5 0.5 0.5; 0.5 0.5 0")
    qtbot.mouseClick(dialog.add_button, LEFT)
    ts = w.draft.tileset
    assert w.block_list.count() == 7 and ts.n_orientations[ts.block_index("I3")] == 3
    assert w.unsaved


@pytest.mark.parametrize("typed, words", [("-1", "[0, inf]"), ("nan", "a finite number"),
                                          ("heavy", "a finite number")])
def test_a_typed_bad_weight_is_refused_at_the_field_and_nothing_changes(qtbot, editor, typed, words):
    w = editor
    _browse(w, "TL+-")
    kept, undo = w.weight_box.value(), w.draft.undo_text()
    type_into(qtbot, w.weight_box, typed)
    text = w.weight_box.message.text()
    assert w.weight_box.refused and words in text and "weight" in text and "kept" in text
    assert w.weight_box.value() == kept and w.draft.undo_text() == undo and not w.draft.dirty
    assert "allowed:" in w.weight_box.toolTip() and "default: 1" in w.weight_box.toolTip()


def test_a_weight_is_kept_as_typed_not_rounded_or_capped(qtbot, editor):
    w = editor
    _browse(w, "TL+-")
    type_into(qtbot, w.weight_box, "2.3456789")        # a QDoubleSpinBox kept 3 decimals
    ts = w.draft.tileset
    assert float(ts.weights[ts.tiles_of("T")].sum()) == pytest.approx(2.3456789, rel=1e-12)
    type_into(qtbot, w.weight_box, "5000000")          # and capped at 1e6
    ts = w.draft.tileset
    assert float(ts.weights[ts.tiles_of("T")].sum()) == pytest.approx(5e6, rel=1e-12)
