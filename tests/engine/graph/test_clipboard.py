"""engine.graph.clipboard: fragments and the undoable paste."""

from __future__ import annotations

import json

import pytest

import engine.nodes  # noqa: F401  (registers the real node types: Voxel is max 1 per graph)
from engine.graph import (AddNode, Connect, GraphDocument, GraphError, NodeType, Param, Port, UndoStack,
                          document_from_dict, document_to_dict, register)
from engine.graph.clipboard import (FRAGMENT_FORMAT, PasteFragment, fragment_from_text, fragment_of,
                                    fragment_origin, fragment_to_text)

STATE = {"key": "ab" * 32, "params": {"value": 1.0}, "seed": 0, "value": {"x": [1, 2]}}


@register
class _Kept(NodeType):
    type_name = "_TestKept"
    code = "kept"
    stateful = True
    inputs = (Port("x", "Field"),)
    outputs = (Port("value", "Field"),)
    params = (Param("value", "float", 1.0, -100.0, 100.0),)

    def evaluate(self, inputs, params, ctx):
        return {"value": params["value"]}


def _doc():
    doc = GraphDocument(seed=3)
    stack = UndoStack(doc)
    stack.push(AddNode("_TestNumber", {"value": 2.0}, (0, 0), node_id="a", label="two"))
    stack.push(AddNode("_TestNumber", {"value": 3.0}, (0, 100), node_id="b"))
    stack.push(AddNode("_TestSum", {"scale": 4.0}, (200, 50), node_id="s"))
    stack.push(AddNode("_TestKept", {"value": 5.0}, (400, 50), node_id="k"))
    stack.push(Connect("a", "value", "s", "terms"))
    stack.push(Connect("b", "value", "s", "terms"))
    stack.push(Connect("s", "value", "k", "x"))
    doc.node_state["k"] = dict(STATE)
    return doc, stack


def _shape(doc, ids):
    """Types, params, labels and relative edges of `ids`, independent of the ids themselves."""
    index = {nid: k for k, nid in enumerate(ids)}
    nodes = [(doc.nodes[n].type_name, doc.nodes[n].params, doc.nodes[n].label) for n in ids]
    edges = sorted((index[e.src], e.src_port, index[e.dst], e.dst_port) for e in doc.edges
                   if e.src in index and e.dst in index)
    return nodes, edges


def test_fragment_is_json_in_the_project_encoding():
    doc, _ = _doc()
    frag = fragment_of(doc, ["s", "a", "b"])
    assert frag["format"] == FRAGMENT_FORMAT
    assert [n["id"] for n in frag["nodes"]] == ["a", "b", "s"]           # document order
    project_nodes = {n["id"]: n for n in document_to_dict(doc)["nodes"]}
    for n in frag["nodes"]:
        assert n == project_nodes[n["id"]]
    assert frag["edges"] == [{"from": ["a", "value"], "to": ["s", "terms"]},
                             {"from": ["b", "value"], "to": ["s", "terms"]}]   # s -> k left out
    assert frag["node_state"] == {}
    assert fragment_from_text(fragment_to_text(frag)) == json.loads(json.dumps(frag))
    assert fragment_origin(frag) == (0.0, 0.0)
    assert fragment_of(doc, ["k"])["node_state"] == {"k": STATE}
    with pytest.raises(GraphError, match="'nope'"):
        fragment_of(doc, ["a", "nope"])


def test_paste_round_trip_new_ids_one_undo_step():
    doc, stack = _doc()
    before = document_to_dict(doc)
    ids = ["a", "b", "s", "k"]
    frag = fragment_of(doc, ids)
    cmd = stack.push(PasteFragment(frag, offset=(30, 40)))
    assert len(cmd.new_ids) == 4 and not set(cmd.new_ids) & set(ids)
    assert cmd.id_map == dict(zip(ids, cmd.new_ids))
    assert _shape(doc, cmd.new_ids) == _shape(doc, ids)
    for old, new in cmd.id_map.items():
        ox, oy = doc.nodes[old].position
        assert doc.nodes[new].position == (ox + 30, oy + 40)
    assert doc.node_state[cmd.id_map["k"]] == STATE
    # the originals are untouched
    assert document_to_dict(doc)["nodes"][:4] == before["nodes"]
    assert len(doc.edges) == 6
    after = document_to_dict(doc)
    assert stack.undo_text() == "paste 4 nodes"
    stack.undo()                                     # one step removes every pasted node and edge
    assert document_to_dict(doc) == before
    stack.redo()                                     # redo brings the same ids back
    assert document_to_dict(doc) == after


def test_paste_twice_never_clobbers():
    doc, stack = _doc()
    frag = fragment_of(doc, ["a", "s"])
    first = stack.push(PasteFragment(frag)).new_ids
    second = stack.push(PasteFragment(frag)).new_ids
    assert len(set(first) | set(second) | {"a", "s"}) == 6
    assert len(doc.nodes) == 8


