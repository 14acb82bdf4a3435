"""Regularisation of a principal-direction field (paper Appendix, Algorithms 1 and 2).

Where the stress is trivial (``|sigma_i| < sigma_min``) or nearly isotropic
(``||sigma_i| - |sigma_j|| < sigma_min``) the principal directions are not
defined and jump from cell to cell (the tests here use ``<=`` so that
``sigma_min = 0`` still catches exact zeros and ties). Following the paper:

1. :func:`mask_trivial_directions` zeroes those directions, with the paper's
   simplification that a later direction is zeroed only when the one before
   it is (2D: ``v2`` only with ``v1``; 3D: ``v3`` only with ``v2``, and
   ``v2, v3`` whenever ``v1`` is). Each cell is then a full rotation, a
   zero matrix, or (3D only) ``(v1, 0, 0)``.
2. :func:`complete_partial_orientations` (Algorithm 1) completes the 3D
   cells ``(v1, 0, 0)`` with ``v2 = v1 x v_alpha`` (or ``v1 x v_beta`` when
   ``v1`` is nearly parallel to ``v_alpha``), normalised, and
   ``v3 = v1 x v2``.
3. :func:`regenerate_trivial_orientations` (Algorithm 2) fills the zero
   cells with the mean of their non-zero neighbours, each first expressed by
   :func:`closest_matrix` in the basis of a reference neighbour (the first
   non-zero one), then orthonormalised; sweeps repeat until every zero cell
   that can be reached is filled.

Choices the paper leaves open, made here: ``Orthonormalize`` is the polar
factor ``U V^T`` of the SVD (the orthogonal matrix nearest in the Frobenius
norm, which treats the columns alike), followed by flipping the last column
if needed so ``det = +1``. ``closestMatrix`` searches the whole signed
permutation group (8 elements in 2D, 48 in 3D) for the element that
maximises ``trace(R_a^T R_b P)``; ties go to the first element in a fixed
order that starts with the identity. The neighbourhood is the face
neighbours (4 / 6) unless ``neighbourhood="full"`` (8 / 26); neighbours are
visited in raster order, which fixes "the first neighbour". ``update=
"sequential"`` is the paper's loop as written (cells visited in raster
order and updated in place, so a cell filled earlier in a sweep already
counts for the cells after it); ``update="simultaneous"`` fills, in each
sweep, every zero cell that touches a non-zero one from the values at the
start of the sweep: order-independent and vectorised, for large grids.
"""

from __future__ import annotations

import functools
import itertools
from typing import NamedTuple

import numpy as np

from engine.progress import report

__all__ = ["Regularised", "mask_trivial_directions", "complete_partial_orientations",
           "regenerate_trivial_orientations", "regularise_orientations", "closest_matrix",
           "signed_permutations", "neighbour_offsets", "orthonormalise",
           "V_ALPHA", "V_BETA", "RELATIVE_SIGMA_MIN"]

#: Algorithm 1's constant vectors: unit, non-colinear, not along any grid axis
#: or diagonal, so a principal direction is unlikely to be parallel to both.
V_ALPHA = tuple(np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0))
V_BETA = tuple(np.array([-3.0, 1.0, 2.0]) / np.sqrt(14.0))
#: Default ``sigma_min`` relative to the field's largest ``|sigma_1|``.
RELATIVE_SIGMA_MIN = 1e-2
# A cross product shorter than this (both inputs unit) is "nearly parallel".
_CROSS_EPS = 1e-3
# Neighbour matrices (cells x neighbours) per vectorised block of the
# simultaneous update: bounds its memory to some tens of MB.
_BLOCK_CANDIDATES = 200_000


class Regularised(NamedTuple):
    """Result of :func:`regularise_orientations`.

    rotation : (..., d, d) float64
        Regular rotation field; proper rotations except in ``unfilled`` cells
        (zero matrices).
    trivial : (...) bool
        Cells whose whole orientation was undefined and was regenerated.
    partial : (...) bool
        3D cells where only ``v1`` was defined and Algorithm 1 completed it.
    unfilled : (...) bool
        Cells still without an orientation (no defined direction reachable,
        or ``max_steps`` too small). All False in the usual case.
    """

    rotation: np.ndarray
    trivial: np.ndarray
    partial: np.ndarray
    unfilled: np.ndarray


def _check_rotation(rotation, name="rotation"):
    r = np.array(rotation, dtype=np.float64)
    if r.ndim < 3 or r.shape[-1] != r.shape[-2] or r.shape[-1] not in (2, 3) or r.ndim - 2 != r.shape[-1]:
        raise ValueError(f"{name} must have shape grid + (d, d) with d = grid dimension (2 or 3); got {r.shape}")
    if not np.isfinite(r).all():
        raise ValueError(f"{name} must be finite; got NaN or infinite entries")
    return r


