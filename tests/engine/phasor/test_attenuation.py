import math

import numpy as np
import pytest

from engine.phasor.attenuation import (FULL_SPREAD, GRADIENT_WEIGHT, attenuation_from_spread, attenuation_grid,
                                       direction_gradient_norm)
from engine.phasor.fields import PhasorFields, constant_fields

LO, HI = np.zeros(3), np.array([20.0, 20.0, 10.0])


def _turning_fields(rate, shape=(4, 8, 40), spread=0.0):
    """D = (cos(rate x), sin(rate x), 0): turns about z at ``rate`` rad/mm."""
    nz, ny, nx = shape
    x = LO[0] + (np.arange(nx) + 0.5) * (HI[0] - LO[0]) / nx
    d = np.zeros(shape + (3,))
    d[..., 0], d[..., 1] = np.cos(rate * x), np.sin(rate * x)
    return PhasorFields(d, np.ones(shape), np.full(shape, spread), LO, HI)


def test_no_spread_and_uniform_d_keep_the_full_filter():
    fields = constant_fields(LO, HI, (3, 4, 5), direction=(0.3, -0.2, 0.9))
    np.testing.assert_array_equal(attenuation_grid(fields, radius=4.5), 1.0)


@pytest.mark.parametrize("gamma, want", [(0.0, 1.0), (FULL_SPREAD / 2, 0.5), (FULL_SPREAD, 0.0),
                                         (math.pi / 2, 0.0)])
def test_attenuation_falls_from_one_to_zero_as_gamma_reaches_the_full_spread(gamma, want):
    fields = constant_fields(LO, HI, (2, 2, 2), spread=gamma)
    np.testing.assert_allclose(attenuation_grid(fields, radius=4.5), want, atol=1e-12)


def test_attenuation_is_smooth_and_monotone_in_the_spread():
    theta = np.linspace(0.0, 2 * FULL_SPREAD, 2001)
    a = attenuation_from_spread(theta)
    assert np.all(np.diff(a) <= 0) and a[0] == 1.0 and a[-1] == 0.0
    slope = np.diff(a) / np.diff(theta)
    assert abs(slope[0]) < 1e-2 and abs(slope[999]) < 1e-2       # flat at both ends (C1)
    # no kink: the slope moves by at most |A''| dtheta = 6 / full^2 * dtheta per step
    assert np.max(np.abs(np.diff(slope))) <= 6.0 / FULL_SPREAD ** 2 * (theta[1] - theta[0]) * 1.01


def test_turning_direction_counts_as_spread_scaled_by_radius():
    rate = 0.05  # rad/mm
    fields = _turning_fields(rate)
    grad = direction_gradient_norm(fields)
    # central differences of cos/sin: |dD/dx| = sin(rate h) / h, within 0.1 % here
    np.testing.assert_allclose(grad[:, :, 1:-1], rate, rtol=1e-3)
    radius = 4.5
    want = attenuation_from_spread(GRADIENT_WEIGHT * radius * rate)
    np.testing.assert_allclose(attenuation_grid(fields, radius=radius)[:, :, 1:-1], want, rtol=1e-3)
    assert 0.9 < want < 1.0  # a gentle turn keeps the filter nearly full


def test_a_reversal_of_d_switches_the_filter_off_there():
    shape = (2, 4, 10)
    d = np.zeros(shape + (3,))
    d[..., 0] = 1.0
    d[:, :, 5:, 0] = -1.0
    fields = PhasorFields(d, np.ones(shape), np.zeros(shape), LO, HI)
    a = attenuation_grid(fields, radius=4.5)
    assert np.all(a[:, :, 4:6] == 0.0) and np.all(a[:, :, :3] == 1.0)


def test_attenuation_stays_in_unit_interval_on_random_fields_and_refuses_bad_options():
    rng = np.random.default_rng(0)
    shape = (5, 6, 7)
    d = rng.normal(size=shape + (3,))
    d /= np.linalg.norm(d, axis=-1)[..., None]
    fields = PhasorFields(d, np.ones(shape), rng.uniform(0, math.pi / 2, shape), LO, HI)
    a = attenuation_grid(fields, radius=4.5)
    assert a.shape == shape and a.min() >= 0.0 and a.max() <= 1.0
    with pytest.raises(ValueError, match="radius"):
        attenuation_grid(fields, radius=0.0)
    with pytest.raises(ValueError, match="full_spread"):
        attenuation_grid(fields, radius=1.0, full_spread=-1.0)
