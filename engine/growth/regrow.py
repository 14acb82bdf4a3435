"""Local regrowth: clear a region of a tiling and grow it again in place."""

from __future__ import annotations

import numpy as np

from .tiling import DEFECT, UNASSIGNED, Tiling
from .wfc import grow_tiling

__all__ = ["regrow_region", "regrowth_start", "dilate"]


def dilate(mask: np.ndarray, margin: int, *, periodic: bool) -> np.ndarray:
    """Grow a bool mask by ``margin`` cells in every direction (square / cube).

    Parameters
    ----------
    mask : bool array, the grid shape
    margin : int >= 0, Chebyshev radius in cells
    periodic : bool, wrap across opposite boundaries

    Returns
    -------
    bool array of the same shape
    """
    out = np.asarray(mask, dtype=bool).copy()
    for axis in range(out.ndim):
        grown = out.copy()
        for k in range(1, margin + 1):
            for step in (k, -k):
                if periodic:
                    grown |= np.roll(out, step, axis=axis)
                elif k < out.shape[axis]:
                    src = [slice(None)] * out.ndim
                    dst = [slice(None)] * out.ndim
                    src[axis] = slice(0, -k) if step > 0 else slice(k, None)
                    dst[axis] = slice(k, None) if step > 0 else slice(0, -k)
                    grown[tuple(dst)] |= out[tuple(src)]
        out = grown
    return out


def regrow_region(tiling: Tiling, tileset, region_mask, *, margin: int = 1, hints=None,
                  rng=None, record_steps: bool = False, progress=None) -> Tiling:
    """Re-grow the cells of ``region_mask`` (plus ``margin``), keeping the rest.

    Cells outside the cleared area keep their tiles (and defects) exactly and
    act as fixed constraints (cells a stopped growth never reached are grown
    as well); the cleared cells grow again by the usual
    minimal-entropy process. Defects can form only inside the cleared area.

    Parameters
    ----------
    tiling : Tiling, grown from ``tileset``
    tileset : TileSet
    region_mask : bool array of ``tiling.shape``
    margin : int >= 0
        Extra cells cleared around the region (square/cube neighbourhood,
        wrapping if the tiling is periodic), so the new tiles are not forced
        to match the old ones right at the region's edge.
    hints, rng, record_steps, progress
        As for ``grow_tiling`` (hints may be a per-cell field).

    Returns
    -------
    Tiling
        Same shape; ``stats["n_cleared"]`` counts the cleared cells.
    """
    cleared = _cleared(tiling, region_mask, margin)
    if tiling.tileset_name != tileset.name:
        raise ValueError(f"tiling was grown from tile set {tiling.tileset_name!r}, "
                         f"not {tileset.name!r}")
    start = np.where(cleared, UNASSIGNED, tiling.tiles)
    # held tiles and defects stay; cleared cells and cells growth never reached grow
    fixed = np.where(start >= 0, start, -1).astype(np.int64)
    out = grow_tiling(tileset, tiling.shape, hints=hints, periodic=tiling.periodic,
                      fixed=fixed, fixed_defects=start == DEFECT, rng=rng,
                      record_steps=record_steps, progress=progress)
    out.stats["n_cleared"] = int(cleared.sum())
    return out


def regrowth_start(tiling: Tiling, region_mask, *, margin: int = 1) -> np.ndarray:
    """The grid `regrow_region` starts from: ``tiling.tiles`` with the region
    and its margin set to UNASSIGNED.

    Parameters
    ----------
    tiling : Tiling
    region_mask : bool array of ``tiling.shape``
    margin : int >= 0, as for `regrow_region`

    Returns
    -------
    int32 array of ``tiling.shape``
        Tiles and defects outside the cleared area as in ``tiling``; -2
        (UNASSIGNED) on the cleared cells. Writing the regrown tiling's
        ``steps`` (``tiles.flat[cell] = tile``) into a copy of it gives the
        regrown tiles.
    """
    cleared = _cleared(tiling, region_mask, margin)
    return np.where(cleared, UNASSIGNED, tiling.tiles).astype(np.int32)


def _cleared(tiling, region_mask, margin) -> np.ndarray:
    """Bool mask of the cells a regrowth clears: the region dilated by margin."""
    if not isinstance(tiling, Tiling):
        raise ValueError(f"tiling must be a Tiling; got {type(tiling).__name__}")
    region = np.asarray(region_mask)
    if region.shape != tiling.shape or region.dtype != bool:
        raise ValueError(f"region_mask must be a bool array of shape {tiling.shape}; "
                         f"got {region.dtype} {region.shape}")
    if isinstance(margin, bool) or not isinstance(margin, (int, np.integer)) or margin < 0:
        raise ValueError(f"margin must be an integer >= 0; got {margin!r}")
    return dilate(region, int(margin), periodic=tiling.periodic)
