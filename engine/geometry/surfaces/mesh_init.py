"""Initial disc-topology triangle meshes spanning a closed boundary polygon.

The boundary polygon (possibly skew, non-planar) is subdivided to a target
edge length and mapped to the unit circle by arc length. Concentric rings of
points fill the disc with about the same spacing, Delaunay triangulation
connects them, and the interior vertices are placed in space by harmonic
interpolation of the boundary: the cotan Laplacian of the (Delaunay, hence
non-negative cotan weights) disc mesh is solved with the boundary positions
as Dirichlet data, a discrete Tutte/harmonic embedding.

Vertex order: the boundary comes first, ``0 .. b-1`` in loop order, then the
interior. Boundary vertex ``source[k]`` keeps the index of the input point it
copies (-1 for points inserted by the subdivision).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.sparse.linalg import splu
from scipy.spatial import Delaunay

from .curvature import corner_cotangents, cotan_laplacian

__all__ = ["DiscMesh", "disc_mesh", "subdivide_polygon", "midpoint_subdivide",
           "harmonic_fill", "boundary_loop_of", "delaunay_flips"]


@dataclass(frozen=True)
class DiscMesh:
    """A triangulated disc spanning a boundary polygon.

    Attributes
    ----------
    vertices : (n, 3) float64
        Positions in model units; boundary first.
    faces : (m, 3) int64
        Triangles, counter-clockwise in ``uv`` (their normals follow the loop
        by the right-hand rule).
    boundary : (b,) int64
        Boundary vertex indices in loop order (``arange(b)``).
    uv : (n, 2) float64
        Positions in the unit disc; the boundary lies on the unit circle.
    source : (b,) int64
        Input point index for each boundary vertex, -1 where subdivision
        inserted it.
    """

    vertices: np.ndarray
    faces: np.ndarray
    boundary: np.ndarray
    uv: np.ndarray
    source: np.ndarray


def _check_polygon(points):
    pts = np.asarray(points, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"boundary_points must have shape (n, 3); got shape {pts.shape}")
    if pts.shape[0] < 3:
        raise ValueError(f"boundary_points must hold at least 3 vertices; got {pts.shape[0]}")
    bad = np.flatnonzero(~np.all(np.isfinite(pts), axis=1))
    if bad.size:
        raise ValueError(f"boundary_points must be finite; vertex {int(bad[0])} is {pts[bad[0]].tolist()}")
    seg = np.linalg.norm(np.roll(pts, -1, axis=0) - pts, axis=1)
    zero = np.flatnonzero(seg <= 1e-12 * max(1.0, float(np.abs(pts).max())))
    if zero.size:
        i = int(zero[0])
        raise ValueError(f"boundary_points vertex {(i + 1) % pts.shape[0]} repeats vertex {i}; "
                         "consecutive vertices must differ")
    return pts


def subdivide_polygon(points, *, edge_length):
    """Split each edge of a closed polygon into equal pieces no longer than
    ``edge_length``.

    Parameters
    ----------
    points : (n, 3) float64
        Closed polygon, each vertex once.
    edge_length : float or None
        Target length (model units); None keeps the polygon.

    Returns
    -------
    (numpy.ndarray (b, 3), numpy.ndarray (b,) int64)
        The subdivided polygon and, per vertex, its input index or -1.
    """
    pts = _check_polygon(points)
    if edge_length is None:
        return pts.copy(), np.arange(pts.shape[0], dtype=np.int64)
    h = float(edge_length)
    if not math.isfinite(h) or h <= 0.0:
        raise ValueError(f"edge_length must be a finite number > 0; got {edge_length!r}")
    nxt = np.roll(pts, -1, axis=0)
    out, src = [], []
    for i in range(pts.shape[0]):
        pieces = max(1, int(math.ceil(np.linalg.norm(nxt[i] - pts[i]) / h - 1e-9)))
        t = np.arange(pieces)[:, None] / pieces
        out.append(pts[i] + t * (nxt[i] - pts[i]))
        src.append(np.concatenate([[i], np.full(pieces - 1, -1)]))
    return np.vstack(out), np.concatenate(src).astype(np.int64)


def _disc_points(b_uv):
    """Interior points in the unit disc: rings spaced like the boundary."""
    b = b_uv.shape[0]
    spacing = 2.0 * math.pi / b
    step = spacing * math.sqrt(3.0) / 2.0             # row height of equilateral triangles
    rings = []
    k = 1
    while True:
        r = 1.0 - k * step
        if r < 0.5 * spacing:
            break
        count = max(3, int(round(2.0 * math.pi * r / spacing)))
        # Stagger neighbouring rings by half a spacing so Delaunay builds
        # near-equilateral triangles between them.
        phase = 0.5 * k * 2.0 * math.pi / count
        a = phase + 2.0 * math.pi * np.arange(count) / count
        rings.append(r * np.column_stack([np.cos(a), np.sin(a)]))
        k += 1
    if b > 3:
        rings.append(np.zeros((1, 2)))
    return np.vstack(rings) if rings else np.zeros((0, 2))


def harmonic_fill(vertices, faces, fixed, *, weights_from=None):
    """Place free vertices by harmonic interpolation of the fixed ones.

    Parameters
    ----------
    vertices : (n, 3) float64
        Positions; rows of fixed vertices are used as Dirichlet data.
    faces : (m, 3) int64
    fixed : (n,) bool
    weights_from : (n, 3) float64, optional
        Geometry whose cotan weights define the Laplacian (e.g. the flat
        parameter mesh); defaults to ``vertices``.

    Returns
    -------
    numpy.ndarray, shape (n, 3)
        New positions; fixed rows unchanged.
    """
    lap = cotan_laplacian(vertices if weights_from is None else weights_from, faces)
    free = np.flatnonzero(~fixed)
    out = vertices.copy()
    if free.size == 0:
        return out
    fix = np.flatnonzero(fixed)
    lap = lap.tocsc()
    a = -lap[free][:, free]
    rhs = lap[free][:, fix] @ vertices[fix]
    out[free] = splu(a.tocsc()).solve(np.ascontiguousarray(rhs))
    return out


def disc_mesh(boundary_points, *, edge_length=None):
    """Triangulate a disc spanning a closed polygon.

    Parameters
    ----------
    boundary_points : array_like, shape (n, 3), float
        Closed polygon, each vertex once, n >= 3, model units.
    edge_length : float, optional
        Target edge length (model units); boundary edges are subdivided to
        at most this length and the interior is filled at the matching
        density. None uses the polygon as given.

    Returns
    -------
    DiscMesh

    Raises
    ------
    ValueError
        Bad shape, fewer than 3 vertices, NaN, coincident consecutive
        vertices, or a bad ``edge_length``.
    """
    pts, source = subdivide_polygon(boundary_points, edge_length=edge_length)
    b = pts.shape[0]
    seg = np.linalg.norm(np.roll(pts, -1, axis=0) - pts, axis=1)
    angle = 2.0 * math.pi * np.concatenate([[0.0], np.cumsum(seg)[:-1]]) / seg.sum()
    b_uv = np.column_stack([np.cos(angle), np.sin(angle)])
    uv = np.vstack([b_uv, _disc_points(b_uv)])
    faces = Delaunay(uv).simplices.astype(np.int64)
    e1, e2 = uv[faces[:, 1]] - uv[faces[:, 0]], uv[faces[:, 2]] - uv[faces[:, 0]]
    cw = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0] < 0.0
    faces[cw] = faces[cw][:, ::-1]
    if uv.shape[0] > b:
        # Every Delaunay triangle on three circle points would have the whole
        # disc as circumcircle; guard against round-off making one anyway.
        faces = faces[~np.all(faces < b, axis=1)]
    flat = np.column_stack([uv, np.zeros(uv.shape[0])])
    start = np.zeros((uv.shape[0], 3))
    start[:b] = pts
    fixed = np.arange(uv.shape[0]) < b
    verts = harmonic_fill(start, faces, fixed, weights_from=flat)
    return DiscMesh(vertices=verts, faces=faces, boundary=np.arange(b, dtype=np.int64),
                    uv=uv, source=source)


def boundary_loop_of(faces, n_vertices):
    """Ordered boundary loop of a disc mesh (follows the face orientation).

    Returns
    -------
    numpy.ndarray, shape (b,), int64
        Starts at the loop's smallest vertex index.
    """
    e = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    key = e[:, 0] * n_vertices + e[:, 1]
    rev = e[:, 1] * n_vertices + e[:, 0]
    border = e[~np.isin(key, rev)]
    nxt = dict(zip(border[:, 0].tolist(), border[:, 1].tolist()))
    if len(nxt) != border.shape[0]:
        raise ValueError("mesh boundary is not a simple loop (a vertex has two outgoing border edges)")
    start = int(border[:, 0].min())
    loop = [start]
    while True:
        v = nxt[loop[-1]]
        if v == start:
            break
        loop.append(v)
    if len(loop) != border.shape[0]:
        raise ValueError(f"mesh has several boundary loops; got one of {len(loop)} edges out of "
                         f"{border.shape[0]} border edges, expected a disc")
    return np.asarray(loop, dtype=np.int64)


def midpoint_subdivide(vertices, faces, boundary, *, uv=None):
    """One 1-to-4 midpoint subdivision of a disc mesh.

    Boundary edges are split at their midpoints, so a polygonal boundary is
    reproduced exactly. The result keeps the boundary-first vertex order.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64
    boundary : (b,) int64
        Boundary loop in order.
    uv : (n, 2) float64, optional
        Parameter positions to subdivide alongside.

    Returns
    -------
    (vertices (n', 3), faces (4m, 3), boundary (2b,), uv (n', 2) or None)
        New boundary vertex ``2k`` is old boundary vertex ``k``.
    """
    n = vertices.shape[0]
    e = np.concatenate([faces[:, [1, 2]], faces[:, [2, 0]], faces[:, [0, 1]]])   # edge opposite corner k
    key = np.sort(e, axis=1)
    uniq, inverse = np.unique(key[:, 0] * n + key[:, 1], return_inverse=True)
    mid_index = n + inverse.reshape(3, -1).T                                      # (m, 3)
    a, c = uniq // n, uniq % n
    new_v = np.vstack([vertices, 0.5 * (vertices[a] + vertices[c])])
    new_uv = None if uv is None else np.vstack([uv, 0.5 * (uv[a] + uv[c])])
    f0, f1, f2 = faces[:, 0], faces[:, 1], faces[:, 2]
    m0, m1, m2 = mid_index[:, 0], mid_index[:, 1], mid_index[:, 2]
    new_f = np.concatenate([np.column_stack([f0, m2, m1]), np.column_stack([f1, m0, m2]),
                            np.column_stack([f2, m1, m0]), np.column_stack([m0, m1, m2])])
    # Reorder: boundary loop first (old vertex, then the midpoint after it).
    bkey = np.sort(np.column_stack([boundary, np.roll(boundary, -1)]), axis=1)
    bmid = n + np.searchsorted(uniq, bkey[:, 0] * n + bkey[:, 1])
    new_boundary = np.column_stack([boundary, bmid]).ravel()
    rest = np.setdiff1d(np.arange(new_v.shape[0]), new_boundary, assume_unique=False)
    order = np.concatenate([new_boundary, rest])
    perm = np.empty_like(order)
    perm[order] = np.arange(order.size)
    out_uv = None if new_uv is None else new_uv[order]
    return new_v[order], perm[new_f], np.arange(new_boundary.size, dtype=np.int64), out_uv


def _interior_edges(faces, n):
    """Interior edges as pairs of half-edges (corner rows into the stacked
    per-corner arrays)."""
    a = np.concatenate([faces[:, 1], faces[:, 2], faces[:, 0]])
    b = np.concatenate([faces[:, 2], faces[:, 0], faces[:, 1]])
    key = np.minimum(a, b) * n + np.maximum(a, b)
    order = np.argsort(key, kind="stable")
    same = np.flatnonzero(key[order][1:] == key[order][:-1])
    return a, b, key, order[same], order[same + 1]


def delaunay_flips(vertices, faces, *, max_passes=20):
    """Flip interior edges whose opposite angles sum to more than pi.

    Such edges have a negative cotan weight, which breaks the maximum
    principle of the harmonic maps the solvers compute; flipping them keeps
    the mesh (extrinsically) Delaunay. A flip is skipped when the new edge
    exists already or a new triangle would fold over.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64
    max_passes : int
        Each pass flips a set of edges sharing no triangle.

    Returns
    -------
    (faces (m, 3) int64, flips int)
        A new face array (the input is not modified) and the flip count.
    """
    f = np.array(faces, dtype=np.int64)
    n = vertices.shape[0]
    total = 0
    for _ in range(max_passes):
        a, b, key, h1, h2 = _interior_edges(f, n)
        cots = corner_cotangents(vertices, f).T.ravel()       # same stacking as a, b
        weight = cots[h1] + cots[h2]
        candidates = np.argsort(weight, kind="stable")
        candidates = candidates[weight[candidates] < -1e-12]
        if candidates.size == 0:
            break
        opposite = f.T.ravel()
        tri = np.tile(np.arange(f.shape[0]), 3)
        edges = set(key.tolist())
        touched = set()
        flips = 0
        for c in candidates.tolist():
            i, j = h1[c], h2[c]
            t1, t2 = int(tri[i]), int(tri[j])
            if t1 in touched or t2 in touched:
                continue
            # Half-edge i runs p -> q in t1 (apex r); j runs q -> p in t2 (apex s).
            p, q, r, s = int(a[i]), int(b[i]), int(opposite[i]), int(opposite[j])
            new_key = min(r, s) * n + max(r, s)
            if new_key in edges or not _flip_keeps_orientation(vertices, p, q, r, s):
                continue
            f[t1] = (p, s, r)
            f[t2] = (s, q, r)
            edges.discard(min(p, q) * n + max(p, q))
            edges.add(new_key)
            touched.update((t1, t2))
            flips += 1
        total += flips
        if flips == 0:
            break
    return f, total


def _flip_keeps_orientation(v, p, q, r, s):
    before = np.cross(v[q] - v[p], v[r] - v[p]) + np.cross(v[p] - v[q], v[s] - v[q])
    scale = float(np.linalg.norm(before))
    for x, y, z in ((p, s, r), (s, q, r)):
        normal = np.cross(v[y] - v[x], v[z] - v[x])
        if normal @ before <= 1e-9 * scale * float(np.linalg.norm(normal)) or not normal.any():
            return False
    return True
