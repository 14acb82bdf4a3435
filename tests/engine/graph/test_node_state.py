"""Stateful nodes' results in the project file: a repainted Grow reopens as it was."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from engine.graph import (AddNode, Connect, Evaluator, GraphDocument, RemoveNode, SetParam, UndoStack,
                          document_to_dict, load_project, save_project)
from engine.growth.regions import format_region_map
from engine.growth.tiling import UNASSIGNED

ROOT = Path(__file__).resolve().parents[3]
SHAPE = (12, 12)


def _graph():
    doc = GraphDocument(seed=4)
    st = UndoStack(doc)
    st.push(AddNode("TileSet", node_id="ts"))
    st.push(AddNode("Grow", {"size": [SHAPE[1], SHAPE[0]]}, node_id="g"))
    st.push(Connect("ts", "tileset", "g", "tileset"))
    return doc, st


def _paint(st, labels, hints="1: +=50,T=1,L=1,-=1"):
    st.push(SetParam("g", "region_hints", hints))
    st.push(SetParam("g", "regions", format_region_map(labels)))


def _box(rows, cols):
    m = np.zeros(SHAPE, bool)
    m[rows, cols] = True
    return m


def _tiles(report):
    assert report.ok, report.errors
    return np.array(report.output("g").tiling.tiles)


@pytest.fixture
def repainted(tmp_path):
    """Grow, repaint a square (local regrowth), save with the evaluator's state."""
    doc, st = _graph()
    ev = Evaluator()
    first = _tiles(ev.evaluate(doc))
    labels = np.zeros(SHAPE, int)
    labels[4:8, 4:8] = 1
    _paint(st, labels)
    regrown = _tiles(ev.evaluate(doc))
    assert not np.array_equal(regrown, first)
    doc.node_state = ev.export_state()
    path = tmp_path / "grown.json"
    save_project(doc, path)
    return path, first, regrown, labels


def test_reopened_project_gives_the_regrown_tiling_not_a_fresh_growth(repainted):
    path, first, regrown, _ = repainted
    doc = load_project(path)
    assert doc.load_warnings == [] and set(doc.node_state) == {"g"}
    ev = Evaluator()
    assert ev.import_state(doc.node_state) == []
    report = ev.evaluate(doc)
    assert report.results["g"].status == "cached"          # restored, not grown again
    restored = _tiles(report)
    assert restored.dtype == regrown.dtype and restored.tobytes() == regrown.tobytes()
    # what reopening did before: growing from scratch with the final parameters
    fresh = _tiles(Evaluator().evaluate(load_project(path)))
    assert not np.array_equal(fresh, regrown)


def test_repaint_after_reopening_regrows_only_the_new_cells(repainted):
    path, _, regrown, labels = repainted
    doc = load_project(path)
    st = UndoStack(doc)
    ev = Evaluator()
    ev.import_state(doc.node_state)
    ev.evaluate(doc)
    labels = labels.copy()
    labels[1:3, 8:11] = 1                                  # a second painted patch
    st.push(SetParam("g", "regions", format_region_map(labels)))
    report = ev.evaluate(doc)
    again = _tiles(report)
    cleared = _box(slice(0, 4), slice(7, 12))              # the patch plus a one-cell margin
    assert np.array_equal(again[~cleared], regrown[~cleared])
    assert not np.array_equal(again[cleared], regrown[cleared])
    start = report.output("g").start_tiles
    assert np.all(start[cleared] == UNASSIGNED) and np.array_equal(start[~cleared], regrown[~cleared])


def test_stored_state_with_an_older_key_is_offered_as_previous(repainted):
    path, _, regrown, _ = repainted
    data = json.loads(path.read_text())
    data["node_state"]["g"]["key"] = "0" * 64              # as if the node's version had changed
    path.write_text(json.dumps(data))
    doc = load_project(path)
    ev = Evaluator()
    ev.import_state(doc.node_state)
    report = ev.evaluate(doc)
    assert report.results["g"].status == "evaluated"
    assert np.array_equal(_tiles(report), regrown)         # same parameters: the tiling is kept


def test_version_1_file_without_state_loads_and_grows(tmp_path):
    doc, _ = _graph()
    data = document_to_dict(doc)
    del data["node_state"]
    data["version"] = 1
    path = tmp_path / "old.json"
    path.write_text(json.dumps(data))
    loaded = load_project(path)
    assert loaded.node_state == {} and loaded.load_warnings == []
    ev = Evaluator()
    ev.import_state(loaded.node_state)
    assert np.array_equal(_tiles(ev.evaluate(loaded)), _tiles(Evaluator().evaluate(doc)))
    save_project(loaded, path)
    assert json.loads(path.read_text())["version"] == 2


