"""Geometric multigrid with Galerkin coarse operators on periodic voxel grids.

Coarsening halves every axis of at least 4 elements (an odd axis ends with
one coarse element spanning 3 fine ones; a shorter axis is kept). Each fine
element then lies inside exactly one coarse element and its nodes
interpolate multilinearly from that coarse element's nodes, so with ``P``
the periodic multilinear interpolation the Galerkin operator ``P^T A P`` is
again element-by-element: coarse element ``E`` gets
``sum_{children c} P_c^T K_c P_c`` with ``P_c`` a fixed (2^dim*d)^2 matrix set
by the child's position inside ``E``. On the first coarsening the children
are ``sum_g scales[g, c] K0[g]`` and the coarse matrix is
``sum_c sum_g scales[g, c] M[g, pos_c]`` with ``M = P^T K0 P`` precomputed;
deeper levels form the triple products directly.

The V-cycle uses damped node-block Jacobi smoothing and a dense Cholesky
solve on the coarsest level, in float32 except the coarsest solve (it is
only a preconditioner; the outer CG is float64). The damping is ``omega = SMOOTHING / lambda``
with ``lambda`` an upper estimate of the largest eigenvalue of ``D^-1 A``:
on the fine level the rigorous element bound
``max eig(blockdiag(K0)^-1 K0)`` (``x.Ax = sum_e x_e.K_e x_e <=
lambda_e sum_e x_e.D_e x_e = lambda_e x.Dx``), on coarse levels a few power
iterations times a safety factor. (A fixed omega diverges for nu near 0.5,
where lambda exceeds 4.) The periodic operator is singular (rigid
translations, possibly hinge mechanisms of corner-connected voxels); its
right-hand sides lie in its range, so the coarsest matrix is regularised by
a relative 1e-10 shift, which only perturbs the (irrelevant) null-space part.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field

import numba
import numpy as np
import scipy.linalg
from numba import njit, prange

from . import element_kernels as ek
from .voxel_mesh import VoxelMesh, build_mesh

__all__ = ["Level", "Hierarchy", "build_hierarchy"]

# (m, c): an axis where one coarse element spans m fine ones and the child is
# the c-th of them. Codes index the position tables below.
_AXIS_CODES = {(1, 0): 0, (2, 0): 1, (2, 1): 2, (3, 0): 3, (3, 1): 4, (3, 2): 5}
_CODE_T0 = np.array([0.0, 0.0, 0.5, 0.0, 1 / 3, 2 / 3])   # child's lower node position
_CODE_DT = np.array([1.0, 0.5, 0.5, 1 / 3, 1 / 3, 1 / 3])  # child's length / coarse length
SERIAL_ELEMENTS = 65536
SMOOTHING = 4.0 / 3.0      # omega * lambda_max of the Jacobi sweeps
POWER_STEPS = 8
POWER_SAFETY = 1.1


@dataclass
class Level:
    """One grid level: mesh, operator, smoother data and transfer to the next.

    ``kind == "scaled"`` uses ``K0`` (G, nde, nde) and ``scales`` (G, n_elem):
    element ``e`` is ``sum_g scales[g, e] K0[g]``; ``"explicit"`` uses ``Ke``.
    ``p_idx, p_w`` (n_nodes, 2**dim) interpolate this level's nodes from the
    next coarser level; ``r_ptr, r_idx, r_w`` are the same weights grouped by
    coarse node (for ``P^T``).
    """

    mesh: VoxelMesh
    d: int
    kind: str
    K0: np.ndarray = None
    scales: np.ndarray = None
    Ke: np.ndarray = None
    dinv: np.ndarray = None
    omega: float = None
    p_idx: np.ndarray = None
    p_w: np.ndarray = None
    r_ptr: np.ndarray = None
    r_idx: np.ndarray = None
    r_w: np.ndarray = None

    @property
    def n_dof(self):
        return self.mesh.n_nodes * self.d

    @property
    def serial(self):
        """Small levels run on one thread: a barrier costs more than the work."""
        return self.mesh.n_elem < SERIAL_ELEMENTS

    def kernels(self, nrhs):
        return ek.get_kernels(self.mesh.dim, nrhs)

    def matvec(self, u, y):
        m = self.mesh
        k = ek.get_kernels(m.dim, u.shape[1])
        if self.kind == "scaled":
            k.matvec_scaled(self.K0, self.scales, m.elem_nodes, m.elem_ptr, m.node_ptr, u, y)
        else:
            k.matvec_explicit(self.Ke, m.elem_nodes, m.elem_ptr, m.node_ptr, u, y)

    def block_diagonal(self):
        m = self.mesh
        if self.kind == "scaled":
            return ek.block_diagonal_scaled(self.K0, self.scales, m.elem_nodes, m.n_nodes)
        return ek.block_diagonal_explicit(self.Ke, m.elem_nodes, m.n_nodes)

    def element_matrices(self):
        """(n_elem, nde, nde) explicit element matrices (small levels only)."""
        if self.kind == "scaled":
            return np.einsum("ge,gij->eij", self.scales, self.K0)
        return self.Ke


# ------------------------------------------------------------------ geometry

def _axis_map(n):
    """Coarse count and, per fine index, coarse element, child code, lower t."""
    if n < 4:
        idx = np.arange(n)
        return n, idx, np.zeros(n, dtype=np.int64), np.zeros(n)
    nc = n // 2
    coarse = np.minimum(np.arange(n) // 2, nc - 1)
    c = np.arange(n) - 2 * coarse
    m = np.where(coarse == nc - 1, n - 2 * (nc - 1), 2)
    code = np.array([_AXIS_CODES[(int(mm), int(cc))] for mm, cc in zip(m, c)])
    return nc, coarse, code, c / m


def _node_interpolation(dim, combo):
    """(2**dim, 2**dim) weights of a child's nodes on its parent's nodes."""
    nen = 2 ** dim
    codes = [(combo // 6 ** a) % 6 for a in range(dim)]
    Pn = np.ones((nen, nen))
    for l in range(nen):
        for L in range(nen):
            for a in range(dim):
                t = _CODE_T0[codes[a]] + ((l >> a) & 1) * _CODE_DT[codes[a]]
                Pn[l, L] *= t if (L >> a) & 1 else 1.0 - t
    return Pn


@njit(parallel=True, cache=True, nogil=True)
def _galerkin_scaled(M, scales, combo, ptr, order, nde):
    n_coarse = ptr.shape[0] - 1
    out = np.zeros((n_coarse, nde, nde))
    for E in prange(n_coarse):
        for k in range(ptr[E], ptr[E + 1]):
            e = order[k]
            for g in range(scales.shape[0]):
                s = scales[g, e]
                if s == 0.0:
                    continue
                Mk = M[g, combo[e]]
                for i in range(nde):
                    for j in range(nde):
                        out[E, i, j] += s * Mk[i, j]
    return out


@njit(parallel=True, cache=True, nogil=True)
def _galerkin_explicit(Ke, Pn, combo, ptr, order, d):
    n_coarse = ptr.shape[0] - 1
    nen = Pn.shape[1]
    nde = nen * d
    out = np.zeros((n_coarse, nde, nde))
    for E in prange(n_coarse):
        T = np.empty((nde, nde))
        for k in range(ptr[E], ptr[E + 1]):
            e = order[k]
            P = Pn[combo[e]]
            K = Ke[e]
            # T = K (P kron I_d), then out += (P kron I_d)^T T, block by block.
            for i in range(nde):
                for L in range(nen):
                    for b in range(d):
                        acc = 0.0
                        for l2 in range(nen):
                            acc += K[i, l2 * d + b] * P[l2, L]
                        T[i, L * d + b] = acc
            for L1 in range(nen):
                for a in range(d):
                    for j in range(nde):
                        acc = 0.0
                        for l in range(nen):
                            acc += P[l, L1] * T[l * d + a, j]
                        out[E, L1 * d + a, j] += acc
    return out


def _coarsen(level, tick=None):
    """Galerkin coarse level of ``level``; fills level's transfer arrays."""
    tick = tick or (lambda: None)
    mesh, d, dim = level.mesh, level.d, level.mesh.dim
    maps = [_axis_map(n) for n in mesh.shape]
    shape_c = tuple(m[0] for m in maps)

    ec = mesh.elem_coords.astype(np.int64)
    parent = np.stack([maps[a][1][ec[:, a]] for a in range(dim)], axis=1)
    combo = np.zeros(len(ec), dtype=np.int64)
    for a in range(dim):
        combo += maps[a][2][ec[:, a]] * 6 ** a
    pflat = np.ravel_multi_index(tuple(parent.T), shape_c)
    uniq = np.unique(pflat)
    cmesh, _ = build_mesh(shape_c, np.stack(np.unravel_index(uniq, shape_c), axis=1))
    lookup = np.full(int(np.prod(shape_c)), -1, dtype=np.int64)
    lookup[np.ravel_multi_index(tuple(cmesh.elem_coords.T.astype(np.int64)), shape_c)] = \
        np.arange(cmesh.n_elem)
    cidx = lookup[pflat]
    tick()
    order = np.argsort(cidx, kind="stable")
    ptr = np.searchsorted(cidx[order], np.arange(cmesh.n_elem + 1))

    combos = np.unique(combo)
    cid = np.searchsorted(combos, combo)
    Pn = np.array([_node_interpolation(dim, int(c)) for c in combos])
    tick()
    if level.kind == "scaled":
        eye = np.eye(d)
        M = np.array([[np.kron(P, eye).T @ K0 @ np.kron(P, eye) for P in Pn]
                      for K0 in level.K0])
        Ke = _galerkin_scaled(M, level.scales, cid, ptr, order, level.K0.shape[1])
    else:
        Ke = _galerkin_explicit(level.Ke, Pn, cid, ptr, order, d)
    tick()
    Ke = 0.5 * (Ke + Ke.transpose(0, 2, 1))
    tick()
    _set_transfer(level, maps, cmesh)
    tick()
    return Level(mesh=cmesh, d=d, kind="explicit", Ke=Ke)


