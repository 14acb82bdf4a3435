"""Suspended particle clouds against brute force over their particles, sampling statistics and the GLSL."""

import math

import numpy as np
import pytest
from scipy import stats

from engine.implicit import cell_hash
from engine.implicit.congruence import CombinedRule, fibres, laminates
from engine.implicit.field_sampling import GridField
from engine.implicit.particle_fields import clusters
from engine.implicit.particles import SizeDistribution, Suspension, shoemake_rotation
from engine.implicit.shapes import SHAPES

W = 1.0
_RNG = np.random.default_rng(123)
# a density field varying over the test box (and clamped beyond it), an offset field in mm
DENSITY = GridField(_RNG.uniform(0.0, 1.0, (4, 5, 6)), (-2.0, -2.0, -2.0), (3.0, 3.0, 3.0))
OFFSET = GridField(_RNG.uniform(-0.08, 0.12, (3, 4, 5)), (-2.5, -1.0, -2.0), (3.0, 3.5, 2.5))


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


def _total_offset(sus, x):
    """offset + o(x) (mm) at points x of the particle frame, o sampled by the field itself
    (tested on its own in test_field_sampling)."""
    return sus.offset + (0.0 if sus.offset_field is None else sus.offset_field.sample(x))


CLOUDS = {
    "spheres_normal": dict(size=SizeDistribution("normal", 0.3, 0.08), density=0.7),
    "boxes_oriented": dict(shape="box", proportions=(1.0, 0.6, 0.4), orient=True,
                           size=SizeDistribution("uniform", 0.15, 0.35)),
    "round_boxes_lognormal": dict(shape="round_box", orient=True, density=0.8,
                                  size=SizeDistribution("lognormal", math.log(0.3), 0.25)),
    "capsules_offset": dict(shape="capsule", orient=True, offset=0.05, jitter=0.6,
                            size=SizeDistribution("fixed", 0.2)),
    "density_field": dict(size=SizeDistribution("uniform", 0.2, 0.45), density_field=DENSITY),
    "offset_field": dict(shape="ellipsoid", orient=True, offset=0.02, offset_field=OFFSET,
                         size=SizeDistribution("normal", 0.25, 0.05)),
    "clusters_rule": dict(size=SizeDistribution("fixed", 0.4), jitter=0.3, rule=clusters(3, 2)),
    "all_three": dict(shape="round_box", orient=True, density=0.9, density_field=DENSITY,
                      offset_field=OFFSET, rule=CombinedRule((fibres(3, 2), laminates(4, 0, 3)), "or"),
                      size=SizeDistribution("uniform", 0.15, 0.35)),
}


@pytest.mark.parametrize("name", sorted(CLOUDS))
def test_lower_bound_of_the_distance_to_the_particles(name):
    sus = Suspension(cell=W, seed=4, **CLOUDS[name])
    x = _points(3000)
    f = sus.field(x)
    total = np.broadcast_to(_total_offset(sus, x), len(x))
    ref = _brute_force(sus, x, exact_sphere=(sus.shape == "sphere")) - total
    # lower bound everywhere; exact within w / 2 of the particles (and inside them)
    assert np.all(f <= ref + 1e-12)
    near = ref < 0.5 * W - total
    assert near.mean() > 0.3
    np.testing.assert_allclose(f[near], ref[near], rtol=0, atol=1e-12)
    assert np.all(f[~near] >= 0.5 * W - total[~near] - 1e-12)


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
    dict(offset_field=OFFSET, density_field=DENSITY, size=SizeDistribution("uniform", 0.2, 0.4)),
    dict(shape="box", orient=True, offset_field=GridField(
        np.random.default_rng(8).uniform(-0.3, 0.3, (6, 6, 6)), (-2, -2, -2), (3, 3, 3)),
         warp_amplitude=0.1, warp_frequency=2.0, rule=clusters(2, 1)),
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


def _box_cells(c0, c1):
    return [(i, j, k) for i in range(c0[0], c1[0] + 1) for j in range(c0[1], c1[1] + 1)
            for k in range(c0[2], c1[2] + 1)]


