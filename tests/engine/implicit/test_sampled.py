"""`engine.implicit.sampled.Sampled` against scipy's grid interpolator and closed forms."""

import numpy as np
import pytest
from scipy.interpolate import RegularGridInterpolator

from engine.gpu.sdf_points import evaluate_glsl
from engine.implicit.sampled import Sampled


def _sphere_grid(n=(9, 11, 7), h=(0.25, 0.2, 0.3), origin=(-1.0, -1.1, -0.9), r=0.7):
    axes = [origin[a] + np.arange(n[a]) * h[a] for a in range(3)]
    x, y, z = np.meshgrid(*axes, indexing="ij")
    return np.sqrt(x * x + y * y + z * z) - r, axes


def test_inside_the_box_it_is_scipys_trilinear_interpolation():
    values, axes = _sphere_grid()
    s = Sampled(values, origin=(-1.0, -1.1, -0.9), spacing=(0.25, 0.2, 0.3), periodic=False)
    ref = RegularGridInterpolator(axes, values, method="linear")
    lo, hi = (np.array([a[0] for a in axes]), np.array([a[-1] for a in axes]))
    p = np.random.default_rng(1).uniform(lo, hi, (4000, 3))
    assert np.allclose(s.field(p), np.maximum(ref(p), -np.inf), atol=1e-12)
    nodes = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
    assert np.allclose(s.field(nodes), values.ravel(), atol=1e-12)      # exact at the nodes


def test_a_periodic_grid_repeats_and_wraps_between_its_last_and_first_node():
    rng = np.random.default_rng(2)
    values = rng.normal(size=(5, 6, 4))
    h = np.array([0.2, 0.3, 0.25])
    s = Sampled(values, origin=(0.1, 0.0, -0.3), spacing=h, periodic=True)
    ext = np.pad(values, ((0, 1), (0, 1), (0, 1)), mode="wrap")           # the wrap node appended
    axes = [(0.1, 0.0, -0.3)[a] + np.arange(ext.shape[a]) * h[a] for a in range(3)]
    ref = RegularGridInterpolator(axes, ext, method="linear")
    period = np.array(values.shape) * h
    p = rng.uniform(0, 1, (3000, 3)) * period + np.array([0.1, 0.0, -0.3])
    shifts = rng.integers(-3, 4, (3000, 3)) * period
    assert np.allclose(s.field(p + shifts), ref(p), atol=1e-9)
    assert s.box() is None


def test_the_carried_bound_holds_and_outside_the_box_it_grows_like_the_box_distance():
    values, axes = _sphere_grid()
    s = Sampled(values, origin=(-1.0, -1.1, -0.9), spacing=(0.25, 0.2, 0.3), periodic=False)
    rng = np.random.default_rng(3)
    a = rng.uniform(-2, 2, (20000, 3))
    b = a + rng.normal(scale=0.02, size=a.shape)
    slope = np.abs(s.field(a) - s.field(b)) / np.linalg.norm(a - b, axis=1)
    assert slope.max() <= s.lipschitz * (1 + 1e-9)
    assert 1.0 <= s.lipschitz <= np.sqrt(3.0) + 1e-9                     # a sampled distance
    lo, hi = (np.array(v) for v in s.box())
    out = a[np.any((a < lo) | (a > hi), axis=1)]
    gap = np.linalg.norm(np.maximum(np.maximum(lo - out, out - hi), 0), axis=1)
    assert np.all(s.field(out) >= gap - 1e-12)


def test_glsl_reads_the_same_interpolation(gpu):
    rng = np.random.default_rng(4)
    for periodic in (True, False):
        values, _ = _sphere_grid()
        s = Sampled(values, origin=(-1.0, -1.1, -0.9), spacing=(0.25, 0.2, 0.3), periodic=periodic)
        p = rng.uniform(-3, 3, (5000, 3))
        assert np.allclose(evaluate_glsl(s, p), s.field(p), atol=1e-5)


@pytest.mark.parametrize("kwargs, match", [
    (dict(values=np.zeros((1, 4, 4))), "at least 2 nodes"),
    (dict(values=np.full((3, 3, 3), np.nan)), "NaN"),
    (dict(values=np.zeros((3, 3, 3)), spacing=(0.1, 0.0, 0.1)), "spacing"),
    (dict(values=np.zeros((3, 3, 3)), origin=(0, 0)), "origin"),
])
def test_bad_grids_are_refused(kwargs, match):
    with pytest.raises(ValueError, match=match):
        Sampled(**kwargs)