def _set_transfer(level, maps, cmesh):
    mesh, dim = level.mesh, level.mesh.dim
    nc = np.array([m[0] for m in maps])
    nodes = mesh.node_coords.astype(np.int64)
    lo = np.stack([maps[a][1][nodes[:, a]] for a in range(dim)], axis=1)
    t = np.stack([maps[a][3][nodes[:, a]] for a in range(dim)], axis=1)
    nen = 2 ** dim
    p_idx = np.zeros((len(nodes), nen), dtype=np.int64)
    p_w = np.ones((len(nodes), nen))
    for L in range(nen):
        bits = np.array([(L >> a) & 1 for a in range(dim)])
        cnode = (lo + bits) % nc
        p_w[:, L] = np.prod(np.where(bits == 1, t, 1.0 - t), axis=1)
        p_idx[:, L] = cmesh.node_index[tuple(cnode.T)]
    p_w[np.abs(p_w) < 1e-14] = 0.0
    if np.any(p_idx[p_w != 0] < 0):
        raise AssertionError("interpolation from an inactive coarse node")
    p_idx[p_w == 0] = 0
    rows = p_idx[p_w != 0]
    fine = np.broadcast_to(np.arange(len(nodes))[:, None], p_w.shape)[p_w != 0]
    order = np.argsort(rows, kind="stable")
    level.p_idx = p_idx.astype(np.int32)
    level.p_w = p_w
    level.r_ptr = np.searchsorted(rows[order], np.arange(cmesh.n_nodes + 1)).astype(np.int64)
    level.r_idx = fine[order].astype(np.int32)
    level.r_w = p_w[p_w != 0][order]


