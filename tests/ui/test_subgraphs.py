"""Subgraphs in the window: the subgraph panel edits exposed parameters like the
inspector does, and the library saves and inserts subgraphs."""

from __future__ import annotations

import pytest
from PySide6 import QtCore

from engine.graph import ExposeParam, MakeSubgraph
from engine.graph.subgraph_library import SubgraphLibrary
from ui.subgraph_actions import fill_insert_menu, insert_subgraph, save_subgraph
from ui.subgraph_inspector import SubgraphPanel

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")  # NodeGraphQt uses distutils versions

Key = QtCore.Qt.Key


def _panel(window, qtbot):
    panel = SubgraphPanel(window.doc, window.undo, window.editor.frames)
    qtbot.addWidget(panel)
    panel.show()
    return panel


def _type(qtbot, box, text):
    box.lineEdit().selectAll()
    qtbot.keyClick(box.lineEdit(), Key.Key_Backspace)
    qtbot.keyClicks(box.lineEdit(), text)
    qtbot.keyClick(box.lineEdit(), Key.Key_Return)


def test_exposed_param_edited_in_the_panel_sets_the_node_param(window, qtbot, strut_graph):
    window.act_auto.setChecked(False)
    ids = strut_graph(window.undo)
    panel = _panel(window, qtbot)
    window.undo.push(MakeSubgraph([ids["obj"], ids["vox"]], "Solid"))
    sub_id = next(iter(window.doc.annotations.subgraphs))
    window.editor.frames.select("subgraph", sub_id)
    assert panel.current == ("subgraph", sub_id) and panel.sub_box.isVisibleTo(panel)
    assert panel.name_edit.text() == "Solid"
    # expose through the panel's chooser
    k = panel.expose_choice.findData(f"{ids['obj']}.resolution")
    assert k >= 0
    panel.expose_choice.setCurrentIndex(k)
    panel.expose_button.click()
    assert [(e.node_id, e.param) for e in window.doc.annotations.subgraph(sub_id).exposed] == \
        [(ids["obj"], "resolution")]
    box = panel.editor_widget(ids["obj"], "resolution")
    assert "allowed:" in box.toolTip()
    _type(qtbot, box, "48")
    assert window.doc.nodes[ids["obj"]].params["resolution"] == 48
    assert window.undo.undo_text() == f"set {ids['obj']}.resolution"
    # a value the schema refuses is refused at the field, nothing changes
    depth = len(window.undo._done)
    box = panel.editor_widget(ids["obj"], "resolution")
    _type(qtbot, box, "100000")
    message = panel.messages[(ids["obj"], "resolution")]
    assert message.refused and "100000 refused" in message.text()
    assert window.doc.nodes[ids["obj"]].params["resolution"] == 48 and len(window.undo._done) == depth
    assert panel.editor_widget(ids["obj"], "resolution").value() == 48
    # undo shows in the panel and in the inspector alike
    window.undo.undo()
    assert window.doc.nodes[ids["obj"]].params["resolution"] == 32
    assert panel.editor_widget(ids["obj"], "resolution").value() == 32
    assert not panel.messages[(ids["obj"], "resolution")].refused
    # renaming through the panel; unexposing through its row button
    panel.name_edit.setText("Voxel solid")
    panel.name_edit.editingFinished.emit()
    assert window.doc.annotations.subgraph(sub_id).name == "Voxel solid"
    assert panel.unexpose(ids["obj"], "resolution")
    assert window.doc.annotations.subgraph(sub_id).exposed == ()
    # the collapsed flag from the panel: one proxy node, undoable
    panel.collapsed_box.setChecked(True)
    assert window.doc.annotations.subgraph(sub_id).collapsed and sub_id in window.editor.frames.proxies
    window.undo.undo()
    assert not panel.collapsed_box.isChecked() and window.editor.frames.proxies == {}
    panel.detach()


