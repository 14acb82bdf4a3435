"""Frames and subgraphs: undoable commands, membership of removed nodes, project files."""

from __future__ import annotations

import json

import pytest

from engine.graph import (AddFrame, AddNode, Connect, EditFrame, Evaluator, ExposeParam, GraphDocument, GraphError,
                          MakeSubgraph, ParamError, ProjectFileError, RemoveFrame, RemoveNode, RenameSubgraph,
                          SetParam, SetSubgraphCollapsed, SetSubgraphParam, UndoStack, UnexposeParam, Ungroup,
                          document_to_dict, load_project, save_project)


def _doc():
    doc = GraphDocument(seed=3)
    stack = UndoStack(doc)
    stack.push(AddNode("_TestNumber", {"value": 2.0}, node_id="a"))
    stack.push(AddNode("_TestNumber", {"value": 3.0}, node_id="b"))
    stack.push(AddNode("_TestSum", node_id="s"))
    stack.push(Connect("a", "value", "s", "terms"))
    stack.push(Connect("b", "value", "s", "terms"))
    return doc, stack


def _roundtrip_undo_redo(doc, stack, command, merge=False):
    """Push, undo, redo; the document dict before / after each step must match."""
    before = document_to_dict(doc)
    stack.push(command, merge=merge)
    after = document_to_dict(doc)
    assert after != before
    stack.undo()
    assert document_to_dict(doc) == before
    stack.redo()
    assert document_to_dict(doc) == after
    return after


def test_frame_commands_do_undo_redo():
    doc, stack = _doc()
    after = _roundtrip_undo_redo(doc, stack, AddFrame((0, 0, 300, 200), "Inputs", "two numbers"))
    assert after["annotations"]["frames"] == [{"id": "frame1", "title": "Inputs", "comment": "two numbers",
                                               "rect": [0.0, 0.0, 300.0, 200.0], "colour": [70, 90, 120]}]
    _roundtrip_undo_redo(doc, stack, EditFrame("frame1", title="Numbers", comment="a and b"))
    assert doc.annotations.frame("frame1").title == "Numbers"
    _roundtrip_undo_redo(doc, stack, RemoveFrame("frame1"))
    assert not doc.annotations.frames


def test_frame_drag_merges_into_one_undo_item():
    doc, stack = _doc()
    stack.push(AddFrame((0, 0, 300, 200)))
    depth = len(stack._done)
    for k in range(1, 6):
        stack.push(EditFrame("frame1", rect=(10 * k, 0, 300, 200 + k)), merge=True)
    assert len(stack._done) == depth + 1
    assert doc.annotations.frame("frame1").rect == (50.0, 0.0, 300.0, 205.0)
    stack.undo()
    assert doc.annotations.frame("frame1").rect == (0.0, 0.0, 300.0, 200.0)


def test_bad_frame_is_refused_naming_the_field():
    doc, stack = _doc()
    with pytest.raises(GraphError, match="rect .* width > 0"):
        stack.push(AddFrame((0, 0, -1, 20)))
    with pytest.raises(GraphError, match=r"colour .* \[0, 255\]"):
        stack.push(AddFrame((0, 0, 10, 20), colour=(300, 0, 0)))
    fid = stack.push(AddFrame((0, 0, 10, 20))).frame_id
    with pytest.raises(GraphError, match="rect"):
        stack.push(EditFrame(fid, rect=(0, 0, float("nan"), 1)))
    assert doc.annotations.frame(fid).rect == (0.0, 0.0, 10.0, 20.0)
    assert not stack.can_redo and len(doc.annotations.frames) == 1


