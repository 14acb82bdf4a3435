"""SOLVECONTOUR: the dual polygon of a conjugate loop (Makatura et al. 2023,
sections 4.1, 4.2.3 and 4.2.4).

At dual vertex ``i`` the Plateau surface must have normal ``vN[i]`` (the
primary's normal, Prop. 4.1a) and interior angle ``vA[i]`` (isometry,
Prop. 4.1b). Dual edge ``i`` joins dual vertices ``i`` and ``i + 1``, so it
is orthogonal to both normals: it runs along ``vN[i] x vN[i+1]``. Its sign
follows from turning: the outgoing edge is the incoming one turned about
``vN[i]`` by the exterior angle ``pi - vA[i]``. (Where two consecutive
vertices share an FBV edge the cross product vanishes; the turn alone then
gives the direction.) With outward plane normals the edge directions come
out as the outward normals of the arcs' planes.

Only the lengths are free. :func:`close_lengths` solves eqs. 5-6: the
closed loop nearest (least squares) to requested lengths, a linear system
with three constraints. :func:`initial_lengths` is the three-case
heuristic of section 4.2.4.
"""

from __future__ import annotations

import math

import numpy as np

from .fbv import LoopOnFBV

__all__ = ["dual_directions", "close_lengths", "solve_contour", "initial_lengths",
           "ContourError"]


class ContourError(ValueError):
    """The dual polygon cannot be built from the given angles and normals."""


def _rotate(v, axis, angle):
    """Rodrigues rotation of ``v`` about the unit ``axis``."""
    c, s = math.cos(angle), math.sin(angle)
    return v * c + np.cross(axis, v) * s + axis * np.dot(axis, v) * (1.0 - c)


def dual_directions(v_angles, v_normals, *, first=None):
    """Unit direction of every dual edge.

    Parameters
    ----------
    v_angles : (n,) float
        Interior angle at each dual vertex (radians, in (0, pi)).
    v_normals : (n, 3) float
        Unit surface normal at each dual vertex.
    first : (3,) float, optional
        Direction of edge ``n - 1`` (entering vertex 0). By default the
        largest cross product of consecutive normals fixes one edge up to a
        global sign (both signs give point-reflected polygons).

    Returns
    -------
    numpy.ndarray, shape (n, 3)

    Raises
    ------
    ContourError
        Angles outside (0, pi), or the turned directions are not orthogonal
        to the next normal (the normals and angles do not fit together),
        or the loop of turns does not return to the first direction.
    """
    a = np.asarray(v_angles, dtype=np.float64).ravel()
    nrm = np.asarray(v_normals, dtype=np.float64)
    n = a.size
    if nrm.shape != (n, 3) or n < 3:
        raise ContourError(f"v_normals must have shape ({n}, 3) with n >= 3; got {nrm.shape}")
    bad = np.flatnonzero(~((a > 0.0) & (a < math.pi)))
    if bad.size:
        raise ContourError(f"vertex {int(bad[0])} has angle {a[bad[0]]!r}; angles must lie in (0, pi)")
    nrm = nrm / np.linalg.norm(nrm, axis=1, keepdims=True)
    # Start the turns after a pair of non-parallel normals: their cross
    # product fixes the edge between them up to one global sign.
    cross = np.cross(np.roll(nrm, 1, axis=0), nrm)          # edge k-1 lies along cross[k]
    size = np.linalg.norm(cross, axis=1)
    if first is not None:
        k0, start = 0, np.asarray(first, dtype=np.float64) / np.linalg.norm(first)
    elif size.max() > 1e-9:
        k0 = int(np.argmax(size))
        start = cross[k0] / size[k0]
    else:
        raise ContourError("all vertex normals are parallel; pass `first`")
    dirs = np.empty((n, 3))
    e = start
    for step in range(n):
        i = (k0 + step) % n
        e = _rotate(e, nrm[i], math.pi - a[i])
        dirs[i] = e
        j = (i + 1) % n
        off = abs(np.dot(e, nrm[j]))
        if off > 1e-6:
            raise ContourError(
                f"dual edge {i} turned at vertex {i} by the exterior angle "
                f"{math.degrees(math.pi - a[i]):.4g} deg is not orthogonal to the normal at "
                f"vertex {j} (|cos| = {off:.3g}); the angles and normals are inconsistent")
    if np.linalg.norm(dirs[(k0 - 1) % n] - start) > 1e-6:
        raise ContourError("the turns around the loop do not return to the first direction; "
                           "the angles and normals are inconsistent")
    return dirs


