"""Frequency hints: per-block / per-tile / per-cell weights, availability,
realised probabilities and Dirichlet sampling of hint vectors.

A block's hint is shared equally by its distinct orientations (the paper
treats every orientation of a block as equally likely), so a per-block hint
is the block's total probability. Hints need not sum to 1; growth
normalises them over each cell's admissible tiles (eq. S1).
"""

from __future__ import annotations

import math
from typing import Mapping

import numpy as np

from .tiling import resolve_rng

__all__ = ["normalize_hints", "expand_block_hints", "hint_table", "availability_counts",
           "realised_probabilities", "dirichlet_hints"]


def normalize_hints(weights, *, axis: int = -1) -> np.ndarray:
    """Scale non-negative weights to sum to 1 along ``axis``.

    Parameters
    ----------
    weights : array_like, float, >= 0, with a positive sum along ``axis``

    Returns
    -------
    float64 array of the same shape
    """
    w = np.asarray(weights, dtype=np.float64)
    if not np.all(np.isfinite(w)) or np.any(w < 0):
        raise ValueError(f"weights must be finite and >= 0; got {w!r}")
    s = w.sum(axis=axis, keepdims=True)
    if np.any(s <= 0):
        raise ValueError(f"weights must have a positive sum along axis {axis}; got sums {s.ravel()!r}")
    return w / s


def expand_block_hints(tileset, block_weights) -> np.ndarray:
    """Per-block weights ``(..., n_blocks)`` to per-tile ``(..., n_tiles)``.

    Each block's weight is divided equally among its orientations.
    """
    w = np.asarray(block_weights, dtype=np.float64)
    if w.shape[-1:] != (tileset.n_blocks,):
        raise ValueError(f"block_weights must end in an axis of length n_blocks = "
                         f"{tileset.n_blocks}; got shape {w.shape}")
    return (w / tileset.n_orientations)[..., tileset.tile_block]


def _from_mapping(tileset, hints: Mapping) -> np.ndarray:
    """Tile weight = its own ``"B@k"`` entry, else ``block entry / orientations``, else 0."""
    per_tile = np.zeros(tileset.n_tiles)
    tile_names = set(tileset.tile_names)
    for key, value in hints.items():
        if key not in tile_names and key not in tileset.block_names:
            raise ValueError(f"hints key {key!r} is neither a block {list(tileset.block_names)} "
                             f"nor a tile name like 'T@0' of tile set {tileset.name!r}")
        if isinstance(value, bool) or not isinstance(value, (int, float, np.number)) \
                or not math.isfinite(value) or value < 0:
            raise ValueError(f"hints[{key!r}] must be a finite number >= 0; got {value!r}")
    for t, tile in enumerate(tileset.tiles):
        if tile.name in hints:
            per_tile[t] = hints[tile.name]
        elif tile.block in hints:
            per_tile[t] = hints[tile.block] / tileset.n_orientations[tileset.tile_block[t]]
    return per_tile


def hint_table(tileset, hints, shape) -> np.ndarray:
    """Resolve any accepted form of ``hints`` to a weight table.

    Parameters
    ----------
    tileset : TileSet
    hints : None, mapping, or array_like
        None: the set's default weights. Mapping: ``{"T": 0.4, "+": 0.6}``
        per block and/or ``{"T@1": 0.2}`` per tile (see ``_from_mapping``;
        names not given get 0). Array ``(n_tiles,)`` or ``(n_blocks,)``: one
        vector for all cells. Array ``shape + (n_tiles,)`` or
        ``shape + (n_blocks,)``: a per-cell field (spatially varying hints).
    shape : tuple of int, the grid shape

    Returns
    -------
    (1, n_tiles) or (n_cells, n_tiles) float64, C-contiguous, >= 0
    """
    n_cells = int(np.prod(shape))
    if hints is None:
        table = np.asarray(tileset.weights, dtype=np.float64)[None, :]
    elif isinstance(hints, Mapping):
        table = _from_mapping(tileset, hints)[None, :]
    else:
        w = np.asarray(hints, dtype=np.float64)
        if w.ndim == 1:
            lead = (1,)
        elif w.shape[:-1] == tuple(shape):
            lead = (n_cells,)
        else:
            raise ValueError(f"hints array must have shape (n_tiles,), (n_blocks,), "
                             f"{tuple(shape)} + (n_tiles,) or {tuple(shape)} + (n_blocks,); "
                             f"got {w.shape}")
        if w.shape[-1] == tileset.n_tiles:
            table = w.reshape(lead + (tileset.n_tiles,))
        elif w.shape[-1] == tileset.n_blocks:
            table = expand_block_hints(tileset, w).reshape(lead + (tileset.n_tiles,))
        else:
            raise ValueError(f"hints last axis must be n_tiles = {tileset.n_tiles} or n_blocks = "
                             f"{tileset.n_blocks}; got {w.shape[-1]}")
    if not np.all(np.isfinite(table)) or np.any(table < 0) or table.sum() <= 0:
        raise ValueError("hints must be finite, >= 0 and not all zero")
    return np.ascontiguousarray(table, dtype=np.float64)


