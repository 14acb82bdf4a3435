"""The designer's control fields for phasor infill (Tricard et al., section 3).

Three fields over the part's box drive the microstructure: the transverse
direction D (unit vectors), the frequency F (cells per mm) and the angular
spread Gamma (radians, 0..pi/2).  They live on a low-resolution regular grid
(the paper uses 64^3) and are sampled trilinearly.

Grid convention (the same as :class:`engine.geometry.values.Field`): arrays are
indexed ``[z, y, x]`` with one sample per cell at the cell centre; the box
corners ``lo, hi`` are in ``(x, y, z)`` order, in mm.  Points outside the
box take the value at the nearest point inside (clamped), so kernels a
little outside the part still get sensible parameters.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

MAX_SPREAD = math.pi / 2
_MIN_NORM = 1e-9


def _frozen(a, dtype=np.float64) -> np.ndarray:
    out = np.array(a, dtype=dtype, copy=True)
    out.setflags(write=False)
    return out


def _where(index, lo, hi, shape) -> str:
    """'cell [z, y, x] at (x, y, z) mm' for error messages."""
    k, j, i = (int(v) for v in index[:3])
    step = (np.asarray(hi) - np.asarray(lo)) / np.asarray(shape[:3][::-1])
    pos = np.asarray(lo) + (np.array([i, j, k]) + 0.5) * step
    return f"cell [z={k}, y={j}, x={i}] at ({pos[0]:.3g}, {pos[1]:.3g}, {pos[2]:.3g}) mm"


@dataclass(frozen=True, eq=False)
class PhasorFields:
    """D, F and Gamma on one grid over the box ``lo..hi`` (mm).

    direction : (nz, ny, nx, 3) float64, unit vectors (x, y, z components)
    frequency : (nz, ny, nx) float64, cells per mm, > 0
    spread : (nz, ny, nx) float64, radians in [0, pi/2]
    lo, hi : (3,) float64, box corners in mm, hi > lo
    """

    direction: np.ndarray
    frequency: np.ndarray
    spread: np.ndarray
    lo: np.ndarray
    hi: np.ndarray

    def __post_init__(self):
        for name in ("direction", "frequency", "spread", "lo", "hi"):
            object.__setattr__(self, name, _frozen(getattr(self, name)))
        validate_fields(self.direction, self.frequency, self.spread, self.lo, self.hi)

    @property
    def shape(self) -> tuple:
        """Grid shape ``(nz, ny, nx)``."""
        return tuple(self.frequency.shape)

    @property
    def spacing(self) -> np.ndarray:
        """(3,) cell size in mm along x, y, z."""
        return (self.hi - self.lo) / np.array(self.shape[::-1], dtype=np.float64)

    def centres(self) -> tuple:
        """Cell-centre coordinates ``(xs, ys, zs)`` in mm, each 1-D."""
        return tuple(self.lo[a] + (np.arange(n) + 0.5) * self.spacing[a]
                     for a, n in enumerate(self.shape[::-1]))

    def sample_frequency(self, points) -> np.ndarray:
        """(n,) cells per mm at ``points`` (n, 3) mm."""
        return trilinear(self.frequency, self.lo, self.hi, points)

    def sample_spread(self, points) -> np.ndarray:
        """(n,) radians at ``points`` (n, 3) mm."""
        return trilinear(self.spread, self.lo, self.hi, points)

    def sample_direction(self, points) -> np.ndarray:
        """(n, 3) unit vectors at ``points`` (n, 3) mm.

        The trilinear blend is renormalised; where opposing neighbours cancel
        it (a blend shorter than 1e-9) the nearest cell's direction is used.
        """
        pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        d = trilinear(self.direction, self.lo, self.hi, pts)
        norm = np.linalg.norm(d, axis=1)
        bad = norm < _MIN_NORM
        if bad.any():
            d[bad] = self.direction[nearest_cell(self.shape, self.lo, self.hi, pts[bad])]
            norm[bad] = 1.0
        return d / norm[:, None]

    def min_frequency(self) -> float:
        return float(self.frequency.min())

    def max_frequency(self) -> float:
        return float(self.frequency.max())


def validate_fields(direction, frequency, spread, lo, hi) -> None:
    """Refuse malformed fields; the message names the field and the first bad cell."""
    lo = np.asarray(lo, dtype=np.float64)
    hi = np.asarray(hi, dtype=np.float64)
    if lo.shape != (3,) or hi.shape != (3,) or not np.all(np.isfinite(lo)) or not np.all(np.isfinite(hi)):
        raise ValueError(f"box: lo and hi must be 3 finite numbers (x, y, z) in mm; got {lo!r}, {hi!r}")
    if np.any(hi <= lo):
        raise ValueError(f"box: hi {hi.tolist()} must exceed lo {lo.tolist()} on every axis")
    f = np.asarray(frequency)
    if f.ndim != 3 or min(f.shape) < 1:
        raise ValueError(f"frequency F: expected a (nz, ny, nx) grid, got shape {f.shape}")
    if np.asarray(direction).shape != f.shape + (3,):
        raise ValueError(f"direction D: expected shape {f.shape + (3,)}, got {np.asarray(direction).shape}")
    if np.asarray(spread).shape != f.shape:
        raise ValueError(f"angular spread Gamma: expected shape {f.shape}, got {np.asarray(spread).shape}")
    bad = ~np.isfinite(f) | (f <= 0)
    if bad.any():
        idx = np.argwhere(bad)[0]
        raise ValueError(f"frequency F must be a finite number > 0 cells/mm; {_where(idx, lo, hi, f.shape)} "
                         f"has {f[tuple(idx)]!r}")
    g = np.asarray(spread)
    bad = ~np.isfinite(g) | (g < 0) | (g > MAX_SPREAD + 1e-12)
    if bad.any():
        idx = np.argwhere(bad)[0]
        raise ValueError(f"angular spread Gamma must lie in [0, pi/2] radians; {_where(idx, lo, hi, f.shape)} "
                         f"has {g[tuple(idx)]!r}")
    d = np.asarray(direction)
    norm = np.linalg.norm(d, axis=-1)
    bad = ~np.all(np.isfinite(d), axis=-1) | (np.abs(norm - 1.0) > 1e-6)
    if bad.any():
        idx = np.argwhere(bad)[0]
        raise ValueError(f"direction D must be a unit vector; {_where(idx, lo, hi, f.shape)} has "
                         f"{d[tuple(idx)].tolist()} (zero, NaN or not normalised)")


def normalise_directions(d) -> np.ndarray:
    """Unit vectors from ``d`` (..., 3); raises ValueError naming the first zero or NaN entry."""
    d = np.asarray(d, dtype=np.float64)
    norm = np.linalg.norm(d, axis=-1)
    bad = ~np.isfinite(norm) | (norm < _MIN_NORM)
    if bad.any():
        idx = tuple(int(v) for v in np.argwhere(bad)[0])
        raise ValueError(f"direction D at index {list(idx)} is {d[idx].tolist()}: zero or NaN, "
                         "so it has no direction")
    return d / norm[..., None]


def _cell_coords(shape, lo, hi, points) -> np.ndarray:
    """(n, 3) continuous cell-centre coordinates (x, y, z) clamped to the grid."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    n_xyz = np.array(shape[:3][::-1], dtype=np.float64)
    u = (pts - lo) / (np.asarray(hi) - lo) * n_xyz - 0.5
    return np.clip(u, 0.0, n_xyz - 1.0)


