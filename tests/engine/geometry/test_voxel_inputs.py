"""Readers for `mesoforge homogenize`: array, image, VTK and mesh inputs,
voxelization against analytic volumes and an implicit torus, the density
checks and the memory guard, each refusal by its message."""

import numpy as np
import pytest
import pyvista as pv
import trimesh
from PIL import Image

from engine.progress import Cancelled
from engine.geometry.mesh_io import export_mesh
from engine.geometry.voxel_inputs import (
    GridTooLarge, available_memory_bytes, check_memory, load_voxel_grid, memory_estimate_bytes,
    validate_density, voxelize_mesh)


def centres(bounds, res):
    lo, hi = np.asarray(bounds[0], float), np.asarray(bounds[1], float)
    h = (hi - lo) / res
    axes = [lo[a] + (np.arange(res) + 0.5) * h[a] for a in range(3)]
    return np.meshgrid(*axes, indexing="ij")


# --------------------------------------------------------------------- .npy

def test_npy_round_trip_voxels_and_pixels(tmp_path):
    rng = np.random.default_rng(0)
    vox = rng.random((5, 6, 7))
    np.save(tmp_path / "v.npy", vox)
    grid, kind, info = load_voxel_grid(tmp_path / "v.npy")
    assert kind == "voxels" and grid.dtype == np.float64 and np.array_equal(grid, vox)
    assert info["shape"] == (5, 6, 7) and info["volume_fraction"] == pytest.approx(vox.mean())
    pix = rng.random((4, 9)) > 0.5
    with open(tmp_path / "p.NPY", "wb") as fh:  # np.save would append ".npy"
        np.save(fh, pix)
    grid, kind, _ = load_voxel_grid(tmp_path / "p.NPY")
    assert kind == "pixels" and np.array_equal(grid, pix.astype(float))
    grid, _, info = load_voxel_grid(tmp_path / "p.NPY", invert=True)
    assert np.array_equal(grid, 1.0 - pix) and info["inverted"] is True
    np.save(tmp_path / "u8.npy", pix.astype(np.uint8))
    assert np.array_equal(load_voxel_grid(tmp_path / "u8.npy")[0], pix.astype(float))
    assert load_voxel_grid(tmp_path / "v.npy", res=None)[0].shape == (5, 6, 7)


@pytest.mark.parametrize("array,kw,words", [
    (np.ones(5), {}, ["2D (pixels) or 3D (voxels)", "ndim 1"]),
    (np.ones((2, 2, 2, 2)), {}, ["ndim 4"]),
    (np.ones((3, 3), dtype=complex), {}, ["dtype complex128"]),
    (np.array([[0.5, np.nan], [1.0, 0.0]]), {}, ["NaN at index (0, 1)"]),
    (np.array([[0.0, 255.0], [1.0, 0.0]]), {}, ["[0, 1]", "min 0", "max 255"]),
    (np.array([[0.0, -0.5], [1.0, 0.0]]), {}, ["min -0.5", "max 1"]),
    (np.zeros((4, 4, 4)), {}, ["empty", "64 cells"]),
    (np.ones((4, 4, 4)), {"invert": True}, ["empty"]),
    (np.ones((4, 4, 4)), {"res": 8}, ["res=8", "(4, 4, 4)", "not resampled"]),
    (np.ones((4, 4, 4)), {"res": 1}, ["res", "[2, 2048]", "1"]),
    (np.ones((4, 4, 4)), {"array": "rho"}, ["array", ".vti"]),
    (np.ones((4, 4, 4)), {"bounds": ((0, 0, 0), (1, 1, 1))}, ["bounds", "meshes"]),
])
def test_npy_refusals(tmp_path, array, kw, words):
    np.save(tmp_path / "a.npy", array)
    with pytest.raises(ValueError) as err:
        load_voxel_grid(tmp_path / "a.npy", **kw)
    for w in words:
        assert w in str(err.value)


