"""thickness_profile: piecewise linear with constant ends (paper section 5.3)."""

import numpy as np
import pytest

from engine.geometry.thickness import thickness_profile


def test_linear_between_samples_and_constant_outside():
    samples = [(0.2, 0.1), (0.6, 0.3), (1.0, 0.2)]
    t = np.array([0.0, 0.1, 0.2, 0.4, 0.6, 0.8, 1.0])
    expected = [0.1, 0.1, 0.1, 0.2, 0.3, 0.25, 0.2]
    np.testing.assert_allclose(thickness_profile(t, samples), expected, rtol=0, atol=1e-15)


def test_order_of_samples_does_not_matter():
    t = np.linspace(0, 1, 11)
    a = thickness_profile(t, [(0.0, 1.0), (0.5, 2.0), (1.0, 1.5)])
    b = thickness_profile(t, [(1.0, 1.5), (0.0, 1.0), (0.5, 2.0)])
    np.testing.assert_array_equal(a, b)


def test_single_sample_is_constant():
    out = thickness_profile(np.linspace(0, 1, 7), [(0.3, 0.05)])
    assert out.shape == (7,) and out.dtype == np.float64
    assert np.all(out == 0.05)


def test_scalar_t_gives_one_value():
    assert thickness_profile(0.5, [(0, 1.0), (1, 3.0)]).tolist() == [2.0]


@pytest.mark.parametrize("t, samples, match", [
    ([0.5], [], "at least one"),
    ([0.5], [(1.2, 0.1)], r"\[0, 1\]"),
    ([0.5], [(-0.1, 0.1)], r"\[0, 1\]"),
    ([0.5], [(0.5, 0.0)], "> 0"),
    ([0.5], [(0.5, -1.0)], "> 0"),
    ([0.5], [(0.5, np.nan)], "> 0"),
    ([0.5], [(np.nan, 0.1)], r"\[0, 1\]"),
    ([0.5], [(0.5, 0.1), (0.5, 0.2)], "distinct"),
    ([1.5], [(0.5, 0.1)], r"t must lie in \[0, 1\]"),
    ([np.nan], [(0.5, 0.1)], r"t must lie in \[0, 1\]"),
    ([0.5], [0.1, 0.2], "pairs"),
])
def test_bad_input_is_refused(t, samples, match):
    with pytest.raises(ValueError, match=match):
        thickness_profile(t, samples)
