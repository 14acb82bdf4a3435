"""Assembly and solution of the grid's linear elastic system.

:class:`GridFE` is built once per problem: it holds the element dof table,
the solid element stiffness and the sparsity pattern of the reduced (free
dof) matrix, with ``slot[k]`` telling which stored entry the ``k``-th kept
element entry adds into. Each design iteration then only forms the entry
values (one scatter, :mod:`._kernels`) and factors or sets up multigrid.

Solvers: up to ``DIRECT_DOFS`` free dofs, SuperLU with the minimum-degree
ordering of ``A^T + A`` in symmetric mode (the matrix is SPD; about twice
as fast as the default COLAMD ordering here); above, multigrid-preconditioned
CG (:mod:`mgcg`), warm-started from the previous design's displacements,
which is ~6x faster than SuperLU on the 160 x 80 cantilever and ~40x on a
48 x 16 x 16 MBB (tests/bench/bench_topopt.py). All load cases share one
factorisation or one multigrid set-up.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from engine.physics.elastic import isotropic_plane_stress, isotropic_stiffness

from .fe2d import element_dofs_2d, q4_centre_strain, q4_stiffness
from ._kernels import scatter_scaled
from .mgcg import MultigridHierarchy
from .fe3d import element_dofs_3d, h8_centre_strain, h8_stiffness

__all__ = ["GridFE", "GridSolver", "grid_fe", "DIRECT_DOFS", "LU_OPTIONS"]

# Largest reduced system solved by SuperLU under method="auto" (measured
# crossover with multigrid CG on the 2-core CI machine, tests/bench/bench_topopt.py).
DIRECT_DOFS = {2: 4000, 3: 2000}
LU_OPTIONS = dict(permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})


class GridFE:
    """Finite-element operators of a problem's grid (no design state).

    Parameters
    ----------
    problem : Problem

    Attributes
    ----------
    edofs : (n_cells, nde) int64, global dofs of each cell (cells row-major).
    Ke : (nde, nde) float64, solid isotropic element stiffness (``young``).
    D : (n_voigt, n_voigt) float64, solid constitutive matrix.
    B : (n_voigt, nde) float64, centre strain operator.
    free : (n_free,) int64, unsupported dofs.
    F : (n_cases, n_dofs) float64, load vectors.
    """

    def __init__(self, problem):
        self.shape = problem.shape
        self.dim = problem.dim
        self.n_dofs = problem.n_dofs
        if self.dim == 2:
            self.edofs = element_dofs_2d(*self.shape)
            self.D = isotropic_plane_stress(problem.young, problem.poisson)
            self.Ke = q4_stiffness(self.D)
            self.B = q4_centre_strain(problem.h)
        else:
            self.edofs = element_dofs_3d(*self.shape)
            self.D = isotropic_stiffness(problem.young, problem.poisson)
            self.Ke = h8_stiffness(problem.young, problem.poisson, problem.h)
            self.B = h8_centre_strain(problem.h)
        self.nde = self.edofs.shape[1]
        fixed = problem.fixed.reshape(-1)
        self.free = np.flatnonzero(~fixed)
        self.F = problem.loads.reshape(problem.n_cases, -1).copy()
        self._pattern(fixed)
        self._mg = None

    def _pattern(self, fixed):
        reduced = np.full(self.n_dofs, -1, np.int64)
        reduced[self.free] = np.arange(self.free.size)
        r = reduced[self.edofs]                                       # (n_cells, nde)
        rows = np.repeat(r, self.nde, axis=1).ravel()
        cols = np.tile(r, (1, self.nde)).ravel()
        keep = (rows >= 0) & (cols >= 0)
        self._keep = np.flatnonzero(keep)
        n = self.free.size
        key = rows[keep] * n + cols[keep]
        uniq, self._slot = np.unique(key, return_inverse=True)
        self._indices = (uniq % n).astype(np.int32)
        counts = np.bincount(uniq // n, minlength=n)
        self._indptr = np.concatenate([[0], np.cumsum(counts)]).astype(np.int32)
        self._n_entries = uniq.size

    def matrix(self, scale=None, element_matrices=None):
        """Reduced stiffness over the free dofs, CSR.

        Parameters
        ----------
        scale : (n_cells,) float64, optional
            Factor on the solid element stiffness of each cell.
        element_matrices : (n_cells, nde, nde) float64, optional
            Per-cell stiffness (e.g. an oriented orthotropic law) instead.
        """
        if element_matrices is None:
            data = scatter_scaled(self._keep, self._slot, np.ascontiguousarray(scale, dtype=np.float64),
                                  self.Ke.ravel(), self._n_entries)
        else:
            values = np.asarray(element_matrices).reshape(-1)
            data = np.bincount(self._slot, weights=values[self._keep], minlength=self._n_entries)
        n = self.free.size
        return sp.csr_matrix((data, self._indices, self._indptr), shape=(n, n))

    def factor(self, scale=None, element_matrices=None, *, method="auto", rtol=1e-6):
        """A solver for the reduced stiffness (factored or multigrid set up once).

        Parameters
        ----------
        scale, element_matrices : see :meth:`matrix`.
        method : {"auto", "direct", "mgcg"}
            "auto" factors directly up to ``DIRECT_DOFS`` free dofs, else
            multigrid-preconditioned CG (:mod:`mgcg`).
        rtol : float, relative residual of the iterative solver.

        Returns
        -------
        GridSolver
        """
        if method not in ("auto", "direct", "mgcg"):
            raise ValueError(f"method must be 'auto', 'direct' or 'mgcg'; got {method!r}")
        if method == "auto":
            method = "direct" if self.free.size <= DIRECT_DOFS[self.dim] else "mgcg"
        return GridSolver(self, self.matrix(scale, element_matrices), method, rtol)

    def solve(self, scale=None, element_matrices=None, loads=None, guess=None, *, method="auto", rtol=1e-6):
        """Displacements of every load case (see :meth:`factor` and :meth:`GridSolver.solve`)."""
        return self.factor(scale, element_matrices, method=method, rtol=rtol).solve(loads, guess)

    def multigrid(self):
        """The :class:`MultigridHierarchy` of this grid (built on first use)."""
        if self._mg is None:
            self._mg = MultigridHierarchy(self.shape, self.free)
        return self._mg

    def element_energy(self, U, Ke=None):
        """``u_e^T Ke u_e`` per cell and load case, (n_cases, n_cells)."""
        Ke = self.Ke if Ke is None else Ke
        ue = U[:, self.edofs]                                         # (n_cases, n_cells, nde)
        return np.sum((ue @ Ke) * ue, axis=-1)


class GridSolver:
    """Solves ``K u = f`` for one assembled stiffness, any number of times."""

    def __init__(self, fe, A, method, rtol):
        self.fe, self.A, self.method, self.rtol = fe, A, method, rtol
        if method == "direct":
            self._lu = spla.splu(A.tocsc(), **LU_OPTIONS)
        else:
            self._mg = fe.multigrid()
            self._ops = self._mg.setup(A)

    def solve(self, loads=None, guess=None):
        """Displacements for the given nodal loads.

        Parameters
        ----------
        loads : (n_cases, n_dofs) float64, optional; default the problem's loads.
            Entries on supported dofs are ignored (reactions).
        guess : (n_cases, n_dofs) float64, optional start for the iterative solver.

        Returns
        -------
        U : (n_cases, n_dofs) float64, zero on supported dofs.
        """
        fe = self.fe
        F = fe.F if loads is None else np.atleast_2d(loads)
        U = np.zeros((F.shape[0], fe.n_dofs))
        if self.method == "direct":
            U[:, fe.free] = self._lu.solve(np.ascontiguousarray(F[:, fe.free].T)).T
            return U
        x0 = None if guess is None else np.ascontiguousarray(guess[:, fe.free].T)
        X, _ = self._mg.solve(self.A, np.ascontiguousarray(F[:, fe.free].T), x0, rtol=self.rtol, ops=self._ops)
        U[:, fe.free] = X.T
        return U


def grid_fe(problem):
    """The :class:`GridFE` of ``problem``, built once and kept on the problem."""
    fe = problem._cache.get("fe")
    if fe is None:
        fe = problem._cache["fe"] = GridFE(problem)
    return fe
