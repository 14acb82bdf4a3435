"""The synthetic reconstruction benchmark (paper 004, supplementary 12.3, Table 3).

Each `SyntheticCase` is a `ParamSpace`, its true parameters and where its
exemplars are sampled (eq. 37: a rotated cube, Gaussian noise on the
points).  The paper's equations 40-53 were lost in extraction; the cases
below are this module's reading of the prose, built from the engine's own
SDF values (`Periodic`, `Suspension`, `TrigSum`, `Shell`, `Affine`,
`Union`), in mm, with a unit cell of about 1 mm:

* ``gyroid_1d`` — Gyroid [1D]: the solid gyroid network (level 0) of cell
  size ``cell``, the one parameter (the paper's "noise scale", which
  controls the density of the pattern);
* ``gyroid_3d`` — Gyroid [3D]: a gyroid wall, ``Shell(Periodic(gyroid, cell,
  level), thickness)``: cell size, the level of the wall's mid-surface
  (F = level) and its thickness (mm).  The paper's three parameters are a
  scale, a cell size and a thickness; its scale and cell size enter only as
  their ratio (Table 3's fits that agree on the ratio disagree on both), so
  here the cell is one parameter and the third is the mid-surface level,
  which every fit can identify;
* ``gyroid_5d`` — Gyroid [5D]: the same wall with the cell split into
  ``cell_x, cell_y, cell_z`` (an anisotropic gyroid), as the paper splits
  Gyroid [3D]'s cell size into three;
* ``spheres_2d`` — Spheres [2D]: a `Suspension` of spheres, one per cubic
  cell of width ``cell`` at a hashed random position (jitter 1, seed 7;
  the seed is known to the fit, as the paper calls the renderer's PRNG),
  radius ``radius_ratio * cell``.  The cell index is floored, so the field
  is not differentiable in ``cell`` (the paper marks SHGO and BH N/A; they
  are run all the same);
* ``fibers_2d`` — Fibers [2D]: two sets of straight fibres (tubes of the
  trigonometric sum cos(2 pi x / s) + cos(2 pi z / s) < -1.5, radius about
  0.16 s) parallel to y in layers of period s along z, the second set half
  a period higher and rotated about the layer normal z by ``angle``
  (radians, in [0, pi / 2]); their union.  Parameters: ``spacing`` s (mm)
  and ``angle``.

Exemplars: a cube of edge `size` (about three cells), `resolution` nodes
per axis, a fixed oblique rotation and noise of 0.5 % of the edge; the
validation exemplar (`validation_exemplar`) is another cube elsewhere with
another rotation and noise seed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .combine import Affine, Shell, Union
from .exemplar import Exemplar
from .particles import SizeDistribution, Suspension
from .periodic import Periodic, TrigSum, TrigTerm
from .reconstruct import ParamSpace
from .values import SDF

__all__ = ["SyntheticCase", "CASES", "LABELS", "synthetic_case", "rotation_matrix"]


def rotation_matrix(axis, angle: float) -> np.ndarray:
    """The rotation by `angle` radians about `axis` ((3,), nonzero): (3, 3) float64 (Rodrigues).

    Raises
    ------
    ValueError
        If the axis is zero or not finite."""
    a = np.asarray(axis, dtype=np.float64).reshape(3)
    n = float(np.linalg.norm(a))
    if not (math.isfinite(n) and n > 0):
        raise ValueError(f"axis must be a finite nonzero (3,) vector, got {axis!r}")
    x, y, z = a / n
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * (k @ k)


@dataclass(frozen=True, eq=False)
class SyntheticCase:
    """One microstructure of the synthetic set.

    name : key in `CASES`; label : the paper's name ("Gyroid [1D]"); space : ParamSpace;
    true : (d,) the ground-truth parameters; centre : (3,) mm and size : mm, the
    training cube; resolution : nodes per axis; noise_sd : mm."""

    name: str
    label: str
    space: ParamSpace
    true: np.ndarray
    centre: tuple = (0.37, -0.21, 0.53)
    size: float = 3.0
    resolution: int = 24
    noise_sd: float = 0.015

    def sdf(self, values=None) -> SDF:
        """The SDF of `values` (default the true parameters)."""
        return self.space.sdf(self.true if values is None else values)

    def exemplar(self, *, resolution: int | None = None, seed: int = 0) -> Exemplar:
        """The training exemplar: the true SDF on the rotated, perturbed cube (eq. 37)."""
        return Exemplar.from_sdf(self.sdf(), self.centre, self.size, resolution or self.resolution,
                                 noise_sd=self.noise_sd, rotation=rotation_matrix((1, 2, 3), 0.5),
                                 seed=seed)

    def validation_exemplar(self, *, resolution: int | None = None, seed: int = 1) -> Exemplar:
        """Another cube (shifted by 5.3 mm along x, other rotation and noise) of the true SDF."""
        centre = np.add(self.centre, (5.3, 1.9, -2.4))
        return Exemplar.from_sdf(self.sdf(), centre, self.size, resolution or self.resolution,
                                 noise_sd=self.noise_sd, rotation=rotation_matrix((-2, 1, 1), 1.1),
                                 seed=seed)

    def relative_errors(self, found) -> np.ndarray:
        """|found - true| / |true| per parameter."""
        return np.abs(np.asarray(found, dtype=np.float64) - self.true) / np.abs(self.true)


def _gyroid_1d(v):
    return Periodic(kind="gyroid", cell=float(v[0]), level=0.0)


def _gyroid_wall(cell, level, thickness):
    return Shell(Periodic(kind="gyroid", cell=cell, level=float(level)), float(thickness))


def _gyroid_3d(v):
    return _gyroid_wall(float(v[0]), v[1], v[2])


def _gyroid_5d(v):
    return _gyroid_wall((float(v[0]), float(v[1]), float(v[2])), v[3], v[4])


def _spheres_2d(v):
    cell, ratio = float(v[0]), float(v[1])
    return Suspension(cell=cell, shape="sphere", size=SizeDistribution("fixed", ratio * cell),
                      jitter=1.0, seed=7)


def _fibre_set(spacing: float, z_phase: float) -> TrigSum:
    x = TrigTerm(1.0, (1.0, 0.0, 0.0), (0.0, 0.0, 0.0), ("cos", "cos", "cos"))
    z = TrigTerm(1.0, (0.0, 0.0, 1.0), (0.0, 0.0, z_phase), ("cos", "cos", "cos"))
    return TrigSum((x, z), width=spacing, level=-1.5)


def _fibers_2d(v):
    spacing, angle = float(v[0]), float(v[1])
    second = Affine(_fibre_set(spacing, math.pi), rotation_matrix((0, 0, 1), angle), np.zeros(3))
    return Union((_fibre_set(spacing, 0.0), second))


def _case(name, label, names, lo, hi, make, true, **kw) -> SyntheticCase:
    return SyntheticCase(name, label, ParamSpace(tuple(names), lo, hi, make),
                         np.array(true, dtype=np.float64), **kw)


CASES = {
    "gyroid_1d": lambda: _case("gyroid_1d", "Gyroid [1D]", ["cell"], [0.5], [2.0], _gyroid_1d, [1.0]),
    "gyroid_3d": lambda: _case("gyroid_3d", "Gyroid [3D]", ["cell", "level", "thickness"],
                               [0.5, -0.8, 0.02], [2.0, 0.8, 0.2], _gyroid_3d, [1.0, 0.3, 0.08]),
    "gyroid_5d": lambda: _case("gyroid_5d", "Gyroid [5D]",
                               ["cell_x", "cell_y", "cell_z", "level", "thickness"],
                               [0.5, 0.5, 0.5, -0.8, 0.02], [2.0, 2.0, 2.0, 0.8, 0.2], _gyroid_5d,
                               [0.8, 1.0, 1.2, 0.3, 0.08]),
    "spheres_2d": lambda: _case("spheres_2d", "Spheres [2D]", ["cell", "radius_ratio"],
                                [0.5, 0.1], [2.0, 0.45], _spheres_2d, [1.0, 0.3]),
    "fibers_2d": lambda: _case("fibers_2d", "Fibers [2D]", ["spacing", "angle"],
                               [0.5, 0.0], [2.0, 0.5 * math.pi], _fibers_2d, [1.0, 0.6]),
}
LABELS = {k: v().label for k, v in CASES.items()}


def synthetic_case(name: str) -> SyntheticCase:
    """The case `name` (a key of `CASES`).

    Raises
    ------
    ValueError
        For an unknown name."""
    if name not in CASES:
        raise ValueError(f"synthetic case must be one of {sorted(CASES)}, got {name!r}")
    return CASES[name]()
