"""Surface thickness profiles: ARAP parametrisation, bounded biharmonic
weights and the blended thickness, against closed forms."""

import numpy as np
import pytest

from engine.geometry.surfaces.mesh_init import disc_mesh
from engine.geometry.surfaces.plateau import solve_plateau
from engine.geometry.surfaces.thickness_profile import (arap_parametrisation,
                                                        bounded_biharmonic_weights,
                                                        boundary_vertices_at, nearest_vertices,
                                                        surface_thickness)

SQUARE = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
D_QUAD = np.array([[0, 0, 0], [1, 1, 0], [0, 1, 1], [1, 0, 1]], float) / 4


@pytest.fixture(scope="module")
def square():
    return disc_mesh(SQUARE, edge_length=0.1)


def _edge_lengths(x, faces):
    e = np.vstack([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    return np.linalg.norm(x[e[:, 0]] - x[e[:, 1]], axis=1)


def test_arap_flattens_a_developable_patch_isometrically(square):
    # The unit square rolled onto a cylinder of radius 1/2 (a developable
    # surface): its ARAP parametrisation is an isometry, edge lengths equal.
    x, y = square.vertices[:, 0], square.vertices[:, 1]
    bent = np.column_stack([0.5 * np.sin(2 * x), y, 0.5 * (1 - np.cos(2 * x))])
    uv = arap_parametrisation(bent, square.faces)
    ratio = _edge_lengths(uv, square.faces) / _edge_lengths(bent, square.faces)
    assert np.abs(ratio - 1).max() < 0.005
    # the flat square maps rigidly: edge lengths agree to solver precision
    flat = arap_parametrisation(square.vertices, square.faces)
    ratio = _edge_lengths(flat, square.faces) / _edge_lengths(square.vertices, square.faces)
    assert np.abs(ratio - 1).max() < 1e-5


def test_weights_are_bounded_partition_of_unity_on_a_curved_patch():
    s = solve_plateau(D_QUAD, edge_length=0.06, max_iter=60)
    uv = arap_parametrisation(s.vertices, s.faces)
    handles = np.array([s.boundary[0], s.boundary[len(s.boundary) // 3], s.vertices.shape[0] - 1,
                        s.boundary[2 * len(s.boundary) // 3]])
    w = bounded_biharmonic_weights(uv, s.faces, handles)
    assert w.shape == (s.vertices.shape[0], 4)
    assert w.min() >= 0.0 and w.max() <= 1.0
    np.testing.assert_allclose(w.sum(axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(w[handles], np.eye(4), atol=1e-9)


def test_constant_samples_give_a_constant_thickness(square):
    handles = nearest_vertices(square.vertices, [[0, 0, 0], [1, 1, 0], [0.5, 0.5, 0]])
    t = surface_thickness(square.vertices, square.faces, handles, [0.07, 0.07, 0.07])
    assert np.all(t == 0.07)


def test_linear_samples_on_a_flat_square_give_a_linear_thickness(square):
    v = square.vertices
    handles = nearest_vertices(v, SQUARE)
    ramp = 0.1 + 0.2 * v[:, 0]                                   # closed form
    exact = surface_thickness(v, square.faces, handles, ramp[handles])
    assert np.abs(exact - ramp).max() < 1e-4
    # Without the affine part bounded biharmonic weights alone are close,
    # not exact (they lack linear precision), and stay within the range.
    blend = surface_thickness(v, square.faces, handles, ramp[handles], linear_precision=False)
    err = np.abs(blend - ramp)
    assert err.max() < 0.12 * 0.2 and err.mean() < 0.05 * 0.2
    assert blend.min() >= 0.1 - 1e-12 and blend.max() <= 0.3 + 1e-12
    # each sample is interpolated
    np.testing.assert_allclose(blend[handles], ramp[handles], atol=1e-9)


def test_samples_on_one_vertex_are_averaged_and_bad_input_refused(square):
    v, f = square.vertices, square.faces
    t = surface_thickness(v, f, [0, 0], [0.1, 0.3])
    assert np.allclose(t, 0.2)
    with pytest.raises(ValueError, match="values must be finite"):
        surface_thickness(v, f, [0, 1], [0.1, np.nan])
    with pytest.raises(ValueError, match="handles must index"):
        surface_thickness(v, f, [0, 10_000], [0.1, 0.2])
    with pytest.raises(ValueError, match="t must lie in"):
        boundary_vertices_at(v, square.boundary, [1.5])


def test_boundary_positions_follow_arc_length(square):
    # boundary[0] is the loop's first vertex (0, 0, 0); a quarter of the
    # perimeter further is the next corner.
    idx = boundary_vertices_at(square.vertices, square.boundary, [0.0, 0.25, 0.5, 0.75, 1.0])
    np.testing.assert_allclose(square.vertices[idx], np.vstack([SQUARE, SQUARE[:1]]), atol=1e-12)
