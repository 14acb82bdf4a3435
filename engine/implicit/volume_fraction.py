"""Solid volume fractions of implicit media, and the TPMS level that gives a fraction.

`volume_fraction` measures the share of a box where f < 0 on a regular grid
of cell-centred samples.  `level_for_fraction` calibrates a `Periodic`'s
level: over one unit cell the solid fraction is monotone in the level t
(F < t grows with t, and so does |F| < t), so the level for a fraction is a
quantile of F (solid) or |F| (sheet) over the cell's samples.  A linear map
of the points (cell size, anisotropy, rotation) does not change a periodic
medium's fraction, so the level depends on the kind and variant only.
"""

from __future__ import annotations

import numpy as np

from .periodic import KINDS, VARIANTS, nodal_field
from .values import SDF

__all__ = ["volume_fraction", "level_for_fraction"]

_CHUNK = 1 << 18            # points per field evaluation


def _resolution(resolution) -> np.ndarray:
    r = np.array(resolution).reshape(-1)
    if r.size == 1:
        r = np.repeat(r, 3)
    if r.size != 3 or not np.all(np.isfinite(r.astype(float))) or np.any(r != np.round(r)) \
            or np.any(r < 1):
        raise ValueError(f"resolution must be an int >= 1 or three of them, got {resolution!r}")
    return r.astype(np.int64)


def _cell_centres(lo, hi, n: np.ndarray):
    axes = [lo[i] + (np.arange(n[i]) + 0.5) * (hi[i] - lo[i]) / n[i] for i in range(3)]
    g = np.meshgrid(*axes, indexing="ij")
    return np.stack([a.ravel() for a in g], axis=1)


def volume_fraction(sdf: SDF, box, resolution=64) -> float:
    """The fraction of `box` where ``sdf.field < 0``, on cell-centred samples.

    Parameters
    ----------
    sdf : SDF
    box : ((x0, y0, z0), (x1, y1, z1)) mm, x0 < x1 etc.
    resolution : int or (3,) ints >= 1, samples per axis.

    Returns
    -------
    float in [0, 1].

    Raises
    ------
    ValueError
        If `sdf` is not an SDF, `box` is not a finite box of positive size, or
        `resolution` is not positive integers.
    """
    if not isinstance(sdf, SDF):
        raise ValueError(f"sdf: expected an SDF, got {type(sdf).__name__}")
    b = np.array(box, dtype=np.float64)
    if b.shape != (2, 3) or not np.all(np.isfinite(b)) or np.any(b[1] <= b[0]):
        raise ValueError(f"box must be ((x0, y0, z0), (x1, y1, z1)) with x0 < x1 etc., got {box!r}")
    n = _resolution(resolution)
    pts = _cell_centres(b[0], b[1], n)
    inside = 0
    for first in range(0, len(pts), _CHUNK):
        inside += int(np.count_nonzero(sdf.field(pts[first:first + _CHUNK]) < 0))
    return inside / len(pts)


def level_for_fraction(kind: str, fraction: float, variant: str = "solid", *,
                       resolution: int = 96) -> float:
    """The level t at which ``Periodic(kind, level=t, variant=variant)`` fills `fraction`.

    F (the kind's nodal function) is sampled at resolution^3 cell centres of one unit
    cell; t is the `fraction` quantile of F ("solid": F < t) or of |F| ("sheet":
    |F| < t), interpolated between neighbouring samples.

    Parameters
    ----------
    kind : one of `engine.implicit.periodic.KINDS`.
    fraction : the solid volume fraction, in the open interval (0, 1) (every kind reaches
        all of it: F < t is empty below min F and everything above max F).
    variant : "solid" or "sheet".
    resolution : int >= 8, samples per axis of the cell.

    Returns
    -------
    float, the level (>= 0 for a sheet).

    Raises
    ------
    ValueError
        For an unknown kind or variant, a fraction outside (0, 1) or NaN, or a
        resolution below 8.
    """
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    if variant not in VARIANTS:
        raise ValueError(f"variant must be one of {VARIANTS}, got {variant!r}")
    fraction = float(fraction)
    if not 0.0 < fraction < 1.0:
        raise ValueError(f"fraction must be in the open interval (0, 1) that a {variant} "
                         f"{kind} reaches, got {fraction!r}")
    if not (isinstance(resolution, (int, np.integer)) and resolution >= 8):
        raise ValueError(f"resolution must be an int >= 8, got {resolution!r}")
    n = np.full(3, int(resolution))
    theta = _cell_centres(np.zeros(3), np.full(3, 2.0 * np.pi), n)
    f = nodal_field(kind, theta)
    if variant == "sheet":
        f = np.abs(f)
    f.sort()
    # fraction(t) = #(f < t) / N; between f[m - 1] and f[m] it is m / N: interpolate the
    # step function's inverse linearly through the midpoints of its steps.
    pos = fraction * f.size - 0.5
    i = int(np.clip(np.floor(pos), 0, f.size - 2))
    w = float(np.clip(pos - i, 0.0, 1.0))
    return float(f[i] + w * (f[i + 1] - f[i]))
