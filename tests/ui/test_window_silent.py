"""Nothing silent (#14): typed values are refused at the field, never clamped;
undo / redo keys work from a focused spin box; shipped files are never written;
closing with unsaved changes asks.  All on the real window."""

from __future__ import annotations

import hashlib

import pytest
from PySide6 import QtCore, QtWidgets

from engine.graph import AddNode, all_node_types, document_to_dict
from ui.inspector import EDITORS
from ui.main_window import EXAMPLES_DIR
from ui.number_box import NumberBox
from ui.window_files import SHIPPED_DIR

Key, Mod = QtCore.Qt.Key, QtCore.Qt.KeyboardModifier


def _quiet(window):
    """No evaluations while typing (they only slow the test down)."""
    window.act_auto.setChecked(False)


def _add(window, type_name, params=None, node_id=None):
    node_id = window.undo.push(AddNode(type_name, params or {}, (0, 0), node_id=node_id)).node_id
    window.editor.select(node_id)
    assert window.inspector.node_id == node_id
    return node_id


def _focus(window, qtbot, widget):
    window.activateWindow()
    qtbot.waitUntil(lambda: QtWidgets.QApplication.activeWindow() is window, timeout=3000)
    widget.setFocus()
    qtbot.waitUntil(widget.hasFocus, timeout=3000)


def _type(qtbot, box, text):
    """What a user does: select the field's text, type, press Enter."""
    box.lineEdit().selectAll()
    qtbot.keyClick(box.lineEdit(), Key.Key_Backspace)
    qtbot.keyClicks(box.lineEdit(), text)
    qtbot.keyClick(box, Key.Key_Return)


def _undo_state(window):
    return len(window.undo._done), window.undo.undo_text(), window.undo.can_redo


@pytest.mark.parametrize("name, typed, allowed", [
    ("resolution", "1000", "[8, 512]"),
    ("resolution", "600", "[8, 512]"),
    ("resolution", "7", "[8, 512]"),
    ("resolution", "12.5", "an integer"),
    ("resolution", "many", "an integer"),
    ("cell_size", "0", "[0.001, 10000] mm"),
    ("cell_size", "", "a finite number"),
])
def test_typed_out_of_range_value_is_refused_at_the_field(window, qtbot, name, typed, allowed):
    _quiet(window)
    nid = _add(window, "Object", {"resolution": 32})
    before, depth = document_to_dict(window.doc), _undo_state(window)
    stored = window.doc.nodes[nid].params[name]
    box = window.inspector.editor_widget(name)
    _type(qtbot, box, typed)
    assert document_to_dict(window.doc) == before              # not clamped, not truncated: unchanged
    assert _undo_state(window) == depth                        # nothing pushed
    message = window.inspector.messages[name]
    assert message.isVisibleTo(window.inspector) and window.inspector.error_label is message
    text = message.text()
    assert name in text and allowed in text and "kept" in text
    assert (repr(typed) if typed in ("many", "") else typed) in text
    assert box.property("refused") is True                     # framed red
    assert box.value() == stored                               # the field shows what is stored
    _type(qtbot, box, "40" if name == "resolution" else "2")   # a good value clears the refusal
    assert window.doc.nodes[nid].params[name] == (40 if name == "resolution" else 2.0)
    assert not message.isVisibleTo(window.inspector) and box.property("refused") is False


def test_vector_component_out_of_range_is_refused(window, qtbot):
    _quiet(window)
    nid = _add(window, "Vertex", {"position": [0.123456789, 0.5, 0.5]})
    depth = _undo_state(window)
    editor = window.inspector.editors["position"]
    _type(qtbot, editor.boxes[0], "20")                        # range [-10, 10] cell: was clamped to 10
    assert window.doc.nodes[nid].params["position"] == [0.123456789, 0.5, 0.5]
    assert _undo_state(window) == depth
    text = window.inspector.messages["position"].text()
    assert "position" in text and "20" in text and "[-10, 10] cell" in text
    _type(qtbot, editor.boxes[1], "0.25")                      # x keeps its exact value, not the 6 digits shown
    assert window.doc.nodes[nid].params["position"] == [0.123456789, 0.25, 0.5]