def test_subgraph_commands_do_undo_redo():
    doc, stack = _doc()
    after = _roundtrip_undo_redo(doc, stack, MakeSubgraph(["a", "b"], "Inputs"))
    assert after["annotations"]["subgraphs"][0] == {"id": "sub1", "name": "Inputs", "members": ["a", "b"],
                                                    "exposed": [], "collapsed": False}
    _roundtrip_undo_redo(doc, stack, ExposeParam("sub1", "a", "value", "first"))
    _roundtrip_undo_redo(doc, stack, ExposeParam("sub1", "b", "value"))
    assert [(e.node_id, e.label) for e in doc.annotations.subgraph("sub1").exposed] == [("a", "first"), ("b", "")]
    _roundtrip_undo_redo(doc, stack, UnexposeParam("sub1", "a", "value"))
    _roundtrip_undo_redo(doc, stack, RenameSubgraph("sub1", "Numbers"))
    _roundtrip_undo_redo(doc, stack, SetSubgraphCollapsed("sub1", True))
    _roundtrip_undo_redo(doc, stack, Ungroup("sub1"))
    assert not doc.annotations.subgraphs
    stack.undo()
    assert doc.annotations.subgraph("sub1").collapsed and doc.annotations.subgraph("sub1").name == "Numbers"


def test_subgraph_refusals_change_nothing():
    doc, stack = _doc()
    with pytest.raises(GraphError, match="no nodes selected"):
        stack.push(MakeSubgraph([]))
    with pytest.raises(GraphError, match="no node with id 'zz'"):
        stack.push(MakeSubgraph(["a", "zz"]))
    stack.push(MakeSubgraph(["a"]))
    with pytest.raises(GraphError, match="already belongs to subgraph 'sub1'"):
        stack.push(MakeSubgraph(["a", "b"]))
    with pytest.raises(GraphError, match="not a member"):
        stack.push(ExposeParam("sub1", "b", "value"))
    with pytest.raises(GraphError, match="has no parameter 'nope'"):
        stack.push(ExposeParam("sub1", "a", "nope"))
    stack.push(ExposeParam("sub1", "a", "value"))
    with pytest.raises(GraphError, match="exposed twice"):
        stack.push(ExposeParam("sub1", "a", "value"))
    with pytest.raises(GraphError, match="does not expose"):
        stack.push(UnexposeParam("sub1", "a", "other"))
    assert list(doc.annotations.subgraphs) == ["sub1"]
    assert len(doc.annotations.subgraph("sub1").exposed) == 1


def test_removed_member_leaves_its_subgraph_and_undo_restores_it():
    doc, stack = _doc()
    stack.push(MakeSubgraph(["a", "b", "s"], "All"))
    stack.push(ExposeParam("sub1", "b", "value"))
    stack.push(ExposeParam("sub1", "s", "scale"))
    before = document_to_dict(doc)
    stack.push(RemoveNode("b"))
    sub = doc.annotations.subgraph("sub1")
    assert sub.members == ("a", "s")
    assert [(e.node_id, e.param) for e in sub.exposed] == [("s", "scale")]
    stack.undo()
    assert document_to_dict(doc) == before  # membership and exposure back, in place
    stack.redo()
    assert doc.annotations.subgraph("sub1").members == ("a", "s")
    # a new node that reuses the id is not a member
    stack.push(AddNode("_TestNumber", node_id="b"))
    assert doc.annotations.subgraph_of("b") is None


def test_set_subgraph_param_is_set_param_of_the_inner_node():
    doc, stack = _doc()
    twin, twin_stack = _doc()
    stack.push(MakeSubgraph(["a", "b"]))
    stack.push(ExposeParam("sub1", "a", "value"))
    stack.push(SetSubgraphParam("sub1", "a", "value", 7.5))
    twin_stack.push(SetParam("a", "value", 7.5))
    assert doc.nodes["a"].params == twin.nodes["a"].params
    one, two = Evaluator().evaluate(doc.snapshot()), Evaluator().evaluate(twin.snapshot())
    assert one.outputs["s"]["value"] == two.outputs["s"]["value"] == 10.5
    # refused exactly as SetParam refuses, nothing changes
    with pytest.raises(ParamError) as refused:
        stack.push(SetSubgraphParam("sub1", "a", "value", 1e6))
    with pytest.raises(ParamError) as refused_twin:
        twin_stack.push(SetParam("a", "value", 1e6))
    assert str(refused.value) == str(refused_twin.value)
    with pytest.raises(GraphError, match="does not expose b.value"):
        stack.push(SetSubgraphParam("sub1", "b", "value", 1.0))
    # merged like a SetParam drag, undone to the old value
    stack.push(SetSubgraphParam("sub1", "a", "value", 8.0), merge=True)
    stack.push(SetSubgraphParam("sub1", "a", "value", 9.0), merge=True)
    assert doc.nodes["a"].params["value"] == 9.0
    stack.undo()
    assert doc.nodes["a"].params["value"] == 2.0


