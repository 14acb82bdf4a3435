"""Conjugate surface construction with edge-length optimisation (Makatura et
al. 2023, Algorithms 1 and 2, sections 4.2.1-4.2.6).

A free-boundary minimal patch P in a convex FBV is found through its dual:
the loop's FBV edges give the dual polygon's corner normals and angles
(:mod:`.fbv`, :mod:`.dual_contour`); only the dual edge lengths are
unknown. CONTOURENERGY(l) builds the dual polygon, solves its Plateau
problem, conjugates (:mod:`.conjugate`), turns the result by a rotation R
fitted once, and measures how well the boundary arcs lie on their planes.
Nelder-Mead searches the lengths in ratio space.

The energy can vanish at more than one patch (in the cube, Schwarz P and a
tetragonal tP member), so the search runs from the user's start and from a
canonical one and keeps the least-area solution (:mod:`.cscm_starts`):
the patch depends on the FBV and the loop's combinatorics, not on where
the vertices sit on their edges (paper Fig. 8).

Choices made here, where the paper leaves room:

* Ratio space is searched on the subspace of ratio changes that keep the
  loop closed and the scale fixed (``N - rank - 1`` dimensions, 2 for the
  Schwarz P hexagon); ratios are clipped to [0.1, 10] and re-closed by
  eqs. 5-6, i.e. a clipped parametrisation instead of bound constraints.
* The overall scale never enters the energy: each candidate is scaled (and
  translated) optimally before measuring, since post-processing scales to
  the FBV anyway.
* The general energy is the mean squared distance of boundary vertices to
  their target planes after that similarity fit. It splits exactly into
  eq. 3 (coplanarity about the fitted plane origins) plus a plane-offset
  form of E_BV (the polyhedron of the fitted planes against H_B, which
  shares its normals) -- used instead of ICP between polyhedra. The AABB
  energy is eq. 4 over all boundary vertices of opposite faces.
* Dual meshes during the search share one connectivity: the Plateau
  solution of the initial contour is deformed to each new contour (boundary
  vertices keep their fractions along the edges, the interior follows
  harmonically) and relaxed by a few Pinkall-Polthier steps
  (:func:`.plateau.relax_plateau`). The energy is then a smooth function of
  the lengths, with no remeshing jumps.
* R is fitted once (Mueller et al. 2005 shape matching of the fitted plane
  normals of a test patch, for both signs of the conjugate; the better fit
  fixes the sign). Because SOLVECONTOUR builds the dual edges along the FBV
  plane normals, the exact R is the identity; a fitted R within
  ``ROTATION_SNAP_DEG`` of it is replaced by the identity (its ~0.1 degree
  of discretisation noise would bias the optimum by ~0.5%).
* FIXBOUNDARY (:mod:`.fix_boundary`): boundary vertices are projected onto
  their plane (corners onto their FBV edge) and the interior follows by a
  harmonic (cotan) extension of those displacements.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize
from scipy.sparse.linalg import splu

from engine.progress import report
from .conjugate import conjugate_surface
from .cscm_starts import choose_run, search_starts
from .curvature import cotan_laplacian, surface_area, surface_report
from .dual_contour import ContourError, close_lengths, dual_directions, initial_lengths
from .fbv import check_conjugate_loop, vertex_frames
from .fix_boundary import fix_boundary
from .plateau import relax_plateau, solve_plateau

__all__ = ["ConjugatePatch", "conjugate_surface_construction", "RATIO_BOUNDS"]

RATIO_BOUNDS = (0.1, 10.0)
# Boundary pieces per dual perimeter: during the search, and for the result.
SEARCH_RESOLUTION = 36
FINAL_RESOLUTION = 128
# Pinkall-Polthier steps after each warm start during the search.
SEARCH_STEPS = 2
_BAD_ENERGY = 1e6
# The dual edges run along the FBV normals, so the exact R is the identity;
# a fitted R this close to it (degrees) only carries discretisation noise,
# which would tilt the patch and bias the optimal lengths.
ROTATION_SNAP_DEG = 2.0
# Initial simplex size (in ratio units) of the re-anchored second stage.
REFINE_SIMPLEX = 0.01
# Energy spread at which the first (coarse) stage stops at the latest; the
# re-anchored second stage refines to ``fatol``. Converged contour energies
# are 1e-9 to 1e-6, so a tighter first stage only spends iterations on the
# warm-start bias the second stage removes (Wei's genus 4: 102 -> 81).
STAGE1_FATOL = 1e-8


@dataclass(frozen=True)
class ConjugatePatch:
    """The primary patch P returned by :func:`conjugate_surface_construction`.

    Attributes
    ----------
    vertices : (n, 3) float64, read-only
        Positions in the FBV (model units).
    faces : (m, 3) int64, read-only
    boundary : (b,) int64, read-only
        Boundary vertices in loop order.
    corners : (k,) int64, read-only
        Vertex index of every input loop vertex.
    boundary_planes : (b, 2) int64, read-only
        Planes each boundary vertex was snapped to (second entry -1 except at
        corners).
    lengths : (k,) float64, read-only
        Optimised dual edge lengths (model units of the dual).
    report : dict
        ``iterations`` and ``evaluations`` of Nelder-Mead in the search whose
        patch was kept (``start``: ``'user'`` or ``'canonical'``), summed
        over all starts in ``iterations_total`` / ``evaluations_total``,
        ``starts`` (one dict per search: name, initial and final lengths,
        energies, area, iterations, evaluations, converged), ``energy``
        (final, of the kept search) and ``initial_energy`` (at the user's
        start), ``energy_history`` (of the kept search), ``converged``,
        ``dimensions``, ``rotation`` (3x3 list), ``conjugate_sign``,
        ``scale``, ``snap_max`` (largest snap distance), ``area``,
        ``max_abs_H`` / ``mean_abs_H`` (1/model units), ``seconds`` and
        ``seconds_search`` / ``seconds_final``, ``energy_kind``.
    """

    vertices: np.ndarray
    faces: np.ndarray
    boundary: np.ndarray
    corners: np.ndarray
    boundary_planes: np.ndarray
    lengths: np.ndarray
    report: dict = field(compare=False)


# ------------------------------------------------------------------ progress

class _Progress:
    """One progress bar over the whole construction.

    Energy evaluations are counted against an estimate (Nelder-Mead takes
    about two per iteration); inner solves only poll for cancellation.
    """

    def __init__(self, callback, total):
        self.callback, self.total, self.done = callback, int(total), 0

    def tick(self):
        self.done += 1
        report(self.callback, min(self.done, self.total - 1), self.total)

    def poll(self, _done=0, _total=0):
        report(self.callback, min(self.done, self.total - 1), self.total)
        return True

    def finish(self):
        report(self.callback, self.total, self.total)


# ---------------------------------------------------------------- dual meshes

def _boundary_layout(source, n_corners):
    """Edge index and fraction along it for every boundary vertex."""
    b = source.size
    first = np.flatnonzero(source >= 0)
    edge = np.empty(b, dtype=np.int64)
    frac = np.empty(b)
    for k, start in enumerate(first):
        stop = first[k + 1] if k + 1 < first.size else b
        count = stop - start
        edge[start:stop] = source[start]
        frac[start:stop] = np.arange(count) / count
    if not np.array_equal(np.sort(source[first]), np.arange(n_corners)):
        raise RuntimeError("Plateau boundary does not keep every contour corner")
    return edge, frac


class _DualFamily:
    """Dual Plateau meshes of one connectivity, warm-started from a reference."""

    def __init__(self, corners, *, resolution, steps, progress):
        perimeter = float(np.linalg.norm(np.roll(corners, -1, axis=0) - corners, axis=1).sum())
        sol = solve_plateau(corners, edge_length=perimeter / resolution, tol=1e-6,
                            max_iter=40, progress=progress.poll if progress else None)
        self.faces = np.array(sol.faces)
        self.boundary = np.array(sol.boundary)
        self.source = np.array(sol.source)
        self.reference = np.array(sol.vertices)
        self.edge, self.frac = _boundary_layout(self.source, corners.shape[0])
        self.steps = steps
        n = self.reference.shape[0]
        fixed = np.zeros(n, dtype=bool)
        fixed[self.boundary] = True
        self.free = np.flatnonzero(~fixed)
        lap = cotan_laplacian(self.reference, self.faces).tocsc()
        self._coupling = lap[self.free][:, self.boundary]
        self._solver = splu((-lap[self.free][:, self.free]).tocsc()) if self.free.size else None

    def boundary_points(self, corners):
        nxt = np.roll(corners, -1, axis=0)
        return corners[self.edge] + self.frac[:, None] * (nxt[self.edge] - corners[self.edge])

    def realise(self, corners):
        """Dual mesh vertices spanning the polygon ``corners``."""
        v = self.reference.copy()
        moved = self.boundary_points(corners)
        shift = moved - v[self.boundary]
        v[self.boundary] = moved
        if self._solver is not None:
            v[self.free] += self._solver.solve(np.ascontiguousarray(self._coupling @ shift))
        if self.steps:
            # No edge flips: one connectivity keeps the energy smooth in l.
            v = relax_plateau(v, self.faces, self.boundary, tol=0.0, max_iter=self.steps,
                              flips=False)[0]
        return v


# ------------------------------------------------------------ energies, fits

def _plane_groups(arc_planes, edge, source, n_planes):
    """Boundary positions (indices into the boundary loop) on each plane."""
    groups = [[] for _ in range(n_planes)]
    n = arc_planes.size
    for k, (e, s) in enumerate(zip(edge, source)):
        groups[int(arc_planes[e])].append(k)
        if s >= 0:
            groups[int(arc_planes[(e - 1) % n])].append(k)
    return [np.asarray(g, dtype=np.int64) for g in groups]


def _fit_similarity(points_by_plane, normals, offsets):
    """Scale s and translation t minimising sum (n_k.(s p + t) - h_k)^2."""
    rows, rhs = [], []
    for k, pts in enumerate(points_by_plane):
        if pts.shape[0] == 0:
            continue
        nk = normals[k]
        rows.append(np.column_stack([pts @ nk, np.tile(nk, (pts.shape[0], 1))]))
        rhs.append(np.full(pts.shape[0], offsets[k]))
    a, b = np.vstack(rows), np.concatenate(rhs)
    x, *_ = np.linalg.lstsq(a, b, rcond=None)
    return float(x[0]), x[1:], a @ x - b


def _energy_planes(q, groups, fbv):
    pts = [q[g] for g in groups]
    s, _, resid = _fit_similarity(pts, fbv.normals, fbv.offsets)
    if s <= 0.0:
        return _BAD_ENERGY
    return float(np.mean(resid ** 2)) / fbv.diameter ** 2


def _aabb_pairs(fbv, groups):
    """Per axis: (axis, low group, high group, target distance)."""
    out = []
    for axis in range(3):
        ks = [k for k in range(fbv.n_planes) if abs(abs(fbv.normals[k, axis]) - 1.0) < 1e-12]
        lo = min(ks, key=lambda k: fbv.normals[k, axis])
        hi = max(ks, key=lambda k: fbv.normals[k, axis])
        width = fbv.offsets[hi] + fbv.offsets[lo]
        out.append((axis, groups[lo], groups[hi], float(width)))
    return out


def _energy_aabb(q, pairs):
    """Eq. 4 with the scale eliminated in closed form."""
    w, d2 = [], []
    for axis, lo, hi, width in pairs:
        diff = q[hi, axis][:, None] - q[lo, axis][None, :]
        w.append((diff ** 2).ravel())
        d2.append(np.full(diff.size, width ** 2))
    w, d2 = np.concatenate(w), np.concatenate(d2)
    t = float(w @ d2) / float(w @ w)
    if not t > 0.0:
        return _BAD_ENERGY
    return float(np.mean((t * w - d2) ** 2)) / float(np.mean(d2 ** 2))


def _fitted_normals(p, groups):
    """Unit normal of the plane fitted to each group, pointing away from the patch."""
    centre = p.mean(axis=0)
    out = np.full((len(groups), 3), np.nan)
    weight = np.zeros(len(groups))
    for k, g in enumerate(groups):
        if g.size < 3:
            continue
        pts = p[g]
        c = pts.mean(axis=0)
        _, sv, vt = np.linalg.svd(pts - c)
        if sv[1] <= 1e-9 * max(sv[0], 1e-300):
            continue                                   # collinear: no plane
        m = vt[2]
        out[k] = m if m @ (c - centre) > 0.0 else -m
        weight[k] = g.size
    return out, weight


def _shape_matching_rotation(target, fitted, weight):
    """Rotation R with R m_k ~ n_k (Mueller et al. 2005: polar decomposition)."""
    use = weight > 0
    a = (target[use] * weight[use, None]).T @ fitted[use]
    u, _, vt = np.linalg.svd(a)
    d = np.sign(np.linalg.det(u @ vt)) or 1.0
    r = u @ np.diag([1.0, 1.0, d]) @ vt
    resid = float(np.sum(weight[use] * np.sum((fitted[use] @ r.T - target[use]) ** 2, axis=1)))
    return r, resid / float(weight[use].sum())


# -------------------------------------------------------------- the search

def _reduced_basis(base, directions):
    """Ratio directions keeping the loop closed and the scale fixed."""
    m = directions.T * base[None, :]                     # closure of l = base * ratio
    _, sv, vt = np.linalg.svd(m)
    rank = int(np.sum(sv > 1e-10 * sv.max()))
    null = vt[rank:].T                                   # (n, n - rank)
    ones = np.ones(base.size) / math.sqrt(base.size)
    null = null - np.outer(ones, ones @ null)
    u, sv2, _ = np.linalg.svd(null, full_matrices=False)
    keep = sv2 > 1e-8
    return u[:, keep]


class _ContourEnergy:
    """CONTOURENERGY (Algorithm 2) for one loop, with its cached pieces."""

    def __init__(self, fbv, loop, directions, base, energy_kind, progress, *,
                 resolution=SEARCH_RESOLUTION, steps=SEARCH_STEPS, anchor=None, frame=None,
                 history=None):
        self.fbv, self.loop, self.dirs, self.base = fbv, loop, directions, base
        self.kind = energy_kind
        self.progress, self.resolution = progress, resolution
        anchor = base if anchor is None else anchor
        self.family = _DualFamily(self.corners(anchor), resolution=resolution, steps=steps,
                                  progress=progress)
        fam = self.family
        self.groups = _plane_groups(loop.arc_planes, fam.edge, fam.source, fbv.n_planes)
        self.vgroups = [fam.boundary[g] for g in self.groups]
        self.pairs = _aabb_pairs(fbv, self.vgroups) if energy_kind == "aabb" else None
        # The frame (R, conjugate sign, fit residual, fitted angle) is fitted
        # once, on the first start's test patch, and shared by every search.
        self.frame = self._fit_rotation() if frame is None else frame
        self.rotation, self.sign, self.rotation_residual, self.fitted_angle = self.frame
        self.history = [] if history is None else history

    def corners(self, lengths):
        steps = lengths[:, None] * self.dirs
        return np.vstack([np.zeros(3), np.cumsum(steps, axis=0)[:-1]])

    def _fit_rotation(self):
        """Algorithm 1: R from a test primary surface (both conjugate signs tried)."""
        dual = self.family.realise(self.corners(self.base))
        best = None
        for sign in (1, -1):
            p = conjugate_surface(dual, self.family.faces, sign=sign).vertices
            fitted, weight = _fitted_normals(p, self.vgroups)
            if np.count_nonzero(weight) < 2:
                raise ContourError("fewer than two boundary arcs span a plane; cannot align "
                                   "the conjugate patch to the FBV")
            r, resid = _shape_matching_rotation(self.fbv.normals, fitted, weight)
            if best is None or resid < best[2] - 1e-12:
                best = (r, sign, resid)
        r, sign, resid = best
        angle = math.degrees(math.acos(float(np.clip((np.trace(r) - 1.0) / 2.0, -1.0, 1.0))))
        if angle <= ROTATION_SNAP_DEG:
            r = np.eye(3)
        return r, sign, resid, angle

    def lengths(self, ratios):
        lo, hi = RATIO_BOUNDS
        l_in = self.base * np.clip(ratios, lo, hi)
        closed, ok = close_lengths(l_in, self.dirs, minimum=0.05 * lo * float(self.base.min()))
        return closed, ok

    def primary(self, lengths, family=None):
        fam = family or self.family
        dual = fam.realise(self.corners(lengths))
        conj = conjugate_surface(dual, fam.faces, sign=self.sign)
        return conj.vertices @ self.rotation.T, conj

    def area(self, lengths):
        """Area of the primary patch at ``lengths``, scaled to the FBV (not counted).

        The dual is solved afresh rather than warm-started, so the area
        carries no bias from where the dual meshes were anchored.
        """
        corners = self.corners(lengths)
        sol = solve_plateau(corners, edge_length=float(lengths.sum()) / self.resolution,
                            tol=1e-6, max_iter=40,
                            progress=self.progress.poll if self.progress else None)
        faces, boundary, source = np.array(sol.faces), np.array(sol.boundary), np.array(sol.source)
        q = conjugate_surface(sol.vertices, faces, sign=self.sign).vertices @ self.rotation.T
        edge, _ = _boundary_layout(source, corners.shape[0])
        groups = _plane_groups(self.loop.arc_planes, edge, source, self.fbv.n_planes)
        s, _, _ = _fit_similarity([q[boundary[g]] for g in groups], self.fbv.normals,
                                  self.fbv.offsets)
        return s * s * surface_area(q, faces)

    def __call__(self, ratios):
        closed, ok = self.lengths(ratios)
        if not ok:
            e = _BAD_ENERGY
        else:
            q, _ = self.primary(closed)
            e = _energy_aabb(q, self.pairs) if self.kind == "aabb" else \
                _energy_planes(q, self.vgroups, self.fbv)
        self.history.append(e)
        if self.progress is not None:
            self.progress.tick()
        return e


def _energy_kind(fbv, loop, energy):
    if energy not in ("auto", "aabb", "planes"):
        raise ValueError(f"energy must be 'auto', 'aabb' or 'planes'; got {energy!r}")
    used = set(loop.arc_planes.tolist())
    full = fbv.is_aabb and used == set(range(6))
    if energy == "aabb" and not full:
        raise ValueError("energy='aabb' needs a cuboid FBV whose six faces all carry an arc")
    return "aabb" if (energy == "aabb" or (energy == "auto" and full)) else "planes"


def conjugate_surface_construction(fbv, loop_points, *, energy="auto", max_iter=80,
                                   xatol=1e-4, fatol=1e-10, search_resolution=SEARCH_RESOLUTION,
                                   final_resolution=FINAL_RESOLUTION, search_steps=SEARCH_STEPS,
                                   initial=None, restart=True, progress=None):
    """Free-boundary minimal patch in an FBV by the conjugate surface method.

    Parameters
    ----------
    fbv : BoundingVolume
        The bounding planes B (outward normals).
    loop_points : array_like, shape (k, 3), float
        Closed loop L; every vertex on an FBV edge, every loop edge on a
        face (model units).
    energy : {'auto', 'aabb', 'planes'}
        Eq. 4 (cuboid FBV with every face used) or the plane-distance
        energy (eq. 3 + E_BV); 'auto' picks eq. 4 when it applies.
    max_iter : int
        Nelder-Mead iteration cap.
    xatol, fatol : float
        Nelder-Mead stopping tolerances on the reduced ratio coordinates and
        on the (dimensionless) energy.
    search_resolution, final_resolution : int
        Boundary pieces per dual perimeter during the search and for P.
    search_steps : int
        Pinkall-Polthier steps after each warm start during the search.
    initial : (k,) float, optional
        Initial dual lengths instead of the section 4.2.4 heuristic.
    restart : bool
        Also search from the canonical start and keep the least-area
        solution (:mod:`.cscm_starts`); False searches from the user's
        start only.
    progress : callable, optional
        ``progress(done, total) -> bool``, called per energy evaluation
        (``total`` estimates two per Nelder-Mead iteration and start) and
        per Plateau step; False cancels
        (:class:`~engine.progress.Cancelled`).

    Returns
    -------
    ConjugatePatch

    Raises
    ------
    FBVError
        The loop breaks an FBV requirement (vertex and rule named).
    ContourError
        The dual polygon cannot be built or closed.
    """
    t0 = time.perf_counter()
    if isinstance(max_iter, bool) or not isinstance(max_iter, (int, np.integer)) or max_iter < 0:
        raise ValueError(f"max_iter must be an integer >= 0; got {max_iter!r}")
    for name, value in (("search_resolution", search_resolution),
                        ("final_resolution", final_resolution)):
        if not isinstance(value, (int, np.integer)) or value < 8:
            raise ValueError(f"{name} must be an integer >= 8; got {value!r}")
    loop = check_conjugate_loop(fbv, loop_points)
    kind = _energy_kind(fbv, loop, energy)
    v_angles, v_normals = vertex_frames(fbv, loop)
    dirs = dual_directions(v_angles, v_normals)
    l_init = initial_lengths(fbv, loop) if initial is None else np.asarray(initial, float).ravel()
    if l_init.shape != (loop.points.shape[0],) or np.any(~(l_init > 0.0)):
        raise ValueError(f"initial must hold {loop.points.shape[0]} positive lengths; got {l_init}")
    starts = search_starts(fbv, loop, l_init, canonical=restart)
    bar = _Progress(progress, len(starts) * (2 * max_iter + 4) + 4) if progress is not None \
        else None
    options = {"max_iter": max_iter, "xatol": xatol, "fatol": fatol,
               "resolution": search_resolution, "steps": search_steps}
    t_search = time.perf_counter()
    runs = [_search(fbv, loop, dirs, kind, starts[0], bar, None, **options)]
    for start in starts[1:] if runs[0].dimensions else ():   # nothing to search: one start
        try:
            runs.append(_search(fbv, loop, dirs, kind, start, bar, runs[0].objective.frame,
                                **options))
        except ContourError:
            continue                 # the user's loop closes; a start that cannot is dropped
    if len(runs) > 1:
        for r in runs:
            r.area = r.objective.area(r.lengths)
    chosen = runs[choose_run([r.energy for r in runs], [r.area for r in runs])]
    objective = chosen.objective
    t_final = time.perf_counter()
    patch = _final_patch(objective, chosen.lengths, final_resolution, bar)
    if bar is not None:
        bar.finish()
    seconds = time.perf_counter() - t0
    patch.report.update({
        "iterations": chosen.iterations, "stage_iterations": chosen.stage_iterations,
        "evaluations": len(objective.history), "converged": chosen.converged,
        "dimensions": chosen.dimensions, "initial_energy": runs[0].initial_energy,
        "energy": chosen.energy,
        "energy_history": list(objective.history), "energy_kind": kind,
        "start": chosen.name, "starts": [r.summary() for r in runs],
        "iterations_total": sum(r.iterations for r in runs),
        "evaluations_total": sum(len(r.objective.history) for r in runs),
        "rotation": objective.rotation.tolist(), "conjugate_sign": objective.sign,
        "rotation_residual": objective.rotation_residual,
        "fitted_rotation_deg": objective.fitted_angle,
        "initial_lengths": l_init.tolist(),
        "seconds": seconds, "seconds_search": t_final - t_search,
        "seconds_final": time.perf_counter() - t_final})
    return patch


@dataclass
class _Run:
    """One search (both stages) from one start."""

    name: str
    initial_lengths: np.ndarray
    objective: _ContourEnergy
    lengths: np.ndarray
    initial_energy: float
    energy: float
    iterations: int
    stage_iterations: list
    converged: bool
    dimensions: int
    area: float = float("nan")             # set only when several runs compete

    def summary(self):
        return {"name": self.name, "initial_lengths": self.initial_lengths.tolist(),
                "lengths": self.lengths.tolist(), "initial_energy": self.initial_energy,
                "energy": self.energy, "area": self.area, "iterations": self.iterations,
                "stage_iterations": list(self.stage_iterations),
                "evaluations": len(self.objective.history), "converged": self.converged}


def _search(fbv, loop, dirs, kind, start, bar, frame, *, max_iter, xatol, fatol, resolution,
            steps):
    """Nelder-Mead in two stages from ``start``; ``frame`` None fits R here."""
    base, ok = close_lengths(start.lengths, dirs)
    if not ok:
        base = _positive_closure(start.lengths, dirs)
    basis = _reduced_basis(base, dirs)
    objective, ratios, nit, converged, e0 = None, np.ones(base.size), 0, True, None
    stage_iterations, final_energy = [], None
    for stage, step in enumerate((0.1, REFINE_SIMPLEX)):
        # Stage 2 re-anchors the dual meshes at the stage-1 optimum, removing
        # the bias of warm starts far from the reference contour.
        objective = _ContourEnergy(fbv, loop, dirs, base, kind, bar, resolution=resolution,
                                   steps=steps,
                                   anchor=objective.lengths(ratios)[0] if stage else None,
                                   frame=objective.frame if stage else frame,
                                   history=objective.history if stage else None)
        if e0 is None:
            e0 = final_energy = objective(ratios)
        if not (basis.shape[1] and max_iter - nit > 0):
            break
        res = _nelder_mead(objective, ratios, basis, step, max_iter - nit,
                           xatol if stage else 10.0 * xatol,
                           fatol if stage else max(fatol, STAGE1_FATOL))
        ratios = ratios + basis @ res.x
        nit += int(res.nit)
        stage_iterations.append(int(res.nit))
        converged = bool(res.success)
        final_energy = float(res.fun)
    lengths, _ = objective.lengths(ratios)
    return _Run(start.name, np.asarray(start.lengths, dtype=np.float64), objective, lengths,
                float(e0), float(final_energy), nit, stage_iterations, converged,
                int(basis.shape[1]))


def _nelder_mead(objective, ratios, basis, step, max_iter, xatol, fatol):
    """Nelder-Mead on reduced ratio coordinates ``z``: ratios + basis @ z."""
    dim = basis.shape[1]
    simplex = np.vstack([np.zeros(dim), step * np.eye(dim)])
    return minimize(lambda z: objective(ratios + basis @ z), np.zeros(dim), method="Nelder-Mead",
                    options={"maxiter": int(max_iter), "xatol": xatol,
                             "fatol": fatol, "initial_simplex": simplex})


def _positive_closure(l_init, dirs):
    """Closed lengths >= 10% of the request, nearest in least squares."""
    from scipy.optimize import minimize as _min

    lo = RATIO_BOUNDS[0] * l_init
    res = _min(lambda l: float(np.sum((l - l_init) ** 2)), np.maximum(l_init, lo),
               jac=lambda l: 2.0 * (l - l_init), method="SLSQP",
               bounds=list(zip(lo, [None] * l_init.size)),
               constraints=[{"type": "eq", "fun": lambda l: dirs.T @ l,
                             "jac": lambda l: dirs.T}])
    if not res.success or np.linalg.norm(dirs.T @ res.x) > 1e-8 * float(l_init.sum()):
        raise ContourError("no closed dual polygon with positive lengths near the initial "
                           "lengths; check the loop")
    return res.x


# ---------------------------------------------------------- post-processing

def _final_patch(objective, lengths, resolution, bar):
    fbv, loop = objective.fbv, objective.loop
    corners = objective.corners(lengths)
    perimeter = float(lengths.sum())
    sol = solve_plateau(corners, edge_length=perimeter / resolution, tol=1e-7, max_iter=40,
                        progress=bar.poll if bar is not None else None)
    faces, boundary, source = np.array(sol.faces), np.array(sol.boundary), np.array(sol.source)
    conj = conjugate_surface(sol.vertices, faces, sign=objective.sign)
    q = conj.vertices @ objective.rotation.T
    edge, _ = _boundary_layout(source, corners.shape[0])
    groups = _plane_groups(loop.arc_planes, edge, source, fbv.n_planes)
    s, t, _ = _fit_similarity([q[boundary[g]] for g in groups], fbv.normals, fbv.offsets)
    q = s * q + t
    n = loop.points.shape[0]
    planes = np.full((boundary.size, 2), -1, dtype=np.int64)
    planes[:, 0] = loop.arc_planes[edge]
    at_corner = source >= 0
    planes[at_corner, 1] = loop.arc_planes[(edge[at_corner] - 1) % n]
    q, snap_max = fix_boundary(q, faces, boundary, planes, fbv)
    corner_idx = np.empty(n, dtype=np.int64)
    corner_idx[source[at_corner]] = boundary[at_corner]
    stats = surface_report(q, faces, boundary)
    rep = {"scale": s, "snap_max": snap_max,
           "closure_error": conj.closure_error * s, "area": stats["area"],
           "max_abs_H": stats["max_abs_H"], "mean_abs_H": stats["mean_abs_H"],
           "plateau_iterations": list(sol.iterations)}
    for arr in (q, faces, boundary, corner_idx, planes, lengths):
        arr.setflags(write=False)
    return ConjugatePatch(vertices=q, faces=faces, boundary=boundary, corners=corner_idx,
                          boundary_planes=planes, lengths=lengths, report=rep)
