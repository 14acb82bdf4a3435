"""Discrete minimal surfaces with a fixed polygonal boundary (the Plateau
problem), by the iteration of Pinkall & Polthier (1993).

Given the current surface ``M_k``, the next one is the harmonic map of
``M_k``: the positions minimising the Dirichlet energy measured with the
cotan weights of ``M_k``, with the boundary held fixed. That is one sparse
solve ``L(M_k)_II X_I = -L(M_k)_IB X_B`` per step. The area never increases
(area <= Dirichlet energy, with equality for the identity map), and a fixed
point has zero discrete mean curvature at every interior vertex.

Two practical additions keep the iteration well behaved. Edges whose cotan
weight turns negative are flipped between steps (the mesh stays Delaunay,
the harmonic maps keep their maximum principle and no triangle collapses).
And since the area is nearly flat along tangential motions, the steps are
Anderson-mixed over a short history; a mixed point is kept only if it has
less area than the plain step, so the area still decreases monotonically
(up to the small changes flips make). Even so the tangential modes converge
slowly on fine meshes: the area is accurate long before a tight ``tol`` is
met, and ``converged`` reports whether it was.

Refinement levels solve a coarse mesh first, split every triangle 1-to-4 at
edge midpoints (exact on a polygonal boundary) and solve again from there.
Discrete areas converge like ``h^2``, so the level areas extrapolate well by
Richardson's rule (:func:`richardson_area`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy.sparse.linalg import splu

from engine.progress import report
from .curvature import cotan_laplacian, face_areas
from .mesh_init import delaunay_flips, disc_mesh, midpoint_subdivide

__all__ = ["MinimalSurface", "solve_plateau", "relax_plateau", "richardson_area"]

DEFAULT_MAX_ITER = 400

# Steps of history the Anderson mixing extrapolates over.
ANDERSON_MEMORY = 5

# Consecutive steps below tolerance that count as convergence: an
# extrapolated step can change the area very little by chance.
PATIENCE = 3

# Default mesh resolution: boundary pieces per loop perimeter.
DEFAULT_PIECES_PER_PERIMETER = 40


@dataclass(frozen=True)
class MinimalSurface:
    """Result of :func:`solve_plateau`.

    Attributes
    ----------
    vertices : (n, 3) float64, read-only
        Finest-level positions, model units; boundary first.
    faces : (m, 3) int64, read-only
    boundary : (b,) int64, read-only
        Boundary vertex indices in loop order; ``boundary[source >= 0]`` are
        the input polygon vertices.
    source : (b,) int64, read-only
        Input polygon vertex of each boundary vertex, or -1.
    iterations : tuple of int
        Pinkall-Polthier steps taken on each level.
    area_history : (k,) float64, read-only
        Area after the initial fill and after every step, all levels in turn.
    level_areas : tuple of float
        Converged area of each level, coarse to fine.
    level_edge_lengths : tuple of float
        Target boundary edge length of each level (halved per level).
    level_seconds : tuple of float
        Wall time of each level (mesh building included on the first).
    converged : bool
        Every level met ``tol`` within ``max_iter`` steps.
    """

    vertices: np.ndarray
    faces: np.ndarray
    boundary: np.ndarray
    source: np.ndarray
    iterations: tuple
    area_history: np.ndarray
    level_areas: tuple
    level_edge_lengths: tuple
    level_seconds: tuple
    converged: bool

    @property
    def area(self) -> float:
        return self.level_areas[-1]


def _harmonic_step(v, faces, free, fix):
    """Positions of the free vertices after one Pinkall-Polthier step."""
    lap = cotan_laplacian(v, faces).tocsc()
    rows = lap[free]
    a = -rows[:, free]
    rhs = rows[:, fix] @ v[fix]
    return splu(a.tocsc()).solve(np.ascontiguousarray(rhs))


class _Anderson:
    """Anderson mixing of the step map ``x -> G(x)`` over the last few steps.

    Near convergence the slow tangential modes of the iteration contract
    almost linearly; extrapolating over a short history removes most of that
    slowness. The caller keeps an extrapolated point only if it has less
    area than the plain step, so the area still never increases.
    """

    def __init__(self, memory):
        self.memory = memory
        self.xs, self.rs = [], []

    def reset(self):
        self.xs, self.rs = [], []

    def propose(self, x, gx):
        r = gx - x
        self.xs = (self.xs + [x])[-(self.memory + 1):]
        self.rs = (self.rs + [r])[-(self.memory + 1):]
        if len(self.rs) < 2:
            return None
        d_r = np.diff(np.asarray(self.rs), axis=0).T
        d_x = np.diff(np.asarray(self.xs), axis=0).T
        gamma = np.linalg.lstsq(d_r, r, rcond=None)[0]
        return gx - (d_x + d_r) @ gamma


def relax_plateau(vertices, faces, boundary, *, tol=1e-10, max_iter=DEFAULT_MAX_ITER,
                  flips=True, acceleration=ANDERSON_MEMORY, progress=None,
                  progress_offset=0, progress_total=None):
    """Run Pinkall-Polthier steps on a mesh with its boundary held fixed.

    Parameters
    ----------
    vertices : (n, 3) float64
        Start positions (not modified).
    faces : (m, 3) int64
        Triangles (not modified).
    boundary : array_like of int
        Fixed vertex indices.
    tol : float
        Stop once ``PATIENCE`` steps in a row change the area by less than
        ``tol`` times the area.
    max_iter : int
        Step limit.
    flips : bool
        Flip edges with negative cotan weight before and after each step, so
        the harmonic maps keep their maximum principle and no triangle
        degenerates.
    acceleration : int
        Anderson memory (0 for plain steps).
    progress : callable, optional
        ``progress(done, total) -> bool``; False cancels
        (:class:`~engine.progress.Cancelled`). Called once per step.
    progress_offset, progress_total : int
        Where these steps sit in a longer run (for multi-level solves).

    Returns
    -------
    (vertices (n, 3), faces (m, 3), steps, areas (steps + 1,), converged)
    """
    v = np.array(vertices, dtype=np.float64)
    f = np.array(faces, dtype=np.int64)
    fixed = np.zeros(v.shape[0], dtype=bool)
    fixed[np.asarray(boundary, dtype=np.int64)] = True
    free, fix = np.flatnonzero(~fixed), np.flatnonzero(fixed)
    total = progress_total if progress_total is not None else max_iter
    if flips:
        f, _ = delaunay_flips(v, f)
    areas = [float(face_areas(v, f).sum())]
    if free.size == 0:
        return v, f, 0, np.asarray(areas), True
    mixer = _Anderson(acceleration) if acceleration else None
    converged = False
    steps = quiet = 0
    for steps in range(1, max_iter + 1):
        step = _harmonic_step(v, f, free, fix)
        v_next = v.copy()
        v_next[free] = step
        area = float(face_areas(v_next, f).sum())
        if mixer is not None:
            guess = mixer.propose(v[free].ravel(), step.ravel())
            if guess is not None:
                v_try = v.copy()
                v_try[free] = guess.reshape(-1, 3)
                area_try = float(face_areas(v_try, f).sum())
                if area_try <= area:
                    v_next, area = v_try, area_try
                else:
                    mixer.reset()
        v = v_next
        if flips:
            f, flipped = delaunay_flips(v, f)
            if flipped:
                area = float(face_areas(v, f).sum())
                if mixer is not None:
                    mixer.reset()
        areas.append(area)
        report(progress, progress_offset + steps, total)
        quiet = quiet + 1 if abs(areas[-2] - areas[-1]) <= tol * areas[-1] else 0
        if quiet >= PATIENCE:
            converged = True
            break
    return v, f, steps, np.asarray(areas), converged


def _check_options(edge_length, levels, tol, max_iter):
    if isinstance(levels, bool) or not isinstance(levels, (int, np.integer)) or levels < 1:
        raise ValueError(f"levels must be an integer >= 1; got {levels!r}")
    if isinstance(max_iter, bool) or not isinstance(max_iter, (int, np.integer)) or max_iter < 1:
        raise ValueError(f"max_iter must be an integer >= 1; got {max_iter!r}")
    if not (isinstance(tol, (int, float, np.floating)) and math.isfinite(tol) and tol >= 0.0):
        raise ValueError(f"tol must be a finite number >= 0; got {tol!r}")
    if edge_length is not None:
        h = float(edge_length)
        if not math.isfinite(h) or h <= 0.0:
            raise ValueError(f"edge_length must be a finite number > 0; got {edge_length!r}")


def solve_plateau(boundary_points, *, edge_length=None, levels=1, tol=1e-10,
                  max_iter=DEFAULT_MAX_ITER, progress=None):
    """Discrete minimal surface spanning a fixed closed polygon.

    Parameters
    ----------
    boundary_points : array_like, shape (n, 3), float
        Closed polygon (each vertex once, n >= 3), model units; possibly
        skew. Its edges are straight and stay exactly in place.
    edge_length : float, optional
        Target edge length of the coarsest level (model units); default the
        perimeter / 40.
    levels : int
        Number of meshes solved; each after the first is the 1-to-4 midpoint
        subdivision of the previous solution (edge length halved).
    tol : float
        Per level, stop once a step changes the area by less than ``tol``
        times the area.
    max_iter : int
        Step limit per level.
    progress : callable, optional
        ``progress(done, total) -> bool`` once per step; False cancels.

    Returns
    -------
    MinimalSurface

    Raises
    ------
    ValueError
        Bad polygon (fewer than 3 vertices, NaN, repeated consecutive
        vertices) or options.
    engine.progress.Cancelled
        The progress callback returned False.
    """
    _check_options(edge_length, levels, tol, max_iter)
    pts = np.asarray(boundary_points, dtype=np.float64)
    if edge_length is None and pts.ndim == 2 and pts.shape[1] == 3 and pts.shape[0] >= 3 \
            and np.all(np.isfinite(pts)):
        perimeter = float(np.linalg.norm(np.roll(pts, -1, axis=0) - pts, axis=1).sum())
        edge_length = perimeter / DEFAULT_PIECES_PER_PERIMETER
    t0 = time.perf_counter()
    mesh = disc_mesh(pts, edge_length=edge_length)
    v, f, b = mesh.vertices, mesh.faces, mesh.boundary
    source = mesh.source
    total = levels * max_iter
    history, iterations, level_areas, seconds, lengths = [], [], [], [], []
    converged = True
    h = float(edge_length)
    for level in range(levels):
        if level:
            t0 = time.perf_counter()
            v, f, b, _ = midpoint_subdivide(v, f, b)
            src = np.full(b.size, -1, dtype=np.int64)
            src[::2] = source
            source = src
            h *= 0.5
        v, f, steps, areas, ok = relax_plateau(v, f, b, tol=tol, max_iter=max_iter, progress=progress,
                                            progress_offset=level * max_iter, progress_total=total)
        history.append(areas if level == 0 else areas[1:])
        iterations.append(steps)
        level_areas.append(float(areas[-1]))
        lengths.append(h)
        seconds.append(time.perf_counter() - t0)
        converged &= ok
    report(progress, total, total)
    hist = np.concatenate(history)
    for arr in (v, f, b, source, hist):
        arr.setflags(write=False)
    return MinimalSurface(vertices=v, faces=f, boundary=b, source=source,
                          iterations=tuple(iterations), area_history=hist,
                          level_areas=tuple(level_areas), level_edge_lengths=tuple(lengths),
                          level_seconds=tuple(seconds), converged=bool(converged))


def richardson_area(level_areas):
    """Extrapolate areas from successively halved meshes to zero edge length.

    Assumes ``A(h) = A + c2 h^2 + c4 h^4 + ...``; with two levels it removes
    the ``h^2`` term, with three or more it also removes ``h^4`` (a Romberg
    table on the last three levels).

    Parameters
    ----------
    level_areas : sequence of float
        Areas at edge lengths ``h, h/2, h/4, ...`` (at least 2).

    Returns
    -------
    float
    """
    a = [float(x) for x in level_areas]
    if len(a) < 2:
        raise ValueError(f"level_areas must hold at least 2 areas; got {len(a)}")
    a = a[-3:]
    first = [(4.0 * fine - coarse) / 3.0 for coarse, fine in zip(a, a[1:])]
    if len(first) == 1:
        return first[0]
    return (16.0 * first[1] - first[0]) / 15.0
