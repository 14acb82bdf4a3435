import math

import numpy as np
import pytest

from engine.phasor.fields import PhasorFields, constant_fields, normalise_directions, trilinear


def _grid(shape, lo, hi):
    nz, ny, nx = shape
    step = (np.asarray(hi) - lo) / np.array([nx, ny, nz])
    xs = lo[0] + (np.arange(nx) + 0.5) * step[0]
    ys = lo[1] + (np.arange(ny) + 0.5) * step[1]
    zs = lo[2] + (np.arange(nz) + 0.5) * step[2]
    return np.meshgrid(zs, ys, xs, indexing="ij")


def test_trilinear_is_exact_for_affine_functions_inside_the_centre_hull():
    lo, hi = np.array([0.0, -1.0, 2.0]), np.array([4.0, 3.0, 5.0])
    z, y, x = _grid((5, 6, 7), lo, hi)
    f = 2.0 * x - 3.0 * y + 0.5 * z + 1.0
    rng = np.random.default_rng(1)
    step = (hi - lo) / np.array([7, 6, 5])
    pts = rng.uniform(lo + step / 2, hi - step / 2, size=(200, 3))
    want = 2.0 * pts[:, 0] - 3.0 * pts[:, 1] + 0.5 * pts[:, 2] + 1.0
    np.testing.assert_allclose(trilinear(f, lo, hi, pts), want, atol=1e-12)


def test_trilinear_clamps_outside_and_hits_cell_centres_exactly():
    lo, hi = np.zeros(3), np.ones(3) * 2
    rng = np.random.default_rng(2)
    g = rng.normal(size=(2, 2, 2, 3))
    centres = np.array([[0.5, 0.5, 0.5], [1.5, 0.5, 1.5]])
    np.testing.assert_allclose(trilinear(g, lo, hi, centres), [g[0, 0, 0], g[1, 0, 1]], atol=1e-12)
    np.testing.assert_allclose(trilinear(g, lo, hi, [[-5.0, -5.0, -5.0]]), [g[0, 0, 0]], atol=1e-12)


def test_sampled_directions_are_unit_and_cancelling_blends_fall_back_to_nearest_cell():
    d = np.zeros((1, 1, 2, 3))
    d[0, 0, 0] = [1, 0, 0]
    d[0, 0, 1] = [-1, 0, 0]
    fields = PhasorFields(d, np.ones((1, 1, 2)), np.zeros((1, 1, 2)), [0, 0, 0], [2, 1, 1])
    out = fields.sample_direction([[1.0, 0.5, 0.5], [0.7, 0.5, 0.5]])
    np.testing.assert_allclose(np.linalg.norm(out, axis=1), 1.0)
    assert out[1, 0] == pytest.approx(1.0)


@pytest.mark.parametrize("field, value, words", [
    ("frequency", 0.0, "frequency F"), ("frequency", math.nan, "frequency F"),
    ("spread", 2.0, "Gamma"), ("spread", -0.1, "Gamma"),
])
def test_bad_scalar_values_are_refused_naming_field_and_place(field, value, words):
    f = constant_fields([0, 0, 0], [4, 4, 4], (4, 4, 4))
    arrays = {"direction": f.direction, "frequency": f.frequency.copy(), "spread": f.spread.copy()}
    arrays[field][2, 1, 3] = value
    with pytest.raises(ValueError, match=words) as info:
        PhasorFields(arrays["direction"], arrays["frequency"], arrays["spread"], f.lo, f.hi)
    assert "z=2, y=1, x=3" in str(info.value)


def test_zero_or_nan_directions_are_refused():
    with pytest.raises(ValueError, match="zero or NaN"):
        normalise_directions([[1, 0, 0], [0, 0, 0]])
    d = np.zeros((2, 2, 2, 3))
    d[..., 2] = 1
    d[1, 1, 1] = np.nan
    with pytest.raises(ValueError, match="direction D"):
        PhasorFields(d, np.ones((2, 2, 2)), np.zeros((2, 2, 2)), [0, 0, 0], [1, 1, 1])
