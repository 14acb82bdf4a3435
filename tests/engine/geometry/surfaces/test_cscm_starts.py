"""Starts of the edge-length search and the choice between its results."""

import numpy as np

from engine.geometry.surfaces.cscm_starts import (AREA_TIE, SOLVED_ENERGY, canonical_loop_points,
                                                  choose_run, search_starts)
from engine.geometry.surfaces.dual_contour import initial_lengths
from engine.geometry.surfaces.fbv import check_conjugate_loop, cuboid

CUBE = cuboid((0, 0, 0), (0.5, 0.5, 0.5))


def hexagon(a, b, c, d, e, f):
    return np.array([[0, .5, a], [0, b, .5], [c, 0, .5], [.5, 0, d], [.5, e, 0], [f, .5, 0]])


def test_canonical_loop_puts_every_vertex_at_its_edge_midpoint():
    loop = check_conjugate_loop(CUBE, hexagon(0.4, 0.05, 0.2, 0.45, 0.3, 0.1))
    np.testing.assert_allclose(canonical_loop_points(CUBE, loop), hexagon(*(0.25,) * 6),
                               atol=1e-15)


def test_starts_are_the_users_then_the_canonical_one_unless_equal():
    loop = check_conjugate_loop(CUBE, hexagon(0.4, 0.05, 0.2, 0.45, 0.3, 0.1))
    user = initial_lengths(CUBE, loop)
    starts = search_starts(CUBE, loop, user)
    assert [s.name for s in starts] == ["user", "canonical"]
    # The midpoint hexagon's arcs are quarter circles of radius 1/4.
    np.testing.assert_allclose(starts[1].lengths, np.full(6, np.pi / 8), rtol=1e-12)
    assert [s.name for s in search_starts(CUBE, loop, user, canonical=False)] == ["user"]
    mid = check_conjugate_loop(CUBE, hexagon(*(0.25,) * 6))
    assert [s.name for s in search_starts(CUBE, mid, 3.0 * initial_lengths(CUBE, mid))] == ["user"]


def test_least_area_solution_wins_ties_go_to_the_earlier_start():
    ok = 0.1 * SOLVED_ENERGY
    # Both solve: the smaller area wins even with the higher energy.
    assert choose_run([ok / 10, ok], [1.0025, 1.0]) == 1
    # Areas within the tie: the same solution, the earlier start is kept.
    assert choose_run([ok, ok / 10], [1.0, 1.0 - 0.5 * AREA_TIE]) == 0
    # A run that is no solution never wins by area.
    assert choose_run([10 * SOLVED_ENERGY, ok], [0.5, 1.0]) == 1
    # No solution at all: the lowest energy, the first of equal ones.
    assert choose_run([1e-3, 1e-4, 1e-4], [1.0, 2.0, 0.5]) == 1
    assert choose_run([ok], [float("nan")]) == 0
