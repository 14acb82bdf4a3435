"""Per-cell stress tensors from solved displacements, and von Mises.

The strain of a bilinear / trilinear cell is evaluated at its centre
(``B(centre) u_e``, the point where it is most accurate), and the stress is
``s(rho_e) D e`` with, by default, the SIMP stiffness factor
``s = e_min + (1 - e_min) rho^p``: the stress the grey material actually
carries, in equilibrium with the loads (near zero in void cells). With
``interpolation="solid"`` the factor is 1: the stress in the solid phase at
the same strain, which stress-constrained methods use.

Output layout: ``sigma[..., i, j]`` with ``i, j`` in ``(x, y[, z])`` order,
cell axes ``[y, x]`` / ``[z, y, x]``, a leading load-case axis, symmetric.
"""

from __future__ import annotations

import numpy as np

from .assembly import grid_fe
from .design import design_space
from .orthotropic import ANISOTROPY, coefficients_to_voigt, orthotropic_material, rotated_material

__all__ = ["element_stress", "von_mises", "voigt_to_tensor_field"]

_VOIGT = {2: np.array([[0, 2], [2, 1]]), 3: np.array([[0, 5, 4], [5, 1, 3], [4, 3, 2]])}


def voigt_to_tensor_field(s):
    """(..., 3) or (..., 6) Voigt stresses to (..., d, d) symmetric tensors."""
    s = np.asarray(s)
    dim = 2 if s.shape[-1] == 3 else 3
    return s[..., _VOIGT[dim]]


def element_stress(problem, rho, displacements, *, interpolation="simp", theta=None,
                   anisotropy=ANISOTROPY):
    """Stress tensor at the centre of every cell, for every load case.

    Parameters
    ----------
    problem : Problem
    rho : float cell array, physical densities.
    displacements : (n_cases,) + node-grid shape + (dim,) float64, or
        (n_cases, n_dofs); a single case may omit the leading axis.
    interpolation : {"simp", "solid"}
        Stiffness factor applied to the solid law (see module notes).
    theta : float cell array, optional (2D)
        Material angles of an oriented orthotropic design
        (:func:`engine.topopt.orthotropic_orientation`); the law is then the
        one of :mod:`.orthotropic` instead of the isotropic solid.
    anisotropy : float, stiffness ratio of that law.

    Returns
    -------
    sigma : (n_cases,) + cell shape + (d, d) float64, symmetric, in the
        units of ``young`` (force per area; 2D is unit thickness).
    """
    if interpolation not in ("simp", "solid"):
        raise ValueError(f"interpolation must be 'simp' or 'solid'; got {interpolation!r}")
    fe = grid_fe(problem)
    rho = np.asarray(rho, dtype=np.float64)
    if rho.shape != problem.shape:
        raise ValueError(f"rho must have the cell shape {problem.shape}; got {rho.shape}")
    U = np.asarray(displacements, dtype=np.float64)
    U = U.reshape(-1, problem.n_dofs) if U.size % problem.n_dofs == 0 else None
    if U is None:
        raise ValueError(f"displacements must hold n_cases x {problem.n_dofs} values")
    strain = U[:, fe.edofs] @ fe.B.T                                 # (n_cases, n_cells, n_voigt)
    if theta is None:
        voigt = strain @ fe.D.T
    else:
        if problem.dim != 2 or np.size(theta) != problem.n_cells:
            raise ValueError(f"theta must hold one angle per cell of a 2D problem; got size {np.size(theta)}")
        Q = orthotropic_material(problem.young, problem.poisson, anisotropy)
        D = coefficients_to_voigt(rotated_material(Q, np.ravel(theta))[0])   # (n_cells, 3, 3)
        voigt = np.einsum("eij,cej->cei", D, strain)
    if interpolation == "simp":
        voigt *= design_space(problem).stiffness_scale(rho)[0][None, :, None]
    sigma = voigt_to_tensor_field(voigt)
    return sigma.reshape((U.shape[0],) + problem.shape + sigma.shape[-2:])


def von_mises(sigma):
    """Von Mises equivalent stress of (..., d, d) tensors.

    2D tensors are read as plane stress (``sigma_zz = 0``).

    Returns
    -------
    (...) float64
    """
    s = np.asarray(sigma, dtype=np.float64)
    d = s.shape[-1]
    dev = s - np.trace(s, axis1=-2, axis2=-1)[..., None, None] * np.eye(d) / 3.0
    j2 = 0.5 * np.einsum("...ij,...ij->...", dev, dev)
    if d == 2:
        # the zz deviator of plane stress is -(s_xx + s_yy) / 3, not in the 2x2 block
        j2 = j2 + 0.5 * (np.trace(s, axis1=-2, axis2=-1) / 3.0) ** 2
    return np.sqrt(3.0 * j2)
