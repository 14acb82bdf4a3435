"""The weights a brush dragged on a slice plane gives the cells of a regular grid.

The one brush of every painted field: the phasor control fields
(`engine.phasor.strokes`) and the scalar fields of `engine.geometry.scalar_field`
both weight their cells here, so a stroke means the same on either.

Grid
----
A box ``lo`` (mm, ``(x, y, z)`` order) cut into cells of ``spacing`` (mm,
``(x, y, z)``), ``shape = (nz, ny, nx)`` of them, one sample at each cell
centre ``lo + (i + 0.5) * spacing``; arrays are indexed ``[z, y, x]``.

In-plane coordinates
--------------------
A brush on the plane normal to ``axis`` at ``position`` mm has points
``(u, v)`` in mm on the two other axes in x, y, z order::

    axis "z": (u, v) = (x, y)     axis "y": (u, v) = (x, z)     axis "x": (u, v) = (y, z)

Weight
------
For a cell centre with in-plane distance ``d`` to the polyline and offset
``n`` from the plane, the brush sees the distance
``s = sqrt(d**2 + (n * radius / depth)**2) / radius`` (with ``depth ==
radius`` this is the plain 3-D distance to the polyline over the radius), and
weights the cell by ``w = strength * falloff(s)``, zero for ``s >= 1``::

    constant: 1          linear: 1 - s          smooth: 1 - 3 s**2 + 2 s**3

Only the block of cells whose centres can lie within reach is computed
(`brush_block`): a stroke costs its own footprint, not the grid.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["PLANE_AXES", "FALLOFFS", "falloff", "drag_segments", "polyline_distance", "brush_block",
           "block_coords", "plane_brush"]

FALLOFFS = ("smooth", "linear", "constant")
# plane axis -> (u, v, normal) as indices into (x, y, z)
PLANE_AXES = {"x": (1, 2, 0), "y": (0, 2, 1), "z": (0, 1, 2)}


def falloff(s, kind: str) -> np.ndarray:
    """The brush profile at normalised distance ``s`` (array, >= 0): 1 at 0, 0 from 1 on.

    kind : "smooth" (1 - 3 s^2 + 2 s^3), "linear" (1 - s) or "constant" (1).
    """
    inside = s < 1.0
    if kind == "constant":
        return inside.astype(np.float64)
    if kind == "linear":
        return np.where(inside, 1.0 - s, 0.0)
    return np.where(inside, 1.0 - s * s * (3.0 - 2.0 * s), 0.0)


def drag_segments(points):
    """Segment starts (m, 2) and ends (m, 2) of a (k, 2) polyline, repeated points dropped."""
    keep = np.ones(len(points), dtype=bool)
    keep[1:] = np.any(points[1:] != points[:-1], axis=1)
    p = points[keep]
    return p[:-1], p[1:]


def _index_range(lo, step, n, a, b):
    """Cells whose centres may lie in [a, b] along one axis, as (start, stop)."""
    start = max(int(math.floor((a - lo) / step - 0.5)), 0)
    stop = min(int(math.ceil((b - lo) / step - 0.5)) + 1, n)
    return start, max(start, stop)


def brush_block(lo, spacing, shape, axis: str, position: float, points, radius: float, reach: float):
    """Index ranges ((k0, k1), (j0, j1), (i0, i1)) of the cells that can hold brushed cells.

    lo, spacing : (3,) mm, ``(x, y, z)``; shape : (nz, ny, nx)
    points : (k, 2) in-plane mm; radius : in-plane reach, mm; reach : out-of-plane reach, mm
    """
    u, v, n = PLANE_AXES[axis]
    lo_xyz = np.empty(3)
    hi_xyz = np.empty(3)
    lo_xyz[[u, v]] = points.min(axis=0) - radius
    hi_xyz[[u, v]] = points.max(axis=0) + radius
    lo_xyz[n], hi_xyz[n] = position - reach, position + reach
    counts = tuple(shape)[::-1]
    ranges = [_index_range(lo[a], spacing[a], counts[a], lo_xyz[a], hi_xyz[a]) for a in range(3)]
    return ranges[::-1]


def block_coords(lo, spacing, ranges):
    """Cell-centre x, y, z over a block, each shaped to broadcast as [z, y, x]."""
    out = []
    for a, (start, stop) in zip(range(3), ranges[::-1]):
        c = lo[a] + (np.arange(start, stop) + 0.5) * spacing[a]
        shape = [1, 1, 1]
        shape[2 - a] = len(c)
        out.append(c.reshape(shape))
    return out


def polyline_distance(pu, pv, points):
    """Squared in-plane distance of (pu, pv) to the (k, 2) polyline ``points`` and the index of
    the nearest drag segment (None when the polyline never moves: the distance is to its point)."""
    starts, ends = drag_segments(points)
    if len(starts) == 0:
        a = points[0]
        return (pu - a[0]) ** 2 + (pv - a[1]) ** 2, None
    best = np.full(np.broadcast_shapes(pu.shape, pv.shape), np.inf)
    which = np.zeros(best.shape, dtype=np.intp)
    for m, (a, b) in enumerate(zip(starts, ends)):
        e = b - a
        t = np.clip(((pu - a[0]) * e[0] + (pv - a[1]) * e[1]) / (e @ e), 0.0, 1.0)
        d2 = (pu - a[0] - t * e[0]) ** 2 + (pv - a[1] - t * e[1]) ** 2
        closer = d2 < best
        best = np.where(closer, d2, best)
        which = np.where(closer, m, which)
    return best, which


def plane_brush(lo, spacing, shape, *, axis: str, position: float, points, radius: float, reach: float,
                strength: float, kind: str):
    """The brush's weights over the block of cells it can reach.

    Parameters
    ----------
    lo, spacing : (3,) float, mm, ``(x, y, z)``: the grid (module docstring)
    shape : (nz, ny, nx)
    axis : "x" | "y" | "z"; position : mm, the plane's coordinate along ``axis``
    points : (k, 2) float64, in-plane mm, k >= 1
    radius, reach : mm, > 0: in-plane radius and out-of-plane depth
    strength : [0, 1]; kind : one of `FALLOFFS`

    Returns
    -------
    ranges : ((k0, k1), (j0, j1), (i0, i1)), the block (`brush_block`)
    w : block-shaped float64 weights in [0, strength]
    which : block-shaped intp index of the nearest drag segment, or None (a still brush)
    """
    ranges = brush_block(lo, spacing, shape, axis, position, points, radius, reach)
    u, v, n = PLANE_AXES[axis]
    coords = block_coords(lo, spacing, ranges)
    d2, which = polyline_distance(coords[u], coords[v], points)
    dn = (coords[n] - position) * (radius / reach)
    s = np.sqrt(d2 + dn * dn) / radius
    return ranges, strength * falloff(s, kind), which
