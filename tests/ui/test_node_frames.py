"""Frames and subgraph boxes in the node editor: drawn from the document, edited by gestures."""

from __future__ import annotations

import pytest
from PySide6 import QtCore, QtWidgets

from engine.graph import AddFrame, MakeSubgraph, MoveNode, Ungroup

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")  # NodeGraphQt uses distutils versions


def _select(editor, ids):
    editor.select(None)
    for nid in ids:
        editor.scene_node(nid).set_property("selected", True, push_undo=False)
    editor._emit_selection()


def _focus(window, qtbot, widget):
    window.act_auto.setChecked(False)  # no evaluations needed here
    window.activateWindow()
    qtbot.waitUntil(lambda: QtWidgets.QApplication.activeWindow() is window, timeout=3000)
    widget.setFocus()
    qtbot.waitUntil(widget.hasFocus, timeout=3000)


def _node_rect(editor, nid):
    return editor.scene_node(nid).view.sceneBoundingRect()


def test_ctrl_g_draws_a_box_around_the_selected_nodes_and_undo_removes_it(window, qtbot, strut_graph):
    ids = strut_graph(window.undo)
    editor, frames = window.editor, window.editor.frames
    members = [ids["v1"], ids["v2"], ids["e"]]
    _select(editor, members)
    viewer = editor.graph.viewer()
    _focus(window, qtbot, viewer)
    qtbot.keyClick(viewer, QtCore.Qt.Key.Key_G, QtCore.Qt.KeyboardModifier.ControlModifier)
    assert len(window.doc.annotations.subgraphs) == 1
    sub = next(iter(window.doc.annotations.subgraphs.values()))
    assert set(sub.members) == set(members)
    item = frames.subgraph_items[sub.id]
    assert item.scene() is viewer.scene()
    for nid in members:
        assert item.rect.contains(_node_rect(editor, nid))
    assert not item.rect.contains(_node_rect(editor, ids["vox"]))
    assert sub.name in item.title
    # moving a member through the document moves the box with it
    window.undo.push(MoveNode(ids["v1"], (-400, -300)))
    assert item.rect.contains(_node_rect(editor, ids["v1"]))
    window.undo.undo()
    qtbot.keyClick(viewer, QtCore.Qt.Key.Key_Z, QtCore.Qt.KeyboardModifier.ControlModifier)
    assert window.doc.annotations.subgraphs == {} and frames.subgraph_items == {}
    # redo brings it back; Ctrl+Shift+G ungroups
    window.undo.redo()
    assert sub.id in frames.subgraph_items
    _select(editor, [ids["v1"]])
    _focus(window, qtbot, viewer)
    qtbot.keyClick(viewer, QtCore.Qt.Key.Key_G,
                   QtCore.Qt.KeyboardModifier.ControlModifier | QtCore.Qt.KeyboardModifier.ShiftModifier)
    assert window.doc.annotations.subgraphs == {} and frames.subgraph_items == {}


def test_add_frame_around_selection_and_drag_its_title(window, qtbot, strut_graph):
    ids = strut_graph(window.undo)
    editor, frames = window.editor, window.editor.frames
    _select(editor, [ids["obj"], ids["vox"]])
    window.act_add_frame.trigger()
    (fid, frame), = window.doc.annotations.frames.items()
    item = frames.frame_items[fid]
    assert item.rect.contains(_node_rect(editor, ids["obj"])) and item.rect.contains(_node_rect(editor, ids["vox"]))
    assert frames.current == ("frame", fid)
    depth = len(window.undo._done)
    viewer = editor.graph.viewer()
    qtbot.wait(50)
    start = item.title_rect().center()
    press = viewer.mapFromScene(start)
    end = viewer.mapFromScene(start + QtCore.QPointF(120, 80))
    qtbot.mousePress(viewer.viewport(), QtCore.Qt.MouseButton.LeftButton, pos=press)
    for k in range(1, 6):
        p = press + (end - press) * (k / 5)
        move = QtGui_mouse_move(viewer.viewport(), p)
        QtWidgets.QApplication.sendEvent(viewer.viewport(), move)
    qtbot.mouseRelease(viewer.viewport(), QtCore.Qt.MouseButton.LeftButton, pos=end)
    moved = window.doc.annotations.frame(fid).rect
    assert len(window.undo._done) == depth + 1, "a drag is one undo item"
    assert moved[0] > frame.rect[0] + 60 and moved[1] > frame.rect[1] + 40
    assert moved[2:] == frame.rect[2:]
    assert item.rect.topLeft() == QtCore.QPointF(moved[0], moved[1])
    window.undo.undo()
    assert window.doc.annotations.frame(fid).rect == frame.rect
    assert item.rect.topLeft() == QtCore.QPointF(frame.rect[0], frame.rect[1])
    # the node under the frame's body is still clicked as a node (the body takes no mouse)
    assert item not in viewer.scene().items(_node_rect(editor, ids["vox"]).center())


