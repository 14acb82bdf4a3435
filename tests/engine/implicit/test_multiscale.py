"""Multiscale particle clouds against hand-computed weights, plain clouds, brute force and counts."""

import math

import numpy as np
import pytest

from engine.implicit.combine import Union
from engine.implicit.field_sampling import GridField
from engine.implicit.multiscale import layer_weights, layer_widths, multiscale_suspension
from engine.implicit.particles import SizeDistribution, Suspension

BASE = dict(cell=1.0, size=SizeDistribution("uniform", 0.2, 0.4), jitter=0.8, seed=7)


def _ramp_z(w0, w1, z0=0.0, z1=12.0, n=24, xy=(0.0, 6.0)):
    """Widths geometric in z from w0 to w1 (one sample along x and y)."""
    z = z0 + (np.arange(n) + 0.5) * (z1 - z0) / n
    w = w0 * (w1 / w0) ** ((z - z0) / (z1 - z0))
    return GridField(w.reshape(n, 1, 1), (xy[0], xy[0], z0), (xy[1], xy[1], z1))


def _brute_force(parts, x):
    best = np.full(len(x), np.inf)
    for sus in parts:
        ps = sus.particles_in_box(x.min(axis=0) - 2 * sus.cell, x.max(axis=0) + 2 * sus.cell)
        for c, s in zip(ps.centres, ps.sizes):
            best = np.minimum(best, np.linalg.norm(x - c, axis=1) - s)
    return best


def test_layer_widths_are_geometric():
    w = layer_widths(0.5, 4.0, 4)
    np.testing.assert_allclose(w, [0.5, 1.0, 2.0, 4.0], rtol=1e-14)
    assert w[0] == 0.5 and w[-1] == 4.0
    np.testing.assert_allclose(np.diff(np.log(layer_widths(0.3, 7.0, 6))), math.log(7.0 / 0.3) / 5)
    assert layer_widths(1.0, 4.0, 1) == (2.0,)
    assert layer_widths(0.7, 0.7, 5) == (0.7,)


def test_hat_weights_by_hand_and_sum_to_one():
    layers = layer_widths(1.0, 4.0, 3)                     # 1, 2, 4
    wt = layer_weights([1.0, math.sqrt(2.0), 2.0, 3.0, 4.0], layers)
    frac = math.log(1.5) / math.log(2.0)                   # 3 mm lies this far from 2 towards 4
    want = np.array([[1, 0.5, 0, 0, 0], [0, 0.5, 1, 1 - frac, 0], [0, 0, 0, frac, 1]])
    np.testing.assert_allclose(wt, want, atol=1e-14)
    rng = np.random.default_rng(1)
    s = rng.uniform(0.3, 5.0, (4, 5, 6))
    many = layer_weights(s, layer_widths(s.min(), s.max(), 5))
    np.testing.assert_allclose(many.sum(axis=0), 1.0, atol=1e-14)
    assert np.all(many >= 0) and np.all((many > 0).sum(axis=0) <= 2)


def test_the_layers_weight_fields_sum_to_one_everywhere():
    rng = np.random.default_rng(2)
    wf = GridField(rng.uniform(0.4, 1.6, (4, 3, 5)), (-2.0, -2.0, -2.0), (2.0, 2.0, 2.0))
    cloud = multiscale_suspension(BASE, wf, 4)
    assert isinstance(cloud, Union) and len(cloud.parts) == 4
    x = rng.uniform(-3.0, 3.0, (2000, 3))
    total = sum(p.density_field.sample(x) for p in cloud.parts)
    np.testing.assert_allclose(total, 1.0, atol=1e-12)
    # at the samples each weight is the hand formula's hat of the sampled width
    centres = np.array([wf.lo + (np.array([i, j, k]) + 0.5) * wf.spacing
                        for k in range(4) for j in range(3) for i in range(5)])
    t = np.log(wf.values.ravel() / wf.minimum) / math.log(wf.maximum / wf.minimum) * 3
    for k, p in enumerate(cloud.parts):
        np.testing.assert_allclose(p.density_field.sample(centres), np.maximum(0, 1 - np.abs(t - k)),
                                   atol=1e-12)
        assert p.seed == 7 + k and p.cell == pytest.approx(layer_widths(wf.minimum, wf.maximum, 4)[k])


