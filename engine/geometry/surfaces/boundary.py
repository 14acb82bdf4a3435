"""Closed boundary loops for the surface solvers (paper sections 3.1, 6.3).

A loop is a cycle of vertices; segment ``i`` joins vertex ``i`` to vertex
``i + 1`` (mod n) and carries a mode:

``"straight"``
    fixed, a straight line;
``"smooth"``
    fixed, part of a natural cubic spline through the run of consecutive
    smooth segments (section 5.2; a fully smooth loop is a periodic spline);
``"sliding"``
    free to move within its bounding plane (mixed minimal solver); the
    segment's vertices must lie on that plane.

A loop vertex is fixed when a fixed segment touches it. A vertex between two
sliding segments slides in their common plane or, when the planes differ,
along the line where they meet.

:func:`sample_loop` turns a loop into the polyline the meshers use, with one
constraint per sample.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..splines import interpolate_chain

__all__ = ["SEGMENT_MODES", "BoundaryLoop", "BoundarySamples", "boundary_loop",
           "loop_from_chains", "sample_loop", "segment_distances"]

SEGMENT_MODES = ("straight", "smooth", "sliding")

# Default tolerance, relative to the loop's bounding-box diagonal, for
# repeated vertices, self-intersection and points lying on their plane.
RELATIVE_TOL = 1e-6

# Dense spline samples per smooth segment before resampling by arc length;
# the chord error at this density is far below any sensible edge length.
_SPLINE_DENSITY = 64


@dataclass(frozen=True)
class BoundaryLoop:
    """A validated closed loop.

    Attributes
    ----------
    points : (n, 3) float64, read-only
        Loop vertices, each once, n >= 3.
    modes : tuple of str, length n
        Mode of segment i (vertex i to vertex i+1 mod n), one of
        :data:`SEGMENT_MODES`.
    planes : (n, 4) float64, read-only
        For a sliding segment its plane as unit normal and offset
        ``(nx, ny, nz, d)`` with ``n . x = d``; NaN for other segments.
    tol : float
        Absolute tolerance (model units) the loop was validated with.
    """

    points: np.ndarray
    modes: tuple
    planes: np.ndarray
    tol: float

    @property
    def n_segments(self) -> int:
        return int(self.points.shape[0])


@dataclass(frozen=True)
class BoundarySamples:
    """A loop discretised into a closed polyline (first sample not repeated).

    Attributes
    ----------
    points : (m, 3) float64
        Polyline vertices in loop order; sample 0 is loop vertex 0.
    segment : (m,) int64
        Loop segment each sample lies on (a loop vertex counts as the start
        of its outgoing segment).
    vertex : (m,) int64
        Loop vertex index of the sample, or -1 for samples inside a segment.
    fixed : (m,) bool
        Sample may not move.
    planes : (m, 2, 4) float64
        Up to two constraint planes ``(nx, ny, nz, d)`` for a moving boundary
        sample; unused rows are NaN. Fixed samples have none.
    """

    points: np.ndarray
    segment: np.ndarray
    vertex: np.ndarray
    fixed: np.ndarray
    planes: np.ndarray


# --------------------------------------------------------------------------
# validation helpers

def _as_loop_points(points, name="points"):
    arr = np.asarray(points, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"{name} must have shape (n, 3); got shape {arr.shape}")
    bad = np.flatnonzero(~np.all(np.isfinite(arr), axis=1))
    if bad.size:
        raise ValueError(f"{name} must be finite; vertex {int(bad[0])} is {arr[bad[0]].tolist()}")
    return arr


def _default_tol(points, tol):
    if tol is None:
        diag = float(np.linalg.norm(np.ptp(points, axis=0))) if points.shape[0] else 0.0
        return RELATIVE_TOL * max(diag, 1e-12)
    tol = float(tol)
    if not math.isfinite(tol) or tol <= 0.0:
        raise ValueError(f"tol must be a finite number > 0; got {tol!r}")
    return tol


def segment_distances(p0, p1, q0, q1):
    """Shortest distance between 3D segments ``p0 p1`` and ``q0 q1``, row-wise.

    Parameters
    ----------
    p0, p1, q0, q1 : (k, 3) float64
        Segment end points; segments must have non-zero length.

    Returns
    -------
    numpy.ndarray, shape (k,), float64
    """
    d1, d2, r = p1 - p0, q1 - q0, p0 - q0
    a = np.einsum("ij,ij->i", d1, d1)
    e = np.einsum("ij,ij->i", d2, d2)
    b = np.einsum("ij,ij->i", d1, d2)
    c = np.einsum("ij,ij->i", d1, r)
    f = np.einsum("ij,ij->i", d2, r)
    denom = a * e - b * b
    # Minimise |r + s d1 - t d2|^2 over the unit square: the unconstrained
    # optimum in s (clamped), then t for that s (clamped) and s again.
    parallel = denom <= 1e-14 * a * e
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(parallel, 0.0, np.clip((b * f - c * e) / denom, 0.0, 1.0))
    t = (b * s + f) / e
    low, high = t < 0.0, t > 1.0
    t = np.clip(t, 0.0, 1.0)
    s = np.where(low, np.clip(-c / a, 0.0, 1.0), s)
    s = np.where(high, np.clip((b - c) / a, 0.0, 1.0), s)
    gap = r + s[:, None] * d1 - t[:, None] * d2
    return np.linalg.norm(gap, axis=1)


def _point_segment_distance(x, a, b):
    d = b - a
    s = np.clip(np.einsum("ij,ij->i", x - a, d) / np.einsum("ij,ij->i", d, d), 0.0, 1.0)
    return np.linalg.norm(x - a - s[:, None] * d, axis=1)


def _check_repeats(pts, tol, what="vertex"):
    n = pts.shape[0]
    for start in range(0, n, 512):
        block = pts[start:start + 512]
        dist = np.linalg.norm(block[:, None, :] - pts[None, :, :], axis=2)
        rows, cols = np.nonzero(dist <= tol)
        keep = cols < rows + start
        if keep.any():
            j, i = int(rows[keep][0]) + start, int(cols[keep][0])
            raise ValueError(f"{what} {j} repeats {what} {i} at {pts[i].tolist()} "
                             f"(distance <= tol {tol:.3g}); a loop visits each point once")


def _check_simple(pts, tol, owner=None, what="segment"):
    """Refuse self-intersections of the closed polyline ``pts``.

    ``owner`` maps polyline segments to the loop segments named in messages.
    """
    n = pts.shape[0]
    nxt = np.roll(pts, -1, axis=0)
    name = (lambda k: f"{what} {k}") if owner is None else (lambda k: f"segment {int(owner[k])}")
    # Neighbouring segments share a vertex; they overlap only if the loop
    # folds back on itself there.
    prev = np.roll(pts, 1, axis=0)
    fold = np.minimum(_point_segment_distance(prev, pts, nxt),
                      _point_segment_distance(nxt, prev, pts))
    bad = np.flatnonzero(fold <= tol)
    if bad.size:
        k = int(bad[0])
        raise ValueError(f"loop folds back on itself at vertex {k if owner is None else int(owner[k])}"
                         f" ({pts[k].tolist()}): {name((k - 1) % n)} and {name(k)} overlap")
    for i in range(n - 2):
        j = np.arange(i + 2, n if i > 0 else n - 1)
        if j.size == 0:
            continue
        dist = segment_distances(np.repeat(pts[i:i + 1], j.size, 0), np.repeat(nxt[i:i + 1], j.size, 0),
                                 pts[j], nxt[j])
        hit = np.flatnonzero(dist <= tol)
        if hit.size:
            k = int(j[hit[0]])
            raise ValueError(f"loop intersects itself: {name(i)} and {name(k)} come within "
                             f"{dist[hit[0]]:.3g} (tol {tol:.3g})")


def _parse_planes(planes, modes, n):
    out = np.full((n, 4), np.nan)
    if planes is None:
        planes = [None] * n
    planes = list(planes)
    if len(planes) != n:
        raise ValueError(f"planes must give one entry (or None) per segment; got {len(planes)} "
                         f"for {n} segments")
    for i, (mode, plane) in enumerate(zip(modes, planes)):
        if plane is None:
            if mode == "sliding":
                raise ValueError(f"segment {i} is sliding but has no plane; give (origin, normal)")
            continue
        try:
            origin, normal = (np.asarray(x, dtype=np.float64) for x in plane)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"planes[{i}] must be (origin (3,), normal (3,)); got {plane!r}") from exc
        if origin.shape != (3,) or normal.shape != (3,) or not (np.all(np.isfinite(origin))
                                                               and np.all(np.isfinite(normal))):
            raise ValueError(f"planes[{i}] must be finite (origin (3,), normal (3,)); got {plane!r}")
        length = float(np.linalg.norm(normal))
        if length <= 1e-12:
            raise ValueError(f"planes[{i}] has a zero normal; got {normal.tolist()}")
        unit = normal / length
        out[i] = np.append(unit, unit @ origin)
    return out


def _parse_modes(modes, n):
    if isinstance(modes, str):
        modes = [modes] * n
    modes = tuple(str(m) for m in modes)
    if len(modes) != n:
        raise ValueError(f"modes must give one mode per segment; got {len(modes)} for {n} segments")
    for i, m in enumerate(modes):
        if m not in SEGMENT_MODES:
            raise ValueError(f"segment {i} has mode {m!r}; expected one of {SEGMENT_MODES}")
    return modes


# --------------------------------------------------------------------------
# constructors

def boundary_loop(points, *, modes="straight", planes=None, tol=None):
    """Validate a closed loop given by its vertices.

    Parameters
    ----------
    points : array_like, shape (n, 3), float
        Loop vertices in order, n >= 3, model units. The loop closes from the
        last vertex back to the first; a repeated first vertex at the end is
        dropped.
    modes : str or sequence of str, optional
        Mode of each segment (see module docstring), or one for all.
    planes : sequence, optional
        Per segment ``None`` or ``(origin (3,), normal (3,))``; required for
        sliding segments.
    tol : float, optional
        Absolute tolerance (model units); default ``1e-6`` times the
        bounding-box diagonal.

    Returns
    -------
    BoundaryLoop

    Raises
    ------
    ValueError
        Fewer than 3 vertices, NaN, repeated vertices, a self-intersecting or
        folded loop, unknown modes, a sliding segment without a plane or with
        a vertex off its plane; the message names the vertex or segment.
    """
    pts = _as_loop_points(points)
    tol = _default_tol(pts, tol)
    if pts.shape[0] > 3 and np.linalg.norm(pts[-1] - pts[0]) <= tol:
        pts = pts[:-1]
    n = pts.shape[0]
    if n < 3:
        raise ValueError(f"a boundary loop needs at least 3 vertices; got {n}")
    _check_repeats(pts, tol)
    mode_t = _parse_modes(modes, n)
    plane_arr = _parse_planes(planes, mode_t, n)
    for i, m in enumerate(mode_t):
        if m != "sliding":
            continue
        for k in (i, (i + 1) % n):
            off = abs(float(plane_arr[i, :3] @ pts[k] - plane_arr[i, 3]))
            if off > tol:
                raise ValueError(f"segment {i} slides in its plane but vertex {k} "
                                 f"({pts[k].tolist()}) is {off:.3g} off it (tol {tol:.3g})")
    _check_simple(pts, tol)
    pts = pts.copy()
    pts.setflags(write=False)
    plane_arr.setflags(write=False)
    return BoundaryLoop(points=pts, modes=mode_t, planes=plane_arr, tol=tol)


def loop_from_chains(chains, *, modes, planes=None, tol=None):
    """Join edge chains end to start into a closed loop.

    Parameters
    ----------
    chains : sequence of array_like, each shape (k_i, 3), k_i >= 2
        Polylines; chain ``c + 1`` starts where chain ``c`` ends and the last
        chain ends where the first starts.
    modes : str or sequence of str
        Mode of every segment of each chain (one per chain, or one for all).
    planes : sequence, optional
        Per chain ``None`` or ``(origin, normal)``.
    tol : float, optional
        As in :func:`boundary_loop`.

    Returns
    -------
    BoundaryLoop

    Raises
    ------
    ValueError
        An open loop (naming the chain whose end misses the next start), a
        chain with fewer than 2 points, or anything :func:`boundary_loop`
        refuses.
    """
    chains = [_as_loop_points(c, name=f"chains[{i}]") for i, c in enumerate(chains)]
    if not chains:
        raise ValueError("chains must hold at least one polyline; got none")
    for i, c in enumerate(chains):
        if c.shape[0] < 2:
            raise ValueError(f"chains[{i}] must hold at least 2 points; got {c.shape[0]}")
    tol = _default_tol(np.vstack(chains), tol)
    chain_modes = _parse_modes(modes, len(chains))
    chain_planes = [None] * len(chains) if planes is None else list(planes)
    if len(chain_planes) != len(chains):
        raise ValueError(f"planes must give one entry per chain; got {len(chain_planes)} "
                         f"for {len(chains)} chains")
    pts, seg_modes, seg_planes = [], [], []
    for i, c in enumerate(chains):
        nxt = chains[(i + 1) % len(chains)]
        gap = float(np.linalg.norm(c[-1] - nxt[0]))
        if gap > tol:
            which = "the first chain's start" if i == len(chains) - 1 else f"chains[{i + 1}]'s start"
            raise ValueError(f"loop is open: chains[{i}] ends at {c[-1].tolist()} but {which} is "
                             f"{nxt[0].tolist()} ({gap:.3g} apart, tol {tol:.3g})")
        pts.append(c[:-1])
        seg_modes += [chain_modes[i]] * (c.shape[0] - 1)
        seg_planes += [chain_planes[i]] * (c.shape[0] - 1)
    return boundary_loop(np.vstack(pts), modes=seg_modes, planes=seg_planes, tol=tol)


# --------------------------------------------------------------------------
# sampling

def _resample(polyline, pieces):
    """``pieces + 1`` points equally spaced in arc length along ``polyline``."""
    seg = np.linalg.norm(np.diff(polyline, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    targets = np.linspace(0.0, s[-1], pieces + 1)
    out = np.column_stack([np.interp(targets, s, polyline[:, k]) for k in range(3)])
    out[0], out[-1] = polyline[0], polyline[-1]
    return out


def _segment_curves(loop):
    """Dense polyline of each segment (smooth runs splined), list of (k, 3)."""
    n, pts, modes = loop.n_segments, loop.points, loop.modes
    curves = [np.vstack([pts[i], pts[(i + 1) % n]]) for i in range(n)]
    smooth = np.array([m == "smooth" for m in modes])
    if smooth.all():
        dense = interpolate_chain(pts, smooth=True, closed=True, samples_per_segment=_SPLINE_DENSITY)
        return [dense[i * _SPLINE_DENSITY:(i + 1) * _SPLINE_DENSITY + 1] for i in range(n)]
    start = int(np.flatnonzero(~smooth)[0])
    i = start
    for _ in range(n):
        if smooth[i] and not smooth[(i - 1) % n]:
            run = [i]
            while smooth[(run[-1] + 1) % n]:
                run.append((run[-1] + 1) % n)
            nodes = pts[[*run, (run[-1] + 1) % n]]
            dense = interpolate_chain(nodes, smooth=True, samples_per_segment=_SPLINE_DENSITY)
            for k, seg in enumerate(run):
                curves[seg] = dense[k * _SPLINE_DENSITY:(k + 1) * _SPLINE_DENSITY + 1]
        i = (i + 1) % n
    return curves


def sample_loop(loop, *, edge_length):
    """Discretise a loop into a closed polyline with per-sample constraints.

    Parameters
    ----------
    loop : BoundaryLoop
    edge_length : float
        Target sample spacing (model units, > 0); every segment is split into
        ``ceil(arc length / edge_length)`` equal arc-length pieces and keeps
        its end vertices exactly.

    Returns
    -------
    BoundarySamples

    Raises
    ------
    ValueError
        A bad ``edge_length``, or a smooth run whose spline crosses the loop.
    """
    h = float(edge_length)
    if not math.isfinite(h) or h <= 0.0:
        raise ValueError(f"edge_length must be a finite number > 0; got {edge_length!r}")
    n = loop.n_segments
    curves = _segment_curves(loop)
    sliding = np.array([m == "sliding" for m in loop.modes])
    pts, segment, vertex, fixed, planes = [], [], [], [], []
    for i, curve in enumerate(curves):
        length = float(np.linalg.norm(np.diff(curve, axis=0), axis=1).sum())
        pieces = max(1, int(math.ceil(length / h - 1e-9)))
        piece_pts = _resample(curve, pieces)[:-1]
        pts.append(piece_pts)
        segment.append(np.full(pieces, i))
        vertex.append(np.concatenate([[i], np.full(pieces - 1, -1)]))
        # The loop vertex at the start of segment i is fixed unless both of
        # its segments slide; inner samples follow their segment.
        corner_free = sliding[i] and sliding[(i - 1) % n]
        fixed.append(np.concatenate([[not corner_free], np.full(pieces - 1, not sliding[i])]))
        pl = np.full((pieces, 2, 4), np.nan)
        if sliding[i]:
            pl[:, 0] = loop.planes[i]
        if corner_free and not _same_plane(loop.planes[i], loop.planes[(i - 1) % n]):
            pl[0, 1] = loop.planes[(i - 1) % n]
        planes.append(pl)
    out = BoundarySamples(points=np.vstack(pts), segment=np.concatenate(segment).astype(np.int64),
                          vertex=np.concatenate(vertex).astype(np.int64),
                          fixed=np.concatenate(fixed).astype(bool), planes=np.concatenate(planes))
    if any(m == "smooth" for m in loop.modes):
        _check_repeats(out.points, loop.tol, what="boundary sample")
        _check_simple(out.points, loop.tol, owner=out.segment)
    return out


def _same_plane(p, q):
    return bool(np.allclose(p, q, atol=1e-12) or np.allclose(p, -q, atol=1e-12))
