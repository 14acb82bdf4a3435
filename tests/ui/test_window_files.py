"""Project files from the window: bad files, unsaved changes, examples, crash recovery."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from engine.autosave import AutosaveManager
from engine.graph import AddNode, Connect, SetParam, SetSeed, document_to_dict, load_project
from engine.growth.regions import format_region_map
from ui.main_window import EXAMPLES_DIR

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")  # NodeGraphQt uses distutils versions


def test_corrupt_project_shows_error_and_keeps_document(window, tmp_path, strut_graph, prompter):
    strut_graph(window.undo)
    before, title = document_to_dict(window.doc), window.windowTitle()
    bad = tmp_path / "broken.json"
    bad.write_text('{"format": "mesoforge-project", "version": 1, "nodes": [')
    assert not window.open_project(bad, ask=False)
    assert prompter.errors and str(bad) in prompter.errors[-1][1]
    assert any(level == "error" and "broken.json" in text for level, text in window.log_lines)
    assert document_to_dict(window.doc) == before
    assert window.windowTitle() == title and window.project_path is None
    assert window.undo.can_undo                      # history kept too
    assert not window.open_project(tmp_path / "missing.json", ask=False)
    assert document_to_dict(window.doc) == before


def test_unsaved_changes_prompt_on_close(make_window, prompter, tmp_path):
    window = make_window()
    window.undo.push(SetSeed(7))
    assert window.windowTitle().startswith("untitled*")
    prompter.unsaved_answer = "cancel"
    assert not window.close()
    assert window.isVisible() and prompter.unsaved_asked == 1
    prompter.unsaved_answer = "save"
    prompter.save_answer = str(tmp_path / "kept.json")
    assert window.close()
    assert (tmp_path / "kept.json").is_file()


def test_open_asks_before_dropping_changes(window, prompter, tmp_path):
    other = tmp_path / "other.json"
    window.undo.push(SetSeed(3))
    window.save_as(other)
    window.undo.push(SetSeed(4))
    prompter.unsaved_answer = "cancel"
    prompter.open_answer = str(other)
    assert not window.open_project()
    assert window.doc.seed == 4
    prompter.unsaved_answer = "discard"
    assert window.open_project()
    assert window.doc.seed == 3 and "*" not in window.windowTitle()


def test_autosave_and_recovery_after_crash(make_window, prompter, tmp_path):
    autosave_dir = tmp_path / "autosave"
    project = tmp_path / "lattice.json"
    first = make_window(autosave_dir=autosave_dir)
    first.undo.push(AddNode("Vertex", {"position": [0.5, 0.5, 0.5]}, (0, 0)))
    first.save_as(project)
    first.undo.push(SetSeed(11))                          # unsaved change
    assert first.autosave_now()
    content = document_to_dict(first.doc)
    # pretend the first process died: re-label its autosave with a dead pid
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    crashed = AutosaveManager(autosave_dir, pid=dead.pid)
    crashed.save(first.doc, project)
    first.autosave.clear()
    prompter.recover_answer = True
    second = make_window(autosave_dir=autosave_dir, offer_recovery=True)
    assert prompter.recover_asked
    assert document_to_dict(second.doc) == content
    assert second.project_path == project.resolve()
    assert second.is_modified and "*" in second.windowTitle()
    assert crashed.find_recoverable() == []               # discarded after recovery


def test_default_example_opens_and_evaluates(make_window, wait_eval, prompter):
    example = EXAMPLES_DIR / "octet.json"
    if not example.is_file():
        pytest.skip("resources/examples/octet.json is not there yet")
    window = make_window(open_example=True)
    assert window.display_name == "octet (example)" and window.project_path is None
    assert window.doc.nodes
    report = wait_eval(window, 0, timeout=180000)
    assert report.ok, report.errors
    assert window.viewport.mesh_point_count() > 0
    assert not prompter.errors


def test_examples_menu_lists_examples(window):
    window._fill_examples_menu()
    names = [a.text() for a in window.examples_menu.actions()]
    files = window.example_files()
    if files:
        assert names == [p.stem.replace("_", " ") for p in files]
    else:
        assert names == ["(no examples found)"]


def test_autosave_timer_writes_only_unsaved_work(make_window, qtbot, tmp_path):
    window = make_window(autosave_dir=tmp_path / "auto", autosave_interval_ms=50)
    qtbot.wait(150)
    assert not window.autosave.autosave_path.exists()     # nothing unsaved: nothing written
    window.undo.push(SetSeed(9))
    qtbot.waitUntil(window.autosave.autosave_path.exists, timeout=2000)
    window.save_as(tmp_path / "p.json")                   # a clean save removes the autosave
    assert not window.autosave.autosave_path.exists()


def test_repainted_tiling_survives_save_and_reopen(make_window, wait_eval, tmp_path, prompter):
    window = make_window()
    window.undo.push(AddNode("TileSet", {}, (0, 0), node_id="ts"))
    window.undo.push(AddNode("Grow", {"size": [12, 12]}, (240, 0), node_id="g"))
    window.undo.push(Connect("ts", "tileset", "g", "tileset"))
    first = wait_eval(window, window.eval_count)
    assert first.ok, first.errors
    grown = np.array(first.output("g").tiling.tiles)
    labels = np.zeros((12, 12), int)
    labels[3:7, 2:8] = 1
    count = window.eval_count
    window.undo.push(SetParam("g", "region_hints", "1: +=50,T=1,L=1,-=1"))
    window.undo.push(SetParam("g", "regions", format_region_map(labels)))
    report = wait_eval(window, count)
    assert report.ok, report.errors
    regrown = np.array(report.output("g").tiling.tiles)
    assert not np.array_equal(regrown, grown)
    assert window.autosave_now()                              # the autosave keeps the history too
    assert set(load_project(window.autosave.autosave_path).node_state) == {"g"}
    project = tmp_path / "grown.json"
    assert window.save_as(project)

    other = make_window(project)
    reopened = wait_eval(other, 0)
    assert reopened.ok, reopened.errors
    assert reopened.results["g"].status == "cached"          # restored from the file
    assert np.array(reopened.output("g").tiling.tiles).tobytes() == regrown.tobytes()
    # the first window, reopening the file over its own session, gets the same tiles
    count = window.eval_count
    assert window.open_project(project, ask=False)
    again = wait_eval(window, count)
    assert np.array(again.output("g").tiling.tiles).tobytes() == regrown.tobytes()
    assert not prompter.errors