def test_a_constant_width_is_that_layers_plain_cloud():
    wf = GridField(np.full((2, 2, 2), 0.5), (0.0, 0.0, 0.0), (1.0, 1.0, 1.0))
    cloud = multiscale_suspension({**BASE, "offset": 0.01}, wf, 3)
    plain = Suspension(cell=0.5, size=SizeDistribution("uniform", 0.1, 0.2), jitter=0.8, seed=7, offset=0.01)
    x = np.random.default_rng(3).uniform(-3.0, 3.0, (4000, 3))
    np.testing.assert_array_equal(cloud.field(x), plain.field(x))


def test_where_the_width_is_a_layer_width_only_that_layer_exists():
    xs = np.where(np.arange(20) < 10, 0.5, 2.0)             # x < 0: 0.5 mm, x > 0: 2 mm
    wf = GridField(np.broadcast_to(xs, (1, 1, 20)), (-10.0, -5.0, -5.0), (10.0, 5.0, 5.0))
    cloud = multiscale_suspension(BASE, wf, 3)
    rng = np.random.default_rng(4)
    small = Suspension(cell=0.5, size=SizeDistribution("uniform", 0.1, 0.2), jitter=0.8, seed=7)
    large = Suspension(cell=2.0, size=SizeDistribution("uniform", 0.4, 0.8), jitter=0.8, seed=9)
    left = np.column_stack([rng.uniform(-9.0, -3.0, 3000), rng.uniform(-4, 4, (3000, 2))])
    np.testing.assert_array_equal(cloud.field(left), small.field(left))
    right = np.column_stack([rng.uniform(4.0, 9.0, 3000), rng.uniform(-4, 4, (3000, 2))])
    f, g = cloud.field(right), large.field(right)
    near = g < 0.25                                        # below the other layers' guards
    assert near.mean() > 0.3
    np.testing.assert_array_equal(f[near], g[near])
    assert np.all(f[~near] >= 0.25 - 1e-12)


def test_a_width_ramp_thins_and_grows_particles_along_z():
    wf = _ramp_z(0.25, 1.0)
    cloud = multiscale_suspension(BASE, wf, 5)
    z_all, s_all = [], []
    for p in cloud.parts:
        ps = p.particles_in_box(np.array([0.0, 0.0, 0.0]), np.array([5.999, 5.999, 11.999]))
        inside = np.all((ps.centres >= 0) & (ps.centres < [6.0, 6.0, 12.0]), axis=1)
        z_all.append(ps.centres[inside, 2])
        s_all.append(ps.sizes[inside])
    z, s = np.concatenate(z_all), np.concatenate(s_all)
    edges = np.linspace(0.0, 12.0, 7)
    counts = np.histogram(z, edges)[0] / (36.0 * 2.0)       # particles per mm^3
    mids = 0.5 * (edges[1:] + edges[:-1])
    w = 0.25 * 4.0 ** (mids / 12.0)
    slope = np.polyfit(np.log(w), np.log(counts), 1)[0]
    assert -3.5 < slope < -2.5
    assert np.all(np.diff(counts) < 0)
    np.testing.assert_allclose(counts * w ** 3, 1.0, rtol=0.35)
    mean_size = [s[(z >= a) & (z < b)].mean() for a, b in zip(edges[:-1], edges[1:])]
    assert np.all(np.diff(mean_size) > 0)
    # each particle keeps its proportion to the local width: mean size / w near 0.3
    np.testing.assert_allclose(np.array(mean_size) / w, 0.3, rtol=0.3)


