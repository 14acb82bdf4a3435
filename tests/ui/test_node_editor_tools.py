"""Node editor tools on the real window: copy / paste / duplicate, search-to-add,
minimap, Fit View on large graphs, the empty-editor hint."""

from __future__ import annotations

import pytest
from PySide6 import QtCore, QtWidgets

from engine.graph import AddNode, Connect, document_to_dict
from engine.graph.clipboard import FRAGMENT_FORMAT
from ui.node_minimap import HINT_TEXT

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")  # NodeGraphQt uses distutils versions

Key, Mod = QtCore.Qt.Key, QtCore.Qt.KeyboardModifier


def _focus_graph(window, qtbot):
    window.activateWindow()
    qtbot.waitUntil(lambda: QtWidgets.QApplication.activeWindow() is window, timeout=3000)
    view = window.editor.graph.viewer()
    view.setFocus()
    qtbot.waitUntil(view.hasFocus, timeout=3000)
    return view


def _pair(window):
    a = window.undo.push(AddNode("Vertex", {"position": [0.1, 0.2, 0.3]}, (0, 0), label="first")).node_id
    b = window.undo.push(AddNode("Vertex", {"position": [0.9, 0.2, 0.3]}, (0, 150))).node_id
    e = window.undo.push(AddNode("EdgeChain", {}, (260, 60))).node_id
    window.undo.push(Connect(a, "point", e, "vertices"))
    window.undo.push(Connect(b, "point", e, "vertices"))
    return [a, b, e]


def _select(window, ids):
    window.editor.clipboard.select_many(ids)
    assert sorted(window.editor.selected_ids()) == sorted(ids)


def _shape(doc, ids):
    index = {nid: k for k, nid in enumerate(ids)}
    return ([(doc.nodes[n].type_name, doc.nodes[n].params, doc.nodes[n].label) for n in ids],
            sorted((index[x.src], x.src_port, index[x.dst], x.dst_port) for x in doc.edges
                   if x.src in index and x.dst in index))


def test_ctrl_c_ctrl_v_pastes_a_copy_and_one_undo_removes_it(window, qtbot):
    ids = _pair(window)
    before = document_to_dict(window.doc)
    _select(window, ids)
    view = _focus_graph(window, qtbot)
    qtbot.keyClick(view, Key.Key_C, Mod.ControlModifier)
    assert FRAGMENT_FORMAT in QtWidgets.QApplication.clipboard().text()
    qtbot.keyClick(view, Key.Key_V, Mod.ControlModifier)
    new = [n for n in window.doc.nodes if n not in ids]
    assert len(new) == 3
    assert _shape(window.doc, new) == _shape(window.doc, ids)
    assert sorted(window.editor.selected_ids()) == sorted(new)          # the pasted nodes are selected
    assert window.editor.scene_node_ids() == set(window.doc.nodes)
    assert window.editor.scene_edges() == set(window.doc.edges)
    assert window.undo.undo_text() == "paste 3 nodes"
    qtbot.keyClick(view, Key.Key_Z, Mod.ControlModifier)                # one step takes all of it away
    assert document_to_dict(window.doc) == before
    assert window.editor.scene_node_ids() == set(ids)


def test_paste_goes_to_the_mouse_or_the_menu_point(window):
    ids = _pair(window)
    _select(window, ids)
    assert window.editor.clipboard.copy()
    new = window.editor.clipboard.paste(at=(1000.0, 500.0))
    xs = [window.doc.nodes[n].position for n in new]
    assert min(p[0] for p in xs) == 1000.0 and min(p[1] for p in xs) == 500.0
    # relative placement kept
    assert (window.doc.nodes[new[2]].position[0] - window.doc.nodes[new[0]].position[0]
            == window.doc.nodes[ids[2]].position[0] - window.doc.nodes[ids[0]].position[0])


