"""The part to fill: a closed triangle mesh, its inside on grids and slices.

Phasor infill fills the inside of the part (Tricard et al., sections 3.3 and
6).  Inside means generalized winding number > 1/2 (Jacobson et al. 2013),
which is robust to small cracks; the mesh must still be closed and
consistently oriented so that "inside" has one meaning.  Slices for
toolpaths use the exact cross-section polygon filled by scanlines (even-odd
rule), which is both exact and much faster than a winding number per pixel.

In-plane coordinates of a slice follow :mod:`engine.phasor.strokes`: on the
plane normal to ``axis`` the pixel columns run along u and the rows along v::

    axis "z": (u, v) = (x, y)     axis "y": (u, v) = (x, z)     axis "x": (u, v) = (y, z)
"""

from __future__ import annotations

import math

import numpy as np

from engine.phasor.strokes import PLANE_AXES

__all__ = ["load_domain_mesh", "check_closed", "inside_mask", "domain_grid", "slice_domain",
           "box_of"]


def mesh_arrays(mesh):
    """(vertices (v, 3) float64, faces (f, 3) int64) of a trimesh or a (v, f) pair."""
    if hasattr(mesh, "vertices") and hasattr(mesh, "faces"):
        v, f = mesh.vertices, mesh.faces
    else:
        v, f = mesh
    v = np.ascontiguousarray(v, dtype=np.float64)
    f = np.ascontiguousarray(f, dtype=np.int64)
    if v.ndim != 2 or v.shape[1] != 3 or f.ndim != 2 or f.shape[1] != 3 or len(f) == 0:
        raise ValueError(f"mesh: expected (v, 3) vertices and non-empty (f, 3) faces; got "
                         f"{v.shape} and {f.shape}")
    return v, f


def _fmt(p) -> str:
    return "(" + ", ".join(f"{c:.4g}" for c in p) + ") mm"


def check_closed(vertices, faces) -> None:
    """Refuse a mesh that does not bound a volume, saying where it fails.

    Every undirected edge must belong to exactly two faces that traverse it
    in opposite directions, and the enclosed volume must be non-zero.
    """
    v, f = mesh_arrays((vertices, faces))
    directed = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    undirected = np.sort(directed, axis=1)
    edges, counts = np.unique(undirected, axis=0, return_counts=True)
    for bad, what in ((counts == 1, "boundary"), (counts > 2, "non-manifold")):
        if bad.any():
            a, b = edges[np.flatnonzero(bad)[0]]
            raise ValueError(f"mesh is not closed: {int(bad.sum())} {what} edge(s), e.g. from "
                             f"{_fmt(v[a])} to {_fmt(v[b])}")
    # a consistently oriented closed mesh uses each directed edge once
    dedges, dcount = np.unique(directed, axis=0, return_counts=True)
    if np.any(dcount > 1):
        a, b = dedges[np.flatnonzero(dcount > 1)[0]]
        raise ValueError(f"mesh faces are not consistently oriented: {int((dcount > 1).sum())} "
                         f"edge(s) traversed twice the same way, e.g. from {_fmt(v[a])} to {_fmt(v[b])}")
    volume = _volume(v, f)
    extent = float(np.ptp(v, axis=0).max())
    if not abs(volume) > 1e-9 * extent ** 3:
        raise ValueError(f"mesh encloses no volume ({volume:.3g} mm^3 for a part {extent:.3g} mm across)")


def _volume(v, f) -> float:
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum()) / 6.0


def load_domain_mesh(path):
    """Read the part (STL, OBJ, PLY or 3MF) and check it is a closed solid.

    Coincident vertices are merged; a mesh whose faces all point inward is
    turned outside-out so that its volume is positive.

    Returns
    -------
    trimesh.Trimesh
        Watertight, consistently wound, positive volume (mm).

    Raises
    ------
    ValueError
        For an open mesh (number of boundary edges and one of them), a
        non-manifold or inconsistently oriented one, or one with no volume.
    """
    import trimesh

    from engine.geometry.mesh_io import load_mesh

    v, f = load_mesh(path)
    if len(f) == 0:
        raise ValueError(f"mesh {str(path)!r} has no faces")
    try:
        check_closed(v, f)
    except ValueError as err:
        raise ValueError(f"{str(path)!r}: {err}") from None
    if _volume(v, f) < 0:
        f = f[:, ::-1].copy()
    return trimesh.Trimesh(v, f, process=False)


def inside_mask(mesh, points) -> np.ndarray:
    """(n,) bool: generalized winding number of ``points`` (n, 3) mm > 1/2.

    Uses libigl's fast (Barnes-Hut) winding number; points within a small
    fraction of a face size of the surface may go either way.
    """
    import igl

    v, f = mesh_arrays(mesh)
    q = np.ascontiguousarray(np.asarray(points, dtype=np.float64).reshape(-1, 3))
    if len(q) == 0:
        return np.zeros(0, dtype=bool)
    wn = igl.fast_winding_number(v, f, q)
    sign = 1.0 if _volume(v, f) >= 0 else -1.0
    return sign * wn > 0.5


def domain_grid(mesh, lo, hi, shape) -> np.ndarray:
    """(nz, ny, nx) bool: which cell centres of a grid over ``lo..hi`` are inside."""
    lo = np.asarray(lo, dtype=np.float64)
    hi = np.asarray(hi, dtype=np.float64)
    shape = tuple(int(s) for s in shape)
    if lo.shape != (3,) or hi.shape != (3,) or np.any(~(hi > lo)) or len(shape) != 3 or min(shape) < 1:
        raise ValueError(f"grid: expected lo < hi (3 numbers each, mm) and shape (nz, ny, nx) >= 1; "
                         f"got {lo.tolist()}, {hi.tolist()}, {shape}")
    step = (hi - lo) / np.array(shape[::-1])
    xs, ys, zs = (lo[a] + (np.arange(n) + 0.5) * step[a] for a, n in enumerate(shape[::-1]))
    z, y, x = np.meshgrid(zs, ys, xs, indexing="ij")
    return inside_mask(mesh, np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)).reshape(shape)


