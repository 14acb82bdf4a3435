"""Suspended particle clouds against brute force over their particles, sampling statistics and the GLSL."""

import math

import numpy as np
import pytest
from scipy import stats

from engine.implicit.particles import SizeDistribution, Suspension, shoemake_rotation
from engine.implicit.shapes import SHAPES

W = 1.0


def _points(n, lo=-2.0, hi=3.0, seed=0):
    return np.random.default_rng(seed).uniform(lo, hi, (n, 3))


def _brute_force(sus, x, exact_sphere=False):
    """min over every particle near the points of the exact distance to it (x in the particle frame)."""
    parts = sus.particles_in_box(x.min(axis=0) - 2 * sus.cell, x.max(axis=0) + 2 * sus.cell)
    best = np.full(len(x), np.inf)
    spec = SHAPES[sus.shape]
    for c, s, rot in zip(parts.centres, parts.sizes, parts.rotations):
        q = x - c
        if exact_sphere:
            d = np.linalg.norm(q, axis=1) - s
        else:
            d = spec.fn(q @ rot, *(s * v for v in sus.proportions))
        best = np.minimum(best, d)
    return best


CLOUDS = {
    "spheres_normal": dict(size=SizeDistribution("normal", 0.3, 0.08), density=0.7),
    "boxes_oriented": dict(shape="box", proportions=(1.0, 0.6, 0.4), orient=True,
                           size=SizeDistribution("uniform", 0.15, 0.35)),
    "round_boxes_lognormal": dict(shape="round_box", orient=True, density=0.8,
                                  size=SizeDistribution("lognormal", math.log(0.3), 0.25)),
    "capsules_offset": dict(shape="capsule", orient=True, offset=0.05, jitter=0.6,
                            size=SizeDistribution("fixed", 0.2)),
}


@pytest.mark.parametrize("name", sorted(CLOUDS))
def test_lower_bound_of_the_distance_to_the_particles(name):
    sus = Suspension(cell=W, seed=4, **CLOUDS[name])
    x = _points(3000)
    f = sus.field(x)
    ref = _brute_force(sus, x, exact_sphere=(sus.shape == "sphere")) - sus.offset
    # lower bound everywhere; exact within w / 2 of the particles (and inside them)
    assert np.all(f <= ref + 1e-12)
    near = ref < 0.5 * W - sus.offset
    assert near.mean() > 0.3
    np.testing.assert_allclose(f[near], ref[near], rtol=0, atol=1e-12)
    assert np.all(f[~near] >= 0.5 * W - sus.offset - 1e-12)


def test_empty_cells_give_the_distance_to_the_dual_block():
    sus = Suspension(cell=0.5, density=0.0, size=SizeDistribution("fixed", 0.2))
    x = _points(2000)
    t = x / 0.5 - np.floor(x / 0.5 - 0.5)           # in [0.5, 1.5): position in the 2x2x2 block
    np.testing.assert_allclose(sus.field(x), 0.5 * np.min(np.minimum(t, 2 - t), axis=1), atol=1e-12)
    assert sus.particles_in_box((0, 0, 0), (3, 3, 3)).sizes.size == 0


def test_warp_moves_the_particle_frame():
    sus = Suspension(cell=W, seed=2, warp_amplitude=0.15, warp_frequency=3.0,
                     size=SizeDistribution("uniform", 0.2, 0.4))
    p = _points(2000)
    x = p + 0.15 * np.sin(3.0 * p[:, [1, 2, 0]])
    np.testing.assert_allclose(sus.warp(p), x, atol=1e-15)
    ref = _brute_force(sus, x, exact_sphere=True)
    f = sus.field(p)
    assert np.all(f <= ref + 1e-12)
    near = ref < 0.5 * W
    np.testing.assert_allclose(f[near], ref[near], atol=1e-12)
    assert sus.lipschitz == pytest.approx(1.0 + 0.45)


@pytest.mark.parametrize("kw", [
    dict(size=SizeDistribution("normal", 0.3, 0.1)),
    dict(shape="ellipsoid", orient=True, size=SizeDistribution("uniform", 0.2, 0.5)),
    dict(shape="torus", orient=True, warp_amplitude=0.2, warp_frequency=2.5,
         size=SizeDistribution("fixed", 0.4)),
    dict(shape="hex_prism", orient=True, offset=-0.1, density=0.5, density_end=1.0, density_span=(-1, 2)),
])
def test_gradient_within_the_carried_bound(kw):
    sus = Suspension(cell=W, seed=9, **kw)
    rng = np.random.default_rng(3)
    a = _points(20000, seed=5)
    for step in (1e-5, 0.2):                          # finite differences, and pairs across cells
        b = a + rng.normal(0, step, a.shape)
        ratio = np.abs(sus.field(a) - sus.field(b)) / np.linalg.norm(a - b, axis=1)
        assert ratio.max() <= sus.lipschitz * (1 + 1e-6)