def test_ctrl_d_duplicates_beside_the_original(window, qtbot):
    ids = _pair(window)
    QtWidgets.QApplication.clipboard().setText("something else")
    _select(window, ids[:1])
    view = _focus_graph(window, qtbot)
    qtbot.keyClick(view, Key.Key_D, Mod.ControlModifier)
    new = [n for n in window.doc.nodes if n not in ids]
    assert len(new) == 1 and window.editor.selected_ids() == new
    assert window.doc.nodes[new[0]].params == window.doc.nodes[ids[0]].params
    assert window.doc.nodes[new[0]].position != window.doc.nodes[ids[0]].position
    assert QtWidgets.QApplication.clipboard().text() == "something else"   # duplicate leaves it alone
    window.undo_edit()
    assert set(window.doc.nodes) == set(ids)


def test_copy_in_one_window_paste_in_another(make_window):
    first, second = make_window(), make_window()
    ids = _pair(first)
    _select(first, ids)
    first.editor.clipboard.copy()
    new = second.editor.clipboard.paste(at=(0.0, 0.0))
    assert len(new) == 3 and set(second.doc.nodes) == set(new)
    assert _shape(second.doc, new) == _shape(first.doc, ids)


def test_paste_of_foreign_text_changes_nothing(window):
    _pair(window)
    before = document_to_dict(window.doc)
    QtWidgets.QApplication.clipboard().setText('{"format": "mesoforge-fragment", "version": 1, '
                                               '"nodes": [{"id": "x", "type": "NoSuch"}]}')
    assert window.editor.clipboard.paste(at=(0, 0)) == []
    assert document_to_dict(window.doc) == before
    assert any("NoSuch" in text for level, text in window.log_lines if level == "error")


def test_search_lists_types_with_descriptions_and_enter_adds(window, qtbot):
    view = _focus_graph(window, qtbot)
    search = window.editor.search
    qtbot.keyClick(view, Key.Key_Tab)
    assert not search.isHidden() and search.line.hasFocus()
    assert len(search.visible_types()) >= 20
    first = search.list.item(0).text()
    assert "·" in first and "\n" in first                                 # family and description line
    qtbot.keyClicks(search.line, "stiffness tensor")                      # words of the description only
    assert search.visible_types() == ["MaterialMatrix"]
    search.line.clear()
    qtbot.keyClicks(search.line, "skeleton reflects")
    assert search.visible_types() == ["Mirror"]
    search.scene_pos = (321.0, 123.0)
    qtbot.keyClick(search.line, Key.Key_Return)
    assert search.isHidden()
    (nid,) = list(window.doc.nodes)
    assert window.doc.nodes[nid].type_name == "Mirror"
    assert window.doc.nodes[nid].position == (321.0, 123.0)
    qtbot.keyClick(view, Key.Key_Tab)
    qtbot.keyClick(search.line, Key.Key_Escape)
    assert search.isHidden() and len(window.doc.nodes) == 1