def test_pickled_npy_refused(tmp_path):
    np.save(tmp_path / "o.npy", np.array([{"a": 1}], dtype=object), allow_pickle=True)
    with pytest.raises(ValueError, match="could not read o.npy"):
        load_voxel_grid(tmp_path / "o.npy")


@pytest.mark.parametrize("name,words", [
    ("grid.tif", ["must end in one of", ".npy", "grid.tif"]),
    ("missing.npy", ["existing file", "missing.npy"]),
])
def test_path_refusals(tmp_path, name, words):
    (tmp_path / "grid.tif").write_bytes(b"x")
    with pytest.raises(ValueError) as err:
        load_voxel_grid(tmp_path / name)
    for w in words:
        assert w in str(err.value)


# --------------------------------------------------------------------- .png

def drawn_pattern():
    """White 12 x 20 page with a black block in the top-left corner and a
    dark-grey bar along the bottom row."""
    img = np.full((12, 20, 3), 255, dtype=np.uint8)
    img[:4, :6] = 0
    img[11, :] = 90
    solid = np.zeros((12, 20))
    solid[:4, :6] = 1
    solid[11, :] = 1
    return img, solid


def test_png_pattern_rows_top_to_bottom(tmp_path):
    img, solid = drawn_pattern()
    Image.fromarray(img).save(tmp_path / "a.png")
    grid, kind, info = load_voxel_grid(tmp_path / "a.png")
    assert kind == "pixels" and grid.shape == (12, 20)
    assert np.array_equal(grid, solid)
    assert grid[0, 0] == 1 and grid[0, -1] == 0  # row 0 is the top of the picture
    assert info["solid_rule"] == "luminance < 0.5"
    inv, _, _ = load_voxel_grid(tmp_path / "a.png", invert=True)
    assert np.array_equal(inv, 1 - solid)


def test_png_modes(tmp_path):
    img, solid = drawn_pattern()
    Image.fromarray(img).convert("L").save(tmp_path / "l.png")
    Image.fromarray(img).convert("P").save(tmp_path / "p.png")
    Image.fromarray((img[..., 0].astype(np.uint16) * 257)).save(tmp_path / "i16.png")
    rgba = np.dstack([img, np.full(img.shape[:2], 255, np.uint8)])
    rgba[0, 0, 3] = 0  # transparent black reads as white paper
    Image.fromarray(rgba, "RGBA").save(tmp_path / "rgba.png")
    for name in ("l.png", "p.png", "i16.png"):
        assert np.array_equal(load_voxel_grid(tmp_path / name)[0], solid), name
    expect = solid.copy()
    expect[0, 0] = 0
    assert np.array_equal(load_voxel_grid(tmp_path / "rgba.png")[0], expect)


def test_png_refusals(tmp_path):
    (tmp_path / "bad.png").write_bytes(b"not a png")
    with pytest.raises(ValueError, match="could not read bad.png"):
        load_voxel_grid(tmp_path / "bad.png")
    Image.fromarray(np.full((5, 5), 255, np.uint8)).save(tmp_path / "white.png")
    with pytest.raises(ValueError, match="empty"):
        load_voxel_grid(tmp_path / "white.png")


# --------------------------------------------------------------------- .vti

def test_vti_cell_and_point_data(tmp_path):
    rng = np.random.default_rng(1)
    a = rng.random((4, 5, 6))  # [x, y, z]
    img = pv.ImageData(dimensions=(5, 6, 7))
    img.cell_data["rho"] = a.ravel(order="F")
    img.cell_data["other"] = np.zeros(a.size)
    img.save(tmp_path / "c.vti")
    grid, kind, info = load_voxel_grid(tmp_path / "c.vti")
    assert kind == "voxels" and np.allclose(grid, a)
    assert info["association"] == "cell" and info["array"] == "rho"
    with pytest.raises(ValueError, match="empty"):
        load_voxel_grid(tmp_path / "c.vti", array="other")
    pts = pv.ImageData(dimensions=a.shape, spacing=(0.1, 0.1, 0.1))
    pts.point_data["density"] = a.ravel(order="F")
    pts.save(tmp_path / "p.vti")
    grid, kind, info = load_voxel_grid(tmp_path / "p.vti")
    assert np.allclose(grid, a) and info["association"] == "point"
    assert info["spacing"] == pytest.approx((0.1, 0.1, 0.1))


