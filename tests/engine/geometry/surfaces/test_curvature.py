"""Cotan Laplacian, mixed areas and mean curvature against closed forms and
libigl (an independent implementation)."""

import igl
import numpy as np
import pytest
import trimesh

from engine.geometry.surfaces.curvature import (cotan_laplacian, mean_curvature, mixed_areas,
                                                surface_area, surface_report, validate_mesh)


def _grid(n=9, rng=None):
    """A planar triangulated square with jittered interior vertices."""
    u, v = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n), indexing="ij")
    pts = np.column_stack([u.ravel(), v.ravel(), np.zeros(n * n)])
    inner = (u.ravel() > 0) & (u.ravel() < 1) & (v.ravel() > 0) & (v.ravel() < 1)
    rng = np.random.default_rng(7) if rng is None else rng
    pts[inner, :2] += rng.uniform(-0.2, 0.2, (inner.sum(), 2)) / (n - 1)
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    faces = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    return pts, faces, ~inner


def test_laplacian_matches_libigl():
    sphere = trimesh.creation.icosphere(subdivisions=2, radius=1.3)
    v, f = np.asarray(sphere.vertices, float), np.asarray(sphere.faces, np.int64)
    ours = cotan_laplacian(v, f).toarray()
    ref = igl.cotmatrix(v, f).toarray()
    np.testing.assert_allclose(ours, ref, atol=1e-12)


@pytest.mark.parametrize("radius", [0.5, 2.0])
def test_sphere_mean_curvature_is_one_over_radius(radius):
    sphere = trimesh.creation.icosphere(subdivisions=3, radius=radius)
    v, f = np.asarray(sphere.vertices, float), np.asarray(sphere.faces, np.int64)
    h = mean_curvature(v, f)
    np.testing.assert_allclose(h, 1.0 / radius, rtol=0.02)
    assert surface_area(v, f) == pytest.approx(4 * np.pi * radius ** 2, rel=0.01)


def test_plane_has_zero_mean_curvature():
    pts, faces, on_border = _grid()
    # Tilt the plane so no coordinate is trivially zero.
    rot = trimesh.transformations.rotation_matrix(0.7, [1, 2, 3])[:3, :3]
    v = pts @ rot.T
    report = surface_report(v, faces, np.flatnonzero(on_border))
    assert report["max_abs_H"] < 1e-10
    assert report["area"] == pytest.approx(1.0, abs=1e-12)


def test_mixed_areas_partition_the_area():
    pts, faces, _ = _grid()
    pts[:, 2] = 0.3 * np.sin(3 * pts[:, 0]) * pts[:, 1]
    assert mixed_areas(pts, faces).sum() == pytest.approx(surface_area(pts, faces), rel=1e-12)
    assert np.all(mixed_areas(pts, faces) > 0)


def test_unit_disc_area_tends_to_pi():
    areas = []
    for n in (16, 64, 256):
        t = 2 * np.pi * np.arange(n) / n
        ring = np.column_stack([np.cos(t), np.sin(t), np.zeros(n)])
        v = np.vstack([[0, 0, 0], ring])
        f = np.column_stack([np.zeros(n, int), 1 + np.arange(n), 1 + (np.arange(n) + 1) % n])
        areas.append(surface_area(v, f))
    errors = np.abs(np.array(areas) - np.pi)
    assert errors[-1] < 1e-3 and np.all(np.diff(errors) < 0)


def test_report_ignores_boundary_vertices():
    sphere = trimesh.creation.icosphere(subdivisions=2)
    v, f = np.asarray(sphere.vertices, float), np.asarray(sphere.faces, np.int64)
    upper = np.all(v[f][:, :, 2] > -0.2, axis=1)
    f = f[upper]
    used = np.unique(f)
    border = np.unique(igl.boundary_loop(f))
    report = surface_report(v, f, border)
    assert report["max_abs_H"] == pytest.approx(1.0, rel=0.05)
    assert report["mean_abs_H"] == pytest.approx(1.0, rel=0.05)
    assert used.size > border.size


def test_bad_meshes_are_refused():
    v = np.zeros((3, 3))
    with pytest.raises(ValueError, match="shape"):
        validate_mesh(np.zeros((3, 2)), [[0, 1, 2]])
    with pytest.raises(ValueError, match="vertex 1"):
        validate_mesh([[0, 0, 0], [np.nan, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    with pytest.raises(ValueError, match="index"):
        validate_mesh(v, [[0, 1, 3]])
