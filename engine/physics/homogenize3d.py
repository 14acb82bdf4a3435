"""Periodic linear-elastic homogenization of a voxelized 3D cell.

Finite elements on the solid voxels only (trilinear hexes), all six load
cases solved together by conjugate gradients preconditioned with a Galerkin
geometric multigrid V-cycle (:mod:`multigrid`, :mod:`block_pcg`); the
stiffness follows from the cell-averaged strain energy (:mod:`periodic_fe`).
"""

from __future__ import annotations

import numpy as np

from .periodic_fe import HomogenizationResult, check_common, check_density, homogenize_grid

__all__ = ["homogenize_voxels", "HomogenizationResult"]


def homogenize_voxels(density, *, E=1.0, nu=0.45, void_modulus=0.0, tol=1e-8,
                      max_iterations=1000, progress=None, threads=None, memory_limit=None,
                      cell=None):
    """Effective elastic stiffness of a periodic voxel cell.

    Parameters
    ----------
    density : (n, n, n) or, with ``cell``, (nx, ny, nz) array of float or bool in [0, 1]
        Material per voxel, index ``[i, j, k] = [x, y, z]``; the cell is the
        unit cube with voxels of side ``1/n`` (a CUBIC grid is required,
        ``nx == ny == nz``, unless ``cell`` is given). A voxel of density ``rho`` has Young's modulus
        ``rho * E`` and Poisson ratio ``nu`` (linear, SIMP exponent 1), so a
        binary array is a solid/void cell and two values give two materials.
    E : float > 0
        Young's modulus of the base material.
    nu : float in (-1, 0.5)
        Poisson ratio of the base material.
    void_modulus : float in [0, 1)
        Empty voxels (density 0). ``0`` (default): void is removed exactly and
        material not connected to its own periodic image (islands) is dropped
        and reported. ``> 0``: void is a soft material with Young's modulus
        ``void_modulus * E`` and Poisson ratio 0 (Liu et al. use 1e-3); all
        voxels are kept and nothing is dropped.
    tol : float in (0, 1)
        Target relative accuracy of the stiffness: every load case stops when
        the estimated relative error of its energy (the diagonal of ``C``) is
        below ``tol`` (:mod:`engine.physics.block_pcg`). Off-diagonal terms
        are accurate to about ``tol`` times the diagonal.
    max_iterations : int
        Conjugate-gradient iteration cap (RuntimeError beyond it).
    progress : callable ``(done, total) -> bool`` or None
        Called about every 50 ms with ``total = 1000``: setup fills the first
        100, the solve the rest in proportion to the log of the error
        reduction reached. Returning False raises
        :class:`engine.progress.Cancelled`.
    threads : int or None
        numba threads for this call. None: one thread for small cells (below
        about 100 000 voxels, ``periodic_fe.AUTO_SERIAL_WORK``: barriers cost
        more than they save), else numba's setting or one thread, whichever
        ran an iteration faster. The result does not depend on it.
    memory_limit : float or None
        Refuse (MemoryError, with the estimate) a grid whose estimated peak
        memory exceeds this many bytes; default the budget of engine.memory
        (the available memory, or MESOFORGE_MEMORY_LIMIT).
    cell : (3,) float or None
        Box cell ``(Lx, Ly, Lz)`` (any unit, only ratios matter): the grid
        covers the box with box voxels of edges ``L_i / n_i`` (trilinear hexes
        of those edges). None: the unit cube, cubic grid.

    Returns
    -------
    HomogenizationResult
        ``C`` is (6, 6) float64 in Voigt notation with ENGINEERING shear
        strains, order ``(xx, yy, zz, yz, xz, xy)``; see the class.

    Raises
    ------
    ValueError
        Bad input (named in the message), or no percolating material.
    MemoryError
        The grid would need more memory than allowed (checked up front).
    RuntimeError
        No convergence within ``max_iterations``.
    engine.progress.Cancelled
        ``progress`` returned False.
    """
    E, nu, vm, tol = check_common(E, nu, void_modulus, tol, max_iterations, threads,
                                  memory_limit)
    arr = check_density(density, "density", 3)
    voxel_size = None
    if cell is None:
        if not arr.shape[0] == arr.shape[1] == arr.shape[2]:
            raise ValueError(f"density must be a cubic grid (nx == ny == nz) for a cubic "
                             f"cell; got shape {arr.shape}")
    else:
        box = np.asarray(cell, dtype=np.float64).reshape(-1)
        if box.shape != (3,) or not np.all(np.isfinite(box) & (box > 0)):
            raise ValueError(f"cell must be three box edges > 0; got {cell!r}")
        h = box / np.array(arr.shape, dtype=np.float64)
        if not np.all(h == h[0]):
            voxel_size = h / h.max()
    return homogenize_grid(arr, E=E, nu=nu, void_modulus=vm, tol=tol,
                           max_iterations=int(max_iterations), progress=progress,
                           threads=threads, memory_limit=memory_limit, voxel_size=voxel_size)