# ------------------------------------------------------------------ hierarchy

@dataclass
class Hierarchy:
    """Multigrid levels (0 = fine) and the V-cycle preconditioner.

    ``levels`` hold the operators in float64 as built; ``cycle`` are the same
    levels with their arrays in ``dtype`` (float32 by default: the cycle is
    only a preconditioner, the outer CG runs in float64, and single precision
    halves the memory traffic that bounds every kernel). The coarsest solve is
    always float64.
    """

    levels: list
    cycle: list
    dtype: type
    sweeps: int = 1
    tick: object = None
    _chol: tuple = None
    _work: dict = field(default_factory=dict)

    def _buffers(self, k, nrhs):
        key = (k, nrhs)
        if key not in self._work:
            n = self.levels[k].n_dof
            nc = self.levels[k + 1].n_dof
            self._work[key] = tuple(np.empty((m, nrhs), dtype=self.dtype) for m in (n, n, nc))
        return self._work[key]

    def _coarse_solve(self, b):
        lower, fac = self._chol
        b64 = b.astype(np.float64)
        if lower == "splu":
            x = fac.solve(b64)
        elif lower is None:                     # pseudo-inverse fallback
            x = fac @ b64
        else:
            x = scipy.linalg.cho_solve((fac, lower), b64)
        return x.astype(self.dtype)

    def __call__(self, r):
        """Preconditioner: one V-cycle on ``r`` (float64), result float64."""
        key = ("io", r.shape[1])
        if key not in self._work:
            self._work[key] = (np.empty(r.shape, dtype=self.dtype), np.empty(r.shape))
        b, out = self._work[key]
        b[:] = r
        out[:] = self.vcycle(b)
        return out

    def vcycle(self, b, k=0):
        """Approximate ``A_k^{-1} b`` in the cycle precision; returns a level buffer."""
        if k == len(self.levels) - 1:
            return self._coarse_solve(b)
        if self.levels[k].serial and numba.get_num_threads() > 1:
            old = numba.get_num_threads()
            numba.set_num_threads(1)
            try:
                return self._cycle(b, k)
            finally:
                numba.set_num_threads(old)
        return self._cycle(b, k)

    def _cycle(self, b, k):
        lev = self.cycle[k]
        x, Ax, bc = self._buffers(k, b.shape[1])
        kern = lev.kernels(b.shape[1])
        kern.jacobi_start(x, b, lev.dinv, lev.omega)
        for _ in range(self.sweeps - 1):
            self._apply(k, x, Ax)
            kern.jacobi_update(x, b, Ax, lev.dinv, lev.omega)
        self._apply(k, x, Ax)
        kern.restrict_residual(b, Ax, lev.r_ptr, lev.r_idx, lev.r_w, bc)
        xc = self.vcycle(bc, k + 1)
        kern.prolong_add(x, xc, lev.p_idx, lev.p_w)
        for _ in range(self.sweeps):
            self._apply(k, x, Ax)
            kern.jacobi_update(x, b, Ax, lev.dinv, lev.omega)
        return x

    def _apply(self, k, u, y):
        if k == 0 and self.tick is not None:
            self.tick()
        self.cycle[k].matvec(u, y)
        if k == 0 and self.tick is not None:
            self.tick()


