"""Boundary loops: validation messages, sampling and constraints."""

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from engine.geometry.surfaces.boundary import (boundary_loop, loop_from_chains, sample_loop,
                                               segment_distances)

SQUARE = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
X0 = ([0, 0, 0], [1, 0, 0])          # plane x = 0 as (origin, normal)
X1 = ([1, 0, 0], [1, 0, 0])
Y1 = ([0, 1, 0], [0, 1, 0])


def test_segment_distance_matches_brute_force():
    rng = np.random.default_rng(3)
    p0, p1, q0, q1 = (rng.normal(size=(200, 3)) for _ in range(4))
    # Make some pairs parallel and some touching to cover the special cases.
    q1[:20] = q0[:20] + (p1[:20] - p0[:20]) * 0.5
    q0[20:30] = p0[20:30] + 0.3 * (p1[20:30] - p0[20:30])
    # Reference: sample one segment densely, exact point-to-segment distance
    # to the other.
    t = np.linspace(0, 1, 4001)
    a = p0[:, None] + t[None, :, None] * (p1 - p0)[:, None]                 # (k, s, 3)
    d = (q1 - q0)[:, None]
    w = np.clip(np.sum((a - q0[:, None]) * d, axis=2) / np.sum(d * d, axis=2), 0, 1)
    brute = np.linalg.norm(a - q0[:, None] - w[..., None] * d, axis=2).min(axis=1)
    ours = segment_distances(p0, p1, q0, q1)
    assert np.all(ours <= brute + 1e-12)
    np.testing.assert_allclose(ours, brute, atol=1e-6)


@pytest.mark.parametrize("points, match", [
    (SQUARE[:2], "at least 3 vertices; got 2"),
    ([[0, 0, 0], [1, 0, 0], [np.nan, 1, 0]], "vertex 2 is"),
    (np.vstack([SQUARE, [[1, 0, 0]], [[0.5, -1, 0]]]), "vertex 4 repeats vertex 1"),
    ([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, -0.5, 0], [0.5, 0.5, 0]],
     "intersects itself: segment 0 and segment 3"),
    ([[0, 0, 0], [1, 0, 0], [2, 0, 0]], "folds back"),
    (np.zeros((4, 2)), r"shape \(n, 3\)"),
])
def test_bad_loops_are_refused_by_name(points, match):
    with pytest.raises(ValueError, match=match):
        boundary_loop(points)


def test_self_intersection_uses_3d_distance_and_tolerance():
    # A figure-eight whose crossing segments pass 1e-3 apart in z.
    eight = np.array([[0, 0, 0], [1, 1, 0.002], [1, 0, 0], [0, 1, 0]], float)
    assert boundary_loop(eight, tol=1e-4).n_segments == 4
    with pytest.raises(ValueError, match="segment 0 and segment 2 come within"):
        boundary_loop(eight, tol=1e-2)


def test_open_chains_are_refused():
    chains = [SQUARE[:2], SQUARE[1:3], SQUARE[2:]]
    with pytest.raises(ValueError, match=r"loop is open: chains\[2\] ends"):
        loop_from_chains(chains, modes="straight")
    with pytest.raises(ValueError, match=r"chains\[1\] must hold at least 2 points"):
        loop_from_chains([SQUARE[:2], SQUARE[1:2]], modes="straight")


def test_chains_join_into_a_loop():
    chains = [SQUARE[:2], SQUARE[1:3], np.vstack([SQUARE[2:], SQUARE[:1]])]
    loop = loop_from_chains(chains, modes=["straight", "smooth", "straight"])
    np.testing.assert_array_equal(loop.points, SQUARE)
    assert loop.modes == ("straight", "smooth", "straight", "straight")
    assert not loop.points.flags.writeable


def test_sliding_needs_a_plane_holding_its_vertices():
    with pytest.raises(ValueError, match="segment 1 is sliding but has no plane"):
        boundary_loop(SQUARE, modes=["straight", "sliding", "straight", "straight"])
    with pytest.raises(ValueError, match="segment 1 slides in its plane but vertex 2"):
        boundary_loop(SQUARE, modes=["straight", "sliding", "straight", "straight"],
                      planes=[None, ([1, 0, 0], [1, 0.5, 0]), None, None])
    with pytest.raises(ValueError, match="segment 2 has mode 'wobbly'"):
        boundary_loop(SQUARE, modes=["straight", "straight", "wobbly", "straight"])


def test_samples_keep_vertices_and_spacing():
    loop = boundary_loop(SQUARE * [2, 1, 1])
    s = sample_loop(loop, edge_length=0.3)
    corners = s.points[s.vertex >= 0]
    np.testing.assert_array_equal(corners, loop.points)
    gaps = np.linalg.norm(np.roll(s.points, -1, axis=0) - s.points, axis=1)
    assert gaps.max() <= 0.3 + 1e-12
    assert s.points.shape[0] == 2 * (7 + 4)
    assert s.fixed.all()


def test_smooth_run_follows_the_natural_spline():
    pts = np.array([[0, 0, 0], [2, 0, 0], [2, 1, 0.5], [1, 1.5, 0.2], [0, 1, 0]], float)
    loop = boundary_loop(pts, modes=["straight", "smooth", "smooth", "smooth", "straight"])
    s = sample_loop(loop, edge_length=0.05)
    run = pts[1:]
    # Reference: scipy's natural cubic spline in chord length.
    u = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(run, axis=0), axis=1))])
    ref = CubicSpline(u, run, bc_type="natural")(np.linspace(0, u[-1], 4000))
    on_run = np.isin(s.segment, [1, 2, 3])
    gap = np.linalg.norm(s.points[on_run][:, None] - ref[None], axis=2).min(axis=1)
    assert gap.max() < 1e-3
    np.testing.assert_array_equal(s.points[s.vertex >= 0], pts)


def test_sliding_constraints():
    loop = boundary_loop(SQUARE, modes=["straight", "sliding", "sliding", "straight"],
                         planes=[None, X1, Y1, None])
    s = sample_loop(loop, edge_length=0.25)
    # Vertex 1 and 3 touch fixed segments; vertex 2 joins two sliding planes.
    corner = np.flatnonzero(s.vertex == 2)[0]
    assert not s.fixed[corner]
    np.testing.assert_allclose(s.planes[corner, :, :3], [[0, 1, 0], [1, 0, 0]])
    assert s.fixed[s.vertex == 1].all() and s.fixed[s.vertex == 3].all()
    inner = (s.segment == 1) & (s.vertex < 0)
    assert not s.fixed[inner].any()
    np.testing.assert_allclose(s.planes[inner, 0], [[1, 0, 0, 1]] * inner.sum())
    assert np.isnan(s.planes[inner, 1]).all()
