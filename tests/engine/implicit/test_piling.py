"""Granular piles against a grain-by-grain brute force, sampled distances, the gradient bound and the GLSL."""

import math

import numpy as np
import pytest
from numpy.polynomial import polynomial as npoly
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from engine.implicit.piling import Pile


def _points(n, lo=-2.0, hi=2.0, seed=0):
    return np.random.default_rng(seed).uniform(lo, hi, (n, 3))


def ref_deform(pile, x):
    """x + P(clamp(s)) N(x), with P from its raw coefficients."""
    s = np.clip(x[:, pile.deform_axis], *pile.deform_span)
    amp = npoly.polyval(s, pile.deform_poly) if pile.deform_poly else np.zeros(len(x))
    a = pile.noise_frequency * x + np.asarray(pile.noise_phases)
    n = np.stack([np.sin(a[:, 0]) * np.cos(a[:, 1]), np.sin(a[:, 1]) * np.cos(a[:, 2]),
                  np.sin(a[:, 2]) * np.cos(a[:, 0])], axis=1)
    return x + amp[:, None] * n


def ref_grain(pile, cell, y):
    """The grain of one cell at lattice-frame points y, written out by hand."""
    w, R = pile.cell, pile.radius
    centre = w * (np.asarray(cell) + 0.5)
    theta = 0.0
    if pile.rotation_poly:
        v = sum(a * cell[0] ** e[0] * cell[1] ** e[1] * cell[2] ** e[2] for a, e in pile.rotation_poly)
        theta = 2 * math.pi * (v % pile.rotation_steps) / pile.rotation_steps
    rot = Rotation.from_rotvec(theta * np.eye(3)[pile.rotation_axis]).as_matrix()
    q = (y - centre) @ rot                                  # R^T (y - centre)
    if pile.grain == "sphere":
        convex = np.linalg.norm(q, axis=1) - R
    else:
        rr = pile.rounding * R
        d = np.abs(q) - (R - rr)
        convex = np.linalg.norm(np.maximum(d, 0), axis=1) + np.minimum(d.max(axis=1), 0) - rr
    dimples = np.min([np.linalg.norm(q - s * R * e, axis=1) for e in np.eye(3) for s in (1, -1)], axis=0)
    lam = pile.concavity
    if pile.concavity_end is not None:
        s0, s1 = pile.concavity_span
        t = min(max((centre[pile.concavity_axis] - s0) / (s1 - s0), 0.0), 1.0)
        lam = pile.concavity + (pile.concavity_end - pile.concavity) * t
    return (1 - lam) * convex + lam * np.maximum(convex, pile.dimple * R - dimples)


def ref_field(pile, x):
    """min over every grain of a box around the deformed points."""
    y = ref_deform(pile, x)
    lo = np.floor(y.min(axis=0) / pile.cell).astype(int) - 2
    hi = np.floor(y.max(axis=0) / pile.cell).astype(int) + 2
    best = np.full(len(x), np.inf)
    for i in range(lo[0], hi[0] + 1):
        for j in range(lo[1], hi[1] + 1):
            for k in range(lo[2], hi[2] + 1):
                best = np.minimum(best, ref_grain(pile, (i, j, k), y))
    return best


