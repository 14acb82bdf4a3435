"""Local update of a phasor infill after the fields were repainted in a box.

A brush stroke changes D, F or Gamma in a few cells of the fields' grid
(:func:`engine.phasor.strokes.apply_stroke` says which).  Only kernels whose
parameters depend on those cells need new oscillators, and only phases near
them need to move, so instead of sampling and aligning everything again:

1. the region of space whose trilinear samples read a changed cell is the
   changed cells' box grown by one cell spacing (to infinity on a side where
   the box touches the grid's face: points beyond the grid clamp to it);
2. the kernel sites in that region are resampled
   (:func:`engine.phasor.sampling.resample_kernels`: the same positions and
   random draws, so each equals what a fresh sample of the new fields gives);
3. the phases of the sites in that region grown by ``margin`` kernel radii
   are aligned again (warm-started from their previous phases) while every
   other phase stays fixed, acting as the boundary condition
   (:func:`engine.phasor.align.align_phases` with ``active``).

The result depends on the history of edits (alignment is iterative and
starts from the previous phases), so it is not what aligning the final
fields from scratch would give; outside the region plus margin it is the
previous infill bit for bit.

The kernel radius ``R = c / F_min`` must not change: the caller resamples
from scratch when painting moved the lowest frequency.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from .fields import PhasorFields
from .infill import PhasorInfill

__all__ = ["changed_cells", "affected_box", "is_empty", "update_infill", "DEFAULT_MARGIN", "EMPTY"]

DEFAULT_MARGIN = 1.0  # kernel radii of re-aligned neighbours around the resampled sites
EMPTY = (slice(0, 0),) * 3


def _same_grid(a: PhasorFields, b: PhasorFields) -> bool:
    return a.shape == b.shape and np.array_equal(a.lo, b.lo) and np.array_equal(a.hi, b.hi)


def _box_of_mask(mask) -> tuple:
    if not mask.any():
        return EMPTY
    box = []
    for axis in range(3):
        hit = np.flatnonzero(mask.any(axis=tuple(a for a in range(3) if a != axis)))
        box.append(slice(int(hit[0]), int(hit[-1]) + 1))
    return tuple(box)


def changed_cells(old: PhasorFields, new: PhasorFields):
    """``[z, y, x]`` bounding box (three slices) of the cells whose D, F or
    Gamma differ between two fields on the same grid; :data:`EMPTY` when none
    do, None when the grids (shape or box) differ."""
    if not _same_grid(old, new):
        return None
    diff = (np.any(old.direction != new.direction, axis=-1) | (old.frequency != new.frequency)
            | (old.spread != new.spread))
    return _box_of_mask(diff)


def is_empty(changed) -> bool:
    """True for a ``[z, y, x]`` box holding no cell (e.g. :data:`EMPTY`)."""
    return changed is not None and any(s.stop <= s.start for s in changed)


def affected_box(fields: PhasorFields, changed) -> tuple:
    """(lo, hi) (3,) mm: the points whose trilinear samples of the fields read
    a cell of ``changed`` (``[z, y, x]`` slices) with non-zero weight, as a
    closed box; +-inf on a side where ``changed`` reaches the grid's face."""
    lo = np.empty(3)
    hi = np.empty(3)
    step = fields.spacing
    for a, (s, n) in enumerate(zip(changed[::-1], fields.shape[::-1])):  # x, y, z
        k0, k1 = int(s.start), int(s.stop)
        lo[a] = -math.inf if k0 <= 0 else fields.lo[a] + (k0 + 0.5) * step[a] - step[a]
        hi[a] = math.inf if k1 >= n else fields.lo[a] + (k1 - 0.5) * step[a] + step[a]
    return lo, hi


def _reach(infill: PhasorInfill) -> float:
    """How far (mm) a kernel's phase shows in a slice of this infill."""
    r = infill.kernels.radius
    return r * math.sqrt(1.0 + infill.filter_scale ** 2) if infill.filtered else r


def update_infill(previous: PhasorInfill, fields: PhasorFields, changed, *,
                  iterations: int | None = None, margin: float = DEFAULT_MARGIN,
                  filtered: bool | None = None, filter_scale: float | None = None,
                  progress=None) -> PhasorInfill:
    """The infill after the fields changed in the cells ``changed``.

    Parameters
    ----------
    previous : PhasorInfill, the infill before the edit
    fields : PhasorFields, the repainted fields, on the previous fields' grid
    changed : (slice, slice, slice), ``[z, y, x]`` cells that may differ
        (e.g. :func:`changed_cells`); cells outside must be unchanged
    iterations : int or None, alignment sweeps of the local update
        (None: ``previous.iterations``)
    margin : float >= 0, kernel radii of neighbours re-aligned around the
        resampled sites
    filtered, filter_scale : evaluation options of the result (None: keep)
    progress : callable(done, total) -> bool or None; False cancels

    Returns
    -------
    PhasorInfill
        ``changed_region`` is the box (mm, clipped to the fields' box) where
        slices may differ from ``previous``: the re-aligned sites' box grown
        by the kernels' reach and two field cells (A(x) reads the gradient of
        D); empty (lo > hi) when nothing changed.

    Raises
    ------
    ValueError
        If the grids differ or the kernel radius ``c / F_min`` of the new
        fields differs from the previous kernels' (sample from scratch then).
    """
    from .align import align_phases
    from .attenuation import attenuation_grid
    from .sampling import resample_kernels

    if not _same_grid(previous.fields, fields):
        raise ValueError("fields: the grid (shape or box) differs from the previous infill's; "
                         "sample the kernels from scratch")
    kernels = previous.kernels
    c = kernels.info.get("c")
    if c is not None and c / fields.min_frequency() != kernels.radius:
        raise ValueError(f"fields: the lowest frequency moved the kernel radius from {kernels.radius:.6g} mm "
                         f"to {c / fields.min_frequency():.6g} mm; sample the kernels from scratch")
    if not (math.isfinite(margin) and margin >= 0):
        raise ValueError(f"margin: expected a number of kernel radii >= 0, got {margin!r}")
    iterations = previous.iterations if iterations is None else int(iterations)
    options = dict(filtered=previous.filtered if filtered is None else bool(filtered),
                   filter_scale=previous.filter_scale if filter_scale is None else float(filter_scale),
                   iterations=iterations)
    if changed is None or is_empty(changed):
        nothing = (fields.hi.copy(), fields.lo.copy())
        return replace(previous, fields=fields, changed_region=nothing, **options)
    lo, hi = affected_box(fields, changed)
    kernels, _ = resample_kernels(kernels, fields, (lo, hi))
    grow = margin * kernels.radius
    active = np.all((kernels.positions >= lo - grow) & (kernels.positions <= hi + grow), axis=1)
    kernels = align_phases(kernels, iterations=iterations, active=active, progress=progress)
    out = replace(previous, kernels=kernels, fields=fields,
                  attenuation=attenuation_grid(fields, radius=kernels.radius), changed_region=None,
                  **options)
    spread = grow + _reach(out) + 2.0 * float(fields.spacing.max())
    region = (np.maximum(lo - spread, fields.lo), np.minimum(hi + spread, fields.hi))
    return replace(out, changed_region=region)
