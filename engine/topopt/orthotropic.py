"""The oriented orthotropic plane-stress law of the multi-load optimisation.

Material axes: ``E1 = young``, ``E2 = young / anisotropy`` (3 in the paper),
``nu12 = poisson`` (so ``nu21 = nu12 / anisotropy``) and Huber's shear modulus
``G12 = sqrt(E1 E2) / (2 (1 + sqrt(nu12 nu21)))`` (the paper states only the
3:1 ratio). Rotated by ``theta`` (axis 1 along ``(cos theta, sin theta)``)
the Voigt matrix follows the Tsai-Pagano invariants, so it and its
theta-derivative are closed forms.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["ANISOTROPY", "orthotropic_material", "rotated_material", "coefficients_to_voigt"]

ANISOTROPY = 3.0


def orthotropic_material(young=1.0, poisson=0.3, anisotropy=ANISOTROPY):
    """Plane-stress Voigt matrix in material axes, axis 1 the stiff one.

    Returns
    -------
    Q : (3, 3) float64, order (11, 22, 12), engineering shear.
    """
    E1, E2 = young, young / anisotropy
    nu12 = poisson
    nu21 = nu12 * E2 / E1
    G12 = math.sqrt(E1 * E2) / (2.0 * (1.0 + math.sqrt(nu12 * nu21)))
    k = 1.0 / (1.0 - nu12 * nu21)
    return np.array([[k * E1, k * nu12 * E2, 0.0], [k * nu12 * E2, k * E2, 0.0], [0.0, 0.0, G12]])


def _invariants(Q):
    q11, q22, q12, q66 = Q[0, 0], Q[1, 1], Q[0, 1], Q[2, 2]
    return ((3 * q11 + 3 * q22 + 2 * q12 + 4 * q66) / 8, (q11 - q22) / 2,
            (q11 + q22 - 2 * q12 - 4 * q66) / 8, (q11 + q22 + 6 * q12 - 4 * q66) / 8,
            (q11 + q22 - 2 * q12 + 4 * q66) / 8)


def rotated_material(Q, theta):
    """Voigt coefficients of ``Q`` rotated by ``theta`` and their derivative.

    Parameters
    ----------
    Q : (3, 3) orthotropic matrix in material axes (no 16 / 26 coupling).
    theta : (n,) float64, radians from +x, counter-clockwise.

    Returns
    -------
    d, dd : (n, 6) float64
        Coefficients in the order of :func:`q4_stiffness_basis`
        (D11, D22, D33, D12, D13, D23) and their theta-derivatives.
    """
    U1, U2, U3, U4, U5 = _invariants(Q)
    t = np.asarray(theta, dtype=np.float64)
    c2, s2, c4, s4 = np.cos(2 * t), np.sin(2 * t), np.cos(4 * t), np.sin(4 * t)
    d = np.stack([U1 + U2 * c2 + U3 * c4, U1 - U2 * c2 + U3 * c4, U5 - U3 * c4,
                  U4 - U3 * c4, 0.5 * U2 * s2 + U3 * s4, 0.5 * U2 * s2 - U3 * s4], axis=-1)
    dd = np.stack([-2 * U2 * s2 - 4 * U3 * s4, 2 * U2 * s2 - 4 * U3 * s4, 4 * U3 * s4,
                   4 * U3 * s4, U2 * c2 + 4 * U3 * c4, U2 * c2 - 4 * U3 * c4], axis=-1)
    return d, dd


def coefficients_to_voigt(d):
    """(n, 6) coefficients (D11, D22, D33, D12, D13, D23) to (n, 3, 3) Voigt matrices."""
    d = np.asarray(d)
    idx = np.array([[0, 3, 4], [3, 1, 5], [4, 5, 2]])
    return d[..., idx]
