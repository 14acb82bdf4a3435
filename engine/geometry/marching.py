"""Tileable meshes from periodic node-sampled fields (paper section 6.5).

A field of shape (N, N, N) holds node samples ``x_i = i / N`` of one periodic
cell (see :mod:`engine.geometry.sdf_lines`); "inside" is ``field < level``.
:func:`periodic_mesh` tiles it, appends the wrap sample so the grid reaches
the far faces, optionally caps the solid where it meets the box, and runs
marching cubes (scikit-image, Lewiner). Because opposite faces of the tiled
grid carry identical samples, the mesh of one cell tiles with its
translated copies; :func:`boundary_section_match` checks that geometrically.
"""

from __future__ import annotations

import numpy as np

__all__ = ["periodic_mesh", "boundary_section_match", "solid_volume_fraction",
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


def periodic_mesh(field, *, level=0.0, tiles=(1, 1, 1), cell_size=1.0, closed=True):
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
        Edge length of one cell in model units.
    closed : bool
        Cap the solid on the faces of the tiled box so the mesh is watertight.
        If False the mesh is open where the solid meets the box.

    Returns
    -------
    vertices : numpy.ndarray, shape (v, 3), float64
        Model units, inside the box ``[0, tiles * cell_size]``.
    faces : numpy.ndarray, shape (f, 3), int64
        Counter-clockwise seen from outside (outward normals, positive
        volume). Empty arrays if the field has no surface.

    Notes
    -----
    Samples within a relative 1e-7 of ``level`` are nudged off it: marching
    cubes would otherwise place several vertices at the same grid node and
    downstream vertex merging would break the watertight topology.
    """
    from skimage.measure import marching_cubes

    f = _check_field(field).astype(np.float64)
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

    spread = float(np.abs(f - lv).max())
    eps = 1e-7 * max(spread, 1e-30)
    near = np.abs(f - lv) < eps
    f[near] = np.where(f[near] < lv, lv - eps, lv + eps)

    grid = np.pad(np.tile(f, t), [(0, 1)] * 3, mode="wrap")
    offset = 0
    if closed:
        # A layer of clearly-outside samples all round closes the surface;
        # the crossings it creates are clipped back onto the box faces below.
        grid = np.pad(grid, 1, mode="constant", constant_values=lv + 10.0 * (spread + 1.0))
        offset = 1
    if not ((grid < lv).any() and (grid > lv).any()):
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)

    verts, faces, _, _ = marching_cubes(grid, level=lv, gradient_direction="descent",
                                        allow_degenerate=True)
    spacing = cs / np.array(f.shape, dtype=np.float64)
    extent = cs * np.array(t, dtype=np.float64)
    verts = (verts.astype(np.float64) - offset) * spacing
    verts = np.clip(verts, 0.0, extent)
    return verts, faces.astype(np.int64)


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


def boundary_section_match(vertices, faces, *, cell_size):
    """How far the mesh's sections on opposite cell faces are from coinciding.

    For each axis, the vertices (referenced by ``faces``) lying on the face
    ``x = 0`` are compared with those on ``x = cell_size`` translated back by
    ``cell_size``. A single-cell mesh from a periodic field tiles iff these
    point sets coincide.

    Parameters
    ----------
    vertices : (v, 3) float; faces : (f, 3) int
    cell_size : float > 0
        Cell edge length in model units (the mesh spans one cell).

    Returns
    -------
    float
        Largest nearest-neighbour distance between the paired point sets,
        both ways, over the three axes (0.0 if no vertex touches any face);
        ``inf`` if a pair of faces carries different numbers of vertices.
    """
    from scipy.spatial import cKDTree

    cs = float(cell_size)
    if not np.isfinite(cs) or cs <= 0:
        raise ValueError(f"cell_size must be a finite length > 0; got {cell_size!r}")
    v = np.asarray(vertices, dtype=np.float64)
    used = np.unique(np.asarray(faces, dtype=np.int64).ravel())
    v = v[used] if used.size else np.zeros((0, 3))
    tol = 1e-9 * max(1.0, cs)
    worst = 0.0
    for axis in range(3):
        low = v[np.abs(v[:, axis]) <= tol]
        high = v[np.abs(v[:, axis] - cs) <= tol].copy()
        if low.shape[0] != high.shape[0]:
            return float("inf")
        if low.shape[0] == 0:
            continue
        high[:, axis] -= cs
        worst = max(worst, float(cKDTree(high).query(low)[0].max()),
                    float(cKDTree(low).query(high)[0].max()))
    return worst
