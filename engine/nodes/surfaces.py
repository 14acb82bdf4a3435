"""Surface, Dual Surface and Associate Family nodes (paper 3.1, 5.1, 5.3, 6.3).

The Surface node joins edge chains into one closed loop and spans it with a
patch; its ``type`` picks the solver (section 5.1):

``direct``
    a thin shell pinned to the loop (:func:`solve_thin_shell`); smooth
    chains are splined, straight ones stay straight.
``mixed_minimal``
    a minimal surface whose straight chains are fixed and whose smooth
    chains slide in the FBV face they lie on (:func:`solve_mixed_minimal`).
    A chain on several faces slides in the one most across the loop (the
    face whose normal is nearest to perpendicular to the loop's fitted
    plane; faces holding the whole loop are skipped); a smooth chain on no
    face is refused. With no smooth chain it is the Plateau problem, solved by
    :func:`solve_plateau` (Pinkall-Polthier).
``conjugate``
    the automated conjugate surface construction (:mod:`.cscm`): every
    segment slides on its FBV face whatever the chains' smoothness (the
    paper's Fig. 5c); the loop must meet the section 6.3 requirements.

The fundamental bounding volume (``fbv``) is fitted to the loop by
:func:`~engine.geometry.surfaces.fbv.fit_fbv` (a cuboid, half-box prism or
tetrahedron of the loop's bounding box); of the candidates that hold every
loop vertex the one breaking the fewest requirements of the surface type
wins. ``custom`` takes the half-spaces ``n . x <= d`` of ``fbv_planes``.

Thickness (section 5.3) comes from sparse samples: ``thickness`` holds
``[t, value]`` pairs with t the arc-length position along the patch boundary
(t = 0 at the loop's first vertex: the first vertex of the first connected
chain, increasing along that chain), ``thickness_points`` holds
``[[x, y, z], value]`` pairs at the patch vertex nearest to each point. The
values are spread by :func:`surface_thickness` (bounded biharmonic weights
over an ARAP parametrisation).
"""

from __future__ import annotations

import math
import time

import numpy as np

from engine.geometry.surfaces.associate import BONNET_ANGLE_DEG, associate_surface
from engine.geometry.surfaces.boundary import loop_from_chains
from engine.geometry.surfaces.conjugate import conjugate_surface
from engine.geometry.surfaces.cscm import conjugate_surface_construction
from engine.geometry.surfaces.curvature import face_areas, surface_report
from engine.geometry.surfaces.dual_contour import ContourError
from engine.geometry.surfaces.fbv import (FBV_KINDS, FBVError, FBVFitError, conjugate_violations,
                                          fit_fbv, locate_points, sliding_planes)
from engine.geometry.surfaces.mesh_init import boundary_loop_of
from engine.geometry.surfaces.mixed_minimal import solve_mixed_minimal
from engine.geometry.surfaces.plateau import solve_plateau
from engine.geometry.surfaces.thickness_profile import (boundary_vertices_at, nearest_vertices,
                                                        surface_thickness)
from engine.geometry.surfaces.thin_shell import solve_thin_shell
from engine.graph.errors import NodeInputError
from engine.graph.node import NodeType, register
from engine.graph.schema import Param, Port
from engine.geometry.surfaces.values import SurfaceReport
from engine.geometry.values import Skeleton, SurfaceElement

from .lines import order_chains

SURFACE_TYPES = ("direct", "mixed_minimal", "conjugate")
QUARTER_TURNS = ("+90", "-90")

# Conjugate search resolution (cscm's default) and the floor of the final one.
_SEARCH_PIECES = 36
_MIN_PIECES = 8
# A conjugate patch whose contour energy stays above this fits its FBV badly.
_CONJUGATE_ENERGY_WARN = 1e-3
# Relative area change per Pinkall-Polthier step that ends a fixed-boundary solve.
_PLATEAU_TOL = 1e-9
# Most entries of the energy history a SurfaceReport carries (enough for a chart).
HISTORY_POINTS = 400


# ----------------------------------------------------------- json params

def _number(x, what):
    if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
        raise ValueError(what)
    return float(x)


def _vector_value_pairs(data, what):
    """The ``[[x, y, z], v]`` items of a JSON list as (3 floats, float); anything
    else raises ValueError(what)."""
    if not isinstance(data, list):
        raise ValueError(what)
    pairs = []
    for item in data:
        if not (isinstance(item, list) and len(item) == 2 and isinstance(item[0], list)
                and len(item[0]) == 3):
            raise ValueError(what)
        pairs.append(([_number(x, what) for x in item[0]], _number(item[1], what)))
    return pairs


