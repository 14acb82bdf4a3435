"""Values of the reaction-diffusion family that travel on graph ports (Garnier,
Schmidt & Rohmer 2022): the growth's input fields, the grown structures and
compiled contours.  Grids are indexed [y, x] / [z, y, x]; tensor and rotation
components are ordered (x, y[, z]).  Immutable once produced (arrays
read-only); no graph import here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from engine.geometry.values import frozen_array, read_only_array

__all__ = ["RDFieldsValue", "RDStructuresValue", "ContourValue"]


@dataclass(frozen=True, eq=False)
class RDFieldsValue:
    """Inputs of reaction-diffusion growth (port type "RDFields").

    rho : grid_shape float64, read-only, infill-space density in [0, 1].
    rotation : grid_shape + (d, d) float64, read-only, principal directions
        as columns (x, y[, z]), sorted by |sigma_i| descending.
    gamma : grid_shape float64, read-only, infill map Gamma in [0, 1]
        (1 = fill with solid material).
    lo, hi : (d,) float64, the box the grid covers, (x, y[, z]).
    sigma : grid_shape + (d, d) float64 or None, the tensor the rotation came
        from (for display).
    gamma_sigma : grid_shape float64 or None, the coherence part of Gamma.
    magnitude : grid_shape + (d,) float64 or None, |principal value| along
        each column of ``rotation`` (None when only directions were given).
    source : RDFieldsValue or None, the fields these were upsampled from
        (None: these are the fields as made).
    """

    rho: np.ndarray
    rotation: np.ndarray
    gamma: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    sigma: np.ndarray | None = None
    gamma_sigma: np.ndarray | None = None
    magnitude: np.ndarray | None = None
    source: "RDFieldsValue | None" = None

    def __post_init__(self):
        for name in ("rho", "rotation", "gamma", "sigma", "gamma_sigma", "magnitude"):
            a = getattr(self, name)
            if a is not None:
                object.__setattr__(self, name, read_only_array(a, np.float64))
        object.__setattr__(self, "lo", frozen_array(self.lo).reshape(-1))
        object.__setattr__(self, "hi", frozen_array(self.hi).reshape(-1))
        d = self.rho.ndim
        if self.rotation.shape != self.rho.shape + (d, d) or self.gamma.shape != self.rho.shape \
                or self.lo.size != d or self.hi.size != d:
            raise ValueError(f"RDFieldsValue: rho {self.rho.shape}, rotation {self.rotation.shape}, "
                             f"gamma {self.gamma.shape} and a {self.lo.size}D box do not fit together")

    @property
    def ndim(self) -> int:
        return int(self.rho.ndim)

    @property
    def grid_shape(self) -> tuple:
        return tuple(self.rho.shape)

    def source_of(self) -> "RDFieldsValue":
        """The fields as made (before any upsampling)."""
        return self if self.source is None else self.source

    def same_as(self, other: "RDFieldsValue") -> bool:
        """Whether ``other`` holds the same rho, rotation and Gamma on the same box."""
        if other is self:
            return True
        return (other is not None and self.grid_shape == other.grid_shape
                and all(np.array_equal(getattr(self, n), getattr(other, n))
                        for n in ("rho", "rotation", "gamma", "lo", "hi")))


@dataclass(frozen=True, eq=False)
class RDStructuresValue:
    """Per-direction structures grown by anisotropic Gray-Scott (port type "RDStructures").

    s : (n,) + grid_shape float32, read-only, s_i = 1 - u_i for each grown
        direction (in ``directions`` order).
    directions : tuple of int, the principal direction of each structure.
    fields : RDFieldsValue on the growth grid (rho, rotation, Gamma upsampled;
        ``fields.source_of()`` is the node's input).
    iso : float, the infill space is ``fields.rho >= iso``.
    steps : tuple of int, steps of each direction's state (regrowth included).
    stop_reasons : tuple of str, why each direction's last run stopped
        ("converged", "max_steps", "cancelled").
    stop_steps : tuple of int, where each direction's last run stopped: steps
        from the seeds (a growth) or from the brush (a regrowth).
    g_history : tuple of (m, 2) float64 arrays, (step, G^t) of eq. 14 of each
        direction's last run (steps counted as in ``stop_steps``).
    seconds : tuple of float, wall time of each direction's last run.
    cell_updates_per_second : float, cells x steps / seconds over the last
        runs: the whole grid for a growth (the kernel skips cells the pattern
        has not reached, so this is an effective rate), the regrown windows
        for a regrowth.
    states : tuple, per direction the resumable kernel state
        (``engine.rd.growth.RDState``), or None.
    edits : tuple of dict, the brush edits applied so far.
    regrown : bool, the last evaluation regrew locally after edits.
    changed : tuple of (start, stop) per grid axis or None, the box the last
        evaluation could change (None: everything).
    """

    s: np.ndarray
    directions: tuple
    fields: RDFieldsValue
    iso: float = 0.5
    steps: tuple = ()
    stop_reasons: tuple = ()
    stop_steps: tuple = ()
    g_history: tuple = ()
    seconds: tuple = ()
    cell_updates_per_second: float = 0.0
    states: tuple | None = None
    edits: tuple = ()
    regrown: bool = False
    changed: tuple | None = None

    def __post_init__(self):
        object.__setattr__(self, "s", read_only_array(self.s, np.float32))
        object.__setattr__(self, "g_history", tuple(read_only_array(g, np.float64).reshape(-1, 2)
                                                    for g in self.g_history))
        if self.s.shape[1:] != self.fields.grid_shape or self.s.shape[0] != len(self.directions):
            raise ValueError(f"RDStructuresValue: s {self.s.shape} does not fit {len(self.directions)} "
                             f"directions on grid {self.fields.grid_shape}")

    @property
    def ndim(self) -> int:
        return self.fields.ndim

    def summary(self) -> dict:
        """JSON-able facts of the growth, per direction."""
        return {"grid": list(self.fields.grid_shape[::-1]), "directions": list(self.directions),
                "steps": list(self.steps), "stop_reasons": list(self.stop_reasons),
                "stop_steps": list(self.stop_steps), "seconds": list(self.seconds),
                "final_g": [float(g[-1, 1]) if len(g) else None for g in self.g_history],
                "cell_updates_per_second": self.cell_updates_per_second,
                "regrown": self.regrown, "edits": len(self.edits)}


@dataclass(frozen=True)
class ContourValue:
    """2D iso-contours of a compiled lattice (port type "Contour").

    polylines : tuple of (m, 2) float64 arrays, read-only, points (x, y) in
        the box's units; a closed loop repeats its first point.
    lo, hi : (2,) float64, the box.
    iso : float, the level contoured.
    """

    polylines: tuple
    lo: np.ndarray
    hi: np.ndarray
    iso: float = 0.5

    def __post_init__(self):
        object.__setattr__(self, "polylines", tuple(frozen_array(p).reshape(-1, 2) for p in self.polylines))
        object.__setattr__(self, "lo", frozen_array(self.lo).reshape(2))
        object.__setattr__(self, "hi", frozen_array(self.hi).reshape(2))