@pytest.mark.parametrize("shape", sorted(SHAPES))
def test_bounding_spheres_inside_their_cells(shape):
    # sd far above the cell allows: many sizes are clamped to the largest
    spec = SHAPES[shape]
    smax = 0.5 * 0.8 / spec.bound(*spec.default)
    sus = Suspension(cell=0.8, shape=shape, orient=True, size=SizeDistribution("normal", 0.9 * smax, smax),
                     seed=1)
    parts = sus.particles_in_box((-2, -2, -2), (4, 4, 4))
    assert len(parts.sizes) > 200
    assert np.all(parts.radii <= 0.4 + 1e-12) and np.mean(parts.radii >= 0.4 - 1e-12) > 0.2
    np.testing.assert_allclose(parts.radii, parts.sizes * spec.bound(*spec.default), rtol=1e-12)
    lo, hi = parts.cells * 0.8, (parts.cells + 1) * 0.8
    assert np.all(parts.centres - parts.radii[:, None] >= lo - 1e-12)
    assert np.all(parts.centres + parts.radii[:, None] <= hi + 1e-12)
    rot = parts.rotations
    np.testing.assert_allclose(np.einsum("nij,nik->njk", rot, rot), np.broadcast_to(np.eye(3), rot.shape),
                               atol=1e-12)


def test_same_seed_same_bits_other_seed_other_field():
    kw = dict(cell=0.7, shape="ellipsoid", orient=True, size=SizeDistribution("normal", 0.25, 0.05))
    x = _points(5000)
    a, b, c = (Suspension(seed=s, **kw).field(x) for s in (17, 17, 18))
    assert a.tobytes() == b.tobytes()
    assert np.mean(a != c) > 0.5


def test_density_is_the_kept_fraction():
    sus = Suspension(cell=1.0, density=0.3, seed=6)
    parts = sus.particles_in_box((0, 0, 0), (29.5, 29.5, 29.5))
    n = 30 ** 3
    assert abs(len(parts.sizes) - 0.3 * n) <= 4 * math.sqrt(n * 0.3 * 0.7)


def test_density_ramp_along_an_axis():
    sus = Suspension(cell=1.0, density=0.1, density_end=0.9, density_axis=1, density_span=(0.0, 20.0), seed=2)
    parts = sus.particles_in_box((0, -10, 0), (39.5, 29.5, 39.5))
    for y, p in [(-5, 0.1), (2, 0.1 + 0.8 * 2.5 / 20), (10, 0.1 + 0.8 * 10.5 / 20), (25, 0.9)]:
        kept = np.sum(parts.cells[:, 1] == y)
        n = 40 * 40
        assert abs(kept - p * n) <= 4 * math.sqrt(n * p * (1 - p)), (y, kept)


def test_size_distributions_match_their_parameters():
    box = ((0, 0, 0), (24.5, 24.5, 24.5))
    normal = Suspension(cell=1.0, size=SizeDistribution("normal", 0.2, 0.04), seed=3).particles_in_box(*box)
    s, n = normal.sizes, len(normal.sizes)
    assert n == 25 ** 3
    assert abs(s.mean() - 0.2) < 4 * 0.04 / math.sqrt(n)
    assert abs(s.std() - 0.04) < 4 * 0.04 / math.sqrt(2 * n)
    assert stats.kstest(s, stats.norm(0.2, 0.04).cdf).pvalue > 1e-4
    logn = Suspension(cell=1.0, size=SizeDistribution("lognormal", math.log(0.15), 0.3), seed=3)
    log_sizes = np.log(logn.particles_in_box(*box).sizes)
    assert stats.kstest(log_sizes, stats.norm(math.log(0.15), 0.3).cdf).pvalue > 1e-4
    uni = Suspension(cell=1.0, size=SizeDistribution("uniform", 0.1, 0.4), seed=3)
    uni = uni.particles_in_box(*box).sizes
    assert stats.kstest(uni, stats.uniform(0.1, 0.3).cdf).pvalue > 1e-4
    fixed = Suspension(cell=1.0, size=SizeDistribution("fixed", 0.33)).particles_in_box(*box).sizes
    assert np.all(fixed == 0.33)


def test_lattice_without_jitter():
    sus = Suspension(cell=0.5, jitter=0.0, size=SizeDistribution("fixed", 0.2))
    parts = sus.particles_in_box((0, 0, 0), (1.9, 1.9, 1.9))
    np.testing.assert_allclose(parts.centres, (parts.cells + 0.5) * 0.5, atol=1e-15)


def test_rotations_are_uniform():
    u = np.random.default_rng(0).random((3, 30000))
    r = shoemake_rotation(*u)
    np.testing.assert_allclose(np.linalg.det(r), 1.0, atol=1e-12)
    # Haar measure: every entry has mean 0 and variance 1 / 3
    assert np.abs(r.mean(axis=0)).max() < 4 * math.sqrt(1 / 3 / 30000)
    np.testing.assert_allclose(r.var(axis=0), 1 / 3, atol=0.02)


