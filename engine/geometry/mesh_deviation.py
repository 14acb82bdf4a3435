"""How far two triangle meshes of the same surface are apart (e.g. a mesh and its decimation).

`mesh_deviation` is the two-sided vertex deviation: the largest distance
from a vertex of either mesh to the other mesh's surface.  The triangles of
the mesh measured against are binned into a uniform grid (each triangle into
every cell it meets); a point's distance is found by visiting
rings of cells around its own, nearest first, taking the exact distance to
each triangle binned there (closest point on a triangle, by its Voronoi
regions), and stopping once everything outside the rings visited is farther
than the best distance found.  No triangle that could be nearer is skipped, so the distance is exact
however long or thin the triangles (a decimated mesh's triangles across a
flat face span many cells).

Written for a worker thread beside a GUI: the binning and the search are
compiled (numba, nogil) and the points go in chunks, so the Python
interpreter is held only for short stretches.  `point_triangle_distance` is
the same closest-point rule in numpy, kept as the array form the compiled
loop is tested against.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["point_triangle_distance", "mesh_deviation"]

CHUNK = 8192          # points per compiled call (the GIL is taken between calls)


def _dot(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return np.einsum("ij,ij->i", u, v)


def point_triangle_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Distance from each point to the paired triangle.

    p, a, b, c : (n, 3) float64, mm: the points and their triangles' corners
    Returns (n,) float64.  The closest point is found in the triangle's Voronoi
    regions (corner, edge, face); a degenerate triangle falls back to its edges.
    """
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = _dot(ab, ap), _dot(ac, ap)
    bp = p - b
    d3, d4 = _dot(ab, bp), _dot(ac, bp)
    cp = p - c
    d5, d6 = _dot(ab, cp), _dot(ac, cp)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        denom = 1.0 / (va + vb + vc)
        closest = a + ab * (vb * denom)[:, None] + ac * (vc * denom)[:, None]          # inside the face
        regions = [                                            # later entries take precedence
            ((va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0),
             lambda: b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))[:, None]),    # edge bc
            ((vb <= 0) & (d2 >= 0) & (d6 <= 0), lambda: a + ac * (d2 / (d2 - d6))[:, None]),   # edge ac
            ((d6 >= 0) & (d5 <= d6), lambda: c),                                       # corner c
            ((vc <= 0) & (d1 >= 0) & (d3 <= 0), lambda: a + ab * (d1 / (d1 - d3))[:, None]),   # edge ab
            ((d3 >= 0) & (d4 <= d3), lambda: b),                                       # corner b
            ((d1 <= 0) & (d2 <= 0), lambda: a),                                        # corner a
        ]
        for mask, point in regions:
            if np.any(mask):
                closest = np.where(mask[:, None], point(), closest)
    dist = np.linalg.norm(p - closest, axis=1)
    bad = ~np.isfinite(dist)
    if np.any(bad):                                             # zero-area triangles: their edges
        q = p[bad]
        dist[bad] = np.min([_segment_distance(q, u[bad], v[bad]) for u, v in ((a, b), (b, c), (c, a))], axis=0)
    return dist


def _segment_distance(p, u, v):
    uv = v - u
    length2 = _dot(uv, uv)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(length2 > 0, _dot(p - u, uv) / length2, 0.0)
    return np.linalg.norm(p - (u + np.clip(t, 0.0, 1.0)[:, None] * uv), axis=1)


