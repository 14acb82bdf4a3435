"""Virtual growth (Liu, Sun & Daraio 2022): WaveFunctionCollapse on a grid.

Every cell starts with all tiles of positive hint admissible. Each step
*observes* the free cell of minimal Shannon entropy (eq. S1, probabilities =
hints normalised over the cell's admissible tiles; ties broken uniformly at
random), assigns it a tile sampled by normalised hint, and *propagates* the
adjacency constraints to a fixed point. A cell whose admissible set becomes
empty is a *defect*: it is recorded (tile -1), imposes no further
constraint on its neighbours (restrictions it caused before it ran empty
stay), and growth goes on -- there are no restarts. ``periodic`` makes
opposite boundaries neighbours (a torus); otherwise boundary faces are free.

With finite availability ``N`` a block's hint is scaled by the fraction of
its copies still unused, and a block that runs out is banned everywhere
(fig. S1D-E).

``grow_tiling`` runs the compiled kernel (``_wfc_kernel``; on grids of
``_HEAP_MIN_CELLS`` cells or more it finds the minimal-entropy cells with a
heap instead of a scan, same choice, near-linear time);
``grow_tiling_reference`` runs the plain-Python version of the same
algorithm (``_wfc_reference``). Both draw ``2 * n_cells`` uniforms from the
generator up front and use them in the same order, so the same seed gives
the same tiling from either.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from engine.progress import next_chunk, report
from . import _wfc_kernel as K
from ._symmetry import grid_offsets
from ._wfc_reference import ReferenceGrowth
from .hints import availability_counts, hint_table
from .tileset import TileSet
from .tiling import UNASSIGNED, Tiling, resolve_rng

__all__ = ["grow_tiling", "grow_tiling_reference", "neighbour_table"]

# From this many cells on, the minimal-entropy cell comes from a heap rather
# than a scan of the grid (same choice; measured faster from ~50 x 50 on).
_HEAP_MIN_CELLS = 2048
_HEAP_SLACK = 4          # heap capacity in cells; full of stale entries -> rebuilt


@lru_cache(maxsize=32)
def neighbour_table(shape: tuple, periodic: bool) -> np.ndarray:
    """(n_cells, 2*ndim) int32: flat index of the neighbour across each face, -1 if none.

    Faces follow ``tileset.faces`` (``+x, +y, [+z,] -x, -y, [-z]``), with
    ``x`` the last grid axis. Read-only, cached per (shape, periodic).
    """
    shape = tuple(int(s) for s in shape)
    idx = np.indices(shape).reshape(len(shape), -1)
    sizes = np.array(shape)[:, None]
    out = np.empty((idx.shape[1], 2 * len(shape)), dtype=np.int32)
    for d, off in enumerate(grid_offsets(len(shape))):
        q = idx + off[:, None]
        inside = np.all((q >= 0) & (q < sizes), axis=0)
        q %= sizes
        flat = np.ravel_multi_index(tuple(q), shape)
        out[:, d] = np.where(inside | periodic, flat, -1)
    out.setflags(write=False)
    return out


@dataclass
class _Problem:
    shape: tuple
    periodic: bool
    seed: int | None
    nbr: np.ndarray         # (n, D) int32
    wave: np.ndarray        # (n, W) uint64
    status: np.ndarray      # (n,) int8
    tiles: np.ndarray       # (n,) int32
    weights: np.ndarray     # (1 or n, T) float64
    initial: np.ndarray | None   # (B,) float64 availability or None
    randoms: np.ndarray     # (2n,) float64
    budget: int


def _check_shape(shape, ndim: int) -> tuple:
    try:
        shp = tuple(int(s) for s in shape)
        ok = len(shp) == ndim and all(s >= 1 and s == v for s, v in zip(shp, shape))
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ValueError(f"shape must be {ndim} positive integers for a {ndim}D tile set; "
                         f"got {shape!r}")
    return shp


def _apply_fixed(tileset, shape, fixed, fixed_defects, nbr, wave, status, tiles):
    n_tiles = tileset.n_tiles
    fix = np.full(len(status), -1, dtype=np.int64)
    if fixed is not None:
        f = np.asarray(fixed)
        if f.shape != shape or not np.issubdtype(f.dtype, np.integer) \
                or f.min(initial=-1) < -1 or f.max(initial=-1) >= n_tiles:
            raise ValueError(f"fixed must be an integer array of shape {shape} with -1 (free) or "
                             f"tile indices < {n_tiles}; got {f.dtype} {f.shape}")
        fix = f.ravel().astype(np.int64)
    held = fix >= 0
    if fixed_defects is not None:
        m = np.asarray(fixed_defects)
        if m.shape != shape or m.dtype != bool:
            raise ValueError(f"fixed_defects must be a bool array of shape {shape}; "
                             f"got {m.dtype} {m.shape}")
        m = m.ravel()
        if np.any(m & held):
            c = int(np.flatnonzero(m & held)[0])
            raise ValueError(f"cell {np.unravel_index(c, shape)} is both fixed to a tile and "
                             f"a fixed defect")
        wave[m] = 0
        status[m] = K.DEFECT
        tiles[m] = -1
    for d in range(nbr.shape[1]):
        nb = nbr[:, d]
        both = held & (nb >= 0)
        both[both] &= held[nb[both]]
        c = np.flatnonzero(both)
        bad = c[~tileset.allowed[d, fix[c], fix[nbr[c, d]]]]
        if bad.size:
            c0 = int(bad[0])
            raise ValueError(f"fixed tiles {tileset.tile_names[fix[c0]]!r} at "
                             f"{np.unravel_index(c0, shape)} and "
                             f"{tileset.tile_names[fix[nbr[c0, d]]]!r} across its face "
                             f"{tileset.faces[d]!r} are not allowed side by side")
    c = np.flatnonzero(held)
    wave[c] = 0
    wave[c, fix[c] >> 6] = np.left_shift(np.uint64(1), (fix[c] & 63).astype(np.uint64))
    status[c] = K.ASSIGNED
    tiles[c] = fix[c]


def _prepare(tileset, shape, hints, periodic, availability, fixed, fixed_defects, rng,
             max_steps) -> _Problem:
    if not isinstance(tileset, TileSet):
        raise ValueError(f"tileset must be a TileSet (see load_tileset); got {type(tileset).__name__}")
    shape = _check_shape(shape, tileset.ndim)
    if not isinstance(periodic, (bool, np.bool_)):
        raise ValueError(f"periodic must be a bool; got {periodic!r}")
    n = int(np.prod(shape))
    weights = hint_table(tileset, hints, shape)
    initial = availability_counts(tileset, availability, weights, n)
    ok = weights > 0
    if initial is not None:
        ok = ok & (initial > 0)[tileset.tile_block][None, :]
    if periodic:
        # on a periodic axis of length 1 a cell is its own neighbour
        for d, off in enumerate(grid_offsets(tileset.ndim)):
            if shape[int(np.flatnonzero(off)[0])] == 1:
                ok = ok & np.diagonal(tileset.allowed[d])[None, :]
    packed = np.packbits(np.pad(ok, ((0, 0), (0, 64 * tileset.n_words - tileset.n_tiles))),
                         axis=1, bitorder="little").view("<u8").astype(np.uint64)
    wave = np.array(np.broadcast_to(packed, (n, tileset.n_words)), order="C")
    nbr = neighbour_table(shape, bool(periodic))
    status = np.zeros(n, dtype=np.int8)
    tiles = np.full(n, UNASSIGNED, dtype=np.int32)
    _apply_fixed(tileset, shape, fixed, fixed_defects, nbr, wave, status, tiles)
    if max_steps is None:
        budget = n
    elif isinstance(max_steps, bool) or not isinstance(max_steps, (int, np.integer)) \
            or max_steps < 0:
        raise ValueError(f"max_steps must be None or an integer >= 0; got {max_steps!r}")
    else:
        budget = int(max_steps)
    gen, seed = resolve_rng(rng)
    randoms = gen.random(2 * n)
    return _Problem(shape, bool(periodic), seed, nbr, wave, status, tiles, weights,
                    initial, randoms, budget)


def _drive(run, total: int, progress) -> None:
    """Call ``run(budget) -> done`` in chunks of ~40 ms (engine.progress.next_chunk),
    reporting progress."""
    if progress is None:
        run(total)
        return
    done, chunk = 0, 16
    report(progress, 0, total)
    while done < total:
        t0 = time.perf_counter()
        made = run(min(chunk, total - done))
        done += made
        report(progress, done, total)
        if made == 0:
            break
        chunk = next_chunk(chunk, made, time.perf_counter() - t0)


def _finish(tileset, p: _Problem, tiles, status, events, n_events, n_obs, remaining,
            record_steps) -> Tiling:
    stats = {
        "n_cells": int(tiles.size),
        "n_defects": int(np.count_nonzero(status == K.DEFECT)),
        "n_observations": int(n_obs),
        "complete": bool(np.all(status != K.FREE)),
    }
    if p.initial is not None:
        stats["remaining"] = {b: float(r) for b, r in zip(tileset.block_names, remaining)}
    steps = np.asarray(events[:n_events], dtype=np.int32).reshape(-1, 2) if record_steps else None
    return Tiling(np.asarray(tiles, dtype=np.int32).reshape(p.shape), tileset.name, p.periodic,
                  p.seed, steps, stats)


def grow_tiling(tileset: TileSet, shape, *, hints=None, periodic: bool = False,
                availability=None, fixed=None, fixed_defects=None, rng=None,
                max_steps: int | None = None, record_steps: bool = False,
                progress=None) -> Tiling:
    """Grow a tiling by virtual growth (minimal-entropy WaveFunctionCollapse).

    Parameters
    ----------
    tileset : TileSet
    shape : (ny, nx) or (nz, ny, nx) ints, matching ``tileset.ndim``
    hints : None, mapping, or array_like, optional
        Frequency hints: ``{"T": .4, "+": .4, "-": .1, "L": .1}`` per block
        (shared by its orientations), ``{"T@1": ...}`` per tile (fig. S6A),
        an array ``(n_blocks,)`` / ``(n_tiles,)``, or a per-cell field
        ``shape + (n_tiles,)`` / ``shape + (n_blocks,)`` (Fig. 5C). Default:
        the tile set's block weights. See ``hints.hint_table``.
    periodic : bool
        Treat opposite boundaries as neighbours (the result tiles the plane).
    availability : None, float, mapping or array_like
        Finite supply of blocks: a ratio ``N`` of blocks to cells, or
        absolute counts per block. None = unlimited. See
        ``hints.availability_counts``.
    fixed : int array of ``shape``, optional
        Partial assignment: tile index per cell, -1 = free. Fixed cells
        constrain their neighbours and are kept as they are (they do not
        consume availability). Adjacent fixed tiles must be compatible.
    fixed_defects : bool array of ``shape``, optional
        Cells held as defects (no tile, no constraint), e.g. for regrowth.
    rng : None, int or numpy.random.Generator
        Seed; None draws one from OS entropy and records it in the result.
    max_steps : int, optional
        Stop after this many observations; cells not reached stay
        ``UNASSIGNED`` (-2) and ``stats["complete"]`` is False.
    record_steps : bool
        Keep the order of decisions in ``Tiling.steps`` (for animation).
    progress : callable, optional
        ``progress(done, total) -> bool``; False cancels (raises
        ``engine.geometry.Cancelled``) within ~40 ms.

    Returns
    -------
    Tiling
        ``tiles`` int32 of ``shape``: tile index, -1 for defects.
    """
    p = _prepare(tileset, shape, hints, periodic, availability, fixed, fixed_defects, rng,
                 max_steps)
    n = p.status.size
    entropy = np.zeros(n)
    dirty = np.ones(n, dtype=bool)          # every entropy starts unknown ...
    dlist = np.arange(n, dtype=np.int32)    # ... and every cell is on the dirty list
    stack = np.empty(n, dtype=np.int32)
    on_stack = np.zeros(n, dtype=bool)
    events = np.empty((n, 2), dtype=np.int32)
    counters = np.array([0, 0, np.count_nonzero(p.status == K.FREE), n, 0], dtype=np.int64)
    limited = p.initial is not None
    use_heap = not limited and n >= _HEAP_MIN_CELLS
    ver = np.zeros(n, dtype=np.int32)
    cap = _HEAP_SLACK * n + 64 if use_heap else 1
    hS, hC, hV = np.empty(cap), np.empty(cap, dtype=np.int32), np.empty(cap, dtype=np.int32)
    tmp = np.empty(n if use_heap else 1, dtype=np.int32)
    walk = np.empty(cap, dtype=np.int32)
    initial = p.initial if limited else np.zeros(tileset.n_blocks)
    remaining = initial.copy()
    masks, block_of, block_masks = tileset.masks, tileset.tile_block, tileset.block_masks
    K.init_state(p.wave, p.status, p.tiles, dirty, dlist, p.nbr, masks, stack, on_stack,
                 events, counters)

    def run(budget):
        return K.run_steps(budget, p.wave, p.status, p.tiles, entropy, dirty, dlist, p.nbr,
                           masks, p.weights, block_of, block_masks, remaining, initial, limited,
                           p.randoms, stack, on_stack, events, counters, use_heap, ver, hS, hC,
                           hV, tmp, walk)

    _drive(run, min(p.budget, int(counters[2])), progress)
    return _finish(tileset, p, p.tiles, p.status, events, counters[1], counters[0], remaining,
                   record_steps)


def grow_tiling_reference(tileset: TileSet, shape, *, hints=None, periodic: bool = False,
                          availability=None, fixed=None, fixed_defects=None, rng=None,
                          max_steps: int | None = None, record_steps: bool = False,
                          progress=None) -> Tiling:
    """Plain-Python growth, same parameters and same result as ``grow_tiling``.

    Slow (sets and full entropy rescans); for tests and reading.
    """
    p = _prepare(tileset, shape, hints, periodic, availability, fixed, fixed_defects, rng,
                 max_steps)
    ok = np.unpackbits(p.wave.view(np.uint8), axis=1, bitorder="little")[:, :tileset.n_tiles]
    domains = [frozenset(np.flatnonzero(row).tolist()) for row in ok]
    g = ReferenceGrowth(domains, p.status.tolist(), p.tiles.tolist(), p.nbr.tolist(),
                        tileset.allowed, p.weights.tolist(), tileset.tile_block.tolist(),
                        None if p.initial is None else p.initial.tolist(), p.randoms.tolist())
    g.start()
    _drive(g.run, min(p.budget, g.status.count(K.FREE)), progress)
    return _finish(tileset, p, np.array(g.tiles), np.array(g.status), g.events,
                   len(g.events), g.n_obs, g.remaining, record_steps)
