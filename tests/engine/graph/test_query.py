"""engine.graph.query: one rule for the node(s) a dock works on."""

import engine.nodes  # noqa: F401  (registers the nodes)
from engine.graph import AddNode, Connect, GraphDocument, UndoStack
from engine.graph.query import (chain_around, downstream_of_type, nearest_upstream, of_types, pick_node,
                                type_of, upstream_closure, upstream_of_type)


def lattice():
    """v1, v2 -> chain -> line -> obj -> vox; a lone vertex v3 and a second Line fed by chain."""
    doc = GraphDocument()
    st = UndoStack(doc)
    for nid, kind in (("v1", "Vertex"), ("v2", "Vertex"), ("chain", "EdgeChain"), ("line", "Line"),
                      ("obj", "Object"), ("vox", "Voxel"), ("v3", "Vertex"), ("line2", "Line")):
        st.push(AddNode(kind, {}, node_id=nid))
    for src, sp, dst, dp in (("v1", "point", "chain", "vertices"), ("v2", "point", "chain", "vertices"),
                             ("chain", "chain", "line", "chains"), ("line", "skeleton", "obj", "skeleton"),
                             ("obj", "solid", "vox", "solid"), ("chain", "chain", "line2", "chains")):
        st.push(Connect(src, sp, dst, dp))
    return doc


def test_the_selection_itself_then_the_nearest_above():
    doc = lattice()
    lines = of_types(doc, ["Line"])
    assert pick_node(doc, "line2", lines) == "line2"
    assert pick_node(doc, "vox", lines) == "line"            # two levels up, breadth first
    assert nearest_upstream(doc, "vox", of_types(doc, ["Vertex"])) == "v1"   # inputs in connection order
    assert nearest_upstream(doc, "line", lines) is None        # the start itself does not count


def test_then_the_previous_choice_then_the_end_of_the_graph():
    doc = lattice()
    lines = of_types(doc, ["Line"])
    assert pick_node(doc, "v3", lines, previous="line2") == "line2"    # nothing above v3
    assert pick_node(doc, "v3", lines, previous="gone") == "line2"     # last Line in topological order
    assert pick_node(doc, None, lines) == "line2"
    assert pick_node(doc, None, of_types(doc, ["MaterialMatrix"])) is None
    assert pick_node(None, "line", lines) is None


def test_a_chain_is_followed_up_and_down_from_any_member():
    doc = lattice()
    kinds = ["EdgeChain", "Line", "Object", "Voxel"]
    want = {"EdgeChain": "chain", "Line": "line", "Object": "obj", "Voxel": "vox"}
    for selected in ("chain", "line", "obj", "vox"):
        assert chain_around(doc, selected, kinds) == want, selected
    # from the second Line the chain goes up to the same EdgeChain but nothing is below it
    assert chain_around(doc, "line2", kinds) == {"EdgeChain": "chain", "Line": "line2", "Object": None,
                                                 "Voxel": None}
    # a selection outside every chain falls back to the last chain node of the graph
    assert chain_around(doc, "v1", kinds)["Line"] == "line2"
    assert chain_around(GraphDocument(), None, kinds) == dict.fromkeys(kinds)


def test_neighbours_of_a_type_and_the_upstream_closure():
    doc = lattice()
    assert upstream_of_type(doc, "chain", "Vertex") == "v1"
    assert upstream_of_type(doc, "chain", "Vertex", port="nope") is None
    assert downstream_of_type(doc, "chain", "Line") == "line"
    assert downstream_of_type(doc, None, "Line") is None
    assert upstream_closure(doc, "obj") == {"obj", "line", "chain", "v1", "v2"}
    assert type_of(doc, "vox") == "Voxel" and type_of(doc, "missing") is None and type_of(None, "vox") is None
