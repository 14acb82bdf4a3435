"""A solid's mesh tiled over several cells: what `eval --tile`, `render --tile`
and the window's mesh export write.

One marching-cubes pass over the tiled distance field gives a watertight
block (copies of the cell mesh would leave duplicate seams).  The peak
memory is estimated first (``engine.memory.tiled_mesh_bytes``) and a block
that would not fit the budget is refused before anything is allocated.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from engine.memory import check_budget, tiled_mesh_bytes

if TYPE_CHECKING:
    from engine.geometry.values import Solid

# Cells per axis of a tiled mesh (eval / render --tile, the window's export).
MAX_TILES = 20


@dataclass
class MeshResult:
    """A tiled mesh and its summary.

    vertices : (n, 3) float64, mm
    faces : (m, 3) int, indices into ``vertices``
    summary : ``engine.geometry.mesh_io.mesh_summary`` plus ``volume_fraction``,
        ``grid_volume_fraction``, ``tiles`` (and ``cell``, ``box_mm`` for a box cell)
    """

    vertices: np.ndarray
    faces: np.ndarray
    summary: dict


def check_tiles(tiles) -> tuple:
    """Three whole cell counts in [1, MAX_TILES]; ValueError otherwise."""
    t = tuple(tiles)
    if len(t) != 3 or any(isinstance(v, bool) or int(v) != v or not 1 <= v <= MAX_TILES for v in t):
        raise ValueError(f"tiles {list(t)}: expected three integers in [1, {MAX_TILES}]")
    return tuple(int(v) for v in t)


def tiled_mesh_estimate(solid: Solid, tiles) -> int:
    """Peak bytes of tiling ``solid`` ``tiles`` cells per axis
    (``engine.memory.tiled_mesh_bytes`` of its grid and face count); 0 for a
    solid that does not tile (it is never re-meshed)."""
    if not solid.periodic:
        return 0
    return tiled_mesh_bytes(np.shape(solid.sdf), tiles, len(solid.faces))


def tiled_arrays(solid: Solid, tiles=(1, 1, 1), progress=None) -> tuple[np.ndarray, np.ndarray]:
    """``(vertices, faces)`` of the solid tiled ``tiles`` cells per axis (copies
    at multiples of the box, ``solid.box`` mm), placed at ``solid.origin``;
    `progress` as `engine.geometry.marching.periodic_mesh` takes it.

    Raises ValueError for tiles outside [1, MAX_TILES] and MemoryLimitError
    (before allocating) when the tiled mesh would not fit the memory budget.
    """
    from engine.geometry.marching import periodic_mesh

    tiles = check_tiles(tiles)
    check_budget(tiled_mesh_estimate(solid, tiles), what=f"tiling {'x'.join(map(str, tiles))} cells",
                 lower="the tiles or the resolution", where="tiles")
    if tiles == (1, 1, 1):
        v, f = np.asarray(solid.vertices), np.asarray(solid.faces)
    else:
        v, f = periodic_mesh(np.asarray(solid.sdf), tiles=tiles, cell_size=solid.cell_size, cell=solid.cell,
                             progress=progress)
    if any(solid.origin):
        v = v + np.asarray(solid.origin)
    return v, f


def tiled_mesh(solid: Solid, tiles=(1, 1, 1)) -> MeshResult:
    """`tiled_arrays` with the block's summary (counts, watertightness, volume
    fraction of the tiled box).  Raises as `tiled_arrays`."""
    from engine.geometry.mesh_io import mesh_summary

    tiles = check_tiles(tiles)
    v, f = tiled_arrays(solid, tiles)
    s = mesh_summary(v, f)
    cell_volume = solid.cell_size ** 3 if solid.is_unit_cube else float(np.prod(solid.box))
    s["volume_fraction"] = float(s["volume"]) / (cell_volume * np.prod(tiles))
    s["grid_volume_fraction"] = solid.volume_fraction
    s["tiles"] = list(tiles)
    if not solid.is_unit_cube:
        s["cell"] = list(solid.cell)
        s["box_mm"] = solid.box.tolist()
    return MeshResult(v, f, s)
