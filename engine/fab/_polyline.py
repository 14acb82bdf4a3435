"""Compiled polyline kernels: clip to a level set, Douglas-Peucker, spacing.

Polylines travel as one flat ``(N, 2) float64`` array plus ``offsets`` of
length ``C + 1`` (polyline ``c`` is ``pts[offsets[c]:offsets[c + 1]]``), so
a whole layer is processed in one compiled call. A polyline is *closed*
when its first and last points coincide.
"""

from __future__ import annotations

import numpy as np
from numba import njit

CLOSED_EPS = 1e-9      # mm; first == last within this means a closed loop


@njit(cache=True, nogil=True)
def _segment_dist2(px, py, ax, ay, bx, by):
    dx, dy = bx - ax, by - ay
    ex, ey = px - ax, py - ay
    l2 = dx * dx + dy * dy
    if l2 > 0.0:
        t = (ex * dx + ey * dy) / l2
        if t < 0.0:
            t = 0.0
        elif t > 1.0:
            t = 1.0
        ex -= t * dx
        ey -= t * dy
    return ex * ex + ey * ey


@njit(cache=True, nogil=True)
def douglas_peucker_keep(pts, tol):
    """Vertices kept by Douglas-Peucker at tolerance ``tol``.

    Distances are to the chord *segment* (not its line), so a closed loop,
    whose first chord has zero length, splits at its farthest vertex.

    Parameters
    ----------
    pts : (m, 2) float64
    tol : float
        Maximum distance of a dropped vertex from the kept chord.

    Returns
    -------
    keep : (m,) bool
    """
    m = pts.shape[0]
    keep = np.zeros(m, np.bool_)
    if m <= 2 or tol <= 0.0:
        keep[:] = True
        return keep
    keep[0] = True
    keep[m - 1] = True
    stack = np.empty((m + 1, 2), np.int64)
    stack[0, 0] = 0
    stack[0, 1] = m - 1
    top = 1
    tol2 = tol * tol
    while top > 0:
        top -= 1
        a = stack[top, 0]
        b = stack[top, 1]
        best = -1.0
        idx = -1
        for k in range(a + 1, b):
            d = _segment_dist2(pts[k, 0], pts[k, 1], pts[a, 0], pts[a, 1], pts[b, 0], pts[b, 1])
            if d > best:
                best = d
                idx = k
        if idx >= 0 and best > tol2:
            keep[idx] = True
            stack[top, 0] = a
            stack[top, 1] = idx
            stack[top + 1, 0] = idx
            stack[top + 1, 1] = b
            top += 2
    return keep


@njit(cache=True, nogil=True)
def _emit(buf, n, tol, min_spacing, min_length, out, count, offsets, nruns):
    """Simplify ``buf[:n]`` and append it to ``out`` as a new polyline if it
    is at least ``min_length`` long. Returns the new (count, nruns)."""
    if n < 2:
        return count, nruns
    keep = douglas_peucker_keep(buf[:n], tol)
    start = count
    lastx = buf[0, 0]
    lasty = buf[0, 1]
    out[count, 0] = lastx
    out[count, 1] = lasty
    count += 1
    sp2 = min_spacing * min_spacing
    for k in range(1, n):
        if not keep[k]:
            continue
        dx = buf[k, 0] - lastx
        dy = buf[k, 1] - lasty
        if k == n - 1:
            # The end point always survives; it replaces a too-close
            # predecessor (but never the start point).
            if dx * dx + dy * dy < sp2 and count - start > 1:
                count -= 1
        elif dx * dx + dy * dy < sp2:
            continue
        out[count, 0] = buf[k, 0]
        out[count, 1] = buf[k, 1]
        lastx = buf[k, 0]
        lasty = buf[k, 1]
        count += 1
    length = 0.0
    for k in range(start + 1, count):
        length += np.hypot(out[k, 0] - out[k - 1, 0], out[k, 1] - out[k - 1, 1])
    if count - start < 2 or length < min_length or length == 0.0:
        return start, nruns
    nruns += 1
    offsets[nruns] = count
    return count, nruns


