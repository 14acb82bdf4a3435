"""Kernel sites of the two phasor noises p_v and p_w (Tricard et al. 2021, 3.2.2).

Sites sit on a virtual grid of cubic cells whose edge is the kernel radius
``R = c / F_min``; every cell holds ``per_cell`` sites at uniform random
positions.  Each site takes its frequency from F and its two directions from
the local frame of D (:func:`local_frame`); the p_v direction is tilted
about w by ``spread_u * Gamma`` with ``spread_u`` uniform in [-1, 1].
Phases start at 0 (phase alignment sets them, see :mod:`.align`).

The random draws (positions, then ``spread_u``) depend only on the seed and
the grid, never on the field values, so :func:`resample_kernels` can redo the
oscillators of a painted region and get exactly what a fresh sample of the
painted fields would give.
"""

from __future__ import annotations

import math

import numpy as np

from .fields import PhasorFields
from .kernels import C_BANDWIDTH, KERNELS_PER_CELL, PhasorKernels, replace_kernels

# Below this |z x D| the direction counts as vertical and the frame falls back
# to the x axis (see local_frame).
VERTICAL_EPS = 1e-6
MAX_SITES = 50_000_000


def local_frame(direction) -> tuple:
    """The diamond diagonals ``v = z x D`` and ``w = (z x D) x D``, normalised.

    Parameters
    ----------
    direction : (n, 3) float64, unit vectors D

    Returns
    -------
    v, w : (n, 3) float64; (v, w, D) is a right-handed orthonormal frame
        (w = v x D).

    Notes
    -----
    Where D is vertical (``|z x D| < 1e-6``) z x D has no direction; there
    ``v`` is the x axis made orthogonal to D (``x - (x.D) D``, normalised), so
    D = +z gives v = +x, w = -y and D = -z gives v = +x, w = +y.  Every
    evaluator (numpy, GLSL) must use this same fallback.
    """
    d = np.asarray(direction, dtype=np.float64).reshape(-1, 3)
    zxd = np.stack([-d[:, 1], d[:, 0], np.zeros(len(d))], axis=1)
    norm = np.linalg.norm(zxd, axis=1)
    vertical = norm < VERTICAL_EPS
    v = zxd / np.where(vertical, 1.0, norm)[:, None]
    if vertical.any():
        dv = d[vertical]
        x_perp = np.array([1.0, 0.0, 0.0]) - dv[:, :1] * dv
        v[vertical] = x_perp / np.linalg.norm(x_perp, axis=1)[:, None]
    w = np.cross(v, d)
    w /= np.linalg.norm(w, axis=1)[:, None]
    return v, w


def rotate_about(vectors, axes, angles) -> np.ndarray:
    """Rodrigues rotation of ``vectors`` (n, 3) about unit ``axes`` (n, 3) by ``angles`` (n,) radians."""
    cos = np.cos(angles)[:, None]
    sin = np.sin(angles)[:, None]
    along = np.sum(axes * vectors, axis=1)[:, None]
    return vectors * cos + np.cross(axes, vectors) * sin + axes * along * (1.0 - cos)


def site_oscillators(fields: PhasorFields, positions, spread_u) -> tuple:
    """Frequency and the two directions of sites at ``positions``.

    Parameters
    ----------
    fields : PhasorFields
    positions : (n, 3) float64, mm
    spread_u : (n,) float64 in [-1, 1], the site's share of the spread Gamma

    Returns
    -------
    frequency : (n,) float64, cycles/mm
    direction_v, direction_w : (n, 3) float64, unit vectors
    """
    pos = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    frequency = fields.sample_frequency(pos)
    v, w = local_frame(fields.sample_direction(pos))
    tilt = np.asarray(spread_u, dtype=np.float64) * fields.sample_spread(pos)
    return frequency, rotate_about(v, w, tilt), w


def _generator(rng) -> tuple:
    """(seed recorded on the kernels, Generator); a Generator records seed -1."""
    if rng is None:
        rng = 0
    if isinstance(rng, np.random.Generator):
        return -1, rng
    if isinstance(rng, (int, np.integer)) and not isinstance(rng, bool) and rng >= 0:
        return int(rng), np.random.default_rng(int(rng))
    raise ValueError(f"rng: expected a non-negative int seed or a numpy Generator, got {rng!r}")


def _box(fields, box) -> tuple:
    if box is None:
        return fields.lo.copy(), fields.hi.copy()
    lo, hi = (np.asarray(b, dtype=np.float64) for b in box)
    if lo.shape != (3,) or hi.shape != (3,) or not np.all(np.isfinite(lo)) or not np.all(np.isfinite(hi)) \
            or np.any(hi <= lo):
        raise ValueError(f"box: expected ((x0, y0, z0), (x1, y1, z1)) mm with hi > lo, got {box!r}")
    return lo, hi


