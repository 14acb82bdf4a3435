"""Voxel Import node: a cell read from a file, keyed by the file's bytes, refused
before it is read when its solve would not fit, and homogenized as it is by the
Material Matrix node."""

import numpy as np
import pytest

from engine.geometry.voxel_inputs import SOLVER_BYTES_PER_DOF, load_voxel_grid, memory_estimate_bytes
from engine.graph import AddNode, Connect, EvalContext, Evaluator, GraphDocument, NodeInputError, UndoStack
from engine.nodes import voxel_import
from engine.geometry.values import ImportedVoxels
from engine.nodes.voxel_import import VoxelImportNode
from engine.physics.homogenize3d import homogenize_voxels


def _cross(n=6, value=1.0):
    grid = np.zeros((n, n, n))
    grid[:, 2:4, :] = value
    grid[2:4, :, :] = value
    grid[:, :, 2:4] = value
    return grid


def _document(path, resolution=0, **params):
    doc = GraphDocument(seed=0)
    undo = UndoStack(doc)
    undo.push(AddNode("VoxelImport", {"path": str(path), **params}, node_id="imp"))
    undo.push(AddNode("MaterialMatrix", {"resolution": resolution}, node_id="mat"))
    undo.push(Connect("imp", "voxels", "mat", "voxels"))
    return doc


def _params(path, **extra):
    return VoxelImportNode.validate_params({"path": str(path), **extra})


def _evaluate_alone(params):
    return VoxelImportNode().evaluate({}, params, EvalContext("imp", 0))


def test_editing_the_file_changes_the_token_and_re_evaluates(tmp_path):
    path = tmp_path / "cell.npy"
    np.save(path, _cross())
    ev = Evaluator()
    doc = _document(path)
    token = VoxelImportNode.source_token(_params(path))
    first = ev.evaluate(doc)
    assert first.ok and first.results["imp"].status == "evaluated"
    again = ev.evaluate(doc)
    assert again.results["imp"].status == again.results["mat"].status == "cached"

    np.save(path, _cross(value=0.5))                             # the same path, other bytes
    assert VoxelImportNode.source_token(_params(path)) not in ("", token)
    edited = ev.evaluate(doc)
    assert edited.results["imp"].status == edited.results["mat"].status == "evaluated"
    assert edited.output("mat").C[0, 0] < first.output("mat").C[0, 0]
    assert edited.output("imp").density.max() == 0.5


def test_the_grid_is_refused_from_its_header_before_it_is_read(tmp_path, monkeypatch):
    path = tmp_path / "big.npy"
    np.lib.format.open_memmap(path, mode="w+", dtype=np.uint8, shape=(40, 40, 40))
    need = memory_estimate_bytes((40, 40, 40), per_dof_bytes=SOLVER_BYTES_PER_DOF)
    assert VoxelImportNode.memory_estimate(_params(path)) == need
    monkeypatch.setenv("MESOFORGE_MEMORY_LIMIT", str(need - 1))

    def never(*_a, **_k):
        raise AssertionError("the grid was read despite the memory estimate")
    monkeypatch.setattr(voxel_import, "load_voxel_grid", never)
    report = Evaluator().evaluate(_document(path))
    r = report.results["imp"]
    assert r.status == "failed" and r.where == "path"
    assert "a 40^3 grid needs about" in r.error
    assert report.results["mat"].status == "blocked"


def test_a_mesh_too_fine_names_res(tmp_path, monkeypatch):
    import trimesh

    path = tmp_path / "box.stl"
    trimesh.creation.box().export(path)
    params = _params(path, res=300)
    assert VoxelImportNode.grid_shape(params) == (300, 300, 300)
    monkeypatch.setenv("MESOFORGE_MEMORY_LIMIT", "10M")
    monkeypatch.setattr(voxel_import, "load_voxel_grid", lambda *a, **k: pytest.fail("voxelized"))
    r = Evaluator().evaluate(_document(path, res=300)).results["imp"]
    assert r.status == "failed" and r.where == "res" and "300^3" in r.error


