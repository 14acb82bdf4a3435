"""Stress-aware SIMP: compliance plus a p-norm of relaxed von Mises stress.

The paper's L-beam (Sec. 6.2) contrasts a compliance design with one that
minimises peak stress under the same mass. A local stress constraint per
cell needs an optimiser with thousands of constraints; here the peak is
replaced by its p-norm and blended with compliance, which keeps a single
(volume) constraint and the one-constraint MMA of :mod:`mma`::

    min_x  J = (1 - w) c / c_0 + w S / S_0,     V(rho(x)) <= volfrac
    S = (sum_{cases, cells} s_e^P)^(1/P),        s_e = rho_e^q vm(D B u_e)

``vm(D B u_e)`` is the von Mises stress of the solid phase at the cell's
strain and ``rho^q`` with ``q < p`` the "qp" relaxation (Bruggi 2008; Le et
al. 2010 use ``q = 1/2``) that lets a cell's stress vanish with its
density. ``c_0``, ``S_0`` are the values of the starting design. The
passive void cells carry no stress and are left out of ``S``.

Sensitivity (adjoint): with ``K lam = dS/du``,
``dS/drho_e = dS/ds_e q rho_e^(q-1) vm_e - lam_e . (dE_e/drho_e) K0 u_e``.
"""

from __future__ import annotations

import numpy as np

from engine.progress import report

from .assembly import grid_fe
from .design import TopOptResult, design_space
from .mma import MMA

__all__ = ["stress_aware_simp", "stress_objective", "von_mises_matrix"]

# rho is floored here inside rho^q so that q rho^(q-1) stays finite in void.
RHO_FLOOR = 1e-3


def von_mises_matrix(dim):
    """``V`` with ``vm^2 = s . V s`` for Voigt stresses (plane stress in 2D)."""
    if dim == 2:
        return np.array([[1.0, -0.5, 0.0], [-0.5, 1.0, 0.0], [0.0, 0.0, 3.0]])
    V = np.zeros((6, 6))
    V[:3, :3] = -0.5
    V[np.arange(3), np.arange(3)] = 1.0
    V[np.arange(3, 6), np.arange(3, 6)] = 3.0
    return V


def stress_objective(problem, x, *, weight=0.8, pnorm=12.0, q=0.5, scales=None, guess=None):
    """Blended objective, its gradient in ``x`` and the state it was computed at.

    Parameters
    ----------
    problem : Problem
    x : (n_design,) float64
    weight : float in [0, 1], share ``w`` of the stress term.
    pnorm : float, exponent ``P`` of the stress aggregate.
    q : float, relaxation exponent.
    scales : (c_0, S_0) or None (then the values at ``x``, i.e. J = 1).
    guess : (n_cases, n_dofs) float64, optional start for the iterative solver.

    Returns
    -------
    J : float
    dJ : (n_design,) float64
    state : dict with "U", "compliances", "pnorm" (S), "relaxed" (cells), "scales".
    """
    fe, ds = grid_fe(problem), design_space(problem)
    rho = ds.density(x)
    scale, dscale = ds.stiffness_scale(rho)
    solver = fe.factor(scale)
    U = solver.solve(guess=guess)
    comps = np.einsum("cd,cd->c", fe.F, U)
    c = float(comps.sum())
    dc = -dscale * fe.element_energy(U).sum(axis=0)

    V = von_mises_matrix(problem.dim)
    DB = fe.D @ fe.B                                              # (n_voigt, nde)
    ue = U[:, fe.edofs]                                           # (n_cases, n_cells, nde)
    sig = ue @ DB.T                                               # solid-phase stress
    vm = np.sqrt(np.maximum(np.einsum("cei,ij,cej->ce", sig, V, sig), 1e-300))
    live = (problem.passive.reshape(-1) != -1)[None, :]
    r = np.maximum(rho.reshape(-1), RHO_FLOOR)
    eta = r ** q
    s = np.where(live, eta * vm, 0.0)
    smax = s.max()
    S = smax * float(np.sum((s / smax) ** pnorm)) ** (1.0 / pnorm)
    dS_ds = np.where(live, (s / S) ** (pnorm - 1.0), 0.0)         # (n_cases, n_cells)
    # explicit part (through rho^q) and adjoint load (through u)
    deta = np.where(rho.reshape(-1) > RHO_FLOOR, q * r ** (q - 1.0), 0.0)
    dS = np.sum(dS_ds * deta * vm, axis=0)
    w_e = dS_ds * eta / vm                                        # (n_cases, n_cells)
    g_e = (w_e[..., None] * (sig @ V)) @ DB                       # (n_cases, n_cells, nde)
    G = np.zeros_like(U)
    for k in range(U.shape[0]):
        G[k] = np.bincount(fe.edofs.ravel(), weights=g_e[k].ravel(), minlength=fe.n_dofs)
    lam = solver.solve(G)
    lam_e = lam[:, fe.edofs]
    dS -= dscale * np.sum(np.einsum("cei,ij,cej->ce", lam_e, fe.Ke, ue), axis=0)

    c0, S0 = (c, S) if scales is None else scales
    J = (1.0 - weight) * c / c0 + weight * S / S0
    dJ = (1.0 - weight) * dc / c0 + weight * dS / S0
    state = {"U": U, "compliances": comps, "pnorm": S, "relaxed": s.reshape((-1,) + problem.shape),
             "scales": (c0, S0)}
    return J, ds.backward(dJ), state


