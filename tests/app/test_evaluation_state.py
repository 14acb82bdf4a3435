"""Headless evaluation (`mesoforge eval`) starts from the node results stored in the project."""

from __future__ import annotations

import json

import numpy as np

from app import cli
from app.evaluation import evaluate_document, report_json
from engine.graph import AddNode, Connect, Evaluator, GraphDocument, SetParam, UndoStack, load_project, save_project
from engine.growth.regions import format_region_map


def _repainted_project(path):
    doc = GraphDocument(seed=2)
    st = UndoStack(doc)
    st.push(AddNode("TileSet", node_id="ts"))
    st.push(AddNode("Grow", {"size": [10, 10]}, node_id="g"))
    st.push(Connect("ts", "tileset", "g", "tileset"))
    ev = Evaluator()
    ev.evaluate(doc)
    labels = np.zeros((10, 10), int)
    labels[2:6, 3:7] = 1
    st.push(SetParam("g", "region_hints", "1: +=50,T=1,L=1,-=1"))
    st.push(SetParam("g", "regions", format_region_map(labels)))
    tiles = np.array(ev.evaluate(doc).output("g").tiling.tiles)
    doc.node_state = ev.export_state()
    save_project(doc, path)
    return tiles


def test_headless_evaluation_restores_the_stored_tiling(tmp_path):
    path = tmp_path / "p.json"
    regrown = _repainted_project(path)
    report = evaluate_document(load_project(path))
    assert report.results["g"].status == "cached"
    assert np.array_equal(report.output("g").tiling.tiles, regrown)


def test_eval_json_lists_a_dropped_state(tmp_path, capsys):
    path = tmp_path / "p.json"
    _repainted_project(path)
    data = json.loads(path.read_text())
    data["node_state"]["g"]["value"]["tiling"]["grid"] = "garbage"
    path.write_text(json.dumps(data))
    assert cli.main(["eval", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["ok"] and len(out["warnings"]) == 1 and "'g'" in out["warnings"][0]
    doc = load_project(path)
    assert report_json(doc, evaluate_document(doc))["warnings"] == out["warnings"]