def test_project_round_trip_keeps_annotations(tmp_path):
    doc, stack = _doc()
    stack.push(AddFrame((-10, 5, 420, 260), "Numbers", "inputs of the sum", (120, 80, 40)))
    stack.push(MakeSubgraph(["a", "b"], "Pair"))
    stack.push(ExposeParam("sub1", "b", "value", "second"))
    stack.push(SetSubgraphCollapsed("sub1", True))
    path = tmp_path / "p.json"
    save_project(doc, path)
    back = load_project(path)
    assert document_to_dict(back) == document_to_dict(doc)
    assert back.annotations.subgraph("sub1").exposed[0].label == "second"
    # and the loaded document's commands work
    UndoStack(back).push(Ungroup("sub1"))
    assert not back.annotations.subgraphs


def test_old_project_without_annotations_loads(tmp_path):
    doc, _ = _doc()
    data = document_to_dict(doc)
    assert "annotations" not in data  # nothing is written when there are none
    path = tmp_path / "old.json"
    path.write_text(json.dumps(data))
    back = load_project(path)
    assert not back.annotations and set(back.nodes) == {"a", "b", "s"}


@pytest.mark.parametrize("annotations, where, words", [
    ([], "annotations", "expected an object"),
    ({"frames": {}}, "annotations.frames", "expected a list"),
    ({"frames": [{"id": "f", "rect": [0, 0, 0, 5]}]}, "annotations.frames[0].rect", "width > 0"),
    ({"frames": [{"id": "f", "title": 3}]}, "annotations.frames[0].title", "expected a string"),
    ({"frames": [{"id": "f"}, {"id": "f"}]}, "annotations.frames[1].id", "used twice"),
    ({"subgraphs": [{"id": "s1", "members": ["a", "ghost"]}]}, "annotations.subgraphs[0].members",
     "no node with id 'ghost'"),
    ({"subgraphs": [{"id": "s1", "members": ["a"], "exposed": [{"node": "a", "param": "zz"}]}]},
     "annotations.subgraphs[0].exposed", "no parameter 'zz'"),
    ({"subgraphs": [{"id": "s1", "members": ["a"], "collapsed": "yes"}]}, "annotations.subgraphs[0].collapsed",
     "true or false"),
    ({"subgraphs": [{"id": "s1", "members": ["a"]}, {"id": "s2", "members": ["a"]}]},
     "annotations.subgraphs[1].members", "already belongs"),
    ({"groups": []}, "annotations.groups", "unknown entry"),
])
def test_malformed_annotations_refuse_the_file_naming_the_field(tmp_path, annotations, where, words):
    doc, _ = _doc()
    data = {**document_to_dict(doc), "annotations": annotations}
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    with pytest.raises(ProjectFileError) as refused:
        load_project(path)
    assert refused.value.where == where
    assert words in refused.value.reason


def test_open_replaces_annotations_and_views_hear_of_changes():
    doc, stack = _doc()
    heard = []
    doc.subscribe(lambda event, payload: heard.append((event, payload)))
    stack.push(AddFrame((0, 0, 10, 10)))
    assert ("annotation_changed", ("frame", "frame1")) in heard
    other = GraphDocument()
    doc.replace_with(other)
    assert not doc.annotations and doc.annotations.doc is doc


def test_boundary_ports_are_the_ports_edges_cross():
    from engine.graph.annotations import boundary_ports
    doc, stack = _doc()
    stack.push(AddNode("_TestSum", node_id="t"))
    stack.push(Connect("s", "value", "t", "terms"))
    stack.push(Connect("a", "value", "t", "terms"))
    assert boundary_ports(doc, ["s"]) == ([("s", "terms")], [("s", "value")])
    assert boundary_ports(doc, ["a", "b", "s"]) == ([], [("s", "value"), ("a", "value")])
    assert boundary_ports(doc, ["a", "b", "s", "t"]) == ([], [])
