"""`mesoforge homogenize PROJECT.json` is the Material Matrix node, and
`mesoforge homogenize GRID` (.npy .vti .png or a mesh) the Voxel Import ->
Material Matrix nodes: the CLI's numbers are the Stiffness a window-built
document gives, bit for bit."""

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


# -- a grid, an image or a mesh: Voxel Import -> Material Matrix ---------------------------------
def _npy(path):
    grid = np.zeros((6, 6, 6))
    grid[:, 2:4, :] = 1.0
    grid[2:4, :, :] = 1.0
    grid[:, :, 2:4] = 0.5            # a density between solid and void stays a density
    np.save(path, grid)


def _vti(path):
    import pyvista as pv

    grid = np.zeros((5, 5, 5))
    grid[1:3, :, :] = 1.0
    grid[:, 1:3, :] = 1.0
    grid[:, :, 1:3] = 1.0
    image = pv.ImageData(dimensions=(6, 6, 6))
    image.cell_data["rho"] = grid.ravel(order="F")
    image.save(path)


def _png(path):
    from PIL import Image

    image = np.full((12, 16), 255, np.uint8)
    image[:, 3:6] = 0
    image[5:8, :] = 40
    Image.fromarray(image).save(path)


def _stl(path):
    import trimesh

    trimesh.creation.annulus(r_min=0.2, r_max=0.45, height=1.0, sections=20).export(path)


FILE_KINDS = {"npy": (_npy, ["--E", 2.0, "--nu", 0.3], {"E": 2.0, "nu": 0.3}, "voxels"),
              "vti": (_vti, [], {}, "voxels"),
              "png": (_png, ["--nu", 0.2], {"nu": 0.2}, "pixels"),
              "stl": (_stl, ["--res", 9], {"res": 9}, "voxels")}


def import_document(path, params: dict, resolution: int = 0):
    """Voxel Import -> Material Matrix, by the commands the window pushes."""
    doc = GraphDocument(seed=0)
    undo = UndoStack(doc)
    imp = undo.push(AddNode("VoxelImport", {}, (0, 0))).node_id
    undo.push(SetParam(imp, "path", str(path)))
    for name, value in params.items():
        undo.push(SetParam(imp, name, value))
    mm = undo.push(AddNode("MaterialMatrix", {"resolution": resolution}, (240, 0))).node_id
    undo.push(Connect(imp, "voxels", mm, "voxels"))
    return doc, imp, mm


@pytest.mark.parametrize("kind", sorted(FILE_KINDS))
def test_file_cli_numbers_are_the_voxel_import_material_matrix_nodes(tmp_path, capsys, kind):
    write, argv, params, grid_kind = FILE_KINDS[kind]
    path = tmp_path / f"cell.{kind}"
    write(path)
    code, out, err = homogenize(capsys, path, *argv, "--json")
    assert code == 0, err
    out = json.loads(out)

    doc, imp, mm = import_document(path, params)
    report = Evaluator().evaluate(doc)
    assert report.ok, report.errors
    st = report.outputs[mm]["stiffness"]
    assert_same_numbers(out, st)
    voxels = report.outputs[imp]["voxels"]
    assert out["kind"] == voxels.kind == grid_kind
    assert out["shape"] == list(voxels.density.shape) == list(st.grid_shape or (st.resolution,) * 3)
    assert json.loads(json.dumps(voxels.info, default=float)) == out["source"]
    if grid_kind == "pixels":
        from engine.physics.material_sphere import material_polar

        theta, e_theta = material_polar(st.C, n=72)
        assert out["polar"]["E"] == e_theta.tolist() and st.C.shape == (3, 3)


def test_file_flags_are_the_voxel_import_nodes(tmp_path, capsys):
    from engine.nodes.solids import VoxelNode
    from engine.nodes.voxel_import import VoxelImportNode

    for name in ("E", "nu", "rho"):
        assert VoxelImportNode.param(name) is VoxelNode.param(name)        # one schema for the material
    res = VoxelImportNode.param("res")
    path = tmp_path / "ring.stl"
    _stl(path)
    code, _, err = homogenize(capsys, path, "--res", res.maximum + 1)
    assert code == 2 and f"--res {res.maximum + 1}" in err and f"{res.maximum}" in err
    grid = tmp_path / "cell.npy"
    _npy(grid)
    code, _, err = homogenize(capsys, grid, "--res", 6)
    assert code == 2 and "--res 6" in err and "mesh" in err
    code, _, err = homogenize(capsys, grid, "--resolution", 6)
    assert code == 2 and "--resolution 6" in err and ".json" in err


def test_an_unreadable_file_is_refused_as_input(tmp_path, capsys):
    import trimesh

    path = tmp_path / "open.stl"
    box = trimesh.creation.box()
    box.faces = box.faces[:-1]
    box.export(path)
    code, out, err = homogenize(capsys, path, "--res", 8)
    assert code == 2 and not out
    (line,) = err.strip().splitlines()
    assert line.startswith(f"mesoforge homogenize: INPUT {path}: mesh open.stl is not watertight")
