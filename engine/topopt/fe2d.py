"""Bilinear four-node (Q4) plane-stress element on a square pixel, in closed form.

Conventions (shared with :mod:`engine.physics.hex_element`)
-----------------------------------------------------------
* The element is the square ``[0, h]^2`` of unit thickness; local node ``l``
  sits at ``h * (l & 1, l >> 1)``: node 0 at the origin, 1 one step along x,
  2 along y, 3 along x and y.
* Element dofs are node-major: dof ``2 l + a`` is displacement component
  ``a`` (0 = x, 1 = y) of local node ``l``.
* Constitutive matrices are 3x3 Voigt, order (xx, yy, xy), engineering shear
  (``sigma = D @ [e_xx, e_yy, 2 e_xy]``).

The stiffness ``K = integral B^T D B`` is exact, not quadrature: with
``N_l(x, y) = f_bx(x / h) f_by(y / h)``, ``f_0(t) = 1 - t``, ``f_1(t) = t``,
every entry is a product of the one-dimensional integrals
``int f_a f_b = 1/3 (a = b) or 1/6``, ``int f_a = 1/2`` and
``f_a' = -1 or +1``. For the square element ``K`` does not depend on ``h``.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "q4_stiffness", "q4_stiffness_basis", "q4_centre_strain",
    "element_dofs_2d", "VOIGT_2D",
]

# Voigt index of the tensor index pair (i, j), 2D.
VOIGT_2D = np.array([[0, 2], [2, 1]])
_BITS = np.array([[l & 1, l >> 1] for l in range(4)])        # (4, 2): x bit, y bit
_SIGN = 2 * _BITS - 1                                          # d f_b / dt


def _overlap(a, b):
    """int_0^1 f_a f_b dt for bit arrays a, b."""
    return np.where(a == b, 1.0 / 3.0, 1.0 / 6.0)


def _gradient_products():
    """G[m, i, n, j] = int_{unit square} dN_m/dx_i dN_n/dx_j, shape (4, 2, 4, 2)."""
    bx, by = _BITS[:, 0], _BITS[:, 1]
    sx, sy = _SIGN[:, 0], _SIGN[:, 1]
    G = np.empty((4, 2, 4, 2))
    G[:, 0, :, 0] = np.outer(sx, sx) * _overlap(by[:, None], by[None, :])
    G[:, 1, :, 1] = np.outer(sy, sy) * _overlap(bx[:, None], bx[None, :])
    # the mixed term integrates each direction separately: (s / 1) * (1 / 2).
    G[:, 0, :, 1] = np.outer(sx, sy) * 0.25
    G[:, 1, :, 0] = np.outer(sy, sx) * 0.25
    return G


_G = _gradient_products()


def _voigt_to_tensor(D):
    D = np.asarray(D, dtype=np.float64)
    if D.shape != (3, 3):
        raise ValueError(f"D must be a 3x3 Voigt matrix (xx, yy, xy); got shape {D.shape}")
    return D[VOIGT_2D[:, :, None, None], VOIGT_2D[None, None, :, :]]


def q4_stiffness(D):
    """8x8 stiffness of the square bilinear element, unit thickness.

    Parameters
    ----------
    D : (3, 3) array_like
        Plane constitutive matrix, Voigt (xx, yy, xy), engineering shear. It
        need not be isotropic; ``K`` is linear in ``D``.

    Returns
    -------
    K : (8, 8) float64, symmetric; independent of the element size.
    """
    C = _voigt_to_tensor(D)
    # K[m a, n b] = sum_ij C[a i b j] G[m i n j]
    K = np.einsum("aibj,minj->manb", C, _G).reshape(8, 8)
    return 0.5 * (K + K.T)


def q4_stiffness_basis():
    """Stiffness per unit entry of ``D``: ``K(D) = sum_k d_k Kb[k]``.

    Returns
    -------
    Kb : (6, 8, 8) float64
        Order of the coefficients ``d``: D11, D22, D33, D12, D13, D23 (the
        off-diagonal ones each stand for both symmetric entries).
    """
    pairs = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)]
    Kb = np.empty((6, 8, 8))
    for k, (i, j) in enumerate(pairs):
        E = np.zeros((3, 3))
        E[i, j] = E[j, i] = 1.0
        Kb[k] = q4_stiffness(E)
    return Kb


def q4_centre_strain(h=1.0):
    """Strain-displacement matrix at the element centre.

    Parameters
    ----------
    h : float
        Element side length.

    Returns
    -------
    B : (3, 8) float64
        ``[e_xx, e_yy, 2 e_xy] = B @ u_e`` at ``(h/2, h/2)``.
    """
    grads = _SIGN * 0.5 / h                      # (4, 2): dN_l/dx, dN_l/dy at the centre
    B = np.zeros((3, 8))
    B[0, 0::2] = grads[:, 0]
    B[1, 1::2] = grads[:, 1]
    B[2, 0::2] = grads[:, 1]
    B[2, 1::2] = grads[:, 0]
    return B


def element_dofs_2d(nely, nelx):
    """Global dofs of every element of a ``nely x nelx`` pixel grid.

    Nodes are numbered ``ix + (nelx + 1) * iy``; dof ``2 node + a``.
    Elements are numbered row-major over ``[y, x]`` (``ix + nelx * iy``).

    Returns
    -------
    edofs : (nely * nelx, 8) int64, local dof order as in :func:`q4_stiffness`.
    """
    iy, ix = np.meshgrid(np.arange(nely), np.arange(nelx), indexing="ij")
    base = (ix + (nelx + 1) * iy).ravel()
    local = np.array([0, 1, nelx + 1, nelx + 2])             # lexicographic, x fastest
    nodes = base[:, None] + local[None, :]
    return (2 * nodes[:, :, None] + np.arange(2)[None, None, :]).reshape(-1, 8)
