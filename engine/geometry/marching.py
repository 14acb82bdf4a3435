"""Tileable meshes from periodic node-sampled fields (paper section 6.5).

A field of shape (nx, ny, nz) holds node samples ``x_i = i * Lx / nx`` (and
likewise along y, z) of one periodic box cell (see
:mod:`engine.geometry.sdf_lines`; the unit cube by default); "inside" is
``field < level``.
:func:`periodic_mesh` tiles it, appends the wrap sample so the grid reaches
the far faces, optionally caps the solid where it meets the box, and runs
marching cubes (scikit-image, Lewiner). Because opposite faces of the tiled
grid carry identical samples, the mesh of one cell tiles with its
translated copies; :func:`boundary_section_match` checks that geometrically.
"""

from __future__ import annotations

import numpy as np

from .box_cell import check_cell
from .slab_marching import slab_marching_cubes
from engine.progress import report

__all__ = ["periodic_mesh", "box_mesh", "drop_specks", "boundary_section_match", "solid_volume_fraction",
           "mesh_volume_fraction", "mesh_volume"]


def _check_field(field):
    f = np.asarray(field)
    if f.ndim != 3 or min(f.shape) < 2:
        raise ValueError(f"field must be a 3-D grid with at least 2 samples per axis; got shape {f.shape}")
    if not np.all(np.isfinite(f)):
        raise ValueError("field must be finite; got NaN or inf")
    return f


def _check_level(level):
    lv = float(level)
    if not np.isfinite(lv):
        raise ValueError(f"level must be finite; got {level!r}")
    return lv


def periodic_mesh(field, *, level=0.0, tiles=(1, 1, 1), cell_size=1.0, cell=None, closed=True,
                  progress=None):
    """Extract the (tiled) solid ``field < level`` as a triangle mesh.

    Parameters
    ----------
    field : numpy.ndarray, shape (N0, N1, N2), float
        Periodic node samples of one cell, ``[x, y, z]`` order.
    level : float
        Iso-value; inside is ``field < level``.
    tiles : tuple of 3 int >= 1
        Number of cells along x, y, z.
    cell_size : float > 0
        Model units (mm) per cell unit: the unit cube's edge length.
    cell : (3,) float, optional
        Box edges ``(Lx, Ly, Lz)`` in cell units (default the unit cube); the
        tile is ``cell_size * cell`` model units, node spacing
        ``cell_size * L_i / n_i`` per axis.
    closed : bool
        Cap the solid on the faces of the tiled box so the mesh is watertight.
        If False the mesh is open where the solid meets the box.
    progress : callable(done, total) -> bool, optional
        Called between slabs of the grid; returning False raises Cancelled.

    Returns
    -------
    vertices : numpy.ndarray, shape (v, 3), float64
        Model units, inside the box ``[0, tiles * cell_size * cell]``.
    faces : numpy.ndarray, shape (f, 3), int64
        Counter-clockwise seen from outside (outward normals, positive
        volume). Empty arrays if the field has no surface.

    Notes
    -----
    Samples within a relative 1e-7 of ``level`` are nudged off it: marching
    cubes would otherwise place several vertices at the same grid node and
    downstream vertex merging would break the watertight topology.
    Caps: crossings into the outside pad layer are clipped onto the box
    faces; where that makes vertices coincide (box edges and corners) they
    are welded and the collapsed triangles dropped.
    Memory: the tiled grid is float32 with ``(N * tiles + 3)`` samples per
    axis (about 230 MB for N = 128 and 3 x 3 x 3 tiles) plus the mesh.
    """
    f = _check_field(field)
    lv = _check_level(level)
    try:
        t = tuple(int(x) for x in tiles)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"tiles must be three integers >= 1; got {tiles!r}") from exc
    if len(t) != 3 or min(t) < 1 or any(float(x) != float(y) for x, y in zip(tiles, t)):
        raise ValueError(f"tiles must be three integers >= 1; got {tiles!r}")
    cs = float(cell_size)
    if not np.isfinite(cs) or cs <= 0:
        raise ValueError(f"cell_size must be a finite length > 0; got {cell_size!r}")
    box = np.array(check_cell(cell), dtype=np.float64)

    spacing = cs * box / np.array(f.shape, dtype=np.float64)
    extent = cs * box * np.array(t, dtype=np.float64)
    axes = [np.arange(f.shape[a] * t[a] + 1) % f.shape[a] for a in range(3)]
    return _mesh_grid(f, axes, lv, spacing, extent, closed, progress)