def signed_permutations(d):
    """All d x d signed permutation matrices, identity first: (d! 2^d, d, d) float64."""
    return _group(int(d)).copy()


@functools.lru_cache(maxsize=None)
def _group(d):
    mats = []
    for perm in itertools.permutations(range(d)):
        for signs in itertools.product((1.0, -1.0), repeat=d):
            p = np.zeros((d, d))
            p[list(perm), range(d)] = signs
            mats.append(p)
    out = np.array(mats)
    out.flags.writeable = False
    return out


def neighbour_offsets(ndim, neighbourhood="face"):
    """Neighbour offsets in raster order: (k, ndim) int, k = 2 ndim ("face") or 3^ndim - 1 ("full")."""
    if neighbourhood not in ("face", "full"):
        raise ValueError(f"neighbourhood must be 'face' or 'full'; got {neighbourhood!r}")
    offs = [o for o in itertools.product((-1, 0, 1), repeat=ndim) if any(o)]
    if neighbourhood == "face":
        offs = [o for o in offs if sum(map(abs, o)) == 1]
    return np.array(offs, dtype=np.int64)


def closest_matrix(reference, rotation):
    """``rotation @ P`` for the signed permutation ``P`` that brings it closest to ``reference``.

    Parameters
    ----------
    reference, rotation : (..., d, d) float
        Broadcast against each other.

    Returns
    -------
    (..., d, d) float64
        The columns of ``rotation`` reordered and sign-flipped to maximise
        ``trace(reference^T rotation P)``; ties go to the first element of
        :func:`signed_permutations`.

    Notes
    -----
    With ``M = reference^T rotation`` the trace for the permutation ``p`` and
    signs ``s`` is ``sum_c s_c M[c, p(c)]``, so the best signs are those of
    ``M`` (``+`` on a zero, as the group lists ``+`` first) and only the
    ``d!`` permutations need scoring.
    """
    a = np.asarray(reference, dtype=np.float64)
    b = np.asarray(rotation, dtype=np.float64)
    a, b = np.broadcast_arrays(a, b)
    d = b.shape[-1]
    m = np.swapaxes(a, -1, -2) @ b
    perms = np.array(list(itertools.permutations(range(d))))           # (p, d)
    picked = m[..., np.arange(d)[None, :], perms]                     # (..., p, d)
    best = np.argmax(np.abs(picked).sum(axis=-1), axis=-1)            # (...,)
    perm = perms[best]                                                # (..., d)
    signs = np.where(np.take_along_axis(picked, best[..., None, None], axis=-2)[..., 0, :] < 0, -1.0, 1.0)
    cols = np.take_along_axis(b, np.broadcast_to(perm[..., None, :], b.shape), axis=-1)
    return cols * signs[..., None, :]


def orthonormalise(m):
    """Nearest proper rotation (polar factor, last column flipped if det < 0): (..., d, d) -> same."""
    u, _, vt = np.linalg.svd(np.asarray(m, dtype=np.float64))
    q = u @ vt
    flip = np.linalg.det(q) < 0
    q[flip, :, -1] *= -1.0
    return q


def mask_trivial_directions(values, rotation, *, sigma_min):
    """Zero the principal directions that are not well defined (paper Appendix).

    Parameters
    ----------
    values : (..., d) float
        Principal stresses sorted by decreasing magnitude.
    rotation : (..., d, d) float
        Matching unit directions as columns.
    sigma_min : float >= 0
        Stress magnitude up to which a stress, or a difference of magnitudes,
        counts as zero.

    Returns
    -------
    (..., d, d) float64
        A copy with zero columns where undefined: all columns when ``v1`` is
        undefined (``|sigma_1| <= sigma_min`` or ``||sigma_1| - |sigma_2|| <=
        sigma_min``); in 3D ``v2`` and ``v3`` when ``v2`` is undefined
        (``|sigma_2| <= sigma_min`` or ``||sigma_2| - |sigma_3|| <= sigma_min``).
        A 2D ``v2`` (3D ``v3``) follows from the columns before it and is never
        zeroed on its own.
    """
    r = _check_rotation(rotation)
    mag = np.abs(np.asarray(values, dtype=np.float64))
    if mag.shape != r.shape[:-1]:
        raise ValueError(f"values must have shape {r.shape[:-1]} to match rotation; got {mag.shape}")
    smin = float(sigma_min)
    if not np.isfinite(smin) or smin < 0:
        raise ValueError(f"sigma_min must be a finite stress >= 0; got {sigma_min!r}")
    d = r.shape[-1]
    # "<=" rather than the paper's "<" so that sigma_min = 0 still drops exact
    # zeros and exact ties, which have no direction either.
    first_bad = (mag[..., 0] <= smin) | (np.abs(mag[..., 0] - mag[..., 1]) <= smin)
    out = r.copy()
    out[first_bad] = 0.0
    if d == 3:
        second_bad = ~first_bad & ((mag[..., 1] <= smin) | (np.abs(mag[..., 1] - mag[..., 2]) <= smin))
        out[second_bad, :, 1:] = 0.0
    return out