def sample_kernels(fields: PhasorFields, *, per_cell: int = KERNELS_PER_CELL, c: float = C_BANDWIDTH,
                   rng=None, box=None) -> PhasorKernels:
    """Random kernel sites and oscillators for the fields.

    Parameters
    ----------
    fields : PhasorFields
    per_cell : int, sites per grid cell (paper: 8)
    c : float, kernel radius in periods of the lowest frequency, ``R = c / F_min``
    rng : int seed (default 0) or numpy Generator
    box : ((3,), (3,)) mm or None; the region to cover (default the fields' box)

    Returns
    -------
    PhasorKernels
        Cells of edge R cover ``box`` plus one cell of margin on every side
        (so points near the boundary see full neighbourhoods); cell
        ``(ix, iy, iz)`` holds rows ``per_cell * flat : per_cell * (flat + 1)``.
        Phases are 0.
    """
    per_cell = int(per_cell)
    if per_cell < 1:
        raise ValueError(f"per_cell: expected at least 1 site per cell, got {per_cell}")
    if not (math.isfinite(c) and c > 0):
        raise ValueError(f"c: expected a positive number of periods per kernel radius, got {c!r}")
    seed, gen = _generator(rng)
    lo, hi = _box(fields, box)
    radius = float(c) / fields.min_frequency()
    grid = np.ceil((hi - lo) / radius).astype(np.int64) + 2
    n_cells = int(np.prod(grid))
    n = n_cells * per_cell
    if n > MAX_SITES:
        raise ValueError(f"sample_kernels: {n} sites ({grid.tolist()} cells of {radius:.3g} mm x {per_cell}) "
                         f"exceed {MAX_SITES}; lower F's range or per_cell")
    origin = lo - radius
    flat = np.repeat(np.arange(n_cells, dtype=np.int64), per_cell)
    cell = np.stack([flat % grid[0], (flat // grid[0]) % grid[1], flat // (grid[0] * grid[1])], axis=1)
    # Keep u < 1 after rounding so each site lies inside the cell it is filed under.
    u = np.minimum(gen.random((n, 3)), 1.0 - 1e-12)
    positions = origin + (cell + u) * radius
    spread_u = gen.uniform(-1.0, 1.0, n)
    frequency, direction_v, direction_w = site_oscillators(fields, positions, spread_u)
    zeros = np.zeros(n)
    return PhasorKernels(origin=origin, radius=radius, grid=grid,
                         cell_start=np.arange(0, n + 1, per_cell, dtype=np.int64),
                         positions=positions, frequency=frequency, direction_v=direction_v,
                         direction_w=direction_w, phase_v=zeros, phase_w=zeros, spread_u=spread_u,
                         seed=seed, info={"per_cell": per_cell, "c": float(c), "box": (lo, hi)})


def site_cells(kernels: PhasorKernels) -> np.ndarray:
    """(n,) int64 flat cell index each site is filed under."""
    counts = np.diff(kernels.cell_start)
    return np.repeat(np.arange(len(counts), dtype=np.int64), counts)


def _region_sites(kernels: PhasorKernels, region) -> np.ndarray:
    if isinstance(region, np.ndarray) and region.dtype == bool:
        n_cells = int(np.prod(kernels.grid))
        if region.size != n_cells or region.shape not in ((n_cells,), tuple(kernels.grid[::-1])):
            raise ValueError(f"region: a cell mask must have shape ({n_cells},) or "
                             f"{tuple(int(g) for g in kernels.grid[::-1])} (z, y, x), got {region.shape}")
        return np.flatnonzero(region.reshape(-1)[site_cells(kernels)])
    try:
        lo, hi = (np.asarray(b, dtype=np.float64) for b in region)
    except (TypeError, ValueError):
        lo = hi = None
    if lo is None or lo.shape != (3,) or hi.shape != (3,):
        raise ValueError("region: expected a boolean cell mask over the kernel grid or a box "
                         f"((x0, y0, z0), (x1, y1, z1)) in mm, got {region!r}")
    inside = np.all((kernels.positions >= lo) & (kernels.positions <= hi), axis=1)
    return np.flatnonzero(inside)


def resample_kernels(kernels: PhasorKernels, fields: PhasorFields, region) -> tuple:
    """Redo f, d_v and d_w of the sites in ``region`` from (repainted) fields.

    Positions, ``spread_u``, phases and the radius are kept, so resampling
    every site equals a fresh :func:`sample_kernels` of ``fields`` with the
    same seed (apart from the phases).  The radius stays ``c / F_min`` of the
    fields the kernels were first sampled from; resample from scratch when
    painting lowers F_min a lot.

    Parameters
    ----------
    kernels : PhasorKernels
    fields : PhasorFields
    region : bool array over the kernel cells, shape (n_cells,) or
        (gz, gy, gx), or a box ``((x0, y0, z0), (x1, y1, z1))`` mm (closed)

    Returns
    -------
    kernels : PhasorKernels, the updated copy
    changed : (m,) int64, sorted indices of the resampled sites
    """
    idx = _region_sites(kernels, region)
    frequency = kernels.frequency.copy()
    direction_v = kernels.direction_v.copy()
    direction_w = kernels.direction_w.copy()
    if len(idx):
        f, dv, dw = site_oscillators(fields, kernels.positions[idx], kernels.spread_u[idx])
        frequency[idx], direction_v[idx], direction_w[idx] = f, dv, dw
    out = replace_kernels(kernels, frequency=frequency, direction_v=direction_v, direction_w=direction_w)
    return out, idx