def QtGui_mouse_move(widget, pos):
    from PySide6 import QtGui
    local = QtCore.QPointF(pos)
    return QtGui.QMouseEvent(QtCore.QEvent.Type.MouseMove, local, widget.mapToGlobal(local),
                             QtCore.Qt.MouseButton.NoButton, QtCore.Qt.MouseButton.LeftButton,
                             QtCore.Qt.KeyboardModifier.NoModifier)


def test_save_and_open_keeps_frames_and_subgraphs(window, tmp_path, strut_graph):
    ids = strut_graph(window.undo)
    window.undo.push(AddFrame((-50, -50, 600, 400), "Struts", "two vertices and a chain"))
    window.undo.push(MakeSubgraph([ids["l"], ids["obj"]], "Thicken"))
    path = tmp_path / "framed.json"
    assert window.save_as(path)
    window.new_project()
    assert window.editor.frames.frame_items == {} and window.editor.frames.subgraph_items == {}
    assert window.open_project(path, ask=False)
    frames = window.editor.frames
    (fid, item), = frames.frame_items.items()
    assert (item.title, item.comment) == ("Struts", "two vertices and a chain")
    assert item.rect == QtCore.QRectF(-50, -50, 600, 400)
    (sid, box), = frames.subgraph_items.items()
    assert window.doc.annotations.subgraph(sid).members == (ids["l"], ids["obj"])
    assert box.rect.contains(_node_rect(window.editor, ids["obj"]))


def _pipes_of(editor, nid):
    node = editor.scene_node(nid)
    return [pipe for port in [*node.input_ports(), *node.output_ports()] for pipe in port.view.connected_pipes]


def test_collapse_shows_one_proxy_node_with_the_boundary_ports(window, qtbot, tmp_path, strut_graph):
    window.act_auto.setChecked(False)
    ids = strut_graph(window.undo)
    editor, frames = window.editor, window.editor.frames
    members = [ids["l"], ids["obj"]]
    window.undo.push(MakeSubgraph(members, "Thicken"))
    sid = next(iter(window.doc.annotations.subgraphs))
    frames.select("subgraph", sid)
    assert frames.toggle_collapsed()
    proxy = frames.proxies[sid]
    assert sid not in frames.subgraph_items
    assert proxy.inputs == [(ids["l"], "chains")] and proxy.outputs == [(ids["obj"], "solid")]
    assert not proxy.wires.path().isEmpty()
    for nid in members:
        assert not editor.scene_node(nid).view.isVisible()
        assert all(not pipe.isVisible() for pipe in _pipes_of(editor, nid))
    assert editor.scene_node(ids["vox"]).view.isVisible()
    assert editor.scene_edges() == set(window.doc.edges)      # connections are unchanged
    # saved and reopened collapsed
    path = tmp_path / "collapsed.json"
    assert window.save_as(path)
    window.new_project()
    assert frames.proxies == {}
    assert window.open_project(path, ask=False)
    assert set(frames.proxies) == {sid}
    assert not editor.scene_node(ids["obj"]).view.isVisible()
    # a double click on the proxy expands it (one undo step)
    viewer = editor.graph.viewer()
    proxy = frames.proxies[sid]
    qtbot.mouseDClick(viewer.viewport(), QtCore.Qt.MouseButton.LeftButton,
                      pos=viewer.mapFromScene(proxy.title_rect().center()))
    assert not window.doc.annotations.subgraph(sid).collapsed
    assert frames.proxies == {} and sid in frames.subgraph_items
    for nid in members:
        assert editor.scene_node(nid).view.isVisible()
        assert all(pipe.isVisible() for pipe in _pipes_of(editor, nid))
    window.undo.undo()
    assert set(frames.proxies) == {sid} and not editor.scene_node(ids["l"]).view.isVisible()
    # ungrouping a collapsed subgraph shows its nodes again
    window.undo.push(Ungroup(sid))
    assert frames.proxies == {} and editor.scene_node(ids["l"]).view.isVisible()