def test_vti_two_d_is_flipped_to_image_rows(tmp_path):
    a = np.zeros((6, 4))  # [x, y]
    a[0, 0] = 1  # bottom-left in VTK's y-up frame
    a[5, 3] = 0.5  # top-right
    img = pv.ImageData(dimensions=(7, 5, 1))
    img.cell_data["rho"] = a.ravel(order="F")
    img.save(tmp_path / "flat.vti")
    grid, kind, _ = load_voxel_grid(tmp_path / "flat.vti")
    assert kind == "pixels" and grid.shape == (4, 6)
    assert grid[3, 0] == 1 and grid[0, 5] == 0.5 and grid.sum() == 1.5


def test_vti_refusals(tmp_path):
    img = pv.ImageData(dimensions=(3, 3, 3))
    img.save(tmp_path / "none.vti")
    with pytest.raises(ValueError, match="no point or cell arrays"):
        load_voxel_grid(tmp_path / "none.vti")
    img.cell_data["vec"] = np.ones((8, 3))
    img.save(tmp_path / "vec.vti")
    with pytest.raises(ValueError, match="3 components"):
        load_voxel_grid(tmp_path / "vec.vti")
    with pytest.raises(ValueError, match="'rho' is not in the image"):
        load_voxel_grid(tmp_path / "vec.vti", array="rho")


# -------------------------------------------------------------------- meshes

@pytest.mark.parametrize("suffix", [".stl", ".obj", ".ply", ".3mf"])
def test_sphere_volume_fraction(tmp_path, suffix):
    s = trimesh.creation.icosphere(subdivisions=4, radius=0.5)
    export_mesh(s.vertices, s.faces, tmp_path / f"s{suffix}")
    grid, kind, info = load_voxel_grid(tmp_path / f"s{suffix}", res=64)
    assert kind == "voxels" and grid.shape == (64, 64, 64)
    assert set(np.unique(grid)) == {0.0, 1.0}
    assert grid.mean() == pytest.approx(np.pi / 6, rel=0.02)
    assert info["mesh_volume_fraction"] == pytest.approx(np.pi / 6, rel=0.02)
    assert info["voxel_size"] == pytest.approx((1 / 64,) * 3, rel=1e-3)


def test_cube_in_a_given_cell(tmp_path):
    cube = trimesh.creation.box(extents=(0.5, 0.5, 0.5))
    cube.apply_translation((0.45, 0.5, 0.55))
    export_mesh(cube.vertices, cube.faces, tmp_path / "c.stl")
    grid, _, _ = load_voxel_grid(tmp_path / "c.stl", res=64, bounds=((0, 0, 0), (1, 1, 1)))
    assert grid.mean() == pytest.approx(0.125, rel=0.02)
    # a box with sides that are not whole voxels: exactly the centres inside
    ext, mid = np.array([0.5, 0.3, 0.7]), np.array([0.5, 0.5, 0.5])
    box = trimesh.creation.box(extents=ext)
    box.apply_translation(mid)
    export_mesh(box.vertices, box.faces, tmp_path / "b.stl")
    grid, _, info = load_voxel_grid(tmp_path / "b.stl", res=64, bounds=((0, 0, 0), (1, 1, 1)))
    c = (np.arange(64) + 0.5) / 64
    expect = np.prod([np.count_nonzero(np.abs(c - m) < e / 2) for m, e in zip(mid, ext)])
    assert grid.sum() == expect
    assert info["mesh_volume_fraction"] == pytest.approx(0.5 * 0.3 * 0.7)
    # without bounds the box is its own cell: all solid
    assert load_voxel_grid(tmp_path / "b.stl", res=8)[0].min() == 1.0


