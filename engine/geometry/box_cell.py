"""The orthorhombic box cell: edge lengths, per-axis grid counts, spacing.

A periodic cell is the box ``[0, Lx] x [0, Ly] x [0, Lz]`` in cell units
(the unit cube is ``(1, 1, 1)``). A hexagonal lattice has the C-centred
orthorhombic cell ``a x a*sqrt(3) x c``, so a box covers hexagonal,
tetragonal and orthorhombic structures. It is sampled at the nodes
``x_i = i * Lx / nx`` (``i = 0 .. nx-1``) and likewise along y and z; the
grid is exactly periodic with period ``L`` per axis.

:func:`box_grid_shape` turns one resolution (nodes along the longest edge)
into per-axis counts whose spacings ``L_i / n_i`` are as equal as integer
counts allow.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["UNIT_CELL", "MAX_EDGE", "MIN_AXIS_NODES", "check_cell", "check_grid_shape",
           "box_grid_shape", "box_spacing", "default_band"]

UNIT_CELL = (1.0, 1.0, 1.0)
MAX_EDGE = 100.0        # longest allowed box edge, cell units
MIN_AXIS_NODES = 8      # fewest grid nodes along a short edge


def check_cell(cell, name="cell"):
    """Validate box edge lengths.

    Parameters
    ----------
    cell : sequence of 3 float or None
        ``(Lx, Ly, Lz)``, each finite, in ``(0, MAX_EDGE]``; None is the unit cube.
    name : str
        Parameter name used in error messages.

    Returns
    -------
    tuple of 3 float
    """
    if cell is None:
        return UNIT_CELL
    try:
        out = tuple(float(v) for v in cell)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be three box edge lengths; got {cell!r}") from None
    if len(out) != 3 or not all(math.isfinite(v) and 0.0 < v <= MAX_EDGE for v in out):
        raise ValueError(f"{name} must be three box edge lengths in (0, {MAX_EDGE:g}]; got {cell!r}")
    return out


def check_grid_shape(resolution, name="resolution"):
    """An int N (an N x N x N grid) or three ints ``(nx, ny, nz)``, each >= 2.

    Returns
    -------
    tuple of 3 int
    """
    vals = resolution if isinstance(resolution, (tuple, list, np.ndarray)) else (resolution,) * 3
    if len(vals) != 3 or any(isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 2
                             for v in vals):
        raise ValueError(f"{name} must be an integer >= 2 or three of them (nx, ny, nz); "
                         f"got {resolution!r}")
    return tuple(int(v) for v in vals)


def box_grid_shape(cell, resolution, *, min_nodes=MIN_AXIS_NODES):
    """Grid nodes per axis for a box sampled at ``resolution`` along its longest edge.

    ``n_i = max(min_nodes, round(resolution * L_i / L_max))`` (halves round
    up); the longest edge gets exactly ``resolution``. The unit cube gives
    ``(resolution,) * 3``.

    Parameters
    ----------
    cell : sequence of 3 float, box edges (cell units)
    resolution : int >= 2

    Returns
    -------
    tuple of 3 int
    """
    lengths = check_cell(cell)
    n = check_grid_shape(resolution)[0]
    top = max(lengths)
    return tuple(n if v == top else max(int(min_nodes), int(math.floor(n * v / top + 0.5)))
                 for v in lengths)


def box_spacing(cell, shape):
    """(3,) float64 node spacing ``L_i / n_i`` (cell units)."""
    return np.asarray(check_cell(cell), dtype=np.float64) / np.asarray(shape, dtype=np.float64)


def default_band(cell, shape):
    """Three voxels along the coarsest axis: ``max(3 L_i / n_i)`` (``3 / N`` on the unit cube)."""
    return max(3.0 * float(v) / int(n) for v, n in zip(check_cell(cell), shape))