def test_64_bit_seed_is_editable(window, qtbot):
    _quiet(window)
    nid = _add(window, "Grow")
    box = window.inspector.editor_widget("seed")
    assert isinstance(box, NumberBox)
    _type(qtbot, box, str(2**63 - 1))
    assert window.doc.nodes[nid].params["seed"] == 2**63 - 1
    assert box.value() == 2**63 - 1
    depth = _undo_state(window)
    _type(qtbot, box, str(2**63))
    assert window.doc.nodes[nid].params["seed"] == 2**63 - 1 and _undo_state(window) == depth
    assert str(2**63 - 1) in window.inspector.messages["seed"].text()


def test_stepping_stops_at_the_range(window, qtbot):
    _quiet(window)
    nid = _add(window, "Object", {"resolution": 511})
    box = window.inspector.editor_widget("resolution")
    box.stepBy(1)
    assert window.doc.nodes[nid].params["resolution"] == 512
    box.stepBy(1)
    assert window.doc.nodes[nid].params["resolution"] == 512
    assert not window.inspector.messages["resolution"].isVisibleTo(window.inspector)


def test_retyping_the_stored_value_pushes_nothing(window, qtbot):
    _quiet(window)
    _add(window, "Object", {"resolution": 32})
    depth = _undo_state(window)
    _type(qtbot, window.inspector.editor_widget("resolution"), "32")
    assert _undo_state(window) == depth


def test_every_parameter_tooltip_gives_range_and_unit(qtbot):
    parent = QtWidgets.QWidget()
    qtbot.addWidget(parent)
    for type_name, cls in all_node_types().items():
        for param in cls.params:
            editor = EDITORS[param.kind](param, parent)
            for w in [editor.widget, *editor.inputs()]:
                tip = w.toolTip()
                assert f"allowed: {param.allowed()}" in tip, (type_name, param.name, tip)
                if param.unit:
                    assert f"unit: {param.unit}" in tip, (type_name, param.name, tip)


# -- undo / redo keys ------------------------------------------------------------------------
def test_undo_redo_keys_from_a_focused_spin_box(window, qtbot):
    _quiet(window)
    nid = _add(window, "Object", {"resolution": 32})
    box = window.inspector.editor_widget("resolution")
    _focus(window, qtbot, box)
    _type(qtbot, box, "40")
    assert window.doc.nodes[nid].params["resolution"] == 40
    box = window.inspector.editor_widget("resolution")
    assert box.hasFocus()
    qtbot.keyClick(box, Key.Key_Z, Mod.ControlModifier)
    assert window.doc.nodes[nid].params["resolution"] == 32 and box.value() == 32
    qtbot.keyClick(box, Key.Key_Y, Mod.ControlModifier)
    assert window.doc.nodes[nid].params["resolution"] == 40 and box.value() == 40
    qtbot.keyClick(box, Key.Key_Z, Mod.ControlModifier)
    assert window.doc.nodes[nid].params["resolution"] == 32
    qtbot.keyClick(box, Key.Key_Z, Mod.ControlModifier | Mod.ShiftModifier)
    assert window.doc.nodes[nid].params["resolution"] == 40


def test_undo_key_from_the_label_field(window, qtbot):
    _quiet(window)
    nid = _add(window, "Object", {"resolution": 32})
    edit = window.inspector.label_edit
    _focus(window, qtbot, edit)
    qtbot.keyClicks(edit, "beam")
    qtbot.keyClick(edit, Key.Key_Return)
    assert window.doc.nodes[nid].label == "beam"
    qtbot.keyClick(edit, Key.Key_Z, Mod.ControlModifier)
    assert window.doc.nodes[nid].label == ""
    qtbot.keyClick(edit, Key.Key_Y, Mod.ControlModifier)
    assert window.doc.nodes[nid].label == "beam"


def test_ctrl_y_redoes_from_a_non_text_widget(window, qtbot):
    _quiet(window)
    nid = _add(window, "Object", {"resolution": 32})
    window.undo_edit()
    assert nid not in window.doc.nodes
    target = window.editor.graph.viewer()
    _focus(window, qtbot, target)
    qtbot.keyClick(target, Key.Key_Y, Mod.ControlModifier)
    assert nid in window.doc.nodes


