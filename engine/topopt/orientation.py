"""Density and material orientation for several load cases (paper eq. 19).

The route built is the paper's own (Sec. 6.3, after Schmidt et al. 2020):
each cell carries a density ``rho_e`` (filtered design variable, SIMP
penalised) and an angle ``theta_e`` of an orthotropic plane-stress material
three times stiffer along its principal axis; the objective is the p-norm
of the load cases' compliances, ``J = (sum_i (f_i . u_i)^P)^(1/P)`` with
``P = 8``, under the volume constraint, optimised by MMA (:mod:`mma`) with
``-pi <= theta <= pi``. 2D only; the 3D presets are single-load, where the
stress tensor itself gives the orientation.

The material law and its rotation are in :mod:`.orthotropic`; the cell
stiffness is linear in the rotated Voigt coefficients
(:func:`engine.topopt.fe2d.q4_stiffness_basis`).

Gradients: ``dc_i/drho_e = -E'(rho_e) u_ie . K(theta_e) u_ie`` and
``dc_i/dtheta_e = -E(rho_e) u_ie . K'(theta_e) u_ie`` (compliance is
self-adjoint), ``dJ/dc_i = (c_i / J)^(P-1)``.

The start angle is the simpler route, kept as :func:`stress_orientation`:
the principal direction of ``sum_i w_i sigma_i^2`` over the load cases of
an isotropic solve (``w_i`` the p-norm weights), i.e. the direction that
maximises ``sum_i w_i |sigma_i n|^2``; squaring makes it blind to the sign
of each case's stress, which a plain sum of tensors is not.
"""

from __future__ import annotations

import numpy as np

from engine.progress import report

from .assembly import grid_fe
from .design import TopOptResult, design_space
from .fe2d import q4_stiffness_basis
from .mma import MMA
from .orthotropic import ANISOTROPY, orthotropic_material, rotated_material
from .stress import element_stress

__all__ = [
    "orthotropic_material", "rotated_material", "orthotropic_orientation",
    "orientation_objective", "stress_orientation", "orientation_tensor",
]

PNORM = 8.0


def orientation_tensor(theta, anisotropy=ANISOTROPY):
    """Symmetric tensors ``R diag(a, 1) R^T`` whose principal axis is ``theta``.

    Parameters
    ----------
    theta : float cell array, radians.
    anisotropy : float, eigenvalue ratio.

    Returns
    -------
    (*theta.shape, 2, 2) float64, components in (x, y) order.
    """
    t = np.asarray(theta, dtype=np.float64)
    n = np.stack([np.cos(t), np.sin(t)], axis=-1)
    return np.eye(2) + (anisotropy - 1.0) * n[..., :, None] * n[..., None, :]


def stress_orientation(sigma, weights=None):
    """Principal direction of ``sum_i w_i sigma_i @ sigma_i`` per cell.

    Parameters
    ----------
    sigma : (n_cases, *cells, 2, 2) float64 stress tensors.
    weights : (n_cases,) float64, optional (default equal).

    Returns
    -------
    theta : float cell array, radians in (-pi/2, pi/2].
    """
    s = np.asarray(sigma, dtype=np.float64)
    w = np.ones(s.shape[0]) if weights is None else np.asarray(weights, dtype=np.float64)
    M = np.einsum("c,c...ij,c...jk->...ik", w, s, s)
    # eigenvector angle of a symmetric 2x2: tan(2 theta) = 2 m_xy / (m_xx - m_yy)
    theta = 0.5 * np.arctan2(2.0 * M[..., 0, 1], M[..., 0, 0] - M[..., 1, 1])
    return np.where(theta <= -np.pi / 2, theta + np.pi, theta)


def _element_matrices(problem, rho, theta, Kb, Q):
    ds = design_space(problem)
    scale, dscale = ds.stiffness_scale(rho)
    d, dd = rotated_material(Q, theta.reshape(-1))
    K = np.einsum("ek,kij->eij", d, Kb)
    return scale, dscale, K, np.einsum("ek,kij->eij", dd, Kb)