def _check_planes(data):
    what = "a list of [[nx, ny, nz], d] half-spaces n . x <= d (finite numbers, non-zero n)"
    out = []
    for n, d in _vector_value_pairs(data, what):
        if not any(n):
            raise ValueError(what)
        out.append([n, d])
    return out


def _check_points(data):
    what = "a list of [[x, y, z], thickness] pairs (finite numbers, thickness in (0, 1])"
    out = []
    for point, value in _vector_value_pairs(data, what):
        if not 0.0 < value <= 1.0:
            raise ValueError(what)
        out.append([point, value])
    return out


# ------------------------------------------------------------- the history

def energy_history(values, final, *, limit=HISTORY_POINTS):
    """A solver's energy history as a short JSON-able list ending on the reported energy.

    Parameters
    ----------
    values : (k,) float, the energy after each solver step (non-finite entries are dropped)
    final : float, the energy the report states; it replaces a last entry within
        round-off of it and is appended otherwise
    limit : int, most entries kept; a longer history is thinned evenly, first and last kept

    Returns
    -------
    list of float, at most ``limit`` entries
    """
    h = np.asarray(values, dtype=np.float64).ravel()
    h = h[np.isfinite(h)]
    final = float(final)
    if h.size and abs(h[-1] - final) <= 1e-12 * max(1.0, abs(final)):
        h = h[:-1]
    h = np.append(h, final) if math.isfinite(final) else h
    if h.size > limit:
        h = h[np.unique(np.round(np.linspace(0, h.size - 1, limit)).astype(np.int64))]
    return [float(x) for x in h]


# ---------------------------------------------------------------- the loop

def _loop_chains(chains):
    """Chains in loop order as polylines, with each loop vertex's owner.

    Returns (polylines, smooth flags, owners) where ``owners[i]`` is
    ``(input chain index, vertex index within that chain)`` of loop vertex i.
    """
    if not chains:
        raise NodeInputError("a surface needs edge chains forming one closed loop; none is connected",
                             where="chains")
    for i, c in enumerate(chains):
        if c.period is not None:
            raise NodeInputError(f"chain {i} has a period: a surface boundary must close inside the cell",
                                 where="chains")
        if c.closed and len(chains) > 1:
            raise NodeInputError(f"chain {i} is closed and already forms a whole loop; it cannot be "
                                 "joined with other chains", where="chains")
    index = {id(c): i for i, c in enumerate(chains)}
    polys, smooth, owners = [], [], []
    for chain, rev in order_chains(list(chains)):
        pts = chain.points[::-1] if rev else chain.points
        k = len(chain.points)
        ids = list(range(k))[::-1] if rev else list(range(k))
        if chain.closed:
            pts, ids = np.vstack([pts, pts[:1]]), ids + ids[:1]
        polys.append(np.asarray(pts))
        smooth.append(bool(chain.smooth))
        owners += [(index[id(chain)], j) for j in ids[:-1]]
    return polys, smooth, owners


def boundary_schematic(chains):
    """The loop a Surface node spans, for drawing (what slides is the solver's business).

    Parameters
    ----------
    chains : sequence of EdgeChain, the node's ``chains`` input

    Returns
    -------
    points : (k, 3) float64, loop vertices in loop order (unit-cell coordinates)
    owners : list of (input chain index, vertex index in that chain), one per loop vertex
    segment_chain : (k,) int64, loop-order chain of segment i (loop vertex i to i + 1)
    smooth : list of bool, per loop-order chain

    Raises
    ------
    NodeInputError
        The chains do not form one closed loop.
    """
    polys, smooth, owners = _loop_chains(chains)
    points = np.vstack([p[:-1] for p in polys])
    segment_chain = np.concatenate([np.full(len(p) - 1, c, dtype=np.int64) for c, p in enumerate(polys)])
    return points, owners, segment_chain, smooth


def _join(polys, modes, planes=None):
    try:
        return loop_from_chains(polys, modes=modes, planes=planes)
    except ValueError as exc:
        raise NodeInputError(f"{exc} (chains numbered in loop order)", where="chains") from None


def _fit(kind, planes, points, score):
    try:
        return fit_fbv(kind, points, planes=planes, score=score)
    except FBVFitError as exc:
        raise NodeInputError(str(exc), where=exc.parameter) from None


