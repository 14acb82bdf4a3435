"""Minimum-compliance SIMP with a density filter and the optimality-criteria update.

Problem (one or several load cases, summed)::

    min_x  c(x) = sum_i f_i . u_i      K(rho(x)) u_i = f_i
    s.t.   V(rho(x)) <= volfrac,  0 <= x <= 1

with ``rho = H x`` (:mod:`density_filter`) and the modified SIMP stiffness
``E(rho) = young (e_min + (1 - e_min) rho^p)``. Because ``K`` is linear in
the cell stiffness and ``u_i`` is in equilibrium, the adjoint of the
compliance is the displacement itself and
``dc/drho_e = -dE_e/drho_e * sum_i u_ie . K0 u_ie`` (``K0`` the solid
element, per unit ``young``).

Optimality criteria: at a KKT point ``-dc/dx_e = lambda dV/dx_e`` on every
cell between its bounds, so each step rescales ``x_e`` by
``B_e^eta = (-dc/dx_e / (lambda dV/dx_e))^eta`` (``eta = 1/2``), clipped to a
move limit and to [0, 1], with the multiplier ``lambda`` found by bisection
so that the new design meets the volume exactly. The volume is linear in
``x`` here, so each bisection step costs one dot product.
"""

from __future__ import annotations

import numpy as np

from engine.progress import report

from .assembly import grid_fe
from .design import TopOptResult, design_space

__all__ = ["simp_compliance", "compliance_and_gradient", "oc_update"]

STALL_WINDOW = 10


def compliance_and_gradient(problem, x, guess=None):
    """Total compliance and its gradient in the design variables.

    Parameters
    ----------
    problem : Problem
    x : (n_design,) float64
        Design variables (design cells, row-major).
    guess : (n_cases, n_dofs) float64, optional
        Start for the iterative solver (the previous iteration's ``U``).

    Returns
    -------
    c : float, ``sum_i f_i . u_i``
    dc : (n_design,) float64
    U : (n_cases, n_dofs) float64, displacements
    compliances : (n_cases,) float64
    """
    fe, ds = grid_fe(problem), design_space(problem)
    rho = ds.density(x)
    scale, dscale = ds.stiffness_scale(rho)
    U = fe.solve(scale, guess=guess)
    energy = fe.element_energy(U)                                  # (n_cases, n_cells)
    compliances = np.einsum("cd,cd->c", fe.F, U)
    dc_drho = -dscale * energy.sum(axis=0)
    return float(compliances.sum()), ds.backward(dc_drho), U, compliances


def oc_update(x, dc, dv, target, *, move=0.2, eta=0.5):
    """One optimality-criteria step.

    Parameters
    ----------
    x : (n,) float64, current design in [0, 1].
    dc : (n,) float64, objective gradient (non-positive for compliance).
    dv : (n,) float64, positive gradient of the (linear) volume.
    target : float, required ``dv @ x_new``.
    move : float, largest change of any ``x_e``.
    eta : float, damping exponent.

    Returns
    -------
    x_new : (n,) float64
    """
    lo = np.maximum(0.0, x - move)
    hi = np.minimum(1.0, x + move)
    ratio = np.maximum(-dc, 0.0) / dv
    positive = ratio[ratio > 0]
    if positive.size == 0:                       # no gradient: keep the volume, stay put
        return np.clip(x * target / max(dv @ x, 1e-300), lo, hi)
    # log-bisection on the multiplier; the volume decreases as it grows.
    a = np.log(positive.min()) - 40.0
    b = np.log(positive.max()) + 40.0
    for _ in range(100):
        mid = 0.5 * (a + b)
        x_new = np.clip(x * (ratio * np.exp(-mid)) ** eta, lo, hi)
        if dv @ x_new > target:
            a = mid
        else:
            b = mid
        if b - a < 1e-13:
            break
    return np.clip(x * (ratio * np.exp(-0.5 * (a + b))) ** eta, lo, hi)


def simp_compliance(problem, *, max_iter=200, tol=0.01, move=0.2, ftol=None, x0=None, progress=None):
    """Optimise the density field of ``problem`` for minimum compliance.

    Parameters
    ----------
    problem : Problem
    max_iter : int
        Upper bound on design iterations.
    tol : float
        Converged when the largest change of a design variable is below this.
    move : float
        OC move limit.
    ftol : float, optional
        Also stop (``info["stop"] == "stall"``, ``converged`` stays False)
        once the objective changed by less than ``ftol`` (relative) over the
        last ``STALL_WINDOW`` iterations: the max-change test is strict and
        the last per mille of compliance can take a hundred iterations.
    x0 : (n_design,) float64, optional
        Starting design (default: uniform at the volume fraction).
    progress : callable(done, total) -> bool, optional
        Called once per iteration; ``False`` raises
        :class:`engine.progress.Cancelled`.

    Returns
    -------
    TopOptResult
        ``objective`` is the summed compliance; ``history`` has
        ``objective``, ``volume`` and ``change``.
    """
    ds = design_space(problem)
    x = ds.initial() if x0 is None else np.clip(np.asarray(x0, float), 0.0, 1.0)
    if x.shape != (ds.n_design,):
        raise ValueError(f"x0 must have one value per design cell, shape ({ds.n_design},); got {x.shape}")
    hist = {"objective": [], "volume": [], "change": []}
    converged, stop = False, "max_iter"
    U = None
    for it in range(max_iter):
        report(progress, it, max_iter)
        c, dc, U, comps = compliance_and_gradient(problem, x, U)
        x_new = oc_update(x, dc, ds.volume_weights, ds.target, move=move)
        change = float(np.abs(x_new - x).max())
        hist["objective"].append(c)
        hist["volume"].append(ds.volume(x))
        hist["change"].append(change)
        x = x_new
        if change < tol:
            converged, stop = True, "change"
            break
        if ftol is not None and it >= STALL_WINDOW:
            old = hist["objective"][-1 - STALL_WINDOW]
            if abs(old - c) <= ftol * abs(c):
                stop = "stall"
                break
    report(progress, max_iter, max_iter)
    # Report the state of the final design, not the one before the last step.
    c, _, U, comps = compliance_and_gradient(problem, x, U)
    return TopOptResult(
        problem=problem, rho=ds.density(x), x=x,
        displacements=U.reshape((problem.n_cases,) + problem.fixed.shape),
        compliances=comps, objective=c, history=hist, iterations=len(hist["objective"]),
        converged=converged, info={"stop": stop})