def _grid(window, n=40, cols=8, dx=420.0, dy=300.0):
    window.act_auto.setChecked(False)
    return [window.undo.push(AddNode("Vertex", {}, ((k % cols) * dx, (k // cols) * dy))).node_id
            for k in range(n)]


def _visible(window):
    viewer = window.editor.graph.viewer()
    return viewer.mapToScene(viewer.viewport().rect()).boundingRect()


def test_fit_view_shows_every_node_of_a_large_graph(window, qtbot):
    ids = _grid(window)
    window.editor.fit_view()
    qtbot.wait(10)
    visible = _visible(window)
    for nid in ids:
        assert visible.contains(window.editor.scene_node(nid).view.sceneBoundingRect()), nid
    # the F shortcut does the same after panning away
    viewer = window.editor.graph.viewer()
    viewer._set_viewer_pan(5000, 5000)
    assert not _visible(window).contains(window.editor.scene_node(ids[0]).view.sceneBoundingRect())
    window.act_fit.trigger()
    visible = _visible(window)
    assert all(visible.contains(window.editor.scene_node(n).view.sceneBoundingRect()) for n in ids)


def test_minimap_click_pans_the_editor(window, qtbot):
    ids = _grid(window, n=12, cols=4)
    editor = window.editor
    viewer = editor.graph.viewer()
    viewer.reset_zoom(QtCore.QPointF(0, 0))                # 1:1 around the first node
    editor.minimap.refresh()
    assert not editor.minimap.isHidden()                     # nodes off screen: the minimap shows
    far = editor.scene_node(ids[-1]).view.sceneBoundingRect().center()
    assert not _visible(window).contains(far)
    s, dx, dy = editor.minimap._transform()
    click = QtCore.QPoint(round(far.x() * s + dx), round(far.y() * s + dy))
    target = editor.minimap.scene_point(QtCore.QPointF(click))
    qtbot.mouseClick(editor.minimap, QtCore.Qt.MouseButton.LeftButton, pos=click)
    centre = _visible(window).center()
    assert abs(centre.x() - target.x()) < 2 / s and abs(centre.y() - target.y()) < 2 / s
    assert _visible(window).contains(far)


def test_minimap_stays_out_of_the_way_while_every_node_is_in_view(window, qtbot):
    ids = _grid(window, n=3, cols=3)
    editor, mm = window.editor, window.editor.minimap
    window.act_fit.trigger()
    mm.refresh()
    visible = _visible(window)
    assert all(visible.contains(editor.scene_node(n).view.sceneBoundingRect()) for n in ids)
    assert mm.isHidden()                                     # three nodes in a row, centred: all in view
    editor.graph.viewer().reset_zoom(QtCore.QPointF(-3000.0, -3000.0))   # look away from the graph
    mm.refresh()
    assert not mm.isHidden()


def test_minimap_redraws_only_when_something_changed(window, qtbot):
    ids = _grid(window, n=5, cols=5)
    mm = window.editor.minimap
    mm.refresh()
    qtbot.wait(100)
    painted = mm.paints
    for _ in range(5):
        mm.refresh()                                       # nothing changed: no redraw
    qtbot.wait(100)
    assert mm.paints == painted
    from engine.graph import MoveNode
    window.undo.push(MoveNode(ids[0], (-900.0, -400.0)))
    qtbot.waitUntil(lambda: mm.paints > painted, timeout=2000)


def test_hint_on_an_empty_editor_goes_with_the_first_node(window, qtbot):
    hint = window.editor.minimap.hint
    assert hint.isVisible() and hint.text() == HINT_TEXT
    assert "Tab" in hint.text() and "Right-click" in hint.text()
    nid = window.undo.push(AddNode("Vertex", {}, (0, 0))).node_id
    qtbot.waitUntil(lambda: not hint.isVisible(), timeout=2000)
    window.undo_edit()
    assert nid not in window.doc.nodes
    qtbot.waitUntil(hint.isVisible, timeout=2000)


def test_ctrl_c_in_a_text_field_copies_its_text_not_nodes(window, qtbot):
    ids = _pair(window)
    window.editor.select(ids[0])
    edits = [e for e in window.inspector.findChildren(QtWidgets.QLineEdit) if e.isVisible() and e.text()]
    assert edits, "the inspector shows some text field"
    edit = edits[0]
    window.activateWindow()
    edit.setFocus()
    qtbot.waitUntil(edit.hasFocus, timeout=3000)
    edit.selectAll()
    qtbot.keyClick(edit, Key.Key_C, Mod.ControlModifier)
    assert QtWidgets.QApplication.clipboard().text() == edit.text()


def test_first_sentence_and_matching():
    from ui.node_search import SearchEntry, first_sentence, matching
    assert first_sentence("Joins chains.  Then more.") == "Joins chains."
    assert first_sentence("Growth (eqs. 9-14) of stripes. More.") == "Growth (eqs. 9-14) of stripes."
    assert first_sentence("The dual (e.g. of a\n   Surface). Next") == "The dual (e.g. of a Surface)."
    long = first_sentence("word " * 100)
    assert len(long) <= 141 and long.endswith("…")
    entries = [SearchEntry("Mirror", "Mirror", "transform", "Reflects a skeleton."),
               SearchEntry("Vertex", "Vertex", "topology", "Places a vertex.")]
    assert [e.type_name for e in matching(entries, "SKELETON refl")] == ["Mirror"]
    assert [e.type_name for e in matching(entries, "")] == ["Mirror", "Vertex"]
    assert matching(entries, "nothing like it") == []
