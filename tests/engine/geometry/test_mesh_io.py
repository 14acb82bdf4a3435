"""export_mesh / load_mesh round trips for every format, atomic writes and
mesh_summary on a cube with known volume and area."""

import os
import zipfile

import numpy as np
import pytest
import trimesh

from engine.geometry.mesh_io import SUPPORTED_SUFFIXES, export_mesh, load_mesh, mesh_summary

CUBE_V = np.array([[x, y, z] for x in (0, 2) for y in (0, 1) for z in (0, 3)], dtype=float)
# 2 x 1 x 3 box, outward-wound
CUBE_F = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                   [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])


def _sphere():
    m = trimesh.creation.icosphere(subdivisions=2, radius=0.7)
    return np.asarray(m.vertices) + 1.5, np.asarray(m.faces)


def test_summary_of_a_box():
    s = mesh_summary(CUBE_V, CUBE_F)
    assert s["vertex_count"] == 8 and s["face_count"] == 12
    assert s["watertight"] is True
    assert s["volume"] == pytest.approx(6.0)
    assert s["area"] == pytest.approx(2 * (2 * 1 + 2 * 3 + 1 * 3))
    assert s["bounds"] == ((0.0, 0.0, 0.0), (2.0, 1.0, 3.0))
    open_box = mesh_summary(CUBE_V, CUBE_F[:-1])
    assert open_box["watertight"] is False
    empty = mesh_summary(np.zeros((0, 3)), np.zeros((0, 3), int))
    assert empty["face_count"] == 0 and empty["bounds"] is None


@pytest.mark.parametrize("suffix", SUPPORTED_SUFFIXES + (".STL",))
def test_round_trip(tmp_path, suffix):
    v, f = _sphere()
    path = tmp_path / f"mesh{suffix}"
    export_mesh(v, f, path)
    v2, f2 = load_mesh(path)
    assert v2.dtype == np.float64 and f2.dtype == np.int64
    before, after = mesh_summary(v, f), mesh_summary(v2, f2)
    assert after["watertight"]
    assert after["face_count"] == before["face_count"]
    assert after["vertex_count"] == before["vertex_count"]
    assert after["volume"] == pytest.approx(before["volume"], rel=1e-5)
    assert after["area"] == pytest.approx(before["area"], rel=1e-5)
    np.testing.assert_allclose(after["bounds"], before["bounds"], atol=1e-6)
    assert [p.name for p in tmp_path.iterdir()] == [path.name]   # no temp files left


def test_3mf_package_layout(tmp_path):
    path = tmp_path / "box.3mf"
    export_mesh(CUBE_V, CUBE_F, path)
    with zipfile.ZipFile(path) as z:
        names = set(z.namelist())
        assert {"[Content_Types].xml", "_rels/.rels", "3D/3dmodel.model"} <= names
        model = z.read("3D/3dmodel.model").decode()
    assert model.count("<vertex ") == 8 and model.count("<triangle ") == 12
    pytest.importorskip("lxml")  # trimesh's own 3MF reader needs lxml
    loaded = trimesh.load(path, force="mesh")
    assert loaded.volume == pytest.approx(6.0)


def test_export_replaces_existing_file_atomically(tmp_path):
    path = tmp_path / "out.stl"
    path.write_bytes(b"old contents")
    export_mesh(CUBE_V, CUBE_F, path)
    assert mesh_summary(*load_mesh(path))["volume"] == pytest.approx(6.0)
    assert sorted(os.listdir(tmp_path)) == ["out.stl"]


def test_failed_export_leaves_no_file(tmp_path, monkeypatch):
    path = tmp_path / "out.ply"

    def disk_full(fd):
        raise OSError("disk full")

    monkeypatch.setattr(os, "fsync", disk_full)
    with pytest.raises(OSError, match="disk full"):
        export_mesh(CUBE_V, CUBE_F, path)
    assert os.listdir(tmp_path) == []


def test_unknown_suffix_lists_the_supported_ones(tmp_path):
    with pytest.raises(ValueError, match=r"\.stl, \.obj, \.ply, \.3mf.*mesh\.step"):
        export_mesh(CUBE_V, CUBE_F, tmp_path / "mesh.step")
    with pytest.raises(ValueError, match="one of"):
        load_mesh(tmp_path / "mesh.vtk")


@pytest.mark.parametrize("v, f, match", [
    (CUBE_V[:, :2], CUBE_F, "vertices"),
    (CUBE_V, CUBE_F[:0], "non-empty"),
    (CUBE_V, CUBE_F + 8, "faces must index"),
    (CUBE_V, CUBE_F.astype(float), "integer"),
])
def test_bad_meshes_are_refused(tmp_path, v, f, match):
    with pytest.raises(ValueError, match=match):
        export_mesh(v, f, tmp_path / "x.stl")


def test_load_missing_file(tmp_path):
    with pytest.raises(ValueError, match="existing file"):
        load_mesh(tmp_path / "nope.obj")
