"""Density-based topology optimisation on regular 2D / 3D grids (no Qt).

Produces the inputs of the reaction-diffusion growth (Garnier, Schmidt &
Rohmer 2022, Sec. 3.2 and 6.2-6.5): a density field ``rho``, per-cell
stress tensors ``sigma`` and, for several load cases, an optimised material
orientation (eq. 19).

Layout: cell arrays ``[y, x]`` / ``[z, y, x]`` (row = y, y up), tensor
components last in ``(x, y[, z])`` order; see :mod:`.problem`.

>>> from engine.topopt import preset, optimise, element_stress
>>> problem = preset("cantilever_2d", res=30)
>>> result = optimise(problem)
>>> sigma = element_stress(problem, result.rho, result.displacements)[0]   # (30, 60, 2, 2)
"""

from .design import TopOptResult
from .orientation import orientation_tensor, orthotropic_orientation, stress_orientation
from .presets import PRESETS, preset
from .problem import Problem, nearest_node, nodes_in_box
from .simp import simp_compliance
from .stress import element_stress, von_mises
from .stress_aware import stress_aware_simp

__all__ = [
    "Problem", "TopOptResult", "PRESETS", "preset", "nodes_in_box", "nearest_node",
    "optimise", "simp_compliance", "stress_aware_simp", "orthotropic_orientation",
    "element_stress", "von_mises", "stress_orientation", "orientation_tensor",
]

_RUNNERS = {
    "compliance": simp_compliance,
    "stress": stress_aware_simp,
    "orientation": orthotropic_orientation,
}


def optimise(problem, *, progress=None, **options):
    """Run the optimiser named by ``problem.objective``.

    Parameters
    ----------
    problem : Problem
    progress : callable(done, total) -> bool, optional; ``False`` cancels
        (raises :class:`engine.progress.Cancelled`).
    **options : keyword options of :func:`simp_compliance`,
        :func:`stress_aware_simp` or :func:`orthotropic_orientation`.

    Returns
    -------
    TopOptResult
    """
    return _RUNNERS[problem.objective](problem, progress=progress, **options)