def _require_inside(fbv, points, owners):
    inside = locate_points(fbv, points)[1]
    if not inside.all():
        i = int(np.flatnonzero(~inside)[0])
        c, j = owners[i]
        raise NodeInputError(f"loop vertex {i} (chain {c}, vertex {j}) at {np.round(points[i], 6).tolist()} "
                             f"lies outside the {fbv.kind} FBV (rule inside)", where="chains")


# ---------------------------------------------------------------- solvers

def _solve_direct(polys, smooth, params, ctx):
    loop = _join(polys, ["smooth" if s else "straight" for s in smooth])
    try:
        sol = solve_thin_shell(loop, alpha=params["alpha"], edge_length=params["edge_length"],
                               max_iter=params["max_iter"], progress=ctx.progress)
    except ValueError as exc:
        raise NodeInputError(str(exc), where="chains") from None
    warning = "" if sol.converged else (f"the thin shell did not converge within max_iter="
                                        f"{params['max_iter']} iterations")
    energy = float(sol.energy_history[-1])
    return (sol.vertices, sol.faces, sol.boundary, sol.iterations, energy, sol.converged, warning,
            {"alpha": params["alpha"], "energy_history": energy_history(sol.energy_history, energy)})


def _solve_mixed(polys, smooth, points, fbv, params, ctx):
    planes = sliding_planes(fbv, polys, smooth, points)
    bad = [p for p in planes if isinstance(p, str)]
    if bad:
        raise NodeInputError(bad[0], where="chains")
    if all(p is None for p in planes):
        return _solve_fixed(points, params, ctx)
    modes = ["sliding" if p is not None else "straight" for p in planes]
    plane_args = [None if p is None else (fbv.normals[p] * fbv.offsets[p], fbv.normals[p]) for p in planes]
    loop = _join(polys, modes, plane_args)
    try:
        sol = solve_mixed_minimal(loop, edge_length=params["edge_length"], max_iter=params["max_iter"],
                                  progress=ctx.progress)
    except ValueError as exc:
        raise NodeInputError(str(exc), where="chains") from None
    warning = "" if sol.converged else (f"the area was still changing after max_iter={params['max_iter']} "
                                        "flow steps")
    sliding = [{"chain": c, "plane": fbv.labels[p], "source": "fbv face"}
               for c, p in enumerate(planes) if p is not None]
    return (sol.vertices, sol.faces, sol.boundary, sol.iterations, float(sol.area), sol.converged,
            warning, {"sliding": sliding, "route": "mixed minimal flow",
                      "energy_history": energy_history(sol.area_history, sol.area)})


def _solve_fixed(points, params, ctx):
    """Nothing slides: the mixed minimal problem is the Plateau problem."""
    sol = solve_plateau(points, edge_length=params["edge_length"], tol=_PLATEAU_TOL,
                        max_iter=params["max_iter"], progress=ctx.progress)
    b = np.roll(sol.boundary, -int(np.flatnonzero(sol.source == 0)[0]))
    warning = "" if sol.converged else (f"the Plateau iteration did not converge within max_iter="
                                        f"{params['max_iter']} steps")
    return (sol.vertices, sol.faces, b, int(sol.iterations[0]), float(sol.level_areas[-1]),
            sol.converged, warning, {"sliding": [], "route": "plateau (no sliding chain)",
                                     "energy_history": energy_history(sol.area_history,
                                                                      sol.level_areas[-1])})


def _conjugate_error(exc, owners):
    parts = []
    for v in getattr(exc, "violations", []):
        if v.vertex >= 0:
            c, j = owners[v.vertex]
            parts.append(f"loop vertex {v.vertex} (chain {c}, vertex {j}), rule {v.rule}: {v.message}")
        else:
            parts.append(f"rule {v.rule}: {v.message}")
    return "; ".join(parts) or str(exc)