def test_default_resolution_and_box(tmp_path):
    s = trimesh.creation.icosphere(subdivisions=3)
    export_mesh(s.vertices, s.faces, tmp_path / "s.stl")
    grid, _, info = load_voxel_grid(tmp_path / "s.stl")
    assert grid.shape == (100, 100, 100) and info["res"] == 100
    assert info["bounds"][0] == pytest.approx(tuple(s.bounds[0]))


def test_torus_matches_implicit_function():
    R, r, res = 1.0, 0.3, 40
    tor = trimesh.creation.torus(major_radius=R, minor_radius=r, major_sections=128, minor_sections=64)
    grid = voxelize_mesh(tor.vertices, tor.faces, res=res)
    x, y, z = centres(tor.bounds, res)
    d = np.sqrt((np.hypot(x, y) - R) ** 2 + z ** 2) - r
    wrong = (d < 0) != (grid > 0)
    # the faceted mesh departs from the exact torus by < 1e-3: only
    # centres that close to the surface may disagree
    assert np.all(np.abs(d[wrong]) < 1e-3)
    assert grid.mean() == pytest.approx(tor.volume / np.prod(tor.extents), rel=0.02)


def test_overlapping_shells_give_their_union():
    a = trimesh.creation.box(extents=(0.6, 1.0, 1.0))
    a.apply_translation((0.3, 0.5, 0.5))
    b = trimesh.creation.box(extents=(0.6, 1.0, 1.0))
    b.apply_translation((0.7, 0.5, 0.5))
    both = trimesh.util.concatenate([a, b])
    grid = voxelize_mesh(both.vertices, both.faces, res=20, bounds=((0, 0, 0), (1, 1, 1)))
    assert grid.mean() == 1.0  # parity would hollow out the overlap 0.4 < x < 0.6


def test_vertices_on_voxel_centres_count_once():
    # a box whose faces pass exactly through centre planes: each column of
    # centres is crossed either twice or not at all, never leaving a streak
    box = trimesh.creation.box(extents=(0.5, 0.5, 0.5))
    grid = voxelize_mesh(box.vertices, box.faces, res=4, bounds=((-1, -1, -1), (1, 1, 1)))
    assert grid.sum() == 1  # the corner centre on the top-left edges, half-open in z
    box.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 4, (0, 0, 1)))
    fine = voxelize_mesh(box.vertices, box.faces, res=8, bounds=((-1, -1, -1), (1, 1, 1)))
    assert fine[:, :, 0].sum() == 0 and fine[:, :, -1].sum() == 0


def test_inverted_orientation_is_still_solid():
    s = trimesh.creation.icosphere(subdivisions=3)
    g1 = voxelize_mesh(s.vertices, s.faces, res=24)
    g2 = voxelize_mesh(s.vertices, s.faces[:, ::-1], res=24)
    assert np.array_equal(g1, g2)


def test_non_watertight_mesh_refused(tmp_path):
    s = trimesh.creation.icosphere(subdivisions=2)
    export_mesh(s.vertices, s.faces[1:], tmp_path / "open.stl")
    with pytest.raises(ValueError) as err:
        load_voxel_grid(tmp_path / "open.stl", res=16)
    assert "not watertight" in str(err.value) and "3 edges" in str(err.value)


def test_voxelize_refusals_and_cancel():
    s = trimesh.creation.icosphere(subdivisions=2)
    with pytest.raises(ValueError, match="res must be an integer"):
        voxelize_mesh(s.vertices, s.faces, res=16.0)
    with pytest.raises(ValueError, match="positive extent"):
        voxelize_mesh(s.vertices * [1, 1, 0], s.faces, res=8)
    with pytest.raises(ValueError, match="bounds must be"):
        voxelize_mesh(s.vertices, s.faces, res=8, bounds=(0, 1))
    with pytest.raises(ValueError, match="faces must index"):
        voxelize_mesh(s.vertices, s.faces + 1000, res=8)
    calls = []
    with pytest.raises(Cancelled):
        voxelize_mesh(s.vertices, s.faces, res=8, progress=lambda d, t: calls.append(d) or False)
    assert calls == [0]
    seen = []
    g = voxelize_mesh(s.vertices, s.faces, res=8, progress=lambda d, t: seen.append((d, t)) or True)
    assert seen[-1] == (len(s.faces), len(s.faces)) and g.sum() > 0


