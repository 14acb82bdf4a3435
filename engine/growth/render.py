"""Tilings to pixels, voxels, beams and outlines.

2D: each tile becomes a ``resolution x resolution`` binary image (1 = solid,
the paper maps each block to 20 x 20 pixels); pixel ``[r, c]`` has its
centre at block coordinates ``x = (c + 0.5) / resolution``,
``y = (r + 0.5) / resolution`` and is solid when that centre lies closer
than ``line_width / 2`` pixels to a polyline segment (round joints and
ends). Arms end at edge midpoints and the sampling is symmetric, so the
images of compatible neighbours meet exactly, periodic seams included. For
even ``line_width`` and ``resolution`` a straight arm is exactly
``line_width`` pixels wide.

3D: tiles become beams -- polylines with a radius, in physical units (the
paper: 5 mm cubes, 1 mm radius) for ``engine.geometry.line_sdf_grid`` -- or
voxel grids sampled the same way as the pixels.

Images and voxel grids are indexed like the tiling grid: ``[row, col]`` =
``[y, x]``, ``[z, y, x]`` in 3D.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from .tiling import Tiling

__all__ = ["segment_distance", "block_image", "tile_images", "tiling_image", "tiling_outline",
           "block_voxels", "tiling_voxels", "tiling_beams"]


def segment_distance(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Euclidean distance from each of (P, ndim) points to the segment [a, b]."""
    ab = b - a
    L2 = float(ab @ ab)
    ap = points - a
    t = np.zeros(len(points)) if L2 == 0 else np.clip(ap @ ab / L2, 0.0, 1.0)
    return np.linalg.norm(ap - t[:, None] * ab, axis=1)


def _sample(polylines, centres: np.ndarray, radius: float) -> np.ndarray:
    """Bool per sample point: strictly within ``radius`` of some segment."""
    solid = np.zeros(len(centres), dtype=bool)
    for poly in polylines:
        p = np.asarray(poly, dtype=np.float64)
        for a, b in zip(p[:-1], p[1:]):
            solid |= segment_distance(centres, a, b) < radius
    return solid


def _centres(resolution: int, ndim: int) -> np.ndarray:
    """(resolution**ndim, ndim) sample centres in (x, y[, z]) block units, grid order."""
    u = (np.arange(resolution) + 0.5) / resolution
    grids = np.meshgrid(*([u] * ndim), indexing="ij")     # axes (z,) y, x
    return np.stack([g.ravel() for g in grids[::-1]], axis=1)


def _check_res(resolution, what="resolution"):
    if isinstance(resolution, bool) or not isinstance(resolution, (int, np.integer)) \
            or resolution < 1:
        raise ValueError(f"{what} must be an integer >= 1; got {resolution!r}")
    return int(resolution)


def block_image(tile, *, resolution: int = 20, line_width: float = 4.0) -> np.ndarray:
    """Pixel image of one 2D tile.

    Parameters
    ----------
    tile : Tile, 2D
    resolution : int, pixels per block edge
    line_width : float > 0, member thickness in pixels

    Returns
    -------
    (resolution, resolution) uint8, 1 = solid
    """
    n = _check_res(resolution)
    if not line_width > 0:
        raise ValueError(f"line_width must be > 0 pixels; got {line_width!r}")
    if tile.transform.shape != (2, 2):
        raise ValueError(f"block_image needs a 2D tile; {tile.name!r} is "
                         f"{tile.transform.shape[0]}D")
    solid = _sample(tile.polylines, _centres(n, 2), line_width / 2.0 / n)
    return solid.reshape(n, n).astype(np.uint8)


@lru_cache(maxsize=32)
def _tile_images(tileset, n: int, line_width: float) -> np.ndarray:
    out = np.stack([block_image(t, resolution=n, line_width=line_width)
                    for t in tileset.tiles] + [np.zeros((n, n), np.uint8)])
    out.setflags(write=False)
    return out


def tile_images(tileset, *, resolution: int = 20, line_width: float = 4.0) -> np.ndarray:
    """(n_tiles, resolution, resolution) uint8 images of every tile (read-only)."""
    return _tile_images(tileset, _check_res(resolution), float(line_width))[:-1]


