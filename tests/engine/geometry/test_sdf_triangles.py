"""surface_sdf_grid against closed forms (flat square -> box / rounded slab)
and a brute-force dense sampling of a bent surface."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from engine.geometry.marching import mesh_volume, periodic_mesh
from engine.geometry.sdf_triangles import boundary_flags, surface_sdf_grid

SQUARE_V = np.array([(0.2, 0.2, 0.5), (0.8, 0.2, 0.5), (0.8, 0.8, 0.5), (0.2, 0.8, 0.5)])
SQUARE_F = np.array([[0, 1, 2], [0, 2, 3]])


def _nodes(n):
    x = np.arange(n) / n
    return np.stack(np.meshgrid(x, x, x, indexing="ij"), axis=-1)


def _box_sdf(p, lo, hi):
    c, h = (lo + hi) / 2, (hi - lo) / 2
    q = np.abs(p - c) - h
    return np.linalg.norm(np.maximum(q, 0), axis=-1) + np.minimum(q.max(-1), 0)


def _check(field, exact, band):
    exact = np.minimum(exact, band)
    near = np.abs(exact) < band
    np.testing.assert_allclose(field[near], exact[near], atol=1e-6)
    clear = np.abs(exact) > 1e-6
    assert np.array_equal(field[clear] < 0, exact[clear] < 0)


@pytest.mark.parametrize("periodic", [True, False])
def test_flat_square_normal_is_a_box(periodic):
    n, t = 40, 0.1
    field = surface_sdf_grid(SQUARE_V, SQUARE_F, np.full(4, t), resolution=n, method="normal",
                             periodic=periodic)
    exact = _box_sdf(_nodes(n), np.array([0.2, 0.2, 0.45]), np.array([0.8, 0.8, 0.55]))
    _check(field, exact, 3 / n)


def test_flat_square_spherical_is_a_rounded_slab():
    n, t = 40, 0.1
    field = surface_sdf_grid(SQUARE_V, SQUARE_F, np.full(4, t), resolution=n)
    p = _nodes(n)
    dist_to_square = _box_sdf(p, np.array([0.2, 0.2, 0.5]), np.array([0.8, 0.8, 0.5]))
    _check(field, dist_to_square - t / 2, 3 / n)


def test_normal_box_mesh_volume():
    n, t = 64, 0.1
    field = surface_sdf_grid(SQUARE_V, SQUARE_F, np.full(4, t), resolution=n, method="normal")
    verts, faces = periodic_mesh(field)
    assert abs(mesh_volume(verts, faces) / (0.6 * 0.6 * t) - 1) < 0.02


def test_linearly_varying_thickness_above_the_surface():
    n = 40
    thick = 0.04 + 0.1 * SQUARE_V[:, 0]             # linear in x, so exact on both triangles
    field = surface_sdf_grid(SQUARE_V, SQUARE_F, thick, resolution=n, method="normal")
    p = _nodes(n)
    x, z = p[..., 0], p[..., 2]
    expected = np.abs(z - 0.5) - (0.04 + 0.1 * x) / 2
    region = (x > 0.3) & (x < 0.7) & (p[..., 1] > 0.3) & (p[..., 1] < 0.7) & (np.abs(expected) < 3 / n)
    assert region.sum() > 50
    np.testing.assert_allclose(field[region], expected[region], atol=1e-6)


def _bent_strip():
    """An open strip folded along y = 0.5 (roof shape), 2 x 2 quads."""
    xs, ys = [0.2, 0.5, 0.8], [0.2, 0.5, 0.8]
    v = np.array([(x, y, 0.4 + (0.15 if y == 0.5 else 0.0)) for y in ys for x in xs])
    f = []
    for j in range(2):
        for i in range(2):
            a, b, c, d = j * 3 + i, j * 3 + i + 1, (j + 1) * 3 + i + 1, (j + 1) * 3 + i
            f += [[a, b, c], [a, c, d]]
    return v, np.array(f)


def _dense_samples(v, f, spacing):
    pts = []
    for tri in v[f]:
        k = int(np.ceil(max(np.linalg.norm(tri[1] - tri[0]), np.linalg.norm(tri[2] - tri[0])) / spacing))
        i, j = np.meshgrid(np.arange(k + 1), np.arange(k + 1), indexing="ij")
        keep = i + j <= k
        u, w = i[keep] / k, j[keep] / k
        pts.append(tri[0] + u[:, None] * (tri[1] - tri[0]) + w[:, None] * (tri[2] - tri[0]))
    return np.concatenate(pts)


@pytest.mark.parametrize("periodic", [True, False])
def test_spherical_matches_brute_force_on_a_bent_strip(periodic):
    v, f = _bent_strip()
    v = v + [0.45, 0.0, 0.0]                         # crosses x = 1 when periodic
    n, t = 24, 0.08
    field = surface_sdf_grid(v, f, np.full(len(v), t), resolution=n, periodic=periodic)
    pts = _dense_samples(v, f, 1e-3)
    nodes = _nodes(n).reshape(-1, 3)
    tree = cKDTree(np.mod(pts, 1.0) % 1.0, boxsize=1.0) if periodic else cKDTree(pts)
    band = 3 / n
    # bounded search: far nodes are clamped to the band anyway
    dist = tree.query(nodes, distance_upper_bound=t / 2 + band)[0]
    ref = np.minimum(dist - t / 2, band).reshape(n, n, n)
    near = np.abs(ref) < band - 1e-3
    assert near.sum() > 100
    assert np.abs(field - ref)[near].max() < 1e-3
    clear = np.abs(ref) > 1e-3
    assert np.array_equal(field[clear] < 0, ref[clear] < 0)


def test_periodic_shift_is_a_roll():
    v, f = _bent_strip()
    n = 20
    base = surface_sdf_grid(v, f, np.full(len(v), 0.06), resolution=n, method="normal")
    moved = surface_sdf_grid(v + np.array([7, 0, -4]) / n, f, np.full(len(v), 0.06), resolution=n,
                             method="normal")
    np.testing.assert_allclose(moved, np.roll(base, (7, 0, -4), axis=(0, 1, 2)), atol=1e-6)


def test_boundary_flags_of_a_square():
    eb, vb = boundary_flags(SQUARE_F, 4)
    # edge opposite corner k; the shared diagonal (0, 2) is interior
    assert eb.tolist() == [[True, False, True], [True, True, False]]
    assert vb.all()


def test_inputs_are_not_mutated():
    v, f, t = SQUARE_V.copy(), SQUARE_F.copy(), np.full(4, 0.1)
    surface_sdf_grid(v, f, t, resolution=8, method="normal")
    np.testing.assert_array_equal(v, SQUARE_V)
    np.testing.assert_array_equal(f, SQUARE_F)
    assert np.all(t == 0.1)


@pytest.mark.parametrize("args, kwargs, match", [
    ((SQUARE_V, SQUARE_F, np.full(3, 0.1)), {}, "thickness_per_vertex"),
    ((SQUARE_V, SQUARE_F + 2, np.full(4, 0.1)), {}, "faces must index"),
    ((SQUARE_V, SQUARE_F.astype(float), np.full(4, 0.1)), {}, "integer"),
    ((SQUARE_V[:, :2], SQUARE_F, np.full(4, 0.1)), {}, "vertices"),
    ((SQUARE_V, SQUARE_F, -np.ones(4)), {}, ">= 0"),
    ((SQUARE_V, SQUARE_F, np.full(4, 0.1)), {"method": "offset"}, "method"),
])
def test_bad_input_is_refused(args, kwargs, match):
    with pytest.raises(ValueError, match=match):
        surface_sdf_grid(*args, resolution=8, **kwargs)
