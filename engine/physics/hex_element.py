"""Element matrices of the voxel (trilinear hex) and pixel (bilinear quad) cells.

Conventions shared by every homogenization kernel in this package:

* Voigt notation with ENGINEERING shear strains. 3D order
  ``(xx, yy, zz, yz, xz, xy)``; 2D order ``(xx, yy, xy)``.
* An element is the cube ``[0, h]^dim`` (voxel or pixel of side ``h``), or
  the box ``[0, h_0] x [0, h_1] (x [0, h_2])`` when ``h`` is one length per
  axis. Its local node ``l`` sits at ``h * (b_0, b_1[, b_2])`` with ``b_a = (l >> a) & 1``,
  i.e. node 0 at the origin, node 1 one step along x, node 2 along y, node 3
  along x and y, node 4 along z, ... ("lexicographic", x fastest).
* Element degrees of freedom are node-major: dof ``l * dim + a`` is the
  displacement component ``a`` of local node ``l``.
* 2D is plane stress of unit thickness.

The matrices are integrated with 2-point Gauss quadrature per axis, which is
exact here: every integrand is a polynomial of degree <= 2 in each coordinate.
"""

from __future__ import annotations

import math

import numpy as np

from .elastic import isotropic_plane_stress as plane_stress_stiffness
from .elastic import isotropic_stiffness

__all__ = [
    "isotropic_stiffness", "plane_stress_stiffness",
    "element_matrices", "hex_stiffness", "hex_strain_loads",
    "quad_stiffness", "quad_strain_loads", "unit_strain_displacements",
]


def _local_nodes(dim):
    """(2**dim, dim) int local node offsets, x fastest."""
    return np.array([[(l >> a) & 1 for a in range(dim)] for l in range(2 ** dim)])


def _shape_gradients(dim, xi):
    """Gradients of the multilinear shape functions on the unit element.

    xi : (dim,) point in [0, 1]^dim. Returns (2**dim, dim).
    """
    nodes = _local_nodes(dim)
    # 1D factors: value and derivative of (1 - t) for bit 0, t for bit 1.
    val = np.where(nodes == 1, xi, 1.0 - xi)
    der = np.where(nodes == 1, 1.0, -1.0)
    grads = np.empty((len(nodes), dim))
    for a in range(dim):
        g = der[:, a].copy()
        for b in range(dim):
            if b != a:
                g *= val[:, b]
        grads[:, a] = g
    return grads


def _strain_operator(grads):
    """B matrix (n_voigt, n_nodes*dim) mapping element dofs to engineering strain."""
    n, dim = grads.shape
    if dim == 3:
        pairs = [(0, 0), (1, 1), (2, 2)]
        shears = [(1, 2), (0, 2), (0, 1)]          # yz, xz, xy
    else:
        pairs = [(0, 0), (1, 1)]
        shears = [(0, 1)]                          # xy
    B = np.zeros((len(pairs) + len(shears), n * dim))
    for row, (a, _) in enumerate(pairs):
        B[row, a::dim] = grads[:, a]
    for k, (a, b) in enumerate(shears):
        row = len(pairs) + k
        B[row, a::dim] = grads[:, b]               # d u_a / d x_b
        B[row, b::dim] = grads[:, a]               # d u_b / d x_a
    return B


def _edges(dim, h):
    """h as given (a float) or a (dim,) float64 array of per-axis edges."""
    if np.ndim(h) == 0:
        return float(h)
    edges = np.asarray(h, dtype=np.float64).reshape(-1)
    if edges.shape != (dim,) or not np.all(np.isfinite(edges) & (edges > 0)):
        raise ValueError(f"h must be a length > 0 or {dim} of them; got {h!r}")
    return edges


def element_matrices(D, dim, h=1.0):
    """Stiffness and unit-strain loads of a cubic (or box) element.

    Parameters
    ----------
    D : (n_voigt, n_voigt) float64
        Constitutive matrix (engineering shear), n_voigt = 6 (3D) or 3 (2D).
    dim : {2, 3}
    h : float or (dim,) float
        Element side length, or the edge lengths ``(h_x, h_y[, h_z])`` of a
        box element.

    Returns
    -------
    K : (2**dim * dim, 2**dim * dim) float64
        ``integral B^T D B`` over the element.
    F : (2**dim * dim, n_voigt) float64
        ``integral B^T D`` over the element: column ``i`` is the nodal force of
        the unit macroscopic strain ``i`` (``F = K @ unit_strain_displacements``).
    """
    D = np.asarray(D, dtype=np.float64)
    gauss = 0.5 + np.array([-0.5, 0.5]) / math.sqrt(3.0)
    nde = 2 ** dim * dim
    K = np.zeros((nde, nde))
    F = np.zeros((nde, D.shape[0]))
    h = _edges(dim, h)
    box = np.ndim(h) == 1
    weight = (float(np.prod(h)) if box else h ** dim) / 2 ** dim
    for idx in np.ndindex(*([2] * dim)):
        xi = gauss[list(idx)]
        if box:   # chain rule per axis: d/dx_a = (1 / h_a) d/dxi_a
            B = _strain_operator(_shape_gradients(dim, xi) / h[None, :])
        else:
            B = _strain_operator(_shape_gradients(dim, xi)) / h
        K += weight * B.T @ D @ B
        F += weight * B.T @ D
    # Exact symmetry (the sum above is symmetric up to rounding only).
    K = 0.5 * (K + K.T)
    return K, F


def unit_strain_displacements(dim, h=1.0):
    """Nodal displacements ``u = eps x`` of the unit macroscopic strains.

    h : float or (dim,) float, element side or box edges.

    Returns
    -------
    U0 : (2**dim * dim, n_voigt) float64; column ``i`` belongs to the unit
        Voigt strain ``i`` (engineering shear 1 = tensor shear 1/2).
    """
    x = _edges(dim, h) * _local_nodes(dim).astype(np.float64)
    if dim == 3:
        comps = [(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)]
    else:
        comps = [(0, 0), (1, 1), (0, 1)]
    U0 = np.zeros((len(x) * dim, len(comps)))
    for i, (a, b) in enumerate(comps):
        eps = np.zeros((dim, dim))
        if a == b:
            eps[a, a] = 1.0
        else:
            eps[a, b] = eps[b, a] = 0.5
        U0[:, i] = (x @ eps.T).ravel()
    return U0


def hex_stiffness(E, nu, h=1.0):
    """24x24 stiffness of a trilinear voxel of side ``h``, isotropic (E, nu)."""
    return element_matrices(isotropic_stiffness(E, nu), 3, h)[0]


def hex_strain_loads(E, nu, h=1.0):
    """24x6 nodal forces of the six unit macroscopic strains on one voxel."""
    return element_matrices(isotropic_stiffness(E, nu), 3, h)[1]


def quad_stiffness(E, nu, h=1.0):
    """8x8 plane-stress stiffness of a bilinear pixel of side ``h``, unit thickness."""
    return element_matrices(plane_stress_stiffness(E, nu), 2, h)[0]


def quad_strain_loads(E, nu, h=1.0):
    """8x3 nodal forces of the three unit macroscopic strains on one pixel."""
    return element_matrices(plane_stress_stiffness(E, nu), 2, h)[1]
