"""Trilinear eight-node (H8) element on a cubic voxel, and the 3D grid numbering.

The element matrix is the one of :mod:`engine.physics.hex_element` (exact
2-point Gauss quadrature, same lexicographic node order: local node ``l`` at
``h * (l & 1, (l >> 1) & 1, l >> 2)``, dofs node-major, Voigt order
(xx, yy, zz, yz, xz, xy) with engineering shear); this module only adds the
centre strain operator and the grid numbering used by the optimiser.
"""

from __future__ import annotations

import numpy as np

from engine.physics.hex_element import element_matrices, isotropic_stiffness

__all__ = ["h8_stiffness", "h8_centre_strain", "element_dofs_3d"]

_BITS = np.array([[(l >> a) & 1 for a in range(3)] for l in range(8)])
_SIGN = 2 * _BITS - 1


def h8_stiffness(young, poisson, h=1.0):
    """24x24 stiffness of an isotropic trilinear voxel of side ``h``.

    Parameters
    ----------
    young : float > 0
    poisson : float in (-1, 0.5)
    h : float > 0
        Voxel side; ``K`` scales with ``h``.
    """
    return element_matrices(isotropic_stiffness(young, poisson), 3, h)[0]


def h8_centre_strain(h=1.0):
    """Strain-displacement matrix at the voxel centre.

    Returns
    -------
    B : (6, 24) float64
        ``[e_xx, e_yy, e_zz, 2 e_yz, 2 e_xz, 2 e_xy] = B @ u_e``.
    """
    grads = _SIGN * 0.25 / h                     # product of two 1/2 factors and one derivative
    B = np.zeros((6, 24))
    for a in range(3):
        B[a, a::3] = grads[:, a]
    for row, (a, b) in zip((3, 4, 5), ((1, 2), (0, 2), (0, 1))):
        B[row, a::3] = grads[:, b]
        B[row, b::3] = grads[:, a]
    return B


def element_dofs_3d(nelz, nely, nelx):
    """Global dofs of every element of a ``nelz x nely x nelx`` voxel grid.

    Nodes are numbered ``ix + (nelx + 1) * (iy + (nely + 1) * iz)``; dof
    ``3 node + a``. Elements are numbered row-major over ``[z, y, x]``.

    Returns
    -------
    edofs : (nelz * nely * nelx, 24) int64
    """
    iz, iy, ix = np.meshgrid(np.arange(nelz), np.arange(nely), np.arange(nelx), indexing="ij")
    sx, sy = 1, nelx + 1
    sz = (nelx + 1) * (nely + 1)
    base = (ix * sx + iy * sy + iz * sz).ravel()
    local = _BITS[:, 0] * sx + _BITS[:, 1] * sy + _BITS[:, 2] * sz
    nodes = base[:, None] + local[None, :]
    return (3 * nodes[:, :, None] + np.arange(3)[None, None, :]).reshape(-1, 24)