def tiling_image(tiling: Tiling, tileset, *, resolution: int = 20,
                 line_width: float = 4.0) -> np.ndarray:
    """Binary image of a 2D tiling; defects and unassigned cells are void.

    Returns
    -------
    (resolution * ny, resolution * nx) uint8, 1 = solid
    """
    if tiling.tiles.ndim != 2:
        raise ValueError(f"tiling_image needs a 2D tiling; got shape {tiling.shape}")
    n = _check_res(resolution)
    imgs = _tile_images(tileset, n, float(line_width))
    idx = np.where(tiling.tiles >= 0, tiling.tiles, len(imgs) - 1)
    ny, nx = idx.shape
    return imgs[idx].transpose(0, 2, 1, 3).reshape(ny * n, nx * n)


def tiling_outline(image: np.ndarray) -> list:
    """Boundary polygons of the solid in a binary image (marching squares).

    Returns
    -------
    list of (m, 2) float64, closed contours in pixel coordinates
    ``(row, col)`` of pixel centres; solids touching the border are closed
    along it.
    """
    from skimage.measure import find_contours
    img = np.pad(np.asarray(image, dtype=np.float64), 1)
    return [c - 1.0 for c in find_contours(img, 0.5)]


def block_voxels(tile, *, resolution: int = 20, radius: float = 0.2) -> np.ndarray:
    """Voxel grid of one 3D tile, beams of ``radius`` (block units).

    Returns
    -------
    (resolution,) * 3 bool, ``[z, y, x]``
    """
    n = _check_res(resolution)
    if not radius > 0:
        raise ValueError(f"radius must be > 0 (block units); got {radius!r}")
    if tile.transform.shape != (3, 3):
        raise ValueError(f"block_voxels needs a 3D tile; {tile.name!r} is "
                         f"{tile.transform.shape[0]}D")
    return _sample(tile.polylines, _centres(n, 3), float(radius)).reshape(n, n, n)


@lru_cache(maxsize=16)
def _tile_voxels(tileset, n: int, radius: float) -> np.ndarray:
    out = np.stack([block_voxels(t, resolution=n, radius=radius) for t in tileset.tiles]
                   + [np.zeros((n, n, n), bool)])
    out.setflags(write=False)
    return out


def tiling_voxels(tiling: Tiling, tileset, *, resolution: int = 20,
                  radius: float = 0.2) -> np.ndarray:
    """Voxel grid of a 3D tiling (paper: 1 mm beams in 5 mm blocks -> radius 0.2).

    Returns
    -------
    (nz * resolution, ny * resolution, nx * resolution) bool, ``[z, y, x]``
    """
    if tiling.tiles.ndim != 3:
        raise ValueError(f"tiling_voxels needs a 3D tiling; got shape {tiling.shape}")
    n = _check_res(resolution)
    vox = _tile_voxels(tileset, n, float(radius))
    idx = np.where(tiling.tiles >= 0, tiling.tiles, len(vox) - 1)
    nz, ny, nx = idx.shape
    return vox[idx].transpose(0, 3, 1, 4, 2, 5).reshape(nz * n, ny * n, nx * n)


def tiling_beams(tiling: Tiling, tileset, *, cell_size: float = 5.0, radius: float = 1.0,
                 normalize: bool = False):
    """Member axes of the tiling as polylines with radii.

    Parameters
    ----------
    cell_size : float > 0, block edge length (paper: 5 mm)
    radius : float > 0, beam radius in the same unit (paper: 1 mm)
    normalize : bool
        Divide coordinates and radii by the longest side of the grid, so a
        cubic tiling maps onto the unit cell that
        ``engine.geometry.line_sdf_grid`` expects.

    Returns
    -------
    polylines : list of (m, ndim) float64, coordinates ``(x, y[, z])``
    radii : list of float, one per polyline
    """
    if not (cell_size > 0 and radius > 0):
        raise ValueError(f"cell_size and radius must be > 0; got {cell_size!r}, {radius!r}")
    scale = cell_size / (max(tiling.shape) * cell_size if normalize else 1.0)
    polys, radii = [], []
    for idx in zip(*np.nonzero(tiling.tiles >= 0)):
        origin = np.array(idx[::-1], dtype=np.float64)       # grid (z, y, x) -> (x, y, z)
        for p in tileset.tiles[tiling.tiles[idx]].polylines:
            polys.append((p + origin) * scale)
            radii.append(radius * scale / cell_size)
    return polys, radii
