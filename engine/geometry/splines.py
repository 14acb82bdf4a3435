"""Interpolating curves through edge-chain vertices (paper section 5.2).

A smooth chain becomes a cubic spline with C2 continuity, parametrised by
chord length, evaluated densely into a polyline that passes exactly through
the input points:

* open chains use natural end conditions (zero curvature at both ends);
  three points give the single parabola through them, two a straight line;
* closed loops use periodic conditions, so the seam is C2 as well;
* chains with a ``period`` translation ``t`` are one period of an infinite
  curve ``C(u + U) = C(u) + t``; they are periodic splines in which the knot
  after the last one is ``points[0] + t``, so the curve tiles with C2
  continuity across the cell face it crosses.

Convention for the spline on knots ``u_i`` with spacing ``h_i`` and unknown
second derivatives ``M_i`` (one per knot)::

    S(u) = a P_i + b P_{i+1} + h_i^2/6 ((a^3 - a) M_i + (b^3 - b) M_{i+1}),
    b = (u - u_i) / h_i,  a = 1 - b,

which interpolates and has continuous S'' by construction; C1 continuity at
every interior knot gives the classic tridiagonal system
``h_{i-1} M_{i-1} + 2 (h_{i-1} + h_i) M_i + h_i M_{i+1} = 6 (D_i - D_{i-1})``
with ``D_i = (P_{i+1} - P_i) / h_i``.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import solve_banded

__all__ = ["interpolate_chain", "arc_length_parameter"]


def _as_points(points, name="points", min_count=2):
    arr = np.asarray(points, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"{name} must have shape (n, 3); got shape {arr.shape}")
    if arr.shape[0] < min_count:
        raise ValueError(f"{name} must hold at least {min_count} points; got {arr.shape[0]}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite; got NaN or inf in {name}")
    return arr


def _same_point(p, q, scale):
    # Relative tolerance: points typed by a user or produced by a transform
    # should count as identical despite round-off.
    return float(np.linalg.norm(p - q)) <= 1e-9 * max(1.0, scale)


def _chord_knots(nodes):
    h = np.linalg.norm(np.diff(nodes, axis=0), axis=1)
    bad = np.flatnonzero(h <= 1e-12 * max(1.0, float(np.abs(nodes).max())))
    if bad.size:
        i = int(bad[0])
        raise ValueError(
            f"points {i} and {i + 1} coincide ({nodes[i].tolist()}); a smooth chain "
            "needs distinct consecutive points")
    return h


def _natural_second_derivatives(nodes, h):
    """M (n,3) for a natural spline: M_0 = M_{n-1} = 0, tridiagonal inside."""
    n = nodes.shape[0]
    m = np.zeros_like(nodes)
    if n < 3:
        return m
    d = np.diff(nodes, axis=0) / h[:, None]
    rhs = 6.0 * (d[1:] - d[:-1])                        # (n-2, 3)
    ab = np.zeros((3, n - 2))
    ab[0, 1:] = h[1:-1]                                 # super-diagonal
    ab[1, :] = 2.0 * (h[:-1] + h[1:])                   # diagonal
    ab[2, :-1] = h[1:-1]                                # sub-diagonal
    m[1:-1] = solve_banded((1, 1), ab, rhs)
    return m


def _periodic_second_derivatives(nodes, h):
    """M (m,3) for a periodic spline over nodes Q_0..Q_m (Q_m = Q_0 + t).

    Dense solve: the matrix is cyclic tridiagonal and m is the number of
    user-placed vertices in one chain (tens), so O(m^3) is irrelevant and
    accumulating with ``+=`` keeps m = 1 and m = 2 (where neighbours alias)
    correct without special cases.
    """
    m = h.shape[0]
    d = np.diff(nodes, axis=0) / h[:, None]             # (m, 3)
    a = np.zeros((m, m))
    rhs = np.empty((m, 3))
    for i in range(m):
        hp, hn = h[i - 1], h[i]                         # h[-1] wraps around
        a[i, (i - 1) % m] += hp
        a[i, i] += 2.0 * (hp + hn)
        a[i, (i + 1) % m] += hn
        rhs[i] = 6.0 * (d[i] - d[i - 1])
    return np.linalg.solve(a, rhs)


def _evaluate(nodes, h, mk, samples):
    """Sample every segment at ``samples`` uniform parameter steps."""
    nseg = h.shape[0]
    b = np.arange(samples, dtype=np.float64) / samples  # [0, 1)
    a = 1.0 - b
    out = np.empty((nseg * samples + 1, 3))
    for i in range(nseg):
        j = (i + 1) % mk.shape[0]                       # periodic M wraps
        curv = (h[i] ** 2 / 6.0) * ((a ** 3 - a)[:, None] * mk[i] + (b ** 3 - b)[:, None] * mk[j])
        out[i * samples:(i + 1) * samples] = a[:, None] * nodes[i] + b[:, None] * nodes[i + 1] + curv
        out[i * samples] = nodes[i]                     # knots exact, not merely close
    out[-1] = nodes[-1]
    return out


def _quadratic(nodes, samples):
    """The parabola through three points, Lagrange form on chord-length knots."""
    h = _chord_knots(nodes)
    u = np.concatenate([[0.0], np.cumsum(h)])
    params = np.concatenate([np.linspace(u[i], u[i + 1], samples, endpoint=False)
                             for i in range(2)] + [[u[2]]])
    l0 = (params - u[1]) * (params - u[2]) / ((u[0] - u[1]) * (u[0] - u[2]))
    l1 = (params - u[0]) * (params - u[2]) / ((u[1] - u[0]) * (u[1] - u[2]))
    l2 = (params - u[0]) * (params - u[1]) / ((u[2] - u[0]) * (u[2] - u[1]))
    out = l0[:, None] * nodes[0] + l1[:, None] * nodes[1] + l2[:, None] * nodes[2]
    out[::samples] = nodes
    return out


def interpolate_chain(points, *, smooth, closed=False, period=None, samples_per_segment=16):
    """Turn an edge chain into a polyline, smooth (C2 spline) or straight.

    Parameters
    ----------
    points : array_like, shape (n, 3), float
        Chain vertices in order, n >= 2 (n >= 3 for ``closed``). For a closed
        loop pass each vertex once; a repeated first point at the end is
        tolerated and dropped.
    smooth : bool
        False: the straight polyline through the points. True: a cubic spline
        with C2 continuity parametrised by chord length (natural for open
        chains, periodic for closed or periodic ones); an open chain of three
        points gives the parabola through them, of two the straight segment.
    closed : bool, optional
        The chain is a loop: the last point connects back to the first.
    period : array_like, shape (3,), optional
        Translation ``t`` (model units, non-zero) under which the curve
        repeats. If ``points[-1] == points[0] + t`` that last point is the
        start of the next period; otherwise the curve is continued from
        ``points[-1]`` to ``points[0] + t``. Either way the result runs from
        ``points[0]`` to ``points[0] + t`` and its tangent and curvature at the
        end equal those at the start. Exclusive with ``closed``.
    samples_per_segment : int, optional
        Polyline points per spline segment (>= 1); ignored when not smooth.

    Returns
    -------
    numpy.ndarray, shape (m, 3), float64
        Polyline containing every input point exactly. Smooth results have
        ``m = segments * samples_per_segment + 1``; a closed result ends with
        a copy of its first point, a periodic one with ``points[0] + t``.
        Straight open chains are returned unchanged (as a copy).

    Raises
    ------
    ValueError
        On bad shapes, non-finite values, too few points, coincident
        consecutive points in a smooth chain, a zero period, or ``closed``
        together with ``period``.
    """
    pts = _as_points(points)
    if isinstance(samples_per_segment, bool) or not isinstance(samples_per_segment, (int, np.integer)) \
            or samples_per_segment < 1:
        raise ValueError(f"samples_per_segment must be an integer >= 1; got {samples_per_segment!r}")
    sps = int(samples_per_segment)
    scale = float(np.ptp(pts, axis=0).max()) if pts.shape[0] > 1 else 1.0

    if closed and period is not None:
        raise ValueError(f"closed=True and period={period!r} are exclusive; a periodic "
                         "chain is already closed up to the translation")

    if closed:
        if pts.shape[0] > 2 and _same_point(pts[-1], pts[0], scale):
            pts = pts[:-1]
        if pts.shape[0] < 3:
            raise ValueError(f"points must hold at least 3 distinct points for closed=True; "
                             f"got {pts.shape[0]}")
        nodes = np.vstack([pts, pts[:1]])
    elif period is not None:
        t = np.asarray(period, dtype=np.float64)
        if t.shape != (3,) or not np.all(np.isfinite(t)):
            raise ValueError(f"period must be a finite (3,) translation vector; got {period!r}")
        if float(np.linalg.norm(t)) <= 1e-12:
            raise ValueError(f"period must be a non-zero translation; got {t.tolist()}")
        if _same_point(pts[-1], pts[0] + t, max(scale, float(np.linalg.norm(t)))):
            pts = pts[:-1]
        nodes = np.vstack([pts, pts[:1] + t])
    else:
        nodes = pts

    if not smooth:
        return nodes.copy()

    if closed or period is not None:
        h = _chord_knots(nodes)
        return _evaluate(nodes, h, _periodic_second_derivatives(nodes, h), sps)
    if nodes.shape[0] == 2:
        _chord_knots(nodes)
        b = np.arange(sps + 1, dtype=np.float64)[:, None] / sps
        out = (1.0 - b) * nodes[0] + b * nodes[1]
        out[-1] = nodes[1]
        return out
    if nodes.shape[0] == 3:
        return _quadratic(nodes, sps)
    h = _chord_knots(nodes)
    return _evaluate(nodes, h, _natural_second_derivatives(nodes, h), sps)


def arc_length_parameter(polyline):
    """Normalised arc length at each polyline vertex.

    Parameters
    ----------
    polyline : array_like, shape (m, 3), float
        m >= 2 points with non-zero total length.

    Returns
    -------
    numpy.ndarray, shape (m,), float64
        Non-decreasing values, 0 at the first vertex and exactly 1 at the last.
    """
    pts = _as_points(polyline, name="polyline")
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    total = float(seg.sum())
    if total <= 0.0:
        raise ValueError(f"polyline must have non-zero length; all {pts.shape[0]} points coincide")
    s = np.concatenate([[0.0], np.cumsum(seg)]) / total
    s[-1] = 1.0
    return s