def _section(v, f, axis, position):
    """(m, 2, 2) in-plane segments where the mesh crosses the plane.

    A vertex lying on the plane counts as below it, so each triangle crossed
    yields exactly one segment and coplanar faces yield none; a solid
    spanning lo..hi along ``axis`` thus has a section for lo <= position < hi.
    """
    u_i, v_i, n_i = PLANE_AXES[axis]
    above = v[:, n_i] > position
    fa = above[f]
    crossed = fa.any(axis=1) & ~fa.all(axis=1)
    tri = f[crossed]
    ta = fa[crossed]
    # roll each triangle so vertex 0 is the one alone on its side
    lone = np.where(ta.sum(axis=1) == 1, np.argmax(ta, axis=1), np.argmin(ta, axis=1))
    order = (lone[:, None] + np.arange(3)) % 3
    tri = np.take_along_axis(tri, order, axis=1)
    p0, p1, p2 = v[tri[:, 0]], v[tri[:, 1]], v[tri[:, 2]]

    def cut(a, b):
        t = (position - a[:, n_i]) / (b[:, n_i] - a[:, n_i])
        return a[:, [u_i, v_i]] + t[:, None] * (b[:, [u_i, v_i]] - a[:, [u_i, v_i]])

    return np.stack([cut(p0, p1), cut(p0, p2)], axis=1)


def slice_domain(mesh, axis, position, *, lo, hi, shape) -> np.ndarray:
    """(H, W) bool: pixels of a slice that lie inside the part.

    Parameters
    ----------
    mesh : trimesh.Trimesh or (vertices, faces), closed
    axis : "x" | "y" | "z", the slice plane's normal
    position : float, mm along ``axis``
    lo, hi : (2,) float, in-plane (u, v) corners of the pixel grid, mm
    shape : (H, W) int; pixel centres at ``lo + (index + 0.5) * (hi - lo) / (W, H)``,
        row r along v, column c along u

    The cross-section polygon is filled by horizontal scanlines through the
    pixel centres with the even-odd rule.
    """
    if axis not in PLANE_AXES:
        raise ValueError(f"axis: expected 'x', 'y' or 'z', got {axis!r}")
    if not isinstance(position, (int, float, np.floating)) or not math.isfinite(position):
        raise ValueError(f"position: expected a finite number of mm, got {position!r}")
    lo = np.asarray(lo, dtype=np.float64)
    hi = np.asarray(hi, dtype=np.float64)
    shape = tuple(int(s) for s in shape)
    if lo.shape != (2,) or hi.shape != (2,) or np.any(~(hi > lo)) or len(shape) != 2 or min(shape) < 1:
        raise ValueError(f"pixel grid: expected lo < hi (2 numbers each, mm) and shape (H, W) >= 1; "
                         f"got {lo.tolist()}, {hi.tolist()}, {shape}")
    v, f = mesh_arrays(mesh)
    seg = _section(v, f, axis, float(position))
    h, w = shape
    us = lo[0] + (np.arange(w) + 0.5) * (hi[0] - lo[0]) / w
    vs = lo[1] + (np.arange(h) + 0.5) * (hi[1] - lo[1]) / h
    out = np.zeros(shape, dtype=bool)
    if len(seg) == 0:
        return out
    a, b = seg[:, 0], seg[:, 1]
    v_lo, v_hi = np.minimum(a[:, 1], b[:, 1]), np.maximum(a[:, 1], b[:, 1])
    # rows each segment spans, half-open in v so a shared endpoint counts once
    r0 = np.searchsorted(vs, v_lo, side="left")
    r1 = np.searchsorted(vs, v_hi, side="left")
    span = r1 - r0
    keep = span > 0
    if not keep.any():
        return out
    seg_id = np.repeat(np.flatnonzero(keep), span[keep])
    first = np.repeat(np.cumsum(span[keep]) - span[keep], span[keep])
    row = r0[seg_id] + np.arange(len(seg_id)) - first
    pa, pb = a[seg_id], b[seg_id]
    t = (vs[row] - pa[:, 1]) / (pb[:, 1] - pa[:, 1])
    cross_u = pa[:, 0] + t * (pb[:, 0] - pa[:, 0])
    # sort crossings by (row, u); per row, a pixel is inside when an odd number lie left of it
    order = np.lexsort((cross_u, row))
    row, cross_u = row[order], cross_u[order]
    starts = np.searchsorted(row, np.arange(h), side="left")
    stops = np.searchsorted(row, np.arange(h), side="right")
    for r in np.flatnonzero(stops > starts):
        left = np.searchsorted(cross_u[starts[r]:stops[r]], us, side="left")
        out[r] = (left & 1).astype(bool)
    return out


def box_of(mesh, margin: float = 0.0):
    """(lo, hi) (3,) float64 mm: the mesh's bounding box grown by ``margin`` >= 0 mm."""
    if isinstance(margin, bool) or not isinstance(margin, (int, float, np.floating)) \
            or not math.isfinite(margin) or margin < 0:
        raise ValueError(f"margin: expected a finite number >= 0 mm, got {margin!r}")
    v, _ = mesh_arrays(mesh)
    return v.min(axis=0) - margin, v.max(axis=0) + margin
