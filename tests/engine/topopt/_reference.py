"""Slow, obviously-correct reference implementations written for the tests.

Nothing here imports engine.topopt's kernels: the element matrix comes from
numerical Gauss quadrature, the global matrix from explicit loops, the
filter from a double loop over cells, and the design update from a plain
bisection on the Lagrange multiplier. Only the documented conventions are
shared (node ``ix + (nelx + 1) iy``, dof ``2 node + a``, local nodes
(0, 0), (1, 0), (0, 1), (1, 1)).
"""

import math

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

LOCAL = [(0, 0), (1, 0), (0, 1), (1, 1)]


def plane_stress(E, nu):
    k = E / (1 - nu * nu)
    return np.array([[k, k * nu, 0], [k * nu, k, 0], [0, 0, k * (1 - nu) / 2]])


def gauss_q4(D, n_gauss=2):
    """8x8 stiffness of the unit square by Gauss-Legendre quadrature (explicit loops)."""
    pts, wts = np.polynomial.legendre.leggauss(n_gauss)
    pts, wts = 0.5 * (pts + 1), 0.5 * wts                 # map to [0, 1]
    K = np.zeros((8, 8))
    for gx, wx in zip(pts, wts):
        for gy, wy in zip(pts, wts):
            B = np.zeros((3, 8))
            for l, (bx, by) in enumerate(LOCAL):
                fx = gx if bx else 1 - gx
                fy = gy if by else 1 - gy
                dx = (1 if bx else -1) * fy
                dy = (1 if by else -1) * fx
                B[0, 2 * l] = dx
                B[1, 2 * l + 1] = dy
                B[2, 2 * l] = dy
                B[2, 2 * l + 1] = dx
            K += wx * wy * B.T @ D @ B
    return K


def element_dofs(nely, nelx):
    out = []
    for iy in range(nely):
        for ix in range(nelx):
            dofs = []
            for bx, by in LOCAL:
                n = (iy + by) * (nelx + 1) + ix + bx
                dofs += [2 * n, 2 * n + 1]
            out.append(dofs)
    return out


def filter_matrix(nely, nelx, rmin):
    """Row-normalised cone filter by a double loop over cells (no passive cells)."""
    n = nely * nelx
    rows, cols, vals = [], [], []
    for iy in range(nely):
        for ix in range(nelx):
            e = iy * nelx + ix
            for jy in range(nely):
                for jx in range(nelx):
                    d = math.hypot(ix - jx, iy - jy)
                    if d < rmin:
                        rows.append(e)
                        cols.append(jy * nelx + jx)
                        vals.append(rmin - d)
    H = sp.csr_matrix((vals, (rows, cols)), shape=(n, n))
    return sp.diags(1 / np.asarray(H.sum(axis=1)).ravel()) @ H


def dense_compliance(problem, x_cells):
    """Compliance and d c / d x (design variable on every cell) by dense linear algebra.

    ``x_cells`` : (nely, nelx) design variables; requires no passive cells.
    """
    nely, nelx = problem.shape
    assert not problem.passive.any()
    Ke = gauss_q4(plane_stress(problem.young, problem.poisson), 3)
    edofs = element_dofs(nely, nelx)
    H = filter_matrix(nely, nelx, problem.rmin).toarray()
    rho = H @ x_cells.ravel()
    ndof = 2 * (nely + 1) * (nelx + 1)
    K = np.zeros((ndof, ndof))
    emin, p = problem.young_min, problem.penal
    for e, dofs in enumerate(edofs):
        E = emin + (1 - emin) * rho[e] ** p
        for i in range(8):
            for j in range(8):
                K[dofs[i], dofs[j]] += E * Ke[i, j]
    free = [d for d in range(ndof) if not problem.fixed.reshape(-1)[d]]
    c, dc_rho = 0.0, np.zeros(nely * nelx)
    for f in problem.loads.reshape(problem.n_cases, -1):
        u = np.zeros(ndof)
        u[free] = np.linalg.solve(K[np.ix_(free, free)], f[free])
        c += f @ u
        for e, dofs in enumerate(edofs):
            ue = u[dofs]
            dc_rho[e] -= p * (1 - emin) * rho[e] ** (p - 1) * ue @ Ke @ ue
    return c, H.T @ dc_rho


def reference_simp(problem, *, max_iter=200, tol=0.01, move=0.2):
    """Straightforward SIMP: loop-built assembly indices, sparse solve, OC by bisection.

    Returns (rho cells, compliance, iterations).
    """
    nely, nelx = problem.shape
    assert not problem.passive.any()
    Ke = gauss_q4(plane_stress(problem.young, problem.poisson))
    edofs = np.array(element_dofs(nely, nelx))
    rows = np.repeat(edofs, 8, axis=1).ravel()
    cols = np.tile(edofs, (1, 8)).ravel()
    H = filter_matrix(nely, nelx, problem.rmin)
    ndof = 2 * (nely + 1) * (nelx + 1)
    free = np.flatnonzero(~problem.fixed.reshape(-1))
    F = problem.loads.reshape(problem.n_cases, -1)
    emin, p, vf = problem.young_min, problem.penal, problem.volfrac
    x = np.full(nely * nelx, vf)
    for it in range(max_iter):
        rho = H @ x
        E = emin + (1 - emin) * rho ** p
        K = sp.coo_matrix((np.kron(E, Ke.ravel()), (rows, cols)), shape=(ndof, ndof)).tocsc()
        Kf = K[free][:, free]
        c, dc = 0.0, np.zeros_like(x)
        for f in F:
            u = np.zeros(ndof)
            u[free] = spla.spsolve(Kf, f[free])
            c += f @ u
            ue = u[edofs]
            dc -= p * (1 - emin) * rho ** (p - 1) * np.einsum("ei,ij,ej->e", ue, Ke, ue)
        dc = H.T @ dc
        dv = H.T @ np.ones_like(x)
        lo, hi = 1e-12, 1e12
        while hi / lo > 1 + 1e-10:
            lam = math.sqrt(lo * hi)
            xn = np.clip(x * np.sqrt(-dc / (lam * dv)), np.maximum(0, x - move), np.minimum(1, x + move))
            if (H @ xn).mean() > vf:
                lo = lam
            else:
                hi = lam
        change = np.abs(xn - x).max()
        x = xn
        if change < tol:
            break
    rho = H @ x
    E = emin + (1 - emin) * rho ** p
    K = sp.coo_matrix((np.kron(E, Ke.ravel()), (rows, cols)), shape=(ndof, ndof)).tocsc()
    c = 0.0
    for f in F:
        u = np.zeros(ndof)
        u[free] = spla.spsolve(K[free][:, free], f[free])
        c += f @ u
    return rho.reshape(nely, nelx), c, it + 1
