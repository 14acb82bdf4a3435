"""`mesoforge eval --out` writes the bytes the window's export writes for the same graph."""

from __future__ import annotations

from app import cli
from engine.geometry.mesh_io import export_mesh
from engine.graph import Evaluator, load_project, save_project
from engine.tiled_mesh import tiled_arrays

from .graphs import straight_beam_graph


def test_eval_export_equals_the_evaluated_node_exported_as_the_window_does(tmp_path, capsys):
    project = tmp_path / "beam.json"
    save_project(straight_beam_graph(diameter=0.25, resolution=40), project)
    by_cli = tmp_path / "cli.stl"
    assert cli.main(["eval", str(project), "--out", str(by_cli), "--tile", "2", "1", "3"]) == 0
    # the window: the document evaluated by the Evaluator, the Object's solid tiled and exported
    report = Evaluator().evaluate(load_project(project))
    solid = report.output("obj1", "solid")
    v, f = tiled_arrays(solid, (2, 1, 3))
    by_window = tmp_path / "window.stl"
    export_mesh(v, f, by_window)
    assert by_cli.read_bytes() == by_window.read_bytes()
