"""Principal decomposition of a per-cell stress tensor field (paper section 3.2.2, eq. 2).

Every cell's symmetric tensor is written ``sigma = R A R^T`` with
``A = diag(sigma_1, ..., sigma_d)``, ``|sigma_1| >= |sigma_2| (>= |sigma_3|)``
and the columns of ``R`` the unit principal directions. The directions are
made reproducible: each column's largest-magnitude component is positive,
then the last column is flipped if needed so that ``det R = +1`` (a proper
rotation, the same handedness in every cell).

Tensors are validated first: NaN or infinite entries are refused naming the
first bad cell. A tensor whose relative asymmetry
``max|sigma - sigma^T| / max|sigma|`` exceeds :data:`SYMMETRY_REFUSE` is
refused (it is not a stress); above :data:`SYMMETRY_WARN` it is replaced by
its symmetric part ``(sigma + sigma^T) / 2`` with a :class:`UserWarning`;
below that the difference is round-off and is removed silently.
"""

from __future__ import annotations

import warnings
from typing import NamedTuple

import numpy as np

from engine.progress import run_chunked

__all__ = ["PrincipalStresses", "principal_decomposition", "check_tensor_field",
           "reconstruct_tensor", "format_cell", "SYMMETRY_WARN", "SYMMETRY_REFUSE"]

#: Relative asymmetry above which a tensor is symmetrised with a warning.
SYMMETRY_WARN = 1e-10
#: Relative asymmetry above which a tensor field is refused.
SYMMETRY_REFUSE = 1e-3


class PrincipalStresses(NamedTuple):
    """Per-cell principal stresses and directions.

    values : (..., d) float64
        Principal stresses sorted by decreasing magnitude (ties: the larger
        signed value first).
    rotation : (..., d, d) float64
        Column ``i`` is the unit direction of ``values[..., i]``; ``det = +1``.
    """

    values: np.ndarray
    rotation: np.ndarray


def format_cell(index, ndim):
    """Name a grid cell in the ``[y, x]`` / ``[z, y, x]`` convention, e.g. ``[y=3, x=5]``."""
    axes = "yx" if ndim == 2 else "zyx"
    return "[" + ", ".join(f"{a}={int(i)}" for a, i in zip(axes, index)) + "]"


def check_tensor_field(sigma, *, name="sigma"):
    """Validate a field of symmetric d x d tensors and return its symmetric part.

    Parameters
    ----------
    sigma : array_like, (..., d, d) float, d in {2, 3}
        One tensor per grid cell; the grid part of the shape has ``d`` axes
        (``[y, x]`` or ``[z, y, x]``), components in (x, y[, z]) order.
    name : str
        Used in messages.

    Returns
    -------
    (..., d, d) float64, a new symmetric array.

    Raises
    ------
    ValueError
        Wrong shape, a NaN / infinite entry, or a grossly non-symmetric tensor
        (relative asymmetry > :data:`SYMMETRY_REFUSE`); the message names the
        first offending cell.
    """
    s = np.array(sigma, dtype=np.float64)
    if s.ndim < 3 or s.shape[-1] != s.shape[-2] or s.shape[-1] not in (2, 3) or s.ndim - 2 != s.shape[-1]:
        raise ValueError(f"{name} must have shape grid + (d, d) with d = grid dimension (2 or 3), "
                         f"i.e. (ny, nx, 2, 2) or (nz, ny, nx, 3, 3); got {s.shape}")
    grid_ndim = s.ndim - 2
    bad = ~np.isfinite(s).all(axis=(-2, -1))
    if bad.any():
        first = np.argwhere(bad)[0]
        raise ValueError(f"{name} has a NaN or infinite entry at cell {format_cell(first, grid_ndim)} "
                         f"({int(bad.sum())} bad cells); expected finite tensors")
    asym = np.abs(s - np.swapaxes(s, -1, -2)).max(axis=(-2, -1))
    size = np.abs(s).max(axis=(-2, -1))
    # A floor tied to the field's largest entry keeps near-zero cells (where
    # round-off dominates) from looking asymmetric.
    floor = max(float(size.max(initial=0.0)) * 1e-12, np.finfo(np.float64).tiny)
    rel = asym / np.maximum(size, floor)
    if (rel > SYMMETRY_REFUSE).any():
        first = np.argwhere(rel > SYMMETRY_REFUSE)[0]
        raise ValueError(f"{name} is not symmetric at cell {format_cell(first, grid_ndim)}: relative "
                         f"asymmetry {rel[tuple(first)]:.3g} > {SYMMETRY_REFUSE:g} "
                         f"({int((rel > SYMMETRY_REFUSE).sum())} such cells); expected a symmetric tensor")
    if (rel > SYMMETRY_WARN).any():
        first = np.argwhere(rel > SYMMETRY_WARN)[0]
        warnings.warn(f"{name}: {int((rel > SYMMETRY_WARN).sum())} slightly non-symmetric tensors "
                      f"(first at cell {format_cell(first, grid_ndim)}, relative asymmetry "
                      f"{rel[tuple(first)]:.3g}) replaced by their symmetric part", UserWarning, stacklevel=3)
    return 0.5 * (s + np.swapaxes(s, -1, -2))