def nearest_cell(shape, lo, hi, points) -> tuple:
    """Index tuple ``(k, j, i)`` of the cells nearest to ``points`` (n, 3)."""
    u = np.rint(_cell_coords(shape, lo, hi, points)).astype(np.intp)
    return u[:, 2], u[:, 1], u[:, 0]


def trilinear(grid, lo, hi, points) -> np.ndarray:
    """Trilinear interpolation of a cell-centred grid.

    Parameters
    ----------
    grid : (nz, ny, nx, ...) array
    lo, hi : (3,) box corners (x, y, z)
    points : (n, 3) positions (x, y, z), clamped into the grid's centre hull

    Returns
    -------
    (n, ...) float64
    """
    g = np.asarray(grid, dtype=np.float64)
    u = _cell_coords(g.shape, np.asarray(lo, np.float64), np.asarray(hi, np.float64), points)
    i0 = np.minimum(np.floor(u).astype(np.intp), np.array(g.shape[:3][::-1]) - 1)
    t = u - i0
    i1 = np.minimum(i0 + 1, np.array(g.shape[:3][::-1]) - 1)
    out = 0.0
    for cz in (0, 1):
        kz, wz = (i1[:, 2], t[:, 2]) if cz else (i0[:, 2], 1.0 - t[:, 2])
        for cy in (0, 1):
            ky, wy = (i1[:, 1], t[:, 1]) if cy else (i0[:, 1], 1.0 - t[:, 1])
            for cx in (0, 1):
                kx, wx = (i1[:, 0], t[:, 0]) if cx else (i0[:, 0], 1.0 - t[:, 0])
                w = wz * wy * wx
                out = out + g[kz, ky, kx] * w.reshape((-1,) + (1,) * (g.ndim - 3))
    return np.asarray(out, dtype=np.float64)


def constant_fields(lo, hi, shape, *, direction=(1.0, 0.0, 0.0), frequency=1.0,
                    spread=0.0) -> PhasorFields:
    """Fields with one value everywhere on a ``shape`` = (nz, ny, nx) grid."""
    shape = tuple(int(s) for s in shape)
    d = normalise_directions(np.asarray(direction, dtype=np.float64))
    return PhasorFields(np.broadcast_to(d, shape + (3,)), np.full(shape, float(frequency)),
                        np.full(shape, float(spread)), lo, hi)
