"""Face conventions and the symmetry groups of the square and the cube.

Directions (faces) are numbered so that the opposite of ``d`` is
``(d + ndim) % (2 * ndim)``:

* 2D: ``0 "+x", 1 "+y", 2 "-x", 3 "-y"``
* 3D: ``0 "+x", 1 "+y", 2 "+z", 3 "-x", 4 "-y", 5 "-z"``

Block coordinates are ``(x, y)`` or ``(x, y, z)`` in the unit block. On a
grid of shape ``(ny, nx)`` / ``(nz, ny, nx)``, ``x`` runs along the last axis,
``y`` along the one before it and ``z`` along the first, so ``+y`` is the
next row (downward in an image).

Group elements are signed permutation matrices ``R`` acting on column
vectors about the block centre: ``p' = R (p - c) + c``. They are listed with
the identity first, then the other rotations, then the improper elements, in
a fixed order; orientation indices of a block follow this order after
removing duplicates, so ``"T@0"`` is always the block as written in its file.
"""

from __future__ import annotations

import itertools
from functools import lru_cache

import numpy as np

FACE_NAMES = {
    2: ("+x", "+y", "-x", "-y"),
    3: ("+x", "+y", "+z", "-x", "-y", "-z"),
}

SYMMETRY_MODES = ("full", "rotations", "none")


def face_names(ndim: int) -> tuple[str, ...]:
    """Face names in direction order for a 2D or 3D block."""
    try:
        return FACE_NAMES[ndim]
    except KeyError:
        raise ValueError(f"dim must be 2 or 3; got {ndim!r}") from None


def opposite(d: int, ndim: int) -> int:
    """Index of the face opposite to face ``d``."""
    return (d + ndim) % (2 * ndim)


@lru_cache(maxsize=None)
def face_normals(ndim: int) -> np.ndarray:
    """(2*ndim, ndim) int64: outward unit normal of each face, in (x, y[, z])."""
    eye = np.eye(ndim, dtype=np.int64)
    out = np.concatenate([eye, -eye])
    out.setflags(write=False)
    return out


def face_centres(ndim: int) -> np.ndarray:
    """(2*ndim, ndim) float64: the centre of each face of the unit block."""
    return 0.5 + 0.5 * face_normals(ndim).astype(np.float64)


def grid_offsets(ndim: int) -> np.ndarray:
    """(2*ndim, ndim) int64: grid index step ``(di, dj[, dk])`` for each face.

    The grid's axes are in reverse coordinate order (z, y, x), so the normal
    is reversed.
    """
    return face_normals(ndim)[:, ::-1].copy()


@lru_cache(maxsize=None)
def group_elements(ndim: int, mode: str = "full") -> tuple[np.ndarray, ...]:
    """Symmetry elements as (ndim, ndim) int8 matrices, identity first.

    Parameters
    ----------
    ndim : {2, 3}
    mode : {"full", "rotations", "none"}
        All 8 / 48 elements, only the proper rotations (4 / 24), or only the
        identity.
    """
    face_names(ndim)
    if mode not in SYMMETRY_MODES:
        raise ValueError(f"symmetry must be one of {SYMMETRY_MODES}; got {mode!r}")
    if ndim == 2:
        rot = np.array([[0, -1], [1, 0]], dtype=np.int64)   # +x -> +y
        mirror = np.array([[-1, 0], [0, 1]], dtype=np.int64)
        rots = [np.linalg.matrix_power(rot, k) for k in range(4)]
        mats = rots + [mirror @ r for r in rots]
    else:
        mats = []
        for perm in itertools.permutations(range(3)):
            for signs in itertools.product((1, -1), repeat=3):
                m = np.zeros((3, 3), dtype=np.int64)
                for row, (col, s) in enumerate(zip(perm, signs)):
                    m[row, col] = s
                mats.append(m)
        # stable sort: proper rotations first, identity stays first
        mats.sort(key=lambda m: round(np.linalg.det(m)) < 0)
    if mode == "rotations":
        mats = [m for m in mats if round(np.linalg.det(m)) > 0]
    elif mode == "none":
        mats = mats[:1]
    out = []
    for m in mats:
        m = m.astype(np.int8)
        m.setflags(write=False)
        out.append(m)
    return tuple(out)


def face_permutation(matrix: np.ndarray) -> np.ndarray:
    """Where each face goes: ``perm[f] = g`` with ``normal[g] = R @ normal[f]``.

    Parameters
    ----------
    matrix : (ndim, ndim) int, a signed permutation matrix.

    Returns
    -------
    (2*ndim,) int64
    """
    ndim = matrix.shape[0]
    normals = face_normals(ndim)
    moved = normals @ np.asarray(matrix, dtype=np.int64).T
    perm = np.empty(len(normals), dtype=np.int64)
    for f, v in enumerate(moved):
        perm[f] = int(np.flatnonzero((normals == v).all(axis=1))[0])
    return perm


def transform_points(points: np.ndarray, matrix: np.ndarray) -> np.ndarray:
    """Apply a group element about the block centre to (m, ndim) points."""
    pts = np.asarray(points, dtype=np.float64)
    return (pts - 0.5) @ np.asarray(matrix, dtype=np.float64).T + 0.5


def transform_connectors(connectors, matrix) -> tuple:
    """Connector labels after the transform: face ``perm[f]`` gets label ``f``."""
    perm = face_permutation(matrix)
    out = [None] * len(connectors)
    for f, label in enumerate(connectors):
        out[perm[f]] = label
    return tuple(out)


def geometry_key(polylines, decimals: int = 6) -> frozenset:
    """Order-free key of a set of polylines: its segments, rounded.

    Two orientations of a block are the same tile when their connectors and
    this key agree.
    """
    segs = set()
    for poly in polylines:
        q = np.rint(np.asarray(poly, dtype=np.float64) * 10**decimals).astype(np.int64)
        for a, b in zip(q[:-1], q[1:]):
            ta, tb = tuple(a.tolist()), tuple(b.tolist())
            if ta != tb:
                segs.add((ta, tb) if ta <= tb else (tb, ta))
    return frozenset(segs)
