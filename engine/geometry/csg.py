"""Boolean operations on signed distance grids (paper section 6.5).

Fields follow the SDF convention (negative inside), so union is the minimum,
intersection the maximum and ``a - b`` is ``max(a, -b)``. Results are exact
in sign and in their zero set; away from the surface they are bounds, which
is all marching cubes needs. Inputs are never modified.
"""

from __future__ import annotations

import numpy as np

__all__ = ["csg_union", "csg_intersection", "csg_difference", "csg_reduce", "CSG_OPS"]

CSG_OPS = ("union", "intersection", "difference")


def _pair(a, b):
    a = np.asarray(a)
    b = np.asarray(b)
    if a.shape != b.shape:
        raise ValueError(f"fields must have the same shape; got a {a.shape} and b {b.shape} "
                         "(objects combined by a Boolean need the same grid resolution)")
    return a, b


def csg_union(a, b):
    """Union ``min(a, b)`` of two SDF grids.

    Parameters
    ----------
    a, b : numpy.ndarray, same shape (e.g. (N, N, N)), float
        Signed distance samples, negative inside.

    Returns
    -------
    numpy.ndarray
        New array, same shape; dtype is the common float type.
    """
    a, b = _pair(a, b)
    return np.minimum(a, b)


def csg_intersection(a, b):
    """Intersection ``max(a, b)`` of two SDF grids (see :func:`csg_union`)."""
    a, b = _pair(a, b)
    return np.maximum(a, b)


def csg_difference(a, b):
    """Difference ``a - b`` = ``max(a, -b)`` of two SDF grids (see :func:`csg_union`)."""
    a, b = _pair(a, b)
    return np.maximum(a, -b)


def csg_reduce(fields, op):
    """Fold a Boolean over several SDF grids.

    Parameters
    ----------
    fields : sequence of numpy.ndarray, all the same shape
        At least one field.
    op : {"union", "intersection", "difference"}
        ``"difference"`` subtracts every later field from the first.

    Returns
    -------
    numpy.ndarray
        New array (a copy even for a single field).
    """
    if op not in CSG_OPS:
        raise ValueError(f"op must be one of {CSG_OPS}; got {op!r}")
    fields = list(fields)
    if not fields:
        raise ValueError("fields must hold at least one grid; got an empty sequence")
    func = {"union": csg_union, "intersection": csg_intersection,
            "difference": csg_difference}[op]
    out = np.array(fields[0], copy=True)
    for k, other in enumerate(fields[1:], start=1):
        other = np.asarray(other)
        if other.shape != out.shape:
            raise ValueError(f"fields must have the same shape; got fields[0] {out.shape} "
                             f"and fields[{k}] {other.shape}")
        out = func(out, other)
    return out