def test_frame_panel_edits_title_and_comment(window, qtbot, strut_graph):
    window.act_auto.setChecked(False)
    strut_graph(window.undo)
    panel = _panel(window, qtbot)
    fid = window.editor.frames.add_frame_around_selection()
    assert panel.current == ("frame", fid) and panel.frame_box.isVisibleTo(panel)
    panel.frame_title.setText("Inputs")
    panel.frame_title.editingFinished.emit()
    panel.frame_comment.setPlainText("the two end points")
    panel._edit_frame(comment=panel.frame_comment.toPlainText())
    frame = window.doc.annotations.frame(fid)
    assert (frame.title, frame.comment) == ("Inputs", "the two end points")
    assert window.editor.frames.frame_items[fid].title == "Inputs"
    window.undo.undo()
    assert window.doc.annotations.frame(fid).comment == ""
    panel.detach()


def test_save_subgraph_to_library_and_insert_it(window, qtbot, tmp_path, strut_graph):
    window.act_auto.setChecked(False)
    ids = strut_graph(window.undo)
    window.subgraph_library = SubgraphLibrary(tmp_path / "library")
    window.undo.push(MakeSubgraph([ids["l"], ids["obj"]], "Thicken"))
    sub_id = next(iter(window.doc.annotations.subgraphs))
    window.undo.push(ExposeParam(sub_id, ids["obj"], "resolution", "voxels"))
    window.editor.frames.select("subgraph", sub_id)
    path = save_subgraph(window)
    assert path is not None and path.startswith(str(tmp_path / "library"))
    fill_insert_menu(window)
    names = [a.text() for a in window.insert_subgraph_menu.actions()]
    assert names == ["Thicken"]
    before = set(window.doc.nodes)
    window.insert_subgraph_menu.actions()[0].trigger()
    new_subs = [s for s in window.doc.annotations.subgraphs.values() if s.id != sub_id]
    assert len(new_subs) == 1
    new = new_subs[0]
    assert set(new.members).isdisjoint(before) and set(window.doc.nodes) == before | set(new.members)
    assert [window.doc.nodes[m].type_name for m in new.members] == ["Line", "Object"]
    assert new.exposed[0].label == "voxels" and new.exposed[0].node_id in new.members
    assert new.id in window.editor.frames.subgraph_items
    assert set(new.members) <= window.editor.scene_node_ids()
    window.undo.undo()                         # one step
    assert set(window.doc.nodes) == before and new.id not in window.doc.annotations.subgraphs
    # inserting an entry directly returns the new id
    entry = window.subgraph_library.entries()[0][0]
    assert insert_subgraph(window, entry) is not None


def test_inspector_context_menu_exposes_a_parameter(window, strut_graph):
    from ui.subgraph_actions import inspector_menu
    window.act_auto.setChecked(False)
    ids = strut_graph(window.undo)
    window.editor.select(ids["obj"])
    label = window.inspector.form.labelForField(window.inspector.editors["resolution"].widget)
    menu = inspector_menu(window, label)
    (action,) = menu.actions()
    assert not action.isEnabled() and "Ctrl+G" in action.text()   # not in a subgraph yet
    window.undo.push(MakeSubgraph([ids["obj"]], "Solid"))
    window.editor.select(ids["obj"])
    (action,) = inspector_menu(window, window.inspector.editor_widget("resolution")).actions()
    action.trigger()
    sub = window.doc.annotations.subgraph_of(ids["obj"])
    assert [(e.node_id, e.param) for e in sub.exposed] == [(ids["obj"], "resolution")]
    (action,) = inspector_menu(window, label).actions()
    assert action.text().startswith("Unexpose")
    action.trigger()
    assert window.doc.annotations.subgraph_of(ids["obj"]).exposed == ()


def test_the_inspector_dock_shows_the_subgraph_of_the_selected_node(window, qtbot, strut_graph):
    window.act_auto.setChecked(False)
    ids = strut_graph(window.undo)
    panel = window.subgraph_panel
    dock = window.inspector_dock
    assert not panel.isVisibleTo(dock)                       # nothing grouped yet
    window.undo.push(MakeSubgraph([ids["obj"], ids["vox"]], "Solid"))
    sub_id = next(iter(window.doc.annotations.subgraphs))
    window.undo.push(ExposeParam(sub_id, ids["obj"], "resolution"))
    window.editor.select(ids["obj"])                         # a member: its subgraph shows under it
    assert window.inspector.node_id == ids["obj"]
    assert panel.isVisibleTo(dock) and panel.current == ("subgraph", sub_id)
    assert (ids["obj"], "resolution") in panel.editors
    window.editor.select(ids["v1"])                          # not a member
    assert not panel.isVisibleTo(dock)