def _drag(qtbot, viewer, start, delta, steps=5):
    press = viewer.mapFromScene(start)
    end = viewer.mapFromScene(start + delta)
    qtbot.mousePress(viewer.viewport(), QtCore.Qt.MouseButton.LeftButton, pos=press)
    for k in range(1, steps + 1):
        QtWidgets.QApplication.sendEvent(viewer.viewport(),
                                         QtGui_mouse_move(viewer.viewport(), press + (end - press) * (k / steps)))
    qtbot.mouseRelease(viewer.viewport(), QtCore.Qt.MouseButton.LeftButton, pos=end)


def test_dragging_a_subgraph_title_moves_its_nodes_in_one_step(window, qtbot, strut_graph):
    window.act_auto.setChecked(False)
    ids = strut_graph(window.undo)
    editor, frames = window.editor, window.editor.frames
    members = [ids["v1"], ids["v2"]]
    window.undo.push(MakeSubgraph(members, "Ends"))
    sid = next(iter(window.doc.annotations.subgraphs))
    before = {n: window.doc.nodes[n].position for n in members}
    depth = len(window.undo._done)
    qtbot.wait(50)
    _drag(qtbot, editor.graph.viewer(), frames.subgraph_items[sid].title_rect().center(), QtCore.QPointF(-200, 60))
    assert len(window.undo._done) == depth + 1 and window.undo.undo_text() == "move subgraph"
    for n in members:
        (x0, y0), (x1, y1) = before[n], window.doc.nodes[n].position
        assert x1 < x0 - 100 and y1 > y0 + 20
        assert editor.scene_node(n).pos() == [x1, y1]
        assert frames.subgraph_items[sid].rect.contains(_node_rect(editor, n))
    assert window.doc.nodes[ids["e"]].position == (240, 80)     # not a member: stays
    window.undo.undo()
    assert {n: window.doc.nodes[n].position for n in members} == before


def test_resizing_a_frame_by_its_corner_is_one_undo_step(window, qtbot):
    window.act_auto.setChecked(False)
    window.undo.push(AddFrame((0, 0, 300, 200), "Notes"))
    frames = window.editor.frames
    item = frames.frame_items["frame1"]
    depth = len(window.undo._done)
    qtbot.wait(50)
    _drag(qtbot, window.editor.graph.viewer(), item.sizer_rect().center(), QtCore.QPointF(150, 100))
    x, y, w, h = window.doc.annotations.frame("frame1").rect
    assert (x, y) == (0.0, 0.0) and w > 400 and h > 260
    assert len(window.undo._done) == depth + 1
    window.undo.undo()
    assert window.doc.annotations.frame("frame1").rect == (0.0, 0.0, 300.0, 200.0)
    assert item.rect == QtCore.QRectF(0, 0, 300, 200)


def test_fit_view_takes_in_frames_and_frame_edits_never_evaluate(window, qtbot, wait_eval, strut_graph):
    ids = strut_graph(window.undo)
    after = window.eval_count
    window.evaluate_now()
    wait_eval(window, after)
    evaluations = window.eval_count
    # a frame far from every node: Fit View must show it too
    window.undo.push(AddFrame((3000.0, 2000.0, 400.0, 300.0), title="notes"))
    qtbot.wait(400)                                              # past the evaluation debounce
    assert window.eval_count == evaluations and window.evaluation_idle
    editor = window.editor
    editor.fit_view()
    viewer = editor.graph.viewer()
    visible = viewer.mapToScene(viewer.viewport().rect()).boundingRect()
    frame = next(iter(editor.frames.frame_items.values()))
    assert visible.contains(frame.sceneBoundingRect())
    for nid in ids.values():
        assert visible.contains(_node_rect(editor, nid))
