"""Extending a surface patch by its symmetries (Makatura et al. 2023,
Prop. 4.2) and welding the copies into one mesh.

A patch bounded by planar symmetry lines continues by mirroring in their
planes (Prop. 4.2a), one bounded by straight lines by half-turns about them
(Prop. 4.2b). :func:`tile_patch` applies such symmetries either as a chain
(each doubles the geometry so far, like a chain of Mirror nodes) or as the
generators of a group folded into a periodic cubic cell.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Symmetry", "mirror", "half_turn", "fbv_mirrors", "tile_patch"]



@dataclass(frozen=True)
class Symmetry:
    """An isometry used to extend a patch (Prop. 4.2).

    ``kind`` is ``"mirror"`` (reflection in the plane through ``point`` with
    normal ``direction``) or ``"half_turn"`` (rotation by 180 degrees about
    the line through ``point`` along ``direction``).
    """

    kind: str
    point: tuple
    direction: tuple

    def affine(self):
        """``(A (3, 3), b (3,))`` with ``x -> A x + b``."""
        d = np.asarray(self.direction, dtype=np.float64)
        d = d / np.linalg.norm(d)
        p = np.asarray(self.point, dtype=np.float64)
        a = np.eye(3) - 2.0 * np.outer(d, d) if self.kind == "mirror" \
            else 2.0 * np.outer(d, d) - np.eye(3)
        return a, p - a @ p


def mirror(point, normal):
    """Reflection in a plane (Prop. 4.2a)."""
    if np.linalg.norm(normal) <= 0.0:
        raise ValueError("mirror normal must be non-zero")
    return Symmetry("mirror", tuple(map(float, point)), tuple(map(float, normal)))


def half_turn(point, direction):
    """Rotation by 180 degrees about a straight line (Prop. 4.2b)."""
    if np.linalg.norm(direction) <= 0.0:
        raise ValueError("half-turn direction must be non-zero")
    return Symmetry("half_turn", tuple(map(float, point)), tuple(map(float, direction)))


def fbv_mirrors(fbv, planes):
    """Mirror symmetries in the given FBV planes (indices)."""
    out = []
    for k in planes:
        n = fbv.normals[int(k)]
        out.append(mirror(n * fbv.offsets[int(k)], n))
    return out


def _copy_key(a, centroid, scale):
    return tuple(np.round(np.concatenate([a.ravel(), centroid / scale]), 6).tolist())


def tile_patch(vertices, faces, symmetries, *, cell=None, weld_tol=None, max_copies=4096):
    """Extend a patch by its symmetries and weld the copies into one mesh.

    Parameters
    ----------
    vertices : (n, 3) float
    faces : (m, 3) int
    symmetries : sequence of Symmetry
        Without ``cell``: applied in turn, each doubling the geometry so far
        (like a chain of mirror nodes: three FBV mirrors give 8 copies).
        With ``cell``: generators of a group; all images are folded into the
        periodic cell by lattice translations until no new copy appears.
    cell : (origin (3,), size float), optional
        Cubic periodic cell for the group mode (model units).
    weld_tol : float, optional
        Vertices closer than this are merged; default 1e-7 times the patch
        diameter.
    max_copies : int
        Refuse to build more copies than this.

    Returns
    -------
    (vertices (n', 3) float64, faces (m', 3) int64, copies int)
        Copies made by an odd number of symmetries have their faces
        reversed, keeping one orientation across the seams.
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    maps = [(np.eye(3), np.zeros(3), 0)]
    gens = [s.affine() for s in symmetries]
    if cell is None:
        for a, b in gens:
            maps += [(a @ m, a @ t + b, parity ^ 1) for m, t, parity in maps]
            if len(maps) > max_copies:
                raise ValueError(f"more than max_copies={max_copies} copies")
    else:
        maps = _group_orbit(v, gens, cell, max_copies)
    size = float(np.ptp(v, axis=0).max()) or 1.0
    tol = 1e-7 * size if weld_tol is None else float(weld_tol)
    all_v, all_f = [], []
    for k, (a, t, parity) in enumerate(maps):
        all_v.append(v @ a.T + t)
        ff = f[:, ::-1] if parity else f
        all_f.append(ff + k * v.shape[0])
    big_v, big_f = np.vstack(all_v), np.vstack(all_f)
    return (*_weld(big_v, big_f, tol), len(maps))


def _group_orbit(v, gens, cell, max_copies):
    origin, size = np.asarray(cell[0], dtype=np.float64), float(cell[1])
    centre = v.mean(axis=0)

    def fold(a, t, parity):
        c = a @ centre + t
        t = t - size * np.floor((c - origin) / size + 1e-9)
        return a, t, parity

    start = fold(np.eye(3), np.zeros(3), 0)
    seen = {_copy_key(start[0], start[0] @ centre + start[1], size): start}
    frontier = [start]
    while frontier:
        nxt = []
        for a, t, parity in frontier:
            for ga, gb in gens:
                cand = fold(ga @ a, ga @ t + gb, parity ^ 1)
                key = _copy_key(cand[0], cand[0] @ centre + cand[1], size)
                if key not in seen:
                    seen[key] = cand
                    nxt.append(cand)
        if len(seen) > max_copies:
            raise ValueError(f"more than max_copies={max_copies} copies; are the symmetries "
                             "compatible with the cell?")
        frontier = nxt
    return list(seen.values())


def _weld(v, f, tol):
    from scipy.spatial import cKDTree

    pairs = cKDTree(v).query_pairs(tol, output_type="ndarray")
    parent = np.arange(v.shape[0])

    def root(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for i, j in pairs:
        ri, rj = root(i), root(j)
        if ri != rj:
            parent[max(ri, rj)] = min(ri, rj)
    roots = np.array([root(i) for i in range(v.shape[0])])
    uniq, inverse = np.unique(roots, return_inverse=True)
    new_f = inverse[f]
    keep = (new_f[:, 0] != new_f[:, 1]) & (new_f[:, 1] != new_f[:, 2]) & (new_f[:, 0] != new_f[:, 2])
    return v[uniq], new_f[keep]
