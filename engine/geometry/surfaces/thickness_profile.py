"""Spatially varying thickness over a surface patch (Makatura et al. 2023,
section 5.3): sparse samples spread over the patch with bounded biharmonic
weights (Jacobson et al. 2011) in an as-rigid-as-possible parametrisation.

The patch is flattened once (:func:`arap_parametrisation`: a harmonic map of
the boundary onto a circle, relaxed by local/global ARAP steps with a free
boundary, so UV distances follow distances on the surface). Each sample is a
mesh vertex (a *handle*) with a thickness. Bounded biharmonic weights over
the UV mesh (:func:`bounded_biharmonic_weights`) are smooth, equal 1 at their
own handle and 0 at the others, lie in [0, 1] and sum to 1, so the blended
thickness is a convex combination of the sample values: it never leaves
their range, and constant samples give a constant thickness.

Bounded biharmonic weights do not reproduce linear functions, so with
``linear_precision`` (the default) the thickness is the least-squares affine
function of UV through the samples plus the weighted blend of what it leaves
at the handles, clipped to the samples' range. Samples taken from an affine
function of UV (e.g. a linear ramp over a flat patch) are then reproduced
exactly wherever the ramp stays within the sample values; constant samples
still give a constant.

Where samples come from is up to the caller; two helpers locate handles:
:func:`boundary_vertices_at` (arc-length positions along the boundary loop)
and :func:`nearest_vertices` (points in space). Samples on one vertex are
averaged.
"""

from __future__ import annotations

import numpy as np

from .curvature import validate_mesh

__all__ = ["arap_parametrisation", "bounded_biharmonic_weights", "boundary_vertices_at",
           "nearest_vertices", "surface_thickness", "ARAP_ITERATIONS"]

# Local/global ARAP iterations after the harmonic initialisation; the
# parametrisation only weights the blend, so a few tens are plenty.
ARAP_ITERATIONS = 30

# Singular values of the centred sample UVs below this fraction of the
# largest are dropped from the affine fit (nearly collinear samples give no
# reliable gradient across their line).
_AFFINE_RCOND = 1e-3


def _boundary_of(faces):
    import igl

    loop = np.asarray(igl.boundary_loop(np.ascontiguousarray(faces, dtype=np.int64)), dtype=np.int64)
    if loop.size < 3:
        raise ValueError("the mesh has no boundary loop; a thickness profile needs a disc-like patch")
    return loop


def arap_parametrisation(vertices, faces, *, iterations=ARAP_ITERATIONS):
    """As-rigid-as-possible UV parametrisation of a disc-like patch.

    Parameters
    ----------
    vertices : array_like, shape (n, 3), float
        Patch vertices (model units).
    faces : array_like, shape (m, 3), int
    iterations : int
        Local/global ARAP steps after the harmonic initialisation (>= 1).

    Returns
    -------
    numpy.ndarray, shape (n, 2), float64
        UV positions in model units (up to a rigid motion of the plane).

    Raises
    ------
    ValueError
        A bad mesh, a mesh without boundary, or bad ``iterations``.
    """
    import igl

    if isinstance(iterations, bool) or not isinstance(iterations, (int, np.integer)) or iterations < 1:
        raise ValueError(f"iterations must be an integer >= 1; got {iterations!r}")
    v, f = validate_mesh(vertices, faces)
    loop = _boundary_of(f)
    circle = igl.map_vertices_to_circle(np.asfortranarray(v), loop.astype(np.int32))
    uv0 = igl.harmonic(v, f, loop, np.ascontiguousarray(circle), 1)
    data = igl.ARAPData()
    data.max_iter = int(iterations)
    # One pinned vertex removes the translation null space (the boundary
    # stays free; rotations are taken care of by the local steps).
    pin = loop[:1]
    igl.arap_precomputation(v, f, 2, pin.astype(np.int32), data)
    uv = igl.arap_solve(np.ascontiguousarray(uv0[pin]), data, np.ascontiguousarray(uv0))
    return np.ascontiguousarray(uv, dtype=np.float64)


def bounded_biharmonic_weights(uv, faces, handles):
    """Bounded biharmonic weights of handle vertices over a planar mesh.

    Parameters
    ----------
    uv : array_like, shape (n, 2), float
        Planar mesh (e.g. :func:`arap_parametrisation`).
    faces : array_like, shape (m, 3), int
    handles : array_like, shape (k,), int
        Distinct vertex indices, k >= 1.

    Returns
    -------
    numpy.ndarray, shape (n, k), float64
        ``W[i, j]`` is the weight of handle j at vertex i: in [0, 1], rows sum
        to 1, ``W[handles[j], j] = 1``.
    """
    import igl

    p = np.ascontiguousarray(uv, dtype=np.float64)
    f = np.ascontiguousarray(faces, dtype=np.int64)
    h = np.asarray(handles, dtype=np.int64).ravel()
    if p.ndim != 2 or p.shape[1] != 2:
        raise ValueError(f"uv must have shape (n, 2); got shape {p.shape}")
    if h.size == 0 or h.min() < 0 or h.max() >= p.shape[0]:
        raise ValueError(f"handles must be 1 or more vertex indices in 0..{p.shape[0] - 1}; got {h.tolist()}")
    if np.unique(h).size != h.size:
        raise ValueError(f"handles must be distinct; got {h.tolist()}")
    if h.size == 1:
        return np.ones((p.shape[0], 1))
    w = igl.bbw(p, f, h, np.eye(h.size), partition_unity=True)
    # The QP meets its bounds to solver tolerance only; renormalise exactly.
    w = np.clip(w, 0.0, 1.0)
    w /= np.maximum(w.sum(axis=1, keepdims=True), 1e-300)
    return w