def orientation_objective(problem, x, theta, *, pnorm=PNORM, anisotropy=ANISOTROPY, guess=None):
    """p-norm of compliances of the oriented orthotropic design, and its gradients.

    Parameters
    ----------
    problem : Problem (2D)
    x : (n_design,) float64, density design variables.
    theta : (n_cells,) float64, orientation of every cell (radians).
    pnorm : float, ``P``.
    guess : (n_cases, n_dofs) float64, optional start for the iterative solver.

    Returns
    -------
    J : float
    dJ_dx : (n_design,) float64
    dJ_dtheta : (n_cells,) float64
    U : (n_cases, n_dofs) float64
    compliances : (n_cases,) float64
    """
    if problem.dim != 2:
        raise ValueError(f"orientation optimisation is 2D only; the problem is {problem.dim}D")
    fe, ds = grid_fe(problem), design_space(problem)
    Q = orthotropic_material(problem.young, problem.poisson, anisotropy)
    rho = ds.density(x)
    scale, dscale, K, dK = _element_matrices(problem, rho, np.asarray(theta), q4_stiffness_basis(), Q)
    U = fe.solve(element_matrices=scale[:, None, None] * K, guess=guess)
    comps = np.einsum("cd,cd->c", fe.F, U)
    cmax = comps.max()
    J = cmax * float(np.sum((comps / cmax) ** pnorm)) ** (1.0 / pnorm)
    w = (comps / J) ** (pnorm - 1.0)                               # dJ/dc_i
    ue = U[:, fe.edofs].transpose(1, 2, 0)                         # (n_cells, 8, n_cases)
    eK = np.sum(ue * (K @ ue), axis=1)                             # (n_cells, n_cases)
    edK = np.sum(ue * (dK @ ue), axis=1)
    dJ_drho = -dscale * (eK @ w)
    dJ_dtheta = -scale * (edK @ w)
    return J, ds.backward(dJ_drho), dJ_dtheta, U, comps


def orthotropic_orientation(problem, *, pnorm=PNORM, anisotropy=ANISOTROPY, max_iter=200, tol=0.01,
                            move=0.1, angle_move=0.1, theta0=None, x0=None, progress=None):
    """Optimise density and material angle for the p-norm of compliances (eq. 19).

    Parameters
    ----------
    problem : Problem, 2D, any number of load cases.
    pnorm : float, ``P`` (8 in the paper).
    anisotropy : float, stiffness ratio along / across the material axis.
    max_iter, tol : iteration cap; converged when densities change by less
        than ``tol`` and angles by less than ``tol * pi``.
    move, angle_move : MMA move limits, as fractions of each range
        (densities [0, 1], angles [-pi, pi]).
    theta0 : float cell array, optional start angles (default
        :func:`stress_orientation` of an isotropic solve of the start design).
    x0 : (n_design,) float64, optional start densities.
    progress : callable(done, total) -> bool, optional

    Returns
    -------
    TopOptResult
        ``theta`` the cell angles (radians from +x, counter-clockwise, in
        [-pi, pi]); ``objective`` J; ``history`` adds ``compliance_max``.
    """
    ds = design_space(problem)
    fe = grid_fe(problem)
    x = ds.initial() if x0 is None else np.clip(np.asarray(x0, float), 0.0, 1.0)
    if theta0 is None:
        rho = ds.density(x)
        U0 = fe.solve(ds.stiffness_scale(rho)[0])
        sig = element_stress(problem, rho, U0)
        c0 = np.einsum("cd,cd->c", fe.F, U0)
        theta = stress_orientation(sig, (c0 / c0.max()) ** (pnorm - 1.0)).reshape(-1)
    else:
        theta = np.asarray(theta0, dtype=np.float64).reshape(-1)
        if theta.size != problem.n_cells:
            raise ValueError(f"theta0 must hold one angle per cell ({problem.n_cells}); got {theta.size}")
    nx = x.size
    lower = np.concatenate([np.zeros(nx), np.full(theta.size, -np.pi)])
    upper = np.concatenate([np.ones(nx), np.full(theta.size, np.pi)])
    moves = np.concatenate([np.full(nx, move), np.full(theta.size, angle_move)])
    # angles may swing in cells where two directions are nearly as good; a
    # closer asymptote floor damps that to well under the angle tolerance.
    spacing = np.concatenate([np.full(nx, 0.01), np.full(theta.size, 0.001)])
    mma = MMA(lower, upper, move=moves, min_spacing=spacing)
    hist = {k: [] for k in ("objective", "volume", "change", "compliance_max")}
    U, converged = None, False
    dv = np.concatenate([ds.volume_weights, np.zeros(theta.size)]) / problem.volfrac
    for it in range(max_iter):
        report(progress, it, max_iter)
        J, dx, dth, U, comps = orientation_objective(problem, x, theta, pnorm=pnorm, anisotropy=anisotropy,
                                                     guess=U)
        vol = ds.volume(x)
        z = mma.step(np.concatenate([x, theta]), np.concatenate([dx, dth]), vol / problem.volfrac - 1.0, dv)
        change = max(float(np.abs(z[:nx] - x).max()), float(np.abs(z[nx:] - theta).max()) / np.pi)
        for k, v in (("objective", J), ("volume", vol), ("change", change), ("compliance_max", comps.max())):
            hist[k].append(v)
        x, theta = z[:nx], z[nx:]
        if change < tol:
            converged = True
            break
    report(progress, max_iter, max_iter)
    J, _, _, U, comps = orientation_objective(problem, x, theta, pnorm=pnorm, anisotropy=anisotropy, guess=U)
    return TopOptResult(
        problem=problem, rho=ds.density(x), x=x,
        displacements=U.reshape((problem.n_cases,) + problem.fixed.shape), compliances=comps,
        objective=J, history=hist, iterations=len(hist["objective"]), converged=converged,
        theta=theta.reshape(problem.shape), info={"anisotropy": anisotropy, "pnorm": pnorm})
