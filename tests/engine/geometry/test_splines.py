"""interpolate_chain / arc_length_parameter against closed forms and scipy's
CubicSpline (which the implementation does not use)."""

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from engine.geometry.splines import arc_length_parameter, interpolate_chain

RNG_SEED = 1234


def _chord_params(nodes, sps):
    """Parameter of every output sample: uniform steps within each chord."""
    h = np.linalg.norm(np.diff(nodes, axis=0), axis=1)
    u = np.concatenate([[0.0], np.cumsum(h)])
    params = np.concatenate([u[i] + h[i] * np.arange(sps) / sps for i in range(h.size)] + [[u[-1]]])
    return u, params


def _second_derivative_jumps(curve, nodes, sps):
    """|S''(knot-) - S''(knot+)| from one-sided second differences, per inner knot."""
    h = np.linalg.norm(np.diff(nodes, axis=0), axis=1) / sps
    jumps = []
    for k in range(1, nodes.shape[0] - 1):
        c = k * sps
        left = (curve[c] - 2 * curve[c - 1] + curve[c - 2]) / h[k - 1] ** 2
        right = (curve[c + 2] - 2 * curve[c + 1] + curve[c]) / h[k] ** 2
        jumps.append(np.linalg.norm(left - right))
    return np.array(jumps)


@pytest.fixture
def wiggly():
    rng = np.random.default_rng(RNG_SEED)
    return np.cumsum(rng.uniform(0.1, 1.0, size=(7, 3)), axis=0)


def test_passes_through_points(wiggly):
    sps = 10
    out = interpolate_chain(wiggly, smooth=True, samples_per_segment=sps)
    assert out.shape == ((wiggly.shape[0] - 1) * sps + 1, 3)
    np.testing.assert_array_equal(out[::sps], wiggly)


def test_natural_spline_matches_scipy(wiggly):
    sps = 12
    out = interpolate_chain(wiggly, smooth=True, samples_per_segment=sps)
    u, params = _chord_params(wiggly, sps)
    ref = CubicSpline(u, wiggly, bc_type="natural")(params)
    np.testing.assert_allclose(out, ref, atol=1e-12, rtol=0)


def test_natural_spline_is_c2_and_natural(wiggly):
    sps = 2000
    out = interpolate_chain(wiggly, smooth=True, samples_per_segment=sps)
    h = np.linalg.norm(np.diff(wiggly, axis=0), axis=1) / sps
    curvature = np.linalg.norm(np.diff(out, 2, axis=0), axis=1) / np.repeat(h, sps)[1:] ** 2
    jumps = _second_derivative_jumps(out, wiggly, sps)
    assert jumps.max() < 1e-2 * curvature.max()
    # natural ends: zero second derivative (up to the O(h) of the estimate)
    assert curvature[0] < 1e-2 * curvature.max()
    assert curvature[-1] < 1e-2 * curvature.max()


def test_c2_check_detects_a_c1_curve(wiggly):
    """The jump test has teeth: a C1 (Catmull-Rom Hermite) curve fails it."""
    sps = 2000
    nodes = wiggly
    u = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(nodes, axis=0), axis=1))])
    tang = np.gradient(nodes, u, axis=0)
    b = (np.arange(sps) / sps)[:, None]
    pieces = []
    for i in range(nodes.shape[0] - 1):
        hi = u[i + 1] - u[i]
        pieces.append((2 * b ** 3 - 3 * b ** 2 + 1) * nodes[i] + (b ** 3 - 2 * b ** 2 + b) * hi * tang[i]
                      + (-2 * b ** 3 + 3 * b ** 2) * nodes[i + 1] + (b ** 3 - b ** 2) * hi * tang[i + 1])
    hermite = np.concatenate(pieces + [nodes[-1:]])
    smooth = interpolate_chain(nodes, smooth=True, samples_per_segment=sps)
    assert _second_derivative_jumps(hermite, nodes, sps).max() > \
        100 * _second_derivative_jumps(smooth, nodes, sps).max()