@njit(cache=True, nogil=True)
def _closest_distance(px, py, pz, a, b, c):
    """Distance from p to triangle (a, b, c): the scalar form of `point_triangle_distance`."""
    abx, aby, abz = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    acx, acy, acz = c[0] - a[0], c[1] - a[1], c[2] - a[2]
    d1 = abx * (px - a[0]) + aby * (py - a[1]) + abz * (pz - a[2])
    d2 = acx * (px - a[0]) + acy * (py - a[1]) + acz * (pz - a[2])
    d3 = abx * (px - b[0]) + aby * (py - b[1]) + abz * (pz - b[2])
    d4 = acx * (px - b[0]) + acy * (py - b[1]) + acz * (pz - b[2])
    d5 = abx * (px - c[0]) + aby * (py - c[1]) + abz * (pz - c[2])
    d6 = acx * (px - c[0]) + acy * (py - c[1]) + acz * (pz - c[2])
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    if d1 <= 0.0 and d2 <= 0.0:                                  # corner a
        qx, qy, qz = a[0], a[1], a[2]
    elif d3 >= 0.0 and d4 <= d3:                                 # corner b
        qx, qy, qz = b[0], b[1], b[2]
    elif vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0 and d1 - d3 != 0.0:   # edge ab
        v = d1 / (d1 - d3)
        qx, qy, qz = a[0] + v * abx, a[1] + v * aby, a[2] + v * abz
    elif d6 >= 0.0 and d5 <= d6:                                 # corner c
        qx, qy, qz = c[0], c[1], c[2]
    elif vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0 and d2 - d6 != 0.0:   # edge ac
        w = d2 / (d2 - d6)
        qx, qy, qz = a[0] + w * acx, a[1] + w * acy, a[2] + w * acz
    elif va <= 0.0 and d4 - d3 >= 0.0 and d5 - d6 >= 0.0 and (d4 - d3) + (d5 - d6) != 0.0:   # edge bc
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        qx, qy, qz = b[0] + w * (c[0] - b[0]), b[1] + w * (c[1] - b[1]), b[2] + w * (c[2] - b[2])
    elif va + vb + vc != 0.0:                                    # inside the face
        inv = 1.0 / (va + vb + vc)
        v, w = vb * inv, vc * inv
        qx, qy, qz = a[0] + abx * v + acx * w, a[1] + aby * v + acy * w, a[2] + abz * v + acz * w
    else:                                                        # zero area: the nearest corner
        best = math.inf
        for q in (a, b, c):
            best = min(best, math.sqrt((px - q[0]) ** 2 + (py - q[1]) ** 2 + (pz - q[2]) ** 2))
        return best
    return math.sqrt((px - qx) ** 2 + (py - qy) ** 2 + (pz - qz) ** 2)


MAX_CELLS_PER_AXIS = 128   # grid resolution cap (the search stays exact at any resolution)


@njit(cache=True, nogil=True)
def _touched_cells(vertices, face, lo, h, dims, reach, out):
    """Cells of the triangle's bounding box whose centre is within `reach` of it (every cell
    the triangle meets, as reach >= half a cell's diagonal); their flat indices into `out`."""
    a, b, c = vertices[face[0]], vertices[face[1]], vertices[face[2]]
    rng = np.empty(6, dtype=np.int64)
    for axis in range(3):
        i0 = int((min(a[axis], b[axis], c[axis]) - lo[axis]) / h)
        i1 = int((max(a[axis], b[axis], c[axis]) - lo[axis]) / h)
        rng[axis] = min(max(i0, 0), dims[axis] - 1)
        rng[3 + axis] = min(max(i1, 0), dims[axis] - 1)
    n = 0
    for i in range(rng[0], rng[3] + 1):
        for j in range(rng[1], rng[4] + 1):
            for k in range(rng[2], rng[5] + 1):
                x, y, z = lo[0] + (i + 0.5) * h, lo[1] + (j + 0.5) * h, lo[2] + (k + 0.5) * h
                if _closest_distance(x, y, z, a, b, c) <= reach:
                    out[n] = (i * dims[1] + j) * dims[2] + k
                    n += 1
    return n


@njit(cache=True, nogil=True)
def _bin_triangles(vertices, faces, lo, h, dims):
    """CSR of the grid: triangle ids binned by the cells they meet, and each cell's start."""
    n_cells = dims[0] * dims[1] * dims[2]
    reach = 0.8661 * h                              # a little over half the diagonal
    counts = np.zeros(n_cells + 1, dtype=np.int64)
    scratch = np.empty(n_cells, dtype=np.int64)
    for t in range(faces.shape[0]):
        n = _touched_cells(vertices, faces[t], lo, h, dims, reach, scratch)
        for m in range(n):
            counts[scratch[m] + 1] += 1
    starts = np.cumsum(counts)
    ids = np.empty(starts[-1], dtype=np.int64)
    fill = starts[:-1].copy()
    for t in range(faces.shape[0]):
        n = _touched_cells(vertices, faces[t], lo, h, dims, reach, scratch)
        for m in range(n):
            ids[fill[scratch[m]]] = t
            fill[scratch[m]] += 1
    return ids, starts


