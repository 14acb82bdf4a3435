"""Local correction of a grown pattern: erase or draw, then let it regrow (paper 6.1, 6.9).

A brush (a disc in 2D, a sphere in 3D, radius in cells) or any painted
region sets ``u, v`` to the empty state (``erase``: ``u = 1, v = 0``) or to
the solid state (``draw``). The growth then resumes on an *active window*
only, the bounding box of the region grown by ``margin`` cells; every cell
outside the window keeps its bytes and is read as a frozen boundary value,
so the new pattern reconnects to the old one. It stops on the criterion of
eq. 14 for the whole grid, ``|sum_Omega (u^t - u^{t-n})| / (V_Omega n dt) <
eps``, in which only the window's cells can contribute (the rest do not
change), as the paper times its local reconstructions (T_2%, Table 3).

The solid state is the uniform steady state of the reaction at the kill
rate of a fully solid infill map (``Gamma = 1``, eq. 10),
``u = (1 - sqrt(1 - 4 s^2 / F)) / 2``, ``v = s / u`` with
``s = k (1 - alpha) + F``: what regions with ``Gamma = 1`` grow into.
(Without such a state, ``4 s^2 >= F``, a seed's ``u = v = 1`` is used.)
Drawing only affects the infill space; elsewhere ``v`` is absorbed anyway.
"""

from __future__ import annotations

import math
import time
from typing import NamedTuple

import numpy as np

from .growth import RDState, _check_count, _check_resumable, _stamp, evolve, prepare_inputs
from .gray_scott import RDParams, Stepper

__all__ = ["regrow", "RegrowResult", "brush_region", "solid_state"]


class RegrowResult(NamedTuple):
    """Outcome of :func:`regrow`.

    state : RDState after the regrowth (``step`` advanced by ``steps``)
    box : tuple of slices (array order), the window; no cell outside it changed
    region : grid bool, the cells the brush set
    steps : int, regrowth steps; time : float, ``steps * dt``
    history : (n, 2) float64, (step since the brush, G)
    stop_reason : "converged", "max_steps" or "cancelled"
    wall_time : float, seconds
    """

    state: RDState
    box: tuple
    region: np.ndarray
    steps: int
    time: float
    history: np.ndarray
    stop_reason: str
    wall_time: float


def solid_state(params: RDParams) -> tuple[float, float]:
    """(u, v) of the solid state used by ``draw`` (module docstring)."""
    s = params.k * (1.0 - params.alpha) + params.F
    disc = 1.0 - 4.0 * s * s / params.F if params.F > 0 else -1.0
    if disc <= 0:
        return 1.0, 1.0
    u = 0.5 * (1.0 - math.sqrt(disc))
    return u, s / u


def brush_region(shape, centre, radius) -> np.ndarray:
    """Cells whose centres lie within ``radius`` of ``centre`` (x, y[, z], cell units)."""
    c = np.asarray(centre, dtype=np.float64).reshape(-1)
    if c.shape != (len(shape),) or not np.isfinite(c).all():
        raise ValueError(f"centre must be {len(shape)} finite coordinates (x, y[, z]) in cells; got {centre!r}")
    r = float(radius)
    if not (math.isfinite(r) and r > 0):
        raise ValueError(f"radius must be a positive length in cells; got {radius!r}")
    return _stamp(tuple(shape), c[None, :], r)


def _window(region, margin):
    idx = np.argwhere(region)
    lo = np.maximum(idx.min(axis=0) - margin, 0)
    hi = np.minimum(idx.max(axis=0) + 1 + margin, region.shape)
    return tuple((int(a), int(b)) for a, b in zip(lo, hi))