def _solve_conjugate(points, owners, fbv, params, ctx):
    perimeter = float(np.linalg.norm(np.roll(points, -1, axis=0) - points, axis=1).sum())
    pieces = max(_MIN_PIECES, int(math.ceil(perimeter / params["edge_length"])))
    try:
        patch = conjugate_surface_construction(fbv, points, max_iter=params["max_iter"],
                                               search_resolution=min(_SEARCH_PIECES, pieces),
                                               final_resolution=pieces, progress=ctx.progress)
    except FBVError as exc:
        raise NodeInputError(_conjugate_error(exc, owners), where="chains") from None
    except ContourError as exc:
        raise NodeInputError(str(exc), where="chains") from None
    rep = patch.report
    b = np.asarray(patch.boundary)
    # Start the boundary at loop vertex 0 and run it in loop order.
    b = np.roll(b, -int(np.flatnonzero(b == patch.corners[0])[0]))
    if np.flatnonzero(b == patch.corners[1])[0] > np.flatnonzero(b == patch.corners[-1])[0]:
        b = np.concatenate([b[:1], b[1:][::-1]])
    warning = ""
    if not rep["converged"]:
        warning = f"the edge-length search stopped at max_iter={params['max_iter']} iterations"
    if rep["energy"] > _CONJUGATE_ENERGY_WARN:
        warning = (warning + "; " if warning else "") + (
            f"the patch fits its FBV poorly (contour energy {rep['energy']:.3g})")
    details = {"energy_kind": rep["energy_kind"], "evaluations": rep["evaluations"],
               "conjugate_sign": rep["conjugate_sign"], "snap_max": rep["snap_max"],
               "note": "every segment slides on its FBV face; chain smoothness is not used",
               # the lowest energy found after each evaluation (a Nelder-Mead iteration makes one
               # or more); the search re-meshes between its two stages, so the reported energy
               # (the second stage's best) may close it slightly above that running minimum
               "energy_history": energy_history(np.minimum.accumulate(rep["energy_history"]),
                                                rep["energy"])}
    return (patch.vertices, patch.faces, b, int(rep["iterations"]), float(rep["energy"]),
            bool(rep["converged"]), warning, details)


def _thickness(vertices, faces, boundary, params):
    samples = params["thickness"]
    handles = [boundary_vertices_at(vertices, boundary, [t for t, _ in samples])]
    values = [np.array([v for _, v in samples])]
    points = params["thickness_points"]
    if points:
        handles.append(nearest_vertices(vertices, [p for p, _ in points]))
        values.append(np.array([v for _, v in points]))
    return surface_thickness(vertices, faces, np.concatenate(handles), np.concatenate(values))


@register
class SurfaceNode(NodeType):
    """Spans a closed loop of edge chains with a surface patch (direct, mixed minimal or conjugate)."""

    type_name = "Surface"
    title = "Surface"
    code = "s"
    family = "skeleton"
    inputs = (Port("chains", "EdgeChain", multi=True, doc="edge chains forming one closed loop"),)
    outputs = (Port("skeleton", "Skeleton"), Port("report", "SurfaceReport"))
    params = (
        Param("type", "enum", "mixed_minimal", choices=SURFACE_TYPES,
              doc="direct: thin shell; mixed_minimal: fixed straight / sliding smooth chains; "
                  "conjugate: free boundary on the FBV faces"),
        Param("fbv", "enum", "cuboid", choices=FBV_KINDS,
              doc="fundamental bounding volume, fitted to the loop's bounding box (custom: fbv_planes)"),
        Param("fbv_planes", "json", [], check=_check_planes,
              doc="custom FBV: half-spaces [[nx, ny, nz], d] meaning n . x <= d"),
        Param("alpha", "float", 0.1, 0.0, 100.0, doc="bending weight of the direct (thin shell) surface"),
        Param("edge_length", "float", 0.05, 0.005, 1.0, unit="cell", doc="target mesh edge length"),
        Param("thickness", "samples", [[0.0, 0.05]], 1e-4, 1.0, unit="cell",
              doc="full thickness at positions t along the boundary (t = 0 at the loop's first vertex)"),
        Param("thickness_points", "json", [], check=_check_points,
              doc="extra thickness samples [[x, y, z], value] at the patch vertex nearest each point"),
        Param("max_iter", "int", 300, 1, 5000,
              doc="solver step limit (L-BFGS iterations, flow steps or edge-length search iterations)"),
    )

    def evaluate(self, inputs, params, ctx):
        t0 = time.perf_counter()
        polys, smooth, owners = _loop_chains(inputs["chains"])
        probe = _join(polys, "straight")             # open loops, self-intersections
        points, kind = probe.points, params["type"]

        def score(fbv):
            if kind == "conjugate":
                return len(conjugate_violations(fbv, points)[0])
            if kind == "mixed_minimal":
                return sum(isinstance(p, str) for p in sliding_planes(fbv, polys, smooth, points))
            return 0

        fbv = _fit(params["fbv"], params["fbv_planes"], points, score)
        if kind == "conjugate":
            result = _solve_conjugate(points, owners, fbv, params, ctx)
        else:
            _require_inside(fbv, points, owners)
            result = (_solve_direct(polys, smooth, params, ctx) if kind == "direct"
                      else _solve_mixed(polys, smooth, points, fbv, params, ctx))
        v, f, b, iterations, energy, converged, warning, details = result
        ctx.check()
        thickness = _thickness(v, f, b, params)
        stats = surface_report(v, f, b)
        details = {"fbv": fbv.kind, "fbv_planes": [fbv.labels[k] for k in range(fbv.n_planes)],
                   "vertices": int(len(v)), "faces": int(len(f)), **details}
        report = SurfaceReport(kind, int(iterations), energy, stats["area"], stats["max_abs_H"],
                               stats["mean_abs_H"], time.perf_counter() - t0, bool(converged), warning,
                               details)
        element = SurfaceElement(v, f, thickness, np.asarray(v)[b])
        return {"skeleton": Skeleton((element,)), "report": report}


