"""Preconditioned conjugate gradients on several right-hand sides at once.

Each column is an independent CG run (its own step lengths) but all columns
share every operator and preconditioner application, which then stream the
operator once for all load cases. The direction update uses the flexible
(Polak-Ribiere) formula ``beta = z_new . (r_new - r_old) / (z_old . r_old)``,
which equals the classical one for a fixed symmetric preconditioner and stays
robust when the preconditioner is only nearly symmetric (rounding in a
multigrid cycle).

Stopping. With ``energy=None`` a column stops when ``|r| <= tol |b|``. With
``energy = a`` (the column's energy at ``x = 0``, e.g. ``eps.C_base.eps |Y|``
in homogenization) it stops when the estimated relative error of the
column's energy ``a - b.x`` is below ``tol``. That error is the squared
energy-norm error ``|x - x*|_A^2 = r.A^+ r``, and
``r.A^+ r <= r.M^-1 r / lambda_min(M^-1 A)``. The smallest eigenvalue is
estimated, per column, by the smallest Ritz value of the Lanczos matrix
that CG builds from its own step lengths (``T_kk = 1/alpha_k +
beta_{k-1}/alpha_{k-1}``, ``T_k,k+1 = sqrt(beta_k)/alpha_k``); a Ritz value
approaches it from above, hence the safety factor ``ENERGY_SAFETY``. A poor
preconditioner therefore makes the iteration run longer instead of
stopping early. Energies below ``ENERGY_FLOOR`` times the largest column's
are measured against that floor (a plate has zero stiffness normal to
itself; its error can only be small relative to the other columns).

Singular, consistent systems (periodic elasticity) are fine: the right-hand
sides lie in the range of the operator, so do all residuals; ``project`` may
remove the known null-space part from each preconditioned residual.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from . import element_kernels as ek

__all__ = ["block_pcg", "PCGResult", "ENERGY_SAFETY"]

ENERGY_SAFETY = 2.0
ENERGY_FLOOR = 1e-4


@dataclass(frozen=True, eq=False)
class PCGResult:
    """Outcome of :func:`block_pcg`.

    x : (n, m) solution; iterations : int; residuals : (m,) final ``|r|/|b|``;
    errors : (m,) final values of the stopping measure; converged : bool.
    """

    x: np.ndarray
    iterations: int
    residuals: np.ndarray
    errors: np.ndarray
    converged: bool


def block_pcg(apply_A, apply_M, b, *, tol=1e-8, max_iterations=500, project=None,
              energy=None, callback=None):
    """Solve ``A x = b`` column by column with shared products.

    Parameters
    ----------
    apply_A : callable ``(u, y) -> None`` writing ``A u`` into ``y``.
    apply_M : callable ``r -> z`` (preconditioner; may return a scratch
        array, which is copied).
    b : (n, m) float64
        Right-hand sides. Columns with ``|b| == 0`` get ``x = 0``.
    tol : float
        Stopping threshold (see module doc).
    max_iterations : int
    project : callable ``z -> None`` or None
        In-place projection of preconditioned residuals (null-space removal).
    energy : (m,) float or None
        Energy at ``x = 0`` per column; switches to the energy criterion.
    callback : callable ``(iteration, errors) -> None`` or None
        Called after every iteration with the stopping measure (m,).
    """
    n, m = b.shape
    bnorm = np.sqrt(ek.column_dots(b, b, b)[0])
    live = bnorm > 0
    safe = np.where(live, bnorm, 1.0)
    x = np.zeros_like(b)
    r = b.copy()
    q = np.empty_like(b)
    z = np.array(apply_M(r), copy=True)
    if project is not None:
        project(z)
    p = z.copy()
    rz = ek.column_dots(r, z, z)[0]

    alphas, betas = [], []

    def measure(rr, rz_now, bx):
        res = np.where(live, np.sqrt(np.maximum(rr, 0.0)) / safe, 0.0)
        if energy is None:
            return res, res
        left = energy - bx
        left = np.maximum(left, ENERGY_FLOOR * np.max(np.where(live, left, 0.0)) + 1e-300)
        lam = _ritz_min(alphas, betas, live)
        err = np.where(live, ENERGY_SAFETY * np.maximum(rz_now, 0.0) / (lam * left), 0.0)
        return res, err

    rel, err = measure(bnorm ** 2, rz, np.zeros(m))
    it = 0
    while it < max_iterations and np.any(err > tol):
        apply_A(p, q)
        pq = ek.column_dots(p, q, q)[0]
        alpha = np.where(live & (pq > 0), rz / np.where(pq > 0, pq, 1.0), 0.0)
        rr, bx = ek.cg_step(x, r, p, q, alpha, b)
        alphas.append(alpha)
        it += 1
        if energy is None:
            rel, err = measure(rr, rz, bx)
            if callback is not None:
                callback(it, err)
            if not np.any(err > tol):
                break
        z[:] = apply_M(r)
        if project is not None:
            project(z)
        rz_new, zq = ek.column_dots(z, r, q)
        if energy is not None:
            rel, err = measure(rr, rz_new, bx)
            if callback is not None:
                callback(it, err)
            if not np.any(err > tol):
                break
        # r_new - r_old = -alpha q  =>  z.(r_new - r_old) = -alpha z.q
        beta = np.where(live & (rz != 0), -alpha * zq / np.where(rz != 0, rz, 1.0), 0.0)
        betas.append(beta)
        rz = rz_new
        ek.update_direction(p, z, beta)
    return PCGResult(x=x, iterations=it, residuals=rel, errors=err,
                     converged=bool(np.all(err <= tol)))


def _ritz_min(alphas, betas, live):
    """Smallest Ritz value of each column's Lanczos matrix (1 before any step)."""
    k = len(alphas)
    out = np.ones(len(live))
    if k == 0:
        return out
    a = np.array(alphas)                       # (k, m)
    b = np.array(betas[:k - 1]).reshape(k - 1, len(live))
    for c in np.flatnonzero(live):
        if np.any(a[:, c] <= 0):
            out[c] = 1e-300                    # breakdown: claim nothing
            continue
        diag = 1.0 / a[:, c]
        diag[1:] += b[:, c] / a[:-1, c]
        off = np.sqrt(np.maximum(b[:, c], 0.0)) / a[:-1, c]
        if k == 1:
            out[c] = diag[0]
        else:
            out[c] = scipy.linalg.eigvalsh_tridiagonal(
                diag, off, select="i", select_range=(0, 0))[0]
        out[c] = max(out[c], 1e-300)
    return out