def test_closed_loop_periodic_and_c2_at_seam():
    theta = np.linspace(0, 2 * np.pi, 6, endpoint=False)
    pts = np.stack([np.cos(theta), 0.7 * np.sin(theta), 0.2 * np.cos(2 * theta)], 1)
    sps = 1000
    out = interpolate_chain(pts, smooth=True, closed=True, samples_per_segment=sps)
    nodes = np.vstack([pts, pts[:1]])
    assert out.shape == (6 * sps + 1, 3)
    np.testing.assert_array_equal(out[0], out[-1])
    np.testing.assert_array_equal(out[::sps], nodes)
    u, params = _chord_params(nodes, sps)
    ref = CubicSpline(u, nodes, bc_type="periodic")(params)
    np.testing.assert_allclose(out, ref, atol=1e-12)
    # seam: compare one-sided derivatives across out[-1] == out[0]
    h_last = np.linalg.norm(nodes[-1] - nodes[-2]) / sps
    h_first = np.linalg.norm(nodes[1] - nodes[0]) / sps
    t_end = (out[-1] - out[-2]) / h_last
    t_start = (out[1] - out[0]) / h_first
    np.testing.assert_allclose(t_end, t_start, atol=5e-3)
    k_end = (out[-1] - 2 * out[-2] + out[-3]) / h_last ** 2
    k_start = (out[2] - 2 * out[1] + out[0]) / h_first ** 2
    np.testing.assert_allclose(k_end, k_start, atol=2e-2)


def test_closed_with_repeated_first_point_is_the_same_loop():
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.5]], float)
    a = interpolate_chain(pts, smooth=True, closed=True)
    b = interpolate_chain(np.vstack([pts, pts[:1]]), smooth=True, closed=True)
    np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("repeat_end", [True, False])
def test_period_curve_tiles_smoothly(repeat_end):
    t = np.array([1.0, 0.0, 0.0])
    pts = np.array([[0.0, 0.5, 0.5], [0.3, 0.7, 0.4], [0.6, 0.4, 0.6], [0.8, 0.55, 0.45]])
    if repeat_end:
        pts = np.vstack([pts, pts[:1] + t])
    sps = 1000
    out = interpolate_chain(pts, smooth=True, period=t, samples_per_segment=sps)
    np.testing.assert_allclose(out[-1], out[0] + t, atol=1e-15)
    nodes = np.vstack([pts[:4], pts[:1] + t])
    np.testing.assert_array_equal(out[::sps], nodes)
    # Reference: subtracting the linear drift t*u/U leaves a periodic spline.
    u, params = _chord_params(nodes, sps)
    drift = np.outer(u / u[-1], t)
    ref = CubicSpline(u, nodes - drift, bc_type="periodic")(params) + np.outer(params / u[-1], t)
    np.testing.assert_allclose(out, ref, atol=1e-12)
    h_last = np.linalg.norm(nodes[-1] - nodes[-2]) / sps
    h_first = np.linalg.norm(nodes[1] - nodes[0]) / sps
    np.testing.assert_allclose((out[-1] - out[-2]) / h_last, (out[1] - out[0]) / h_first, atol=5e-3)
    np.testing.assert_allclose((out[-1] - 2 * out[-2] + out[-3]) / h_last ** 2,
                               (out[2] - 2 * out[1] + out[0]) / h_first ** 2, atol=5e-2)


def test_period_with_one_point_per_period_is_straight():
    out = interpolate_chain([[0, 0.5, 0.5], [1, 0.5, 0.5]], smooth=True, period=[1, 0, 0])
    np.testing.assert_allclose(out[:, 1:], 0.5, atol=1e-15)
    assert np.all(np.diff(out[:, 0]) > 0)


