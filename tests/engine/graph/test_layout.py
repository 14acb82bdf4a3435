"""engine.graph.layout.layered_positions: columns by depth, fewer crossings, no overlaps."""

from __future__ import annotations

from itertools import combinations, permutations, product

import numpy as np
import pytest

from engine.graph.layout import fit_columns, layer_depths, layered_positions

CW, RH = 240.0, 110.0


# ------------------------------------------------------------ independent references

def ref_depths(ids, edges):
    """Longest path from a source by repeated relaxation (DAG only)."""
    d = {n: 0 for n in ids}
    for _ in range(len(ids)):
        for s, t in edges:
            d[t] = max(d[t], d[s] + 1)
    return d


def crossings(pos, edges):
    """Brute force: every pair of straight edges, proper intersection test."""
    def orient(a, b, c):
        return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    n = 0
    for (s1, t1), (s2, t2) in combinations(edges, 2):
        if {s1, t1} & {s2, t2}:
            continue
        p1, p2, q1, q2 = pos[s1], pos[t1], pos[s2], pos[t2]
        if (orient(q1, q2, p1) * orient(q1, q2, p2) < 0
                and orient(p1, p2, q1) * orient(p1, p2, q2) < 0):
            n += 1
    return n


def columns_in_input_order(ids, edges):
    d = ref_depths(ids, edges)
    cols = [[] for _ in range(max(d.values()) + 1)]
    for n in ids:
        cols[d[n]].append(n)
    return cols


def place(cols):
    tallest = max(len(c) for c in cols)
    return {n: (c * CW, (tallest - len(col)) * RH / 2 + r * RH)
            for c, col in enumerate(cols) for r, n in enumerate(col)}


def best_possible(ids, edges):
    """Fewest crossings over every row order of every column (same placement rule)."""
    cols = columns_in_input_order(ids, edges)
    return min(crossings(place(list(map(list, choice))), edges)
               for choice in product(*(permutations(c) for c in cols)))


def random_dag(rng, n, p):
    ids = [f"n{k}" for k in range(n)]
    order = rng.permutation(n)
    edges = [(ids[order[i]], ids[order[j]]) for i in range(n) for j in range(i + 1, n)
             if rng.random() < p]
    return ids, edges


def check_basic(ids, edges, pos):
    assert set(pos) == set(ids)
    # no two nodes share a cell of the grid (so none overlap)
    cells = {(round(x / CW * 2), round(y / RH * 2)) for x, y in pos.values()}
    assert len(cells) == len(ids)
    for a, b in combinations(ids, 2):
        (xa, ya), (xb, yb) = pos[a], pos[b]
        assert xa != xb or abs(ya - yb) >= RH - 1e-9
    for s, t in edges:
        assert pos[s][0] < pos[t][0], (s, t)
    d = ref_depths(ids, edges)
    for n in ids:
        assert pos[n][0] == pytest.approx(d[n] * CW)


# ------------------------------------------------------------ tests

def test_chain_is_one_row_and_columns_follow_depth():
    ids = ["a", "b", "c", "d"]
    edges = [("a", "b"), ("b", "c"), ("a", "d"), ("c", "d")]
    pos = layered_positions(ids, edges)
    check_basic(ids, edges, pos)
    assert pos["d"][0] == 3 * CW  # longest path a-b-c-d, not the short a-d


def test_two_layer_cross_is_untangled():
    ids = ["x", "y", "a", "b"]
    edges = [("x", "b"), ("y", "a")]
    naive = place(columns_in_input_order(ids, edges))
    assert crossings(naive, edges) == 1
    pos = layered_positions(ids, edges)
    check_basic(ids, edges, pos)
    assert crossings(pos, edges) == 0


@pytest.mark.parametrize("seed", range(12))
def test_small_random_graphs_reach_the_brute_force_optimum_or_near(seed):
    rng = np.random.default_rng(seed)
    ids, edges = random_dag(rng, int(rng.integers(4, 8)), 0.35)
    pos = layered_positions(ids, edges)
    check_basic(ids, edges, pos)
    got = crossings(pos, edges)
    naive = crossings(place(columns_in_input_order(ids, edges)), edges)
    best = best_possible(ids, edges)
    assert best <= got <= naive
    assert got <= best + 1


@pytest.mark.parametrize("seed", range(6))
def test_larger_graphs_never_worse_than_input_order(seed):
    rng = np.random.default_rng(100 + seed)
    ids, edges = random_dag(rng, 40, 0.06)
    pos = layered_positions(ids, edges)
    check_basic(ids, edges, pos)
    assert crossings(pos, edges) <= crossings(place(columns_in_input_order(ids, edges)), edges)


def test_bipartite_with_known_optimum():
    # a1..a3 -> b's in reversed order: input order has 3 crossings, 0 are possible
    ids = ["a1", "a2", "a3", "b1", "b2", "b3"]
    edges = [("a1", "b3"), ("a2", "b2"), ("a3", "b1")]
    pos = layered_positions(ids, edges)
    assert crossings(pos, edges) == 0 == best_possible(ids, edges)


