"""Tile sets for virtual growth: blocks, their orientations, adjacency.

A tile set file (JSON, schema in ``resources/tilesets/README.md``) lists
base *blocks*; each block is expanded into its distinct *orientations*
(tiles) under the symmetry group of the square (8 elements) or the cube
(48), deduplicated by connectors and geometry. Two tiles may sit side by
side when the connector labels on the facing faces are equal; the file's
``rules`` then allow or forbid further pairs, in order, last rule wins.

``allowed[d, a, b]`` is True when tile ``b`` may be the neighbour of tile
``a`` across ``a``'s face ``d``; it always satisfies
``allowed[d, a, b] == allowed[opposite(d), b, a]``.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Mapping

import numpy as np

from ._symmetry import (SYMMETRY_MODES, face_centres, face_names, geometry_key,
                        group_elements, opposite, transform_connectors,
                        transform_points)

__all__ = ["Tile", "TileSet", "load_tileset", "parse_tileset", "list_tilesets", "check_block_weight",
           "BLOCK_WEIGHT_MIN", "TILESET_DIR"]

TILESET_DIR = Path(__file__).resolve().parents[2] / "resources" / "tilesets"
FORMAT = "mesoforge-tileset"
VERSION = 1
BLOCK_WEIGHT_MIN = 0.0        # a block's weight: finite, >= this (the Tile Set dock shows it)
_BLOCK_KEYS = {"name", "weight", "symmetry", "arms", "junction", "polylines",
               "connectors", "description"}
_TOP_KEYS = {"format", "version", "name", "dim", "description", "blocks", "rules"}


def _readonly(a: np.ndarray) -> np.ndarray:
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class Tile:
    """One orientation of a block.

    Attributes
    ----------
    name : str
        ``"<block>@<orientation>"``, e.g. ``"T@2"``.
    block : str
    orientation : int
        Index among the block's distinct orientations (0 = as in the file).
    transform : (ndim, ndim) int8
        Signed permutation taking the block's geometry to this tile's,
        about the block centre.
    connectors : tuple of str, length 2*ndim
        Label on each face, in direction order (``face_names``).
    polylines : tuple of (m, ndim) float64
        Geometry in the unit block, used for rendering.
    """

    name: str
    block: str
    orientation: int
    transform: np.ndarray
    connectors: tuple
    polylines: tuple


@dataclass(frozen=True, eq=False)
class TileSet:
    """An immutable set of tiles with their adjacency tensor.

    Attributes
    ----------
    name : str
    ndim : int, 2 or 3
    block_names : tuple of str, file order
    tiles : tuple of Tile, grouped by block in file order
    allowed : (2*ndim, n_tiles, n_tiles) bool, read-only
    weights : (n_tiles,) float64, read-only
        Default hints: each block's ``weight`` shared equally by its
        orientations.
    description : str
    source : str or None, the file it was read from
    """

    name: str
    ndim: int
    block_names: tuple
    tiles: tuple
    allowed: np.ndarray
    weights: np.ndarray
    description: str = ""
    source: str | None = None
    rules: tuple = field(default=())

    @property
    def n_tiles(self) -> int:
        return len(self.tiles)

    @property
    def n_blocks(self) -> int:
        return len(self.block_names)

    @property
    def faces(self) -> tuple:
        return face_names(self.ndim)

    @cached_property
    def tile_names(self) -> tuple:
        return tuple(t.name for t in self.tiles)

    @cached_property
    def tile_block(self) -> np.ndarray:
        """(n_tiles,) int32: block index of each tile."""
        idx = {b: i for i, b in enumerate(self.block_names)}
        return _readonly(np.array([idx[t.block] for t in self.tiles], dtype=np.int32))

    @cached_property
    def n_orientations(self) -> np.ndarray:
        """(n_blocks,) int64: number of distinct orientations of each block."""
        return _readonly(np.bincount(self.tile_block, minlength=self.n_blocks))

    @cached_property
    def n_words(self) -> int:
        """64-bit words per admissible-set bitset."""
        return max(1, (self.n_tiles + 63) // 64)

    @cached_property
    def masks(self) -> np.ndarray:
        """(2*ndim, n_tiles, n_words) uint64: ``allowed`` as bitsets over b."""
        return _readonly(_pack_bits(self.allowed, self.n_words))

    @cached_property
    def block_masks(self) -> np.ndarray:
        """(n_blocks, n_words) uint64: the tiles of each block as bitsets."""
        onehot = self.tile_block[None, :] == np.arange(self.n_blocks)[:, None]
        return _readonly(_pack_bits(onehot, self.n_words))

    def block_index(self, name: str) -> int:
        try:
            return self.block_names.index(name)
        except ValueError:
            raise ValueError(f"block {name!r} is not in tile set {self.name!r}; "
                             f"blocks are {list(self.block_names)}") from None

    def tile_index(self, name: str) -> int:
        """Index of a tile given as ``"<block>@<orientation>"``."""
        try:
            return self.tile_names.index(name)
        except ValueError:
            raise ValueError(f"tile {name!r} is not in tile set {self.name!r}; "
                             f"tiles are {list(self.tile_names)}") from None

    def tiles_of(self, block: str) -> np.ndarray:
        """Indices of the tiles (orientations) of one block."""
        return np.flatnonzero(self.tile_block == self.block_index(block))


def _pack_bits(bools: np.ndarray, n_words: int) -> np.ndarray:
    """Pack the last axis of a bool array into little-endian uint64 words."""
    n = bools.shape[-1]
    padded = np.zeros(bools.shape[:-1] + (n_words * 64,), dtype=bool)
    padded[..., :n] = bools
    packed = np.packbits(padded, axis=-1, bitorder="little")
    return np.ascontiguousarray(packed).view("<u8").astype(np.uint64)


# ------------------------------------------------------------------ parsing

def _check_number(value, what: str, lo=-math.inf, hi=math.inf) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) \
            or not math.isfinite(value) or not lo <= value <= hi:
        raise ValueError(f"{what} must be a finite number in [{lo}, {hi}]; got {value!r}")
    return float(value)


def check_block_weight(value, what: str = "weight") -> float:
    """A block's weight (its default hint, shared by its orientations): a finite
    number >= 0 (`BLOCK_WEIGHT_MIN`); ValueError naming ``what`` otherwise."""
    return _check_number(value, what, BLOCK_WEIGHT_MIN)


def _check_point(p, ndim: int, what: str) -> list:
    if not isinstance(p, (list, tuple)) or len(p) != ndim:
        raise ValueError(f"{what} must be a list of {ndim} coordinates; got {p!r}")
    return [_check_number(v, what, 0.0, 1.0) for v in p]


def _block_geometry(spec: Mapping, ndim: int, where: str):
    """Polylines and connectors of a block as written in the file."""
    faces = face_names(ndim)
    polylines = []
    arm_faces = spec.get("arms", [])
    if not isinstance(arm_faces, list) or len(set(arm_faces)) != len(arm_faces):
        raise ValueError(f"{where}: 'arms' must be a list of distinct face names "
                         f"from {list(faces)}; got {arm_faces!r}")
    junction = _check_point(spec.get("junction", [0.5] * ndim), ndim, f"{where}: 'junction'")
    centres = face_centres(ndim)
    for f in arm_faces:
        if f not in faces:
            raise ValueError(f"{where}: unknown face {f!r} in 'arms'; expected one of {list(faces)}")
        polylines.append(np.array([junction, centres[faces.index(f)]]))
    raw = spec.get("polylines", [])
    if not isinstance(raw, list):
        raise ValueError(f"{where}: 'polylines' must be a list of point lists; got {raw!r}")
    for k, poly in enumerate(raw):
        if not isinstance(poly, list) or len(poly) < 2:
            raise ValueError(f"{where}: polylines[{k}] must list at least 2 points; got {poly!r}")
        polylines.append(np.array([_check_point(p, ndim, f"{where}: polylines[{k}] point")
                                   for p in poly]))
    if not polylines:
        raise ValueError(f"{where}: a block needs 'arms' or 'polylines'")
    conn = spec.get("connectors")
    if conn is None:
        if not arm_faces:
            raise ValueError(f"{where}: 'connectors' is required when the block has no 'arms'")
        conn = {f: ("1" if f in arm_faces else "0") for f in faces}
    if not isinstance(conn, dict) or set(conn) != set(faces):
        raise ValueError(f"{where}: 'connectors' must map exactly the faces {list(faces)} "
                         f"to labels; got {conn!r}")
    labels = []
    for f in faces:
        v = conn[f]
        if isinstance(v, bool) or not isinstance(v, (str, int)):
            raise ValueError(f"{where}: connector label on face {f!r} must be a string "
                             f"or an integer; got {v!r}")
        labels.append(str(v))
    return polylines, tuple(labels)


def _orientations(name: str, polylines, connectors, mode: str, ndim: int) -> list:
    tiles, seen = [], set()
    for m in group_elements(ndim, mode):
        conn = transform_connectors(connectors, m)
        polys = tuple(_readonly(transform_points(p, m)) for p in polylines)
        key = (conn, geometry_key(polys))
        if key in seen:
            continue
        seen.add(key)
        k = len(tiles)
        tiles.append(Tile(f"{name}@{k}", name, k, m, conn, polys))
    return tiles


def _resolve_ref(ref, tiles, blocks, where: str) -> np.ndarray:
    """Tile indices named by a rule operand: a block name or ``block@k``."""
    if not isinstance(ref, str):
        raise ValueError(f"{where}: operand must be a block or tile name string; got {ref!r}")
    names = [t.name for t in tiles]
    if ref in blocks:
        return np.array([i for i, t in enumerate(tiles) if t.block == ref])
    if ref in names:
        return np.array([names.index(ref)])
    raise ValueError(f"{where}: unknown block or tile {ref!r}; blocks are {list(blocks)} "
                     f"and tiles are named like {names[0]!r}")


def _apply_rules(allowed: np.ndarray, rules, tiles, blocks, ndim: int) -> list:
    faces = face_names(ndim)
    parsed = []
    if not isinstance(rules, list):
        raise ValueError(f"'rules' must be a list of rule objects; got {rules!r}")
    for k, rule in enumerate(rules):
        where = f"rules[{k}]"
        if not isinstance(rule, dict):
            raise ValueError(f"{where} must be an object; got {rule!r}")
        kinds = [key for key in ("allow", "forbid") if key in rule]
        extra = set(rule) - {"allow", "forbid", "face", "description"}
        if len(kinds) != 1 or extra:
            raise ValueError(f"{where} needs exactly one of 'allow' / 'forbid' (plus optional "
                             f"'face', 'description'); got keys {sorted(rule)}")
        pair = rule[kinds[0]]
        if not isinstance(pair, list) or len(pair) != 2:
            raise ValueError(f"{where}: '{kinds[0]}' must be a list of two names; got {pair!r}")
        a_idx = _resolve_ref(pair[0], tiles, blocks, where)
        b_idx = _resolve_ref(pair[1], tiles, blocks, where)
        face = rule.get("face")
        if face is None:
            dirs = range(2 * ndim)
        elif face in faces:
            dirs = [faces.index(face)]
        else:
            raise ValueError(f"{where}: 'face' must be one of {list(faces)}; got {face!r}")
        value = kinds[0] == "allow"
        for d in dirs:
            allowed[d][np.ix_(a_idx, b_idx)] = value
            allowed[opposite(d, ndim)][np.ix_(b_idx, a_idx)] = value
        parsed.append(dict(rule))
    return parsed


def parse_tileset(data: Mapping, *, source: str | None = None) -> TileSet:
    """Build a TileSet from the decoded JSON document.

    Parameters
    ----------
    data : mapping, the file's content (schema in resources/tilesets/README.md)
    source : str, optional, shown in error messages

    Raises
    ------
    ValueError
        With the offending key, value and what was expected.
    """
    src = f" ({source})" if source else ""
    if not isinstance(data, Mapping):
        raise ValueError(f"tile set{src} must be a JSON object; got {type(data).__name__}")
    if data.get("format", FORMAT) != FORMAT or data.get("version", VERSION) != VERSION:
        raise ValueError(f"tile set{src}: expected format {FORMAT!r} version {VERSION}; "
                         f"got {data.get('format')!r} version {data.get('version')!r}")
    unknown = set(data) - _TOP_KEYS
    if unknown:
        raise ValueError(f"tile set{src}: unknown keys {sorted(unknown)}; allowed {sorted(_TOP_KEYS)}")
    name = data.get("name")
    if not isinstance(name, str) or not name:
        raise ValueError(f"tile set{src}: 'name' must be a non-empty string; got {name!r}")
    ndim = data.get("dim")
    if ndim not in (2, 3) or isinstance(ndim, bool):
        raise ValueError(f"tile set {name!r}{src}: 'dim' must be 2 or 3; got {ndim!r}")
    blocks = data.get("blocks")
    if not isinstance(blocks, list) or not blocks:
        raise ValueError(f"tile set {name!r}{src}: 'blocks' must be a non-empty list")
    tiles, block_names, block_w = [], [], []
    for k, spec in enumerate(blocks):
        where = f"tile set {name!r}{src}: blocks[{k}]"
        if not isinstance(spec, dict):
            raise ValueError(f"{where} must be an object; got {spec!r}")
        if set(spec) - _BLOCK_KEYS:
            raise ValueError(f"{where}: unknown keys {sorted(set(spec) - _BLOCK_KEYS)}; "
                             f"allowed {sorted(_BLOCK_KEYS)}")
        bname = spec.get("name")
        if not isinstance(bname, str) or not bname or "@" in bname or bname in block_names:
            raise ValueError(f"{where}: 'name' must be a unique non-empty string without '@'; "
                             f"got {bname!r}")
        where = f"tile set {name!r}{src}: block {bname!r}"
        weight = check_block_weight(spec.get("weight", 1.0), f"{where}: 'weight'")
        mode = spec.get("symmetry", "full")
        if mode not in SYMMETRY_MODES:
            raise ValueError(f"{where}: 'symmetry' must be one of {SYMMETRY_MODES}; got {mode!r}")
        polylines, connectors = _block_geometry(spec, ndim, where)
        new = _orientations(bname, polylines, connectors, mode, ndim)
        tiles += new
        block_names.append(bname)
        block_w += [weight / len(new)] * len(new)
    conn = np.array([t.connectors for t in tiles], dtype=object)      # (T, D)
    faces = face_names(ndim)
    allowed = np.empty((len(faces), len(tiles), len(tiles)), dtype=bool)
    for d in range(len(faces)):
        allowed[d] = conn[:, d][:, None] == conn[:, opposite(d, ndim)][None, :]
    rules = _apply_rules(allowed, data.get("rules", []), tiles, block_names, ndim)
    weights = np.array(block_w, dtype=np.float64)
    if weights.sum() <= 0:
        raise ValueError(f"tile set {name!r}{src}: block weights sum to 0; at least one must be > 0")
    return TileSet(name=name, ndim=ndim, block_names=tuple(block_names), tiles=tuple(tiles),
                   allowed=_readonly(allowed), weights=_readonly(weights),
                   description=str(data.get("description", "")), source=source,
                   rules=tuple(rules))


# ------------------------------------------------------------------ files

def list_tilesets(folder: str | os.PathLike | None = None) -> dict:
    """Map set name (and file stem) to path for the JSON files in ``folder``."""
    folder = Path(folder) if folder is not None else TILESET_DIR
    out = {}
    for p in sorted(folder.glob("*.json")):
        try:
            name = json.loads(p.read_text(encoding="utf-8")).get("name")
        except (OSError, ValueError, AttributeError):
            continue
        if isinstance(name, str):
            out.setdefault(name, p)
        out.setdefault(p.stem, p)
    return out


_CACHE: dict = {}


def load_tileset(path_or_name: str | os.PathLike) -> TileSet:
    """Read a tile set from a JSON file, or by name from ``resources/tilesets``.

    Parameters
    ----------
    path_or_name : str or path
        A file path, or a set name (``"TL+-"``) or file stem (``"tl_basic"``).

    Returns
    -------
    TileSet
        Cached per file content: loading the same unchanged file twice gives
        the same object.
    """
    p = Path(path_or_name)
    if not p.is_file():
        known = list_tilesets()
        if str(path_or_name) not in known:
            raise ValueError(f"tile set {str(path_or_name)!r} is neither a file nor a known set "
                             f"name; known: {sorted(known)}")
        p = known[str(path_or_name)]
    raw = p.read_bytes()
    key = (str(p.resolve()), hashlib.sha256(raw).hexdigest())
    if key not in _CACHE:
        try:
            data = json.loads(raw.decode("utf-8"))
        except ValueError as e:
            raise ValueError(f"tile set file {str(p)!r} is not valid JSON: {e}") from None
        _CACHE[key] = parse_tileset(data, source=str(p))
    return _CACHE[key]
