"""Signed distance grid of thickened triangle meshes (surface skeletons).

Same grid convention as :mod:`engine.geometry.sdf_lines` (nodes at
``i * L / n`` per axis on the periodic box cell, the unit cube by default,
``[x, y, z]`` order, ``+band`` far away).

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

from engine.progress import run_chunked
from .sdf_lines import check_band, grid_nodes, grid_of, index_ranges

__all__ = ["surface_sdf_grid", "surface_sdf_reference", "boundary_flags"]

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
    # one int64 per undirected edge: a 1-D sort, where np.unique over rows
    # sorts a void view holding the GIL for the whole call
    n = max(int(vertex_count), int(f.max()) + 1 if f.size else 0, 1)
    key = np.minimum(edges[:, 0], edges[:, 1]) * n + np.maximum(edges[:, 0], edges[:, 1])
    _, inverse, counts = np.unique(key, return_inverse=True, return_counts=True)
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
                    walls, wlo, whi, shape, box, periodic, band, normal_mode):
    ntri, nwall = tris.shape[0], walls.shape[0]
    nx, ny, nz = shape[0], shape[1], shape[2]
    lx, ly, lz = box[0], box[1], box[2]
    for pp in prange(p1 - p0):
        p = p0 + pp
        plane = field[p]
        plane[:, :] = band
        bestd = np.full((ny, nz), np.inf)
        walld = np.full((ny, nz), np.inf)
        for e in range(ntri + nwall):
            is_wall = e >= ntri
            lo, hi = (wlo[e - ntri], whi[e - ntri]) if is_wall else (tlo[e], thi[e])
            tri = walls[e - ntri] if is_wall else tris[e]
            i = lo[0] + (p - lo[0]) % nx if periodic else p
            while lo[0] <= i <= hi[0]:
                x = i * lx / nx
                jlo, jhi, klo, khi = lo[1], hi[1], lo[2], hi[2]
                if not periodic:
                    jlo, jhi, klo, khi = max(jlo, 0), min(jhi, ny - 1), max(klo, 0), min(khi, nz - 1)
                for j in range(jlo, jhi + 1):
                    y, jj = j * ly / ny, j % ny
                    for k in range(klo, khi + 1):
                        z, kk = k * lz / nz, k % nz
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
                i += nx
        if normal_mode:
            for jj in range(ny):
                for kk in range(nz):
                    if plane[jj, kk] < 0.0 and -walld[jj, kk] > plane[jj, kk]:
                        plane[jj, kk] = -walld[jj, kk]


# ------------------------------------------------------------------ public API

def _prepare(vertices, faces, thickness_per_vertex, method):
    """Per-triangle arrays shared by the kernel and the reference.

    Returns tris (f, 3, 3), rads (f, 3) half thickness per corner, nrm (f, 3)
    unit normals, ebound (f, 3) / vbound (f, 3) boundary flags of the edge
    opposite / the vertex at each corner, walls (w, 3, 3) triangles of the
    flat end walls ("normal" only, else empty).
    """
    v, f, t = _check_mesh(vertices, faces, thickness_per_vertex, method)
    tris = v[f] if f.size else np.zeros((0, 3, 3))
    rads = 0.5 * t[f] if f.size else np.zeros((0, 3))
    nrm = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]) if f.size else np.zeros((0, 3))
    length = np.linalg.norm(nrm, axis=1, keepdims=True)
    nrm = np.where(length > 0, nrm / np.where(length > 0, length, 1.0), 0.0)
    ebound, vb = boundary_flags(f, v.shape[0]) if f.size else (np.zeros((0, 3), bool), None)
    vbound = vb[f] if f.size else np.zeros((0, 3), bool)

    walls = np.zeros((0, 3, 3))
    if method == "normal" and f.size:
        quads = []
        for tri_id, corner in zip(*np.nonzero(ebound)):
            i, j = (corner + 1) % 3, (corner + 2) % 3
            a, b = tris[tri_id, i], tris[tri_id, j]
            ra, rb, nv = rads[tri_id, i], rads[tri_id, j], nrm[tri_id]
            q = [a + ra * nv, a - ra * nv, b - rb * nv, b + rb * nv]
            quads += [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]
        if quads:
            walls = np.array(quads, dtype=np.float64)
    return tris, rads, nrm, ebound, vbound, walls


def surface_sdf_grid(vertices, faces, thickness_per_vertex, *, resolution, method="spherical",
                     periodic=True, band=None, progress=None, cell=None):
    """Signed distance field of a thickened triangle mesh on the periodic box cell.

    Parameters
    ----------
    vertices : array_like, shape (n, 3), float
        Mesh vertices in cell units.
    faces : array_like, shape (f, 3), int
        Triangles as vertex indices.
    thickness_per_vertex : array_like, shape (n,), float
        Full thickness (cell units, >= 0) at each vertex; half of it is the
        offset on each side of the surface.
    resolution : int or (3,) int
        N >= 2 nodes along the longest box edge (N per axis on the unit
        cube), or the grid shape ``(nx, ny, nz)``; nodes at ``i * Lx / nx`` etc.
    method : {"spherical", "normal"}
        Rounded swept spheres, or a slab cut flat at the surface boundary.
    periodic : bool
        Wrap the mesh across the cell faces with the box period (exactly
        periodic field).
    band : float, optional
        Values are exact up to this distance outside; default 3 voxels
        (``3 / N`` on the unit cube).
    progress : callable, optional
        ``progress(done_planes, nx) -> bool``; False raises
        :class:`engine.geometry.Cancelled`.
    cell : (3,) float, optional
        Box edges ``(Lx, Ly, Lz)`` in cell units; default the unit cube.

    Returns
    -------
    numpy.ndarray, shape (nx, ny, nz), float32
        Signed distance (cell units), negative inside, ``[x, y, z]`` order.
    """
    shape, box = grid_of(resolution, cell)
    band = check_band(band, shape, box)
    tris, rads, nrm, ebound, vbound, walls = _prepare(vertices, faces, thickness_per_vertex, method)
    normal_mode = method == "normal"
    nonempty = tris.shape[0] > 0
    reach = (rads.max(axis=1) if nonempty else np.zeros(0)) + band
    tlo, thi = index_ranges(tris.min(axis=1) - reach[:, None], tris.max(axis=1) + reach[:, None],
                            shape, box)
    wreach = (rads.max() if nonempty else 0.0) + band
    wlo, whi = index_ranges(walls.min(axis=1) - wreach, walls.max(axis=1) + wreach, shape, box)
    field = np.empty(shape, dtype=np.float32)
    per = bool(periodic)
    shape_arr, box_arr = np.array(shape, dtype=np.int64), np.array(box, dtype=np.float64)

    def work(start, stop):
        _surface_planes(field, start, stop, tris, rads, nrm, ebound, vbound, tlo, thi,
                        walls, wlo, whi, shape_arr, box_arr, per, band, normal_mode)

    run_chunked(work, shape[0], progress)
    return field


# ------------------------------------------------------- slow reference (tests)

def _closest_on_segments(p, a, b):
    """(m,) distance from points p (m, 3) to segment ab and the parameter t in [0, 1]."""
    e = b - a
    ee = float(e @ e)
    t = np.zeros(p.shape[0]) if ee <= 0.0 else np.clip((p - a) @ e / ee, 0.0, 1.0)
    return np.linalg.norm(p - (a + t[:, None] * e), axis=1), t


def _closest_on_triangle(p, tri):
    """Distance from points p (m, 3) to a triangle and the barycentric
    coordinates (m, 3) of the closest point: the foot of the perpendicular
    when it lies inside, else the nearest point of the three edges (with
    exact zeros off the edge's corners; a zero-area triangle is its edges)."""
    a, b, c = tri
    n = np.cross(b - a, c - a)
    n2 = float(n @ n)
    w = p - a
    if n2 > 0.0:
        # Barycentrics of the projection (Cramer's rule in the triangle's plane).
        v_ = (np.cross(w, c - a) @ n) / n2
        w_ = (np.cross(b - a, w) @ n) / n2
        bary = np.stack([1.0 - v_ - w_, v_, w_], axis=1)
        inside = (bary >= 0.0).all(axis=1)
        dist = np.where(inside, np.abs(w @ n) / math.sqrt(n2), np.inf)
    else:
        bary, inside, dist = np.zeros((p.shape[0], 3)), np.zeros(p.shape[0], bool), np.full(p.shape[0], np.inf)
    for k in range(3):                 # edge opposite corner k: corners i -> j
        i, j = (k + 1) % 3, (k + 2) % 3
        d, t = _closest_on_segments(p, tri[i], tri[j])
        better = ~inside & (d < dist)
        dist = np.where(better, d, dist)
        edge_bary = np.zeros((p.shape[0], 3))
        edge_bary[:, i], edge_bary[:, j] = 1.0 - t, t
        bary = np.where(better[:, None], edge_bary, bary)
    return dist, bary


def _images(lo, hi, reach, box):
    """(k, 3) lattice translations of a body spanning [lo, hi] that can come
    within ``reach`` of the box."""
    klo = np.floor((-reach - hi) / box).astype(int)
    khi = np.ceil((box + reach - lo) / box).astype(int)
    rng = [np.arange(klo[a], khi[a] + 1) for a in range(3)]
    return np.stack(np.meshgrid(*rng, indexing="ij"), -1).reshape(-1, 3) * box


def surface_sdf_reference(vertices, faces, thickness_per_vertex, *, resolution,
                          method="spherical", periodic=True, band=None, cell=None):
    """Slow, plain-numpy version of :func:`surface_sdf_grid` for tests.

    Every triangle (and every end wall) is measured from every grid node in
    every lattice image that can reach the box (brute force, no index
    windows); the closest point is found by projection onto the plane or
    onto the edges. Same parameters, grid, band and normal-mode rules as
    :func:`surface_sdf_grid` (zero-area skeleton triangles are not
    supported: the kernel treats slivers separately).
    """
    shape, box = grid_of(resolution, cell)
    band = check_band(band, shape, box)
    tris, rads, nrm, ebound, vbound, walls = _prepare(vertices, faces, thickness_per_vertex, method)
    box_arr = np.array(box)
    nodes = grid_nodes(shape, box)
    m = nodes.shape[0]
    field = np.full(m, band)
    bestd = np.full(m, np.inf)
    walld = np.full(m, np.inf)
    zero = np.zeros((1, 3))

    def images(body, reach):
        if not periodic:
            return zero
        return _images(body.min(axis=0), body.max(axis=0), reach, box_arr)

    for e in range(tris.shape[0]):
        for o in images(tris[e], rads[e].max() + band):
            d, bary = _closest_on_triangle(nodes, tris[e] + o)
            r = bary @ rads[e]
            if method == "spherical":
                field = np.minimum(field, d - r)
                continue
            closer = d < bestd
            bestd = np.where(closer, d, bestd)
            nzero = (bary == 0.0).sum(axis=1)
            edge = np.where(nzero == 1, ebound[e][np.argmin(np.abs(bary), axis=1)], False)
            vert = np.where(nzero == 2, vbound[e][np.argmax(np.abs(bary), axis=1)], False)
            h = np.abs((nodes - (bary @ (tris[e] + o))) @ nrm[e])
            past = np.sqrt(np.maximum(d * d - h * h, 0.0) + np.maximum(h - r, 0.0) ** 2)
            val = np.minimum(band, np.where(edge | vert, past, d - r))
            field = np.where(closer, val, field)
    wreach = (rads.max() if tris.shape[0] else 0.0) + band
    for w in walls:
        for o in images(w, wreach):
            walld = np.minimum(walld, _closest_on_triangle(nodes, w + o)[0])
    if method == "normal":
        field = np.where((field < 0.0) & (-walld > field), -walld, field)
    return field.reshape(shape).astype(np.float32)