def test_deterministic_and_spacing_used():
    rng = np.random.default_rng(7)
    ids, edges = random_dag(rng, 15, 0.2)
    a = layered_positions(ids, edges, column_width=300.0, row_height=90.0)
    b = layered_positions(list(ids), list(edges), column_width=300.0, row_height=90.0)
    assert a == b
    xs = sorted({x for x, _ in a.values()})
    assert xs == [300.0 * k for k in range(len(xs))]


def test_cycles_duplicates_and_self_loops_do_not_break_it():
    ids = ["a", "b", "c"]
    pos = layered_positions(ids, [("a", "b"), ("b", "c"), ("c", "a"), ("a", "a"), ("a", "b")])
    assert len({p for p in pos.values()}) == 3
    assert layer_depths(ids, [("a", "b"), ("b", "c"), ("c", "a")]) == {"a": 0, "b": 1, "c": 2}


def test_isolated_nodes_and_empty():
    assert layered_positions([], []) == {}
    pos = layered_positions(["p", "q", "r"], [])
    assert {x for x, _ in pos.values()} == {0.0}
    assert len({y for _, y in pos.values()}) == 3


def test_refusals_name_the_problem():
    with pytest.raises(ValueError, match="unknown node 'z'"):
        layered_positions(["a"], [("a", "z")])
    with pytest.raises(ValueError, match="more than once"):
        layered_positions(["a", "a"], [])
    with pytest.raises(ValueError, match="> 0"):
        layered_positions(["a"], [], column_width=0)


# -- bands: long chains of columns wrapped for a narrow editor ----------------------------------

def _chain(n):
    ids = [f"n{k}" for k in range(n)]
    return ids, list(zip(ids, ids[1:]))


def _branchy(seed, n=24):
    rng = np.random.default_rng(seed)
    ids = [f"v{k}" for k in range(n)]
    edges = [(ids[int(rng.integers(0, k))], ids[k]) for k in range(1, n)]
    edges += [(ids[a], ids[b]) for a, b in rng.integers(0, n, (8, 2)) if a < b]
    return ids, edges


@pytest.mark.parametrize("k", [1, 2, 3, 5])
def test_bands_keep_reading_order_and_never_overlap(k):
    for ids, edges in (_chain(13), _branchy(3), _branchy(8)):
        pos = layered_positions(ids, edges, column_width=200.0, row_height=100.0, max_columns=k)
        depth = layer_depths(ids, edges)
        band = {n: depth[n] // k for n in ids}
        assert {round(pos[n][0] / 200.0) for n in ids} <= set(range(k))
        for n in ids:
            assert pos[n][0] == pytest.approx((depth[n] % k) * 200.0)
        # every band lies wholly below the one before it (a row of nodes apart)
        for b in range(max(band.values())):
            low = max(pos[n][1] for n in ids if band[n] == b)
            high = min(pos[n][1] for n in ids if band[n] == b + 1)
            assert high >= low + 200.0 - 1e-9
        # edges read forward: to a later band, or to a later column of the same band
        for s, t in edges:
            if depth[s] < depth[t]:
                assert (band[s], pos[s][0]) < (band[t], pos[t][0])
        assert len({pos[n] for n in ids}) == len(ids)


def _drawn_scale(pos, view, node_size):
    xs = [p[0] for p in pos.values()]
    ys = [p[1] for p in pos.values()]
    width = max(xs) - min(xs) + node_size[0]
    height = max(ys) - min(ys) + node_size[1]
    return min(1.0, view[0] / width, view[1] / height)


@pytest.mark.parametrize("view", [(420.0, 640.0), (360.0, 900.0), (1800.0, 300.0), (800.0, 800.0)])
def test_fit_columns_picks_the_band_width_drawn_largest(view):
    """Reference: lay the graph out at every band width and measure its drawn size."""
    node = (180.0, 80.0)
    for ids, edges in (_chain(12), _branchy(5), _branchy(11, 30)):
        chosen = fit_columns(ids, edges, view, column_width=240.0, row_height=110.0, node_size=node)
        scales = {k: _drawn_scale(layered_positions(ids, edges, column_width=240.0, row_height=110.0,
                                                    max_columns=k), view, node)
                  for k in range(1, max(layer_depths(ids, edges).values()) + 2)}
        assert scales[chosen] == pytest.approx(max(scales.values()))
        assert all(k <= chosen for k, v in scales.items() if v == pytest.approx(scales[chosen]))
    ids, edges = _chain(12)
    assert fit_columns(ids, edges, (4000.0, 300.0)) == 12               # wide: one row
    assert fit_columns(ids, edges, (420.0, 640.0)) <= 3                 # a narrow dock: wrapped
    assert fit_columns(*_chain(2), (600.0, 400.0)) == 2                 # fits at 1:1: one row


def test_band_refusals():
    ids, edges = _chain(3)
    for bad in (0, -2, 1.5, True):
        with pytest.raises(ValueError, match="max_columns"):
            layered_positions(ids, edges, max_columns=bad)
    with pytest.raises(ValueError, match="band_gap"):
        layered_positions(ids, edges, max_columns=2, band_gap=-1.0)
    with pytest.raises(ValueError, match="view"):
        fit_columns(ids, edges, (0.0, 100.0))