def _roulette_uniform(seed, cell):
    """u_0 of one cell, straight from the hash."""
    st = cell_hash.cell_stream(np.array([cell[0]]), np.array([cell[1]]), np.array([cell[2]]),
                               cell_hash.seed_word(seed))
    return float(cell_hash.cell_uniform(st, 0)[0])


def test_density_field_keeps_the_cells_a_per_cell_loop_keeps():
    sus = Suspension(cell=0.5, seed=13, density=0.9, density_end=0.4, density_axis=0, density_span=(-1.0, 2.0),
                     density_field=DENSITY, size=SizeDistribution("fixed", 0.2))
    c0, c1 = (-6, -5, -6), (5, 6, 5)
    want = set()
    for c in _box_cells(c0, c1):
        centre = (np.array(c) + 0.5) * 0.5
        t = min(max((centre[0] + 1.0) / 3.0, 0.0), 1.0)
        p = (0.9 * (1 - t) + 0.4 * t) * DENSITY.sample(centre[None])[0]
        if _roulette_uniform(13, c) < p:
            want.add(c)
    got = sus.particles_in_box(np.array(c0) * 0.5, np.array(c1) * 0.5 + 0.25)
    assert set(map(tuple, got.cells.tolist())) == want
    assert 0.2 * 12 ** 3 < len(want) < 0.8 * 12 ** 3


def test_density_field_sets_the_kept_fraction():
    # 0.25 where x < 10 (clamped below the first sample centre), 1 beyond x = 30, linear between
    field = GridField(np.array([[[0.25, 1.0]]]), (0.0, 0.0, 0.0), (40.0, 30.0, 30.0))
    sus = Suspension(cell=1.0, seed=4, density_field=field, size=SizeDistribution("fixed", 0.3))
    parts = sus.particles_in_box((0, 0, 0), (39.5, 29.5, 29.5))
    n = 30 * 30
    for xs, p in [(range(0, 10), 0.25), (range(30, 40), 1.0), (range(19, 20), 0.25 + 0.75 * 9.5 / 20)]:
        kept = np.sum(np.isin(parts.cells[:, 0], list(xs)))
        m = n * len(xs)
        assert abs(kept - p * m) <= 4 * math.sqrt(m * p * (1 - p)) + 1e-9, (xs, kept)


def test_offset_field_ramp_is_added_to_the_offset():
    # samples of o = 0.02 + 0.05 x at the centres along x: trilinear reproduces it between them
    xs = -2.0 + (np.arange(8) + 0.5) * 0.75
    field = GridField(np.broadcast_to(0.02 + 0.05 * xs, (2, 3, 8)), (-2.0, -3.0, -3.0), (4.0, 3.0, 3.0))
    sus = Suspension(cell=W, seed=6, offset=0.1, offset_field=field, size=SizeDistribution("uniform", 0.2, 0.35))
    x = _points(4000, lo=xs[0], hi=xs[-1], seed=3)
    total = 0.1 + 0.02 + 0.05 * x[:, 0]
    ref = _brute_force(sus, x, exact_sphere=True) - total
    f = sus.field(x)
    near = ref < 0.5 * W - total
    assert near.mean() > 0.5 and np.all(f <= ref + 1e-12)
    np.testing.assert_allclose(f[near], ref[near], atol=1e-12)
    assert sus.lipschitz == pytest.approx(1.0 + 0.05)


@pytest.mark.parametrize("rule, by_hand", [
    (clusters(3, 2), lambda c: all(v % 3 < 2 for v in c)),
    (clusters(5, 1), lambda c: all(v % 5 == 0 for v in c)),
    (laminates(4, 1, 2), lambda c: c[1] % 4 < 2),
    (CombinedRule((fibres(3, 2), laminates(4, 0)), "or"), lambda c: (c[0] % 3 == 0 and c[1] % 3 == 0) or c[0] % 4 == 0),
])
def test_rule_keeps_the_cells_it_keeps_by_hand(rule, by_hand):
    c0, c1 = (-7, -6, -5), (6, 7, 5)
    box = (np.array(c0) + 0.1, np.array(c1) + 0.9)
    every = Suspension(cell=1.0, seed=2, rule=rule, size=SizeDistribution("fixed", 0.3))
    got = set(map(tuple, every.particles_in_box(*box).cells.tolist()))
    assert got == {c for c in _box_cells(c0, c1) if by_hand(c)}
    half = Suspension(cell=1.0, seed=2, rule=rule, density=0.6, size=SizeDistribution("fixed", 0.3))
    got = set(map(tuple, half.particles_in_box(*box).cells.tolist()))
    assert got == {c for c in _box_cells(c0, c1) if by_hand(c) and _roulette_uniform(2, c) < 0.6}


