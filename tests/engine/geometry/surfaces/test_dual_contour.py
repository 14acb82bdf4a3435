"""SOLVECONTOUR: dual edge directions from vertex angles and normals, the
closing least-squares problem (eqs. 5-6) and the three-case initial lengths."""

import math

import numpy as np
import pytest
from scipy.optimize import minimize

from engine.geometry.surfaces.dual_contour import (ContourError, close_lengths, dual_directions,
                                                   initial_lengths, solve_contour)
from engine.geometry.surfaces.fbv import (LoopOnFBV, check_conjugate_loop, cuboid, tetrahedron,
                                          vertex_frames)

CUBE = cuboid((0, 0, 0), (0.5, 0.5, 0.5))
TET = tetrahedron([[0, 0, 0], [0.5, 0, 0], [0.5, 0.5, 0], [0.5, 0.5, 0.5]])
P_HEX = np.array([[0, .5, .25], [0, .25, .5], [.25, 0, .5], [.5, 0, .25], [.5, .25, 0],
                  [.25, .5, 0]])
P_TET = np.array([[1 / 3, 1 / 3, 0], [.25, .25, .25], [.5, 1 / 6, 1 / 6], [.5, .25, 0]])


def _frames(fbv, pts):
    loop = check_conjugate_loop(fbv, pts)
    return loop, *vertex_frames(fbv, loop)


@pytest.mark.parametrize("fbv, pts", [(CUBE, P_HEX), (TET, P_TET)])
def test_dual_edges_are_orthogonal_to_both_normals_and_turn_by_the_angles(fbv, pts):
    loop, v_a, v_n = _frames(fbv, pts)
    d = dual_directions(v_a, v_n)
    n = d.shape[0]
    assert np.allclose(np.linalg.norm(d, axis=1), 1)
    for i in range(n):
        j = (i + 1) % n
        assert abs(d[i] @ v_n[i]) < 1e-12 and abs(d[i] @ v_n[j]) < 1e-12
        # Interior angle at dual vertex j between -d[i] and d[j] is vA[j].
        assert math.isclose(math.acos(np.clip(-d[i] @ d[j], -1, 1)), v_a[j], abs_tol=1e-9)
        assert np.allclose(np.cross(d[i], np.cross(v_n[i], v_n[j])), 0, atol=1e-12)
    # All along the outward normals of the arcs' planes, or all against them.
    dots = np.einsum("ij,ij->i", d, fbv.normals[loop.arc_planes])
    assert np.allclose(np.abs(dots), 1) and len(set(np.sign(dots))) == 1


def test_inconsistent_normals_and_angles_are_refused():
    _, v_a, v_n = _frames(CUBE, P_HEX)
    with pytest.raises(ContourError, match="not orthogonal to the normal at vertex"):
        dual_directions(np.full(6, math.radians(80)), v_n)
    with pytest.raises(ContourError, match="angles must lie in"):
        dual_directions(np.r_[v_a[:5], 0.0], v_n)


def test_closing_lengths_matches_a_generic_constrained_solver():
    _, v_a, v_n = _frames(CUBE, P_HEX)
    d = dual_directions(v_a, v_n)
    want = np.array([0.3, 0.5, 0.4, 0.35, 0.45, 0.2])
    got, ok = close_lengths(want, d)
    ref = minimize(lambda l: np.sum((l - want) ** 2), want, method="SLSQP",
                   constraints=[{"type": "eq", "fun": lambda l: d.T @ l}],
                   options={"ftol": 1e-14}).x
    assert ok and np.allclose(got, ref, atol=1e-7)
    assert np.allclose(d.T @ got, 0, atol=1e-14)
    # Opposite hexagon edges are parallel: closing averages each pair.
    assert np.allclose(got, np.tile((want[:3] + want[3:]) / 2, 2))
    closed = np.full(6, 0.4)
    assert np.allclose(close_lengths(closed, d)[0], closed)


def test_solve_contour_closes_and_refuses_non_positive_lengths():
    _, v_a, v_n = _frames(CUBE, P_HEX)
    corners, lengths = solve_contour(np.full(6, 0.4), v_a, v_n)
    steps = np.roll(corners, -1, axis=0) - corners
    assert np.allclose(np.linalg.norm(steps, axis=1), lengths)
    # The Schwarz D hexagon: a Petrie polygon of a cube of edge 0.4.
    assert np.allclose(np.ptp(corners, axis=0), 0.4)
    with pytest.raises(ContourError, match="edge [03] length -0.1"):
        solve_contour([0.1, 1, 1, 0.1 - 0.4, 1, 1], v_a, v_n)


def test_initial_lengths_follow_the_three_cases():
    # Case 1 (neighbouring edges, quarter circle about the cube corner).
    loop = check_conjugate_loop(CUBE, P_HEX)
    assert np.allclose(initial_lengths(CUBE, loop), math.pi / 2 * 0.25)
    loop = check_conjugate_loop(CUBE, np.array([[0, .5, .1], [0, .3, .5], [.25, 0, .5],
                                                [.5, 0, .25], [.5, .25, 0], [.25, .5, 0]]))
    r = (0.4 + 0.2) / 2
    assert math.isclose(initial_lengths(CUBE, loop)[0], math.pi / 2 * r)
    # Case 2 (edges on one face that do not meet): the chord. Case 3 (both
    # ends on one edge): half the circle on the chord as diameter.
    pts = np.array([[0, 0, .1], [0, .5, .2], [0, .5, .4], [.5, 0, .3]])
    planes = np.array([[2, 0], [0, 3], [3, 0], [0, 2]])        # (in, out) per vertex
    loop = LoopOnFBV(points=pts, arc_planes=planes[:, 1], vertex_planes=planes)
    got = initial_lengths(CUBE, loop)
    assert math.isclose(got[0], np.linalg.norm(pts[1] - pts[0]))
    assert math.isclose(got[1], math.pi / 2 * 0.2)
