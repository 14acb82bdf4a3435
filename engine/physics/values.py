"""Values of the physics family that travel on graph ports: homogenized stiffness.
Immutable once produced (arrays read-only); no graph import here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from engine.geometry.values import frozen_array

__all__ = ["Stiffness"]


@dataclass(frozen=True)
class Stiffness:
    """Homogenized elastic stiffness of a periodic cell (paper 6.6).

    C : (6, 6) Voigt stiffness, engineering shear strains, order
        (xx, yy, zz, yz, xz, xy); (3, 3) (xx, yy, xy) for 2D plane stress.
    E, nu, rho : base material; density : solid volume fraction of the cell;
    constants : engineering constants (E_x ... nu_avg, eqs. 1-8 of Liu et al.);
    symmetry : detected symmetry class; zener : Zener ratio (cubic only, else None);
    dropped_fraction : material removed as disconnected islands (fraction of the cell).
    resolution : voxels along the longest cell edge of the solve.
    grid_shape : (nx, ny, nz) voxels of the solve, or None (``resolution``^3).
    cell : (Lx, Ly, Lz) box the solve covered (cell units), or None (the unit cube).
    """

    C: np.ndarray
    E: float
    nu: float
    rho: float
    density: float
    constants: dict
    symmetry: str
    zener: float | None
    dropped_fraction: float
    iterations: int
    resolution: int
    grid_shape: tuple | None = None
    cell: tuple | None = None

    def __post_init__(self):
        object.__setattr__(self, "C", frozen_array(self.C))

    @property
    def S(self) -> np.ndarray:
        return np.linalg.inv(self.C)

    @property
    def effective_density(self) -> float:
        """Mass per cell volume (kg/m^3): base density times solid fraction."""
        return self.rho * self.density

    def summary(self) -> dict:
        return {"C": self.C.tolist(), "density": self.density, "effective_density": self.effective_density,
                "symmetry": self.symmetry, "zener": self.zener, "dropped_fraction": self.dropped_fraction,
                "iterations": self.iterations, "resolution": self.resolution, "E": self.E, "nu": self.nu,
                "rho": self.rho, **self.constants,
                **({} if self.grid_shape is None else {"grid_shape": list(self.grid_shape)}),
                **({} if self.cell is None else {"cell": list(self.cell)})}
