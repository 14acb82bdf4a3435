"""Direct (thin-shell) surfaces: analytic gradients, the flat case, a
near-planar saddle against its harmonic (linearised minimal) graph, and the
effect of the bending weight."""

import numpy as np
import pytest

from engine.progress import Cancelled
from engine.geometry.surfaces.boundary import boundary_loop
from engine.geometry.surfaces.mesh_init import disc_mesh
from engine.geometry.surfaces.thin_shell import shell_energy, shell_model, solve_thin_shell

EPS = 0.1
THETA = np.linspace(0, 2 * np.pi, 30, endpoint=False)
# Unit circle lifted by eps cos(2 theta): the harmonic extension is
# z = eps r^2 cos(2 theta), the small-slope limit of the minimal surface.
SADDLE = np.column_stack([np.cos(THETA), np.sin(THETA), EPS * np.cos(2 * THETA)])


def test_energy_gradient_matches_finite_differences():
    m = disc_mesh(SADDLE)
    model = shell_model(m.uv * 0.3, m.faces, stretch=1 / 0.3)
    rng = np.random.default_rng(2)
    x = m.vertices + 0.02 * rng.normal(size=m.vertices.shape)
    for alpha in (0.0, 0.7):
        _, _, _, grad = shell_energy(x, model, alpha=alpha)
        d = rng.normal(size=x.shape)
        h = 1e-6
        fd = (shell_energy(x + h * d, model, alpha=alpha)[0]
              - shell_energy(x - h * d, model, alpha=alpha)[0]) / (2 * h)
        assert np.sum(grad * d) == pytest.approx(fd, rel=1e-6)


def test_planar_boundary_gives_a_flat_patch():
    rot, _ = np.linalg.qr(np.random.default_rng(4).normal(size=(3, 3)))
    flat = SADDLE * [1, 1, 0] @ rot.T
    s = solve_thin_shell(flat)
    assert np.abs(s.vertices @ rot[:, 2]).max() < 1e-9
    assert s.bend_energy < 1e-16


def test_saddle_is_smooth_and_keeps_its_boundary():
    s = solve_thin_shell(SADDLE, alpha=0.1)
    assert s.converged
    b = s.vertices[s.boundary]
    np.testing.assert_array_equal(b[::2], SADDLE)           # loop vertices, exactly
    mid = 0.5 * (SADDLE + np.roll(SADDLE, -1, axis=0))
    np.testing.assert_allclose(b[1::2], mid, atol=1e-15)     # straight edges, halved
    assert np.all(np.diff(s.energy_history) <= 1e-12)
    v = s.vertices
    r2 = v[:, 0] ** 2 + v[:, 1] ** 2
    angle = np.arctan2(v[:, 1], v[:, 0])
    harmonic = EPS * r2 * np.cos(2 * angle)
    assert np.abs(v[:, 2] - harmonic).max() < 0.2 * EPS
    assert np.hypot(v[:, 0], v[:, 1]).max() <= 1.0 + 1e-12


def test_more_bending_weight_is_smoother():
    bends = [solve_thin_shell(SADDLE, alpha=a).bend_energy for a in (0.0, 0.1, 1.0)]
    print(f"\nbending energy at alpha 0, 0.1, 1: {np.round(bends, 4).tolist()}")
    assert bends[0] > bends[1] > bends[2]


def test_loop_input_with_smooth_segments():
    square = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0.2], [0, 1, 0]], float)
    loop = boundary_loop(square, modes=["straight", "smooth", "smooth", "straight"])
    s = solve_thin_shell(loop, edge_length=0.1)
    np.testing.assert_array_equal(s.vertices[0], square[0])
    assert s.converged and s.iterations > 0


def test_bad_input_and_cancel():
    with pytest.raises(ValueError, match="alpha"):
        solve_thin_shell(SADDLE, alpha=-1.0)
    with pytest.raises(ValueError, match="rest_scale"):
        solve_thin_shell(SADDLE, rest_scale=0.0)
    with pytest.raises(ValueError, match="vertex 1"):
        solve_thin_shell([[0, 0, 0], [np.nan, 0, 0], [0, 1, 0]])
    with pytest.raises(Cancelled):
        solve_thin_shell(SADDLE, progress=lambda d, t: d < 3)
