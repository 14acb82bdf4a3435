"""Diffusion tensors of the oriented growth (paper eq. 11) and field upsampling.

For direction ``i`` the tensor of every cell is

    sigma_i = R D_i R^T / Tr(D_i),    D_i = diag(1, .., xi, .., 1)  (xi at (i, i)),

so ``u`` diffuses ``xi`` times faster along the principal direction
``R[:, i]`` than across it and the trace is 1. The grown stripes (2D) or
sheets (3D) lie *perpendicular* to ``R[:, i]``: ``u`` spreads fastest
along it, so the pattern's wave vector points along it (4.3.1).

Conventions (shared with the rest of :mod:`engine.rd`): grids are indexed
``[y, x]`` / ``[z, y, x]``; tensor and rotation components are in
``(x, y[, z])`` order, shape ``grid + (d, d)``; rotation columns are the
principal directions sorted by decreasing ``|sigma_i|``. Cell centres sit
at half-integer cell coordinates, so upsampling maps the centres of the
fine cells into the coarse grid and interpolates linearly there.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

__all__ = ["diffusion_tensors", "check_rotation", "rotation_from_angle", "upsample_field", "upsample_rotation"]

#: Largest accepted deviation of R^T R from the identity.
ORTHONORMAL_TOL = 1e-6


def _cell_name(index, ndim):
    axes = "yx" if ndim == 2 else "zyx"
    return "[" + ", ".join(f"{a}={int(i)}" for a, i in zip(axes, index)) + "]"


def check_rotation(rotation, *, name="rotation") -> np.ndarray:
    """Validate a per-cell rotation field; return it as float64.

    Parameters
    ----------
    rotation : grid + (d, d) float, d = grid dimension (2 or 3), orthonormal columns

    Raises
    ------
    ValueError naming ``name`` and the first bad cell (NaN, not orthonormal).
    """
    r = np.asarray(rotation, dtype=np.float64)
    if r.ndim < 4 or r.shape[-1] != r.shape[-2] or r.shape[-1] not in (2, 3) or r.ndim - 2 != r.shape[-1]:
        raise ValueError(f"{name} must have shape grid + (d, d) with d = grid dimension, i.e. "
                         f"(ny, nx, 2, 2) or (nz, ny, nx, 3, 3); got {r.shape}")
    dim = r.shape[-1]
    bad = ~np.isfinite(r).all(axis=(-2, -1))
    if bad.any():
        raise ValueError(f"{name} has a NaN or infinite entry at cell {_cell_name(np.argwhere(bad)[0], dim)} "
                         f"({int(bad.sum())} such cells)")
    err = np.abs(np.swapaxes(r, -1, -2) @ r - np.eye(dim)).max(axis=(-2, -1))
    if (err > ORTHONORMAL_TOL).any():
        first = tuple(np.argwhere(err > ORTHONORMAL_TOL)[0])
        raise ValueError(f"{name} is not orthonormal at cell {_cell_name(first, dim)} "
                         f"(max |R^T R - I| = {err[first]:.3g}); expected unit, mutually orthogonal "
                         f"principal directions as columns")
    return r


def rotation_from_angle(theta) -> np.ndarray:
    """2D rotation field whose first column points at angle ``theta`` from +x towards +y.

    Parameters
    ----------
    theta : (ny, nx) float, radians

    Returns
    -------
    (ny, nx, 2, 2) float64, columns ``(cos t, sin t)`` and ``(-sin t, cos t)``, det = +1
    """
    t = np.asarray(theta, dtype=np.float64)
    if t.ndim != 2 or not np.isfinite(t).all():
        raise ValueError(f"theta must be a finite 2D [y, x] grid of angles; got shape {t.shape}")
    c, s = np.cos(t), np.sin(t)
    return np.stack([np.stack([c, -s], axis=-1), np.stack([s, c], axis=-1)], axis=-2)


def diffusion_tensors(rotation, *, direction: int = 0, xi: float = 5.0) -> np.ndarray:
    """Trace-normalised diffusion tensors for growth along principal direction ``direction`` (eq. 11).

    Parameters
    ----------
    rotation : grid + (d, d) float64, columns = principal directions, (x, y[, z]) components
    direction : int in [0, d), which column gets the fast diffusion ``xi``
    xi : float >= 1, anisotropy

    Returns
    -------
    grid + (d, d) float64, symmetric, trace 1, eigenvalues ``xi / (xi + d - 1)``
    (along ``R[:, direction]``) and ``1 / (xi + d - 1)``.
    """
    r = check_rotation(rotation)
    dim = r.shape[-1]
    if isinstance(direction, bool) or not isinstance(direction, (int, np.integer)) or not 0 <= direction < dim:
        raise ValueError(f"direction must be a principal direction index in [0, {dim}); got {direction!r}")
    if not np.isfinite(xi) or xi < 1:
        raise ValueError(f"xi must be a finite anisotropy >= 1; got {xi!r}")
    weights = np.ones(dim)
    weights[direction] = xi
    weights /= weights.sum()
    sigma = np.einsum("...ik,k,...jk->...ij", r, weights, r)
    # exact symmetry: the kernel refuses asymmetric tensors
    return 0.5 * (sigma + np.swapaxes(sigma, -1, -2))


def _fine_coordinates(n_coarse, n_fine):
    """Coarse-grid index coordinates of the fine cell centres (cell-centred grids)."""
    return (np.arange(n_fine) + 0.5) * (n_coarse / n_fine) - 0.5


def upsample_field(a, shape) -> np.ndarray:
    """Linear (bi/trilinear) interpolation of a cell-centred grid onto a finer ``shape``.

    Parameters
    ----------
    a : (ny, nx) or (nz, ny, nx) float, e.g. a density ``rho`` or infill map ``Gamma``
    shape : tuple of ints, the target grid, same number of axes

    Returns
    -------
    float64 array of ``shape``; values stay within [a.min(), a.max()]
    (edge cells are extended, no extrapolation).
    """
    a = np.asarray(a, dtype=np.float64)
    shape = tuple(int(n) for n in shape)
    if a.ndim not in (2, 3) or len(shape) != a.ndim or min(shape) < 1:
        raise ValueError(f"upsample_field: a must be a 2D or 3D grid and shape a positive size per axis; "
                         f"got a.shape={a.shape}, shape={shape}")
    if not np.isfinite(a).all():
        raise ValueError("upsample_field: a has NaN or infinite values")
    coords = np.meshgrid(*[_fine_coordinates(n, m) for n, m in zip(a.shape, shape)], indexing="ij",
                         sparse=True)
    full = [np.broadcast_to(c, shape) for c in coords]
    return ndimage.map_coordinates(a, full, order=1, mode="nearest")


def upsample_rotation(rotation, shape, *, weights=None) -> np.ndarray:
    """Upsample a rotation field: interpolate tensors, then re-diagonalise.

    Columns of ``R`` have no sign (``v`` and ``-v`` are the same direction),
    so they cannot be interpolated directly. Each coarse cell is turned into
    the tensor ``T = R diag(weights) R^T``, the components of ``T`` are
    interpolated linearly (:func:`upsample_field`), and every fine tensor is
    diagonalised again: columns sorted by decreasing weight, orthonormal,
    ``det = +1``, signs chosen to agree with the nearest coarse cell.

    Parameters
    ----------
    rotation : grid + (d, d) float64, orthonormal columns
    shape : target grid shape
    weights : (d,) distinct decreasing positive numbers or None (d, d-1, ..., 1);
        e.g. ``|principal stresses|`` of a representative cell

    Returns
    -------
    shape + (d, d) float64
    """
    r = check_rotation(rotation)
    dim = r.shape[-1]
    shape = tuple(int(n) for n in shape)
    if len(shape) != dim:
        raise ValueError(f"upsample_rotation: shape must have {dim} axes; got {shape}")
    w = np.arange(dim, 0, -1, dtype=np.float64) if weights is None else np.asarray(weights, dtype=np.float64)
    if w.shape != (dim,) or not np.all(np.diff(w) < 0) or not np.all(w > 0):
        raise ValueError(f"upsample_rotation: weights must be {dim} distinct decreasing positive numbers; "
                         f"got {weights!r}")
    tensor = np.einsum("...ik,k,...jk->...ij", r, w, r)
    fine = np.empty(shape + (dim, dim))
    for i in range(dim):
        for j in range(i, dim):
            fine[..., i, j] = upsample_field(tensor[..., i, j], shape)
            fine[..., j, i] = fine[..., i, j]
    _, vecs = np.linalg.eigh(fine)
    vecs = vecs[..., ::-1]                      # decreasing weight first
    # signs: agree with the coarse cell the fine centre falls in
    idx = np.meshgrid(*[np.minimum((np.arange(m) * n) // m, n - 1) for n, m in zip(r.shape[:-2], shape)],
                      indexing="ij", sparse=True)
    near = r[tuple(idx)]
    dots = np.einsum("...ki,...ki->...i", vecs, near)
    vecs = vecs * np.where(dots < 0, -1.0, 1.0)[..., None, :]
    det = np.linalg.det(vecs)
    vecs[..., :, dim - 1] *= np.where(det < 0, -1.0, 1.0)[..., None]
    return np.ascontiguousarray(vecs)