def stress_aware_simp(problem, *, weight=0.8, pnorm=12.0, q=0.5, max_iter=300, tol=0.01, move=0.1,
                      x0=None, progress=None):
    """Optimise ``problem`` for the blended compliance / p-norm stress objective.

    Parameters
    ----------
    problem : Problem
    weight : float in [0, 1]
        Share of the stress term (0 is plain compliance, 1 pure p-norm stress).
    pnorm, q : float
        Aggregation and relaxation exponents (module notes).
    max_iter, tol, move : MMA iteration cap, max-change tolerance and move limit.
    x0 : (n_design,) float64, optional start (default uniform at volfrac).
    progress : callable(done, total) -> bool, optional

    Returns
    -------
    TopOptResult
        ``history`` adds ``compliance`` and ``stress_pnorm``; ``info`` holds
        the normalising ``scales`` (c_0, S_0).
    """
    if not 0.0 <= weight <= 1.0:
        raise ValueError(f"weight must lie in [0, 1]; got {weight!r}")
    if not 0.0 < q <= problem.penal:
        raise ValueError(f"q must lie in (0, penal={problem.penal}]; got {q!r}")
    ds = design_space(problem)
    x = ds.initial() if x0 is None else np.clip(np.asarray(x0, float), 0.0, 1.0)
    mma = MMA(np.zeros_like(x), np.ones_like(x), move=move)
    hist = {k: [] for k in ("objective", "volume", "change", "compliance", "stress_pnorm")}
    scales, U, converged = None, None, False
    for it in range(max_iter):
        report(progress, it, max_iter)
        J, dJ, st = stress_objective(problem, x, weight=weight, pnorm=pnorm, q=q, scales=scales, guess=U)
        scales, U = st["scales"], st["U"]
        vol = ds.volume(x)
        x_new = mma.step(x, dJ, vol / problem.volfrac - 1.0, ds.volume_weights / problem.volfrac)
        change = float(np.abs(x_new - x).max())
        for k, v in (("objective", J), ("volume", vol), ("change", change),
                     ("compliance", float(st["compliances"].sum())), ("stress_pnorm", st["pnorm"])):
            hist[k].append(v)
        x = x_new
        if change < tol:
            converged = True
            break
    report(progress, max_iter, max_iter)
    J, _, st = stress_objective(problem, x, weight=weight, pnorm=pnorm, q=q, scales=scales, guess=U)
    return TopOptResult(
        problem=problem, rho=ds.density(x), x=x,
        displacements=st["U"].reshape((problem.n_cases,) + problem.fixed.shape),
        compliances=st["compliances"], objective=J, history=hist, iterations=len(hist["objective"]),
        converged=converged, info={"scales": scales, "stress_pnorm": st["pnorm"]})