def close_lengths(lengths, directions, *, minimum=0.0):
    """Eqs. 5-6: the closed loop nearest to the requested lengths.

    Solves ``min sum (l - l_in)^2  s.t.  sum l_i e_i = 0`` directly:
    ``l = l_in - E^T (E E^T)^+ E l_in`` with ``E = directions.T``.

    Parameters
    ----------
    lengths : (n,) float
        Requested lengths ``l_in`` (model units).
    directions : (n, 3) float
        Unit edge directions.
    minimum : float
        Lengths below this are reported as a failure (model units).

    Returns
    -------
    (numpy.ndarray (n,), bool)
        Closed lengths and whether all exceed ``minimum``.
    """
    l_in = np.asarray(lengths, dtype=np.float64).ravel()
    e = np.asarray(directions, dtype=np.float64).T
    correction = e.T @ (np.linalg.pinv(e @ e.T, rcond=1e-12) @ (e @ l_in))
    out = l_in - correction
    return out, bool(np.all(out > minimum))


def solve_contour(lengths, v_angles, v_normals, *, origin=(0.0, 0.0, 0.0), directions=None):
    """SOLVECONTOUR: corners of the dual polygon.

    Parameters
    ----------
    lengths : (n,) float
        Requested edge lengths (model units); regularised by
        :func:`close_lengths` first.
    v_angles, v_normals
        See :func:`dual_directions`.
    origin : (3,) float
        Position of dual vertex 0.
    directions : (n, 3) float, optional
        Precomputed :func:`dual_directions`.

    Returns
    -------
    (corners (n, 3), lengths (n,))
        Dual vertex ``i`` and the closed lengths used.

    Raises
    ------
    ContourError
        A regularised length is not positive.
    """
    dirs = dual_directions(v_angles, v_normals) if directions is None else directions
    closed, ok = close_lengths(lengths, dirs)
    if not ok:
        i = int(np.argmin(closed))
        raise ContourError(f"closing the loop makes edge {i} length {closed[i]:.4g} <= 0; "
                           "the requested lengths are too far from a closed loop")
    steps = closed[:, None] * dirs
    corners = np.asarray(origin, dtype=np.float64) + np.vstack([np.zeros(3),
                                                                 np.cumsum(steps, axis=0)[:-1]])
    return corners, closed


def _edge_of(loop, i):
    return tuple(sorted(int(k) for k in loop.vertex_planes[i]))


def _neighbour_corner(fbv, h1, h2):
    """The polyhedron corner shared by two FBV edges, or None."""
    a = set(fbv.edge_corners(*h1))
    b = set(fbv.edge_corners(*h2))
    common = sorted(a & b)
    return fbv.corners[common[0]] if common else None


def initial_lengths(fbv, loop: LoopOnFBV):
    """Three-case heuristic for the initial dual lengths (section 4.2.4).

    For the arc from vertex ``i`` (on FBV edge ``h1``) to vertex ``i + 1``
    (on ``h2``) on one face:

    1. ``h1``, ``h2`` meet at a polyhedron corner ``X``: a circular arc about
       ``X`` with the mean distance of the two vertices to ``X`` as radius,
       spanning the face angle at ``X``;
    2. ``h1``, ``h2`` do not meet: the distance between the vertices;
    3. ``h1 == h2``: half the perimeter of the circle with the two vertices
       as a diameter.

    Returns
    -------
    numpy.ndarray, shape (n,), float64 (model units)
    """
    p = loop.points
    n = p.shape[0]
    out = np.empty(n)
    for i in range(n):
        j = (i + 1) % n
        h1, h2 = _edge_of(loop, i), _edge_of(loop, j)
        chord = float(np.linalg.norm(p[j] - p[i]))
        if h1 == h2:
            out[i] = 0.5 * math.pi * chord
            continue
        x = _neighbour_corner(fbv, h1, h2)
        if x is None:
            out[i] = chord
            continue
        a, b = p[i] - x, p[j] - x
        ra, rb = np.linalg.norm(a), np.linalg.norm(b)
        if ra <= 1e-12 or rb <= 1e-12:
            out[i] = chord
            continue
        angle = math.acos(float(np.clip(a @ b / (ra * rb), -1.0, 1.0)))
        out[i] = 0.5 * (ra + rb) * angle
    return out
