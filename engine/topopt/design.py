"""Design variables, physical densities and the result record shared by the optimisers.

Design variables ``x`` live on the design cells (``passive == 0``) only.
The physical density field ``rho`` covers every cell: filtered ``x`` on the
design cells, 1 on passive solid, 0 on passive void. Stiffness follows the
modified SIMP law ``E(rho) = young (e_min + (1 - e_min) rho^p)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .density_filter import DensityFilter

__all__ = ["DesignSpace", "TopOptResult", "design_space"]


class DesignSpace:
    """Map between design variables and the physical density of a problem.

    Attributes
    ----------
    design : bool cell array, cells with a design variable.
    filter : DensityFilter over those cells.
    volume_weights : (n_design,) float64, ``d(domain volume fraction)/dx``.
    target : float, required ``volume_weights @ x``.
    """

    def __init__(self, problem):
        self.problem = problem
        self.design = problem.passive == 0
        self.n_design = int(self.design.sum())
        self.filter = DensityFilter(self.design, problem.rmin)
        n_domain = problem.n_domain
        self.volume_weights = self.filter.backward(np.ones(self.n_design)) / n_domain
        self.solid_fraction = float((problem.passive == 1).sum()) / n_domain
        self.target = problem.volfrac - self.solid_fraction
        self.base = (problem.passive == 1).astype(np.float64)

    def initial(self):
        """Uniform design variables that meet the volume fraction exactly."""
        return np.full(self.n_design, self.target / self.volume_weights.sum())

    def density(self, x):
        """Physical density of every cell (cell-shaped float64 array)."""
        rho = self.base.copy()
        rho[self.design] = self.filter(x)
        return rho

    def volume(self, x):
        """Material volume as a fraction of the design domain."""
        return float(self.volume_weights @ x) + self.solid_fraction

    def backward(self, g_rho):
        """Gradient in ``x`` from a gradient in ``rho`` (cell-shaped or flat)."""
        g = np.asarray(g_rho).reshape(self.problem.shape)[self.design]
        return self.filter.backward(g)

    def stiffness_scale(self, rho):
        """``E(rho) / young`` and its derivative in ``rho``, flat over cells."""
        p = self.problem
        r = np.asarray(rho).reshape(-1)
        scale = p.young_min + (1.0 - p.young_min) * r ** p.penal
        dscale = p.penal * (1.0 - p.young_min) * r ** (p.penal - 1.0)
        return scale, dscale


def design_space(problem):
    """The problem's :class:`DesignSpace`, built once and kept on the problem."""
    ds = problem._cache.get("design")
    if ds is None:
        ds = problem._cache["design"] = DesignSpace(problem)
    return ds


def _frozen(a):
    a = np.array(a, dtype=np.float64)
    a.flags.writeable = False
    return a


@dataclass(frozen=True, eq=False)
class TopOptResult:
    """Outcome of an optimisation run; arrays are read-only.

    Attributes
    ----------
    problem : Problem
    rho : float64 cell array, physical density in [0, 1].
    x : (n_design,) float64, design variables.
    displacements : (n_cases,) + node-grid shape + (dim,) float64.
    compliances : (n_cases,) float64, ``f_i . u_i`` per load case.
    objective : float, the optimiser's objective at ``rho``.
    history : dict of str -> (iterations,) float64
        At least ``objective``, ``volume`` and ``change`` per iteration.
    iterations : int
    converged : bool, max design change fell below the tolerance.
    theta : float64 cell array or None
        Material orientation (radians from +x, counter-clockwise) of the
        orthotropic multi-load optimisation.
    """

    problem: object
    rho: np.ndarray
    x: np.ndarray
    displacements: np.ndarray
    compliances: np.ndarray
    objective: float
    history: dict
    iterations: int
    converged: bool
    theta: np.ndarray = None
    info: dict = field(default_factory=dict)

    def __post_init__(self):
        for name in ("rho", "x", "displacements", "compliances", "theta"):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, _frozen(value))
        object.__setattr__(self, "history", {k: _frozen(v) for k, v in self.history.items()})
