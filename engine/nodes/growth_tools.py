"""The Growth and Tile Set docks' own settings as `Param` schemas, from the kernels' rules.

The hint brush's radius is checked by `engine.growth.regions.paint_disc` (a
finite number of cells >= 0; 0 paints the cell under the pointer), a block's
weight by the tile-set loader (`engine.growth.tileset.check_block_weight`).
These schemas give the docks' fields those rules with a unit and a default;
the checks run the kernels' own on a value.
"""

from __future__ import annotations

import numpy as np

from engine.graph import Param
from engine.growth.regions import paint_disc
from engine.growth.tileset import BLOCK_WEIGHT_MIN, check_block_weight

__all__ = ["REGION_BRUSH_RADIUS", "BLOCK_WEIGHT", "region_brush_check", "block_weight_check"]

REGION_BRUSH_RADIUS = Param("radius", "float", 1.0, 0.0, None, unit="cells",
                            doc="cells whose centres lie within this distance of the pointer are "
                                "painted (0: the cell under the pointer)")
BLOCK_WEIGHT = Param("weight", "float", 1.0, BLOCK_WEIGHT_MIN, None,
                     doc="the block's default frequency hint, shared by its orientations")


def region_brush_check(radius) -> None:
    """ValueError (paint_disc's message) when the hint brush cannot paint with ``radius``."""
    paint_disc(np.zeros((1, 1), np.int64), [[0.5, 0.5]], radius, 1)


def block_weight_check(weight) -> None:
    """ValueError (the tile-set loader's message) for a weight no block may have."""
    check_block_weight(weight)
