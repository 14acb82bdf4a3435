"""Signed distance grid of thickened triangle meshes (surface skeletons).

Same grid convention as :mod:`engine.geometry.sdf_lines` (nodes at i/N on
the periodic unit cell, ``[x, y, z]`` order, ``+band`` far away).

* ``"spherical"``: per triangle ``|p - c| - r(c)`` with ``c`` the closest
  point of the triangle and ``r`` the barycentric interpolation of half the
  vertex thickness; the union is the minimum over triangles. For constant
  thickness this is exactly the union of spheres swept over the surface.
* ``"normal"``: a slab bounded by the two offset surfaces and cut flat where
  the surface ends. With ``c`` the closest point of the whole mesh:
  if ``c`` is interior (not on a boundary edge or vertex) the value is
  ``|p - c| - r(c)``, clipped inside to ``-(distance to the nearest wall)``;
  if ``c`` is on the boundary the point lies beyond the edge and the value is
  the distance to the flat wall, ``sqrt(delta^2 + max(|h| - r, 0)^2)`` with
  ``h`` the height above the triangle's plane and ``delta`` the in-plane
  distance past the edge. A wall is the rectangle swept by a boundary edge
  along its triangle's normal, ``+- r`` at each end. For a flat square this
  is exactly the SDF of the box ``square x [-r, r]``.

Boundary edges are those used by exactly one face.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from .cancel import run_chunked
from .sdf_lines import check_band, check_resolution, index_ranges

__all__ = ["surface_sdf_grid", "boundary_flags"]

METHODS = ("spherical", "normal")


# ----------------------------------------------------------------- validation

def _check_mesh(vertices, faces, thickness_per_vertex, method):
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}; got {method!r}")
    v = np.asarray(vertices, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"vertices must have shape (n, 3); got {v.shape}")
    f = np.asarray(faces)
    if f.ndim != 2 or f.shape[1] != 3 or (f.size and not np.issubdtype(f.dtype, np.integer)):
        raise ValueError(f"faces must be an integer array of shape (f, 3); got {f.shape} {f.dtype}")
    f = f.astype(np.int64)
    if f.size and (f.min() < 0 or f.max() >= v.shape[0]):
        raise ValueError(f"faces must index vertices 0..{v.shape[0] - 1}; got range "
                         f"{f.min()}..{f.max()}")
    t = np.asarray(thickness_per_vertex, dtype=np.float64)
    if t.shape != (v.shape[0],):
        raise ValueError(f"thickness_per_vertex must have shape ({v.shape[0]},); got {t.shape}")
    if not (np.all(np.isfinite(v)) and np.all(np.isfinite(t))):
        raise ValueError("vertices and thickness_per_vertex must be finite; got NaN or inf")
    if np.any(t < 0):
        raise ValueError(f"thickness_per_vertex must be >= 0; got minimum {t.min()!r}")
    return v, f, t


def boundary_flags(faces, vertex_count):
    """Which face edges and vertices lie on the mesh boundary.

    Parameters
    ----------
    faces : (f, 3) int array
    vertex_count : int

    Returns
    -------
    edge_boundary : (f, 3) bool
        ``[t, k]`` is True if the edge opposite corner k of face t is used
        by exactly one face.
    vertex_boundary : (vertex_count,) bool
        True for vertices on a boundary edge.
    """
    f = np.asarray(faces, dtype=np.int64)
    # Edge opposite corner k joins the other two corners.
    edges = np.stack([f[:, [1, 2]], f[:, [2, 0]], f[:, [0, 1]]], axis=1).reshape(-1, 2)
    key = np.sort(edges, axis=1)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    edge_boundary = (counts[inverse.ravel()] == 1).reshape(-1, 3)
    vertex_boundary = np.zeros(vertex_count, dtype=bool)
    vertex_boundary[edges[edge_boundary.ravel()].ravel()] = True
    return edge_boundary, vertex_boundary


# --------------------------------------------------------------- numba kernel

@njit(cache=True, fastmath=False, nogil=True)
def _seg_closest(px, py, pz, ax, ay, az, bx, by, bz):
    ex, ey, ez = bx - ax, by - ay, bz - az
    ee = ex * ex + ey * ey + ez * ez
    if ee <= 0.0:
        return 0.0
    t = ((px - ax) * ex + (py - ay) * ey + (pz - az) * ez) / ee
    return min(1.0, max(0.0, t))


@njit(cache=True, fastmath=False, nogil=True)
def _closest_bary(px, py, pz, tri):
    """Barycentric coordinates of the point of triangle ``tri`` closest to p.

    Classifies p into the Voronoi regions of the corners, edges and face;
    coordinates that vanish on the chosen feature are exactly 0.
    """
    ax, ay, az = tri[0, 0], tri[0, 1], tri[0, 2]
    abx, aby, abz = tri[1, 0] - ax, tri[1, 1] - ay, tri[1, 2] - az
    acx, acy, acz = tri[2, 0] - ax, tri[2, 1] - ay, tri[2, 2] - az
    nx, ny, nz = aby * acz - abz * acy, abz * acx - abx * acz, abx * acy - aby * acx
    area2 = nx * nx + ny * ny + nz * nz
    scale = (abx * abx + aby * aby + abz * abz) * (acx * acx + acy * acy + acz * acz)
    if area2 <= 1e-24 * scale or scale == 0.0:
        # Sliver: the nearest of its three edges.
        best, bu, bv, bw = np.inf, 1.0, 0.0, 0.0
        for e in range(3):
            i, j = (e + 1) % 3, (e + 2) % 3
            t = _seg_closest(px, py, pz, tri[i, 0], tri[i, 1], tri[i, 2], tri[j, 0], tri[j, 1], tri[j, 2])
            cx = tri[i, 0] + t * (tri[j, 0] - tri[i, 0])
            cy = tri[i, 1] + t * (tri[j, 1] - tri[i, 1])
            cz = tri[i, 2] + t * (tri[j, 2] - tri[i, 2])
            d = (px - cx) ** 2 + (py - cy) ** 2 + (pz - cz) ** 2
            if d < best:
                w3 = [0.0, 0.0, 0.0]
                w3[i], w3[j] = 1.0 - t, t
                best, bu, bv, bw = d, w3[0], w3[1], w3[2]
        return bu, bv, bw
    apx, apy, apz = px - ax, py - ay, pz - az
    d1 = abx * apx + aby * apy + abz * apz
    d2 = acx * apx + acy * apy + acz * apz
    if d1 <= 0.0 and d2 <= 0.0:
        return 1.0, 0.0, 0.0
    bpx, bpy, bpz = apx - abx, apy - aby, apz - abz
    d3 = abx * bpx + aby * bpy + abz * bpz
    d4 = acx * bpx + acy * bpy + acz * bpz
    if d3 >= 0.0 and d4 <= d3:
        return 0.0, 1.0, 0.0
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        v = d1 / (d1 - d3)
        return 1.0 - v, v, 0.0
    cpx, cpy, cpz = apx - acx, apy - acy, apz - acz
    d5 = abx * cpx + aby * cpy + abz * cpz
    d6 = acx * cpx + acy * cpy + acz * cpz
    if d6 >= 0.0 and d5 <= d6:
        return 0.0, 0.0, 1.0
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        w = d2 / (d2 - d6)
        return 1.0 - w, 0.0, w
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and d4 - d3 >= 0.0 and d5 - d6 >= 0.0:
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return 0.0, 1.0 - w, w
    denom = va + vb + vc
    v, w = vb / denom, vc / denom
    return 1.0 - v - w, v, w


@njit(cache=True, fastmath=False, nogil=True)
def _on_boundary(u, v, w, k_edge, k_vert):
    """k_edge/k_vert: boundary flags of the edges opposite / the corners."""
    zu, zv, zw = u == 0.0, v == 0.0, w == 0.0
    nzero = int(zu) + int(zv) + int(zw)
    if nzero == 0:
        return False
    if nzero == 1:
        return k_edge[0] if zu else (k_edge[1] if zv else k_edge[2])
    return k_vert[0] if u != 0.0 else (k_vert[1] if v != 0.0 else k_vert[2])


@njit(cache=True, fastmath=False, parallel=True, nogil=True)
def _surface_planes(field, p0, p1, tris, rads, normals, ebound, vbound, tlo, thi,
                    walls, wlo, whi, n, periodic, band, normal_mode):
    ntri, nwall = tris.shape[0], walls.shape[0]
    for pp in prange(p1 - p0):
        p = p0 + pp
        plane = field[p]
        plane[:, :] = band
        bestd = np.full((n, n), np.inf)
        walld = np.full((n, n), np.inf)
        for e in range(ntri + nwall):
            is_wall = e >= ntri
            lo, hi = (wlo[e - ntri], whi[e - ntri]) if is_wall else (tlo[e], thi[e])
            tri = walls[e - ntri] if is_wall else tris[e]
            i = lo[0] + (p - lo[0]) % n if periodic else p
            while lo[0] <= i <= hi[0]:
                x = i / n
                jlo, jhi, klo, khi = lo[1], hi[1], lo[2], hi[2]
                if not periodic:
                    jlo, jhi, klo, khi = max(jlo, 0), min(jhi, n - 1), max(klo, 0), min(khi, n - 1)
                for j in range(jlo, jhi + 1):
                    y, jj = j / n, j % n
                    for k in range(klo, khi + 1):
                        z, kk = k / n, k % n
                        u, v, w = _closest_bary(x, y, z, tri)
                        cx = u * tri[0, 0] + v * tri[1, 0] + w * tri[2, 0]
                        cy = u * tri[0, 1] + v * tri[1, 1] + w * tri[2, 1]
                        cz = u * tri[0, 2] + v * tri[1, 2] + w * tri[2, 2]
                        d = math.sqrt((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2)
                        if is_wall:
                            walld[jj, kk] = min(walld[jj, kk], d)
                            continue
                        r = u * rads[e, 0] + v * rads[e, 1] + w * rads[e, 2]
                        if not normal_mode:
                            plane[jj, kk] = min(plane[jj, kk], d - r)
                            continue
                        if d >= bestd[jj, kk]:
                            continue
                        bestd[jj, kk] = d
                        if _on_boundary(u, v, w, ebound[e], vbound[e]):
                            h = abs((x - cx) * normals[e, 0] + (y - cy) * normals[e, 1]
                                    + (z - cz) * normals[e, 2])
                            delta2 = max(d * d - h * h, 0.0)
                            over = max(h - r, 0.0)
                            plane[jj, kk] = min(band, math.sqrt(delta2 + over * over))
                        else:
                            plane[jj, kk] = min(band, d - r)
                if not periodic:
                    break
                i += n
        if normal_mode:
            for jj in range(n):
                for kk in range(n):
                    if plane[jj, kk] < 0.0 and -walld[jj, kk] > plane[jj, kk]:
                        plane[jj, kk] = -walld[jj, kk]


# ------------------------------------------------------------------ public API

def surface_sdf_grid(vertices, faces, thickness_per_vertex, *, resolution, method="spherical",
                     periodic=True, band=None, progress=None):
    """Signed distance field of a thickened triangle mesh on the unit cell.

    Parameters
    ----------
    vertices : array_like, shape (n, 3), float
        Mesh vertices in unit-cell coordinates.
    faces : array_like, shape (f, 3), int
        Triangles as vertex indices.
    thickness_per_vertex : array_like, shape (n,), float
        Full thickness (cell units, >= 0) at each vertex; half of it is the
        offset on each side of the surface.
    resolution : int
        N >= 2; nodes at ``i / N``.
    method : {"spherical", "normal"}
        Rounded swept spheres, or a slab cut flat at the surface boundary.
    periodic : bool
        Wrap the mesh across the cell faces (exactly periodic field).
    band : float, optional
        Values are exact up to this distance outside; default ``3 / N``.
    progress : callable, optional
        ``progress(done_planes, N) -> bool``; False raises
        :class:`engine.geometry.Cancelled`.

    Returns
    -------
    numpy.ndarray, shape (N, N, N), float32
        Signed distance (cell units), negative inside, ``[x, y, z]`` order.
    """
    n = check_resolution(resolution)
    band = check_band(band, n)
    v, f, t = _check_mesh(vertices, faces, thickness_per_vertex, method)
    normal_mode = method == "normal"
    tris = v[f] if f.size else np.zeros((0, 3, 3))
    rads = 0.5 * t[f] if f.size else np.zeros((0, 3))
    nrm = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]) if f.size else np.zeros((0, 3))
    length = np.linalg.norm(nrm, axis=1, keepdims=True)
    nrm = np.where(length > 0, nrm / np.where(length > 0, length, 1.0), 0.0)
    ebound, vb = boundary_flags(f, v.shape[0]) if f.size else (np.zeros((0, 3), bool), None)
    vbound = vb[f] if f.size else np.zeros((0, 3), bool)

    walls = np.zeros((0, 3, 3))
    if normal_mode and f.size:
        quads = []
        for tri_id, corner in zip(*np.nonzero(ebound)):
            i, j = (corner + 1) % 3, (corner + 2) % 3
            a, b = tris[tri_id, i], tris[tri_id, j]
            ra, rb, nv = rads[tri_id, i], rads[tri_id, j], nrm[tri_id]
            q = [a + ra * nv, a - ra * nv, b - rb * nv, b + rb * nv]
            quads += [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]
        if quads:
            walls = np.array(quads, dtype=np.float64)

    reach = (rads.max(axis=1) if f.size else np.zeros(0)) + band
    tlo, thi = index_ranges(tris.min(axis=1) - reach[:, None], tris.max(axis=1) + reach[:, None], n)
    wreach = (rads.max() if f.size else 0.0) + band
    wlo, whi = index_ranges(walls.min(axis=1) - wreach, walls.max(axis=1) + wreach, n)
    field = np.empty((n, n, n), dtype=np.float32)
    per = bool(periodic)

    def work(start, stop):
        _surface_planes(field, start, stop, tris, rads, nrm, ebound, vbound, tlo, thi,
                        walls, wlo, whi, n, per, band, normal_mode)

    run_chunked(work, n, progress)
    return field
