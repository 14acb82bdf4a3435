"""Tiling files (``*.tiling.json``).

::

    {"format": "mesoforge-tiling", "version": 1,
     "tileset": "TL+-", "shape": [ny, nx], "periodic": false, "seed": 7,
     "grid": [["T@2", "+@0", null, ...], ...],
     "defects": [[i, j], ...]}

``grid`` nests one list per grid axis and holds ``"<block>@<orientation>"``
or null. A null cell listed in ``defects`` is a defect; one not listed was
never reached (growth stopped by ``max_steps``).
"""

from __future__ import annotations

import json
import os

import numpy as np

from ..fileio import write_atomic
from .tileset import TileSet, load_tileset
from .tiling import DEFECT, UNASSIGNED, Tiling

__all__ = ["tiling_to_dict", "tiling_from_dict", "save_tiling", "load_tiling"]

FORMAT = "mesoforge-tiling"
VERSION = 1


def tiling_to_dict(tiling: Tiling, tileset: TileSet) -> dict:
    """The JSON document of a tiling (plain Python types)."""
    if tiling.tileset_name != tileset.name:
        raise ValueError(f"tiling was grown from tile set {tiling.tileset_name!r}, "
                         f"not {tileset.name!r}")
    names = tiling.tile_names(tileset)
    return {
        "format": FORMAT, "version": VERSION,
        "tileset": tileset.name,
        "shape": list(tiling.shape),
        "periodic": bool(tiling.periodic),
        "seed": tiling.seed,
        "grid": names.tolist(),
        "defects": np.argwhere(tiling.tiles == DEFECT).tolist(),
    }


def tiling_from_dict(data: dict, tileset: TileSet | None = None, *,
                     source: str = "tiling") -> Tiling:
    """Rebuild a Tiling from its JSON document, checking every field.

    ``tileset`` defaults to ``load_tileset(data["tileset"])``.
    """
    if not isinstance(data, dict) or data.get("format") != FORMAT \
            or data.get("version") != VERSION:
        raise ValueError(f"{source}: expected a {FORMAT!r} version {VERSION} document")
    for key, kind in (("tileset", str), ("shape", list), ("periodic", bool), ("grid", list),
                      ("defects", list)):
        if not isinstance(data.get(key), kind):
            raise ValueError(f"{source}: {key!r} must be a {kind.__name__}; "
                             f"got {data.get(key)!r}")
    seed = data.get("seed")
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int)):
        raise ValueError(f"{source}: 'seed' must be an integer or null; got {seed!r}")
    if tileset is None:
        tileset = load_tileset(data["tileset"])
    elif tileset.name != data["tileset"]:
        raise ValueError(f"{source}: file names tile set {data['tileset']!r}, "
                         f"given {tileset.name!r}")
    shape = tuple(data["shape"])
    if len(shape) != tileset.ndim or not all(isinstance(s, int) and s >= 1 for s in shape):
        raise ValueError(f"{source}: 'shape' must hold {tileset.ndim} positive integers; "
                         f"got {data['shape']!r}")
    lookup = {name: i for i, name in enumerate(tileset.tile_names)}
    lookup[None] = UNASSIGNED
    try:
        flat = np.array(data["grid"], dtype=object)
        if flat.shape != shape:
            raise ValueError
        tiles = np.array([lookup[v] for v in flat.ravel()], dtype=np.int32).reshape(shape)
    except (ValueError, KeyError, TypeError):
        raise ValueError(f"{source}: 'grid' must be nested lists of shape {shape} holding tile "
                         f"names of {tileset.name!r} (like {tileset.tile_names[0]!r}) or null"
                         ) from None
    for cell in data["defects"]:
        if not (isinstance(cell, list) and len(cell) == len(shape)
                and all(isinstance(v, int) and 0 <= v < s for v, s in zip(cell, shape))) \
                or tiles[tuple(cell)] != UNASSIGNED:
            raise ValueError(f"{source}: defect {cell!r} must be an in-range index of a null cell")
        tiles[tuple(cell)] = DEFECT
    return Tiling(tiles, tileset.name, data["periodic"], seed, None,
                  {"n_cells": int(tiles.size), "n_defects": int(np.sum(tiles == DEFECT)),
                   "complete": bool(np.all(tiles != UNASSIGNED))})


def save_tiling(path: str | os.PathLike, tiling: Tiling, tileset: TileSet) -> None:
    """Write ``tiling.json`` atomically (old content or new, never a mix)."""
    text = json.dumps(tiling_to_dict(tiling, tileset), ensure_ascii=False)
    write_atomic(path, text.encode("utf-8"))


def load_tiling(path: str | os.PathLike, tileset: TileSet | None = None) -> Tiling:
    """Read a tiling file; ``tileset`` defaults to the one named in the file."""
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except OSError as e:
        raise ValueError(f"cannot read tiling file {str(path)!r}: {e}") from None
    except ValueError as e:
        raise ValueError(f"tiling file {str(path)!r} is not valid JSON: {e}") from None
    return tiling_from_dict(data, tileset, source=f"tiling file {str(path)!r}")