def regrow(state: RDState, rho, rotation, *, region=None, centre=None, radius=None, mode="erase",
           gamma_map=None, iso=0.5, margin=4, eps=1e-7, max_steps=50_000, check_every=50,
           progress=None) -> RegrowResult:
    """Erase or draw a region of a grown pattern and regrow it locally.

    Parameters
    ----------
    state : RDState from :func:`engine.rd.growth.grow` (or an earlier regrowth)
    rho, rotation, gamma_map, iso : the inputs the state was grown with (checked by digest)
    region : grid bool or None, the cells to set; or give ``centre`` and ``radius``
    centre : (d,) float, brush centre (x, y[, z]) in cell units (cell centres at half-integers)
    radius : float, brush radius in cells
    mode : "erase" (u = 1, v = 0) or "draw" (the solid state, inside the infill space)
    margin : int >= 0, cells added around the region's box to form the window. The
        default, 4, is about half a stripe period at the usual 8-10 cell wavelengths:
        room for the old stripes to bend into the new ones. A wider margin lets
        defects glide further before the window settles (measured: 8 cells took
        ~1.5x the steps of 4 on the cantilever test)
    eps : float, stopping threshold of eq. 14 (sum over the window, divided by V_Omega)
    max_steps : int, most regrowth steps (counted from the brush)
    check_every : int, steps between evaluations of G
    progress : callable(done, max_steps) -> bool or None; False stops after the last
        complete step (stop_reason "cancelled")

    Returns
    -------
    RegrowResult
    """
    t_start = time.perf_counter()
    if not isinstance(state, RDState):
        raise ValueError(f"state must be an RDState; got {type(state).__name__}")
    if mode not in ("erase", "draw"):
        raise ValueError(f"mode must be 'erase' or 'draw'; got {mode!r}")
    max_steps = _check_count("max_steps", max_steps, 0)
    check_every = _check_count("check_every", check_every, 1)
    eps = float(eps)
    if not (math.isfinite(eps) and eps > 0):
        raise ValueError(f"eps must be a positive threshold; got {eps!r}")
    inputs = prepare_inputs(rho, rotation, direction=state.direction, gamma_map=gamma_map, iso=iso,
                            params=state.params)
    _check_resumable(state, inputs)
    shape = inputs.inside.shape
    if region is None:
        if centre is None or radius is None:
            raise ValueError("give either region (a bool grid) or centre and radius of a brush")
        region = brush_region(shape, centre, radius)
    else:
        region = np.asarray(region)
        if region.shape != shape:
            raise ValueError(f"region must have the grid shape {shape}; got {region.shape}")
        region = region.astype(bool)
    if not region.any():
        raise ValueError("the brush region contains no cell of the grid")
    margin = _check_count("margin", margin, 0)
    window = _window(region, margin)
    if not inputs.inside[tuple(slice(a, b) for a, b in window)].any():
        raise ValueError(f"the brush region and its margin of {margin} cells hold no cell of the infill "
                         f"space (rho >= iso = {iso:g}): nothing can grow there")
    stepper = Stepper(inputs.sigma, inputs.inside, inputs.gamma_map, inputs.params)
    w = stepper.new_state(state.u, state.v)
    if mode == "erase":
        w[0][region] = 1.0
        w[1][region] = 0.0
    else:
        us, vs = solid_state(inputs.params)
        paint = region & inputs.inside
        w[0][paint] = us
        w[1][paint] = vs
    run = evolve(stepper, w, inside=inputs.inside, step=0, eps=eps, max_steps=max_steps,
                 check_every=check_every, window=window, track_empty=False, progress=progress,
                 volume=float(np.count_nonzero(inputs.inside)))
    dt = inputs.params.dt
    step = state.step + run.step
    new_state = RDState(w[0], w[1], step, step * dt, inputs.params, inputs.direction, inputs.digest,
                        np.asarray(state.history), None)
    box = tuple(slice(a, b) for a, b in window)
    hist = np.array(run.history, dtype=np.float64).reshape(-1, 2)
    return RegrowResult(new_state, box, region, run.step, run.step * dt, hist, run.reason,
                        time.perf_counter() - t_start)
