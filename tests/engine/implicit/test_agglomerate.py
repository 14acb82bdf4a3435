"""Agglomerates against brute force over every kept particle, their gradient bound and the GLSL."""

import math

import numpy as np
import pytest

from engine.implicit import cell_hash
from engine.implicit import congruence as cg
from engine.implicit.agglomerate import Agglomerate
from engine.implicit.shapes import SHAPES


def _points(n, lo=-3.0, hi=3.0, seed=0):
    return np.random.default_rng(seed).uniform(lo, hi, (n, 3))


def _rot(seed):
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    return q * np.sign(np.diag(r))


def _brute_force(agg, x, exact_sphere=False):
    """min over every kept particle within 2 cells of the points of its distance."""
    parts = agg.particles_in_box(x.min(axis=0) - 2 * agg.cell, x.max(axis=0) + 2 * agg.cell)
    spec = SHAPES[agg.shape]
    best = np.full(len(x), np.inf)
    for c, rot in zip(parts.centres, parts.rotations):
        q = x - c
        if exact_sphere:
            d = np.linalg.norm(q, axis=1) - agg.size * agg.proportions[0]
        else:
            d = spec.fn(q @ rot, *(agg.size * v for v in agg.proportions))
        best = np.minimum(best, d)
    return best


CASES = {
    "spheres_fibres_max_size": dict(size=1.0, rule=cg.fibres(3, axis=0)),
    "spheres_gel_jitter": dict(size=0.75, rule=cg.bezier_gel(), jitter=1.0),
    "boxes_frame_rotated": dict(shape="box", size=0.7, rule=cg.cubic_frame(4), rotation=_rot(1), jitter=0.5),
    "capsules_laminates": dict(shape="capsule", size=0.9, rule=cg.laminates(3, axis=2, width=2), jitter=0.3,
                               rotation=_rot(2)),
    "cylinders_porous": dict(shape="cylinder", size=0.5, rule=cg.porous(3), jitter=1.0),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_lower_bound_exact_near_particles(name):
    agg = Agglomerate(cell=1.0, seed=5, **CASES[name])
    x = _points(2500)
    f = agg.field(x)
    ref = _brute_force(agg, x, exact_sphere=(agg.shape == "sphere"))
    assert np.all(f <= ref + 1e-12)
    near = ref < 0.5
    assert 0.2 < near.mean() < 1.0
    np.testing.assert_allclose(f[near], ref[near], rtol=0, atol=1e-12)
    assert np.all(f >= np.minimum(ref, 0.5) - 1e-12)   # never below min(distance, w / 2)


def test_non_euclidean_shape_is_the_min_over_all_particles():
    agg = Agglomerate(cell=0.6, shape="ellipsoid", size=0.55, rule=cg.laminates(2), rotation=_rot(3),
                      jitter=0.8)
    x = _points(2000, -1.5, 1.5, seed=1)
    f, ref = agg.field(x), _brute_force(agg, x)
    assert np.all(f <= ref + 1e-12)
    near = ref < 0.3
    np.testing.assert_allclose(f[near], ref[near], atol=1e-12)


@pytest.mark.parametrize("shape", sorted(SHAPES))
def test_shapes_are_above_the_distance_to_their_bounding_sphere(shape):
    # the continuity argument of the module docstring relies on d(q) >= |q| - r
    spec = SHAPES[shape]
    q = _points(20000, -3.0, 3.0, seed=2)
    r = spec.bound(*spec.default)
    assert np.all(spec.fn(q, *spec.default) >= np.linalg.norm(q, axis=1) - r - 1e-12)


def test_nothing_kept_gives_the_guard_distance():
    never = cg.CongruenceRule((((1, (0, 0, 0)),),), (None,), (((0, 1),),))       # 1 < 0: false
    agg = Agglomerate(cell=0.5, rule=never)
    x = _points(2000)
    t = x / 0.5 - np.floor(x / 0.5)
    np.testing.assert_allclose(agg.field(x), 0.5 * np.min(np.minimum(t + 0.5, 1.5 - t), axis=1), atol=1e-12)
    assert np.all(agg.field(x) >= 0.25 - 1e-12)


def test_lattice_and_jitter_keep_the_bounding_spheres_in_the_27_cells():
    lattice = Agglomerate(cell=0.5, size=0.2, rule=cg.laminates(2))
    p = lattice.particles_in_box((0, 0, 0), (2.9, 2.9, 2.9))
    np.testing.assert_allclose(p.centres, (p.cells + 0.5) * 0.5, atol=1e-15)
    assert np.all(p.cells[:, 2] % 2 == 0) and len(p.cells) == 6 * 6 * 3
    agg = Agglomerate(cell=1.0, shape="box", size=0.4, jitter=1.0, seed=3)
    p = agg.particles_in_box((0, 0, 0), (19, 19, 19))
    r = 0.4 * SHAPES["box"].bound(*SHAPES["box"].default)
    off = np.abs(p.centres - (p.cells + 0.5))
    assert np.all(off + r <= 1.0 + 1e-12)                  # inside [(c - 0.5) w, (c + 1.5) w]
    assert off.max() > 0.99 * (1.0 - r)                     # the jitter uses its whole range
    # uniforms from the xorshift seeding of section 3.2
    st = cell_hash.xorshift_key(p.cells[:, 0], p.cells[:, 1], p.cells[:, 2], cell_hash.seed_word(3))
    u = cell_hash.cell_uniform(st, 1)
    np.testing.assert_allclose(p.centres[:, 1], p.cells[:, 1] + 0.5 + (1 - r) * (2 * u - 1), atol=1e-12)


@pytest.mark.parametrize("name", sorted(CASES))
def test_gradient_within_one(name):
    agg = Agglomerate(cell=1.0, seed=2, **CASES[name])
    rng = np.random.default_rng(4)
    a = _points(15000, seed=6)
    for step in (1e-5, 0.3):
        b = a + rng.normal(0, step, a.shape)
        ratio = np.abs(agg.field(a) - agg.field(b)) / np.linalg.norm(a - b, axis=1)
        assert ratio.max() <= 1.0 + 1e-6
    assert agg.lipschitz == 1.0


@pytest.mark.parametrize("name", sorted(CASES))
def test_glsl_matches_numpy(gpu, name):
    from engine.gpu.sdf_points import evaluate_glsl
    agg = Agglomerate(cell=1.0, seed=-4, **CASES[name])
    x = _points(6000, -5.0, 5.0, seed=7)
    np.testing.assert_allclose(evaluate_glsl(agg, x), agg.field(x), rtol=0, atol=1e-5)


@pytest.mark.parametrize("cell", [0.037, 3.7])
def test_glsl_matches_numpy_at_other_scales(gpu, cell):
    from engine.gpu.sdf_points import evaluate_glsl
    agg = Agglomerate(cell=cell, shape="hex_prism", size=0.6 * cell, rule=cg.bezier_gel(period=7), jitter=0.7,
                      rotation=_rot(5), seed=11)
    x = _points(6000, -6.0 * cell, 6.0 * cell, seed=8) - 30 * cell
    np.testing.assert_allclose(evaluate_glsl(agg, x), agg.field(x), rtol=0, atol=1e-5 * cell)


def test_same_seed_same_bits():
    kw = dict(cell=0.7, shape="round_box", size=0.5, rule=cg.bezier_gel(), jitter=1.0)
    x = _points(4000)
    a, b, c = (Agglomerate(seed=s, **kw).field(x) for s in (9, 9, 10))
    assert a.tobytes() == b.tobytes()
    assert np.mean(a != c) > 0.5
    assert Agglomerate(**kw).box() is None


@pytest.mark.parametrize("kw, match", [
    (dict(size=1.01), r"size must be in \(0, 1.0\] mm"),
    (dict(shape="box", size=1.0), r"size must be in \(0, 0.96"),
    (dict(size=0.0), "size"),
    (dict(cell=0.0), "cell width"),
    (dict(jitter=-0.1), "jitter"),
    (dict(rule="fibres"), "rule must be"),
    (dict(rotation=np.ones((3, 3))), "orthogonal"),
    (dict(shape="cone"), "unknown particle shape"),
    (dict(seed=2.5), "seed must be an int"),
])
def test_bad_input_refused(kw, match):
    with pytest.raises(ValueError, match=match):
        Agglomerate(**kw)


def test_bad_box_refused():
    with pytest.raises(ValueError, match="lo <= hi"):
        Agglomerate().particles_in_box((1, 0, 0), (0, 1, 1))
    with pytest.raises(ValueError, match="at most"):
        Agglomerate().particles_in_box((0, 0, 0), (1000, 1000, 1000))
    assert math.isfinite(Agglomerate().bounding_radius)