def _cast_level(level, dtype):
    """Copy of ``level`` with its floating-point arrays in ``dtype``."""
    out = copy.copy(level)
    for name in ("K0", "scales", "Ke", "dinv", "p_w", "r_w"):
        arr = getattr(level, name)
        if arr is not None:
            setattr(out, name, np.ascontiguousarray(arr, dtype=dtype))
    out.omega = dtype(level.omega) if level.omega is not None else None
    return out


# Above this many dofs the coarsest level is factorised as a sparse matrix: a
# larger coarsest level keeps thin members that further coarsening would blur
# (2D growth tilings: 105 -> ~10 CG iterations), and sparse LU keeps it cheap.
SPARSE_COARSE_DOFS = 4000


def _factor_coarsest_sparse(level, dofs, Ke):
    from scipy.sparse import coo_matrix, identity
    from scipy.sparse.linalg import splu

    rows = np.repeat(dofs, dofs.shape[1], axis=1).ravel()
    cols = np.tile(dofs, (1, dofs.shape[1])).ravel()
    A = coo_matrix((Ke.reshape(len(dofs), -1).ravel(), (rows, cols)), shape=(level.n_dof, level.n_dof)).tocsc()
    A = 0.5 * (A + A.T)
    shift = 1e-10 * max(np.abs(A.diagonal()).max(), 1e-300)
    return "splu", splu((A + shift * identity(level.n_dof, format="csc")).tocsc())


