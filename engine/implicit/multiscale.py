"""A particle cloud whose cell width varies over space (paper 004, section 3.1 and the introduction).

A hashed grid has one cell width, so a spatially varying width w(x) (mm, a
`GridField`) is built as the paper blends size and density distributions:
a Boolean union of K clouds (`Suspension`s) on geometric widths

    w_k = w_min (w_max / w_min)^(k / (K - 1)),   k = 0 .. K - 1,

spanning the field's sample range [w_min, w_max].  Each layer's keep
probability is multiplied by a partition-of-unity weight of the local width,
read at that layer's cell centres (the cloud's `density_field` hook): with
``t = log(w / w_0) / log(w_{K-1} / w_0) (K - 1)`` layer k has weight
``hat(t - k) = max(0, 1 - |t - k|)``.  Where w(x) equals a layer's width only
that layer exists; in between, two neighbouring layers share the cells.

The weights are computed at the width field's samples and interpolated
trilinearly like any GridField.  Interpolation is linear in the samples, so
the layers' weights sum to exactly 1 everywhere (up to float rounding), not
only at the samples; but between samples the interpolated weight of a layer
equals the hat of the interpolated width only approximately (exactly where w
is constant over the interpolation cell, or where t is linear across it and
stays between two layers).

Sizes scale with the layer: the base size distribution is given relative to
the base ``cell`` (the reference width), and layer k uses it times
``w_k / cell`` (a lognormal's mu shifted by ``log(w_k / cell)``), so
particles keep their proportion to their cell.  Everything else of the base
(offsets in mm, density ramp in mm, rule on each layer's own cell indices,
warp) is passed on unchanged; layer k has seed ``seed + k``.  A warp of more
than one octave is refused: its phases follow the seed, so each layer would
live in another frame and the weights would no longer share one.

A base `density_field` is multiplied into every layer's weights: on the
width field's grid when both grids are the same (or one is constant along an
axis, where the other's axis is used), otherwise both are resampled on a
common grid (the union box, the finer spacing per axis), which is exact at
the common samples only.
"""

from __future__ import annotations

import math

import numpy as np

from .combine import Union
from .field_sampling import GridField, as_grid_field
from .particles import SizeDistribution, Suspension
from .values import SDF

__all__ = ["layer_widths", "layer_weights", "multiscale_suspension", "MAX_LAYERS", "MAX_COMMON_SAMPLES"]

MAX_LAYERS = 6
MAX_COMMON_SAMPLES = 4_000_000       # samples of a resampled density x weight grid at most


def _is_int(v) -> bool:
    return isinstance(v, (int, np.integer)) and not isinstance(v, (bool, np.bool_))


def _check_layers(layers) -> int:
    if not (_is_int(layers) and 1 <= layers <= MAX_LAYERS):
        raise ValueError(f"layers must be an int in [1, {MAX_LAYERS}], got {layers!r}")
    return int(layers)


def layer_widths(w_min: float, w_max: float, layers: int) -> tuple:
    """Geometric cell widths (mm) from `w_min` to `w_max`: a tuple of `layers` floats.

    One layer gives the geometric mean sqrt(w_min w_max); equal ends give one layer
    ``(w_min,)`` whatever `layers` is (there is nothing to blend).

    Raises
    ------
    ValueError
        If w_min, w_max are not finite with 0 < w_min <= w_max, or layers is not an int
        in [1, MAX_LAYERS].
    """
    k = _check_layers(layers)
    a, b = float(w_min), float(w_max)
    if not (math.isfinite(a) and math.isfinite(b) and 0.0 < a <= b):
        raise ValueError(f"layer widths need finite 0 < w_min <= w_max (mm), got {w_min!r}, {w_max!r}")
    if a == b:
        return (a,)
    if k == 1:
        return (math.sqrt(a * b),)
    ratio = b / a
    return tuple([a] + [a * ratio ** (i / (k - 1)) for i in range(1, k - 1)] + [b])


def layer_weights(widths, layers_w) -> np.ndarray:
    """Hat weights of local widths `widths` (any shape, mm, > 0) for layer widths `layers_w`
    (from `layer_widths`): (K, *widths.shape) float64, summing to 1 over the layers."""
    w = np.asarray(widths, dtype=np.float64)
    k = len(layers_w)
    if k == 1:
        return np.ones((1,) + w.shape)
    t = np.log(w / layers_w[0]) / math.log(layers_w[-1] / layers_w[0]) * (k - 1)
    t = np.clip(t, 0.0, k - 1.0)
    return np.stack([np.maximum(0.0, 1.0 - np.abs(t - i)) for i in range(k)])


def _scaled(size: SizeDistribution, r: float) -> SizeDistribution:
    if size.kind == "lognormal":
        return SizeDistribution("lognormal", size.a + math.log(r), size.b)
    return SizeDistribution(size.kind, size.a * r, size.b * r)


