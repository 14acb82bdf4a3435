"""periodic_mesh and friends against closed-form volumes and trimesh's
watertightness check."""

import numpy as np
import pytest
import trimesh

from engine.geometry.marching import (boundary_section_match, mesh_volume, mesh_volume_fraction,
                                      periodic_mesh, solid_volume_fraction)
from engine.geometry.sdf_lines import line_sdf_grid


def _nodes(n):
    x = np.arange(n) / n
    return np.stack(np.meshgrid(x, x, x, indexing="ij"), axis=-1)


def _beam(n, r):
    """Periodic beam along x through the cell: closed-form SDF."""
    p = _nodes(n)
    return (np.hypot(p[..., 1] - 0.5, p[..., 2] - 0.5) - r).astype(np.float32)


def _sphere(n, r, centre=(0.5, 0.5, 0.5)):
    return (np.linalg.norm(_nodes(n) - centre, axis=-1) - r).astype(np.float32)


def test_beam_volume_fraction_and_tiled_watertight_mesh():
    r, n = 0.2, 64
    field = _beam(n, r)
    assert abs(solid_volume_fraction(field) / (np.pi * r ** 2) - 1) < 0.02
    v, f = periodic_mesh(field)
    assert abs(mesh_volume_fraction(v, f, 1.0) / (np.pi * r ** 2) - 1) < 0.02
    cs = 2.5
    v3, f3 = periodic_mesh(field, tiles=(3, 1, 1), cell_size=cs)
    mesh = trimesh.Trimesh(v3, f3)
    assert mesh.is_watertight and mesh.is_winding_consistent
    assert abs(mesh.volume / (3 * np.pi * r ** 2 * cs ** 3) - 1) < 0.02
    np.testing.assert_allclose(mesh.bounds[:, 0], [0.0, 3 * cs])
    assert v3.min() >= 0 and np.all(v3.max(axis=0) <= [3 * cs, cs, cs])
    assert v3.dtype == np.float64 and f3.dtype == np.int64


def test_sphere_volume_orientation_and_watertightness():
    r = 0.3
    v, f = periodic_mesh(_sphere(64, r))
    mesh = trimesh.Trimesh(v, f)
    assert mesh.is_watertight
    assert abs(mesh_volume(v, f) / (4 / 3 * np.pi * r ** 3) - 1) < 0.01
    outward = np.einsum("ij,ij->i", mesh.face_normals, mesh.triangles_center - 0.5)
    assert np.all(outward > 0)


def test_samples_exactly_on_the_level_still_give_a_watertight_mesh():
    field = _sphere(16, 0.25)                 # passes exactly through grid nodes
    assert np.count_nonzero(field == 0) >= 6
    v, f = periodic_mesh(field)
    assert trimesh.Trimesh(v, f).is_watertight


def test_tiled_octet_like_lattice_is_watertight_and_tiles():
    n = 32
    diag = [np.array([[0, 0, 0], [1, 1, 1]]), np.array([[1, 0, 0], [0, 1, 1]]),
            np.array([[0, 1, 0], [1, 0, 1]]), np.array([[0, 0, 1], [1, 1, 0]])]
    field = line_sdf_grid(diag, [0.08] * 4, resolution=n)
    v, f = periodic_mesh(field, tiles=(2, 2, 2))
    assert trimesh.Trimesh(v, f).is_watertight
    v1, f1 = periodic_mesh(field)
    assert boundary_section_match(v1, f1, cell_size=1.0) < 1e-9
    v2, f2 = periodic_mesh(field, closed=False, cell_size=3.0)
    assert not trimesh.Trimesh(v2, f2).is_watertight
    assert boundary_section_match(v2, f2, cell_size=3.0) < 1e-9


def test_boundary_section_match_sees_a_mismatch():
    v, f = periodic_mesh(_beam(32, 0.2))
    assert boundary_section_match(v, f, cell_size=1.0) < 1e-9
    moved = v.copy()
    on_far_face = np.abs(moved[:, 0] - 1.0) < 1e-12
    moved[on_far_face, 1] += 0.01
    assert boundary_section_match(moved, f, cell_size=1.0) == pytest.approx(0.01, abs=1e-9)
    moved[np.flatnonzero(on_far_face)[0], 0] = 0.99
    assert boundary_section_match(moved, f, cell_size=1.0) == np.inf


def test_empty_and_full_fields():
    v, f = periodic_mesh(np.ones((8, 8, 8)))
    assert v.shape == (0, 3) and f.shape == (0, 3)
    v, f = periodic_mesh(-np.ones((8, 8, 8)))          # solid everywhere: the box itself
    assert abs(mesh_volume(v, f) - 1.0) < 1e-9
    v, f = periodic_mesh(-np.ones((8, 8, 8)), closed=False)
    assert f.shape == (0, 3)


def test_level_sets_the_iso_value():
    field = _sphere(48, 0.0) + 0.0                     # distance to the centre
    v, f = periodic_mesh(field, level=0.25)
    assert abs(mesh_volume(v, f) / (4 / 3 * np.pi * 0.25 ** 3) - 1) < 0.02
    assert solid_volume_fraction(field, level=0.25) == pytest.approx(np.mean(field < 0.25))