def _factor_coarsest(level):
    """Cholesky of the regularised dense coarsest matrix (or a pseudo-inverse);
    sparse LU when the coarsest level is large."""
    mesh, d = level.mesh, level.d
    Ke = level.element_matrices()
    nen = mesh.elem_nodes.shape[1]
    dofs = (mesh.elem_nodes[:, :, None].astype(np.int64) * d + np.arange(d)).reshape(-1, nen * d)
    if level.n_dof > SPARSE_COARSE_DOFS:
        return _factor_coarsest_sparse(level, dofs, np.asarray(Ke, np.float64))
    A = np.zeros((level.n_dof, level.n_dof))
    np.add.at(A, (dofs[:, :, None], dofs[:, None, :]), Ke)
    A = 0.5 * (A + A.T)
    shift = 1e-10 * max(np.abs(np.diag(A)).max(), 1e-300)
    try:
        fac, lower = scipy.linalg.cho_factor(A + shift * np.eye(len(A)), lower=True)
        return lower, fac
    except np.linalg.LinAlgError:
        w, V = np.linalg.eigh(A)
        keep = w > 1e-10 * w.max()
        return None, (V[:, keep] / w[keep]) @ V[:, keep].T


def build_hierarchy(fine, *, nrhs, max_coarse_dofs=3000, sweeps=1, dtype=np.float32,
                    tick=None):
    """Coarsen ``fine`` (a Level) until the coarsest has few dofs.

    Parameters
    ----------
    fine : Level
        Fine level, normally ``kind="scaled"``.
    nrhs : int
        Number of right-hand sides the cycle will be applied to.
    max_coarse_dofs : int
        Stop coarsening once a level has at most this many dofs (it is then
        solved by dense Cholesky).
    sweeps : int
        Number of pre- and post-smoothing block-Jacobi sweeps.
    dtype : numpy float type
        Precision of the V-cycle (see :class:`Hierarchy`).
    tick : callable or None
        Called after each fine-level operator application (progress hook).
    """
    levels = [fine]
    while levels[-1].n_dof > max_coarse_dofs and any(n >= 4 for n in levels[-1].mesh.shape):
        if tick is not None:
            tick()
        levels.append(_coarsen(levels[-1], tick))
        if tick is not None:
            tick()
    tick = tick or (lambda: None)
    for k, lev in enumerate(levels[:-1]):
        tick()
        blocks = lev.block_diagonal()
        tick()
        lev.dinv = _invert_blocks(blocks)
        tick()
        if lev.kind == "scaled":
            used = np.flatnonzero(lev.scales.any(axis=1))
            lam = max(_element_bound(K0, lev.d) for K0 in lev.K0[used])
        else:
            lam = POWER_SAFETY * _power_estimate(lev, nrhs, tick)
        lev.omega = SMOOTHING / lam
    cycle = []
    for lev in levels[:-1]:
        tick()
        cycle.append(_cast_level(lev, dtype))
    for lev in levels[1:-1]:
        lev.Ke = None            # coarse operators live on in the cycle copies only
    h = Hierarchy(levels=levels, cycle=cycle, dtype=dtype, sweeps=sweeps, tick=tick)
    tick()
    h._chol = _factor_coarsest(levels[-1])
    return h


def _element_bound(K, d):
    """max eig(blockdiag(K)^-1 K): bounds eig(D^-1 A) of any sum of such elements."""
    Dn = np.zeros_like(K)
    for l in range(K.shape[0] // d):
        sl = slice(l * d, (l + 1) * d)
        Dn[sl, sl] = K[sl, sl]
    return float(scipy.linalg.eigh(K, Dn, eigvals_only=True)[-1])


def _power_estimate(level, nrhs, tick):
    """Largest eigenvalue of D^-1 A by (block) power iteration, fixed start."""
    x = np.random.default_rng(12345).standard_normal((level.n_dof, nrhs))
    y = np.empty_like(x)
    kern = level.kernels(nrhs)
    lam = 1.0
    for _ in range(POWER_STEPS):
        tick()
        x /= np.linalg.norm(x, axis=0)
        level.matvec(x, y)
        kern.jacobi_start(x, y, level.dinv, 1.0)          # x = D^-1 A x
        lam = float(np.linalg.norm(x, axis=0).max())
    return lam


def _invert_blocks(blocks):
    """Inverse of each (d, d) node block; singular blocks (not expected) -> pinv."""
    try:
        return np.linalg.inv(blocks)
    except np.linalg.LinAlgError:
        return np.linalg.pinv(blocks)
