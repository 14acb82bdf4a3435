"""File › Export Mesh runs off the GUI thread with progress and cancel, and never leaves a partial file.

Counts and bytes, never wall time: GUI-thread heartbeats while an export is
held in its worker, progress reports, the files in the folder after a
cancel, and the exported bytes against `mesoforge eval --out`.
"""

from __future__ import annotations

import threading

import pytest

import engine.geometry.mesh_io as mesh_io
import ui.export_task as export_task
from app.cli import main as cli_main

from heartbeat import Heartbeat

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")  # NodeGraphQt uses distutils versions

HEARTBEATS_WHILE_EXPORTING = 5


@pytest.fixture
def tiled(window, strut_graph, wait_eval):
    ids = strut_graph(window.undo)
    assert wait_eval(window, 0).ok
    window.act_tiling.setChecked(True)
    window.ids = ids
    return window


def test_export_reports_progress_and_writes_what_the_cli_writes(tiled, tmp_path):
    window = tiled
    project = tmp_path / "struts.json"
    assert window.save_as(project)
    out = tmp_path / "block.stl"
    assert window.export_mesh(out), window.prompter.errors
    exporter = window.mesh_export()
    assert exporter.outcome == "done" and exporter.progress_seen >= 2
    assert not exporter.box.isVisible()                         # the progress bar goes when it is done
    cli_out = tmp_path / "cli.stl"
    assert cli_main(["eval", str(project), "--out", str(cli_out), "--tile", "3", "3", "3",
                     "--node", window.ids["obj"]]) == 0
    assert out.read_bytes() == cli_out.read_bytes()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]   # no temporary file left


def _held(monkeypatch, module, name, gate, started):
    """Replace module.name by a call that signals `started`, then waits for `gate`."""
    real = getattr(module, name)

    def held(*args, **kwargs):
        if name == "mesh_arrays":                               # hold inside the meshing, at its first report
            progress = kwargs["progress"]

            def report(done, total):
                started.set()
                assert gate.wait(60), "the export was never cancelled"
                return progress(done, total)
            kwargs["progress"] = report
            return real(*args, **kwargs)
        result = real(*args, **kwargs)                          # the temporary file is complete here
        started.set()
        assert gate.wait(60), "the export was never cancelled"
        return result

    monkeypatch.setattr(module, name, held)


@pytest.mark.parametrize("stage", ["meshing", "writing"])
def test_cancelled_export_leaves_no_file_and_the_old_one_untouched(tiled, tmp_path, qtbot, monkeypatch, stage):
    window = tiled
    folder = tmp_path / "out"
    folder.mkdir()
    old = folder / "block.obj"
    old.write_bytes(b"the previous export")
    gate, started = threading.Event(), threading.Event()
    if stage == "meshing":
        _held(monkeypatch, export_task, "mesh_arrays", gate, started)
    else:
        _held(monkeypatch, mesh_io, "export_mesh", gate, started)
    window.prompter.save_answer = str(old)
    beat = Heartbeat()
    try:
        window.act_export.trigger()                             # the menu: returns while the export runs
        exporter = window.mesh_export()
        assert exporter.busy and exporter.box.isVisible()
        qtbot.waitUntil(started.is_set, timeout=30000)
        start = beat.ticks
        qtbot.waitUntil(lambda: beat.ticks - start >= HEARTBEATS_WHILE_EXPORTING, timeout=30000)
        assert exporter.busy                                    # held in its worker, the GUI ticked N times
        assert not window.export_mesh(folder / "other.stl")     # one export at a time, refused with a reason
        assert "another export" in window.prompter.errors[-1][1]
        exporter.cancel_button.click()
        gate.set()
        assert not exporter.wait()
    finally:
        gate.set()
        beat.stop()
    assert exporter.outcome == "cancelled"
    assert old.read_bytes() == b"the previous export"
    assert [p.name for p in folder.iterdir()] == ["block.obj"]   # no temporary file left
    assert any("cancelled" in text for _level, text in window.log_lines)


def test_bad_export_is_refused_before_anything_is_written(tiled, tmp_path):
    window = tiled
    missing = tmp_path / "no_such_folder" / "block.stl"
    assert not window.export_mesh(missing)
    assert "does not exist" in window.prompter.errors[-1][1]
    assert not missing.parent.exists()
    assert not window.export_mesh(tmp_path / "block.xyz")
    assert ".stl" in window.prompter.errors[-1][1]
    assert window.mesh_export().outcome is None                 # nothing was started
    assert not [p for p in tmp_path.rglob("*") if p.suffix in (".stl", ".xyz", ".tmp") or p.name.startswith(".")]