GLSL_CASES = [
    dict(),
    dict(size=SizeDistribution("uniform", 0.15, 0.45), jitter=0.5, offset=0.1),
    dict(size=SizeDistribution("normal", 0.3, 0.1), density=0.6),
    dict(size=SizeDistribution("lognormal", math.log(0.25), 0.3), density=0.2, density_end=0.9,
         density_axis=0, density_span=(-2.0, 3.0)),
    dict(shape="round_box", orient=True, size=SizeDistribution("normal", 0.3, 0.05)),
    dict(shape="torus", orient=True, warp_amplitude=0.2, warp_frequency=2.0,
         size=SizeDistribution("fixed", 0.4)),
] + [dict(shape=s, orient=True,
          size=SizeDistribution("uniform", 0.1, 0.48 / SHAPES[s].bound(*SHAPES[s].default)))
     for s in sorted(SHAPES)]


@pytest.mark.parametrize("kw", GLSL_CASES)
def test_glsl_matches_numpy(gpu, kw):
    from engine.gpu.sdf_points import evaluate_glsl
    sus = Suspension(cell=1.0, seed=21, **kw)
    x = _points(6000, lo=-4.0, hi=4.0, seed=1)
    np.testing.assert_allclose(evaluate_glsl(sus, x), sus.field(x), rtol=0, atol=1e-5)


@pytest.mark.parametrize("cell", [0.037, 3.7])
def test_glsl_matches_numpy_at_other_scales(gpu, cell):
    from engine.gpu.sdf_points import evaluate_glsl
    sus = Suspension(cell=cell, seed=-8, shape="cylinder", orient=True, offset=0.1 * cell,
                     size=SizeDistribution("normal", 0.3 * cell, 0.1 * cell),
                     warp_amplitude=0.1 * cell, warp_frequency=3.0 / cell)
    x = _points(6000, lo=-6.0 * cell, hi=5.0 * cell, seed=2) + 20 * cell
    np.testing.assert_allclose(evaluate_glsl(sus, x), sus.field(x), rtol=0, atol=1e-5 * cell)


def test_fills_space_and_evaluates_a_grid():
    sus = Suspension(cell=0.25, shape="ellipsoid", orient=True, size=SizeDistribution("normal", 0.1, 0.02))
    assert sus.box() is None and sus.children == () and sus.lipschitz == 1.0
    g = np.stack(np.meshgrid(*[np.linspace(0, 4, 64)] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    f = sus.field(g)
    assert f.shape == (64 ** 3,) and np.all(np.isfinite(f)) and (f < 0).mean() > 0.01


@pytest.mark.parametrize("kw, match", [
    (dict(cell=0.0), r"cell width must be a finite number in \(0.0"),
    (dict(cell=-1.0), "cell width"),
    (dict(size=SizeDistribution("fixed", 0.6)), r"size = 0.6 is too large.*at most 0.5 mm"),
    (dict(size=SizeDistribution("uniform", 0.1, 0.7)), r"hi = 0.7 is too large.*at most 0.5 mm"),
    (dict(size=SizeDistribution("normal", 0.55, 0.1)), r"mean = 0.55 is too large"),
    (dict(size=SizeDistribution("lognormal", 0.0, 0.1)), r"mu = 0.0 is too large.*at most -0.69"),
    (dict(proportions=(2.0,), size=SizeDistribution("fixed", 0.3)), r"at most 0.25 mm"),
    (dict(density=1.2), r"density must be a finite number in \[0.0, 1.0\]"),
    (dict(density=-0.1), "density"),
    (dict(density_end=2.0), "density_end"),
    (dict(density_end=0.5, density_span=(1.0, 1.0)), "start < end"),
    (dict(density_end=0.5, density_span=(0.0, 1.0, 2.0)), "density_span"),
    (dict(density_end=0.5, density_axis=3), "density_axis"),
    (dict(shape="cone"), "unknown particle shape"),
    (dict(proportions=(1.0, 2.0)), "takes parameters"),
    (dict(jitter=1.5), "jitter"),
    (dict(offset=0.5), "offset"),
    (dict(warp_amplitude=-1.0), "warp_amplitude"),
    (dict(warp_frequency=math.inf), "warp_frequency"),
    (dict(seed=1.5), "seed must be an int"),
    (dict(size=0.3), "SizeDistribution"),
    (dict(orient="yes"), "orient"),
])
def test_bad_input_refused(kw, match):
    with pytest.raises(ValueError, match=match):
        Suspension(**kw)


@pytest.mark.parametrize("args, match", [
    (("gamma", 1.0), "kind must be one of"),
    (("fixed", 0.0), "size must be > 0"),
    (("uniform", 0.3, 0.2), "hi must be >= lo"),
    (("normal", 0.3, -0.1), "sd must be >= 0"),
    (("lognormal", 0.0, math.nan), "finite"),
])
def test_bad_size_distribution_refused(args, match):
    with pytest.raises(ValueError, match=match):
        SizeDistribution(*args)


def test_bad_box_refused():
    sus = Suspension()
    with pytest.raises(ValueError, match="lo <= hi"):
        sus.particles_in_box((1, 0, 0), (0, 1, 1))
    with pytest.raises(ValueError, match="at most"):
        sus.particles_in_box((0, 0, 0), (1000, 1000, 1000))