# -- shipped files -------------------------------------------------------------------------
def _digest(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.mark.parametrize("how", ["open_example", "project_path"])
def test_plain_launch_and_ctrl_s_leave_the_shipped_example_untouched(make_window, prompter, qtbot, how):
    example = EXAMPLES_DIR / "octet.json"
    if not example.is_file():
        pytest.skip("resources/examples/octet.json is not there")
    digest = _digest(example)
    # `mesoforge` passes the default example's path (app.cli.cmd_open); the GUI's own default opens it too
    window = make_window(**({"open_example": True} if how == "open_example" else {"project_path": example}))
    _quiet(window)
    assert window.project_path is None and window.display_name == "octet (example)"
    some = next(iter(window.doc.nodes))
    window.undo.push(AddNode("Vertex", {}, (0, 0)))
    assert window.is_modified and window.doc.nodes[some]
    asked = []
    prompter.save_path = lambda caption, directory="", filters="": asked.append(directory)   # cancel
    _focus(window, qtbot, window.editor.graph.viewer())
    qtbot.keyClick(window.editor.graph.viewer(), Key.Key_S, Mod.ControlModifier)
    assert len(asked) == 1 and not asked[0].startswith(str(SHIPPED_DIR))
    assert _digest(example) == digest
    assert window.is_modified


def test_saving_into_resources_is_refused(make_window, prompter):
    example = EXAMPLES_DIR / "octet.json"
    if not example.is_file():
        pytest.skip("resources/examples/octet.json is not there")
    digest = _digest(example)
    window = make_window(open_example=True)
    _quiet(window)
    window.undo.push(AddNode("Vertex", {}, (0, 0)))
    prompter.save_answer = str(example)
    assert not window.save()
    assert _digest(example) == digest
    assert prompter.errors and "resources" in prompter.errors[-1][1]
    assert window.project_path is None and window.is_modified
    new_file = SHIPPED_DIR / "examples" / "new_one.json"
    assert not window.save_as(new_file) and not new_file.exists()
    assert not window.export_mesh(SHIPPED_DIR / "cell.stl") and not (SHIPPED_DIR / "cell.stl").exists()


def test_open_of_a_shipped_file_gives_an_untitled_copy(window, prompter):
    example = EXAMPLES_DIR / "octet.json"
    if not example.is_file():
        pytest.skip("resources/examples/octet.json is not there")
    prompter.open_answer = str(example)
    assert window.open_project()
    assert window.project_path is None and window.display_name == "octet (example)"


# -- closing -------------------------------------------------------------------------------
def test_closing_with_unsaved_changes_asks(make_window, prompter, qtbot):
    window = make_window()
    _quiet(window)
    window.undo.push(AddNode("Vertex", {}, (0, 0)))
    prompter.unsaved_answer = "cancel"
    assert not window.close()
    assert prompter.unsaved_asked == 1 and window.isVisible() and window.doc.nodes
    prompter.unsaved_answer = "discard"
    assert window.close()
    assert prompter.unsaved_asked == 2 and not window.isVisible()


def test_closing_a_clean_window_does_not_ask(make_window, prompter):
    window = make_window()
    assert window.close()
    assert prompter.unsaved_asked == 0


def test_the_view_menu_lists_every_dock(window):
    from PySide6 import QtWidgets

    view = next(a.menu() for a in window.menuBar().actions() if a.text() == "&View")
    docks_menu = next(a.menu() for a in view.actions() if a.menu() is not None and a.text() == "Docks")
    listed = {a.text() for a in docks_menu.actions()}
    every = {d.windowTitle() for d in window.findChildren(QtWidgets.QDockWidget)}
    assert len(every) >= 9 and listed == every


def test_property_nodes_are_not_drawn_in_the_failure_red():
    from ui.colours import FAMILY_COLOURS, STATUS_COLOURS

    failed = tuple(int(STATUS_COLOURS["failed"][i:i + 2], 16) for i in (1, 3, 5))
    r, g, b = FAMILY_COLOURS["property"]
    assert abs(r - failed[0]) + abs(g - failed[1]) + abs(b - failed[2]) > 200
