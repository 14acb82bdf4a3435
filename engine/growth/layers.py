"""A 3D tiling seen layer by layer: each block's beams projected onto the layer plane.

A layer is the slab of cells with one grid index fixed along ``axis``
(``"z"``, ``"y"`` or ``"x"``). Its picture has one row of blocks per
remaining first grid axis and one column per remaining last grid axis, as
the 2D tiling images: layer ``z = k`` is ``tiles[k]`` with rows ``y`` and
columns ``x``; layer ``y = k`` has rows ``z`` and columns ``x``; layer
``x = k`` has rows ``z`` and columns ``y``.

A beam with an in-plane extent is drawn as its projection (a line of
``line_width`` pixels, round ends); a beam along the layer normal projects
to a point and is drawn as a disc, a small one (``ARM_UP``) when it points
to the next layer (+axis), a larger one (``ARM_DOWN``) when it points to the
previous layer, so a block with both shows a small disc inside a larger one.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from .render import segment_distance
from .tiling import DEFECT, UNASSIGNED

__all__ = ["LAYER_AXES", "VOID", "BEAM", "ARM_UP", "ARM_DOWN", "NOT_GROWN",
           "tiling_layer", "tile_projections", "layer_image"]

# pixel codes of a layer image
VOID, BEAM, ARM_UP, ARM_DOWN, NOT_GROWN = 0, 1, 2, 3, 4

# axis name -> (grid axis of tiles [z, y, x], tile coordinate of the normal, tile coordinates
# drawn along the columns and the rows)
LAYER_AXES = {"z": (0, 2, 0, 1), "y": (1, 1, 0, 2), "x": (2, 0, 1, 2)}

_POINT_EPS = 1e-9
_ARM_UP_SCALE = 1.5    # disc radii in half line widths
_ARM_DOWN_SCALE = 2.6


def _axis(axis: str) -> tuple:
    try:
        return LAYER_AXES[axis]
    except (KeyError, TypeError):
        raise ValueError(f"axis must be one of {', '.join(LAYER_AXES)}; got {axis!r}") from None


def tiling_layer(tiles: np.ndarray, axis: str, index: int) -> np.ndarray:
    """The tile indices of one layer of a 3D grid.

    Parameters
    ----------
    tiles : (nz, ny, nx) int
    axis : "z", "y" or "x", the layer normal
    index : int, the layer's grid index along ``axis``

    Returns
    -------
    2-D int array (a view): ``tiles[index]``, ``tiles[:, index, :]`` or
    ``tiles[:, :, index]``.
    """
    t = np.asarray(tiles)
    if t.ndim != 3:
        raise ValueError(f"tiles must be a 3D grid; got shape {t.shape}")
    grid_axis = _axis(axis)[0]
    n = t.shape[grid_axis]
    if isinstance(index, bool) or not isinstance(index, (int, np.integer)) or not 0 <= index < n:
        raise ValueError(f"layer index must be an int in [0, {n - 1}] along {axis}; got {index!r}")
    return np.take(t, int(index), axis=grid_axis)


def _check(resolution, line_width) -> tuple:
    if isinstance(resolution, bool) or not isinstance(resolution, (int, np.integer)) \
            or resolution < 1:
        raise ValueError(f"resolution must be an integer >= 1; got {resolution!r}")
    if not line_width > 0:
        raise ValueError(f"line_width must be > 0 pixels; got {line_width!r}")
    return int(resolution), float(line_width)


@lru_cache(maxsize=16)
def _projections(tileset, axis: str, n: int, line_width: float) -> np.ndarray:
    _, normal, cu, cv = _axis(axis)
    u = (np.arange(n) + 0.5) / n
    vv, uu = np.meshgrid(u, u, indexing="ij")
    centres = np.stack([uu.ravel(), vv.ravel()], axis=1)     # (u, v) of pixel centres, row-major
    half = line_width / 2.0 / n
    out = np.zeros((tileset.n_tiles + 1, n * n), dtype=np.uint8)  # last row: empty cell
    for k, tile in enumerate(tileset.tiles):
        beam = np.zeros(n * n, bool)
        up = np.zeros(n * n, bool)
        down = np.zeros(n * n, bool)
        for poly in tile.polylines:
            p = np.asarray(poly, dtype=np.float64)
            for a, b in zip(p[:-1], p[1:]):
                pa, pb = a[[cu, cv]], b[[cu, cv]]
                if np.hypot(*(pb - pa)) > _POINT_EPS:
                    beam |= segment_distance(centres, pa, pb) < half
                elif b[normal] > a[normal]:
                    up |= np.hypot(*(centres - pa).T) < _ARM_UP_SCALE * half
                elif b[normal] < a[normal]:
                    down |= np.hypot(*(centres - pa).T) < _ARM_DOWN_SCALE * half
        code = out[k]
        code[beam] = BEAM
        code[down] = ARM_DOWN
        code[up] = ARM_UP
    out = out.reshape(-1, n, n)
    out.setflags(write=False)
    return out


def tile_projections(tileset, axis: str, *, resolution: int = 20,
                     line_width: float = 4.0) -> np.ndarray:
    """Every 3D tile's beams projected onto the plane normal to ``axis``.

    Parameters
    ----------
    tileset : TileSet, 3D
    axis : "z", "y" or "x"
    resolution : int, pixels per block edge
    line_width : float > 0, beam width in pixels

    Returns
    -------
    (n_tiles, resolution, resolution) uint8 codes (``VOID``, ``BEAM``,
    ``ARM_UP``, ``ARM_DOWN``), read-only; pixel ``[r, c]`` has its centre at
    ``((c + 0.5) / resolution, (r + 0.5) / resolution)`` in the block's
    column and row coordinates.
    """
    if tileset.ndim != 3:
        raise ValueError(f"tile_projections needs a 3D tile set; {tileset.name!r} is "
                         f"{tileset.ndim}D")
    _axis(axis)
    n, lw = _check(resolution, line_width)
    return _projections(tileset, axis, n, lw)[:-1]


def layer_image(tiles: np.ndarray, tileset, axis: str, index: int, *, resolution: int = 20,
                line_width: float = 4.0) -> np.ndarray:
    """Picture of one layer of a 3D tiling (cells not grown yet included).

    Parameters
    ----------
    tiles : (nz, ny, nx) int, tile indices, ``DEFECT`` or ``UNASSIGNED``
    tileset : TileSet, 3D, the set the tiles index
    axis, index : the layer (see ``tiling_layer``)
    resolution, line_width : as for ``tile_projections``

    Returns
    -------
    (rows * resolution, cols * resolution) uint8 codes; defects are
    ``VOID``, unassigned cells ``NOT_GROWN``.
    """
    layer = tiling_layer(tiles, axis, index)
    if tileset.ndim != 3:
        raise ValueError(f"layer_image needs a 3D tile set; {tileset.name!r} is {tileset.ndim}D")
    n, lw = _check(resolution, line_width)
    if layer.size and (layer.max() >= tileset.n_tiles or layer.min() < UNASSIGNED):
        raise ValueError(f"tiles must hold tile indices < {tileset.n_tiles}, {DEFECT} or "
                         f"{UNASSIGNED}")
    proj = _projections(tileset, axis, n, lw)
    idx = np.where(layer >= 0, layer, len(proj) - 1)
    rows, cols = idx.shape
    img = proj[idx].transpose(0, 2, 1, 3).reshape(rows * n, cols * n).copy()
    if np.any(layer == UNASSIGNED):
        img[np.repeat(np.repeat(layer == UNASSIGNED, n, axis=0), n, axis=1)] = NOT_GROWN
    return img
