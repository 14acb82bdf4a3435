"""Pictures of a tiling for the Virtual Growth dock (numpy in, RGB arrays out).

Solid dark, void light, undecided cells grey; a 3D tiling is drawn one layer
at a time (``engine.growth.layers``), beams to the next layer as blue discs,
to the previous as orange ones. Also the lookups of what an evaluation's
outputs hold (a tiling, a 2D stiffness).
"""

from __future__ import annotations

import numpy as np

from engine.growth.values import TilingValue
from engine.physics.values import Stiffness
from engine.growth import UNASSIGNED, Tiling, tiling_image
from engine.growth.layers import layer_image

SOLID_RGB = (40, 44, 52)
VOID_RGB = (236, 236, 230)
UNASSIGNED_RGB = (160, 160, 160)
ARM_UP_RGB = (31, 119, 180)
ARM_DOWN_RGB = (230, 140, 30)
# layer image codes (engine.growth.layers: VOID, BEAM, ARM_UP, ARM_DOWN, NOT_GROWN) -> colour
LAYER_RGB = np.array([VOID_RGB, SOLID_RGB, ARM_UP_RGB, ARM_DOWN_RGB, UNASSIGNED_RGB], np.uint8)
MAX_IMAGE_PX = 800  # longest side of the rendered tiling image, in pixels


def tiling_of(outputs: dict) -> TilingValue | None:
    """The first TilingValue among a node's outputs, or None."""
    for value in (outputs or {}).values():
        if isinstance(value, TilingValue):
            return value
    return None


def stiffness2d_of(outputs: dict) -> Stiffness | None:
    """The first in-plane (3 x 3) Stiffness among a node's outputs, or None."""
    for value in (outputs or {}).values():
        if isinstance(value, Stiffness) and np.shape(value.C) == (3, 3):
            return value
    return None


def pixels_per_block(shape) -> int:
    """Pixels per block edge so the longest side is at most MAX_IMAGE_PX (2 to 20)."""
    return int(max(2, min(20, MAX_IMAGE_PX // max(1, max(shape)))))


def tiling_rgb(tiles: np.ndarray, tileset, tileset_name: str, periodic: bool, ppb: int) -> np.ndarray:
    """(ny*ppb, nx*ppb, 3) uint8: solid dark, void light, unassigned cells grey."""
    tiling = Tiling(np.array(tiles, dtype=np.int32), tileset_name, periodic)
    img = tiling_image(tiling, tileset, resolution=ppb, line_width=max(1.0, ppb / 5.0))
    rgb = np.where(img[..., None] > 0, np.array(SOLID_RGB, np.uint8), np.array(VOID_RGB, np.uint8))
    unassigned = np.asarray(tiles) == UNASSIGNED
    if unassigned.any():
        mask = np.repeat(np.repeat(unassigned, ppb, axis=0), ppb, axis=1)
        rgb[mask] = UNASSIGNED_RGB
    return np.ascontiguousarray(rgb.astype(np.uint8))


def layer_rgb(tiles: np.ndarray, tileset, axis: str, index: int, ppb: int) -> np.ndarray:
    """(rows*ppb, cols*ppb, 3) uint8 picture of one layer of a 3D grid."""
    codes = layer_image(tiles, tileset, axis, index, resolution=ppb, line_width=max(1.0, ppb / 5.0))
    return np.ascontiguousarray(LAYER_RGB[codes])
