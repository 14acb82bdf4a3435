import itertools

import numpy as np
import pytest

from engine.fab import order_paths, travel_length
from engine.fab.contours import frontier_walls


def brute_force_travel(paths, start):
    best = np.inf
    for perm in itertools.permutations(range(len(paths))):
        for flips in itertools.product((False, True), repeat=len(paths)):
            seq = [paths[i][::-1] if f else paths[i] for i, f in zip(perm, flips)]
            best = min(best, travel_length(seq, start))
    return best


def same_paths(a, b):
    """Each output path is an input path, possibly reversed (open paths)."""
    left = [p for p in b]
    for p in a:
        for i, q in enumerate(left):
            if p.shape == q.shape and (np.array_equal(p, q) or np.array_equal(p, q[::-1])):
                del left[i]
                break
        else:
            return False
    return not left


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_four_paths_match_exhaustive_optimum(seed):
    rng = np.random.default_rng(seed)
    paths = [rng.uniform(0, 10, (rng.integers(2, 5), 2)) for _ in range(4)]
    start = (0.0, 0.0)
    ordered = order_paths(paths, start=start)
    assert same_paths(ordered, paths)
    assert travel_length(ordered, start) == pytest.approx(brute_force_travel(paths, start))


def test_heuristic_never_worse_than_input_and_keeps_paths(diamonds):
    walls = frontier_walls(diamonds(120, 0.1, z=1.3), None, pixel_size=0.1, inset=0.4)
    assert len(walls) > 20
    start = (-5.0, -5.0)
    ordered = order_paths(walls, start=start)
    assert len(ordered) == len(walls)
    unordered = travel_length(walls, start)
    assert travel_length(ordered, start) <= unordered
    assert travel_length(ordered, start) < 0.6 * unordered
    # loops are re-entered at some vertex, still closed, same vertex set
    for p in ordered:
        if np.allclose(p[0], p[-1]):
            match = [w for w in walls if len(w) == len(p) and
                     set(map(tuple, w[:-1])) == set(map(tuple, p[:-1]))]
            assert match


def test_greedy_without_exact_search_on_a_small_case():
    # three collinear segments given in the worst order: greedy + 2-opt
    # finds the obvious sweep
    paths = [np.array([[4.0, 0], [5, 0]]), np.array([[0.0, 0], [1, 0]]),
             np.array([[3.0, 0], [2, 0]])]
    ordered = order_paths(paths, start=(0, 0), exact_below=0)
    assert travel_length(ordered, (0, 0)) == pytest.approx(2.0)
    assert order_paths([], start=(0, 0)) == []
