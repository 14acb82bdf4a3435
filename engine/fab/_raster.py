"""Compiled rasteriser for the print emulation (see :mod:`.printability`).

Grid coordinates: pixel ``[i, j]`` covers ``[j, j + 1) x [i, i + 1)`` in
pixel units, its centre is ``(j + 0.5, i + 0.5)``; x runs along columns.
A *piece* is a short polyline ``pts[a:b]`` (pixel units). Its *footprint*
is the set of pixel centres within the bead radius of the polyline (the
swept disc); its *band* is the part of the footprint that projects inside
one of its segments (the footprint without the round end caps).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _scan_piece(pts, a, b, radius, below, canvas, stamp, H, W):
    """Visit the footprint of piece ``pts[a:b]``.

    Returns (footprint pixels, supported by ``below``, band pixels, band
    pixels already in ``canvas``); when ``stamp`` the footprint is also
    written to ``canvas`` (and nothing is counted).
    """
    r2 = radius * radius
    xmin = xmax = pts[a, 0]
    ymin = ymax = pts[a, 1]
    for k in range(a + 1, b):
        xmin = min(xmin, pts[k, 0])
        xmax = max(xmax, pts[k, 0])
        ymin = min(ymin, pts[k, 1])
        ymax = max(ymax, pts[k, 1])
    j0 = max(0, int(math.floor(xmin - radius - 0.5)))
    j1 = min(W - 1, int(math.ceil(xmax + radius - 0.5)))
    i0 = max(0, int(math.floor(ymin - radius - 0.5)))
    i1 = min(H - 1, int(math.ceil(ymax + radius - 0.5)))
    foot = supp = band = over = 0
    for i in range(i0, i1 + 1):
        cy = i + 0.5
        for j in range(j0, j1 + 1):
            cx = j + 0.5
            in_foot = False
            in_band = False
            for k in range(a, b - 1):
                ax, ay = pts[k, 0], pts[k, 1]
                dx, dy = pts[k + 1, 0] - ax, pts[k + 1, 1] - ay
                ex, ey = cx - ax, cy - ay
                l2 = dx * dx + dy * dy
                t = (ex * dx + ey * dy) / l2 if l2 > 0.0 else 0.0
                if 0.0 <= t <= 1.0:
                    px, py = ex - t * dx, ey - t * dy
                    if px * px + py * py <= r2:
                        in_foot = True
                        in_band = True
                        break
                else:
                    t = min(max(t, 0.0), 1.0)
                    px, py = ex - t * dx, ey - t * dy
                    if px * px + py * py <= r2:
                        in_foot = True
            if not in_foot:
                continue
            if stamp:
                canvas[i, j] = True
                continue
            foot += 1
            if below[i, j]:
                supp += 1
            if in_band:
                band += 1
                if canvas[i, j]:
                    over += 1
    return foot, supp, band, over


@njit(cache=True, nogil=True)
def emulate_layer(pts, piece_start, piece_path, radius, below, canvas):
    """Measure every piece of a layer, then deposit it.

    Parameters
    ----------
    pts : (N, 2) float64
        Piece vertices, pixel units; piece ``q`` is
        ``pts[piece_start[q]:piece_start[q + 1]]``.
    piece_start : (Q + 1,) int64
    piece_path : (Q,) int64
        Path of each piece; pieces of one path are consecutive and a path's
        material joins ``canvas`` only after all its pieces are measured.
    radius : float
        Bead radius, pixels.
    below : (H, W) bool
        Material of the previous layer (all True on the bed).
    canvas : (H, W) bool
        Material of this layer so far; updated in place.

    Returns
    -------
    counts : (Q, 4) int64
        footprint, supported, band, band already covered (pixels).
    """
    H, W = canvas.shape
    Q = piece_path.shape[0]
    counts = np.zeros((Q, 4), np.int64)
    q = 0
    while q < Q:
        r = q
        while r < Q and piece_path[r] == piece_path[q]:
            r += 1
        for p in range(q, r):
            f, s, bnd, o = _scan_piece(pts, piece_start[p], piece_start[p + 1], radius,
                                       below, canvas, False, H, W)
            counts[p, 0] = f
            counts[p, 1] = s
            counts[p, 2] = bnd
            counts[p, 3] = o
        for p in range(q, r):
            _scan_piece(pts, piece_start[p], piece_start[p + 1], radius,
                        below, canvas, True, H, W)
        q = r
    return counts
