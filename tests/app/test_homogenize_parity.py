"""`mesoforge homogenize PROJECT.json` is the Material Matrix node: the CLI's
numbers are the Stiffness a window-built document gives, bit for bit."""

from __future__ import annotations

import json

import numpy as np
import pytest

from app import cli
from engine.graph import AddNode, Connect, Evaluator, GraphDocument, SetParam, UndoStack, node_type, save_project


def cross_project(seed: int = 5) -> tuple[GraphDocument, UndoStack, dict]:
    """A beam along x and its two copies about the body diagonal (three
    orthogonal beams: a non-singular cubic C) -> Object (16) -> Voxel, built by
    the commands the window pushes."""
    doc = GraphDocument(seed=seed)
    undo = UndoStack(doc)
    ids = {}
    ids["v1"] = undo.push(AddNode("Vertex", {"position": [0.0, 0.5, 0.5]}, (0, 0))).node_id
    ids["v2"] = undo.push(AddNode("Vertex", {"position": [1.0, 0.5, 0.5]}, (0, 160))).node_id
    ids["e"] = undo.push(AddNode("EdgeChain", {}, (240, 80))).node_id
    undo.push(Connect(ids["v1"], "point", ids["e"], "vertices"))
    undo.push(Connect(ids["v2"], "point", ids["e"], "vertices"))
    ids["l"] = undo.push(AddNode("Line", {"thickness": [[0.0, 0.3], [1.0, 0.3]]}, (480, 80))).node_id
    undo.push(Connect(ids["e"], "chain", ids["l"], "chains"))
    ids["t1"] = undo.push(AddNode("Transform", {"rotation_angle": 120.0, "rotation_axis": [1, 1, 1]})).node_id
    ids["t2"] = undo.push(AddNode("Transform", {"rotation_angle": 240.0, "rotation_axis": [1, 1, 1]})).node_id
    undo.push(Connect(ids["l"], "skeleton", ids["t1"], "skeleton"))
    undo.push(Connect(ids["t1"], "skeleton", ids["t2"], "skeleton"))
    ids["obj"] = undo.push(AddNode("Object", {"resolution": 16})).node_id
    undo.push(Connect(ids["t2"], "skeleton", ids["obj"], "skeleton"))
    ids["vox"] = undo.push(AddNode("Voxel", {})).node_id
    undo.push(Connect(ids["obj"], "solid", ids["vox"], "solid"))
    return doc, undo, ids


def homogenize(capsys, *argv):
    code = cli.main(["homogenize", *map(str, argv)])
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def node_stiffness(doc: GraphDocument, mm: str):
    report = Evaluator().evaluate(doc)
    assert report.ok, report.errors
    return report.outputs[mm]["stiffness"]


def assert_same_numbers(out: dict, st) -> None:
    C = np.asarray(out["C"], dtype=np.float64)
    assert C.tobytes() == np.asarray(st.C, dtype=np.float64).tobytes()          # bit for bit
    assert out["constants"] == st.constants and out["constants"]
    assert np.asarray(out["S"]).tobytes() == np.linalg.inv(st.C).tobytes()
    assert (out["density"], out["dropped_fraction"], out["iterations"]) == (
        st.density, st.dropped_fraction, st.iterations)
    assert (out["symmetry"], out["zener"], out["E"], out["nu"]) == (st.symmetry, st.zener, st.E, st.nu)


def test_cli_numbers_are_the_material_matrix_nodes_bit_for_bit(tmp_path, capsys):
    project, _, _ = cross_project()
    path = tmp_path / "cross.json"
    save_project(project, path)
    code, out, err = homogenize(capsys, path, "--E", 2.5, "--nu", 0.3, "--resolution", 10, "--json")
    assert code == 0, err
    out = json.loads(out)

    doc, undo, ids = cross_project()                        # as the window builds it
    undo.push(SetParam(ids["vox"], "E", 2.5))
    undo.push(SetParam(ids["vox"], "nu", 0.3))
    mm = undo.push(AddNode("MaterialMatrix", {"resolution": 10})).node_id
    undo.push(Connect(ids["vox"], "voxels", mm, "voxels"))
    st = node_stiffness(doc, mm)
    assert_same_numbers(out, st)
    assert out["kind"] == "project" and out["shape"] == [10, 10, 10] and st.symmetry == "cubic"


def test_a_projects_own_material_matrix_and_material_are_used(tmp_path, capsys):
    doc, undo, ids = cross_project(seed=9)
    undo.push(SetParam(ids["vox"], "E", 7.0))
    mm = undo.push(AddNode("MaterialMatrix", {"resolution": 8})).node_id
    undo.push(Connect(ids["vox"], "voxels", mm, "voxels"))
    path = tmp_path / "own.json"
    save_project(doc, path)
    code, out, err = homogenize(capsys, path, "--json")       # no flags: the project's values
    assert code == 0, err
    out = json.loads(out)
    assert out["node"] == mm and out["E"] == 7.0 and out["shape"] == [8, 8, 8]
    assert_same_numbers(out, node_stiffness(doc, mm))


def test_project_flags_are_checked_by_the_node_schemas(tmp_path, capsys):
    project, _, _ = cross_project()
    path = tmp_path / "cross.json"
    save_project(project, path)
    top = node_type("MaterialMatrix").param("resolution").maximum
    code, _, err = homogenize(capsys, path, "--resolution", top + 1)
    assert code == 2 and f"--resolution {top + 1}" in err and f"{top}" in err and len(err.strip().splitlines()) == 1
    code, _, err = homogenize(capsys, path, "--nu", 0.5)
    assert code == 2 and "--nu 0.5" in err
    code, _, err = homogenize(capsys, path, "--res", 20)
    assert code == 2 and "--res" in err and "mesh" in err


def test_project_without_a_voxel_node_is_refused(tmp_path, capsys):
    doc = GraphDocument()
    UndoStack(doc).push(AddNode("Vertex", {}))
    path = tmp_path / "novox.json"
    save_project(doc, path)
    code, out, err = homogenize(capsys, path)
    assert code == 2 and "INPUT" in err and "Voxel" in err and not out


def test_help_shows_the_schema_ranges_and_units(capsys):
    with pytest.raises(SystemExit):
        cli.build_parser().parse_args(["homogenize", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    p = node_type("MaterialMatrix").param("resolution")
    assert f"default: {p.default} {p.unit}" in text
    for name in ("E", "nu"):
        q = node_type("Voxel").param(name)
        assert f"default: {q.default}{' ' + q.unit if q.unit else ''}" in text