def box_mesh(samples, *, spacing, level=0.0, progress=None):
    """The solid ``samples < level`` of a box that is not a periodic cell, capped where it
    meets the box (watertight).

    Parameters
    ----------
    samples : (n0, n1, n2) float, n_i >= 2
        Node samples ``[x, y, z]`` at ``i * spacing`` (both box faces included).
    spacing : (3,) float > 0
        Node spacing per axis, model units (mm).
    level, progress : as in `periodic_mesh`.

    Returns
    -------
    vertices (v, 3) float64 in ``[0, (n - 1) * spacing]``, faces (f, 3) int64,
    outward; empty arrays if nothing lies inside.

    Raises
    ------
    ValueError
        For a grid that is not 3-D with two samples per axis, NaN samples or a
        spacing that is not three lengths > 0.
    """
    f = _check_field(samples)
    lv = _check_level(level)
    h = np.asarray(spacing, dtype=np.float64).reshape(-1)
    if h.shape != (3,) or not np.all(np.isfinite(h)) or np.any(h <= 0):
        raise ValueError(f"spacing must be three lengths > 0; got {spacing!r}")
    extent = h * (np.array(f.shape, dtype=np.float64) - 1)
    return _mesh_grid(f, [np.arange(n) for n in f.shape], lv, h, extent, True, progress)


def _mesh_grid(f, axes, lv, spacing, extent, closed, progress):
    """Marching cubes of ``f[np.ix_(*axes)]`` (node spacing `spacing`), capped on the box
    ``[0, extent]`` if `closed`."""
    # scikit-image works in float32; do the nudging there so it survives.
    f = f.astype(np.float32)
    lv32 = np.float32(lv)
    spread = float(np.abs(f - lv32).max())
    eps = np.float32(max(1e-7 * spread, 4.0 * float(np.spacing(np.abs(lv32))), 1e-30))
    near = np.abs(f - lv32) < eps
    f[near] = np.where(f[near] < lv32, lv32 - eps, lv32 + eps)
    if not ((f < lv32).any() and ((f > lv32).any() or closed)):
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)

    # Gather the grid (a tiled cell appends the wrap sample); with ``closed``
    # it gets a layer of clearly-outside samples all round, whose crossings
    # are clipped back onto the box faces below.
    pad = 1 if closed else 0
    grid = tiled_grid(f, axes, pad, lv32 + np.float32(10.0 * (spread + 1.0)))

    verts, faces = slab_marching_cubes(grid, float(lv32), progress)
    verts = (verts.astype(np.float64) - pad) * spacing
    faces = faces.astype(np.int64)
    if closed:
        # the last node plane times the spacing can miss the box face by an
        # ulp (L / n * n != L); put it exactly on the face, where the welding
        # below recognises the box edges
        verts = np.where(np.abs(verts - extent) <= 1e-12 * extent, extent, np.clip(verts, 0.0, extent))
        verts, faces = weld_clipped(verts, faces, extent)
        verts, faces = drop_specks(verts, faces, 0.5 * float(np.prod(spacing)))
    return verts, faces


def tiled_grid(f, axes, pad, outside, planes=8):
    """The tiled grid ``f[np.ix_(*axes)]`` inside ``pad`` layers of ``outside``.

    Filled a few x planes at a time: one gather over the whole block (58 M
    samples for 3 x 3 x 3 cells of 128^3) would hold the GIL for a long stretch.
    """
    shape = [len(ax) + 2 * pad for ax in axes]
    grid = np.empty(shape, dtype=np.float32)
    if pad:
        grid[:pad] = outside
        grid[shape[0] - pad:] = outside
    for i0 in range(0, len(axes[0]), planes):
        sub = grid[pad + i0:pad + min(i0 + planes, len(axes[0]))]
        if pad:
            sub[:, :pad] = outside
            sub[:, shape[1] - pad:] = outside
            sub[:, :, :pad] = outside
            sub[:, :, shape[2] - pad:] = outside
        sub[:, pad:shape[1] - pad, pad:shape[2] - pad] = f[np.ix_(axes[0][i0:i0 + planes], axes[1], axes[2])]
    return grid


def drop_specks(vertices, faces, min_volume):
    """Remove closed pieces enclosing less than ``min_volume`` (absolute).

    Where two rounded solids meet in a sharp concave crease, single grid
    nodes can be trapped just outside both; marching cubes then emits
    sub-voxel void bubbles (or solid specks) that are closed but carry no
    real geometry.  Whole closed pieces are dropped, so a watertight mesh
    stays watertight.
    """
    from .mesh_components import vertex_components
    from .slab_marching import CHUNK_ROWS, compress_rows, index_of_kept, take_chunked

    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    if f.shape[0] == 0:
        return v, f
    n = v.shape[0]
    count, label = vertex_components(f, n)
    if count == 1:
        return v, f
    # in chunks of faces: each numpy call below is short (the results are row-wise)
    vol6 = np.empty(f.shape[0])
    for r0 in range(0, f.shape[0], CHUNK_ROWS):
        tri = v[f[r0:r0 + CHUNK_ROWS]]
        vol6[r0:r0 + CHUNK_ROWS] = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2]))
    face_label = take_chunked(label, f[:, 0])
    piece_volume = np.abs(np.bincount(face_label, weights=vol6, minlength=count)) / 6.0
    keep_face = piece_volume[face_label] >= min_volume
    if keep_face.all():
        return v, f
    f = compress_rows(f, keep_face)
    used = np.zeros(n, dtype=bool)
    used[f.ravel()] = True
    return take_chunked(v, np.flatnonzero(used)), take_chunked(index_of_kept(used), f)


