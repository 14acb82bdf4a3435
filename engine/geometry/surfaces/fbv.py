"""Fundamental bounding volumes (FBVs) and the requirements a boundary loop
must meet on them (Makatura et al. 2023, sections 3.3, 4.2.1 and 6.3).

An FBV is a convex polyhedron given by outward half-spaces
``normals[k] . x <= offsets[k]``. Three scalable primitives -- the cuboid
(an axis-aligned box), the triangular prism and the tetrahedron -- and
custom convex volumes are supported.

For a *conjugate* surface every loop vertex must sit on an FBV edge (on
exactly two planes), every loop edge must run on an FBV face, and at each
vertex the loop must turn from one face of its edge to the other. Then the
primary patch meets both planes orthogonally there, so its normal is the
edge direction; the dual polygon has those normals at its corners and
edges along the normals of the arcs' planes. A loop whose arcs' plane
normals admit no positive closing lengths cannot be realised (the surface
normal cannot align with the FBV edges): it is refused too.

Violations are reported as :class:`Violation` records naming the vertex
and the rule; :func:`check_conjugate_loop` raises :class:`FBVError`
carrying all of them.

:func:`fit_fbv` fits a primitive to a boundary loop: a cuboid is the loop's
axis-aligned bounding box (an axis along which the loop is flat is widened
by half the box's largest side both ways, so that no face holds the whole
loop); a prism is half of that box cut along a diagonal and extruded along
an axis; a tetrahedron is a cube-corner orthoscheme of the box (1/6 of it)
or one of its two alternate-corner tetrahedra. Of the candidates that hold
every loop vertex the one with the lowest score wins, ties in a fixed order.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

__all__ = ["BoundingVolume", "Violation", "FBVError", "FBVFitError", "LoopOnFBV",
           "cuboid", "triangular_prism", "tetrahedron", "convex_volume",
           "locate_points", "conjugate_violations", "sliding_violations",
           "check_conjugate_loop", "vertex_frames", "dihedral_angle",
           "FBV_KINDS", "loop_box", "box_prisms", "box_tetrahedra", "volume_from_planes",
           "fit_fbv", "sliding_planes", "DEFAULT_TOL"]

# Distances below this fraction of the FBV diameter count as "on a plane".
DEFAULT_TOL = 1e-5


@dataclass(frozen=True)
class BoundingVolume:
    """A convex fundamental bounding volume.

    Attributes
    ----------
    normals : (k, 3) float64, read-only
        Outward unit normals of the bounding planes.
    offsets : (k,) float64, read-only
        Inside is ``normals @ x <= offsets`` (model units).
    labels : tuple of str
        Human-readable plane names used in messages (``"x = 0"``).
    corners : (c, 3) float64, read-only
        Polyhedron vertices.
    corner_planes : tuple of frozenset
        Planes through each corner.
    edges : tuple of (int, int)
        Plane pairs ``(i, j)``, ``i < j``, whose intersection holds an edge.
    kind : str
        ``"cuboid"``, ``"prism"``, ``"tetrahedron"`` or ``"convex"``.
    """

    normals: np.ndarray
    offsets: np.ndarray
    labels: tuple
    corners: np.ndarray
    corner_planes: tuple
    edges: tuple
    kind: str

    @property
    def n_planes(self) -> int:
        return int(self.normals.shape[0])

    @property
    def diameter(self) -> float:
        c = self.corners
        return float(np.max(np.linalg.norm(c[:, None] - c[None], axis=2)))

    @property
    def is_aabb(self) -> bool:
        """True for six axis-aligned planes (a cuboid)."""
        if self.n_planes != 6:
            return False
        axes = np.abs(self.normals).argmax(axis=1)
        return bool(np.allclose(np.abs(self.normals).max(axis=1), 1.0)
                    and np.all(np.bincount(axes, minlength=3) == 2))

    def signed_distances(self, points):
        """``normals . p - offsets`` for each point and plane, shape (n, k)."""
        return np.asarray(points, dtype=np.float64) @ self.normals.T - self.offsets

    def edge_corners(self, i, j):
        """Indices of the corners on the edge between planes ``i`` and ``j``."""
        return [c for c, planes in enumerate(self.corner_planes) if i in planes and j in planes]


@dataclass(frozen=True)
class Violation:
    """One broken requirement: the loop vertex, a rule id and a message."""

    vertex: int
    rule: str
    message: str


class FBVError(ValueError):
    """A boundary loop does not meet the FBV requirements.

    Attributes
    ----------
    violations : list of Violation
    """

    def __init__(self, violations):
        self.violations = list(violations)
        super().__init__("; ".join(v.message for v in self.violations))


@dataclass(frozen=True)
class LoopOnFBV:
    """A checked conjugate loop: which planes each vertex and arc use.

    Attributes
    ----------
    points : (n, 3) float64
        The loop vertices.
    arc_planes : (n,) int64
        Plane holding arc ``i`` (from vertex ``i`` to ``i + 1``).
    vertex_planes : (n, 2) int64
        ``(incoming, outgoing)`` plane of every vertex, i.e.
        ``(arc_planes[i - 1], arc_planes[i])``.
    """

    points: np.ndarray
    arc_planes: np.ndarray
    vertex_planes: np.ndarray


def _plane_label(n, h):
    axis = int(np.argmax(np.abs(n)))
    if abs(abs(n[axis]) - 1.0) < 1e-12:
        return f"{'xyz'[axis]} = {h / n[axis] + 0.0:.6g}"
    terms = [f"{c:+.4g}{name}" for c, name in zip(n, "xyz") if abs(c) > 1e-12]
    return f"{' '.join(terms).lstrip('+')} = {h + 0.0:.6g}"


def convex_volume(normals, offsets, *, labels=None, kind="convex"):
    """A custom convex FBV from outward half-spaces ``n . x <= h``.

    Parameters
    ----------
    normals : array_like, shape (k, 3), float
        Outward normals (normalised here); k >= 4.
    offsets : array_like, shape (k,), float
        Plane offsets (model units) for the given (unnormalised) normals.
    labels : sequence of str, optional
        Plane names for messages; default from the equations.

    Returns
    -------
    BoundingVolume

    Raises
    ------
    ValueError
        Wrong shapes, a zero normal, an empty or unbounded volume, or a
        plane that does not carry a face (redundant planes are refused so
        that every plane index means a face).
    """
    n = np.asarray(normals, dtype=np.float64)
    h = np.asarray(offsets, dtype=np.float64)
    if n.ndim != 2 or n.shape[1] != 3 or n.shape[0] < 4:
        raise ValueError(f"normals must have shape (k, 3) with k >= 4; got shape {n.shape}")
    if h.shape != (n.shape[0],):
        raise ValueError(f"offsets must have shape ({n.shape[0]},); got shape {h.shape}")
    if not (np.all(np.isfinite(n)) and np.all(np.isfinite(h))):
        raise ValueError("normals and offsets must be finite")
    length = np.linalg.norm(n, axis=1)
    if np.any(length <= 1e-12):
        k = int(np.argmin(length))
        raise ValueError(f"normals[{k}] is zero; every plane needs a direction")
    n, h = n / length[:, None], h / length
    corners, corner_planes = _polyhedron_corners(n, h)
    if corners.shape[0] < 4:
        raise ValueError("the half-spaces enclose no volume (fewer than 4 corners); "
                         "check the normals point outwards")
    scale = float(np.max(np.abs(corners))) + 1.0
    if scale > 1e6:
        raise ValueError("the half-spaces do not bound a finite volume")
    for k in range(n.shape[0]):
        on = [c for c, planes in enumerate(corner_planes) if k in planes]
        if len(on) < 3:
            raise ValueError(f"plane {k} ({_plane_label(n[k], h[k])}) does not carry a face "
                             "of the volume; remove redundant planes")
    edges = []
    for i, j in itertools.combinations(range(n.shape[0]), 2):
        if sum(1 for planes in corner_planes if i in planes and j in planes) >= 2:
            edges.append((i, j))
    if labels is None:
        labels = tuple(_plane_label(n[k], h[k]) for k in range(n.shape[0]))
    elif len(labels) != n.shape[0]:
        raise ValueError(f"labels must name all {n.shape[0]} planes; got {len(labels)}")
    for arr in (n, h, corners):
        arr.setflags(write=False)
    return BoundingVolume(normals=n, offsets=h, labels=tuple(labels), corners=corners,
                          corner_planes=tuple(corner_planes), edges=tuple(edges), kind=kind)


def _polyhedron_corners(n, h):
    """Vertices of ``{x : n x <= h}`` by brute force over plane triples."""
    k = n.shape[0]
    size = float(np.max(np.abs(h))) + 1.0
    tol = 1e-9 * size
    found = []
    for tri in itertools.combinations(range(k), 3):
        a = n[list(tri)]
        if abs(np.linalg.det(a)) < 1e-12:
            continue
        x = np.linalg.solve(a, h[list(tri)])
        if np.all(n @ x - h <= tol):
            found.append(x)
    if not found:
        return np.zeros((0, 3)), []
    pts = np.asarray(found)
    keep = []
    for p in pts:
        if not any(np.linalg.norm(p - q) <= tol for q in keep):
            keep.append(p)
    corners = np.asarray(keep)
    planes = [frozenset(np.flatnonzero(np.abs(n @ c - h) <= tol).tolist()) for c in corners]
    return corners, planes


def cuboid(lower=(0.0, 0.0, 0.0), upper=(0.5, 0.5, 0.5)):
    """Axis-aligned box ``lower <= x <= upper`` (an AABB FBV).

    Planes are ordered ``x = lo, x = hi, y = lo, y = hi, z = lo, z = hi``.
    """
    lo = np.asarray(lower, dtype=np.float64).reshape(3)
    hi = np.asarray(upper, dtype=np.float64).reshape(3)
    if np.any(hi - lo <= 0.0):
        raise ValueError(f"upper must exceed lower on every axis; got lower={lo.tolist()}, "
                         f"upper={hi.tolist()}")
    normals, offsets = [], []
    for a in range(3):
        e = np.eye(3)[a]
        normals += [-e, e]
        offsets += [-lo[a], hi[a]]
    return convex_volume(normals, offsets, kind="cuboid")


def tetrahedron(points):
    """Tetrahedron spanned by four points, shape (4, 3)."""
    p = np.asarray(points, dtype=np.float64)
    if p.shape != (4, 3):
        raise ValueError(f"points must have shape (4, 3); got shape {p.shape}")
    centre = p.mean(axis=0)
    normals, offsets = [], []
    for skip in range(4):
        a, b, c = p[[k for k in range(4) if k != skip]]
        n = np.cross(b - a, c - a)
        if np.linalg.norm(n) <= 1e-12 * (1.0 + np.abs(p).max()) ** 2:
            raise ValueError("points are coplanar; a tetrahedron needs volume")
        if n @ (centre - a) > 0.0:
            n = -n
        normals.append(n)
        offsets.append(n @ a)
    return convex_volume(normals, offsets, kind="tetrahedron")


def triangular_prism(triangle, extrusion):
    """Prism swept by a triangle along a vector.

    Parameters
    ----------
    triangle : array_like, shape (3, 3)
        Base triangle corners (model units).
    extrusion : array_like, shape (3,)
        Sweep vector; must leave the triangle's plane.
    """
    t = np.asarray(triangle, dtype=np.float64)
    d = np.asarray(extrusion, dtype=np.float64).reshape(3)
    if t.shape != (3, 3):
        raise ValueError(f"triangle must have shape (3, 3); got shape {t.shape}")
    m = np.cross(t[1] - t[0], t[2] - t[0])
    if abs(m @ d) <= 1e-12 * np.linalg.norm(m) * max(np.linalg.norm(d), 1e-300):
        raise ValueError("extrusion lies in the triangle's plane (or the triangle is degenerate)")
    centre = t.mean(axis=0) + 0.5 * d
    normals, offsets = [], []
    for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
        n = np.cross(b - a, d)
        if n @ (centre - a) > 0.0:
            n = -n
        normals.append(n)
        offsets.append(n @ a)
    for base in (t[0], t[0] + d):
        n = m if m @ (centre - base) < 0.0 else -m
        normals.append(n)
        offsets.append(n @ base)
    return convex_volume(normals, offsets, kind="prism")


def locate_points(fbv, points, *, tol=None):
    """The planes each point lies on.

    Parameters
    ----------
    fbv : BoundingVolume
    points : array_like, shape (n, 3)
    tol : float, optional
        Distance counted as "on the plane"; default ``DEFAULT_TOL`` times
        the FBV diameter.

    Returns
    -------
    (list of frozenset, numpy.ndarray (n,) bool)
        Planes through each point and whether the point is inside (within
        ``tol``).
    """
    tol = DEFAULT_TOL * fbv.diameter if tol is None else float(tol)
    d = fbv.signed_distances(points)
    on = [frozenset(np.flatnonzero(np.abs(row) <= tol).tolist()) for row in d]
    return on, np.all(d <= tol, axis=1)


def _names(fbv, planes):
    return " and ".join(f"'{fbv.labels[k]}'" for k in sorted(planes))


def _vertex_rules(fbv, on, inside):
    out = []
    for i, (planes, ok) in enumerate(zip(on, inside)):
        if not ok:
            out.append(Violation(i, "inside", f"vertex {i} lies outside the FBV"))
        elif len(planes) == 0:
            out.append(Violation(i, "on-edge", f"vertex {i} lies inside the FBV, not on an FBV "
                                 "edge; conjugate vertices must sit on an FBV edge (two planes)"))
        elif len(planes) == 1:
            out.append(Violation(i, "on-edge", f"vertex {i} lies on face {_names(fbv, planes)} "
                                 "only; conjugate vertices must sit on an FBV edge (two planes)"))
        elif len(planes) > 2:
            out.append(Violation(i, "on-edge", f"vertex {i} sits at an FBV corner (planes "
                                 f"{_names(fbv, planes)}); conjugate vertices must sit inside an "
                                 "FBV edge, where exactly two planes meet"))
        elif tuple(sorted(planes)) not in fbv.edges:
            out.append(Violation(i, "on-edge", f"vertex {i} lies on planes {_names(fbv, planes)}, "
                                 "which do not meet in an FBV edge"))
    return out


def _assign_arcs(on, n):
    """Plane of each arc: shared by both ends, alternating at every vertex."""
    shared = [on[i] & on[(i + 1) % n] for i in range(n)]
    arcs = [next(iter(s)) if len(s) == 1 else None for s in shared]
    for _ in range(n):
        for i in range(n):
            if arcs[i] is None and len(shared[i]) == 2:
                prev, nxt = arcs[i - 1], arcs[(i + 1) % n]
                options = [p for p in shared[i] if p != prev and p != nxt]
                if len(options) == 1:
                    arcs[i] = options[0]
    for i in range(n):
        if arcs[i] is None and len(shared[i]) == 2:
            arcs[i] = min(p for p in shared[i] if p != arcs[i - 1]) if arcs[i - 1] in shared[i] \
                else min(shared[i])
    return shared, arcs


def _closure_violation(fbv, arcs):
    """Is there l > 0 with sum_i l_i n_{arc i} = 0? (A small LP.)"""
    from scipy.optimize import linprog

    e = fbv.normals[np.asarray(arcs)].T                    # (3, n)
    n = e.shape[1]
    res = linprog(np.ones(n), A_eq=e, b_eq=np.zeros(3), bounds=[(1.0, None)] * n,
                  method="highs")
    if res.status == 0:
        return None
    names = ", ".join(f"'{fbv.labels[k]}'" for k in dict.fromkeys(arcs))
    return Violation(-1, "normals", "the dual contour cannot close: no positive edge lengths "
                     f"make the outward normals of the arcs' planes ({names}) sum to zero, so "
                     "the surface normal cannot align with the FBV edge at every vertex; "
                     "the loop must wind around the FBV")


def conjugate_violations(fbv, points, *, tol=None):
    """Every requirement a conjugate boundary loop breaks (section 6.3).

    Rules (ids): ``inside``; ``on-edge`` (each vertex on an FBV edge, i.e.
    exactly two planes that meet in an edge); ``edge-on-face`` (each loop
    edge on an FBV face: its ends share a plane); ``turn`` (at each vertex
    the loop passes from one plane of its edge to the other); ``normals``
    (the dual polygon closes with positive lengths). ``vertex`` is -1 for
    rules of the whole loop.

    Returns
    -------
    (list of Violation, LoopOnFBV or None)
        The loop description is None when any rule is broken.
    """
    p = np.asarray(points, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3 or p.shape[0] < 3:
        raise ValueError(f"points must have shape (n, 3) with n >= 3; got shape {p.shape}")
    n = p.shape[0]
    on, inside = locate_points(fbv, p, tol=tol)
    found = _vertex_rules(fbv, on, inside)
    shared, arcs = _assign_arcs(on, n)
    for i in range(n):
        if not shared[i]:
            found.append(Violation(i, "edge-on-face",
                                   f"loop edge from vertex {i} to vertex {(i + 1) % n} does not "
                                   "lie on an FBV face (its ends share no plane)"))
    if any(v.rule in ("on-edge", "inside", "edge-on-face") for v in found):
        return found, None
    for i in range(n):
        before, after = arcs[i - 1], arcs[i]
        if before == after:
            found.append(Violation(i, "turn", f"vertex {i} lies on the FBV edge of "
                                   f"{_names(fbv, on[i])}, but both loop edges at it run on "
                                   f"'{fbv.labels[before]}'; the loop must pass from one plane "
                                   "of the edge to the other so the surface normal can follow "
                                   "the edge"))
    if found:
        return found, None
    closure = _closure_violation(fbv, arcs)
    if closure is not None:
        return [closure], None
    arc_planes = np.asarray(arcs, dtype=np.int64)
    vertex_planes = np.column_stack([np.roll(arc_planes, 1), arc_planes])
    for arr in (p, arc_planes, vertex_planes):
        arr.setflags(write=False)
    return [], LoopOnFBV(points=p, arc_planes=arc_planes, vertex_planes=vertex_planes)


def check_conjugate_loop(fbv, points, *, tol=None):
    """Validate a conjugate loop; return its :class:`LoopOnFBV`.

    Raises
    ------
    FBVError
        With one :class:`Violation` per broken rule (vertex and rule named).
    """
    found, loop = conjugate_violations(fbv, points, tol=tol)
    if found:
        raise FBVError(found)
    return loop


def sliding_violations(fbv, points, smooth, *, tol=None):
    """Requirement of sliding (smooth) segments: each lies on an FBV face.

    Parameters
    ----------
    points : (n, 3) float
        Closed loop.
    smooth : (n,) bool
        ``smooth[i]`` marks the segment from vertex ``i`` to ``i + 1`` as
        sliding.

    Returns
    -------
    list of Violation
    """
    p = np.asarray(points, dtype=np.float64)
    s = np.asarray(smooth, dtype=bool).ravel()
    if s.shape != (p.shape[0],):
        raise ValueError(f"smooth must have one flag per segment ({p.shape[0]}); got {s.shape}")
    on, inside = locate_points(fbv, p, tol=tol)
    out = [Violation(i, "inside", f"vertex {i} lies outside the FBV")
           for i in np.flatnonzero(~inside)]
    n = p.shape[0]
    for i in np.flatnonzero(s):
        if not (on[i] & on[(i + 1) % n]):
            out.append(Violation(int(i), "sliding-on-face",
                                 f"sliding segment from vertex {i} to vertex {(i + 1) % n} does "
                                 "not lie on an FBV face"))
    return out


def dihedral_angle(n_in, n_out):
    """Interior dihedral angle (radians) between planes with outward normals."""
    c = float(np.clip(np.dot(n_in, n_out), -1.0, 1.0))
    return math.pi - math.acos(c)


def vertex_frames(fbv, loop):
    """Algorithm 1 pre-processing: vertex angles vA and normals vN.

    Parameters
    ----------
    fbv : BoundingVolume
    loop : LoopOnFBV

    Returns
    -------
    (vA (n,) float64 radians, vN (n, 3) float64 unit)
        ``vA[i]`` is the dihedral angle between the incoming and outgoing
        planes at vertex ``i``; ``vN[i]`` is the normalised cross product of
        their outward normals (the direction of the FBV edge).
    """
    n_in = fbv.normals[loop.vertex_planes[:, 0]]
    n_out = fbv.normals[loop.vertex_planes[:, 1]]
    cross = np.cross(n_in, n_out)
    v_n = cross / np.linalg.norm(cross, axis=1, keepdims=True)
    v_a = np.array([dihedral_angle(a, b) for a, b in zip(n_in, n_out)])
    return v_a, v_n


# ------------------------------------------------------------ fitting a loop

FBV_KINDS = ("cuboid", "prism", "tetrahedron", "custom")


class FBVFitError(ValueError):
    """No FBV of the requested kind can be built for a loop.

    Attributes
    ----------
    parameter : str
        The input at fault: ``"fbv"`` (no primitive of that kind holds the
        loop) or ``"fbv_planes"`` (the custom half-spaces are unusable).
    """

    def __init__(self, message, parameter):
        self.parameter = parameter
        super().__init__(message)


def loop_box(points):
    """Axis-aligned bounding box of a loop, widened along flat axes.

    Parameters
    ----------
    points : (n, 3) float
        Loop vertices (model units).

    Returns
    -------
    (lo (3,) float64, hi (3,) float64)
        An axis along which the loop is flat is widened by half the box's
        largest side both ways, so that no face of the box holds the whole
        loop.
    """
    p = np.asarray(points, dtype=np.float64)
    lo, hi = p.min(axis=0), p.max(axis=0)
    ext = hi - lo
    flat = ext <= 1e-9 * max(float(ext.max()), 1e-12)
    pad = 0.5 * float(ext.max())
    return np.where(flat, lo - pad, lo), np.where(flat, hi + pad, hi)


def box_prisms(lo, hi):
    """The 12 half-box prisms of a box: per axis (z, x, y) the four halves
    cut along a diagonal of the cross-section, extruded along the axis."""
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    for axis in (2, 0, 1):
        p, q = [a for a in range(3) if a != axis]
        rect = []
        for bp, bq in ((0, 0), (1, 0), (1, 1), (0, 1)):
            x = lo.copy()
            x[p] = hi[p] if bp else lo[p]
            x[q] = hi[q] if bq else lo[q]
            rect.append(x)
        sweep = np.zeros(3)
        sweep[axis] = hi[axis] - lo[axis]
        for drop in range(4):
            yield triangular_prism([rect[(drop + k) % 4] for k in (1, 2, 3)], sweep)


def box_tetrahedra(lo, hi):
    """The two alternate-corner tetrahedra of a box, then its 24 cube-corner
    orthoschemes (paths of three edges in turn along each axis)."""
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)

    def corner(bits):
        return np.where(np.asarray(bits, bool), hi, lo)

    yield tetrahedron([corner(b) for b in ((0, 0, 0), (1, 1, 0), (1, 0, 1), (0, 1, 1))])
    yield tetrahedron([corner(b) for b in ((1, 1, 1), (0, 0, 1), (0, 1, 0), (1, 0, 0))])
    seen = set()
    for start in itertools.product((0, 1), repeat=3):
        for perm in itertools.permutations(range(3)):
            bits, path = list(start), [tuple(start)]
            for a in perm:
                bits[a] = 1 - bits[a]
                path.append(tuple(bits))
            key = frozenset(path)
            if key not in seen:
                seen.add(key)
                yield tetrahedron([corner(b) for b in path])


def volume_from_planes(planes):
    """A custom FBV from ``[[nx, ny, nz], d]`` half-spaces ``n . x <= d``.

    Raises
    ------
    FBVFitError
        Fewer than 4 half-spaces, or ones that bound no usable volume
        (``parameter`` is ``"fbv_planes"``).
    """
    if len(planes) < 4:
        raise FBVFitError(f"fbv 'custom' needs at least 4 half-spaces in fbv_planes; got "
                          f"{len(planes)}", "fbv_planes")
    try:
        return convex_volume([p[0] for p in planes], [p[1] for p in planes])
    except ValueError as exc:
        raise FBVFitError(f"fbv_planes: {exc}", "fbv_planes") from None


def fit_fbv(kind, points, *, planes=(), score=None):
    """The FBV of ``kind`` that holds a loop and scores lowest.

    Parameters
    ----------
    kind : {'cuboid', 'prism', 'tetrahedron', 'custom'}
    points : (n, 3) float
        Loop vertices (model units).
    planes : sequence of ([nx, ny, nz], d), keyword-only
        Half-spaces of a ``custom`` FBV.
    score : callable, optional
        ``score(fbv) -> number``, e.g. the count of broken requirements;
        ties go to the earlier candidate (see :func:`box_prisms`,
        :func:`box_tetrahedra`).

    Returns
    -------
    BoundingVolume

    Raises
    ------
    FBVFitError
        No candidate holds every loop vertex, or the custom planes are
        unusable.
    """
    if kind not in FBV_KINDS:
        raise FBVFitError(f"fbv must be one of {FBV_KINDS}; got {kind!r}", "fbv")
    if kind == "custom":
        return volume_from_planes(planes)
    p = np.asarray(points, dtype=np.float64)
    lo, hi = loop_box(p)
    if kind == "cuboid":
        return cuboid(lo, hi)
    candidates = box_prisms(lo, hi) if kind == "prism" else box_tetrahedra(lo, hi)
    best = None
    for k, fbv in enumerate(candidates):
        if not locate_points(fbv, p)[1].all():
            continue
        rank = (score(fbv) if score is not None else 0, k)
        if best is None or rank < best[0]:
            best = (rank, fbv)
    if best is None:
        raise FBVFitError(f"no {kind} fitted to the loop's bounding box {np.round(lo, 6).tolist()} .. "
                          f"{np.round(hi, 6).tolist()} holds every loop vertex; use cuboid or custom",
                          "fbv")
    return best[1]


def _fitted_normal(points):
    c = points - points.mean(axis=0)
    return np.linalg.svd(c, full_matrices=False)[2][-1]


def sliding_planes(fbv, polylines, smooth, loop_points):
    """The FBV plane each smooth chain of a loop slides in.

    A chain on several faces slides in the one most across the loop (the
    face whose normal is nearest to perpendicular to the loop's fitted
    plane); faces holding the whole loop are skipped.

    Parameters
    ----------
    fbv : BoundingVolume
    polylines : sequence of (k_i, 3) float
        The loop's chains in loop order.
    smooth : sequence of bool
        Which chains are smooth (sliding).
    loop_points : (n, 3) float
        The joined loop's vertices.

    Returns
    -------
    list
        Per chain: ``None`` (straight), a plane index, or a message (str)
        saying why a smooth chain cannot slide (rule ``sliding-on-face``).
    """
    loop_points = np.asarray(loop_points, dtype=np.float64)
    whole = frozenset.intersection(*locate_points(fbv, loop_points)[0])
    normal = _fitted_normal(loop_points)
    out = []
    for c, (pts, s) in enumerate(zip(polylines, smooth)):
        if not s:
            out.append(None)
            continue
        common = sorted(frozenset.intersection(*locate_points(fbv, pts)[0]) - whole)
        if not common:
            out.append(f"smooth chain {c} (in loop order) lies on no face of the {fbv.kind} FBV, so it "
                       "cannot slide (rule sliding-on-face); make it straight or move it onto a face")
            continue
        out.append(min(common, key=lambda k: (round(abs(float(fbv.normals[k] @ normal)), 9), k)))
    return out
