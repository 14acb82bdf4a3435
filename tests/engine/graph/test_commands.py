import pytest

from engine.graph import (AddNode, Connect, Disconnect, GraphDocument, GraphError, Macro, MoveNode, ParamError,
                          RemoveNode, SetParam, UndoStack, document_to_dict)


def _doc():
    doc = GraphDocument(seed=3)
    stack = UndoStack(doc)
    stack.push(AddNode("_TestNumber", {"value": 2.0}, node_id="a"))
    stack.push(AddNode("_TestNumber", {"value": 3.0}, node_id="b"))
    stack.push(AddNode("_TestSum", node_id="s"))
    stack.push(Connect("a", "value", "s", "terms"))
    stack.push(Connect("b", "value", "s", "terms"))
    return doc, stack


def test_undo_all_then_redo_all_restores_every_state():
    doc, stack = _doc()
    states = []
    stack.push(SetParam("a", "value", 5.0))
    stack.push(MoveNode("s", (100, 20)))
    stack.push(RemoveNode("b"))
    final = document_to_dict(doc)
    while stack.can_undo:
        states.append(document_to_dict(doc))
        stack.undo()
    assert doc.nodes == {} and doc.edges == []
    while stack.can_redo:
        stack.redo()
    assert document_to_dict(doc) == final


def test_remove_node_restores_edges_in_their_order():
    doc, stack = _doc()
    before = list(doc.edges)
    stack.push(RemoveNode("a"))
    assert all("a" not in (e.src, e.dst) for e in doc.edges)
    stack.undo()
    assert doc.edges == before  # order of multi-input connections is meaningful


def test_refused_commands_change_nothing_and_name_the_problem():
    doc, stack = _doc()
    before = document_to_dict(doc)
    with pytest.raises(ParamError, match=r"'value'.*\[-100.0, 100.0\]"):
        stack.push(SetParam("a", "value", 1e9))
    with pytest.raises(GraphError, match="cycle"):
        stack.push(AddNode("_TestSum", node_id="s2"))
        stack.push(Connect("s", "value", "s2", "terms"))
        stack.push(Connect("s2", "value", "s", "terms"))
    stack.undo(), stack.undo()
    with pytest.raises(GraphError, match="takes one connection"):
        stack.push(AddNode("_TestFail", node_id="f"))
        stack.push(Connect("a", "value", "f", "x"))
        stack.push(Connect("b", "value", "f", "x"))
    stack.undo(), stack.undo()
    with pytest.raises(GraphError, match="no input port 'nope'"):
        stack.push(Connect("a", "value", "s", "nope"))
    with pytest.raises(GraphError, match="already exists"):
        stack.push(AddNode("_TestNumber", node_id="a"))
    assert document_to_dict(doc) == before


def test_wrong_port_type_is_refused():
    doc = GraphDocument()
    stack = UndoStack(doc)
    stack.push(AddNode("Vertex", node_id="v"))
    stack.push(AddNode("Line", node_id="l"))
    with pytest.raises(GraphError, match=r"\(Point\).*takes EdgeChain"):
        stack.push(Connect("v", "point", "l", "chains"))
    assert doc.edges == []


def test_slider_drag_merges_into_one_undo_item_and_clean_mark():
    doc, stack = _doc()
    stack.set_clean()
    for v in (1.0, 2.0, 3.0, 4.0):
        stack.push(SetParam("a", "value", v), merge=True)
    assert not stack.is_clean
    assert doc.nodes["a"].params["value"] == 4.0
    stack.undo()
    assert doc.nodes["a"].params["value"] == 2.0
    assert stack.is_clean
    stack.push(Disconnect("a", "value", "s", "terms"))
    stack.undo()
    assert stack.is_clean


def test_macro_is_all_or_nothing():
    doc, stack = _doc()
    before = document_to_dict(doc)
    with pytest.raises(GraphError):
        stack.push(Macro("two", [AddNode("_TestNumber", node_id="c"), Connect("c", "value", "zzz", "terms")]))
    assert document_to_dict(doc) == before
    stack.push(Macro("two", [AddNode("_TestNumber", node_id="c"), Connect("c", "value", "s", "terms")]))
    stack.undo()
    assert document_to_dict(doc) == before


def test_events_reach_subscribers():
    doc, stack = _doc()
    seen = []
    doc.subscribe(lambda ev, payload: seen.append(ev))
    stack.push(SetParam("a", "value", 7.0))
    stack.undo()
    assert seen == ["param_changed", "param_changed"]


def test_at_most_one_voxel_node():
    doc = GraphDocument()
    stack = UndoStack(doc)
    stack.push(AddNode("Voxel"))
    with pytest.raises(GraphError, match="at most 1 Voxel"):
        stack.push(AddNode("Voxel"))
