"""volume_fraction on closed forms; level_for_fraction checked by Monte Carlo on other samples."""

from dataclasses import dataclass

import numpy as np
import pytest

from engine.implicit.periodic import KINDS, Periodic
from engine.implicit.values import SDF, as_points
from engine.implicit.volume_fraction import level_for_fraction, volume_fraction


@dataclass(frozen=True, eq=False)
class HalfSpace(SDF):
    """x < x0."""

    x0: float

    def field(self, points):
        return as_points(points)[:, 0] - self.x0


@dataclass(frozen=True, eq=False)
class Ball(SDF):
    radius: float

    def field(self, points):
        return np.linalg.norm(as_points(points), axis=1) - self.radius


def test_fraction_of_a_half_space_counts_cell_centres():
    box = ((0.0, -1.0, 2.0), (1.0, 1.0, 3.0))
    assert volume_fraction(HalfSpace(0.3), box, 10) == pytest.approx(0.3, abs=1e-12)
    assert volume_fraction(HalfSpace(0.36), box, (10, 3, 2)) == pytest.approx(0.4, abs=1e-12)
    assert volume_fraction(HalfSpace(-1.0), box, 4) == 0.0
    assert volume_fraction(HalfSpace(5.0), box, 4) == 1.0


def test_fraction_of_a_ball():
    f = volume_fraction(Ball(1.0), ((-1, -1, -1), (1, 1, 1)), 80)
    assert f == pytest.approx(np.pi / 6, abs=2e-3)


@pytest.mark.parametrize("kind", ["gyroid", "schwarz_p", "schwarz_d", "neovius"])
def test_level_zero_is_half_by_symmetry(kind):
    """F(-x) = -F(x) (gyroid, diamond) or F(x + cell/2) = -F(x) (P, neovius): F < 0 is half."""
    cell = (1.3, 0.9, 2.0)
    box = ((0.2, 0.1, -0.4), (1.5, 1.0, 1.6))
    assert volume_fraction(Periodic(kind, cell=cell), box, 48) == pytest.approx(0.5, abs=5e-3)
    assert abs(level_for_fraction(kind, 0.5)) < 1e-3


def _monte_carlo(sdf, cell, n=120_000, seed=0):
    p = np.random.default_rng(seed).uniform(0.0, 1.0, (n, 3)) * cell + [0.37, -1.1, 2.3]
    return float(np.mean(sdf.field(p) < 0))


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("variant, fractions", [("solid", (0.15, 0.62)), ("sheet", (0.1, 0.4))])
def test_calibrated_level_fills_the_fraction(kind, variant, fractions):
    cell = np.array([1.5, 2.0, 0.8])      # fraction does not depend on the cell's shape
    for i, target in enumerate(fractions):
        t = level_for_fraction(kind, target, variant, resolution=48)
        sdf = Periodic(kind, cell=cell, level=t, variant=variant)
        assert _monte_carlo(sdf, cell, seed=i) == pytest.approx(target, abs=0.01)


def test_calibration_independent_of_a_rotated_lattice():
    t = level_for_fraction("iwp", 0.3)
    theta = 0.4
    rot = np.array([[np.cos(theta), -np.sin(theta), 0], [np.sin(theta), np.cos(theta), 0],
                    [0, 0, 1]])
    sdf = Periodic("iwp", cell=0.5, level=t, matrix=rot)
    fraction = volume_fraction(sdf, ((0, 0, 0), (4, 4, 1)), (100, 100, 25))
    assert fraction == pytest.approx(0.3, abs=0.01)


@pytest.mark.parametrize("kind, max_abs", [("gyroid", 1.5), ("lidinoid", 1.35), ("frd", 7.0)])
def test_sheet_fraction_is_monotone_in_the_level(kind, max_abs):
    box = ((0, 0, 0), (1, 1, 1))
    fr = [volume_fraction(Periodic(kind, level=t, variant="sheet"), box, 24)
          for t in np.linspace(0.0, 1.01 * max_abs, 17)]
    assert fr[0] == 0.0 and fr[-1] == 1.0
    assert np.all(np.diff(fr) >= 0)
    assert len(set(fr)) > 5
    # and the calibration inverts it
    levels = [level_for_fraction(kind, f, "sheet", resolution=32) for f in (0.1, 0.3, 0.5, 0.9)]
    assert np.all(np.diff(levels) > 0)


@pytest.mark.parametrize("args, kwargs, match", [
    (("gyroid", 0.0), {}, "fraction"),
    (("gyroid", 1.0), {}, "fraction"),
    (("gyroid", -0.2, "sheet"), {}, r"\(0, 1\)"),
    (("gyroid", float("nan")), {}, "fraction"),
    (("cube", 0.3), {}, "kind"),
    (("gyroid", 0.3, "foam"), {}, "variant"),
    (("gyroid", 0.3), {"resolution": 4}, "resolution"),
    (("gyroid", 0.3), {"resolution": 20.5}, "resolution"),
])
def test_bad_calibration_refused(args, kwargs, match):
    with pytest.raises(ValueError, match=match):
        level_for_fraction(*args, **kwargs)


@pytest.mark.parametrize("args, match", [
    ((Ball(1.0), ((0, 0, 0), (1, 1, 1)), 0), "resolution"),
    ((Ball(1.0), ((0, 0, 0), (1, 1, 1)), 2.5), "resolution"),
    ((Ball(1.0), ((0, 0, 0), (1, 0, 1)), 4), "box"),
    ((Ball(1.0), ((0, 0, 0), (1, np.nan, 1)), 4), "box"),
    (("ball", ((0, 0, 0), (1, 1, 1)), 4), "sdf"),
])
def test_bad_volume_fraction_refused(args, match):
    with pytest.raises(ValueError, match=match):
        volume_fraction(*args)
