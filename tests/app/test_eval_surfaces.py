"""`mesoforge eval --json` reports every Surface node's solve."""

import json

import pytest

from app import cli
from engine.graph import AddNode, Connect, GraphDocument, UndoStack, save_project

# Schwarz D's skew quadrilateral: four edges of the regular tetrahedron in a
# cube of edge 1/4; 48 patches make the cell's area 3.8377 (Schoen 1970).
D_QUAD = [[0, 0, 0], [0.25, 0.25, 0], [0, 0.25, 0.25], [0.25, 0, 0.25]]


def _add_surface(st, nid, loop, **params):
    st.push(AddNode("Surface", params, node_id=nid))
    for i, p in enumerate(loop):
        st.push(AddNode("Vertex", {"position": p}, node_id=f"{nid}_v{i}"))
    for i in range(len(loop)):
        st.push(AddNode("EdgeChain", node_id=f"{nid}_e{i}"))
        st.push(Connect(f"{nid}_v{i}", "point", f"{nid}_e{i}", "vertices"))
        st.push(Connect(f"{nid}_v{(i + 1) % len(loop)}", "point", f"{nid}_e{i}", "vertices"))
        st.push(Connect(f"{nid}_e{i}", "chain", nid, "chains"))


@pytest.fixture
def surface_file(tmp_path):
    doc = GraphDocument()
    st = UndoStack(doc)
    _add_surface(st, "s", D_QUAD, type="mixed_minimal", edge_length=0.06, thickness=[[0.0, 0.04]])
    st.push(AddNode("Object", {"resolution": 24}, node_id="obj"))
    st.push(Connect("s", "skeleton", "obj", "skeleton"))
    p = tmp_path / "surface.json"
    save_project(doc, p)
    return p, doc


def test_eval_json_reports_each_surface_solve(surface_file, capsys):
    path, _ = surface_file
    assert cli.main(["eval", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["ok"] and out["result_node"] == "obj" and out["mesh"]["watertight"]
    s = out["surfaces"]["s"]
    assert set(s) >= {"status", "solver", "iterations", "energy", "area", "max_abs_H", "mean_abs_H"}
    assert s["solver"] == "mixed_minimal" and s["status"] == "evaluated" and s["iterations"] > 0
    assert s["area"] * 48 == pytest.approx(3.8377, rel=0.01)
    assert s["max_abs_H"] >= s["mean_abs_H"] >= 0.0
    # existing keys stay: the node list, with the report's summary among its outputs
    (node,) = [n for n in out["nodes"] if n["id"] == "s"]
    assert node["type"] == "Surface" and node["outputs"]["report"]["solver"] == "mixed_minimal"


def test_a_failed_surface_is_reported_and_the_rest_kept(surface_file, tmp_path, capsys):
    _, doc = surface_file
    st = UndoStack(doc)
    _add_surface(st, "bad", [[0, 0, 0], [1, 0, 0], [0.5, 0.5, 0]], type="conjugate")
    p = tmp_path / "two.json"
    save_project(doc, p)
    assert cli.main(["eval", str(p), "--json"]) == 1
    out = json.loads(capsys.readouterr().out)
    assert out["failed"] == ["bad"]
    assert out["surfaces"]["bad"]["status"] == "failed" and "rule" in out["surfaces"]["bad"]["error"]
    assert out["surfaces"]["s"]["status"] == "evaluated" and out["mesh"]["watertight"]
