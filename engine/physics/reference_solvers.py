"""Slow, straightforward homogenization solvers for tests and benchmarks.

* :func:`homogenize_direct` assembles the global periodic stiffness with
  scipy.sparse (every grid node, every element with nonzero modulus) and
  solves the six load cases directly: ``"lu"`` pins the three translations
  at one node and uses SuperLU (needs a cell without floating pieces or
  hinges, e.g. all densities > 0), ``"pinv"`` takes the dense symmetric
  eigen-decomposition pseudo-inverse (any cell, a few thousand dofs at most).
* :func:`homogenize_baseline` is the homo3D-style method the fast solver is
  benchmarked against: all voxels are elements, void gets ``1e-6 E``, the
  assembled matrix is solved by Jacobi-preconditioned CG one load case at a
  time (scipy), unpinned (the loads are consistent).

Conventions are those of :mod:`periodic_fe`: array axis ``a`` is direction
``a``, Voigt order with engineering shear, unit voxels, C from the energy.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .hex_element import element_matrices, isotropic_stiffness, plane_stress_stiffness

__all__ = ["assemble_periodic", "homogenize_direct", "homogenize_baseline"]

_CHUNK = 1 << 15


def _materials(dim, nu):
    D_of = isotropic_stiffness if dim == 3 else plane_stress_stiffness
    return [D_of(1.0, nu), D_of(1.0, 0.0)]


def assemble_periodic(moduli, groups, nu):
    """Global periodic stiffness and unit-strain loads (internal E = 1).

    Parameters
    ----------
    moduli : (n0, n1[, n2]) float
        Young's modulus of each element, 0 = no element.
    groups : int array, same shape
        0 = Poisson ratio ``nu``, 1 = Poisson ratio 0 (soft void).
    nu : float

    Returns
    -------
    K : (n_dof, n_dof) scipy.sparse.csr_matrix over all grid nodes
    F : (n_dof, n_voigt) ndarray
    A0 : (n_voigt, n_voigt) ndarray, ``sum_e |e| D_e``
    """
    shape = moduli.shape
    dim = len(shape)
    Ds = _materials(dim, nu)
    mats = [element_matrices(D, dim) for D in Ds]
    nen, nde = 2 ** dim, 2 ** dim * dim
    elems = np.argwhere(moduli > 0)
    n = int(np.prod(shape)) * dim
    F = np.zeros((n, Ds[0].shape[0]))
    A0 = np.zeros_like(Ds[0])
    K = sp.csr_matrix((n, n))
    for g in (0, 1):
        sel_g = elems[groups[tuple(elems.T)] == g]
        A0 += Ds[g] * moduli[tuple(sel_g.T)].sum()
        Ke, Fe = mats[g]
        # Chunks keep the COO triplets of a 64^3 grid well under a gigabyte.
        for start in range(0, len(sel_g), _CHUNK):
            sel = sel_g[start:start + _CHUNK]
            s = moduli[tuple(sel.T)]
            dofs = np.empty((len(sel), nde), dtype=np.int64)
            for l in range(nen):
                bits = np.array([(l >> a) & 1 for a in range(dim)])
                node = np.ravel_multi_index(tuple(((sel + bits) % shape).T), shape)
                for a in range(dim):
                    dofs[:, l * dim + a] = node * dim + a
            rows = np.repeat(dofs, nde, axis=1).ravel().astype(np.int32)
            cols = np.tile(dofs, (1, nde)).ravel().astype(np.int32)
            vals = (s[:, None, None] * Ke[None]).ravel()
            K = K + sp.coo_matrix((vals, (rows, cols)), shape=(n, n)).tocsr()
            np.add.at(F, dofs.ravel(), (s[:, None, None] * Fe[None]).reshape(-1, Fe.shape[1]))
    return K, F, A0


def _energy_C(K, F, U, A0, volume):
    FU = F.T @ U
    C = (A0 - FU - FU.T + U.T @ (K @ U)) / volume
    return 0.5 * (C + C.T)


def homogenize_direct(density, *, E=1.0, nu=0.45, void_modulus=0.0, method="pinv"):
    """Homogenized stiffness by a direct solve (see module doc).

    Parameters
    ----------
    density : (n0, n1[, n2]) float in [0, 1]; axis ``a`` = direction ``a``.
    E, nu, void_modulus : as in :func:`homogenize_voxels`.
    method : {"pinv", "lu"}

    Returns
    -------
    C : (n_voigt, n_voigt) float64
    """
    density = np.asarray(density, dtype=np.float64)
    moduli = np.where(density > 0, density, void_modulus)
    groups = (density == 0).astype(np.int64)
    K, F, A0 = assemble_periodic(moduli, groups, nu)
    active = np.flatnonzero(K.diagonal() > 0)
    Ka = K[active][:, active]
    Fa = F[active]
    if method == "pinv":
        w, V = np.linalg.eigh(Ka.toarray())
        keep = w > 1e-10 * w.max()
        Ua = V[:, keep] @ ((V[:, keep].T @ Fa) / w[keep, None])
    elif method == "lu":
        dim = density.ndim
        free = np.ones(len(active), dtype=bool)
        free[:dim] = False          # the first active node's components
        Kf = Ka[free][:, free].tocsc()
        Ua = np.zeros_like(Fa)
        Ua[free] = spla.splu(Kf).solve(Fa[free])
    else:
        raise ValueError(f"method must be 'pinv' or 'lu'; got {method!r}")
    C = _energy_C(Ka, Fa, Ua, A0, density.size)
    return C * E


def homogenize_baseline(density, *, E=1.0, nu=0.45, void_ratio=1e-6, rtol=1e-6,
                        max_iterations=20000, callback=None):
    """homo3D-style homogenization: all voxels, soft void, Jacobi-PCG per load case.

    Parameters
    ----------
    density : (n0, n1[, n2]) float in [0, 1]
        Density 0 voxels get ``void_ratio * E`` with the same ``nu``.
    rtol : float
        scipy CG relative residual per load case.
    callback : callable ``(case, iterations) -> None`` or None

    Returns
    -------
    C : (n_voigt, n_voigt) float64
    info : dict with ``iterations`` (list per case) and ``seconds``
    """
    t0 = time.perf_counter()
    density = np.asarray(density, dtype=np.float64)
    moduli = np.where(density > 0, density, void_ratio)
    K, F, A0 = assemble_periodic(moduli, np.zeros(density.shape, dtype=np.int64), nu)
    dinv = 1.0 / K.diagonal()
    M = spla.LinearOperator(K.shape, matvec=lambda v: dinv * v, dtype=np.float64)
    U = np.zeros_like(F)
    iterations = []
    for i in range(F.shape[1]):
        count = [0]

        def cb(_xk, count=count):
            count[0] += 1
        if np.linalg.norm(F[:, i]) > 0:
            U[:, i], _ = spla.cg(K, F[:, i], rtol=rtol, maxiter=max_iterations, M=M,
                                 callback=cb)
        iterations.append(count[0])
        if callback is not None:
            callback(i, count[0])
    C = _energy_C(K, F, U, A0, density.size) * E
    return C, {"iterations": iterations, "seconds": time.perf_counter() - t0}

