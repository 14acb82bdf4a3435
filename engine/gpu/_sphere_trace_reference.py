"""Slow, obviously correct ray casting of an SDF in numpy (float64): the references
the GPU sphere tracer (`engine.gpu.sphere_trace`) is tested and timed against.

* `clip_rays` -- the ray parameter interval inside an axis-aligned box;
* `march_fixed` -- plain Lipschitz sphere tracing, ``t += f(p) / L``, all
  rays at once (one vectorised `SDF.distance` call per step over the rays
  still marching), with the tracer's hit rule ``f / L < epsilon`` tested
  before each step;
* `march_dense` -- no distance bound used at all: the field sampled at fixed
  tiny increments, the first sample with ``f <= 0`` taken as the crossing
  and refined by bisection on f's sign.

Rays are (n, 3) origins and unit directions in mm; ``t`` is the distance
along the ray (mm), ``inf`` where nothing was hit.
"""

from __future__ import annotations

import numpy as np

from engine.implicit.values import SDF

__all__ = ["clip_rays", "march_fixed", "march_dense"]


def _rays(origins, directions) -> tuple[np.ndarray, np.ndarray]:
    o = np.asarray(origins, dtype=np.float64).reshape(-1, 3)
    d = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    if o.shape != d.shape:
        raise ValueError(f"origins {o.shape} and directions {d.shape} must hold the same number of rays")
    return o, d


def clip_rays(origins, directions, lo, hi, far: float) -> tuple[np.ndarray, np.ndarray]:
    """The part ``[t0, t1]`` of each ray ``o + t d, 0 <= t <= far`` inside the box [lo, hi].

    Returns
    -------
    t0, t1 : (n,) float64, mm; ``t0 > t1`` where the ray misses the box
    """
    o, d = _rays(origins, directions)
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        ta, tb = (lo - o) / d, (hi - o) / d
    # a coordinate that does not change along the ray: inside its slab or not
    parallel = d == 0.0
    inside = (o >= lo) & (o <= hi)
    near = np.where(parallel, np.where(inside, -np.inf, np.inf), np.minimum(ta, tb))
    away = np.where(parallel, np.where(inside, np.inf, -np.inf), np.maximum(ta, tb))
    return np.maximum(near.max(axis=1), 0.0), np.minimum(away.min(axis=1), float(far))


def march_fixed(sdf: SDF, origins, directions, t0, t1, *, epsilon: float, max_steps: int):
    """Lipschitz sphere tracing on every ray at once.

    Each ray starts at ``t0``; while it marches, a hit is ``f / L < epsilon``
    at the current point, a miss is ``t > t1`` or `max_steps` evaluations.

    Returns
    -------
    t : (n,) float64, mm, ``inf`` on a miss
    hit : (n,) bool
    steps : (n,) int64, evaluations of the SDF per ray (0 where ``t0 > t1``)
    """
    o, d = _rays(origins, directions)
    t = np.array(t0, dtype=np.float64).reshape(-1).copy()
    t1 = np.asarray(t1, dtype=np.float64).reshape(-1)
    n = len(t)
    hit = np.zeros(n, bool)
    steps = np.zeros(n, np.int64)
    active = np.flatnonzero(t <= t1)
    while active.size:
        dist = sdf.distance(o[active] + t[active, None] * d[active])
        steps[active] += 1
        done = dist < epsilon
        hit[active[done]] = True
        t[active] += np.where(done, 0.0, dist)
        keep = ~done & (t[active] <= t1[active]) & (steps[active] < max_steps)
        active = active[keep]
    t[~hit] = np.inf
    return t, hit, steps


def march_dense(sdf: SDF, origins, directions, t0, t1, *, dt: float, bisections: int = 60,
                chunk: int = 64):
    """The first sign change of f along each ray, found without any distance bound.

    f is sampled at ``t0 + k dt`` (k = 0, 1, ... up to and including ``t1``);
    the first sample with ``f <= 0`` is the crossing (at ``t0`` itself if the
    ray starts inside), refined by `bisections` halvings of the last bracket.
    A surface only touched between two samples, or crossed twice within
    ``dt``, is missed: `dt` must be small next to the scene's features.

    Returns
    -------
    t : (n,) float64, mm, ``inf`` where f stays positive
    hit : (n,) bool
    """
    if not dt > 0:
        raise ValueError(f"dt must be > 0 mm, got {dt!r}")
    o, d = _rays(origins, directions)
    t0 = np.asarray(t0, dtype=np.float64).reshape(-1)
    t1 = np.asarray(t1, dtype=np.float64).reshape(-1)
    n = len(t0)
    t = np.full(n, np.inf)
    lo_t = np.full(n, np.nan)               # last sample with f > 0 before the crossing
    active = np.flatnonzero(t0 <= t1)
    k0 = 0
    while active.size:
        ks = k0 + np.arange(chunk)
        ts = np.minimum(t0[active, None] + ks[None, :] * dt, t1[active, None])   # (m, chunk)
        pts = o[active, None, :] + ts[..., None] * d[active, None, :]
        f = sdf.field(pts.reshape(-1, 3)).reshape(ts.shape)
        inside = f <= 0.0
        first = np.argmax(inside, axis=1)
        found = inside[np.arange(len(active)), first]
        rows = active[found]
        t[rows] = ts[found, first[found]]
        prev = first[found] - 1
        before = np.minimum(t0[rows] + (k0 - 1) * dt, t1[rows])   # the previous chunk's last sample
        lo_t[rows] = np.where(prev >= 0, ts[found, np.maximum(prev, 0)], np.where(k0 > 0, before, np.nan))
        ended = ts[:, -1] >= t1[active]
        active = active[~found & ~ended]
        k0 += chunk
    # bisection on the bracket [lo_t (f > 0), t (f <= 0)]
    br = np.flatnonzero(np.isfinite(t) & np.isfinite(lo_t))
    a, b = lo_t[br], t[br]
    for _ in range(bisections):
        m = 0.5 * (a + b)
        fm = sdf.field(o[br] + m[:, None] * d[br])
        a, b = np.where(fm > 0, m, a), np.where(fm > 0, b, m)
    t[br] = b
    return t, np.isfinite(t)
