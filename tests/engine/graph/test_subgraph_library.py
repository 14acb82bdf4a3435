"""Saved subgraphs: save to a library folder, insert into another document."""

from __future__ import annotations

import json

import pytest

from engine.graph import (AddNode, Connect, Evaluator, ExposeParam, GraphDocument, GraphError, MakeSubgraph,
                          SetSubgraphParam, UndoStack, document_to_dict)
from engine.graph.subgraph_library import InsertSubgraph, SubgraphLibrary


def _source():
    doc = GraphDocument(seed=1)
    stack = UndoStack(doc)
    stack.push(AddNode("_TestNumber", {"value": 2.0}, (0, 0), node_id="a"))
    stack.push(AddNode("_TestNumber", {"value": 3.0}, (0, 100), node_id="b"))
    stack.push(AddNode("_TestSum", {"scale": 2.0}, (200, 50), node_id="s"))
    stack.push(AddNode("_TestNumber", {"value": 9.0}, (0, 300), node_id="outside"))
    stack.push(Connect("a", "value", "s", "terms"))
    stack.push(Connect("b", "value", "s", "terms"))
    stack.push(Connect("outside", "value", "s", "terms"))
    stack.push(MakeSubgraph(["a", "b", "s"], "Doubled pair"))
    stack.push(ExposeParam("sub1", "s", "scale", "gain"))
    return doc, stack


def _shape(doc, ids):
    """Types, params, relative positions and inner edges of `ids`, independent of the ids."""
    order = {nid: k for k, nid in enumerate(ids)}
    x0 = min(doc.nodes[n].position[0] for n in ids)
    y0 = min(doc.nodes[n].position[1] for n in ids)
    nodes = [(doc.nodes[n].type_name, doc.nodes[n].params,
              (doc.nodes[n].position[0] - x0, doc.nodes[n].position[1] - y0)) for n in ids]
    edges = sorted((order[e.src], e.src_port, order[e.dst], e.dst_port) for e in doc.edges
                   if e.src in order and e.dst in order)
    return nodes, edges


def test_save_then_insert_into_another_document_reproduces_the_nodes(tmp_path):
    src, _ = _source()
    library = SubgraphLibrary(tmp_path / "lib")
    path, replaced = library.save(src, "sub1")
    assert path.parent == tmp_path / "lib" and not replaced
    entries, problems = library.entries()
    assert [e.name for e in entries] == ["Doubled pair"] and problems == []

    dst = GraphDocument()
    stack = UndoStack(dst)
    stack.push(AddNode("_TestNumber", node_id="a"))     # an id the copy must not take
    before = document_to_dict(dst)
    cmd = stack.push(InsertSubgraph(entries[0], offset=(500, 0)))
    sub = dst.annotations.subgraph(cmd.subgraph_id)
    assert sub.name == "Doubled pair" and len(sub.members) == 3 and "a" not in sub.members
    assert _shape(dst, list(sub.members)) == _shape(src, ["a", "b", "s"])
    assert [e.label for e in sub.exposed] == ["gain"]
    inner_sum = sub.exposed[0].node_id
    assert dst.nodes[inner_sum].type_name == "_TestSum"
    # the inserted copy evaluates as the original does without its outside input
    stack.push(SetSubgraphParam(sub.id, inner_sum, "scale", 3.0))
    assert Evaluator().evaluate(dst.snapshot()).outputs[inner_sum]["value"] == 15.0
    stack.undo()
    # one undo step takes the whole insertion away; redo brings back the same ids
    after = document_to_dict(dst)
    stack.undo()
    assert document_to_dict(dst) == before
    stack.redo()
    assert document_to_dict(dst) == after


def test_saving_again_replaces_and_bad_files_are_reported(tmp_path):
    src, _ = _source()
    library = SubgraphLibrary(tmp_path)
    library.save(src, "sub1")
    _, replaced = library.save(src, "sub1")
    assert replaced
    (tmp_path / "broken.json").write_text("{not json")
    data = json.loads(library.path_of("Doubled pair").read_text())
    data["exposed"][0]["node"] = "ghost"
    (tmp_path / "ghost.json").write_text(json.dumps(data))
    entries, problems = library.entries()
    assert [e.name for e in entries] == ["Doubled pair"]
    assert any("broken.json" in p and "cannot be read" in p for p in problems)
    assert any("exposed[0].node" in p for p in problems)


def test_an_empty_subgraph_is_not_saved(tmp_path):
    doc = GraphDocument()
    stack = UndoStack(doc)
    stack.push(AddNode("_TestNumber", node_id="a"))
    stack.push(MakeSubgraph(["a"]))
    from engine.graph import RemoveNode
    stack.push(RemoveNode("a"))
    with pytest.raises(GraphError, match="no nodes left"):
        SubgraphLibrary(tmp_path).save(doc, "sub1")
    assert list(tmp_path.iterdir()) == []
