"""Phasor-noise kernels: the data every evaluator (numpy reference, numba,
GLSL shader) shares, and the exact formulas they all implement.

Two sawtooth phasor noises are built from one set of kernel sites
(Tricard et al. 2021, eqs. 2-3 and 14-16):

* sites ``x_j`` on a virtual grid of cubic cells of edge ``R`` (the kernel
  radius), ``per_cell`` sites per cell at uniform random positions;
* per site and per noise ``k`` in {v, w}: frequency ``f_j`` (cycles/mm,
  sampled from F at x_j), unit direction ``d_kj`` and phase ``phi_kj``
  (radians).  ``d_vj`` is v = z x D(x_j) rotated about w(x_j) by an angle
  uniform in [-Gamma(x_j), Gamma(x_j)]; ``d_wj`` is w = (z x D) x D.
  Both normalised; where D is vertical (|z x D| < 1e-6) v is
  normalise(x - (x . D) D) instead, and always w = v x D
  (:func:`engine.phasor.sampling.local_frame`; e_k below uses it too).

Unfiltered complex noise at a point x (mm), truncated at |x - x_j| < R:

    G_k(x) = sum_j exp(-b |r|^2) exp(i (2 pi f_j d_kj . r + phi_kj)),  r = x - x_j

with the Gaussian coefficient ``b = pi / R^2`` (mm^-2), so a kernel has
fallen to exp(-pi) at its radius.  The paper's "b = c / F_min, c = 4.5" is
read as fixing the radius to c periods of the lowest frequency:
``R = c / F_min``.

Filtered noise (eq. 14 with eqs. 15-16): with a filter exp(-a |delta|^2)
(``a = b / s^2`` for a filter radius s times the kernel radius, default
s = 2), the local frequency vector ``q(x) = F(x) e_k(x)`` (e_k = v or w at x,
unperturbed) and ``Delta_j = A(x) (f_j d_kj - q(x))``:

    K_j(x) = exp(-(a b / (a + b)) |r|^2 - pi^2 |Delta_j|^2 / (a + b))
             * exp(i (2 pi (f_j d_kj - (b / (a + b)) Delta_j) . r + phi_kj))

truncated at |r| < s' R with s' = sqrt((a + b) / (a b)) * sqrt(b) (where the
filtered Gaussian falls to exp(-pi)).  This is the Gaussian convolution of
the local phasor field worked out in closed form (the constant factor
(pi / (a + b))^(3/2) is the same for every kernel and dropped: only Arg
matters).  A(x) in [0, 1] attenuates the filter where the local angular
spread is large (section 4.2.4); it is a grid on the fields' cells sampled
trilinearly like F (:mod:`engine.phasor.attenuation`), A = 1 when none is given.

The sawtooth value is ``p_k(x) = (Arg G_k(x) / 2 pi) mod 1`` and a point is
in a black diamond cell when ``|1/2 - p_v| + |1/2 - p_w| < 1/2``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

C_BANDWIDTH = 4.5  # kernel radius in periods of the lowest frequency (paper 3.2.2)
KERNELS_PER_CELL = 8


def _frozen(a, dtype) -> np.ndarray:
    out = np.ascontiguousarray(np.array(a, dtype=dtype, copy=True))
    out.setflags(write=False)
    return out


@dataclass(frozen=True, eq=False)
class PhasorKernels:
    """Kernel sites and oscillators of the two noises p_v and p_w.

    Attributes
    ----------
    origin : (3,) float64, mm, corner of cell (0, 0, 0)
    radius : float, mm, kernel radius R = cell edge
    grid : (3,) int64, cells along (x, y, z)
    cell_start : (n_cells + 1,) int64; the sites of cell c (flat index
        ``ix + nx * (iy + ny * iz)``) are rows ``cell_start[c]:cell_start[c+1]``
    positions : (n, 3) float64, mm
    frequency : (n,) float64, cycles per mm
    direction_v, direction_w : (n, 3) float64, unit vectors
    phase_v, phase_w : (n,) float64, radians
    spread_u : (n,) float64 in [-1, 1]; the Gamma perturbation angle of site j
        is ``spread_u[j] * Gamma(x_j)`` (kept so a resample after painting
        reuses the same random draw)
    seed : int
    """

    origin: np.ndarray
    radius: float
    grid: np.ndarray
    cell_start: np.ndarray
    positions: np.ndarray
    frequency: np.ndarray
    direction_v: np.ndarray
    direction_w: np.ndarray
    phase_v: np.ndarray
    phase_w: np.ndarray
    spread_u: np.ndarray
    seed: int = 0
    info: dict = field(default_factory=dict)

    def __post_init__(self):
        for name, dtype in (("origin", np.float64), ("grid", np.int64), ("cell_start", np.int64),
                            ("positions", np.float64), ("frequency", np.float64),
                            ("direction_v", np.float64), ("direction_w", np.float64),
                            ("phase_v", np.float64), ("phase_w", np.float64),
                            ("spread_u", np.float64)):
            object.__setattr__(self, name, _frozen(getattr(self, name), dtype))
        n = len(self.positions)
        if self.grid.shape != (3,) or self.cell_start.shape != (int(np.prod(self.grid)) + 1,):
            raise ValueError(f"PhasorKernels: cell_start has shape {self.cell_start.shape} for a "
                             f"grid of {self.grid.tolist()} cells")
        if self.cell_start[0] != 0 or self.cell_start[-1] != n or np.any(np.diff(self.cell_start) < 0):
            raise ValueError("PhasorKernels: cell_start must rise from 0 to the number of sites")
        for name in ("frequency", "phase_v", "phase_w", "spread_u"):
            if getattr(self, name).shape != (n,):
                raise ValueError(f"PhasorKernels: {name} has shape {getattr(self, name).shape}, want ({n},)")
        for name in ("positions", "direction_v", "direction_w"):
            if getattr(self, name).shape != (n, 3):
                raise ValueError(f"PhasorKernels: {name} has shape {getattr(self, name).shape}, want ({n}, 3)")

    @property
    def n(self) -> int:
        return int(len(self.positions))

    @property
    def bandwidth(self) -> float:
        """Gaussian coefficient b = pi / R^2, mm^-2."""
        return float(np.pi / self.radius ** 2)

    def cell_of(self, points) -> np.ndarray:
        """(n, 3) int64 cell coordinates (x, y, z) of ``points`` (may lie outside the grid)."""
        return np.floor((np.asarray(points, np.float64).reshape(-1, 3) - self.origin) / self.radius
                        ).astype(np.int64)

    def with_phases(self, phase_v, phase_w) -> "PhasorKernels":
        """A copy with new phases (alignment result)."""
        return _replace(self, phase_v=phase_v, phase_w=phase_w)


def _replace(k: PhasorKernels, **changes) -> PhasorKernels:
    values = {name: getattr(k, name) for name in PhasorKernels.__dataclass_fields__}
    values.update(changes)
    return PhasorKernels(**values)


def replace_kernels(k: PhasorKernels, **changes) -> PhasorKernels:
    """A copy of ``k`` with some fields replaced (validated again)."""
    return _replace(k, **changes)
