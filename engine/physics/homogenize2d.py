"""Periodic plane-stress homogenization of a pixelized 2D cell.

Same method as :mod:`homogenize3d` on bilinear quads (unit thickness).
"""

from __future__ import annotations

import numpy as np

from .periodic_fe import HomogenizationResult, check_common, check_density, homogenize_grid

__all__ = ["homogenize_pixels", "HomogenizationResult"]


def homogenize_pixels(image, *, E=1.0, nu=0.45, void_modulus=0.0, tol=1e-8,
                      max_iterations=1000, progress=None, threads=None, memory_limit=None):
    """Effective plane-stress stiffness of a periodic pixel cell.

    Parameters
    ----------
    image : (ny, nx) array of float or bool in [0, 1]
        Material per pixel, laid out as an image is displayed: row 0 is the
        TOP of the cell, column 0 its left side. The x axis runs along the
        columns (left to right), the y axis UP the rows (from the last row to
        row 0). Pixels are square; the cell is ``nx`` by ``ny`` pixels
        (rectangular cells are allowed). A pixel of density ``rho`` has
        Young's modulus ``rho * E`` and Poisson ratio ``nu``.
    E, nu, void_modulus, tol, max_iterations, progress, threads, memory_limit
        As in :func:`engine.physics.homogenize3d.homogenize_voxels` (void
        voxels become void pixels; soft void has Poisson ratio 0).

    Returns
    -------
    HomogenizationResult
        ``C`` is (3, 3) float64 in Voigt notation with ENGINEERING shear
        strain, order ``(xx, yy, xy)``, plane stress per unit thickness;
        ``shape`` is the image shape ``(ny, nx)``.

    Raises
    ------
    ValueError, MemoryError, RuntimeError, Cancelled
        As :func:`engine.physics.homogenize3d.homogenize_voxels`.
    """
    E, nu, vm, tol = check_common(E, nu, void_modulus, tol, max_iterations, threads,
                                  memory_limit)
    arr = check_density(image, "image", 2)
    # Internal grid: axis 0 = x (columns), axis 1 = y (rows, upward).
    grid = np.ascontiguousarray(arr[::-1, :].T)
    return homogenize_grid(grid, E=E, nu=nu, void_modulus=vm, tol=tol,
                           max_iterations=int(max_iterations), progress=progress,
                           threads=threads, memory_limit=memory_limit, shape_out=arr.shape)