def test_clusters_correlate_positively():
    # among kept cells, a face neighbour is kept far more often than the kept fraction
    sus = Suspension(cell=1.0, seed=1, density=0.5, rule=clusters(4, 2), size=SizeDistribution("fixed", 0.3))
    cells = sus.particles_in_box((0, 0, 0), (39.5, 39.5, 39.5)).cells
    kept = np.zeros((40, 40, 40), dtype=bool)
    kept[tuple(cells.T)] = True
    fraction = kept.mean()
    pairs = kept[:-1] & kept[1:]
    assert abs(fraction - 0.5 / 8) < 0.01
    assert pairs.sum() / kept[:-1].sum() > 3 * fraction


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
    dict(density_field=DENSITY, size=SizeDistribution("uniform", 0.2, 0.45)),
    dict(density=0.7, density_end=0.2, density_span=(-3.0, 3.0), density_field=DENSITY),
    dict(offset=0.05, offset_field=OFFSET, shape="ellipsoid", orient=True),
    dict(rule=clusters(3, 2), size=SizeDistribution("fixed", 0.45)),
    dict(rule=CombinedRule((fibres(3, 2), laminates(4, 0, 3)), "or"), density=0.8),
    dict(shape="round_box", orient=True, density_field=DENSITY, offset_field=OFFSET, rule=clusters(2, 1),
         warp_amplitude=0.1, warp_frequency=2.0),
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
    (dict(density_field=GridField(np.array([[[0.5, 1.2]]]), (0, 0, 0), (1, 1, 1))),
     r"density_field values must lie in \[0, 1\].*to 1.2"),
    (dict(density_field=GridField(np.array([[[-0.1, 1.0]]]), (0, 0, 0), (1, 1, 1))), "density_field values"),
    (dict(density_field=0.5), "density_field must be a GridField"),
    (dict(offset=0.3, offset_field=GridField(np.array([[[0.0, 0.2]]]), (0, 0, 0), (1, 1, 1))),
     r"offset \+ max\(offset_field\) = 0.3 \+ 0.2 mm must be < w / 2 = 0.5"),
    (dict(offset_field=np.zeros((2, 2, 2))), "offset_field must be a GridField"),
    (dict(rule="clusters"), "rule must be a CongruenceRule"),
])
def test_bad_input_refused(kw, match):
    with pytest.raises(ValueError, match=match):
        Suspension(**kw)


@pytest.mark.parametrize("args, match", [
    ((1, 1), r"cluster period must be an int in \[2"),
    ((4, 4), r"cluster size must be an int in \[1, 3\]"),
    ((4, 0), "cluster size"),
    ((4.0, 2), "cluster period"),
])
def test_bad_clusters_refused(args, match):
    with pytest.raises(ValueError, match=match):
        clusters(*args)


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


# -- the turbulence warp (supplementary 10.1) ---------------------------------------------

TURBULENT = dict(shape="ellipsoid", orient=True, size=SizeDistribution("uniform", 0.15, 0.3),
                 warp_amplitude=0.12, warp_frequency=2.5, warp_octaves=3, warp_gain=0.6,
                 warp_lacunarity=2.2, warp_matrix=((1.0, 0.3, 0.0), (0.0, 0.8, -0.4), (0.2, 0.0, 1.1)),
                 warp_amplitudes=((0.12, 0.02, 0.0), (0.0, 0.05, 0.0), (0.03, 0.0, 0.1)))