def test_the_union_is_a_lower_bound_of_the_distance_to_all_layers_particles():
    wf = _ramp_z(0.3, 1.2, z0=-2.0, z1=3.0, n=10, xy=(-2.0, 3.0))
    cloud = multiscale_suspension(BASE, wf, 3)
    x = np.random.default_rng(5).uniform(-2.0, 3.0, (3000, 3))
    f = cloud.field(x)
    ref = _brute_force(cloud.parts, x)
    assert np.all(f <= ref + 1e-12)
    near = ref < 0.15                                       # half the smallest layer's width
    assert near.mean() > 0.2
    np.testing.assert_allclose(f[near], ref[near], rtol=0, atol=1e-12)


def test_a_base_density_field_multiplies_every_layers_weight():
    rng = np.random.default_rng(6)
    wf = GridField(rng.uniform(0.4, 1.6, (3, 4, 5)), (-2.0, -2.0, -2.0), (2.0, 2.0, 2.0))
    same = GridField(rng.uniform(0.0, 1.0, (3, 4, 5)), wf.lo, wf.hi)
    other = GridField(rng.uniform(0.0, 1.0, (2, 7, 3)), (-1.0, -3.0, -2.0), (3.0, 2.0, 1.0))
    weights = layer_weights(wf.values, layer_widths(wf.minimum, wf.maximum, 3))
    cloud = multiscale_suspension({**BASE, "density_field": same}, wf, 3)
    for p, wt in zip(cloud.parts, weights):
        np.testing.assert_allclose(p.density_field.values, wt * same.values, atol=1e-15)
    # different grids: the product at the common grid's samples is the product of the two fields
    cloud = multiscale_suspension({**BASE, "density_field": other}, wf, 3)
    g = cloud.parts[0].density_field
    nx, ny, nz = g.counts
    centres = np.array([g.lo + (np.array([i, j, k]) + 0.5) * g.spacing
                        for k in range(nz) for j in range(ny) for i in range(nx)])
    total = sum(p.density_field.sample(centres) for p in cloud.parts)
    np.testing.assert_allclose(total, other.sample(centres), atol=1e-12)
    assert np.all(g.lo <= [-2.0, -3.0, -2.0]) and np.all(g.hi >= [3.0, 2.0, 2.0])


def test_glsl_matches_numpy(gpu):
    from engine.gpu.sdf_points import evaluate_glsl
    wf = _ramp_z(0.3, 1.2, z0=-3.0, z1=3.0, n=12, xy=(-3.0, 3.0))
    dens = GridField(np.random.default_rng(8).uniform(0.5, 1.0, (3, 3, 3)), (-3.0,) * 3, (3.0,) * 3)
    cloud = multiscale_suspension({**BASE, "density_field": dens, "shape": "ellipsoid", "orient": True},
                                  wf, 3)
    x = np.random.default_rng(9).uniform(-4.0, 4.0, (6000, 3))
    np.testing.assert_allclose(evaluate_glsl(cloud, x), cloud.field(x), rtol=0, atol=1e-5)


@pytest.mark.parametrize("base, field, layers, match", [
    ({}, np.array([[[1.0, 0.0]]]), 3, r"width_field samples must be finite and > 0"),
    ({}, np.array([[[1.0, -2.0]]]), 3, r"width_field samples must be finite and > 0"),
    ({}, np.array([[[1.0, 2.0]]]), 0, r"layers must be an int in \[1, 6\]"),
    ({}, np.array([[[1.0, 2.0]]]), 7, r"layers must be an int in \[1, 6\]"),
    ({}, np.array([[[1.0, 2.0]]]), True, r"layers must be an int in \[1, 6\]"),
    ({"offset": 0.3}, np.array([[[0.5, 2.0]]]), 3, r"layer 0 of 3 \(width 0.5 mm\): offset"),
    ({"size": SizeDistribution("fixed", 0.6)}, np.array([[[0.5, 2.0]]]), 2, r"layer 0 .*size distribution"),
    ({"warp_octaves": 2, "warp_amplitude": 0.1, "warp_frequency": 1.0}, np.array([[[1.0, 2.0]]]), 2,
     "warp_octaves must be 1"),
])
def test_bad_input_refused(base, field, layers, match):
    with pytest.raises(ValueError, match=match):
        multiscale_suspension({**BASE, **base}, GridField(field, (0.0,) * 3, (1.0,) * 3), layers)