def _is_zero(r):
    return ~(r != 0.0).any(axis=(-2, -1))


def complete_partial_orientations(rotation, *, v_alpha=V_ALPHA, v_beta=V_BETA, eps=_CROSS_EPS):
    """Algorithm 1: complete 3D cells ``(v1, 0, 0)`` into proper rotations.

    Parameters
    ----------
    rotation : (nz, ny, nx, 3, 3) float
        Columns are directions; a zero column means "undefined". 2D fields
        are returned unchanged (a 2D ``v2`` is never undefined alone).
    v_alpha, v_beta : 3 floats
        Non-colinear constant vectors (normalised here).
    eps : float
        If ``|v1 x v_alpha| < eps`` (after normalising) ``v_beta`` is used.

    Returns
    -------
    (..., d, d) float64 copy; cells with ``v1 != 0`` and ``v2 = 0`` now hold
    ``(v1, v2, v1 x v2)`` with ``v2 = normalise(v1 x v_alpha or v_beta)``.
    """
    r = _check_rotation(rotation)
    if r.shape[-1] == 2:
        return r
    va = np.asarray(v_alpha, dtype=np.float64)
    vb = np.asarray(v_beta, dtype=np.float64)
    for name, v in (("v_alpha", va), ("v_beta", vb)):
        if v.shape != (3,) or not np.isfinite(v).all() or np.linalg.norm(v) == 0:
            raise ValueError(f"{name} must be a finite non-zero 3-vector; got {v!r}")
    va, vb = va / np.linalg.norm(va), vb / np.linalg.norm(vb)
    if np.linalg.norm(np.cross(va, vb)) < eps:
        raise ValueError("v_alpha and v_beta must not be colinear")
    out = r.copy()
    v1 = r[..., :, 0]
    v2 = r[..., :, 1]
    todo = (v1 != 0).any(axis=-1) & ~(v2 != 0).any(axis=-1)
    a = v1[todo]
    a = a / np.linalg.norm(a, axis=-1, keepdims=True)
    w = np.cross(a, va)
    short = np.linalg.norm(w, axis=-1) < eps
    w[short] = np.cross(a[short], vb)
    w /= np.linalg.norm(w, axis=-1, keepdims=True)
    out[todo, :, 0] = a
    out[todo, :, 1] = w
    out[todo, :, 2] = np.cross(a, w)
    return out


def _neighbour_table(shape, neighbourhood):
    """Flat neighbour indices (n, k) and validity (n, k) for a C-ordered grid."""
    offs = neighbour_offsets(len(shape), neighbourhood)
    idx = np.indices(shape).reshape(len(shape), -1).T          # (n, ndim)
    nb = idx[:, None, :] + offs[None, :, :]
    valid = ((nb >= 0) & (nb < np.array(shape))).all(axis=-1)
    flat = np.ravel_multi_index(tuple(np.clip(nb, 0, np.array(shape) - 1).transpose(2, 0, 1)), shape)
    return flat, valid


def _fill(rs, ok):
    """Mean of neighbour rotations in the first one's basis: (m, k, d, d), (m, k) -> (m, d, d)."""
    first = np.argmax(ok, axis=1)
    ref = rs[np.arange(rs.shape[0]), first]
    tmp = closest_matrix(ref[:, None], rs)
    total = np.where(ok[..., None, None], tmp, 0.0).sum(axis=1)
    return orthonormalise(total)


