"""Grow an oriented pattern in the infill space (paper 4.2-4.6, eqs. 8-14).

``grow`` seeds the empty state ``u = 1, v = 0`` with small discs / spheres
where ``v = 1`` (eq. 12), integrates eq. 13 with the fused kernel of
:mod:`engine.rd.gray_scott` and stops when the structure's relative rate
of change (eq. 14)

    G^t = | sum_Omega (u^{t+1} - u^t) | / (V_Omega dt)

falls below ``eps``. ``G`` is evaluated at the steps that are multiples of
``check_every`` (absolute step numbers, so a resumed run checks at the same
steps as an uninterrupted one) as the mean rate since the previous check,
``|sum_Omega (u^t - u^{t-n})| / (V_Omega n dt)``: with ``check_every=1``
that is eq. 14 itself; over ``n`` steps it averages out the sign changes of
the one-step sum in the oscillations after the growth phase, which would
otherwise dip below ``eps`` by chance. The structure is ``s = 1 - u``.

Orientation: for ``direction=i`` the tensors are ``sigma_i`` of eq. 11, and
the stripes (2D) / sheets (3D) grow *perpendicular* to ``rotation[..., :, i]``
(the fast diffusion direction of ``u`` is the pattern's wave vector).

Exactness. Cells more than ``n`` cells (Chebyshev) away from every cell
that differs from the empty state stay exactly empty for ``n`` steps, so
each run of ``n`` steps updates only the bounding box of the non-empty
cells grown by ``n``; the result is bit-for-bit what updating the whole
grid gives. Growing ``N`` steps, saving the state and resuming for ``M``
more equals growing ``N + M`` steps, bit for bit.

Cancelling (``progress`` returning False) stops after the last complete
step and returns the result with ``stop_reason == "cancelled"``; its
``state`` resumes the growth exactly.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from dataclasses import dataclass, field

import numpy as np

from engine.progress import PARALLEL_LOCK, TARGET_CHUNK_SECONDS, next_chunk

from .diffusion import diffusion_tensors
from .gray_scott import RDParams, Stepper, check_fields, resolve_params

__all__ = ["grow", "RDResult", "RDState", "GrowthInputs", "prepare_inputs", "place_seeds",
           "save_state", "load_state"]

STATE_FORMAT = "mesoforge-rd-state/1"


@dataclass(frozen=True)
class RDState:
    """Everything needed to continue a growth exactly.

    u, v : grid float64, concentrations after ``step`` steps
    step : int, steps taken since the seeds were placed
    time : float, ``step * dt``
    params : RDParams, resolved (``dt`` and ``lambda_`` set)
    direction : int, principal direction the growth follows
    inputs : str, digest of the infill space, tensors and infill map it was grown on
    history : (n, 2) float64, (step, G) at every check so far
    last_check : (int, float), step of the last check and the Omega sum of u then
    """

    u: np.ndarray
    v: np.ndarray
    step: int
    time: float
    params: RDParams
    direction: int
    inputs: str
    history: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    last_check: tuple | None = None


@dataclass(frozen=True)
class RDResult:
    """Outcome of :func:`grow`.

    u, v : grid float64 (views of ``state.u, state.v``); the structure is ``1 - u``
    steps : int, total steps of the state; time : float, ``steps * dt``
    history : (n, 2) float64, (step, G^t) at every check (eq. 14), from the first seed on
    stop_reason : "converged" (G < eps), "max_steps" or "cancelled"
    stop_step, stop_time : where it stopped; stop_g : G at the last check (nan if none)
    state : RDState to save or resume
    seeds : (n, d) float64, seed centres (x, y[, z]) placed by this call (empty when resumed)
    wall_time : float, seconds spent in this call
    """

    u: np.ndarray
    v: np.ndarray
    steps: int
    time: float
    history: np.ndarray
    stop_reason: str
    stop_step: int
    stop_time: float
    stop_g: float
    state: RDState
    seeds: np.ndarray
    wall_time: float


@dataclass(frozen=True)
class GrowthInputs:
    """Validated, derived inputs of one growth direction (what a state is tied to)."""

    inside: np.ndarray       # grid bool, Omega = {rho >= iso}
    sigma: np.ndarray        # grid + (d, d), eq. 11
    gamma_map: np.ndarray    # grid float in [0, 1]
    params: RDParams         # resolved
    direction: int
    digest: str


def _digest(inside, sigma, gamma_map, direction):
    h = hashlib.sha256()
    h.update(repr((inside.shape, int(direction))).encode())
    h.update(np.packbits(inside).tobytes())
    h.update(np.ascontiguousarray(sigma).tobytes())
    h.update(np.ascontiguousarray(gamma_map).tobytes())
    return h.hexdigest()[:32]


def prepare_inputs(rho, rotation, *, direction=0, gamma_map=None, iso=0.5, params=None) -> GrowthInputs:
    """Validate ``rho``, ``rotation``, ``gamma_map``, build ``sigma_i`` and resolve ``params``.

    Raises ValueError naming the input: bad shapes, NaN, a non-orthonormal
    rotation, an empty infill space, an unstable ``dt``.
    """
    rho = np.asarray(rho, dtype=np.float64)
    if rho.ndim not in (2, 3):
        raise ValueError(f"rho must be a 2D [y, x] or 3D [z, y, x] density grid; got shape {rho.shape}")
    if not np.isfinite(rho).all():
        raise ValueError("rho has NaN or infinite values; expected densities in [0, 1]")
    if not (isinstance(iso, (int, float, np.integer, np.floating)) and 0.0 < float(iso) < 1.0):
        raise ValueError(f"iso must be a threshold in (0, 1); got {iso!r}")
    inside = rho >= iso
    if not inside.any():
        raise ValueError(f"the infill space {{rho >= iso}} is empty (max rho = {rho.max():.4g}, "
                         f"iso = {iso:g}); lower iso or check rho")
    p = RDParams() if params is None else params
    if not isinstance(p, RDParams):
        raise ValueError(f"params must be an RDParams; got {type(p).__name__}")
    p = p.validated()
    rot = np.asarray(rotation, dtype=np.float64)
    if rot.shape[:-2] != rho.shape:
        raise ValueError(f"rotation must have shape {rho.shape + (rho.ndim, rho.ndim)} (rho's grid + (d, d)); "
                         f"got {rot.shape}")
    sigma = diffusion_tensors(rot, direction=direction, xi=p.xi)
    _, _, sigma, inside, gmap = check_fields(rho, rho, sigma, inside, gamma_map)
    p = resolve_params(sigma, p)
    return GrowthInputs(inside, sigma, gmap, p, int(direction), _digest(inside, sigma, gmap, direction))


# ------------------------------------------------------------------ seeds

def _point_cell(point, shape):
    """Cell index (array order) containing point (x, y[, z]) in cell units."""
    return tuple(int(math.floor(c)) for c in reversed(point))


def place_seeds(inside, *, seeds=None, radius=None, spacing=None, rng=None) -> np.ndarray:
    """Seed centres (n, d) in (x, y[, z]) cell units; centres of cells sit at half-integers.

    Parameters
    ----------
    inside : grid bool, the infill space
    seeds : None, int or (n, d) array_like
        None: one seed at the cell of Omega nearest the centroid of Omega;
        int n: n seeds drawn at random among Omega's cells with pairwise
        distance >= ``spacing`` (fewer if no more fit); array: given centres,
        each of which must lie in Omega.
    radius : float, seed radius in cells (for the default spacing)
    spacing : float or None, minimum centre distance for random seeds;
        None: 4 radii (a free gap of at least one diameter, paper 6.1)
    rng : None, int or numpy Generator

    Raises ValueError naming a seed outside the infill space.
    """
    dim = inside.ndim
    if seeds is None:
        cells = np.argwhere(inside).astype(np.float64)
        centroid = cells.mean(axis=0)
        best = cells[np.argmin(((cells - centroid) ** 2).sum(axis=1))]
        return (best[::-1] + 0.5)[None, :]
    if isinstance(seeds, (int, np.integer)) and not isinstance(seeds, bool):
        if seeds < 1:
            raise ValueError(f"seeds must be >= 1 when a count; got {seeds!r}")
        gen = np.random.default_rng(rng)
        gap = 4.0 * radius if spacing is None else float(spacing)
        if not (math.isfinite(gap) and gap >= 0):
            raise ValueError(f"seed_spacing must be a distance >= 0 in cells; got {spacing!r}")
        cells = np.argwhere(inside)
        order = gen.permutation(len(cells))
        chosen = []
        for idx in order:
            c = cells[idx][::-1] + 0.5
            if all(np.sum((c - o) ** 2) >= gap * gap for o in chosen):
                chosen.append(c)
                if len(chosen) == seeds:
                    break
        return np.array(chosen, dtype=np.float64).reshape(-1, dim)
    pts = np.asarray(seeds, dtype=np.float64)
    if pts.ndim == 1:
        pts = pts[None, :]
    if pts.ndim != 2 or pts.shape[1] != dim or len(pts) == 0:
        raise ValueError(f"seeds must be None, a count, or (n, {dim}) points (x, y[, z]) in cell units; "
                         f"got shape {pts.shape}")
    for n, p in enumerate(pts):
        cell = _point_cell(p, inside.shape)
        if not np.isfinite(p).all() or any(not 0 <= c < s for c, s in zip(cell, inside.shape)):
            raise ValueError(f"seeds[{n}] at {tuple(float(c) for c in p)} lies outside the grid "
                             f"{inside.shape[::-1]} (x, y[, z] cells)")
        if not inside[cell]:
            raise ValueError(f"seeds[{n}] at {tuple(float(c) for c in p)} lies outside the infill space "
                             f"(rho < iso at cell {list(cell)} [array order])")
    return pts


def _stamp(mask_shape, centres, radius):
    """Bool grid of the cells whose centres lie within ``radius`` of a centre."""
    out = np.zeros(mask_shape, dtype=bool)
    r = max(float(radius), 0.5)
    for c in centres:
        lo = [max(int(math.floor(cc - r)), 0) for cc in c[::-1]]
        hi = [min(int(math.ceil(cc + r)) + 1, n) for cc, n in zip(c[::-1], mask_shape)]
        if any(b <= a for a, b in zip(lo, hi)):
            continue
        axes = np.meshgrid(*[np.arange(a, b) + 0.5 for a, b in zip(lo, hi)], indexing="ij", sparse=True)
        d2 = sum((ax - cc) ** 2 for ax, cc in zip(axes, c[::-1]))
        out[tuple(slice(a, b) for a, b in zip(lo, hi))] |= d2 <= r * r
    return out


# ------------------------------------------------------------------ evolution

def _active_box(w, box):
    """Bounding box (array order, half-open) of the non-empty cells of ``w = [u, v]`` within ``box``, or None."""
    sl = tuple(slice(a, b) for a, b in box)
    busy = (w[0][sl] != 1.0) | (w[1][sl] != 0.0)
    if not busy.any():
        return None
    out = []
    for axis in range(busy.ndim):
        other = tuple(i for i in range(busy.ndim) if i != axis)
        idx = np.flatnonzero(busy.any(axis=other))
        out.append((box[axis][0] + int(idx[0]), box[axis][0] + int(idx[-1]) + 1))
    return tuple(out)


def _grown(box, n, limit):
    return tuple((max(a - n, lo), min(b + n, hi)) for (a, b), (lo, hi) in zip(box, limit))


class _ThreadPicker:
    """Picks 1 or all numba threads per chunk by measured throughput.

    On a machine shared with other work a parallel step can be several
    times slower than a serial one (every step ends in a barrier that waits
    for the slowest, possibly descheduled, thread), on an idle one it is
    faster. Results do not depend on the choice: no value is reduced across
    threads. Every ``PROBE_EVERY``-th chunk runs with the other setting for
    an eighth of its steps to follow changes in load (a probe on a busy
    machine then costs a few per cent).
    """

    PROBE_EVERY = 32
    #: Below this many cell updates per chunk one thread is used outright:
    #: the launch and barrier costs of a parallel step exceed the work.
    SERIAL_WORK = 2_000_000

    def __init__(self):
        import numba
        self._numba = numba
        self.saved = numba.get_num_threads()
        self.options = [self.saved, 1] if self.saved > 1 else [1]
        self.rate = {t: None for t in self.options}
        self.count = 0

    def choose(self, n, cells):
        """Threads for the next chunk of ``n`` steps on ``cells`` cells, and how many steps to run."""
        if len(self.options) == 1 or n * cells < self.SERIAL_WORK:
            self._numba.set_num_threads(1)
            return 1, n
        self.count += 1
        untried = [t for t in self.options if self.rate[t] is None]
        best = max(self.options, key=lambda t: self.rate[t] or 0.0)
        if untried and self.count > 1:
            t, n = untried[0], max(1, n // 8)
        elif len(self.options) > 1 and self.count % self.PROBE_EVERY == 0:
            t, n = [t for t in self.options if t != best][0], max(1, n // 8)
        else:
            t = best
        self._numba.set_num_threads(t)
        return t, n

    def record(self, threads, work, seconds):
        if work < 50_000 or seconds <= 0:     # too small to time
            return
        r = work / seconds
        old = self.rate[threads]
        self.rate[threads] = r if old is None else 0.5 * (old + r)

    def restore(self):
        self._numba.set_num_threads(self.saved)


@dataclass
class _Run:
    step: int
    history: list
    last_check: tuple       # (step, sum of u over Omega) at the previous check
    reason: str = ""
    g: float = float("nan")


def evolve(stepper: Stepper, w, *, inside, step, eps, max_steps, check_every, window=None,
           track_empty=True, progress=None, history=(), last_check=None, volume=None) -> _Run:
    """Advance ``w = [u, v]`` in place from absolute ``step`` until G < eps, ``max_steps`` or a cancel.

    ``window`` (tuple of (start, stop) per axis) restricts the update and the
    Omega sum of eq. 14 to a box, the rest being frozen; ``track_empty``
    skips cells that are exactly empty and out of reach (bit-exact).
    ``last_check`` is (step, Omega sum of u) at the previous check; None:
    this step and the current ``u``. ``volume`` divides the sum in eq. 14;
    None: the number of Omega cells in the window.
    """
    shape = w.shape[1:]
    window = tuple((0, n) for n in shape) if window is None else window
    sl = tuple(slice(a, b) for a, b in window)
    if not inside[sl].any():
        raise ValueError("the window contains no cell of the infill space")
    volume = float(np.count_nonzero(inside[sl]) if volume is None else volume)
    if last_check is None:
        with PARALLEL_LOCK:
            last_check = (int(step), stepper.omega_sum(w, window))
    run = _Run(step=int(step), history=list(history), last_check=last_check)
    picker = _ThreadPicker()
    try:
        return _loop(stepper, w, run, picker, volume, window, eps, max_steps, check_every, track_empty,
                     progress)
    finally:
        picker.restore()


def _loop(stepper, w, run, picker, volume, window, eps, max_steps, check_every, track_empty, progress):
    dt = stepper.params.dt
    active = _active_box(w, window) if track_empty else window
    chunk = check_every if progress is None else 1
    t_report = -math.inf          # report after the first chunk, then every TARGET_CHUNK_SECONDS
    while True:
        if run.step >= max_steps:
            run.reason = "max_steps"
            return run
        next_check = (run.step // check_every + 1) * check_every
        n = min(chunk, next_check - run.step, max_steps - run.step)
        reach = window if active is None else _grown(active, n, window) if track_empty else window
        threads, n = picker.choose(n, math.prod(b - a for a, b in reach))
        # None: nothing in reach can ever change
        box = None if active is None else (_grown(active, n, window) if track_empty else window)
        with PARALLEL_LOCK:
            t0 = time.perf_counter()
            if box is not None:
                stepper.run(w, n, box)
            elapsed = time.perf_counter() - t0
            run.step += n
            if run.step == next_check:
                total = stepper.omega_sum(w, window)
        if box is not None:
            picker.record(threads, n * math.prod(b - a for a, b in box), elapsed)
        if track_empty and box is not None:
            # once the box is the whole window there is nothing left to skip
            active = _active_box(w, box) if box != window else window
        if run.step == next_check:
            s0, total0 = run.last_check
            run.g = abs(total - total0) / (volume * (run.step - s0) * dt)
            run.last_check = (run.step, total)
            run.history.append((run.step, run.g))
            if run.g < eps:
                run.reason = "converged"
                return run
        if progress is not None:
            if elapsed > 0:       # aim at ~TARGET_CHUNK_SECONDS per chunk, growing by <= 4x at a time
                chunk = next_chunk(chunk, n, elapsed, most=check_every)
            now = time.perf_counter()
            if now - t_report >= TARGET_CHUNK_SECONDS or run.step >= max_steps:
                t_report = now
                answer = progress(int(run.step), int(max_steps))
                if answer is not None and not answer:
                    run.reason = "cancelled"
                    return run


def _check_count(name, value, minimum):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}; got {value!r}")
    return int(value)


def grow(rho, rotation, *, direction=0, gamma_map=None, iso=0.5, params=None, seeds=None,
         seed_radius=None, seed_spacing=None, eps=1e-7, max_steps=200_000, check_every=50,
         rng=None, progress=None, state=None) -> RDResult:
    """Grow the pattern of principal direction ``direction`` in ``Omega = {rho >= iso}``.

    Parameters
    ----------
    rho : (ny, nx) or (nz, ny, nx) float in [0, 1], infill density on the growth grid
    rotation : grid + (d, d) float64, principal directions as columns, (x, y[, z]) components
    direction : int, the column of ``rotation`` whose fast diffusion orients this pattern;
        stripes / sheets grow perpendicular to it
    gamma_map : grid float in [0, 1] or None, infill map ``Gamma`` (solid where 1, eq. 10)
    iso : float in (0, 1), threshold of the infill space
    params : RDParams or None (defaults); ``dt=None`` takes ``default_dt`` (0.9 of the stable limit)
    seeds : None (one seed nearest the centroid of Omega), int (that many random
        seeds, ``rng``), or (n, d) centres (x, y[, z]) in cell units (cell centres at
        half-integers), each inside Omega
    seed_radius : float or None, in cells; None: 0.05 x the longest grid side (paper 6.1)
    seed_spacing : float or None, minimum distance of random seeds; None: 4 radii
    eps : float, threshold of the stopping criterion G^t (eq. 14)
    max_steps : int, absolute step limit (counting the resumed state's steps)
    check_every : int, G is evaluated at steps that are multiples of this
    rng : None, int or numpy Generator, for random seeds only
    progress : callable(done_steps, max_steps) -> bool or None; False cancels
    state : RDState or None, resume it (seeds must then be None; params None or equal)

    Returns
    -------
    RDResult
    """
    t_start = time.perf_counter()
    eps = float(eps)
    if not (math.isfinite(eps) and eps > 0):
        raise ValueError(f"eps must be a positive threshold; got {eps!r}")
    max_steps = _check_count("max_steps", max_steps, 0)
    check_every = _check_count("check_every", check_every, 1)
    if state is not None and params is None:
        params = state.params
    inputs = prepare_inputs(rho, rotation, direction=direction, gamma_map=gamma_map, iso=iso, params=params)
    shape = inputs.inside.shape
    if state is None:
        radius = 0.05 * max(shape) if seed_radius is None else float(seed_radius)
        if not (math.isfinite(radius) and radius > 0):
            raise ValueError(f"seed_radius must be a positive length in cells; got {seed_radius!r}")
        centres = place_seeds(inputs.inside, seeds=seeds, radius=radius, spacing=seed_spacing, rng=rng)
        u = np.ones(shape)
        v = np.zeros(shape)
        v[_stamp(shape, centres, radius)] = 1.0
        u0, v0 = u, v
        step, history, last_check = 0, (), None
    else:
        if seeds is not None:
            raise ValueError("seeds and state are exclusive: a resumed growth keeps its seeds")
        _check_resumable(state, inputs)
        u0, v0 = state.u, state.v
        step, history = int(state.step), [tuple(r) for r in state.history]
        last_check = state.last_check
        centres = np.zeros((0, len(shape)))
    stepper = Stepper(inputs.sigma, inputs.inside, inputs.gamma_map, inputs.params)
    w = stepper.new_state(u0, v0)
    u, v = w[0], w[1]
    run = evolve(stepper, w, inside=inputs.inside, step=step, eps=eps, max_steps=max_steps,
                 check_every=check_every, progress=progress, history=history, last_check=last_check)
    dt = inputs.params.dt
    hist = np.array(run.history, dtype=np.float64).reshape(-1, 2)
    new_state = RDState(u, v, run.step, run.step * dt, inputs.params, inputs.direction, inputs.digest, hist,
                        run.last_check)
    return RDResult(u, v, run.step, run.step * dt, hist, run.reason, run.step, run.step * dt, run.g,
                    new_state, centres, time.perf_counter() - t_start)


def _check_resumable(state, inputs):
    if not isinstance(state, RDState):
        raise ValueError(f"state must be an RDState; got {type(state).__name__}")
    if state.u.shape != inputs.inside.shape:
        raise ValueError(f"state is for a grid of shape {state.u.shape}, not {inputs.inside.shape}")
    if state.params != inputs.params:
        raise ValueError(f"state was grown with params {state.params}, not {inputs.params}; "
                         f"resume with params=None")
    if state.direction != inputs.direction:
        raise ValueError(f"state grows direction {state.direction}, not {inputs.direction}")
    if state.inputs != inputs.digest:
        raise ValueError("state was grown on a different infill space, rotation field or infill map "
                         "(input digest differs)")


# ------------------------------------------------------------------ files

def save_state(state: RDState, path) -> None:
    """Write ``state`` to an ``.npz`` file (no pickles)."""
    meta = {"format": STATE_FORMAT, "step": int(state.step), "time": float(state.time),
            "params": state.params.to_dict(), "direction": int(state.direction), "inputs": state.inputs,
            "last_check": None if state.last_check is None else [int(state.last_check[0]),
                                                                  float(state.last_check[1])]}
    with open(path, "wb") as fh:
        np.savez(fh, u=state.u, v=state.v, history=np.asarray(state.history, dtype=np.float64).reshape(-1, 2),
                 meta=np.array(json.dumps(meta)))


def load_state(path) -> RDState:
    """Read a state written by :func:`save_state`; refuses other files naming what is wrong."""
    try:
        with np.load(path, allow_pickle=False) as data:
            meta = json.loads(str(data["meta"]))
            u, v, history = data["u"], data["v"], data["history"]
    except (OSError, KeyError, ValueError) as exc:
        raise ValueError(f"{path}: not a reaction/diffusion state file ({exc})") from None
    if meta.get("format") != STATE_FORMAT:
        raise ValueError(f"{path}: format {meta.get('format')!r}, expected {STATE_FORMAT!r}")
    if u.shape != v.shape or u.dtype != np.float64 or v.dtype != np.float64:
        raise ValueError(f"{path}: u and v must be float64 grids of one shape; got {u.shape}, {v.shape}")
    last = meta.get("last_check")
    return RDState(u, v, int(meta["step"]), float(meta["time"]), RDParams.from_dict(meta["params"]),
                   int(meta["direction"]), str(meta["inputs"]), history,
                   None if last is None else (int(last[0]), float(last[1])))