@njit(cache=True, nogil=True)
def clip_simplify(pts, vals, offsets, level, tol, min_spacing, min_length):
    """Keep the parts of each polyline where ``vals >= level``, then simplify.

    The cut points are interpolated linearly in ``vals`` along the crossing
    edge. A closed polyline that leaves the region is re-entered at an
    outside vertex first, so the piece spanning its seam stays in one run.

    Parameters
    ----------
    pts : (N, 2) float64
    vals : (N,) float64
        Scalar per vertex (e.g. distance inside the part, mm).
    offsets : (C + 1,) int64
    level : float
    tol, min_spacing, min_length : float
        Douglas-Peucker tolerance, minimal distance between consecutive kept
        vertices, minimal length of an output polyline (all mm).

    Returns
    -------
    out : (M, 2) float64
    out_offsets : (R + 1,) int64
    """
    total = pts.shape[0]
    ncurves = offsets.shape[0] - 1
    out = np.empty((2 * total + 2, 2), np.float64)
    out_offsets = np.zeros(total + 2, np.int64)
    buf = np.empty((total + 2, 2), np.float64)
    count = 0
    nruns = 0
    for c in range(ncurves):
        o0 = offsets[c]
        n = offsets[c + 1] - o0
        if n < 2:
            continue
        closed = (abs(pts[o0, 0] - pts[o0 + n - 1, 0]) < CLOSED_EPS
                  and abs(pts[o0, 1] - pts[o0 + n - 1, 1]) < CLOSED_EPS and n > 2)
        first_out = -1
        for k in range(n):
            if not vals[o0 + k] >= level:
                first_out = k
                break
        if first_out < 0:
            for k in range(n):
                buf[k, 0] = pts[o0 + k, 0]
                buf[k, 1] = pts[o0 + k, 1]
            count, nruns = _emit(buf, n, tol, min_spacing, min_length,
                                 out, count, out_offsets, nruns)
            continue
        # Walk the vertices; a closed loop starts at an outside vertex and
        # visits its n - 1 distinct vertices plus the start again.
        steps = n
        shift = 0
        m = n
        if closed:
            m = n - 1
            shift = first_out
        nb = 0
        for i in range(steps):
            k = o0 + (i + shift) % m
            inside = vals[k] >= level
            if i > 0:
                kp = o0 + (i - 1 + shift) % m
                was = vals[kp] >= level
                if inside != was:
                    t = (vals[kp] - level) / (vals[kp] - vals[k])
                    buf[nb, 0] = pts[kp, 0] + t * (pts[k, 0] - pts[kp, 0])
                    buf[nb, 1] = pts[kp, 1] + t * (pts[k, 1] - pts[kp, 1])
                    nb += 1
                    if was:                       # leaving: close the run
                        count, nruns = _emit(buf, nb, tol, min_spacing, min_length,
                                             out, count, out_offsets, nruns)
                        nb = 0
            if inside:
                buf[nb, 0] = pts[k, 0]
                buf[nb, 1] = pts[k, 1]
                nb += 1
        if nb > 0:
            count, nruns = _emit(buf, nb, tol, min_spacing, min_length,
                                 out, count, out_offsets, nruns)
    return out[:count], out_offsets[:nruns + 1]


def split_flat(out, offsets):
    """List of ``(m, 2)`` float64 arrays from a flat array and its offsets."""
    return [np.ascontiguousarray(out[a:b]) for a, b in zip(offsets[:-1], offsets[1:])]


def flatten(polylines):
    """Flat ``(N, 2)`` float64 array and ``(C + 1,)`` int64 offsets."""
    if not polylines:
        return np.zeros((0, 2)), np.zeros(1, np.int64)
    lengths = np.fromiter((len(p) for p in polylines), np.int64, len(polylines))
    offsets = np.zeros(len(polylines) + 1, np.int64)
    np.cumsum(lengths, out=offsets[1:])
    return np.ascontiguousarray(np.concatenate(polylines), dtype=np.float64), offsets
