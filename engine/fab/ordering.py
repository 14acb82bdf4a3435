"""Print order of a layer's paths: short travel between extrusions.

Open paths may be printed in either direction; closed loops (first point
repeated at the end) may be entered at any vertex. The order is a greedy
nearest-neighbour tour over the entry points, improved by 2-opt moves (a
block of consecutive paths is reversed, each path in it flipped); tiny sets
of open paths are solved exactly (Held-Karp over subsets and directions).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._polyline import CLOSED_EPS

EXACT_BELOW = 8          # exact search for up to this many open paths
MAX_TWO_OPT_PASSES = 25
_GAIN_EPS = 1e-9         # mm; smaller gains are ties (keeps results stable)


def is_closed(path) -> bool:
    """True when ``path`` (m, 2) returns to its first point."""
    return (len(path) > 2 and abs(path[0, 0] - path[-1, 0]) < CLOSED_EPS
            and abs(path[0, 1] - path[-1, 1]) < CLOSED_EPS)


def travel_length(paths, start=(0.0, 0.0)) -> float:
    """Total travel (mm) from ``start`` through ``paths`` in the given order
    and direction: start -> first point, last point -> next first point."""
    pos = np.asarray(start, dtype=np.float64)
    total = 0.0
    for p in paths:
        total += math.hypot(p[0, 0] - pos[0], p[0, 1] - pos[1])
        pos = p[-1]
    return total


@njit(cache=True, nogil=True)
def _greedy(cand, cand_exit, cand_path, n, x0, y0):
    used = np.zeros(n, np.bool_)
    pick = np.empty(n, np.int64)
    px, py = x0, y0
    for step in range(n):
        best = np.inf
        bi = -1
        for k in range(cand.shape[0]):
            if used[cand_path[k]]:
                continue
            dx = cand[k, 0] - px
            dy = cand[k, 1] - py
            d = dx * dx + dy * dy
            if d < best:
                best = d
                bi = k
        used[cand_path[bi]] = True
        pick[step] = bi
        px = cand_exit[bi, 0]
        py = cand_exit[bi, 1]
    return pick


@njit(cache=True, nogil=True)
def _dist(ax, ay, bx, by):
    return np.hypot(ax - bx, ay - by)


@njit(cache=True, nogil=True)
def _two_opt(S, E, order, flip, x0, y0, max_passes, eps):
    """Improve in place; S/E are the entry/exit points in print order."""
    n = S.shape[0]
    for _ in range(max_passes):
        improved = False
        for i in range(n):
            if i == 0:
                ax, ay = x0, y0
            else:
                ax, ay = E[i - 1, 0], E[i - 1, 1]
            for j in range(i, n):
                old = _dist(ax, ay, S[i, 0], S[i, 1])
                new = _dist(ax, ay, E[j, 0], E[j, 1])
                if j + 1 < n:
                    old += _dist(E[j, 0], E[j, 1], S[j + 1, 0], S[j + 1, 1])
                    new += _dist(S[i, 0], S[i, 1], S[j + 1, 0], S[j + 1, 1])
                if new < old - eps:
                    lo, hi = i, j
                    while lo < hi:
                        for c in range(2):
                            t = S[lo, c]
                            S[lo, c] = E[hi, c]
                            E[hi, c] = t
                            t = E[lo, c]
                            E[lo, c] = S[hi, c]
                            S[hi, c] = t
                        t2 = order[lo]
                        order[lo] = order[hi]
                        order[hi] = t2
                        fl = flip[lo]
                        flip[lo] = not flip[hi]
                        flip[hi] = not fl
                        lo += 1
                        hi -= 1
                    if lo == hi:
                        for c in range(2):
                            t = S[lo, c]
                            S[lo, c] = E[lo, c]
                            E[lo, c] = t
                        flip[lo] = not flip[lo]
                    improved = True
        if not improved:
            break


@njit(cache=True, nogil=True)
def _held_karp(ends, x0, y0):
    """Exact shortest travel for open paths; ``ends[p, d]`` is the entry
    point of path ``p`` printed in direction ``d`` (its exit is ``ends[p, 1-d]``)."""
    n = ends.shape[0]
    full = 1 << n
    cost = np.full((full, n, 2), np.inf)
    prev = np.full((full, n, 2), -1, np.int64)
    for p in range(n):
        for d in range(2):
            cost[1 << p, p, d] = _dist(x0, y0, ends[p, d, 0], ends[p, d, 1])
    for mask in range(1, full):
        for p in range(n):
            if not (mask >> p) & 1:
                continue
            for d in range(2):
                c = cost[mask, p, d]
                if c == np.inf:
                    continue
                ex, ey = ends[p, 1 - d, 0], ends[p, 1 - d, 1]
                for q in range(n):
                    if (mask >> q) & 1:
                        continue
                    m2 = mask | (1 << q)
                    for e in range(2):
                        c2 = c + _dist(ex, ey, ends[q, e, 0], ends[q, e, 1])
                        if c2 < cost[m2, q, e] - 1e-12:
                            cost[m2, q, e] = c2
                            prev[m2, q, e] = p * 2 + d
    best = np.inf
    bp, bd = 0, 0
    for p in range(n):
        for d in range(2):
            if cost[full - 1, p, d] < best - 1e-12:
                best = cost[full - 1, p, d]
                bp, bd = p, d
    order = np.empty(n, np.int64)
    flip = np.empty(n, np.bool_)
    mask = full - 1
    for k in range(n - 1, -1, -1):
        order[k] = bp
        flip[k] = bd == 1
        pr = prev[mask, bp, bd]
        mask &= ~(1 << bp)
        bp, bd = pr // 2, pr % 2
    return order, flip


def _candidates(paths, closed):
    """Entry points with their exit point and path index."""
    cand, exits, owner, vertex = [], [], [], []
    for i, (p, c) in enumerate(zip(paths, closed)):
        if c:
            ring = p[:-1]
            cand.append(ring)
            exits.append(ring)
            owner.append(np.full(len(ring), i))
            vertex.append(np.arange(len(ring)))
        else:
            cand.append(p[[0, -1]])
            exits.append(p[[-1, 0]])
            owner.append(np.array([i, i]))
            vertex.append(np.array([0, -1]))
    return (np.concatenate(cand), np.concatenate(exits),
            np.concatenate(owner).astype(np.int64), np.concatenate(vertex))


def _orient(path, closed, entry):
    """``path`` printed from vertex ``entry`` (loops) or reversed (entry -1)."""
    if closed:
        ring = path[:-1]
        return np.concatenate([ring[entry:], ring[:entry], ring[entry:entry + 1]])
    return path[::-1].copy() if entry == -1 else path


def order_paths(paths, *, start=(0.0, 0.0), improve=True, exact_below=EXACT_BELOW):
    """Reorder and reorient paths so the travel between them is short.

    Parameters
    ----------
    paths : sequence of (m, 2) float64
        mm; a path whose last point equals its first is a closed loop.
    start : (2,) float
        Nozzle position before the first path.
    improve : bool
        Apply 2-opt moves after the greedy tour.
    exact_below : int
        Up to this many paths, all open, the optimum is found exactly.

    Returns
    -------
    ordered : list of (m, 2) float64
        The same paths (reversed or, for loops, rotated) in print order. The
        travel is never longer than that of the input order.
    """
    paths = [np.asarray(p, dtype=np.float64) for p in paths]
    paths = [p for p in paths if len(p) >= 2]
    n = len(paths)
    if n == 0:
        return []
    x0, y0 = (float(v) for v in start)
    closed = [is_closed(p) for p in paths]
    if n <= exact_below and not any(closed):
        ends = np.stack([np.stack([p[0], p[-1]]) for p in paths])
        order, flip = _held_karp(ends, x0, y0)
        return [paths[i][::-1].copy() if f else paths[i] for i, f in zip(order, flip)]

    cand, exits, owner, vertex = _candidates(paths, closed)
    pick = _greedy(cand, exits, owner, n, x0, y0)
    ordered = [_orient(paths[i], c, e) for i, e in zip(owner[pick], vertex[pick])
               for c in [closed[i]]]
    if improve:
        ordered = _improve(ordered, x0, y0)
    # The greedy tour is almost always far shorter than the given order; in
    # the rare case it is not, improving the given order keeps the promise.
    given = travel_length(paths, (x0, y0))
    if travel_length(ordered, (x0, y0)) > given:
        ordered = _improve(paths, x0, y0) if improve else paths
        if travel_length(ordered, (x0, y0)) > given:
            ordered = paths
    return list(ordered)


def _improve(ordered, x0, y0):
    S = np.array([p[0] for p in ordered])
    E = np.array([p[-1] for p in ordered])
    order = np.arange(len(ordered))
    flip = np.zeros(len(ordered), np.bool_)
    _two_opt(S, E, order, flip, x0, y0, MAX_TWO_OPT_PASSES, _GAIN_EPS)
    return [ordered[i][::-1].copy() if f else ordered[i] for i, f in zip(order, flip)]
