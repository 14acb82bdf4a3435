"""Disc meshes spanning polygons: topology, boundary correspondence, the
harmonic fill, subdivision and flips."""

import igl
import numpy as np
import pytest

from engine.geometry.surfaces.curvature import corner_cotangents, surface_area
from engine.geometry.surfaces.mesh_init import (boundary_loop_of, delaunay_flips, disc_mesh,
                                                midpoint_subdivide)

SKEW = np.array([[0, 0, 0], [1, 0, 0.3], [1.2, 1, 0], [0, 0.8, 0.4], [-0.3, 0.4, 0.1]], float)


def _euler(faces):
    edges = np.unique(np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]],
                                              faces[:, [2, 0]]]), axis=1), axis=0)
    return np.unique(faces).size - edges.shape[0] + faces.shape[0]


def test_disc_topology_and_boundary_order():
    m = disc_mesh(SKEW, edge_length=0.1)
    assert _euler(m.faces) == 1
    b = m.boundary.size
    np.testing.assert_array_equal(m.boundary, np.arange(b))
    loop = igl.boundary_loop(m.faces)
    # libigl's loop is the same cycle as ours (possibly shifted / reversed).
    shift = int(np.flatnonzero(loop == 0)[0])
    rolled = np.roll(loop, -shift)
    assert np.array_equal(rolled, np.arange(b)) or np.array_equal(np.roll(rolled[::-1], 1), np.arange(b))
    np.testing.assert_array_equal(boundary_loop_of(m.faces, m.vertices.shape[0]), np.arange(b))


def test_boundary_copies_the_polygon():
    m = disc_mesh(SKEW, edge_length=0.1)
    corners = m.source >= 0
    np.testing.assert_array_equal(m.vertices[m.boundary[corners]], SKEW[m.source[corners]])
    np.testing.assert_array_equal(m.source[corners], np.arange(5))
    # Inserted points lie on the polygon edges, no farther apart than asked.
    b = m.vertices[m.boundary]
    gaps = np.linalg.norm(np.roll(b, -1, axis=0) - b, axis=1)
    assert gaps.max() <= 0.1 + 1e-12
    seg = np.maximum.accumulate(np.where(corners, m.source, -1))
    a, c = SKEW[seg], SKEW[(seg + 1) % 5]
    cross = np.linalg.norm(np.cross(b - a, c - a), axis=1)
    assert cross.max() < 1e-12


def test_uv_is_a_valid_disc_triangulation():
    m = disc_mesh(SKEW, edge_length=0.1)
    uv = m.uv[m.faces]
    e1, e2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    signed = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    assert signed.min() > 0
    np.testing.assert_allclose(np.linalg.norm(m.uv[m.boundary], axis=1), 1.0)
    assert np.linalg.norm(m.uv[m.boundary.size:], axis=1).max() < 1.0


def test_planar_polygon_fills_its_plane():
    theta = np.linspace(0, 2 * np.pi, 7, endpoint=False)
    hexagon = np.column_stack([np.cos(theta), np.sin(theta), np.zeros(7)])
    normal = np.array([1.0, -2.0, 2.0]) / 3.0
    u = np.cross(normal, [0, 0, 1.0])
    u /= np.linalg.norm(u)
    w = np.cross(normal, u)
    poly = hexagon[:, :1] * u + hexagon[:, 1:2] * w + 0.5 * normal
    m = disc_mesh(poly, edge_length=0.15)
    assert np.abs(m.vertices @ normal - 0.5).max() < 1e-12
    shoelace = 0.5 * np.linalg.norm(np.cross(poly, np.roll(poly, -1, axis=0)).sum(axis=0))
    assert surface_area(m.vertices, m.faces) == pytest.approx(shoelace, rel=1e-12)


def test_midpoint_subdivision():
    m = disc_mesh(SKEW, edge_length=0.2)
    v, f, b, uv = midpoint_subdivide(m.vertices, m.faces, m.boundary, uv=m.uv)
    assert f.shape[0] == 4 * m.faces.shape[0]
    assert _euler(f) == 1
    np.testing.assert_array_equal(b, np.arange(2 * m.boundary.size))
    np.testing.assert_array_equal(v[b[::2]], m.vertices[m.boundary])
    old = m.vertices[m.boundary]
    np.testing.assert_allclose(v[b[1::2]], 0.5 * (old + np.roll(old, -1, axis=0)))
    np.testing.assert_array_equal(boundary_loop_of(f, v.shape[0]), b)
    assert uv.shape == (v.shape[0], 2)


def test_flips_remove_negative_cotan_weights():
    rng = np.random.default_rng(11)
    m = disc_mesh(SKEW, edge_length=0.1)
    v = m.vertices.copy()
    v[m.boundary.size:] += rng.normal(scale=0.02, size=(v.shape[0] - m.boundary.size, 3))
    f, flips = delaunay_flips(v, m.faces)
    assert flips > 0 and _euler(f) == 1
    n = v.shape[0]
    cots = corner_cotangents(v, f)
    a = np.concatenate([f[:, 1], f[:, 2], f[:, 0]])
    c = np.concatenate([f[:, 2], f[:, 0], f[:, 1]])
    key = np.minimum(a, c) * n + np.maximum(a, c)
    weight = np.bincount(np.unique(key, return_inverse=True)[1], weights=cots.T.ravel())
    interior = np.bincount(np.unique(key, return_inverse=True)[1]) == 2
    assert weight[interior].min() > -1e-9
    np.testing.assert_array_equal(boundary_loop_of(f, n), m.boundary)


@pytest.mark.parametrize("points, match", [
    (SKEW[:2], "at least 3"),
    ([[0, 0, 0], [1, 0, 0], [1, 0, 0], [0, 1, 0]], "vertex 2 repeats vertex 1"),
    ([[0, 0, 0], [1, np.inf, 0], [0, 1, 0]], "vertex 1"),
])
def test_bad_polygons_are_refused(points, match):
    with pytest.raises(ValueError, match=match):
        disc_mesh(points)