# --------------------------------------------------------- validate_density

@pytest.mark.parametrize("grid,kw,words", [
    (np.ones(3), {}, ["ndim 1"]),
    (np.ones((0, 3)), {}, ["no cells", "(0, 3)"]),
    (np.array([["a", "b"]]), {}, ["dtype <U1"]),
    (np.array([[[0.2, 0.3], [np.nan, 1]]]), {}, ["NaN at index (0, 1, 0)", "1 NaN"]),
    (np.array([[0.2, np.inf]]), {}, ["min 0.2", "max inf"]),
    (np.array([[1.5, 0.1]]), {}, ["[0, 1]", "max 1.5"]),
    (np.zeros((3, 3)), {}, ["empty", "9 cells", "no solid"]),
    (np.ones((4, 4, 5)), {"cubic": True}, ["cubic", "(4, 4, 5)"]),
    (np.ones((4, 5)), {"cubic": True}, ["square", "(4, 5)"]),
])
def test_validate_density_messages(grid, kw, words):
    with pytest.raises(ValueError) as err:
        validate_density(grid, **kw)
    for w in words:
        assert w in str(err.value)


def test_validate_density_accepts_and_converts():
    out = validate_density(np.ones((3, 3, 3), dtype=bool), cubic=True)
    assert out.dtype == np.float64 and out.shape == (3, 3, 3)
    a = np.full((2, 3), 0.5)
    assert validate_density(a) is a


# --------------------------------------------------------------------- memory

def test_memory_estimate_formula():
    assert memory_estimate_bytes((10, 10, 10)) == 1000 * (3 * 2000 + 64)
    assert memory_estimate_bytes((10, 20)) == 200 * (2 * 2000 + 64)
    assert memory_estimate_bytes((10, 10, 10), per_dof_bytes=100, solid_fraction=0.5) == 1000 * (150 + 64)
    assert memory_estimate_bytes((200,) * 3) > memory_estimate_bytes((100,) * 3)
    for bad, word in [((10,), "shape"), ((0, 4, 4), "shape"), ("abc", "shape")]:
        with pytest.raises(ValueError, match=word):
            memory_estimate_bytes(bad)
    with pytest.raises(ValueError, match="per_dof_bytes"):
        memory_estimate_bytes((4, 4, 4), per_dof_bytes=0)
    with pytest.raises(ValueError, match="solid_fraction"):
        memory_estimate_bytes((4, 4, 4), solid_fraction=2)


def test_check_memory_refuses_with_sizes():
    need = memory_estimate_bytes((300, 300, 300))
    with pytest.raises(GridTooLarge) as err:
        check_memory((300, 300, 300), limit_bytes=8e9)
    msg = str(err.value)
    assert msg.startswith("a 300^3 grid needs about ") and f"{need / 1e9:.3g} GB" in msg
    assert "more than the 8 GB available" in msg
    assert isinstance(err.value, ValueError)
    with pytest.raises(GridTooLarge, match="a 30x40x50 grid"):
        check_memory((30, 40, 50), limit_bytes=1000)
    assert check_memory((8, 8, 8), limit_bytes=10**12) == memory_estimate_bytes((8, 8, 8))


def test_available_memory_is_known_here():
    avail = available_memory_bytes()
    assert avail is None or avail > 0
    if avail is not None:
        with pytest.raises(GridTooLarge, match="available"):
            check_memory((2000, 2000, 2000))
        check_memory((4, 4, 4))
