"""The node editor is a view of the document: commands and gestures both end in the document."""

from __future__ import annotations

import pytest

from engine.graph import AddNode, Connect, Edge, RemoveNode, document_to_dict
from engine.graph.layout import layer_depths

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")  # NodeGraphQt uses distutils versions


def test_scene_follows_commands_and_undo(window):
    editor, undo, doc = window.editor, window.undo, window.doc
    a = undo.push(AddNode("Vertex", {"position": [0, 0, 0]}, (10, 20))).node_id
    b = undo.push(AddNode("EdgeChain", {}, (250, 20))).node_id
    assert editor.scene_node_ids() == {a, b}
    assert editor.scene_node(a).pos() == [10.0, 20.0]
    undo.push(Connect(a, "point", b, "vertices"))
    assert editor.scene_edges() == {Edge(a, "point", b, "vertices")}
    assert editor.scene_pipe_count() == 1
    undo.push(RemoveNode(a))
    assert editor.scene_node_ids() == {b}
    assert editor.scene_edges() == set()
    undo.undo()                                  # node and its edge come back
    assert editor.scene_node_ids() == {a, b}
    assert editor.scene_edges() == {Edge(a, "point", b, "vertices")}
    undo.undo()
    assert editor.scene_edges() == set() and editor.scene_pipe_count() == 0
    # NodeGraphQt's private undo stack is never used
    assert editor.graph.undo_stack().count() == 0


def test_refused_connection_leaves_no_edge(window):
    editor, undo, doc = window.editor, window.undo, window.doc
    v = undo.push(AddNode("Vertex", {}, (0, 0))).node_id
    line = undo.push(AddNode("Line", {}, (300, 0))).node_id
    # by command: Point -> EdgeChain input refused, nothing changes
    before = document_to_dict(doc)
    try:
        undo.push(Connect(v, "point", line, "chains"))
    except Exception as exc:
        assert "EdgeChain" in str(exc)
    assert document_to_dict(doc) == before
    assert editor.scene_edges() == set() and editor.scene_pipe_count() == 0
    # by gesture: the viewer reports a dragged pipe; the engine refuses; the scene shows nothing
    out, inp = editor.scene_node(v).outputs()["point"], editor.scene_node(line).inputs()["chains"]
    editor.graph.viewer().connection_changed.emit([], [(out.view, inp.view)])
    assert doc.edges == []
    assert editor.scene_edges() == set() and editor.scene_pipe_count() == 0
    assert any(level == "error" and "refused" in text for level, text in window.log_lines)


def test_gesture_connect_and_detach_become_commands(window):
    editor, undo, doc = window.editor, window.undo, window.doc
    v1 = undo.push(AddNode("Vertex", {}, (0, 0))).node_id
    v2 = undo.push(AddNode("Vertex", {"position": [1, 0, 0]}, (0, 150))).node_id
    e = undo.push(AddNode("EdgeChain", {}, (300, 50))).node_id
    viewer = editor.graph.viewer()
    inp = editor.scene_node(e).inputs()["vertices"]
    for v in (v1, v2):                                   # a multi input takes both, in order
        viewer.connection_changed.emit([], [(editor.scene_node(v).outputs()["point"].view, inp.view)])
    assert doc.edges == [Edge(v1, "point", e, "vertices"), Edge(v2, "point", e, "vertices")]
    assert editor.scene_pipe_count() == 2
    assert undo.undo_text() == f"connect {v2}.point -> {e}.vertices"
    # dragging a pipe off an input: the viewer has already removed the pipe item
    out1 = editor.scene_node(v1).outputs()["point"]
    pipe = next(p for p in inp.view.connected_pipes if p.output_port is out1.view)
    pipe.delete()
    viewer.connection_changed.emit([(inp.view, out1.view)], [])
    assert doc.edges == [Edge(v2, "point", e, "vertices")]
    assert editor.scene_edges() == set(doc.edges) and editor.scene_pipe_count() == 1
    undo.undo()                                          # the pipe is drawn again
    assert editor.scene_edges() == set(doc.edges) and editor.scene_pipe_count() == 2
    # slicing pipes disconnects them
    viewer.connection_sliced.emit([(inp.view, out1.view)])
    assert Edge(v1, "point", e, "vertices") not in doc.edges
    assert editor.scene_pipe_count() == 1