# ------------------------------------------------- conjugate and associates

_TURN = Param("quarter_turn", "enum", "+90", choices=QUARTER_TURNS,
              doc="direction of the conjugate's quarter turn about the normal (the two differ by a "
                  "point reflection)")


def _surfaces_of(skeleton):
    if not skeleton.surfaces:
        raise NodeInputError("the skeleton holds no surface element", where="skeleton")
    return skeleton


def _area_centroid(vertices, faces):
    """Area-weighted centroid of a triangle mesh.

    Members of an associate family are placed by it: for a patch with a
    symmetry centre (the Schwarz D hexagon, the gyroid patch) it is that
    centre up to O(h^2), whereas the vertex centroid drifts with the mesh.
    """
    v, f = np.asarray(vertices), np.asarray(faces)
    a = face_areas(v, f)
    return (a[:, None] * v[f].mean(axis=1)).sum(axis=0) / a.sum()


def _placed_element(element, vertices):
    """``element`` with new vertex positions (same faces and thickness),
    translated so that its area centroid stays on the input's."""
    v = np.asarray(vertices)
    f = np.asarray(element.faces)
    # at phi = 0 the member is the input bit for bit, and so is the shift zero
    v = v + (_area_centroid(element.vertices, f) - _area_centroid(v, f))
    b = boundary_loop_of(f, v.shape[0])
    return SurfaceElement(v, element.faces, element.thickness, v[b])


@register
class DualSurfaceNode(NodeType):
    """The discrete conjugate of each surface patch (e.g. the dual of a conjugate Surface).

    The conjugate is isometric to the input and shares its normals; it is
    placed with its area centroid on the input's. Line elements pass
    through unchanged.
    """

    type_name = "DualSurface"
    title = "Dual Surface"
    code = "dual"
    family = "skeleton"
    inputs = (Port("skeleton", "Skeleton"),)
    outputs = (Port("skeleton", "Skeleton"),)
    params = (_TURN,)

    def evaluate(self, inputs, params, ctx):
        sign = 1 if params["quarter_turn"] == "+90" else -1
        out = []
        for e in _surfaces_of(inputs["skeleton"]).elements:
            if isinstance(e, SurfaceElement):
                e = _placed_element(e, conjugate_surface(e.vertices, e.faces, sign=sign).vertices)
            out.append(e)
        return {"skeleton": Skeleton(tuple(out))}


@register
class AssociateFamilyNode(NodeType):
    """Member phi of the associate family of each surface patch (eq. 1).

    phi = 0 gives the input, 90 its conjugate; from Schwarz D the gyroid
    lies at the Bonnet angle (about 38.015 degrees) and Schwarz P at 90.
    Members keep the input's area centroid (for the D hexagon: the gyroid patch's
    centre lands on the hexagon's); lines pass through unchanged.
    """

    type_name = "AssociateFamily"
    title = "Associate Family"
    code = "assoc"
    family = "skeleton"
    inputs = (Port("skeleton", "Skeleton"),)
    outputs = (Port("skeleton", "Skeleton"),)
    params = (
        Param("phi", "float", round(BONNET_ANGLE_DEG, 4), -360.0, 360.0, unit="deg",
              doc="family angle: 0 = input, 90 = conjugate, ~38.015 = gyroid from Schwarz D"),
        _TURN,
    )

    def evaluate(self, inputs, params, ctx):
        sign = 1 if params["quarter_turn"] == "+90" else -1
        phi = math.radians(params["phi"])
        out = []
        for e in _surfaces_of(inputs["skeleton"]).elements:
            if isinstance(e, SurfaceElement):
                e = _placed_element(e, associate_surface(e.vertices, e.faces, phi, sign=sign).vertices)
            out.append(e)
        return {"skeleton": Skeleton(tuple(out))}
