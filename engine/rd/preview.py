"""Pictures of reaction/diffusion inputs and structures, as plain arrays.

What the RD dock draws, computed without any GUI so that it can be tested
and used from a notebook:

* axis-aligned slices of ``[y, x]`` / ``[z, y, x]`` grids (`grid_slice`),
  with the in-plane coordinates ``(u, v)`` of each slice normal
  (`PLANE_AXES`) and the cell a point of a slice lies in (`slice_point`);
* the principal directions of a rotation field as short line glyphs
  sampled on a coarse lattice (`principal_glyphs`), or as streamlines
  (`principal_streamlines`), both in slice cell units;
* a brush drag turned into stamp centres no further apart than half the
  brush radius (`stroke_centres`), so that a fast drag leaves no gaps.

Conventions (shared with ``engine.rd.values``): grids are indexed
``[y, x]`` or ``[z, y, x]``; vector and rotation components are ordered
``(x, y[, z])``; a point ``(x, y[, z])`` in cell units lies in cell
``[floor(y), floor(x)]``, cell centres sit at half-integers. A slice normal
to ``z`` has ``(u, v) = (x, y)``, normal to ``y`` ``(x, z)``, normal to
``x`` ``(y, z)``; a slice image is indexed ``[v, u]``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["AXES", "PLANE_AXES", "grid_slice", "slice_shape", "slice_point", "rescale_index",
           "GlyphSet", "principal_glyphs", "glyph_segments", "principal_streamlines", "stroke_centres"]

AXES = ("x", "y", "z")
#: components (indices into (x, y, z)) of the in-plane axes (u, v) of a slice normal to each axis
PLANE_AXES = {"z": (0, 1), "y": (0, 2), "x": (1, 2)}
#: the grid axis (of [z, y, x]) each slice normal runs along
_GRID_AXIS = {"z": 0, "y": 1, "x": 2}


def _check_axis(axis) -> str:
    if axis not in PLANE_AXES:
        raise ValueError(f"slice axis must be one of 'x', 'y', 'z'; got {axis!r}")
    return axis


def _grid_ndim(values, ndim):
    nd = np.ndim(values) if ndim is None else int(ndim)
    if nd not in (2, 3) or np.ndim(values) < nd:
        raise ValueError(f"a grid has 2 or 3 axes ([y, x] or [z, y, x]); got ndim={nd} for an array "
                         f"of shape {np.shape(values)}")
    return nd


def grid_slice(values, axis: str = "z", index: int = 0, *, ndim: int | None = None) -> np.ndarray:
    """One axis-aligned slice of a grid, indexed ``[v, u]`` (plus any component axes).

    Parameters
    ----------
    values : (ny, nx, ...) or (nz, ny, nx, ...) array
        Grid samples; trailing axes (vector / tensor components) are kept.
    axis : "x" | "y" | "z"
        Slice normal. A 2D grid only has the ``"z"`` slice, its whole self.
    index : int
        Cell layer along ``axis`` (0-based); ignored for a 2D grid.
    ndim : int, optional
        Number of grid axes when ``values`` carries component axes.

    Returns
    -------
    (n_v, n_u, ...) array, a view of ``values``.
    """
    _check_axis(axis)
    nd = _grid_ndim(values, ndim)
    a = np.asarray(values)
    if nd == 2:
        if axis != "z":
            raise ValueError(f"a 2D grid is only sliced normal to 'z'; got axis {axis!r}")
        return a
    g = _GRID_AXIS[axis]
    n = a.shape[g]
    k = int(index)
    if not 0 <= k < n:
        raise ValueError(f"slice index along {axis} must be in [0, {n - 1}]; got {index}")
    return np.take(a, k, axis=g)


def slice_shape(grid_shape, axis: str = "z") -> tuple:
    """``(n_v, n_u)`` of the slice of a ``[y, x]`` / ``[z, y, x]`` grid normal to ``axis``."""
    _check_axis(axis)
    shape = tuple(int(s) for s in grid_shape)
    if len(shape) == 2:
        if axis != "z":
            raise ValueError(f"a 2D grid is only sliced normal to 'z'; got axis {axis!r}")
        return shape
    nz, ny, nx = shape
    return {"z": (ny, nx), "y": (nz, nx), "x": (nz, ny)}[axis]


def slice_point(u: float, v: float, axis: str = "z", index: int | None = None) -> np.ndarray:
    """The grid point ``(x, y[, z])`` in cell units of the in-plane point ``(u, v)``.

    With ``index`` None the grid is 2D and ``(x, y) = (u, v)``; otherwise the
    point lies mid-way through cell layer ``index`` along ``axis``.
    """
    _check_axis(axis)
    if index is None:
        return np.array([u, v], dtype=np.float64)
    p = np.empty(3)
    cu, cv = PLANE_AXES[axis]
    p[cu], p[cv] = u, v
    p["xyz".index(axis)] = int(index) + 0.5
    return p


def rescale_index(index: int, n_from: int, n_to: int) -> int:
    """The layer of an ``n_to`` grid holding the centre of layer ``index`` of an ``n_from``
    grid over the same span."""
    return int(min(n_to - 1, max(0, np.floor((int(index) + 0.5) * n_to / max(int(n_from), 1)))))


class GlyphSet(NamedTuple):
    """Line glyphs on a slice, in its cell units.

    centres : (k, 2) float64, ``(u, v)`` of the sampled cell centres.
    vectors : (k, 2) float64, in-plane part of the unit principal direction
        (shorter than 1 where the direction leaves the slice plane).
    values : (k,) float64, ``|sigma_i|`` there (NaN without a magnitude).
    """

    centres: np.ndarray
    vectors: np.ndarray
    values: np.ndarray


def _lattice(n_v: int, n_u: int, count: int):
    """Row and column indices of a coarse lattice: about ``count`` samples along the longer side."""
    step = max(1.0, max(n_v, n_u) / max(int(count), 1))
    rows = np.unique(np.floor((np.arange(np.ceil(n_v / step)) + 0.5) * step).astype(np.int64).clip(0, n_v - 1))
    cols = np.unique(np.floor((np.arange(np.ceil(n_u / step)) + 0.5) * step).astype(np.int64).clip(0, n_u - 1))
    return np.meshgrid(rows, cols, indexing="ij")


def principal_glyphs(rotation, *, direction: int = 0, magnitude=None, mask=None, axis: str = "z",
                     index: int = 0, count: int = 16) -> GlyphSet:
    """Glyphs of principal direction ``direction`` on a coarse lattice of one slice.

    Parameters
    ----------
    rotation : (ny, nx, 2, 2) or (nz, ny, nx, 3, 3) float
        Columns are the unit principal directions, components ``(x, y[, z])``.
    direction : int
        Which column (0 = the largest ``|sigma_i|``).
    magnitude : (ny, nx[, nz...]) grid of floats, optional
        Colour value per cell (e.g. ``|sigma_1|``); NaN without it.
    mask : grid of bool, optional
        Only cells where it is True get a glyph (e.g. ``rho > iso``).
    axis, index : the slice (see `grid_slice`).
    count : int
        Glyphs along the longer side of the slice.

    Returns
    -------
    GlyphSet, centres in the slice's ``(u, v)`` cell units.
    """
    r = np.asarray(rotation, dtype=np.float64)
    d = r.shape[-1]
    if r.ndim != d + 2 or r.shape[-2] != d or d not in (2, 3):
        raise ValueError(f"rotation must have shape (ny, nx, 2, 2) or (nz, ny, nx, 3, 3); got {r.shape}")
    if not 0 <= int(direction) < d:
        raise ValueError(f"direction must be in [0, {d - 1}]; got {direction}")
    rs = grid_slice(r, axis, index, ndim=d)
    n_v, n_u = rs.shape[:2]
    rows, cols = _lattice(n_v, n_u, count)
    keep = np.ones(rows.shape, bool)
    if mask is not None:
        keep &= np.asarray(grid_slice(np.asarray(mask, bool), axis, index, ndim=d))[rows, cols]
    rows, cols = rows[keep], cols[keep]
    cu, cv = PLANE_AXES[axis] if d == 3 else (0, 1)
    vec = rs[rows, cols, :, int(direction)]
    vectors = np.stack([vec[:, cu], vec[:, cv]], axis=1)
    centres = np.stack([cols + 0.5, rows + 0.5], axis=1).astype(np.float64)
    if magnitude is None:
        values = np.full(len(rows), np.nan)
    else:
        values = np.asarray(grid_slice(np.asarray(magnitude, np.float64), axis, index, ndim=d))[rows, cols]
    return GlyphSet(centres, vectors, np.asarray(values, np.float64))


def glyph_segments(centres, vectors, length: float) -> np.ndarray:
    """(k, 2, 2) line segments of ``length`` (at unit vector length) centred on ``centres``."""
    c = np.asarray(centres, np.float64).reshape(-1, 2)
    half = 0.5 * float(length) * np.asarray(vectors, np.float64).reshape(-1, 2)
    return np.stack([c - half, c + half], axis=1)


def _trace(field, inside, start, h, n_max):
    """One-sided streamline of an axis field (sign free) by midpoint steps of ``h`` cells."""
    n_v, n_u = inside.shape
    pts = [np.asarray(start, np.float64)]
    prev = None
    for _ in range(n_max):
        p = pts[-1]
        a = _axis_at(field, inside, p, prev)
        if a is None:
            break
        mid = p + 0.5 * h * a
        b = _axis_at(field, inside, mid, a)
        if b is None:
            break
        q = p + h * b
        if not (0.0 <= q[0] < n_u and 0.0 <= q[1] < n_v):
            break
        pts.append(q)
        prev = b
    return np.array(pts)


def _axis_at(field, inside, p, prev):
    """Unit in-plane axis at point ``p`` (nearest cell), turned to agree with ``prev``; None to stop."""
    n_v, n_u = inside.shape
    j, i = int(np.floor(p[0])), int(np.floor(p[1]))
    if not (0 <= i < n_v and 0 <= j < n_u) or not inside[i, j]:
        return None
    a = field[i, j]
    norm = float(np.hypot(a[0], a[1]))
    if norm < 0.2:          # the direction leaves the slice plane: the line ends
        return None
    a = a / norm
    if prev is not None:
        dot = float(a @ prev)
        if dot < 0:
            a = -a
        if abs(dot) < 0.5:  # a turn of more than 60 degrees in one step: a singularity
            return None
    return a


def principal_streamlines(rotation, *, direction: int = 0, mask=None, axis: str = "z", index: int = 0,
                          count: int = 12, step: float = 0.5, max_length: float | None = None) -> list:
    """Streamlines of principal direction ``direction`` on one slice, in ``(u, v)`` cell units.

    Seeds sit on the same coarse lattice as `principal_glyphs` (``count``
    along the longer side); each line is traced both ways with midpoint steps
    of ``step`` cells using the nearest cell's direction, the sign chosen to
    continue the previous step. A line stops at the grid edge, outside
    ``mask``, where the direction leaves the plane, or at a turn of more than
    60 degrees within a step (a singular point of the field).

    Returns
    -------
    list of (m, 2) float64 polylines, m >= 2.
    """
    r = np.asarray(rotation, dtype=np.float64)
    d = r.shape[-1]
    if r.ndim != d + 2 or r.shape[-2] != d or d not in (2, 3):
        raise ValueError(f"rotation must have shape (ny, nx, 2, 2) or (nz, ny, nx, 3, 3); got {r.shape}")
    if step <= 0:
        raise ValueError(f"streamline step must be > 0 cells; got {step}")
    rs = grid_slice(r, axis, index, ndim=d)
    n_v, n_u = rs.shape[:2]
    cu, cv = PLANE_AXES[axis] if d == 3 else (0, 1)
    field = np.stack([rs[..., cu, int(direction)], rs[..., cv, int(direction)]], axis=-1)
    inside = (np.ones((n_v, n_u), bool) if mask is None
              else np.asarray(grid_slice(np.asarray(mask, bool), axis, index, ndim=d), bool))
    if max_length is None:
        max_length = 0.5 * max(n_v, n_u) / max(int(count), 1) * 3.0
    n_max = max(1, int(np.ceil(max_length / step)))
    rows, cols = _lattice(n_v, n_u, count)
    lines = []
    for i, j in zip(rows.ravel(), cols.ravel()):
        if not inside[i, j]:
            continue
        seed = np.array([j + 0.5, i + 0.5])
        a = _axis_at(field, inside, seed, None)
        if a is None:
            continue
        fwd = _trace(field, inside, seed, step, n_max)
        back = _trace(field, inside, seed, -step, n_max)
        line = np.concatenate([back[::-1], fwd[1:]])
        if len(line) >= 2:
            lines.append(line)
    return lines


def stroke_centres(points, radius: float, *, spacing: float | None = None) -> np.ndarray:
    """Brush stamp centres along a drag: the polyline ``points`` resampled so that
    consecutive centres are at most ``spacing`` apart (default half the radius,
    at least 0.25 cell), first and last points kept.

    Parameters
    ----------
    points : (k, dim) float, k >= 1, the pointer positions in grid cell units.
    radius : float > 0, brush radius in cells.

    Returns
    -------
    (m, dim) float64, m >= 1.
    """
    p = np.asarray(points, dtype=np.float64)
    if p.ndim != 2 or len(p) == 0:
        raise ValueError(f"a stroke needs points of shape (k, dim), k >= 1; got {p.shape}")
    if not np.isfinite(radius) or radius <= 0:
        raise ValueError(f"brush radius must be > 0 cells; got {radius}")
    if not np.isfinite(p).all():
        raise ValueError("a stroke point is not finite")
    gap = max(0.25, 0.5 * float(radius)) if spacing is None else float(spacing)
    if gap <= 0:
        raise ValueError(f"stamp spacing must be > 0 cells; got {spacing}")
    out = [p[0]]
    for a, b in zip(p[:-1], p[1:]):
        length = float(np.linalg.norm(b - a))
        n = int(np.ceil(length / gap))
        for t in np.arange(1, n + 1) / max(n, 1):
            out.append(a + t * (b - a))
    return np.array(out)