def boundary_vertices_at(vertices, boundary, t):
    """Boundary vertices nearest to arc-length positions along the loop.

    Parameters
    ----------
    vertices : array_like, shape (n, 3), float
    boundary : array_like, shape (b,), int
        Boundary vertex indices in loop order; ``t = 0`` is ``boundary[0]``.
    t : array_like, shape (k,), float
        Positions in [0, 1] as a fraction of the loop's length (1 is back at
        the start).

    Returns
    -------
    numpy.ndarray, shape (k,), int64
        Vertex indices.
    """
    v = np.asarray(vertices, dtype=np.float64)
    b = np.asarray(boundary, dtype=np.int64).ravel()
    t = np.asarray(t, dtype=np.float64).ravel()
    if np.any(~np.isfinite(t)) or np.any((t < 0.0) | (t > 1.0)):
        raise ValueError(f"t must lie in [0, 1]; got {t.tolist()}")
    pts = v[b]
    seg = np.linalg.norm(np.roll(pts, -1, axis=0) - pts, axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])           # s[b] = loop length (back at boundary[0])
    target = t * s[-1]
    k = np.abs(target[:, None] - s[None, :]).argmin(axis=1)
    return b[k % b.size]


def nearest_vertices(vertices, points):
    """Index of the vertex nearest to each point, shape (k,) int64."""
    from scipy.spatial import cKDTree

    v = np.asarray(vertices, dtype=np.float64)
    p = np.asarray(points, dtype=np.float64).reshape(-1, v.shape[1])
    return np.asarray(cKDTree(v).query(p)[1], dtype=np.int64).reshape(-1)


def _affine_fit(uv, values):
    """Least-squares ``a + g . (uv - c)`` through samples; returns a callable."""
    c = uv.mean(axis=0)
    a = float(values.mean())
    if uv.shape[0] < 2:
        return lambda x: np.full(x.shape[0], a)
    g, *_ = np.linalg.lstsq(uv - c, values - a, rcond=_AFFINE_RCOND)
    return lambda x: a + (x - c) @ g


def surface_thickness(vertices, faces, handles, values, *, linear_precision=True, uv=None):
    """Per-vertex thickness from sparse samples (section 5.3).

    Parameters
    ----------
    vertices : array_like, shape (n, 3), float
        Disc-like patch (model units).
    faces : array_like, shape (m, 3), int
    handles : array_like, shape (k,), int
        Vertex of each sample (repeats allowed: their values are averaged).
    values : array_like, shape (k,), float
        Thickness at each sample (model units, finite).
    linear_precision : bool
        Add the least-squares affine function of UV (see module docstring);
        False blends the sample values with the weights alone.
    uv : array_like, shape (n, 2), optional
        A precomputed parametrisation; default :func:`arap_parametrisation`.

    Returns
    -------
    numpy.ndarray, shape (n,), float64
        Thickness at every vertex, within ``[min(values), max(values)]``.
    """
    h = np.asarray(handles, dtype=np.int64).ravel()
    val = np.asarray(values, dtype=np.float64).ravel()
    n = np.asarray(vertices).shape[0]
    if h.size == 0 or h.shape != val.shape:
        raise ValueError(f"handles and values must be non-empty and of equal length; got {h.size} and {val.size}")
    if not np.all(np.isfinite(val)):
        raise ValueError(f"values must be finite; got {val.tolist()}")
    if h.min() < 0 or h.max() >= n:
        raise ValueError(f"handles must index vertices 0..{n - 1}; got {h.tolist()}")
    uniq, inverse = np.unique(h, return_inverse=True)
    mean = np.bincount(inverse, weights=val) / np.bincount(inverse)
    lo, hi = float(mean.min()), float(mean.max())
    if hi - lo <= 1e-12 * max(abs(hi), 1.0):
        return np.full(n, lo)
    v, f = validate_mesh(vertices, faces)
    p = arap_parametrisation(v, f) if uv is None else np.asarray(uv, dtype=np.float64)
    w = bounded_biharmonic_weights(p, f, uniq)
    if not linear_precision:
        return np.clip(w @ mean, lo, hi)
    affine = _affine_fit(p[uniq], mean)
    base = affine(p)
    return np.clip(base + w @ (mean - base[uniq]), lo, hi)

