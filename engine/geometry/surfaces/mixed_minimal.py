"""Minimal surfaces over partly fixed, partly sliding boundaries (paper
section 5.1.1, the *mixed minimal* solver).

Mean-curvature flow, implicit in time and re-weighted every step: with the
cotan Laplacian ``L`` and the mixed-area mass ``M`` of the current surface,
the next positions solve ``(M - dt L) X' = M X``. Fixed boundary samples are
Dirichlet data. A sliding sample may move only within its bounding plane (or
along the line two planes share, at a corner between two sliding segments):
its displacement is written in a basis of that plane, so the linear system is
the flow's energy restricted to the allowed motions and the sample meets its
plane orthogonally in the limit (the natural boundary condition). After each
step sliding samples are projected back onto their planes to remove
round-off. The flow stops when the area stagnates.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from engine.progress import report
from .boundary import BoundaryLoop, sample_loop
from .curvature import cotan_laplacian, face_areas, mixed_areas, surface_report
from .mesh_init import delaunay_flips, disc_mesh

__all__ = ["MixedMinimalSurface", "solve_mixed_minimal"]

DEFAULT_PIECES_PER_PERIMETER = 40
# Consecutive stagnant steps that end the flow.
PATIENCE = 3


@dataclass(frozen=True)
class MixedMinimalSurface:
    """Result of :func:`solve_mixed_minimal`.

    Attributes
    ----------
    vertices : (n, 3) float64, read-only
        Positions (model units); boundary first, in loop order.
    faces : (m, 3) int64, read-only
    boundary : (b,) int64, read-only
        Boundary vertex indices in loop order.
    sliding : (b,) bool, read-only
        Boundary vertices that were free to slide.
    segment : (b,) int64, read-only
        Loop segment each boundary vertex belongs to.
    iterations : int
    area_history : (iterations + 1,) float64, read-only
    area : float
        Final area (model units squared).
    max_abs_H, mean_abs_H : float
        Mean curvature over interior vertices (1 / model units).
    converged : bool
        The area stagnated before ``max_iter``.
    """

    vertices: np.ndarray
    faces: np.ndarray
    boundary: np.ndarray
    sliding: np.ndarray
    segment: np.ndarray
    iterations: int
    area_history: np.ndarray
    area: float
    max_abs_H: float
    mean_abs_H: float
    converged: bool


def _plane_basis(normals):
    """Orthonormal basis (k, 3) of the directions allowed by ``normals``."""
    if normals.shape[0] == 1:
        n = normals[0]
        helper = np.eye(3)[int(np.argmin(np.abs(n)))]
        t1 = np.cross(n, helper)
        t1 /= np.linalg.norm(t1)
        return np.vstack([t1, np.cross(n, t1)])
    d = np.cross(normals[0], normals[1])
    return (d / np.linalg.norm(d))[None, :]


def _constraints(samples, n_vertices):
    """Sparse basis ``P`` (3n, k) of allowed motions and the plane table.

    Interior vertices move freely, fixed ones not at all, sliding ones within
    their plane(s).
    """
    rows, cols, vals = [], [], []
    col = 0
    b = samples.points.shape[0]
    sliding = []
    for i in range(n_vertices):
        if i < b:
            if samples.fixed[i]:
                continue
            planes = samples.planes[i][~np.isnan(samples.planes[i, :, 0])]
            basis = _plane_basis(planes[:, :3])
            sliding.append((i, planes))
        else:
            basis = np.eye(3)
        for vec in basis:
            rows += [3 * i, 3 * i + 1, 3 * i + 2]
            cols += [col] * 3
            vals += vec.tolist()
            col += 1
    basis = sp.csr_matrix((vals, (rows, cols)), shape=(3 * n_vertices, col))
    return basis, sliding


def _project_onto_planes(v, sliding):
    for i, planes in sliding:
        normals, offsets = planes[:, :3], planes[:, 3]
        # Closest point on the intersection of the planes (one or two).
        gram = normals @ normals.T
        v[i] -= normals.T @ np.linalg.solve(gram, normals @ v[i] - offsets)


def _check_options(time_step, tol, max_iter, edge_length):
    if isinstance(max_iter, bool) or not isinstance(max_iter, (int, np.integer)) or max_iter < 1:
        raise ValueError(f"max_iter must be an integer >= 1; got {max_iter!r}")
    for name, value in (("time_step", time_step), ("tol", tol)):
        if not isinstance(value, (int, float, np.floating)) or not math.isfinite(value) or value < 0:
            raise ValueError(f"{name} must be a finite number >= 0; got {value!r}")
    if time_step <= 0:
        raise ValueError(f"time_step must be > 0; got {time_step!r}")
    if edge_length is not None and not (math.isfinite(float(edge_length)) and float(edge_length) > 0):
        raise ValueError(f"edge_length must be a finite number > 0; got {edge_length!r}")


def solve_mixed_minimal(loop, *, edge_length=None, time_step=0.05, tol=1e-7, max_iter=500,
                        progress=None):
    """Minimal surface with fixed and sliding boundary segments.

    Parameters
    ----------
    loop : BoundaryLoop
        Straight and smooth segments stay fixed (smooth runs splined);
        sliding segments move within their planes.
    edge_length : float, optional
        Target edge length (model units); default the perimeter / 40.
    time_step : float
        Flow time step as a fraction of ``R^2``, ``R`` = perimeter / (2 pi);
        the flow is implicit, so large steps are stable and fast.
    tol : float
        Stop once ``PATIENCE`` steps in a row change the area by less than
        ``tol`` times the area.
    max_iter : int
        Step limit.
    progress : callable, optional
        ``progress(done, total) -> bool`` once per step; False cancels.

    Returns
    -------
    MixedMinimalSurface

    Raises
    ------
    ValueError
        Not a BoundaryLoop, no fixed segment (a fully sliding loop needs the
        conjugate solver), or bad options.
    engine.progress.Cancelled
        The progress callback returned False.
    """
    if not isinstance(loop, BoundaryLoop):
        raise ValueError(f"loop must be a BoundaryLoop (see boundary_loop); got {type(loop).__name__}")
    if all(m == "sliding" for m in loop.modes):
        raise ValueError("every segment of loop slides; the mixed minimal solver needs at least "
                         "one fixed segment (use the conjugate solver for fully sliding loops)")
    _check_options(time_step, tol, max_iter, edge_length)
    perimeter = float(np.linalg.norm(np.roll(loop.points, -1, axis=0) - loop.points, axis=1).sum())
    h = perimeter / DEFAULT_PIECES_PER_PERIMETER if edge_length is None else float(edge_length)
    samples = sample_loop(loop, edge_length=h)
    mesh = disc_mesh(samples.points)
    v, f = mesh.vertices.copy(), mesh.faces
    n = v.shape[0]
    basis, sliding = _constraints(samples, n)
    _project_onto_planes(v, sliding)
    dt = time_step * (perimeter / (2.0 * math.pi)) ** 2
    f, _ = delaunay_flips(v, f)
    areas = [float(face_areas(v, f).sum())]
    quiet = steps = 0
    converged = basis.shape[1] == 0          # nothing may move
    eye3 = sp.identity(3, format="csr")
    while not converged and steps < max_iter:
        steps += 1
        lap = cotan_laplacian(v, f)
        mass = sp.diags(mixed_areas(v, f))
        system = sp.kron(mass - dt * lap, eye3, format="csr")
        reduced = (basis.T @ system @ basis).tocsc()
        rhs = basis.T @ (dt * (lap @ v)).ravel()
        v = v + (basis @ splu(reduced).solve(rhs)).reshape(n, 3)
        _project_onto_planes(v, sliding)
        f, _ = delaunay_flips(v, f)
        areas.append(float(face_areas(v, f).sum()))
        report(progress, steps, max_iter)
        quiet = quiet + 1 if abs(areas[-2] - areas[-1]) <= tol * areas[-1] else 0
        converged = quiet >= PATIENCE
    stats = surface_report(v, f, mesh.boundary)
    is_sliding = ~samples.fixed
    hist = np.asarray(areas)
    for arr in (v, f, mesh.boundary, is_sliding, samples.segment, hist):
        arr.setflags(write=False)
    return MixedMinimalSurface(vertices=v, faces=f, boundary=mesh.boundary, sliding=is_sliding,
                               segment=samples.segment, iterations=int(steps), area_history=hist,
                               area=stats["area"], max_abs_H=stats["max_abs_H"],
                               mean_abs_H=stats["mean_abs_H"], converged=bool(converged))
