"""Infill map: where to put solid material instead of lattice (paper section 3.2.3, eqs. 3-5).

The alignment of the principal directions with those of the neighbours,

    a(x) = 1 / (N_x d) * sum_{y in N(x)} sum_i |v_i(y) . v_i(x)|      (eq. 3)

is 1 where the orientation is locally consistent and drops where it jumps
(near-isotropic or near-zero stress). ``Gamma_sigma = (1 - a) rho`` (eq. 4)
marks such regions inside the part, and the infill map is the union with
the designer's painted map, ``Gamma = max(Gamma_c, Gamma_sigma)`` (eq. 5).

``N(x)`` is the cell's face neighbours (4 in 2D, 6 in 3D) or, with
``neighbourhood="full"``, all 8 / 26 surrounding cells, in both cases only
those inside the grid (``N_x`` is their count; the cell itself is not
included). A zero direction (an undefined one, see
:mod:`engine.rd.regularise`) contributes 0.
"""

from __future__ import annotations

import numpy as np

from .regularise import neighbour_offsets

__all__ = ["alignment", "gamma_sigma", "infill_map"]

# Values this far outside [0, 1] are round-off and are clipped; further out they are refused.
_RANGE_TOL = 1e-6


def _check_rotation(rotation):
    r = np.asarray(rotation, dtype=np.float64)
    if r.ndim < 3 or r.shape[-1] != r.shape[-2] or r.shape[-1] not in (2, 3) or r.ndim - 2 != r.shape[-1]:
        raise ValueError(f"rotation must have shape grid + (d, d) with d = grid dimension (2 or 3); got {r.shape}")
    if not np.isfinite(r).all():
        raise ValueError("rotation must be finite; got NaN or infinite entries")
    return r


def _check_unit_field(field, name, shape):
    f = np.asarray(field, dtype=np.float64)
    if f.shape != shape:
        raise ValueError(f"{name} must have the grid shape {shape}; got {f.shape}")
    if not np.isfinite(f).all():
        raise ValueError(f"{name} must be finite; got NaN or infinite values")
    lo, hi = float(f.min(initial=0.0)), float(f.max(initial=0.0))
    if lo < -_RANGE_TOL or hi > 1.0 + _RANGE_TOL:
        raise ValueError(f"{name} must lie in [0, 1]; got values in [{lo:.6g}, {hi:.6g}]")
    return np.clip(f, 0.0, 1.0)


def _shifted(a, offset):
    """Views (here, there) of ``a`` such that ``there`` is ``a`` shifted by ``offset`` cells."""
    here, there = [], []
    for o, n in zip(offset, a.shape):
        here.append(slice(max(0, -o), n - max(0, o)))
        there.append(slice(max(0, o), n - max(0, -o)))
    return tuple(here), tuple(there)


def alignment(rotation, *, neighbourhood="face"):
    """Local alignment ``a(x)`` of the principal directions (eq. 3).

    Parameters
    ----------
    rotation : (ny, nx, 2, 2) or (nz, ny, nx, 3, 3) float
        Unit principal directions as columns (zero columns allowed).
    neighbourhood : {"face", "full"}

    Returns
    -------
    (ny, nx) or (nz, ny, nx) float64 in [0, 1]
        1 for a constant direction field. A grid of a single cell has no
        neighbours and gets 1.
    """
    r = _check_rotation(rotation)
    grid, d = r.shape[:-2], r.shape[-1]
    total = np.zeros(grid)
    count = np.zeros(grid)
    for off in neighbour_offsets(len(grid), neighbourhood):
        here, there = _shifted(total, off)
        # sum_i |v_i(y) . v_i(x)|: contract over components, then over columns
        dots = np.abs(np.einsum("...ki,...ki->...i", r[here], r[there])).sum(axis=-1)
        total[here] += dots
        count[here] += 1.0
    a = np.where(count > 0, total / np.maximum(count, 1.0) / d, 1.0)
    return np.clip(a, 0.0, 1.0)


def gamma_sigma(rotation, rho, *, neighbourhood="face"):
    """``Gamma_sigma = (1 - a) rho`` (eq. 4).

    Parameters
    ----------
    rotation : (..., d, d) float
        Principal directions per cell.
    rho : (...) float in [0, 1]
        Density (infill space) on the same grid.
    neighbourhood : {"face", "full"}

    Returns
    -------
    (...) float64 in [0, 1]
    """
    a = alignment(rotation, neighbourhood=neighbourhood)
    p = _check_unit_field(rho, "rho", a.shape)
    return (1.0 - a) * p


def infill_map(rotation, rho, *, gamma_c=None, neighbourhood="face"):
    """The infill map ``Gamma = max(Gamma_c, Gamma_sigma)`` (eq. 5).

    Parameters
    ----------
    rotation : (..., d, d) float
        Principal directions per cell.
    rho : (...) float in [0, 1]
        Density on the same grid.
    gamma_c : (...) float in [0, 1], optional
        The designer's painted map; None means zero everywhere.
    neighbourhood : {"face", "full"}

    Returns
    -------
    (...) float64 in [0, 1]
    """
    g = gamma_sigma(rotation, rho, neighbourhood=neighbourhood)
    if gamma_c is None:
        return g
    return np.maximum(_check_unit_field(gamma_c, "gamma_c", g.shape), g)