def weld_clipped(verts, faces, extent):
    """Merge vertices that clipping made identical; drop collapsed triangles.

    A node on a box edge (corner) has two (three) pad neighbours; the
    crossings towards them all clip onto that node. They are joined by
    surface edges, so welding them is an edge collapse of a thin strip of
    the cap, which keeps the surface closed and manifold; the triangles
    that collapse to zero area (repeated index) are removed. Only vertices
    on box edges can coincide, so only those are compared.
    """
    on_box = ((verts == 0.0) | (verts == extent)).sum(axis=1) >= 2
    cand = np.flatnonzero(on_box)
    if cand.size < 2:
        return verts, faces
    _, first, inverse = np.unique(verts[cand], axis=0, return_index=True, return_inverse=True)
    if first.size == cand.size:
        return verts, faces
    from .slab_marching import compress_rows, index_of_kept, take_chunked

    remap = np.arange(verts.shape[0])
    remap[cand] = cand[first][inverse.ravel()]
    faces = take_chunked(remap, faces)
    keep = (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 2] != faces[:, 0])
    faces = compress_rows(faces, keep)
    used = np.zeros(verts.shape[0], dtype=bool)
    used[faces.ravel()] = True
    return take_chunked(verts, np.flatnonzero(used)), take_chunked(index_of_kept(used), faces)


def mesh_volume(vertices, faces):
    """Signed enclosed volume (divergence theorem), model units cubed."""
    v = np.asarray(vertices, dtype=np.float64)
    tri = v[np.asarray(faces, dtype=np.int64)]
    if tri.size == 0:
        return 0.0
    return float(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6.0)


def mesh_volume_fraction(vertices, faces, cell_volume):
    """Enclosed volume of a closed mesh divided by ``cell_volume``.

    Parameters
    ----------
    vertices : (v, 3) float; faces : (f, 3) int
        A closed, outward-oriented mesh (e.g. from :func:`periodic_mesh`).
    cell_volume : float > 0
        Volume of the box the mesh fills (model units cubed).

    Returns
    -------
    float
    """
    cv = float(cell_volume)
    if not np.isfinite(cv) or cv <= 0:
        raise ValueError(f"cell_volume must be a finite volume > 0; got {cell_volume!r}")
    return mesh_volume(vertices, faces) / cv


def solid_volume_fraction(field, *, level=0.0):
    """Fraction of node samples inside (``field < level``).

    Parameters
    ----------
    field : numpy.ndarray, shape (N0, N1, N2)
        Periodic node samples; each stands for one voxel of the cell.
    level : float

    Returns
    -------
    float in [0, 1]
    """
    f = _check_field(field)
    return float(np.count_nonzero(f < _check_level(level)) / f.size)


def _distinct(points, tol):
    """One copy of each position (positions closer than ``tol`` are one)."""
    if points.shape[0] < 2:
        return points.copy()
    return points[np.unique(np.round(points / tol), axis=0, return_index=True)[1]].copy()


def boundary_section_match(vertices, faces, *, cell_size, cell=None):
    """How far the mesh's sections on opposite cell faces are from coinciding.

    For each axis, the vertices (referenced by ``faces``) lying on the face
    ``x = 0`` are compared with those on ``x = cell_size * Lx`` translated
    back by that period. A single-cell mesh from a periodic field tiles iff
    these point sets coincide.

    Parameters
    ----------
    vertices : (v, 3) float; faces : (f, 3) int
    cell_size : float > 0
        Model units per cell unit (the unit cube's edge; the mesh spans one cell).
    cell : (3,) float, optional
        Box edges in cell units; default the unit cube.

    Returns
    -------
    float
        Largest nearest-neighbour distance between the paired point sets,
        both ways, over the three axes (0.0 if no vertex touches any face);
        ``inf`` if a pair of faces carries different numbers of distinct vertex positions.
    """
    from scipy.spatial import cKDTree

    cs = float(cell_size)
    if not np.isfinite(cs) or cs <= 0:
        raise ValueError(f"cell_size must be a finite length > 0; got {cell_size!r}")
    period = cs * np.array(check_cell(cell), dtype=np.float64)
    v = np.asarray(vertices, dtype=np.float64)
    used = np.unique(np.asarray(faces, dtype=np.int64).ravel())
    v = v[used] if used.size else np.zeros((0, 3))
    worst = 0.0
    for axis in range(3):
        tol = 1e-9 * max(1.0, float(period[axis]))
        # distinct positions: where two sheets of the solid touch the face at
        # a point, marching cubes keeps one vertex per sheet there
        low = _distinct(v[np.abs(v[:, axis]) <= tol], tol)
        high = _distinct(v[np.abs(v[:, axis] - period[axis]) <= tol], tol)
        if low.shape[0] != high.shape[0]:
            return float("inf")
        if low.shape[0] == 0:
            continue
        high[:, axis] -= period[axis]
        worst = max(worst, float(cKDTree(high).query(low)[0].max()),
                    float(cKDTree(low).query(high)[0].max()))
    return worst