@pytest.mark.parametrize("name, content, message", [
    ("missing.npy", None, "existing file"),
    ("cell.xyz", b"", "must end in one of"),
    ("nan.npy", np.full((3, 3, 3), np.nan), "NaN"),
    ("box.npy", np.ones((3, 3, 4)), "cubic"),
    ("text.png", b"not an image", "PNG"),
])
def test_a_bad_file_is_a_node_input_error_on_path(tmp_path, name, content, message):
    path = tmp_path / name
    if isinstance(content, bytes):
        path.write_bytes(content)
    elif content is not None:
        np.save(path, content)
    with pytest.raises(NodeInputError, match=message) as info:
        _evaluate_alone(_params(path))
    assert info.value.where == "path"
    r = Evaluator().evaluate(_document(path)).results["imp"]
    assert r.status == "failed" and r.where == "path" and message in r.error


def test_no_path_and_a_misplaced_array_are_refused():
    with pytest.raises(NodeInputError, match="no file") as info:
        _evaluate_alone(VoxelImportNode.validate_params({}))
    assert info.value.where == "path"
    with pytest.raises(NodeInputError, match=".vti files only") as info:
        _evaluate_alone(_params("cell.npy", array="rho"))
    assert info.value.where == "array"


def test_the_density_is_homogenized_as_it_was_read(tmp_path):
    path = tmp_path / "cell.npy"
    grid = _cross()
    grid[0, 0, 0] = 0.25
    np.save(path, 1.0 - grid)                                    # read inverted: the cross again
    report = Evaluator().evaluate(_document(path, E=3.0, nu=0.2, invert=True))
    assert report.ok, report.errors
    vox = report.output("imp")
    expected, kind, _ = load_voxel_grid(path, invert=True)
    assert isinstance(vox, ImportedVoxels) and kind == vox.kind == "voxels"
    assert np.array_equal(expected, grid)
    assert vox.density.tobytes() == expected.tobytes() and not vox.density.flags.writeable
    assert np.array_equal(vox.occupancy, expected >= 0.5)
    direct = homogenize_voxels(expected, E=3.0, nu=0.2)
    assert report.output("mat").C.tobytes() == np.asarray(direct.C).tobytes()


def test_pixels_give_a_plane_stress_c_and_an_xyz_slab(tmp_path):
    from PIL import Image

    image = np.full((4, 6), 255, np.uint8)
    image[0, :] = 0                                              # the top row is solid
    image[:, 1] = 0
    path = tmp_path / "cell.png"
    Image.fromarray(image).save(path)
    report = Evaluator().evaluate(_document(path))
    assert report.ok, report.errors
    vox, st = report.output("imp"), report.output("mat")
    assert vox.kind == "pixels" and vox.density.shape == (4, 6) and vox.occupancy.shape == (6, 4, 1)
    assert vox.occupancy[:, 3, 0].all() and vox.occupancy[1, :, 0].all()     # y grows upwards
    assert vox.solid.cell == pytest.approx((1.0, 4 / 6, 1 / 6))
    assert st.C.shape == (3, 3) and st.grid_shape == (4, 6) and st.resolution == 6


def test_material_matrix_solves_an_imported_grid_only_as_it_is(tmp_path):
    path = tmp_path / "cell.npy"
    np.save(path, _cross())
    same = Evaluator().evaluate(_document(path, resolution=6))
    assert same.ok and same.output("mat").C.tobytes() == \
        Evaluator().evaluate(_document(path)).output("mat").C.tobytes()
    r = Evaluator().evaluate(_document(path, resolution=64)).results["mat"]
    assert r.status == "failed" and r.where == "resolution" and "set resolution to 0" in r.error


def test_material_matrix_estimate_follows_the_imported_grid(tmp_path):
    from engine.graph import node_type

    path = tmp_path / "cell.npy"
    np.save(path, _cross())
    vox = Evaluator().evaluate(_document(path)).output("imp")
    cls = node_type("MaterialMatrix")
    assert cls.memory_estimate(cls.validate_params({"resolution": 0}), {"voxels": vox}) == \
        memory_estimate_bytes((6, 6, 6), per_dof_bytes=SOLVER_BYTES_PER_DOF)
