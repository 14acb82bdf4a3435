"""Mixed minimal surfaces (fixed + sliding boundary) against closed forms:
a flat strip and Scherk's first surface."""

import numpy as np
import pytest

from engine.progress import Cancelled
from engine.geometry.surfaces.boundary import boundary_loop, loop_from_chains
from engine.geometry.surfaces.mixed_minimal import solve_mixed_minimal


def _strip_loop():
    """Unit square: fixed edges y = 0 and y = 1; the x = 0 and x = 1 edges
    slide in their planes and start bulged out of the square's plane."""
    chains = [np.array([[0, 0, 0], [1, 0, 0]], float),
              np.array([[1, 0, 0], [1, 0.5, 0.3], [1, 1, 0]], float),
              np.array([[1, 1, 0], [0, 1, 0]], float),
              np.array([[0, 1, 0], [0, 0.5, -0.2], [0, 0, 0]], float)]
    planes = [None, ([1, 0, 0], [1, 0, 0]), None, ([0, 0, 0], [1, 0, 0])]
    return loop_from_chains(chains, modes=["straight", "sliding", "straight", "sliding"],
                            planes=planes)


def test_strip_flattens_and_slides_in_its_planes():
    # Near the flat answer the area excess is quadratic in the height, so the
    # default stagnation test stops at heights ~1e-4; a tight one goes on.
    loose = solve_mixed_minimal(_strip_loop(), edge_length=0.1)
    assert loose.converged and np.abs(loose.vertices[:, 2]).max() < 1e-3
    s = solve_mixed_minimal(_strip_loop(), edge_length=0.1, tol=1e-13, time_step=0.5)
    assert s.converged
    assert s.area == pytest.approx(1.0, abs=1e-10)
    assert np.abs(s.vertices[:, 2]).max() < 1e-6
    assert s.max_abs_H < 1e-4
    sliding = s.vertices[s.boundary[s.sliding]]
    on_plane = np.minimum(np.abs(sliding[:, 0]), np.abs(sliding[:, 0] - 1.0))
    assert on_plane.max() < 1e-9
    assert s.area_history[-1] < s.area_history[0]


def test_scherk_surface_with_a_free_boundary():
    # Scherk's first surface z = log(cos y / cos x) over 0 <= y <= x <= c:
    # the diagonal y = x (z = 0) is a straight line on it, the side x = c is
    # fixed to the exact curve, and the side y = 0 lies in a mirror plane of
    # the surface, which it meets orthogonally: that side slides in y = 0 and
    # starts as a straight chord.
    c = 1.0
    ys = np.linspace(c, 0.0, 21)
    side = np.column_stack([np.full_like(ys, c), ys, np.log(np.cos(ys) / np.cos(c))])
    chains = [np.array([[0, 0, 0], [c, c, 0]]), side, np.array([side[-1], [0, 0, 0]])]
    loop = loop_from_chains(chains, modes=["straight", "straight", "sliding"],
                            planes=[None, None, ([0, 0, 0], [0, 1, 0])])
    s = solve_mixed_minimal(loop, edge_length=0.1)
    v = s.vertices
    exact = np.log(np.cos(v[:, 1]) / np.cos(v[:, 0]))
    error = np.abs(v[:, 2] - exact).max()
    print(f"\nScherk: {s.iterations} steps, area {s.area:.6f}, max |z - z_exact| {error:.2e}, "
          f"max|H| {s.max_abs_H:.4f}")
    assert error < 2e-3                      # z spans 0 .. 0.62
    sliding = v[s.boundary[s.sliding]]
    assert np.abs(sliding[:, 1]).max() < 1e-9
    # The free side became the curve z = -log cos x within y = 0.
    assert np.abs(sliding[:, 2] + np.log(np.cos(sliding[:, 0]))).max() < 2e-3
    # Fixed samples stayed on the diagonal or on the fixed side.
    fixed = v[s.boundary[~s.sliding]]
    on_diagonal = (np.abs(fixed[:, 0] - fixed[:, 1]) < 1e-15) & (fixed[:, 2] == 0.0)
    on_side = fixed[:, 0] == c
    assert np.all(on_diagonal | on_side)


def test_fully_sliding_or_wrong_input_is_refused():
    square = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    planes = [([0, 0, 0], [0, 0, 1])] * 4
    loop = boundary_loop(square, modes="sliding", planes=planes)
    with pytest.raises(ValueError, match="conjugate solver"):
        solve_mixed_minimal(loop)
    with pytest.raises(ValueError, match="BoundaryLoop"):
        solve_mixed_minimal(square)
    with pytest.raises(ValueError, match="time_step"):
        solve_mixed_minimal(_strip_loop(), time_step=0.0)


def test_cancel():
    with pytest.raises(Cancelled):
        solve_mixed_minimal(_strip_loop(), edge_length=0.1, progress=lambda d, t: d < 2)