def _turbulent_frame(p, a, f, octaves, gain, lacunarity, m, seed):
    """p + A T(p) written out from the formula (phases from the seed's phase table)."""
    from engine.implicit.turbulence import phase_table
    phases = phase_table(seed)
    q = (p @ np.asarray(m).T)[:, [1, 2, 0]]
    t = sum(gain ** o * np.sin(lacunarity ** o * f * q + phases[o]) for o in range(octaves))
    return p + t @ np.asarray(a).T


def test_turbulent_warp_moves_the_particle_frame():
    sus = Suspension(cell=W, seed=6, **{**TURBULENT, "shape": "sphere", "orient": False})
    p = _points(3000, seed=3)
    x = _turbulent_frame(p, TURBULENT["warp_amplitudes"], 2.5, 3, 0.6, 2.2, TURBULENT["warp_matrix"], 6)
    np.testing.assert_allclose(sus.warp(p), x, rtol=0, atol=1e-12)
    ref = _brute_force(sus, x, exact_sphere=True)
    f = sus.field(p)
    assert np.all(f <= ref + 1e-12)
    near = ref < 0.5 * W
    assert near.mean() > 0.3
    np.testing.assert_allclose(f[near], ref[near], rtol=0, atol=1e-12)


@pytest.mark.parametrize("kw", [
    TURBULENT,
    dict(warp_amplitude=0.1, warp_frequency=3.0, warp_octaves=5, warp_gain=0.7, warp_lacunarity=1.8,
         size=SizeDistribution("normal", 0.3, 0.05)),
])
def test_turbulent_distance_is_a_lower_bound_of_the_world_distance(kw):
    # the ball of radius |f(p)| / L about p lies wholly on p's side of the surface: no point q in
    # it is inside a particle (brute force in the warped frame) when p is outside, and vice versa
    sus = Suspension(cell=W, seed=11, **kw)
    rng = np.random.default_rng(12)
    p = _points(1500, seed=7)
    d = sus.distance(p)
    checked = 0
    for _ in range(20):
        u = rng.normal(size=p.shape)
        u *= (rng.uniform(0, 1, (len(p), 1)) ** (1 / 3)) / np.linalg.norm(u, axis=1, keepdims=True)
        q = p + np.abs(d)[:, None] * u * (1 - 1e-9)
        inside = _brute_force(sus, sus.warp(q), exact_sphere=(sus.shape == "sphere")) - sus.offset < 0
        assert not np.any(inside[d > 0]) and np.all(inside[d < 0])
        checked += len(q)
    assert checked == 30000 and (d < 0).sum() >= 20 and (d > 0).mean() > 0.3


def test_turbulent_gradient_within_the_carried_bound():
    sus = Suspension(cell=W, seed=9, **TURBULENT)
    assert sus.lipschitz == pytest.approx(SHAPES["ellipsoid"].lipschitz * sus._warp.lipschitz)
    rng = np.random.default_rng(4)
    a = _points(20000, seed=8)
    for step in (1e-5, 0.2):
        b = a + rng.normal(0, step, a.shape)
        ratio = np.abs(sus.field(a) - sus.field(b)) / np.linalg.norm(a - b, axis=1)
        assert ratio.max() <= sus.lipschitz * (1 + 1e-6)


def test_one_octave_fields_are_the_single_sine_warp():
    old = dict(cell=W, seed=2, warp_amplitude=0.15, warp_frequency=3.0, size=SizeDistribution("uniform", 0.2, 0.4))
    p = _points(2000)
    same = Suspension(**old, warp_octaves=1, warp_gain=0.9, warp_lacunarity=3.0,
                      warp_amplitudes=None, warp_matrix=None)
    np.testing.assert_array_equal(same.field(p), Suspension(**old).field(p))
    np.testing.assert_array_equal(Suspension(**old).warp(p), p + 0.15 * np.sin(3.0 * p[:, [1, 2, 0]]))
    assert Suspension(**old).lipschitz == 1.0 + 0.15 * 3.0