def test_inputs_are_not_mutated():
    field = _sphere(16, 0.25)
    before = field.copy()
    periodic_mesh(field)
    np.testing.assert_array_equal(field, before)


@pytest.mark.parametrize("kwargs, match", [
    (dict(tiles=(0, 1, 1)), "tiles"),
    (dict(tiles=(1, 1)), "tiles"),
    (dict(tiles=(1.5, 1, 1)), "tiles"),
    (dict(cell_size=0.0), "cell_size"),
    (dict(level=np.nan), "level"),
])
def test_bad_options_are_refused(kwargs, match):
    with pytest.raises(ValueError, match=match):
        periodic_mesh(np.ones((4, 4, 4)), **kwargs)


def test_bad_fields_are_refused():
    with pytest.raises(ValueError, match="3-D"):
        periodic_mesh(np.ones((4, 4)))
    with pytest.raises(ValueError, match="finite"):
        solid_volume_fraction(np.full((4, 4, 4), np.nan))
    with pytest.raises(ValueError, match="cell_volume"):
        mesh_volume_fraction(np.zeros((3, 3)), np.zeros((1, 3), int), 0.0)


def test_overlapping_balls_leave_no_void_specks():
    # Two overlapping balls (radius 0.47 at the corner and the centre) with
    # concentric cavities: the concave crease used to trap single nodes and
    # mesh as zero-volume bubbles.  Every piece left must carry real volume.
    import trimesh
    from engine.geometry.csg import csg_difference
    from engine.geometry.sdf_lines import line_sdf_grid

    pts = [np.array([[0.0, 0, 0], [0.0, 0, 0]]), np.array([[0.5, 0.5, 0.5], [0.5, 0.5, 0.5]])]
    outer = line_sdf_grid(pts, [np.full(2, 0.47)] * 2, resolution=48)
    inner = line_sdf_grid(pts, [np.full(2, 0.41)] * 2, resolution=48)
    v, f = periodic_mesh(csg_difference(outer, inner))
    mesh = trimesh.Trimesh(v, f, process=False)
    assert mesh.is_watertight
    voxel = (1 / 48) ** 3
    assert all(abs(p.volume) > voxel for p in mesh.split(only_watertight=False))


def test_drop_specks_keeps_big_pieces():
    from engine.geometry.marching import drop_specks
    big = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    tet = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    small = big * 1e-3 + 5
    v = np.vstack([big, small])
    f = np.vstack([tet, tet + 4])
    v2, f2 = drop_specks(v, f, 1e-6)
    assert len(v2) == 4 and np.array_equal(f2, tet)


def test_slab_meshing_equals_one_marching_cubes_call_and_cancels():
    # The slab-wise extraction must give the same surface as one skimage call
    # on the whole padded grid (compared as sets of triangles by coordinates).
    from skimage.measure import marching_cubes
    from engine.geometry import marching
    from engine.progress import Cancelled

    rng = np.random.default_rng(5)
    field = np.asarray(rng.normal(size=(60, 20, 20)), np.float32)
    v1, f1 = marching.slab_marching_cubes(field, 0.0, None)
    v2, f2, _, _ = marching_cubes(field, level=0.0, gradient_direction="descent", allow_degenerate=True)
    from scipy.spatial import cKDTree

    def canonical(v, f):
        tri = np.asarray(v, np.float64)[f]                       # (f, 3, 3)
        order = np.lexsort(tri.transpose(2, 0, 1)[::-1], axis=1)   # corners in a fixed order
        return np.take_along_axis(tri, order[:, :, None], axis=1).reshape(-1, 9)

    assert len(f1) == len(f2) and len(v1) == len(np.unique(v2, axis=0))
    a, b = canonical(v1, f1), canonical(v2, f2)
    assert cKDTree(b).query(a)[0].max() < 1e-4 and cKDTree(a).query(b)[0].max() < 1e-4
    calls = []
    with pytest.raises(Cancelled):
        marching.periodic_mesh(field, progress=lambda d, t: calls.append(d) or d < 1)
    assert calls[-1] == 1


def test_resample_periodic_is_exact_for_linear_periodic_fields():
    # A trilinear interpolant reproduces a field that is linear between nodes;
    # cos(2 pi x) sampled finely changes little; the wrap keeps periodicity.
    from engine.geometry.resample import resample_periodic
    n = 64
    x = np.arange(n) / n
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    f = np.cos(2 * np.pi * X) + np.sin(2 * np.pi * Y) * np.cos(2 * np.pi * Z)
    g = resample_periodic(f, 48)
    x2 = np.arange(48) / 48
    X2, Y2, Z2 = np.meshgrid(x2, x2, x2, indexing="ij")
    exact = np.cos(2 * np.pi * X2) + np.sin(2 * np.pi * Y2) * np.cos(2 * np.pi * Z2)
    assert np.abs(g - exact).max() < 3 * (2 * np.pi / n) ** 2
    assert np.array_equal(resample_periodic(f, 32), f[::2, ::2, ::2].astype(np.float32))
