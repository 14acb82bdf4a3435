"""Kernels seen from a slice plane, and their lists per square bin of pixels.

Pure numpy, float64.  A kernel at signed distance ``w`` from the plane
reaches the pixels inside the ellipse (a circle for square pixels) of
radius ``sqrt(reach^2 - w^2)`` mm around its foot on the plane.  Each tile
of the slice is cut into ``bin`` x ``bin`` pixel squares and every bin gets
the list of kernels whose footprint touches it; a fragment then loops over
its bin's list only.  (On Mesa's llvmpipe a fragment pays for every kernel
it tests, whether or not it is in reach: masked-off lanes still execute, so
tight lists matter more than an early distance test.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class PlaneKernels:
    """Kernels within reach of the plane, in plane coordinates.

    index : (m,) int64, rows of the PhasorKernels
    col, row : (m,) float64, foot of the kernel in pixel-index coordinates
        (pixel [i, j] is centred at col = j, row = i)
    depth : (m,) float64, mm, signed distance w along ``u x v``
    reach2 : (m,) float64, mm^2, ``reach^2 - w^2`` (footprint radius squared)
    g_v, g_w : (m, 3) float64, cycles/mm, ``f_j d_kj`` in the (u, v, n) basis
    c_v, c_w : (m,) float64, cycles in [0, 1), ``phi_kj / 2 pi - g_n w``
        (the part of the phase that does not change across the plane)
    """

    index: np.ndarray
    col: np.ndarray
    row: np.ndarray
    depth: np.ndarray
    reach2: np.ndarray
    g_v: np.ndarray
    g_w: np.ndarray
    c_v: np.ndarray
    c_w: np.ndarray


def plane_basis(plane) -> np.ndarray:
    """(3, 3) float64 rows u, v, n = u x v."""
    return np.stack([plane.u_axis, plane.v_axis, np.cross(plane.u_axis, plane.v_axis)])


def project_kernels(kernels, plane, reach: float) -> PlaneKernels:
    """The kernels whose reach sphere meets the slice rectangle."""
    basis = plane_basis(plane)
    pu, pv = (float(v) for v in plane.size / plane.resolution)
    rel = (kernels.positions - plane.origin) @ basis.T          # (n, 3) mm in (u, v, n)
    col = rel[:, 0] / pu - 0.5
    row = rel[:, 1] / pv - 0.5
    reach2 = reach ** 2 - rel[:, 2] ** 2
    w, h = (int(v) for v in plane.resolution)
    r = np.sqrt(np.maximum(reach2, 0.0))
    keep = ((reach2 > 0) & (col + r / pu >= 0) & (col - r / pu <= w - 1)
            & (row + r / pv >= 0) & (row - r / pv <= h - 1))
    idx = np.flatnonzero(keep)
    depth = rel[idx, 2]
    out = {}
    for k, d, phi in (("v", kernels.direction_v, kernels.phase_v), ("w", kernels.direction_w, kernels.phase_w)):
        g = (kernels.frequency[idx, None] * d[idx]) @ basis.T
        out["g_" + k] = g
        out["c_" + k] = np.mod(phi[idx] / (2 * math.pi) - g[:, 2] * depth, 1.0)
    return PlaneKernels(idx, col[idx], row[idx], depth, reach2[idx], **out)


def tile_members(pk: PlaneKernels, plane, rect) -> np.ndarray:
    """(k,) int64 positions in ``pk`` of the kernels whose footprint meets the
    tile ``rect = (row0, col0, height, width)`` (bounding-box test)."""
    r0, c0, th, tw = (int(v) for v in rect)
    pu, pv = (float(v) for v in plane.size / plane.resolution)
    rad = np.sqrt(pk.reach2)
    s, t = pk.col - c0, pk.row - r0
    return np.flatnonzero((s + rad / pu >= 0) & (s - rad / pu <= tw - 1)
                          & (t + rad / pv >= 0) & (t - rad / pv <= th - 1))


def bin_lists(pk: PlaneKernels, members, plane, rect, bin_px: int):
    """Per-bin lists of the kernels ``pk[members]`` for the tile ``rect``.

    Parameters
    ----------
    members : (k,) int64, positions in ``pk`` (e.g. from :func:`tile_members`)
    rect : (row0, col0, height, width), pixels
    bin_px : int, bin side in pixels

    Returns
    -------
    bin_start : (n_bins + 1,) int64, CSR offsets; bin ``by * nbx + bx`` covers
        tile pixels rows ``by*bin .. by*bin+bin-1``, columns likewise
    bin_items : (e,) int64, indices into ``members``, increasing within a bin
    """
    r0, c0, th, tw = (int(v) for v in rect)
    pu, pv = (float(v) for v in plane.size / plane.resolution)
    nbx, nby = -(-tw // bin_px), -(-th // bin_px)
    s, t, rad2 = pk.col[members] - c0, pk.row[members] - r0, pk.reach2[members]
    # Bin rows each footprint spans (pixel centres are at integer coordinates).
    rv = np.sqrt(rad2) / pv
    y0 = np.clip(np.ceil(t - rv), 0, th - 1).astype(np.int64) // bin_px
    y1 = np.clip(np.floor(t + rv), 0, th - 1).astype(np.int64) // bin_px
    k_of, by = _expand(np.arange(len(members)), y0, y1 - y0 + 1)
    # Nearest distance from the foot to the bin row's pixel centres, then the chord there.
    top, bottom = by * bin_px, np.minimum(by * bin_px + bin_px - 1, th - 1)
    dy = np.maximum(0.0, np.maximum(top - t[k_of], t[k_of] - bottom)) * pv
    hx = np.sqrt(np.maximum(rad2[k_of] - dy * dy, 0.0)) / pu
    x0 = np.ceil(s[k_of] - hx)
    x1 = np.floor(s[k_of] + hx)
    ok = (x1 >= 0) & (x0 <= tw - 1) & (x0 <= x1)
    k_of, by = k_of[ok], by[ok]
    bx0 = np.clip(x0[ok], 0, tw - 1).astype(np.int64) // bin_px
    bx1 = np.clip(x1[ok], 0, tw - 1).astype(np.int64) // bin_px
    items, bins = _expand(k_of, by * nbx + bx0, bx1 - bx0 + 1)
    # Entries were made in kernel order; a stable sort keeps that order inside each bin.
    order = np.argsort(bins.astype(np.int32 if nbx * nby >= 2 ** 15 else np.int16), kind="stable")
    bin_start = np.zeros(nbx * nby + 1, dtype=np.int64)
    np.cumsum(np.bincount(bins, minlength=nbx * nby), out=bin_start[1:])
    return bin_start, items[order]


def _expand(owner, first, count):
    """Rows ``(owner[i], first[i] + k)`` for ``0 <= k < count[i]``, in order."""
    count = np.maximum(count, 0)
    rep = np.repeat(np.arange(len(owner)), count)
    step = np.arange(len(rep)) - np.repeat(np.cumsum(count) - count, count)
    return owner[rep], first[rep] + step