def test_single_input_is_replaced_by_a_new_connection(window):
    editor, undo, doc = window.editor, window.undo, window.doc
    lines = [undo.push(AddNode("Line", {}, (0, 150 * i))).node_id for i in range(2)]
    obj = undo.push(AddNode("Object", {"resolution": 16}, (300, 0))).node_id
    undo.push(Connect(lines[0], "skeleton", obj, "skeleton"))
    assert editor.connect_ports(lines[1], "skeleton", obj, "skeleton")
    assert doc.inputs_of(obj) == [Edge(lines[1], "skeleton", obj, "skeleton")]
    assert editor.scene_edges() == set(doc.edges) and editor.scene_pipe_count() == 1
    undo.undo()                                           # one undo item restores the old link
    assert doc.inputs_of(obj) == [Edge(lines[0], "skeleton", obj, "skeleton")]
    assert editor.scene_edges() == set(doc.edges)


def test_create_move_rename_delete_gestures(window):
    editor, undo, doc = window.editor, window.undo, window.doc
    editor.graph.viewer().search_triggered.emit(editor._node_classes["Vertex"].type_, (40.0, 60.0))
    (vid,) = doc.nodes
    assert doc.nodes[vid].position == (40.0, 60.0)
    assert editor.selected_ids() == [vid] and window.inspector.node_id == vid
    node = editor.scene_node(vid)
    node.view.xy_pos = [140.0, 90.0]                     # the user dragged it
    editor.graph.viewer().moved_nodes.emit({node.view: [40.0, 60.0]})
    assert doc.nodes[vid].position == (140.0, 90.0)
    undo.undo()
    assert doc.nodes[vid].position == (40.0, 60.0) and node.pos() == [40.0, 60.0]
    editor.graph.viewer().node_name_changed.emit(node.id, "corner")
    assert doc.nodes[vid].label == "corner"
    editor.select(vid)
    window.act_delete.trigger()
    assert vid not in doc.nodes and editor.scene_node_ids() == set()
    undo.undo()
    assert editor.scene_node_ids() == {vid}
    assert editor.graph.undo_stack().count() == 0


def test_failed_node_is_marked(window, wait_eval):
    editor, undo = window.editor, window.undo
    v = undo.push(AddNode("Vertex", {}, (0, 0))).node_id
    e = undo.push(AddNode("EdgeChain", {}, (250, 0))).node_id
    undo.push(Connect(v, "point", e, "vertices"))        # one vertex: the chain fails
    report = wait_eval(window, 0)
    assert report.results[e].status == "failed"
    assert editor.node_status(e) == "failed"
    assert "at least two vertices" in editor.scene_node(e).view.toolTip()
    assert editor.node_status(v) == "evaluated"
    editor.select(e)
    assert "failed" in window.inspector.status_text()
    assert any(level == "error" and "at least two vertices" in t for level, t in window.log_lines)


def test_reset_rebuilds_scene(window, strut_graph):
    ids = strut_graph(window.undo)
    window.new_project()                                 # prompter discards
    assert window.editor.scene_node_ids() == set() and window.editor.scene_pipe_count() == 0
    assert not window.undo.can_undo
    assert window.windowTitle().startswith("untitled")
    assert ids  # graph existed


def test_arrange_nodes_is_one_undo_step(window, strut_graph):
    ids = strut_graph(window.undo)
    before = {nid: n.position for nid, n in window.doc.nodes.items()}
    assert window.editor.arrange_nodes()
    after = {nid: n.position for nid, n in window.doc.nodes.items()}
    assert after[ids["v1"]][0] == after[ids["v2"]][0] == 0.0       # sources share the first column
    # columns by depth, wrapped into bands of k columns that fit the editor: read like text
    depth = layer_depths(list(after), [(e.src, e.dst) for e in window.doc.edges])
    xs = sorted({p[0] for p in after.values()})
    k = len(xs)
    assert 1 <= k <= max(depth.values()) + 1
    for nid, (x, _) in after.items():
        assert xs.index(x) == depth[nid] % k
    for e in window.doc.edges:
        assert (depth[e.src] // k, after[e.src][0]) < (depth[e.dst] // k, after[e.dst][0])
    rects = [window.editor.scene_node(n).view.sceneBoundingRect() for n in after]
    assert not any(a.intersects(b) for i, a in enumerate(rects) for b in rects[i + 1:])
    assert window.editor.scene_node(ids["obj"]).pos() == list(after[ids["obj"]])
    assert window.undo.undo_text() == "arrange nodes"
    window.undo_edit()
    assert {nid: n.position for nid, n in window.doc.nodes.items()} == before