def test_three_points_give_the_exact_parabola():
    pts = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [2.0, 0.0, 0.0]])
    out = interpolate_chain(pts, smooth=True, samples_per_segment=50)
    # symmetric chords: x is linear in the parameter, so y = 2x - x^2 exactly
    np.testing.assert_allclose(out[:, 1], 2 * out[:, 0] - out[:, 0] ** 2, atol=1e-12)
    np.testing.assert_allclose(np.diff(out[:, 0]), 2.0 / 100, atol=1e-12)
    assert np.all(out[:, 2] == 0)


def test_three_points_in_3d_form_one_quadratic():
    pts = np.array([[0.1, 0.2, 0.3], [0.9, 0.4, 0.1], [0.5, 1.3, 0.8]])
    sps = 40
    out = interpolate_chain(pts, smooth=True, samples_per_segment=sps)
    _, params = _chord_params(pts, sps)
    coef = np.polyfit(params, out, 2)
    np.testing.assert_allclose(np.polyval(coef[:, 0], params), out[:, 0], atol=1e-12)
    for axis in range(3):
        np.testing.assert_allclose(np.polyval(coef[:, axis], params), out[:, axis], atol=1e-12)
    normal = np.cross(pts[1] - pts[0], pts[2] - pts[0])
    np.testing.assert_allclose((out - pts[0]) @ normal, 0.0, atol=1e-12)


def test_two_points_give_a_straight_segment():
    out = interpolate_chain([[0, 0, 0], [1, 2, 3]], smooth=True, samples_per_segment=4)
    np.testing.assert_allclose(out, np.outer(np.linspace(0, 1, 5), [1, 2, 3]), atol=1e-15)


def test_straight_chains_are_returned_as_is():
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0]], float)
    out = interpolate_chain(pts, smooth=False)
    np.testing.assert_array_equal(out, pts)
    assert out is not pts
    closed = interpolate_chain(pts, smooth=False, closed=True)
    np.testing.assert_array_equal(closed, np.vstack([pts, pts[:1]]))
    per = interpolate_chain(pts, smooth=False, period=[0, 0, 1])
    np.testing.assert_array_equal(per, np.vstack([pts, [[0, 0, 1]]]))


def test_inputs_are_not_mutated(wiggly):
    before = wiggly.copy()
    interpolate_chain(wiggly, smooth=True, closed=True)
    np.testing.assert_array_equal(wiggly, before)


@pytest.mark.parametrize("kwargs, match", [
    (dict(points=[[0, 0, 0]], smooth=True), "at least 2"),
    (dict(points=[[0, 0], [1, 1]], smooth=True), r"shape \(n, 3\)"),
    (dict(points=[[0, 0, 0], [np.nan, 0, 0]], smooth=True), "finite"),
    (dict(points=[[0, 0, 0], [1, 0, 0]], smooth=True, closed=True), "at least 3"),
    (dict(points=[[0, 0, 0], [1, 0, 0], [1, 0, 0], [2, 1, 0]], smooth=True), "coincide"),
    (dict(points=[[0, 0, 0], [1, 0, 0], [2, 1, 0]], smooth=True, closed=True, period=[1, 0, 0]),
     "exclusive"),
    (dict(points=[[0, 0, 0], [1, 0, 0]], smooth=True, period=[0, 0, 0]), "non-zero"),
    (dict(points=[[0, 0, 0], [1, 0, 0]], smooth=True, samples_per_segment=0), "samples_per_segment"),
])
def test_bad_input_is_refused(kwargs, match):
    points = kwargs.pop("points")
    with pytest.raises(ValueError, match=match):
        interpolate_chain(points, **kwargs)


def test_arc_length_parameter():
    square = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 0]], float)
    np.testing.assert_allclose(arc_length_parameter(square), [0, 0.25, 0.5, 0.75, 1.0])
    uneven = np.array([[0, 0, 0], [3, 0, 0], [3, 4, 0]], float)
    np.testing.assert_allclose(arc_length_parameter(uneven), [0, 3 / 7, 1.0])
    with pytest.raises(ValueError, match="non-zero length"):
        arc_length_parameter([[1, 1, 1], [1, 1, 1]])
