"""Values of the topology-optimisation family that travel on graph ports: a design.
Immutable once produced (arrays read-only); no graph import here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from engine.geometry.values import frozen_array, read_only_array

__all__ = ["DesignValue"]


@dataclass(frozen=True, eq=False)
class DesignValue:
    """A topology-optimised design (port type "Design").

    rho : grid_shape float64, read-only, element densities in [0, 1].
    sigma : (n_cases,) + grid_shape + (d, d) float64, read-only, element
        stress tensors per load case (components (x, y[, z])).
    sigma_combined : grid_shape + (d, d) float64, read-only, the tensor that
        orients the growth (the single case's stress, or the load cases
        combined / the optimised orientation for several cases).
    rotation : grid_shape + (d, d) float64, read-only, columns = principal
        directions sorted by |sigma_i| descending.
    principal : grid_shape + (d,) float64, read-only, the principal values
        of ``sigma_combined`` along the columns of ``rotation``.
    problem : the engine's topology-optimisation problem (JSON-able).
    result : the optimiser's own result object (history, compliance, timing).
    lo, hi : (d,) float64, the design box in element units, (x, y[, z]).
    seconds : float, wall time of the optimisation.
    """

    rho: np.ndarray
    sigma: np.ndarray
    sigma_combined: np.ndarray
    rotation: np.ndarray
    principal: np.ndarray
    problem: object
    result: object = None
    lo: np.ndarray | None = None
    hi: np.ndarray | None = None
    seconds: float = 0.0

    def __post_init__(self):
        for name in ("rho", "sigma", "sigma_combined", "rotation", "principal"):
            object.__setattr__(self, name, read_only_array(getattr(self, name), np.float64))
        d = self.rho.ndim
        lo = np.zeros(d) if self.lo is None else self.lo
        hi = np.array(self.rho.shape[::-1], float) if self.hi is None else self.hi
        object.__setattr__(self, "lo", frozen_array(lo).reshape(d))
        object.__setattr__(self, "hi", frozen_array(hi).reshape(d))

    @property
    def ndim(self) -> int:
        return int(self.rho.ndim)

    @property
    def grid_shape(self) -> tuple:
        return tuple(self.rho.shape)