def regenerate_trivial_orientations(rotation, *, neighbourhood="face", max_steps=None,
                                    update="sequential", progress=None):
    """Algorithm 2: replace zero orientations by the aligned mean of their neighbours.

    Parameters
    ----------
    rotation : (ny, nx, 2, 2) or (nz, ny, nx, 3, 3) float
        Each cell a rotation or a zero matrix (run Algorithm 1 first in 3D).
    neighbourhood : {"face", "full"}
        4 / 6 or 8 / 26 neighbours.
    max_steps : int, optional
        Number of sweeps ("nStep"); default: until no zero cell can be filled.
    update : {"sequential", "simultaneous"}
        The paper's in-place raster sweep, or the order-independent
        vectorised sweep (see the module notes).
    progress : callable(done, total) -> bool, optional
        ``done`` counts filled cells out of the zero cells at the start;
        returning False raises :class:`engine.progress.Cancelled`.

    Returns
    -------
    rotation : (..., d, d) float64
        A copy with the reachable zero cells filled by proper rotations.
    unfilled : (...) bool
        Cells still zero.
    """
    r = _check_rotation(rotation)
    if update not in ("sequential", "simultaneous"):
        raise ValueError(f"update must be 'sequential' or 'simultaneous'; got {update!r}")
    if max_steps is not None and (int(max_steps) != max_steps or max_steps < 0):
        raise ValueError(f"max_steps must be an int >= 0 or None; got {max_steps!r}")
    shape, d = r.shape[:-2], r.shape[-1]
    flat_r = r.reshape(-1, d, d)
    zero = _is_zero(flat_r)
    total = int(zero.sum())
    nb, valid = _neighbour_table(shape, neighbourhood)
    report(progress, 0, total)
    step = 0
    while zero.any() and (max_steps is None or step < max_steps):
        if update == "sequential":
            changed = _sweep_sequential(flat_r, zero, nb, valid, progress, total)
        else:
            changed = _sweep_simultaneous(flat_r, zero, nb, valid)
        step += 1
        report(progress, total - int(zero.sum()), total)
        if not changed:
            break
    return flat_r.reshape(r.shape), zero.reshape(shape)


def _sweep_sequential(flat_r, zero, nb, valid, progress, total):
    changed = False
    for n, i in enumerate(np.flatnonzero(zero)):
        k = nb[i][valid[i]]
        ok = ~zero[k]
        if not ok.any():
            continue
        flat_r[i] = _fill(flat_r[k][None], ok[None])[0]
        zero[i] = False
        changed = True
        if n % 256 == 255:
            report(progress, total - int(zero.sum()), total)
    return changed


def _sweep_simultaneous(flat_r, zero, nb, valid):
    cells = np.flatnonzero(zero)
    ok = valid[cells] & ~zero[nb[cells]]
    reach = ok.any(axis=1)
    cells, ok = cells[reach], ok[reach]
    new = np.empty((cells.size,) + flat_r.shape[1:])
    block = max(1, _BLOCK_CANDIDATES // nb.shape[1])
    for s in range(0, cells.size, block):
        sl = slice(s, s + block)
        new[sl] = _fill(flat_r[nb[cells[sl]]], ok[sl])
    flat_r[cells] = new
    zero[cells] = False
    return cells.size > 0


def regularise_orientations(values, rotation, *, sigma_min=None, relative_sigma_min=RELATIVE_SIGMA_MIN,
                            v_alpha=V_ALPHA, v_beta=V_BETA, neighbourhood="face", max_steps=None,
                            update="sequential", progress=None):
    """Mask undefined directions, then run Algorithms 1 and 2 (paper Appendix).

    Parameters
    ----------
    values : (..., d) float
        Principal stresses sorted by decreasing magnitude (from
        :func:`engine.rd.tensor_field.principal_decomposition`).
    rotation : (..., d, d) float
        Principal directions as columns.
    sigma_min : float, optional
        Absolute threshold (stress units). Default:
        ``relative_sigma_min * max |sigma_1|``.
    relative_sigma_min : float
        Used when ``sigma_min`` is None.
    v_alpha, v_beta, neighbourhood, max_steps, update, progress
        See :func:`complete_partial_orientations` and
        :func:`regenerate_trivial_orientations`.

    Returns
    -------
    Regularised
    """
    r = _check_rotation(rotation)
    vals = np.asarray(values, dtype=np.float64)
    if vals.shape != r.shape[:-1] or not np.isfinite(vals).all():
        raise ValueError(f"values must be finite with shape {r.shape[:-1]}; got {vals.shape}")
    if sigma_min is None:
        rel = float(relative_sigma_min)
        if not np.isfinite(rel) or rel < 0:
            raise ValueError(f"relative_sigma_min must be a finite number >= 0; got {relative_sigma_min!r}")
        sigma_min = rel * float(np.abs(vals[..., 0]).max(initial=0.0))
    masked = mask_trivial_directions(vals, r, sigma_min=sigma_min)
    trivial = _is_zero(masked)
    partial = ~trivial & ~(masked[..., :, 1] != 0).any(axis=-1)
    completed = complete_partial_orientations(masked, v_alpha=v_alpha, v_beta=v_beta)
    filled, unfilled = regenerate_trivial_orientations(completed, neighbourhood=neighbourhood,
                                                       max_steps=max_steps, update=update, progress=progress)
    return Regularised(filled, trivial, partial, unfilled)