CASES = {
    "spheres": dict(),
    "deformed_spheres": dict(radius=0.5, deform_poly=(0.2, 0.05, -0.02), deform_span=(-2.0, 2.5),
                             noise_frequency=2.5, seed=3),
    "dimpled_ramp_rotated": dict(grain="round_box", radius=0.45, rounding=0.3, dimple=0.6, concavity=0.0,
                                 concavity_end=1.0, concavity_axis=0, concavity_span=(-2.0, 2.0),
                                 rotation_axis=1,
                                 rotation_poly=((1, (2, 0, 0)), (3, (0, 1, 1)), (-2, (0, 0, 1))),
                                 rotation_steps=17),
    "rock_pile": dict(grain="round_box", radius=0.5, rounding=0.5, dimple=0.4, concavity=0.7,
                      rotation_axis=0, rotation_poly=((5, (1, 1, 0)), (1, (0, 0, 3))), rotation_steps=9,
                      deform_poly=(0.1, -0.04, 0.0, 0.01), deform_axis=1, deform_span=(-1.5, 1.5),
                      noise_frequency=4.0, seed=-7),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_min_over_all_grains_within_half_a_cell(name):
    pile = Pile(cell=1.0, **CASES[name])
    x = _points(1500, -2.5, 2.5)
    np.testing.assert_allclose(pile.deform(x), ref_deform(pile, x), rtol=0, atol=1e-13)
    f, ref = pile.field(x), ref_field(pile, x)
    assert np.all(f <= ref + 1e-12)
    assert np.all(f >= np.minimum(ref, 0.5) - 1e-12)
    near = ref < 0.5
    assert near.mean() > 0.5
    np.testing.assert_allclose(f[near], ref[near], rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", sorted(CASES))
def test_lower_bound_of_the_sampled_distance(name):
    # |f| / L never exceeds the distance to sampled points of the other sign (an upper bound of the
    # distance to the surface)
    pile = Pile(cell=1.0, **CASES[name])
    dense = _points(200000, -1.2, 1.2, seed=1)
    fd = pile.field(dense)
    x = _points(3000, -0.8, 0.8, seed=2)
    fx = pile.distance(x)
    for sign in (1, -1):
        tree = cKDTree(dense[sign * fd < 0])
        sel = sign * fx > 0
        gap, _ = tree.query(x[sel])
        assert np.all(np.abs(fx[sel]) <= gap + 1e-12)


@pytest.mark.parametrize("name", sorted(CASES))
def test_gradient_within_the_carried_bound(name):
    pile = Pile(cell=1.0, **CASES[name])
    rng = np.random.default_rng(3)
    a = _points(15000, -3.0, 3.0, seed=4)
    worst = 0.0
    for step in (1e-5, 0.2):
        b = a + rng.normal(0, step, a.shape)
        worst = max(worst, (np.abs(pile.field(a) - pile.field(b)) / np.linalg.norm(a - b, axis=1)).max())
    assert worst <= pile.lipschitz * (1 + 1e-6)
    if pile.deform_poly:
        assert worst > 1.05 and pile.lipschitz > 1.0        # the deformation does stretch the field


def test_deformation_bounds_and_domain():
    pile = Pile(**CASES["rock_pile"])
    pmax, dmax = pile.deformation_bounds
    s = np.linspace(-1.5, 1.5, 20001)
    c = pile.deform_poly
    assert pmax >= np.abs(npoly.polyval(s, c)).max()
    assert dmax >= np.abs(npoly.polyval(s, npoly.polyder(c))).max()
    assert pile.lipschitz == pytest.approx(1 + math.sqrt(3) * (4.0 * pmax + dmax))
    # beyond the span the amplitude keeps its end value
    x = np.array([[0.3, 5.0, 0.2], [-0.7, 40.0, 2.0]])
    a = 4.0 * x + np.asarray(pile.noise_phases)
    noise = np.stack([np.sin(a[:, 0]) * np.cos(a[:, 1]), np.sin(a[:, 1]) * np.cos(a[:, 2]),
                      np.sin(a[:, 2]) * np.cos(a[:, 0])], axis=1)
    np.testing.assert_allclose(pile.deform(x) - x, npoly.polyval(1.5, c) * noise, atol=1e-12)
    Pile(cell=1.0, deform_poly=(0.49,))                     # just inside w / 2
    with pytest.raises(ValueError, match=r"deformation amplitude.*must be < w / 2 = 0.5 mm"):
        Pile(cell=1.0, deform_poly=(0.2, 0.2), deform_span=(0.0, 1.5))


def test_quarter_turns_of_cubes_change_nothing():
    base = dict(grain="round_box", radius=0.45, rounding=0.2, dimple=0.5, concavity=1.0,
                rotation_poly=((1, (1, 2, 0)), (2, (0, 0, 1))))
    x = _points(4000)
    plain = Pile(**{k: v for k, v in base.items() if k != "rotation_poly"}).field(x)
    np.testing.assert_allclose(Pile(rotation_steps=4, **base).field(x), plain, atol=1e-12)
    assert np.abs(Pile(rotation_steps=8, **base).field(x) - plain).max() > 0.01


def test_convex_to_concave():
    x = _points(3000)
    lattice = np.round(x - 0.5) + 0.5                       # the nearest grain centre, w = 1
    spheres = np.linalg.norm(x - lattice, axis=1) - 0.5
    np.testing.assert_allclose(Pile(radius=0.5).field(x), spheres, atol=1e-12)
    probe = np.array([[0.5 + 0.45, 0.5, 0.5]])              # just inside the sphere, under a dimple
    assert Pile(radius=0.5, concavity=0.0).field(probe)[0] < 0
    assert Pile(radius=0.5, concavity=1.0).field(probe)[0] > 0
    ramp = Pile(radius=0.5, concavity=0.0, concavity_end=1.0, concavity_axis=2, concavity_span=(0.0, 10.0))
    assert ramp.field(probe - [0, 0, 5])[0] < 0 and ramp.field(probe + [0, 0, 10])[0] > 0
    assert Pile().box() is None and Pile().lipschitz == 1.0


@pytest.mark.parametrize("name", sorted(CASES))
def test_glsl_matches_numpy(gpu, name):
    from engine.gpu.sdf_points import evaluate_glsl
    pile = Pile(cell=1.0, **CASES[name])
    x = _points(6000, -5.0, 5.0, seed=5)
    np.testing.assert_allclose(evaluate_glsl(pile, x), pile.field(x), rtol=0, atol=1e-5)


@pytest.mark.parametrize("cell", [0.037, 3.7])
def test_glsl_matches_numpy_at_other_scales(gpu, cell):
    from engine.gpu.sdf_points import evaluate_glsl
    pile = Pile(cell=cell, grain="round_box", radius=0.4 * cell, concavity=0.5,
                rotation_poly=((1, (1, 1, 1)),), rotation_steps=5, deform_poly=(0.1 * cell, 0.02),
                deform_span=(-2 * cell, 2 * cell), noise_frequency=3.0 / cell, seed=8)
    x = _points(6000, -6.0 * cell, 6.0 * cell, seed=6) + 10 * cell
    np.testing.assert_allclose(evaluate_glsl(pile, x), pile.field(x), rtol=0, atol=1e-5 * cell)


def test_same_seed_same_bits():
    kw = dict(CASES["rock_pile"])
    kw.pop("seed")
    x = _points(4000)
    a, b, c = (Pile(seed=s, **kw).field(x) for s in (4, 4, 5))
    assert a.tobytes() == b.tobytes()
    assert np.mean(a != c) > 0.5
    assert all(0 <= p < 2 * math.pi for p in Pile(seed=4).noise_phases)


@pytest.mark.parametrize("kw, match", [
    (dict(radius=1.01), r"radius must be at most 1.0 mm"),
    (dict(grain="round_box", radius=0.7, rounding=0.0), r"radius must be at most 0.577"),
    (dict(radius=0.0), "radius"),
    (dict(cell=-1.0), "cell width"),
    (dict(grain="cone"), "grain must be one of"),
    (dict(rounding=1.5), "rounding"),
    (dict(dimple=0.0), "dimple"),
    (dict(concavity=-0.1), "concavity"),
    (dict(concavity_end=1.1), "concavity_end"),
    (dict(concavity_end=1.0, concavity_span=(2.0, 1.0)), "concavity_span"),
    (dict(concavity_axis=3), "concavity_axis"),
    (dict(rotation_axis=-1), "rotation_axis"),
    (dict(rotation_steps=0), "rotation_steps"),
    (dict(rotation_poly=((0.5, (1, 0, 0)),)), "rotation_poly monomial 0: coefficient"),
    (dict(deform_poly=(0.6,)), "deformation amplitude"),
    (dict(deform_poly=(0.1, math.nan)), "finite"),
    (dict(deform_poly=(0.1,), deform_span=(1.0, 1.0)), "deform_span"),
    (dict(deform_axis=5), "deform_axis"),
    (dict(noise_frequency=-1.0), "noise_frequency"),
    (dict(seed="a"), "seed must be an int"),
])
def test_bad_input_refused(kw, match):
    with pytest.raises(ValueError, match=match):
        Pile(**kw)