def availability_counts(tileset, availability, table: np.ndarray, n_cells: int):
    """Initial number of blocks available for growth (fig. S1D-E).

    Parameters
    ----------
    availability : None, float, mapping or array_like
        None or ``inf``: unlimited (hints never change). A number ``N > 0``:
        the paper's ratio of available blocks to cells; block ``b`` gets
        ``round(N * n_cells * f_b)`` copies, ``f_b`` its normalised hint
        (averaged over cells for a field). A mapping ``{block: count}`` or an
        array ``(n_blocks,)``: absolute counts; blocks missing from a
        mapping, or given ``inf``, are unlimited.
    table : (1 or n_cells, n_tiles) float64, from ``hint_table``

    Returns
    -------
    None or (n_blocks,) float64, whole numbers or inf
    """
    if availability is None:
        return None
    B = tileset.n_blocks
    if isinstance(availability, Mapping):
        counts = np.full(B, np.inf)
        for key, v in availability.items():
            b = tileset.block_index(key)
            if isinstance(v, bool) or not isinstance(v, (int, float, np.number)) or v < 0 \
                    or (math.isfinite(v) and v != int(v)):
                raise ValueError(f"availability[{key!r}] must be a whole number >= 0 or inf; got {v!r}")
            counts[b] = float(v)
    elif np.ndim(availability) == 0:
        n = float(availability)
        if not n > 0:
            raise ValueError(f"availability must be a ratio N > 0 (or None / inf); got {availability!r}")
        if math.isinf(n):
            return None
        per_block = np.zeros(B)
        np.add.at(per_block, tileset.tile_block, table.mean(axis=0))
        counts = np.floor(n * n_cells * per_block / per_block.sum() + 0.5)
    else:
        counts = np.asarray(availability, dtype=np.float64)
        if counts.shape != (B,) or np.any(counts < 0) or np.any(np.isnan(counts)) \
                or np.any(np.isfinite(counts) & (counts != np.floor(counts))):
            raise ValueError(f"availability array must have shape ({B},) with whole numbers >= 0 "
                             f"or inf; got {availability!r}")
    if np.all(np.isinf(counts)):
        return None
    return counts


def realised_probabilities(tiling, tileset, *, per: str = "block") -> np.ndarray:
    """Fraction of the assigned (non-defect) cells holding each block or tile.

    Parameters
    ----------
    per : {"block", "tile"}

    Returns
    -------
    (n_blocks,) or (n_tiles,) float64, summing to 1 (zeros if nothing assigned)
    """
    t = np.asarray(tiling.tiles).ravel()
    t = t[t >= 0]
    if per == "tile":
        counts = np.bincount(t, minlength=tileset.n_tiles)
    elif per == "block":
        counts = np.bincount(tileset.tile_block[t], minlength=tileset.n_blocks)
    else:
        raise ValueError(f"per must be 'block' or 'tile'; got {per!r}")
    return counts / max(1, t.size)


def dirichlet_hints(n_blocks: int, count: int, *, min_distance: float = 0.0, rng=None,
                    max_attempts: int | None = None) -> np.ndarray:
    """Hint vectors spread over the simplex (paper, Supplementary Text).

    Each candidate is ``w = q / sum(q)`` with ``q_i = -log(p_i)``, ``p_i``
    uniform on (0, 1] -- a symmetric Dirichlet(1) sample, i.e. uniform on
    the open standard simplex. It is kept only if its Euclidean distance to
    every kept point exceeds ``min_distance``.

    Parameters
    ----------
    n_blocks : int >= 1
    count : int >= 0, number of vectors wanted
    min_distance : float >= 0
    rng : None, int or numpy.random.Generator
    max_attempts : int, optional
        Candidates drawn before giving up; default ``1000 * count + 1000``.

    Returns
    -------
    (count, n_blocks) float64, rows summing to 1

    Raises
    ------
    ValueError
        If ``count`` points at ``min_distance`` cannot be placed in
        ``max_attempts`` draws.
    """
    for name, v in (("n_blocks", n_blocks), ("count", count)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < (1 if name == "n_blocks" else 0):
            raise ValueError(f"{name} must be an integer >= {1 if name == 'n_blocks' else 0}; got {v!r}")
    if not (isinstance(min_distance, (int, float)) and math.isfinite(min_distance) and min_distance >= 0):
        raise ValueError(f"min_distance must be a finite number >= 0; got {min_distance!r}")
    attempts = 1000 * count + 1000 if max_attempts is None else int(max_attempts)
    gen, _ = resolve_rng(rng)
    kept = np.empty((count, n_blocks))
    k = 0
    d2 = float(min_distance) ** 2
    for _ in range(attempts):
        if k == count:
            break
        q = -np.log(1.0 - gen.random(n_blocks))   # 1 - U lies in (0, 1]
        s = q.sum()
        w = q / s if s > 0 else np.full(n_blocks, 1.0 / n_blocks)
        if k == 0 or d2 == 0 or np.min(((kept[:k] - w) ** 2).sum(axis=1)) > d2:
            kept[k] = w
            k += 1
    if k < count:
        raise ValueError(f"dirichlet_hints: placed only {k} of count={count} points with "
                         f"min_distance={min_distance} in {attempts} attempts; lower min_distance "
                         f"or count, or raise max_attempts")
    return kept
