"""Values of the surface solvers that travel on graph ports: how a Surface node
solved its patch.  No graph import here.
"""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["SurfaceReport"]


@dataclass(frozen=True)
class SurfaceReport:
    """How a Surface node solved its patch (port type "SurfaceReport").

    solver : "direct" (thin shell), "mixed_minimal" or "conjugate".
    iterations : solver steps (L-BFGS iterations, flow steps, Nelder-Mead
        iterations of the edge-length search).
    energy : final value of the solver's energy: the shell energy
        (in-plane + alpha * bending, dimensionless), the area (cell units^2)
        or the conjugate contour energy (dimensionless).
    area : patch area (cell units^2); max_abs_H, mean_abs_H : mean curvature
        over interior vertices (1 / cell units), the mean area-weighted.
    seconds : wall time of the solve (thickness profile included).
    converged : the solver met its tolerance within max_iter.
    warning : why the result may be unreliable ("" when converged).
    details : further JSON-able facts (FBV, sliding planes, vertex count...).
    """

    solver: str
    iterations: int
    energy: float
    area: float
    max_abs_H: float
    mean_abs_H: float
    seconds: float
    converged: bool = True
    warning: str = ""
    details: dict = field(default_factory=dict, compare=False)

    def summary(self) -> dict:
        return {"solver": self.solver, "iterations": self.iterations, "energy": self.energy,
                "area": self.area, "max_abs_H": self.max_abs_H, "mean_abs_H": self.mean_abs_H,
                "seconds": self.seconds, "converged": self.converged, "warning": self.warning,
                "details": dict(self.details)}
