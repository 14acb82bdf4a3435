"""Virtual growth of irregular architected materials (Liu, Sun & Daraio 2022).

Tile sets (``tileset``), the growth itself (``wfc``: minimal-entropy
WaveFunctionCollapse with defects), local regrowth (``regrow``), frequency
hints (``hints``), rendering to pixels / voxels / beams (``render``) and the
tiling file format (``tiling_io``). Pure functions on numpy arrays; no Qt,
no graph or node imports.
"""

from .hints import (availability_counts, dirichlet_hints, expand_block_hints, hint_table,
                    normalize_hints, realised_probabilities)
from .tileset import TILESET_DIR, Tile, TileSet, list_tilesets, load_tileset, parse_tileset
from .tiling import DEFECT, UNASSIGNED, Tiling
from .regrow import regrow_region
from .render import (block_image, block_voxels, tile_images, tiling_beams, tiling_image,
                     tiling_outline, tiling_voxels)
from .tiling_io import load_tiling, save_tiling, tiling_from_dict, tiling_to_dict
from .wfc import grow_tiling, grow_tiling_reference, neighbour_table

__all__ = [
    "Tile", "TileSet", "load_tileset", "parse_tileset", "list_tilesets", "TILESET_DIR",
    "Tiling", "DEFECT", "UNASSIGNED",
    "grow_tiling", "grow_tiling_reference", "neighbour_table", "regrow_region",
    "block_image", "tile_images", "tiling_image", "tiling_outline",
    "block_voxels", "tiling_voxels", "tiling_beams",
    "save_tiling", "load_tiling", "tiling_to_dict", "tiling_from_dict",
    "normalize_hints", "expand_block_hints", "hint_table", "availability_counts",
    "realised_probabilities", "dirichlet_hints",
]
