"""FIXBOUNDARY (Makatura et al. 2023, Algorithm 1, last step): put the
boundary of a conjugate patch exactly on its FBV planes.

The thin-shell direct solver of the paper is not used: every boundary
vertex is projected onto its plane (a corner onto the FBV edge where its
two planes meet) and the interior follows by the cotan-harmonic extension
of those displacements, so a patch that already fits moves by a hair and
stays smooth.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse.linalg import splu

from .curvature import cotan_laplacian

__all__ = ["fix_boundary", "snap_to_planes", "harmonic_shift"]


def snap_to_planes(points, planes, fbv):
    """Nearest point of each point's one or two planes.

    Parameters
    ----------
    points : (b, 3) float64, model units
    planes : (b, 2) int64
        Plane indices of each point; the second is -1 for one plane.
    fbv : BoundingVolume

    Returns
    -------
    (b, 3) float64
    """
    out = np.array(points, dtype=np.float64)
    for k, (a, b) in enumerate(planes):
        ks = [a] if b < 0 else [a, b]
        n = fbv.normals[ks]
        h = fbv.offsets[ks]
        out[k] = out[k] - n.T @ np.linalg.solve(n @ n.T, n @ out[k] - h)
    return out


def harmonic_shift(vertices, faces, boundary, shift):
    """Vertices moved by a boundary displacement and its cotan-harmonic extension.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int64
    boundary : (b,) int64
    shift : (b, 3) float64
        Displacement of each boundary vertex (model units).

    Returns
    -------
    (n, 3) float64
        Interior vertices moved harmonically; boundary vertices not moved.
    """
    n = vertices.shape[0]
    fixed = np.zeros(n, dtype=bool)
    fixed[boundary] = True
    free = np.flatnonzero(~fixed)
    out = np.array(vertices, dtype=np.float64)
    if free.size:
        lap = cotan_laplacian(vertices, faces).tocsc()
        rhs = lap[free][:, boundary] @ shift
        out[free] += splu((-lap[free][:, free]).tocsc()).solve(np.ascontiguousarray(rhs))
    return out


def fix_boundary(vertices, faces, boundary, planes, fbv):
    """Snap the boundary onto its planes; the interior follows harmonically.

    Parameters
    ----------
    vertices : (n, 3) float64, model units
    faces : (m, 3) int64
    boundary : (b,) int64
        Boundary vertex indices.
    planes : (b, 2) int64
        See :func:`snap_to_planes`.
    fbv : BoundingVolume

    Returns
    -------
    (vertices (n, 3) float64, snap_max float)
        The fixed vertices and the largest boundary displacement.
    """
    target = snap_to_planes(vertices[boundary], planes, fbv)
    shift = target - vertices[boundary]
    out = harmonic_shift(vertices, faces, boundary, shift)
    out[boundary] = target
    return out, float(np.linalg.norm(shift, axis=1).max())
