import json
import math

import numpy as np
import pytest
import trimesh

from app import cli
from engine.graph import save_project

from .graphs import straight_beam_graph


@pytest.fixture
def beam_file(tmp_path):
    p = tmp_path / "beam.json"
    save_project(straight_beam_graph(diameter=0.2, resolution=48), p)
    return p


def test_eval_json_summary_and_tiled_export(beam_file, tmp_path, capsys):
    out = tmp_path / "cell.stl"
    code = cli.main(["eval", str(beam_file), "--out", str(out), "--tile", "3", "1", "2", "--json"])
    assert code == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["ok"] and summary["failed"] == []
    assert [n["id"] for n in summary["nodes"]] == ["v1", "v2", "e1", "l1", "obj1", "vox1"]
    assert all(n["status"] == "evaluated" and n["seconds"] >= 0 for n in summary["nodes"])
    assert summary["result_node"] == "obj1"
    m = summary["mesh"]
    assert m["watertight"] and m["tiles"] == [3, 1, 2]
    # an infinite cylinder of radius 0.1: volume fraction pi r^2 (independent closed form)
    assert m["volume_fraction"] == pytest.approx(math.pi * 0.01, rel=0.03)
    mesh = trimesh.load(out)
    assert mesh.is_watertight
    assert np.allclose(mesh.bounds[1] - mesh.bounds[0], [3.0, 0.2, 1.2], atol=0.03)  # two beams stacked in z
    assert m["vertex_count"] == len(mesh.vertices) or m["face_count"] == len(mesh.faces)


def test_eval_reports_failures_with_node_and_exit_code(tmp_path, capsys):
    doc = straight_beam_graph()
    from engine.graph import Disconnect, UndoStack
    UndoStack(doc).push(Disconnect("v2", "point", "e1", "vertices"))
    p = tmp_path / "broken.json"
    save_project(doc, p)
    assert cli.main(["eval", str(p), "--json"]) == 1
    summary = json.loads(capsys.readouterr().out)
    assert summary["failed"] == ["e1"]
    bad = next(n for n in summary["nodes"] if n["id"] == "e1")
    assert "at least two vertices" in bad["error"]
    assert {n["id"]: n["status"] for n in summary["nodes"]}["obj1"] == "blocked"


def test_bad_project_file_names_path_and_reason(tmp_path, capsys):
    p = tmp_path / "corrupt.json"
    p.write_text('{"format": "mesoforge-project", "version": 1, "nodes": [')
    assert cli.main(["eval", str(p)]) == 2
    err = capsys.readouterr().err
    assert str(p) in err and "not valid JSON" in err


def test_unknown_export_suffix_is_refused(beam_file, tmp_path, capsys):
    assert cli.main(["eval", str(beam_file), "--out", str(tmp_path / "x.xyz")]) == 2
    assert "x.xyz" in capsys.readouterr().err


def test_headless_start_renders_png_and_mesh(beam_file, tmp_path, monkeypatch, capsys):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(cli, "DEFAULT_EXAMPLE", beam_file)
    assert cli.main([]) == 0
    text = capsys.readouterr().out
    png = tmp_path / "mesoforge-out" / "beam.png"
    stl = tmp_path / "mesoforge-out" / "beam.stl"
    assert str(png) in text and str(stl) in text
    assert png.stat().st_size > 1000 and trimesh.load(stl).is_watertight