def _common_axis(a: GridField, b: GridField, axis: int):
    """(lo, hi, count) along `axis` of a grid both fields are resampled on."""
    na, nb = a.counts[axis], b.counts[axis]
    same = na == nb and a.lo[axis] == b.lo[axis] and a.hi[axis] == b.hi[axis]
    if same or nb == 1:
        return a.lo[axis], a.hi[axis], na
    if na == 1:
        return b.lo[axis], b.hi[axis], nb
    lo, hi = min(a.lo[axis], b.lo[axis]), max(a.hi[axis], b.hi[axis])
    h = min(a.spacing[axis], b.spacing[axis])
    return lo, hi, max(1, int(math.ceil((hi - lo) / h - 1e-9)))


def _on_common_grid(width: GridField, dens: GridField):
    """The width and density samples on one grid: (widths, densities, lo, hi)."""
    axes = [_common_axis(width, dens, a) for a in range(3)]
    counts = [n for _, _, n in axes]
    if (tuple(counts) == width.counts and all(
            (lo, hi) == (width.lo[a], width.hi[a]) for a, (lo, hi, _) in enumerate(axes))
            and dens.counts == width.counts and np.array_equal(dens.lo, width.lo)
            and np.array_equal(dens.hi, width.hi)):
        return width.values, dens.values, width.lo, width.hi
    total = int(np.prod(counts))
    if total > MAX_COMMON_SAMPLES:
        raise ValueError(f"density_field and width_field grids differ; their common grid would hold "
                         f"{total} samples, at most {MAX_COMMON_SAMPLES}")
    lo = np.array([x for x, _, _ in axes])
    hi = np.array([x for _, x, _ in axes])
    centres = [lo[a] + (np.arange(counts[a]) + 0.5) * (hi[a] - lo[a]) / counts[a] for a in range(3)]
    zz, yy, xx = np.meshgrid(centres[2], centres[1], centres[0], indexing="ij")
    pts = np.stack([xx.ravel(), yy.ravel(), zz.ravel()], axis=1)
    shape = (counts[2], counts[1], counts[0])
    return (width.sample(pts).reshape(shape), dens.sample(pts).reshape(shape), lo, hi)


def multiscale_suspension(base: dict, width_field, layers: int) -> SDF:
    """The union of `layers` particle clouds blending cell widths after `width_field`.

    Parameters
    ----------
    base : dict of `Suspension` keyword arguments; its ``cell`` (mm, default 1) is the
        reference width of its ``size`` distribution, its ``seed`` (default 0) layer 0's.
    width_field : GridField (or a Field-like with values, lo, hi): the desired cell width
        w(x) (mm, samples finite and > 0), read at each layer's cell centres.
    layers : int in [1, MAX_LAYERS], the number of clouds K (one if the field is constant).

    Returns
    -------
    Union of the Suspensions of the layers any sample gives a positive weight, layer k on
    width ``layer_widths(...)[k]`` with seed ``seed + k`` (module docstring).

    Raises
    ------
    ValueError
        Naming width_field, layers or base, or (prefixed by the layer and its width) what a
        layer's Suspension refuses, e.g. an offset not below half the layer's cell.
    """
    if not isinstance(base, dict):
        raise ValueError(f"base must be a dict of Suspension arguments, got {type(base).__name__}")
    k = _check_layers(layers)
    wf = as_grid_field(width_field, "width_field")
    if not (np.all(np.isfinite(wf.values)) and wf.minimum > 0.0):
        raise ValueError(f"width_field samples must be finite and > 0 mm, got samples from "
                         f"{wf.minimum!r} to {wf.maximum!r}")
    if int(base.get("warp_octaves", 1)) > 1:
        raise ValueError(f"warp_octaves must be 1 for a multiscale cloud (got {base['warp_octaves']!r}): "
                         f"the octaves' phases follow each cloud's seed (seed + k), so the clouds "
                         f"would not share a frame")
    ref = float(base.get("cell", 1.0))
    if not (math.isfinite(ref) and ref > 0.0):
        raise ValueError(f"cell width (the reference of the size distribution) must be finite and > 0 mm, "
                         f"got {base.get('cell')!r}")
    size = base.get("size", SizeDistribution())
    if not isinstance(size, SizeDistribution):
        raise ValueError(f"size must be a SizeDistribution, got {type(size).__name__}")
    widths = layer_widths(wf.minimum, wf.maximum, k)
    dens = base.get("density_field")
    if dens is None:
        w_samples, d_samples, lo, hi = wf.values, None, wf.lo, wf.hi
    else:
        w_samples, d_samples, lo, hi = _on_common_grid(wf, as_grid_field(dens, "density_field"))
    weights = layer_weights(w_samples, widths)
    seed = int(base.get("seed", 0))
    parts = []
    for i, (w_k, wt) in enumerate(zip(widths, weights)):
        if not np.any(wt > 0.0):
            continue
        if np.all(wt == 1.0):
            field = dens                                  # the base field (or None) exactly
        else:
            field = GridField(wt if d_samples is None else wt * d_samples, lo, hi)
        kw = {**base, "cell": w_k, "size": _scaled(size, w_k / ref), "density_field": field,
              "seed": seed + i}
        try:
            parts.append(Suspension(**kw))
        except ValueError as exc:
            raise ValueError(f"layer {i} of {len(widths)} (width {w_k!r} mm): {exc}") from None
    return Union(tuple(parts))