def _decompose(flat):
    """Sorted, sign-normalised eigen-decomposition of (n, d, d) symmetric tensors."""
    vals, vecs = np.linalg.eigh(flat)            # ascending signed values
    vals, vecs = vals[:, ::-1], vecs[:, :, ::-1]  # descending: equal magnitudes put + first
    order = np.argsort(-np.abs(vals), axis=1, kind="stable")
    vals = np.take_along_axis(vals, order, axis=1)
    vecs = np.take_along_axis(vecs, order[:, None, :], axis=2)
    n, d = vals.shape
    big = np.abs(vecs).argmax(axis=1)             # (n, d) row of each column's largest entry
    sign = np.sign(np.take_along_axis(vecs, big[:, None, :], axis=1))
    vecs = vecs * np.where(sign == 0, 1.0, sign)
    flip = np.linalg.det(vecs) < 0
    vecs[flip, :, d - 1] *= -1.0
    return vals, vecs


def principal_decomposition(sigma, *, progress=None):
    """Principal stresses and directions of every cell (paper eq. 2).

    Parameters
    ----------
    sigma : array_like, (ny, nx, 2, 2) or (nz, ny, nx, 3, 3) float
        Symmetric stress tensors, components in (x, y[, z]) order. Validated
        with :func:`check_tensor_field` (NaN refused, small asymmetry
        symmetrised with a warning, gross asymmetry refused).
    progress : callable(done, total) -> bool, optional
        Called between chunks of cells; returning False raises
        :class:`engine.progress.Cancelled`.

    Returns
    -------
    PrincipalStresses
        ``values`` (..., d) sorted by decreasing ``|sigma_i|``; ``rotation``
        (..., d, d) with unit principal directions as columns, ``det = +1``,
        so that ``sigma = R diag(values) R^T``.
    """
    s = check_tensor_field(sigma)
    d = s.shape[-1]
    grid = s.shape[:-2]
    flat = s.reshape(-1, d, d)
    vals = np.empty(flat.shape[:2])
    vecs = np.empty(flat.shape)

    def work(start, stop):
        vals[start:stop], vecs[start:stop] = _decompose(flat[start:stop])

    run_chunked(work, flat.shape[0], progress, first_chunk=4096)
    return PrincipalStresses(vals.reshape(grid + (d,)), vecs.reshape(grid + (d, d)))


def reconstruct_tensor(values, rotation):
    """``R diag(values) R^T`` per cell: (..., d), (..., d, d) -> (..., d, d) float64."""
    v = np.asarray(values, dtype=np.float64)
    r = np.asarray(rotation, dtype=np.float64)
    return np.einsum("...ik,...k,...jk->...ij", r, v, r)
