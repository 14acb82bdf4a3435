"""Spatially varying thickness along a line (paper section 5.3).

The user places a few ``(t, thickness)`` samples on the curve's parameter
``t in [0, 1]`` (normalised arc length); the profile is piecewise linear
between them and constant beyond the first and last sample.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["thickness_profile"]


def _check_samples(samples):
    try:
        pairs = [(float(ti), float(vi)) for ti, vi in samples]
    except (TypeError, ValueError) as exc:
        raise ValueError(f"samples must be a sequence of (t, value) pairs; got {samples!r}") from exc
    if not pairs:
        raise ValueError("samples must hold at least one (t, value) pair; got an empty sequence")
    for ti, vi in pairs:
        if math.isnan(ti) or not 0.0 <= ti <= 1.0:
            raise ValueError(f"samples t must lie in [0, 1]; got t={ti!r}")
        if not math.isfinite(vi) or vi <= 0.0:
            raise ValueError(f"samples thickness must be finite and > 0; got {vi!r} at t={ti!r}")
    pairs.sort()
    for (t0, _), (t1, _) in zip(pairs, pairs[1:]):
        if t0 == t1:
            # Two values at one t would make the profile jump; say so rather
            # than silently keep one of them.
            raise ValueError(f"samples must have distinct t; t={t0!r} appears twice")
    return np.array(pairs, dtype=np.float64)


def thickness_profile(t, samples):
    """Evaluate a piecewise-linear thickness profile.

    Parameters
    ----------
    t : array_like, shape (m,), float
        Curve parameters in [0, 1] (e.g. from
        :func:`engine.geometry.splines.arc_length_parameter`).
    samples : sequence of (float, float)
        ``(t_i, thickness_i)`` pairs, t_i in [0, 1], distinct, any order;
        thickness in model units, > 0 (full thickness, i.e. twice the radius
        used by the SDF kernels).

    Returns
    -------
    numpy.ndarray, shape (m,), float64
        Thickness at each ``t``: linear between samples, constant outside
        their range; constant everywhere for a single sample.

    Raises
    ------
    ValueError
        Empty samples, t outside [0, 1], NaN, or non-positive thickness.
    """
    table = _check_samples(samples)
    tt = np.atleast_1d(np.asarray(t, dtype=np.float64))
    if tt.ndim != 1:
        raise ValueError(f"t must be one-dimensional; got shape {tt.shape}")
    bad = ~((tt >= 0.0) & (tt <= 1.0))                  # also catches NaN
    if bad.any():
        raise ValueError(f"t must lie in [0, 1]; got {tt[bad][0]!r}")
    # np.interp extrapolates with the end values, which is exactly the
    # constant extension wanted; one sample therefore gives a constant.
    return np.interp(tt, table[:, 0], table[:, 1])
