"""The associate family of a discrete minimal surface (Makatura et al. 2023,
eq. 1) and the translation periods of its members.

``F_phi = cos(phi) S + sin(phi) S*`` with ``S*`` the discrete conjugate
(:mod:`.conjugate`). On every triangle the map is a rotation by ``phi``
about the face normal, so each member is isometric to ``S`` and shares its
normals. Values are given on the edge midpoints (where ``S*`` is exact) and
on the vertices (with the vertex-mapped conjugate).

Schwarz D (``phi = 0``), the gyroid (``phi`` = the Bonnet angle, about
38.015 degrees) and Schwarz P (``phi`` = 90 degrees) form one family. Only
at those angles is the continued surface periodic: :func:`associate_periods`
continues a patch bounded by straight lines across its edges by half-turns
(Prop. 4.2b) and returns the translations the family member inherits, which
form a lattice exactly at those angles.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .conjugate import ConjugateSurface, conjugate_surface
from .curvature import validate_mesh

__all__ = ["AssociateSurface", "associate_surface", "associate_periods", "lattice_basis",
           "BONNET_ANGLE_DEG"]

# Gyroid in the D -> P family, measured from D (Karcher 1989; Schoen 1970).
BONNET_ANGLE_DEG = 38.0147740


@dataclass(frozen=True)
class AssociateSurface:
    """Result of :func:`associate_surface`.

    Attributes
    ----------
    vertices : (n, 3) float64, read-only
        ``cos(phi) V + sin(phi) V*`` on the input connectivity.
    faces : (m, 3) int64, read-only
    midpoints : (e, 3) float64, read-only
        ``cos(phi) m + sin(phi) m*`` on the edge midpoints.
    face_edges : (m, 3) int64, read-only
        Midpoint triangles, as in :class:`~.conjugate.ConjugateSurface`.
    phi : float
        Angle in radians.
    """

    vertices: np.ndarray
    faces: np.ndarray
    midpoints: np.ndarray
    face_edges: np.ndarray
    phi: float


def associate_surface(vertices, faces, phi, *, conjugate=None, sign=1):
    """Member ``phi`` of the associate family of a discrete minimal surface.

    Parameters
    ----------
    vertices : array_like, shape (n, 3), float
        Discrete minimal surface ``S`` (model units).
    faces : array_like, shape (m, 3), int
    phi : float
        Angle in radians (``0`` gives ``S``, ``pi / 2`` its conjugate).
    conjugate : ConjugateSurface, optional
        Precomputed :func:`~.conjugate.conjugate_surface` of the same mesh.
    sign : {1, -1}
        Quarter-turn direction of the conjugate (see ``conjugate_surface``).

    Returns
    -------
    AssociateSurface
    """
    v, f = validate_mesh(vertices, faces)
    if not math.isfinite(float(phi)):
        raise ValueError(f"phi must be finite; got {phi!r}")
    conj = conjugate if conjugate is not None else conjugate_surface(v, f, sign=sign)
    if not isinstance(conj, ConjugateSurface) or conj.vertices.shape != v.shape:
        raise ValueError("conjugate must be the ConjugateSurface of the same mesh")
    c, s = math.cos(phi), math.sin(phi)
    mid = 0.5 * (v[conj.edges[:, 0]] + v[conj.edges[:, 1]])
    out_v = c * v + s * conj.vertices
    out_m = c * mid + s * conj.midpoints
    for arr in (out_v, out_m):
        arr.setflags(write=False)
    return AssociateSurface(vertices=out_v, faces=conj.faces, midpoints=out_m,
                            face_edges=conj.face_edges, phi=float(phi))


def _half_turn(p, d):
    a = 2.0 * np.outer(d, d) - np.eye(3)
    return a, p - a @ p


def associate_periods(vertices, conjugate_vertices, segments, phi, *, max_word=6):
    """Translations of the associate member ``phi`` of a patch bounded by lines.

    A patch ``S`` whose boundary holds straight segments continues across
    segment ``j`` by the half-turn ``H_j`` about it. Along a word of such
    continuations ``g = H_j1 H_j2 ...`` the continued surface is
    ``A_g S + b_g`` and, matching the conjugate across each seam (the
    conjugate of segment ``j`` lies in a plane orthogonal to it, and every
    half-turn flips the orientation), its conjugate is
    ``sigma_g A_g S* + b*_g``. A word with ``A_g = I`` and ``sigma_g = +1``
    therefore shifts the member ``phi`` by ``cos(phi) b_g + sin(phi) b*_g``.

    Parameters
    ----------
    vertices : (n, 3) float
        The patch ``S`` (model units).
    conjugate_vertices : (n, 3) float
        Its conjugate on the same vertices (e.g. ``conjugate_surface(...).vertices``).
    segments : sequence of (k,) int arrays
        Boundary vertex indices along each straight segment, in order; the
        line runs from the first to the last.
    phi : float
        Family angle (radians).
    max_word : int
        Longest word of half-turns explored (the count grows like 5^k).

    Returns
    -------
    numpy.ndarray, shape (t, 3)
        Distinct non-zero translations found (model units).
    """
    v = np.asarray(vertices, dtype=np.float64)
    vs = np.asarray(conjugate_vertices, dtype=np.float64)
    lines = []
    for seg in segments:
        seg = np.asarray(seg, dtype=np.int64)
        d = v[seg[-1]] - v[seg[0]]
        d /= np.linalg.norm(d)
        a, b = _half_turn(v[seg[0]], d)
        # Plane offset of the conjugate of this segment along its direction.
        lines.append((a, b, d, float(np.mean(vs[seg] @ d))))
    c, s = math.cos(phi), math.sin(phi)
    found = []
    # State: (last segment, A, b, sigma, b*).
    frontier = [(-1, np.eye(3), np.zeros(3), 1, np.zeros(3))]
    for _ in range(max_word):
        nxt = []
        for last, a, b, sigma, bs in frontier:
            for j, (aj, bj, dj, cj) in enumerate(lines):
                if j == last:
                    continue
                bs_new = bs + 2.0 * sigma * cj * (a @ dj)
                state = (j, a @ aj, a @ bj + b, -sigma, bs_new)
                nxt.append(state)
                if state[3] == 1 and np.allclose(state[1], np.eye(3), atol=1e-9):
                    found.append(c * state[2] + s * state[4])
        frontier = nxt
    if not found:
        return np.zeros((0, 3))
    out = np.asarray(found)
    scale = float(np.ptp(v, axis=0).max()) or 1.0
    out = out[np.linalg.norm(out, axis=1) > 1e-9 * scale]
    key = np.round(out / (1e-6 * scale)).astype(np.int64)
    _, first = np.unique(key, axis=0, return_index=True)
    return out[np.sort(first)]


def lattice_basis(vectors, *, zero=0.02, tol=1e-3):
    """Shortest three independent vectors and how well they generate the rest.

    At a periodic member of an associate family the continued surface's
    translations form a lattice, and some products of half-turns translate
    by exactly zero; discretisation leaves those as tiny vectors. They are
    set apart first.

    Parameters
    ----------
    vectors : (t, 3) float
        Candidate translations.
    zero : float
        Vectors shorter than ``zero`` times the median length count as zero.
    tol : float
        Relative tolerance for linear independence.

    Returns
    -------
    (basis (3, 3) rows, residual float, zero_max float)
        ``residual`` is the largest distance of a candidate's lattice
        coordinates from integers (0 iff every candidate lies on the lattice
        the basis spans; ``inf`` without three independent vectors);
        ``zero_max`` the longest vector counted as zero (model units).
    """
    t = np.asarray(vectors, dtype=np.float64)
    length = np.linalg.norm(t, axis=1)
    small = length < zero * float(np.median(length))
    zero_max = float(length[small].max()) if small.any() else 0.0
    t, length = t[~small], length[~small]
    basis = []
    for k in np.argsort(length):
        trial = basis + [t[k]]
        if np.linalg.matrix_rank(np.asarray(trial), tol=tol * length[k]) == len(trial):
            basis = trial
        if len(basis) == 3:
            break
    if len(basis) < 3:
        return np.asarray(basis), math.inf, zero_max
    b = np.asarray(basis)
    coords = np.linalg.solve(b.T, t.T).T
    return b, float(np.max(np.abs(coords - np.round(coords)))), zero_max