def test_paste_into_another_document_through_text():
    doc, _ = _doc()
    text = fragment_to_text(fragment_of(doc, ["a", "b", "s"]))
    other = GraphDocument()
    stack = UndoStack(other)
    stack.push(AddNode("_TestNumber", {}, node_id="num1"))   # the id the copy would get first
    cmd = stack.push(PasteFragment(fragment_from_text(text), offset=(0, 0)))
    assert "num1" not in cmd.new_ids and len(other.nodes) == 4
    assert _shape(other, cmd.new_ids) == _shape(doc, ["a", "b", "s"])
    # the result saves and loads as a project
    assert document_to_dict(document_from_dict(document_to_dict(other))) == document_to_dict(other)


def _refused(stack, frag, match):
    before = document_to_dict(stack.doc)
    events = []
    stack.doc.subscribe(lambda e, p: events.append(e))
    with pytest.raises(GraphError, match=match):
        stack.push(PasteFragment(frag))
    assert document_to_dict(stack.doc) == before and events == []
    assert not stack.can_redo


def test_refusals_change_nothing():
    doc, stack = _doc()
    frag = fragment_of(doc, ["a", "b", "s"])
    bad_type = json.loads(json.dumps(frag))
    bad_type["nodes"][1]["type"] = "NoSuchNode"
    _refused(stack, bad_type, "unknown node type 'NoSuchNode'")
    bad_param = json.loads(json.dumps(frag))
    bad_param["nodes"][2]["params"]["scale"] = 1000.0
    _refused(stack, bad_param, "scale")
    bad_edge = json.loads(json.dumps(frag))
    bad_edge["edges"].append({"from": ["a", "value"], "to": ["zz", "terms"]})
    _refused(stack, bad_edge, "no node 'zz'")
    bad_port = json.loads(json.dumps(frag))
    bad_port["edges"][0]["to"][1] = "nope"
    _refused(stack, bad_port, "edge 0")
    vox = GraphDocument()
    vstack = UndoStack(vox)
    vstack.push(AddNode("Voxel", {}, node_id="vox1"))
    _refused(vstack, fragment_of(vox, ["vox1"]), "at most 1 Voxel")


@pytest.mark.parametrize("text, match", [
    ("not json", "not a Mesoforge fragment"),
    ('{"format": "mesoforge-project", "version": 2, "nodes": []}', "format"),
    ('{"format": "mesoforge-fragment", "version": 9, "nodes": []}', "version"),
    ('{"format": "mesoforge-fragment", "version": 1, "nodes": [{"id": 1}]}', r"nodes\[0\]"),
    ('{"format": "mesoforge-fragment", "version": 1, "nodes": [], "edges": [1]}', r"edges\[0\]"),
])
def test_clipboard_text_that_is_no_fragment_is_refused(text, match):
    with pytest.raises(GraphError, match=match):
        fragment_from_text(text)


def test_a_pasted_grow_keeps_its_copied_repainted_tiling_when_the_evaluator_takes_its_state():
    """Stored results travel with a copy: the evaluator's latest state is copied, and
    `Evaluator.add_state` hands the pasted node its copy (without emptying the cache)."""
    import numpy as np

    from engine.graph import Evaluator, SetParam
    from engine.growth.regions import format_region_map

    doc = GraphDocument(seed=4)
    st = UndoStack(doc)
    st.push(AddNode("TileSet", node_id="ts", position=(0, 0)))
    st.push(AddNode("Grow", {"size": [12, 12], "seed": 77}, node_id="g", position=(240, 0)))
    st.push(Connect("ts", "tileset", "g", "tileset"))
    ev = Evaluator()
    first = np.array(ev.evaluate(doc).output("g").tiling.tiles)
    labels = np.zeros((12, 12), int)
    labels[4:8, 4:8] = 1
    st.push(SetParam("g", "region_hints", "1: +=50,T=1,L=1,-=1"))
    st.push(SetParam("g", "regions", format_region_map(labels)))
    regrown = np.array(ev.evaluate(doc).output("g").tiling.tiles)
    assert not np.array_equal(regrown, first)

    fragment = fragment_of(doc, ["ts", "g"], node_state=ev.export_state())
    assert set(fragment["node_state"]) == {"g"}
    cmd = PasteFragment(fragment, offset=(0, 300))
    st.push(cmd)
    g2 = cmd.id_map["g"]
    assert ev.add_state({g2: doc.node_state[g2]}) == []
    assert ev.add_state({"g": doc.node_state[g2]})          # a node holding a result keeps it
    report = ev.evaluate(doc)
    assert report.results["g"].status == "cached"              # the cache survived
    pasted = np.array(report.output(g2).tiling.tiles)
    assert pasted.tobytes() == regrown.tobytes()
    # without the copied state the pasted node grows afresh: the same parameters, no repaint history
    fresh = Evaluator().evaluate(doc).output(g2).tiling.tiles
    assert not np.array_equal(np.array(fresh), regrown)
