"""Periodic finite-element homogenization on a voxel/pixel grid (shared driver).

For each unit macroscopic strain ``eps_i`` the periodic fluctuation solves
``K U_i = F_i`` with ``F_i = sum_e integral B^T D_e eps_i``; the homogenized
stiffness is the cell-averaged strain energy

    C_ij |Y| = sum_e integral (eps_i - B U_i)^T D_e (eps_j - B U_j)
             = A0_ij - F_i.U_j - U_i.F_j + U_i.K U_j,

evaluated in that symmetric form (error quadratic in the solver error).
``A0_ij = sum_e |e| eps_i.D_e eps_j``. Internally E = 1; C is scaled by E.

The front ends :mod:`homogenize3d` and :mod:`homogenize2d` validate input and
fix the axis conventions; here array axis ``a`` is lattice direction ``a``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from engine.progress import PARALLEL_LOCK, report
from engine.memory import memory_budget

from . import element_kernels as ek
from .block_pcg import block_pcg
from .hex_element import element_matrices, isotropic_stiffness, plane_stress_stiffness
from .islands import keep_percolating
from .multigrid import Level, build_hierarchy
from .voxel_mesh import build_mesh

__all__ = ["HomogenizationResult", "homogenize_grid", "estimate_memory"]

# Progress is reported as (done, PROGRESS_TOTAL): setup fills the first
# SETUP_SHARE, the solve the rest in proportion to log(residual reduction).
PROGRESS_TOTAL = 1000
# The coarsest multigrid level is solved densely once it has at most this
# many dofs (so grids this small are solved directly, in one iteration).
MAX_COARSE_DOFS = {2: 20000, 3: 3000}  # 2D: large sparse coarsest level keeps thin members
# threads=None: cells whose fine operator costs fewer multiply-adds per
# application than this run on one thread (3D ~100k voxels; every practical
# 2D cell): there the dozen thread barriers per iteration cost more than they
# save, badly so when other processes share the two cores (OpenMP threads
# spin waiting for a descheduled partner; measured 3-6x slower). Larger cells
# time one iteration on all threads and one on a single thread and keep the
# faster setting (the result does not depend on the thread count).
AUTO_SERIAL_WORK = 3.5e8
SETUP_SHARE = 100
TICK_SECONDS = 0.05


@dataclass(frozen=True, eq=False)
class HomogenizationResult:
    """Homogenized stiffness of a periodic cell.

    Attributes
    ----------
    C : (6, 6) or (3, 3) float64, read-only
        Effective stiffness in Voigt notation with ENGINEERING shear strains
        (sigma = C eps, eps_shear = 2 eps_tensor). Order in 3D
        ``(xx, yy, zz, yz, xz, xy)``, in 2D ``(xx, yy, xy)``; units of ``E``
        (2D: plane stress, per unit thickness).
    density : float
        Solid volume fraction of the input, ``mean(density)``.
    dropped_fraction : float
        Material removed as floating islands, as a fraction of the cell.
    iterations : int
        Conjugate-gradient iterations (all load cases solved together).
    residual : float
        Largest final relative residual ``|r| / |f|`` over the load cases.
    error_estimate : float
        Estimated relative error of the diagonal of ``C`` (the stopping
        measure, see :mod:`block_pcg`); it bounds the solver's share of the
        error, not the discretisation error.
    seconds : float
        Wall time of the call.
    shape : tuple of int
        Grid shape as given.
    E, nu, void_modulus : float
        Material parameters used (void_modulus as a fraction of E).
    levels : int
        Multigrid levels used.
    """

    C: np.ndarray
    density: float
    dropped_fraction: float
    iterations: int
    residual: float
    error_estimate: float
    seconds: float
    shape: tuple
    E: float
    nu: float
    void_modulus: float
    levels: int


# ----------------------------------------------------------------- validation

def check_common(E, nu, void_modulus, tol, max_iterations, threads, memory_limit):
    """Refuse bad scalar options with a message naming the parameter."""
    for name, v in (("E", E), ("nu", nu), ("void_modulus", void_modulus), ("tol", tol)):
        if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)):
            raise ValueError(f"{name} must be a real number; got {v!r}")
    E, nu, vm, tol = float(E), float(nu), float(void_modulus), float(tol)
    if not math.isfinite(E) or E <= 0:
        raise ValueError(f"E must be a finite Young's modulus > 0; got {E!r}")
    if not math.isfinite(nu) or not -1.0 < nu < 0.5:
        raise ValueError(f"nu must be a Poisson ratio in (-1, 0.5); got {nu!r}")
    if not math.isfinite(vm) or not 0.0 <= vm < 1.0:
        raise ValueError(f"void_modulus must be a fraction of E in [0, 1); got {vm!r}")
    if not math.isfinite(tol) or not 0.0 < tol < 1.0:
        raise ValueError(f"tol must be a relative accuracy in (0, 1); got {tol!r}")
    if isinstance(max_iterations, bool) or not isinstance(max_iterations, (int, np.integer)) \
            or max_iterations < 1:
        raise ValueError(f"max_iterations must be an integer >= 1; got {max_iterations!r}")
    if threads is not None:
        import numba
        top = numba.config.NUMBA_NUM_THREADS
        if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) \
                or not 1 <= threads <= top:
            raise ValueError(f"threads must be None or an integer in [1, {top}]; got {threads!r}")
    if memory_limit is not None:
        if isinstance(memory_limit, bool) \
                or not isinstance(memory_limit, (int, float, np.integer, np.floating)) \
                or not memory_limit > 0:
            raise ValueError(f"memory_limit must be None or a byte count > 0; got {memory_limit!r}")
    return E, nu, vm, tol


def check_density(density, name, ndim):
    """Array of numbers in [0, 1] with at least one solid cell; returned as
    given (no copy): `homogenize_grid` makes its float64 copy once the
    memory check has passed."""
    try:
        arr = np.asarray(density)
    except Exception as exc:   # noqa: BLE001 - ragged lists etc.
        raise ValueError(f"{name} must be an array of densities in [0, 1]; {exc}") from None
    if arr.dtype == object or not (np.issubdtype(arr.dtype, np.number) or arr.dtype == bool):
        raise ValueError(f"{name} must be a numeric array of densities in [0, 1]; "
                         f"got dtype {arr.dtype}")
    if np.iscomplexobj(arr):
        raise ValueError(f"{name} must be real; got dtype {arr.dtype}")
    if arr.ndim != ndim:
        raise ValueError(f"{name} must be a {ndim}D array; got shape {arr.shape}")
    if min(arr.shape) < 2:
        raise ValueError(f"{name} needs at least 2 cells per axis; got shape {arr.shape}")
    # min / max propagate NaN and show infinities, so the grid is checked
    # without a float64 copy (a refused or too-large grid allocates nothing)
    lo, hi = float(arr.min()), float(arr.max())
    if not (np.isfinite(lo) and np.isfinite(hi)):
        raise ValueError(f"{name} contains NaN or infinite values")
    if lo < 0.0 or hi > 1.0:
        raise ValueError(f"{name} values must lie in [0, 1]; got range [{lo:g}, {hi:g}]")
    if hi == 0.0:
        raise ValueError(f"{name} is empty: no cell has density > 0")
    return arr


# --------------------------------------------------------------------- memory

def estimate_memory(density, void_modulus=0.0):
    """Upper estimate (bytes) of the solver's peak memory for a grid.

    Counts the active nodes exactly (nodes touching an element) and charges
    per node the CG/multigrid vectors and per element the mesh and the
    Galerkin matrices; calibrated on measured peaks (see the bench).
    """
    dim = density.ndim
    n_elem = int(np.count_nonzero(density)) if void_modulus == 0 else density.size
    if n_elem == density.size:       # every node is active: no masks needed
        return _memory_for(dim, n_elem, n_elem, density.size)
    elem = density > 0
    node = elem.copy()
    for a in range(dim):
        node |= np.roll(node, 1, axis=a)
    return _memory_for(dim, n_elem, int(node.sum()), density.size)


def _memory_for(dim, n_elem, n_nodes, size):
    """The estimate of `estimate_memory` from the element and node counts."""
    nv = 6 if dim == 3 else 3
    vec = n_nodes * dim * nv * 8
    # Fine vectors: 7 float64 (CG x r z p q, loads, K u) and the float32
    # cycle buffers, coarse levels ~1/6 of that, temporaries: ~12 vectors.
    # Per element: mesh ints (~100 B) and the level-1 Galerkin matrices (one
    # per 2^dim elements, built in float64). Calibrated on the bench's truss
    # cells: 64^3 0.36 GB estimated / 0.34 GB peak RSS measured, 100^3
    # 0.79 / 0.69 GB, 2D 400^2 0.31 / 0.31 GB (incl. ~0.2 GB of Python).
    nde = 2 ** dim * dim
    per_elem = 100 + nde * nde * 8 * 1.3 / 2 ** dim
    return int(12 * vec + n_elem * per_elem + size * 24 + 200e6)


# --------------------------------------------------------------------- driver

class _Ticker:
    """Rate-limited progress callback (about every TICK_SECONDS)."""

    def __init__(self, progress):
        self.progress = progress
        self.done = 0
        self.last = time.perf_counter()

    def __call__(self, force=False):
        if self.progress is None:
            return
        now = time.perf_counter()
        if force or now - self.last >= TICK_SECONDS:
            self.last = now
            report(self.progress, min(self.done, PROGRESS_TOTAL), PROGRESS_TOTAL)


def homogenize_grid(density, *, E, nu, void_modulus, tol, max_iterations, progress,
                    threads, memory_limit, shape_out=None, voxel_size=None):
    """Homogenize a validated density grid (axis a = direction a). See fronts.

    voxel_size : None (cubic voxels) or (dim,) float edge lengths of a box
        voxel (any common scale: only their ratios matter).
    """
    t_start = time.perf_counter()
    dim = density.ndim
    limit = memory_limit if memory_limit is not None else memory_budget()
    if limit is not None:
        # nodes >= elements on a periodic grid: a lower bound that needs no
        # masks refuses a huge grid before the exact count allocates them
        n_elem = int(np.count_nonzero(density)) if void_modulus == 0 else density.size
        need = _memory_for(dim, n_elem, n_elem, density.size)
        if need <= limit:
            need = estimate_memory(density, void_modulus)
        if need > limit:
            raise MemoryError(
                f"homogenizing a {'x'.join(map(str, density.shape))} grid needs about "
                f"{need / 1e9:.1f} GB, more than the {limit / 1e9:.1f} GB allowed; "
                f"use a coarser grid")
    density = np.array(density, dtype=np.float64)      # the kernel's own copy
    ticker = _Ticker(progress)
    ticker(force=True)

    import numba
    old = numba.get_num_threads()
    choose = False
    if threads is None:
        n_elem = density.size if void_modulus > 0 else int(np.count_nonzero(density))
        work = n_elem * (2 ** dim * dim) ** 2 * (6 if dim == 3 else 3)
        choose = work >= AUTO_SERIAL_WORK and old > 1
        threads = old if choose else 1
    numba.set_num_threads(int(threads))
    try:
        return _solve(density, dim, E, nu, void_modulus, tol, max_iterations, ticker,
                      t_start, shape_out, _ThreadChooser(choose), voxel_size)
    finally:
        numba.set_num_threads(old)


class _ThreadChooser:
    """Times iteration 2 on all threads and iteration 3 on one, keeps the faster."""

    def __init__(self, enabled):
        self.enabled = enabled
        self.stamps = []

    def __call__(self, iteration):
        if not self.enabled:
            return
        import numba
        self.stamps.append(time.perf_counter())
        if iteration == 2:
            self.threads = numba.get_num_threads()
            numba.set_num_threads(1)
        elif iteration == 3:
            t_all = self.stamps[1] - self.stamps[0]
            t_one = self.stamps[2] - self.stamps[1]
            numba.set_num_threads(1 if t_one <= t_all else self.threads)
            self.enabled = False


def _parallel_guard():
    """The geometry package's kernel lock when numba runs on its "workqueue"
    layer (which aborts on concurrent parallel launches), else a no-op."""
    import contextlib

    import numba
    try:
        layer = numba.threading_layer()
    except ValueError:                 # no parallel kernel has run yet
        z = np.zeros((2, 1))
        ek.column_dots(z, z, z)
        layer = numba.threading_layer()
    return PARALLEL_LOCK if layer == "workqueue" else contextlib.nullcontext()


def _solve(density, dim, E, nu, vm, tol, max_iterations, ticker, t_start, shape_out,
           chooser, voxel_size=None):
    nv = 6 if dim == 3 else 3
    D_of = isotropic_stiffness if dim == 3 else plane_stress_stiffness
    # Groups: 0 = base material (nu), 1 = soft void (nu = 0); internal E = 1.
    Ds = [D_of(1.0, nu), D_of(1.0, 0.0)]
    if voxel_size is None:
        mats = [element_matrices(D, dim) for D in Ds]
    else:
        mats = [element_matrices(D, dim, voxel_size) for D in Ds]
    K0 = np.array([m[0] for m in mats])
    Fe = np.array([m[1] for m in mats])

    guard = _parallel_guard()
    with guard:
        if vm == 0.0:
            kept, dropped, comp = keep_percolating(density, return_labels=True)
            ticker()
            if not kept.any():
                raise ValueError("no solid component percolates: the material does not "
                                 "connect to its own periodic image in any direction, "
                                 "so the cell carries no load")
            coords = np.argwhere(kept)
            scales = density[kept][None, :]
        else:
            dropped, comp = 0.0, None
            coords = np.argwhere(np.ones(density.shape, dtype=bool))
            flat = density.ravel()
            scales = np.stack([flat, np.where(flat > 0, 0.0, vm)])
        mesh, order = build_mesh(density.shape, coords)
        scales = np.ascontiguousarray(scales[:, order], dtype=np.float64)
    ticker.done = SETUP_SHARE // 5
    ticker()

    fine = Level(mesh=mesh, d=dim, kind="scaled", K0=K0[:len(scales)], scales=scales)
    labels, n_labels = _node_labels(mesh, comp)
    with guard:
        F = ek.scatter_scaled_vectors(Fe[:len(scales)], scales, mesh.elem_nodes, mesh.n_nodes)
        ticker()
        hier = build_hierarchy(fine, nrhs=nv, max_coarse_dofs=MAX_COARSE_DOFS[dim],
                               tick=ticker)
    ticker.done = SETUP_SHARE
    ticker()

    def project(z):
        ek.remove_mean(z, labels, n_labels, dim)

    def apply_A(u, y):
        ticker()
        fine.matvec(u, y)
        ticker()

    A0 = sum(Ds[g] * scales[g].sum() for g in range(len(scales)))
    log_goal = -math.log(tol)

    def callback(it, err):
        chooser(it)
        worst = float(err.max())
        frac = 1.0 if worst <= 0 else min(1.0, max(0.0, -math.log(worst) / log_goal))
        ticker.done = SETUP_SHARE + int(frac * (PROGRESS_TOTAL - SETUP_SHARE - 1))
        ticker()

    with guard:
        sol = block_pcg(apply_A, hier, F, tol=tol, max_iterations=max_iterations,
                        project=project, energy=np.diag(A0).copy(), callback=callback)
        U = sol.x
        project(U)
        KU = np.empty_like(U)
        fine.matvec(U, KU)
    if not sol.converged:
        raise RuntimeError(f"homogenization did not converge in {max_iterations} iterations "
                           f"(estimated error {sol.errors.max():.2e} > tol {tol:.1e})")

    FU = F.T @ U
    if voxel_size is None:
        C = (A0 - FU - FU.T + U.T @ KU) / density.size
    else:   # A0 counted unit volumes per element; a box voxel has prod(h)
        vol = float(np.prod(voxel_size))
        C = (A0 * vol - FU - FU.T + U.T @ KU) / (density.size * vol)
    C = 0.5 * (C + C.T) * E
    C.setflags(write=False)
    ticker.done = PROGRESS_TOTAL
    ticker(force=True)
    return HomogenizationResult(
        C=C, density=float(density.mean()), dropped_fraction=float(dropped),
        iterations=int(sol.iterations), residual=float(sol.residuals.max()),
        error_estimate=float(sol.errors.max()),
        seconds=time.perf_counter() - t_start,
        shape=tuple(shape_out) if shape_out is not None else density.shape,
        E=float(E), nu=float(nu), void_modulus=float(vm), levels=len(hier.levels))


def _node_labels(mesh, comp):
    """Component label per active node (rigid translations to project out).

    comp : int array of the grid shape (component per voxel) or None (one piece).
    """
    if comp is None:
        return np.zeros(mesh.n_nodes, dtype=np.int64), 1
    elab = comp[tuple(mesh.elem_coords.T)]
    uniq, elab = np.unique(elab, return_inverse=True)
    labels = np.zeros(mesh.n_nodes, dtype=np.int64)
    labels[mesh.elem_nodes.ravel()] = np.repeat(elab, mesh.elem_nodes.shape[1])
    return labels, len(uniq)