@pytest.mark.parametrize("corrupt, at_load", [
    (lambda s: s.update(value="not an object"), True),
    (lambda s: s.update(key="xyz"), True),
    (lambda s: s.update(seed=-3), True),
    (lambda s: s["value"]["tiling"].update(grid=[["Q@9"]]), False),
    (lambda s: s["value"]["tiling"].update(tileset="TL+-acute"), False),
    (lambda s: s["value"].pop("tiling"), False),
])
def test_corrupt_state_opens_with_a_warning_and_grows_afresh(repainted, corrupt, at_load):
    path, _, _, _ = repainted
    data = json.loads(path.read_text())
    corrupt(data["node_state"]["g"])
    path.write_text(json.dumps(data))
    doc = load_project(path)                               # no ProjectFileError
    assert set(doc.nodes) == {"ts", "g"}
    ev = Evaluator()
    ev.import_state(doc.node_state)
    report = ev.evaluate(doc)
    if at_load:
        assert len(doc.load_warnings) == 1 and "'g'" in doc.load_warnings[0]
        assert report.warnings == {}
    else:
        assert doc.load_warnings == []
        assert "'g'" in report.warnings["g"] and "from scratch" in report.warnings["g"]
    assert report.results["g"].status == "evaluated"
    fresh = _tiles(Evaluator().evaluate(load_project(path)))
    assert np.array_equal(_tiles(report), fresh)
    assert "g" in ev.export_state()                        # the new growth is kept from now on


def test_node_state_that_is_not_an_object_is_dropped_with_a_warning(repainted):
    path, _, _, _ = repainted
    data = json.loads(path.read_text())
    data["node_state"] = ["g"]
    data["nodes"].append({"id": "orphan", "type": "TileSet"})
    path.write_text(json.dumps(data))
    doc = load_project(path)
    assert doc.node_state == {} and "node_state" in doc.load_warnings[0]


def test_removing_a_node_drops_its_state(repainted):
    path, _, _, _ = repainted
    doc = load_project(path)
    ev = Evaluator()
    ev.import_state(doc.node_state)
    st = UndoStack(doc)
    st.push(RemoveNode("g"))
    assert "g" not in doc.node_state
    doc.node_state = ev.export_state()                    # the evaluator still holds it ...
    assert document_to_dict(doc)["node_state"] == {}       # ... but the file does not
    st.undo()                                              # the command kept no state ...
    doc.node_state = ev.export_state()
    assert set(document_to_dict(doc)["node_state"]) == {"g"}   # ... the evaluator's comes back


def test_exported_state_round_trips_before_any_evaluation(repainted):
    path, _, _, _ = repainted
    doc = load_project(path)
    ev = Evaluator()
    ev.import_state(doc.node_state)
    assert ev.export_state() == doc.node_state             # saving right after opening loses nothing


def test_importing_replaces_the_state_of_the_previous_document(repainted):
    path, _, regrown, _ = repainted
    ev = Evaluator()
    ev.import_state(load_project(path).node_state)
    ev.evaluate(load_project(path))
    other, _ = _graph()                                     # same ids, no stored state
    ev.import_state(other.node_state)
    assert ev.export_state() == {}
    assert np.array_equal(_tiles(ev.evaluate(other)), _tiles(Evaluator().evaluate(other)))


def test_cache_key_is_the_same_in_another_process(repainted):
    """The stored key must match the key a later process computes, whatever its
    hash seed (json with sorted keys, sha256: nothing process-dependent)."""
    path, _, _, _ = repainted
    stored = json.loads(path.read_text())["node_state"]["g"]["key"]
    script = ("import sys; from engine.graph import Evaluator, load_project; "
              "r = Evaluator().evaluate(load_project(sys.argv[1])); print(r.results['g'].key)")
    keys = set()
    for hash_seed in ("1", "2"):
        env = {**os.environ, "PYTHONHASHSEED": hash_seed}
        out = subprocess.run([sys.executable, "-c", script, str(path)], cwd=ROOT, env=env,
                             capture_output=True, text=True, timeout=300, check=True)
        keys.add(out.stdout.strip().splitlines()[-1])
    assert keys == {stored}
