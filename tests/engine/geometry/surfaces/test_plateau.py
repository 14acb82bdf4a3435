"""Plateau problem: planar polygons (closed form) and Schwarz's D surface
(published area), with refinement and Richardson extrapolation."""

import time

import numpy as np
import pytest

from engine.progress import Cancelled
from engine.geometry.surfaces.curvature import surface_report
from engine.geometry.surfaces.plateau import richardson_area, solve_plateau

# Schwarz D, per conventional cubic cell of edge 1 (Schoen 1970; Schwarz).
D_AREA_PER_CELL = 3.8377

# Four edges of the regular tetrahedron inscribed in a cube of edge 1/4
# (alternate corners) bound the D surface's fundamental patch. Its interior
# angles are 60 degrees, so by Gauss-Bonnet each patch carries total
# curvature 2 pi - 4 (2 pi / 3) = -2 pi / 3; the cell has Euler
# characteristic -16 (genus 3 per primitive fcc cell, four per cubic cell),
# hence -32 pi / (-2 pi / 3) = 48 patches per cell.
TETRA = np.array([[0, 0, 0], [1, 1, 0], [1, 0, 1], [0, 1, 1]], float) / 4
D_QUAD = TETRA[[0, 1, 3, 2]]
PATCHES_PER_CELL = 48


def _shoelace(poly):
    return 0.5 * np.linalg.norm(np.cross(poly, np.roll(poly, -1, axis=0)).sum(axis=0))


def test_planar_polygon_gives_the_flat_patch():
    rng = np.random.default_rng(5)
    theta = np.sort(rng.uniform(0, 2 * np.pi, 9))
    radius = rng.uniform(0.8, 1.2, 9)
    flat = np.column_stack([radius * np.cos(theta), radius * np.sin(theta), np.zeros(9)])
    rot, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    poly = flat @ rot.T + [0.3, -0.2, 0.5]
    s = solve_plateau(poly, edge_length=0.2, levels=2, tol=1e-12, max_iter=50)
    normal = rot[:, 2]
    assert np.abs((s.vertices - poly[0]) @ normal).max() < 1e-12
    assert s.area == pytest.approx(_shoelace(poly), rel=1e-12)
    report = surface_report(s.vertices, s.faces, s.boundary)
    assert report["max_abs_H"] < 1e-8
    np.testing.assert_array_equal(s.vertices[s.boundary[s.source >= 0]], poly)


def test_schwarz_d_area_extrapolates_to_the_published_value():
    t0 = time.perf_counter()
    s = solve_plateau(D_QUAD, edge_length=0.08, levels=3, tol=1e-9, max_iter=150)
    elapsed = time.perf_counter() - t0
    cell = [a * PATCHES_PER_CELL for a in s.level_areas]
    extrapolated = richardson_area(s.level_areas) * PATCHES_PER_CELL
    report = surface_report(s.vertices, s.faces, s.boundary)
    print(f"\nSchwarz D per cell: levels {np.round(cell, 5).tolist()} "
          f"(h = {np.round(s.level_edge_lengths, 4).tolist()}), extrapolated {extrapolated:.5f} "
          f"vs {D_AREA_PER_CELL}; steps {s.iterations}; seconds "
          f"{np.round(s.level_seconds, 3).tolist()} (total {elapsed:.2f}); "
          f"max|H| * cell {report['max_abs_H']:.4f}, mean {report['mean_abs_H']:.5f}")
    # Discrete areas decrease towards the limit under refinement.
    assert cell[0] > cell[1] > cell[2] > D_AREA_PER_CELL
    assert extrapolated == pytest.approx(D_AREA_PER_CELL, rel=1.5e-3)
    assert report["max_abs_H"] * 1.0 < 0.05
    # The straight boundary is reproduced exactly.
    np.testing.assert_array_equal(s.vertices[s.boundary[s.source >= 0]], D_QUAD)


def test_area_history_decreases():
    s = solve_plateau(D_QUAD, edge_length=0.06, tol=0.0, max_iter=40)
    h = s.area_history
    assert h.size == 41
    assert h[-1] < h[1] < h[0]
    # Flips may nudge the area up by round-off amounts only.
    assert np.diff(h).max() < 1e-9 * h[0]


def test_richardson_is_exact_for_polynomial_error():
    exact, h = 2.5, 0.4
    areas = [exact + 0.3 * x ** 2 - 0.7 * x ** 4 for x in (h, h / 2, h / 4)]
    assert richardson_area(areas) == pytest.approx(exact, abs=1e-14)
    assert richardson_area(areas[:2]) == pytest.approx(exact, abs=0.7 * h ** 4)


def test_progress_and_cancel():
    calls = []
    solve_plateau(D_QUAD, edge_length=0.1, levels=2, tol=0.0, max_iter=3,
                  progress=lambda d, t: calls.append((d, t)) or True)
    assert calls[-1] == (6, 6) and all(t == 6 for _, t in calls)
    with pytest.raises(Cancelled):
        solve_plateau(D_QUAD, edge_length=0.1, max_iter=10, progress=lambda d, t: d < 2)


@pytest.mark.parametrize("kwargs, match", [
    ({"boundary_points": D_QUAD[:2]}, "at least 3"),
    ({"boundary_points": [[0, 0, 0], [1, 0, 0], [np.nan, 1, 0]]}, "vertex 2"),
    ({"boundary_points": D_QUAD, "levels": 0}, "levels"),
    ({"boundary_points": D_QUAD, "edge_length": -1.0}, "edge_length"),
    ({"boundary_points": D_QUAD, "max_iter": 0}, "max_iter"),
])
def test_bad_input_is_refused(kwargs, match):
    with pytest.raises(ValueError, match=match):
        solve_plateau(**kwargs)