@njit(cache=True, nogil=True)
def _nearest_in_grid(points, vertices, faces, ids, starts, lo, h, dims):
    """(n,) the exact distance from each point (inside the grid's box) to the nearest triangle."""
    out = np.empty(points.shape[0])
    reach = max(dims[0], dims[1], dims[2])
    for p in range(points.shape[0]):
        px, py, pz = points[p, 0], points[p, 1], points[p, 2]
        ci = min(max(int((px - lo[0]) / h), 0), dims[0] - 1)
        cj = min(max(int((py - lo[1]) / h), 0), dims[1] - 1)
        ck = min(max(int((pz - lo[2]) / h), 0), dims[2] - 1)
        best = math.inf
        for r in range(reach):
            # the shell of cells at Chebyshev distance r from the point's cell
            for i in range(max(ci - r, 0), min(ci + r, dims[0] - 1) + 1):
                for j in range(max(cj - r, 0), min(cj + r, dims[1] - 1) + 1):
                    on_shell = abs(i - ci) == r or abs(j - cj) == r
                    step = 1 if on_shell else 2 * r
                    k = ck - r
                    while k <= ck + r:
                        if 0 <= k < dims[2]:
                            cell = (i * dims[1] + j) * dims[2] + k
                            for s in range(starts[cell], starts[cell + 1]):
                                f = faces[ids[s]]
                                d = _closest_distance(px, py, pz, vertices[f[0]], vertices[f[1]], vertices[f[2]])
                                if d < best:
                                    best = d
                        k += step if step > 0 else 1
            # a point outside the block of shells 0..r is at least `margin` away
            margin = math.inf
            for axis, c in ((0, ci), (1, cj), (2, ck)):
                q = points[p, axis] - lo[axis]
                if c - r > 0:
                    margin = min(margin, q - (c - r) * h)
                if c + r < dims[axis] - 1:
                    margin = min(margin, (c + r + 1) * h - q)
            if best <= margin:
                break
        out[p] = best
    return out


def _grid(vertices, faces, points):
    """Cell size, origin and dims of a grid over both point sets, about one triangle per cell."""
    lo = np.minimum(vertices.min(axis=0), points.min(axis=0))
    hi = np.maximum(vertices.max(axis=0), points.max(axis=0))
    extent = np.maximum(hi - lo, 1e-12)
    edges = np.linalg.norm(vertices[faces[:, 0]] - vertices[faces[:, 1]], axis=1)
    h = max(float(np.median(edges)) * 0.5, float(extent.max()) / MAX_CELLS_PER_AXIS, 1e-12)
    dims = np.minimum(np.floor(extent / h).astype(np.int64) + 1, MAX_CELLS_PER_AXIS + 1)
    return h, lo, dims


def _one_way(points, vertices, faces, check):
    h, lo, dims = _grid(vertices, faces, points)
    ids, starts = _bin_triangles(vertices, faces, lo, h, dims)
    worst = 0.0
    for start in range(0, len(points), CHUNK):
        if check is not None:
            check()
        p = points[start:start + CHUNK]
        worst = max(worst, float(_nearest_in_grid(p, vertices, faces, ids, starts, lo, h, dims).max()))
    return worst


def mesh_deviation(vertices_a, faces_a, vertices_b, faces_b, *, check=None) -> float:
    """The largest distance (mm) from a vertex of either mesh to the other's surface.

    vertices_a, vertices_b : (n, 3) float, mm; faces_a, faces_b : (m, 3) int vertex indices
    check : called between chunks of points (may raise to cancel)
    Returns inf if either mesh has no triangle.  Vertices no triangle uses are not
    on the surface and are ignored.

    Raises
    ------
    ValueError
        If an array has the wrong shape, holds NaN / infinite coordinates or a face
        names a missing vertex.
    """
    meshes = []
    for name, v, f in (("a", vertices_a, faces_a), ("b", vertices_b, faces_b)):
        v = np.ascontiguousarray(v, dtype=np.float64)
        f = np.ascontiguousarray(f, dtype=np.int64)
        if v.ndim != 2 or v.shape[1] != 3 or f.ndim != 2 or f.shape[1] != 3:
            raise ValueError(f"mesh {name}: vertices must be (n, 3) and faces (m, 3), "
                             f"got {v.shape} and {f.shape}")
        if len(f) and (f.min() < 0 or f.max() >= len(v)):
            bad = int(f.max()) if f.max() >= len(v) else int(f.min())
            raise ValueError(f"mesh {name}: a face names vertex {bad}, outside 0..{len(v) - 1}")
        if not np.all(np.isfinite(v)):
            raise ValueError(f"mesh {name}: vertices hold NaN or infinite coordinates")
        meshes.append((v, f))
    (va, fa), (vb, fb) = meshes
    if not len(fa) or not len(fb):
        return float("inf")
    used_a, used_b = va[np.unique(fa)], vb[np.unique(fb)]
    return max(_one_way(used_a, vb, fb, check), _one_way(used_b, va, fa, check))