@pytest.mark.parametrize("kw", [
    TURBULENT,
    dict(warp_amplitude=0.1, warp_frequency=2.0, warp_octaves=4, warp_gain=0.5, warp_lacunarity=2.0,
         shape="round_box", orient=True, density_field=DENSITY, offset_field=OFFSET),
    dict(warp_amplitude=0.2, warp_frequency=1.5, warp_octaves=2, warp_amplitudes=np.diag([0.2, 0.0, 0.1]),
         size=SizeDistribution("fixed", 0.4)),
])
def test_turbulent_glsl_matches_numpy(gpu, kw):
    from engine.gpu.sdf_points import evaluate_glsl
    sus = Suspension(cell=1.0, seed=21, **kw)
    x = _points(6000, lo=-4.0, hi=4.0, seed=1)
    np.testing.assert_allclose(evaluate_glsl(sus, x), sus.field(x), rtol=0, atol=1e-5)


@pytest.mark.parametrize("kw, match", [
    (dict(warp_octaves=0), r"warp_octaves must be an int in \[1, 8\], got 0"),
    (dict(warp_octaves=9), r"warp_octaves must be an int in \[1, 8\]"),
    (dict(warp_octaves=2.5), "warp_octaves must be an int"),
    (dict(warp_gain=0.0), r"warp_gain must be a finite number in \(0.0, 1.0\]"),
    (dict(warp_gain=2.0), "warp_gain"),
    (dict(warp_lacunarity=0.9), r"warp_lacunarity must be a finite number in \[1.0, 4.0\]"),
    (dict(warp_lacunarity=math.nan), "warp_lacunarity"),
    (dict(warp_matrix=np.eye(4)), "warp_matrix must be None or a 3 x 3 matrix of finite numbers"),
    (dict(warp_matrix=np.full((3, 3), math.inf)), "warp_matrix"),
    (dict(warp_amplitudes=[0.1, 0.2, 0.3]), "warp_amplitudes must be a number >= 0 .* or a 3 x 3 matrix"),
    (dict(warp_amplitudes=np.full((3, 3), math.nan)), "warp_amplitudes"),
])
def test_bad_turbulence_refused(kw, match):
    with pytest.raises(ValueError, match=match):
        Suspension(**kw)


def test_particles_node_passes_the_turbulence_on():
    from engine.graph import AddNode, Evaluator, GraphDocument, SetParam, UndoStack
    from engine.graph.node import node_type
    doc = GraphDocument()
    st = UndoStack(doc)
    st.push(AddNode("Particles", {"cell": 1.0, "warp_amplitude": 0.2, "warp_frequency": 2.0, "warp_octaves": 3,
                                  "warp_gain": 0.4, "warp_lacunarity": 2.5,
                                  "warp_anisotropy": [1.0, 0.5, 0.0]}, node_id="p"))
    res = Evaluator().evaluate(doc)
    assert res.ok, res.errors
    sus = res.output("p")
    assert (sus.warp_octaves, sus.warp_gain, sus.warp_lacunarity) == (3, 0.4, 2.5)
    np.testing.assert_array_equal(sus.warp_amplitudes, np.diag([0.2, 0.1, 0.0]))
    p = _points(500)
    x = _turbulent_frame(p, np.diag([0.2, 0.1, 0.0]), 2.0, 3, 0.4, 2.5, np.eye(3), sus.seed)
    np.testing.assert_allclose(sus.warp(p), x, rtol=0, atol=1e-12)
    # defaults: the schema's, and the single-octave warp of before
    cls = node_type("Particles")
    assert [cls.param(n).default for n in ("warp_octaves", "warp_gain", "warp_lacunarity", "warp_anisotropy")] \
        == [1, 0.5, 2.0, [1.0, 1.0, 1.0]]
    st.push(SetParam("p", "warp_anisotropy", [1.0, 1.0, 1.0]))
    st.push(SetParam("p", "warp_octaves", 1))
    sus = Evaluator().evaluate(doc).output("p")
    assert sus.warp_amplitudes is None
    np.testing.assert_array_equal(sus.warp(p), p + 0.2 * np.sin(2.0 * p[:, [1, 2, 0]]))
