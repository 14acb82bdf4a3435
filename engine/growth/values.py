"""Values of the growth family that travel on graph ports: a grown tiling.
Immutable once produced (arrays read-only); no graph import here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from engine.geometry.values import read_only_array

__all__ = ["TilingValue"]


@dataclass(frozen=True)
class TilingValue:
    """A grown tiling with the tile set it came from (port type "Tiling").

    tiling : engine.growth.Tiling (tile indices read-only); tileset :
    engine.growth.TileSet. Both are immutable; downstream nodes render or
    homogenize the tiling without knowing where the set was loaded from.

    How this evaluation made it, for replaying the growth (both None when the
    tiling was restored from a project file or loaded):

    steps : (n_events, 2) int32, read-only, or None
        ``[flat cell index, tile]`` in the order cells were decided; the flat
        index is row-major over ``tiling.tiles`` and tile -1 marks a defect
        forming (``Tiling.steps``).
    start_tiles : int32 array of the grid shape, read-only, or None
        The grid before this growth's first step: all UNASSIGNED (-2) for a
        fresh growth; for a local regrowth the previous tiling with the
        regrown cells (painted region plus margin) set to UNASSIGNED.
        Writing each step's tile into a copy of it gives ``tiling.tiles``.
    """

    tiling: object
    tileset: object
    steps: np.ndarray | None = None
    start_tiles: np.ndarray | None = None

    def __post_init__(self):
        if self.steps is not None:
            object.__setattr__(self, "steps", read_only_array(self.steps, np.int32).reshape(-1, 2))
        if self.start_tiles is not None:
            start = read_only_array(self.start_tiles, np.int32)
            if start.shape != self.tiling.tiles.shape:
                raise ValueError(f"TilingValue: start_tiles has shape {start.shape}, the tiling "
                                 f"{self.tiling.tiles.shape}")
            object.__setattr__(self, "start_tiles", start)

    @property
    def ndim(self) -> int:
        return int(self.tiling.tiles.ndim)
