import math

import numpy as np
import pytest

from engine.progress import Cancelled
from engine.phasor.align import align_phases
from engine.phasor.fields import PhasorFields, constant_fields
from engine.phasor.kernels import PhasorKernels
from engine.phasor.noise import (SliceGrid, diamond_mask, phasor_complex, phasor_complex_reference,
                                 phasor_slice, sawtooth, slice_points)
from engine.phasor.sampling import sample_kernels


def _random_setup(seed=0):
    rng = np.random.default_rng(seed)
    lo, hi = np.zeros(3), np.array([14.0, 12.0, 7.0])
    shape = (3, 5, 6)
    d = rng.normal(size=shape + (3,))
    d /= np.linalg.norm(d, axis=-1)[..., None]
    fields = PhasorFields(d, rng.uniform(0.8, 1.6, shape), rng.uniform(0.0, 0.6, shape), lo, hi)
    k = sample_kernels(fields, rng=seed)
    k = k.with_phases(rng.uniform(-np.pi, np.pi, k.n), rng.uniform(-np.pi, np.pi, k.n))
    pts = rng.uniform(lo - 4.0, hi + 4.0, size=(250, 3))
    return fields, k, pts, rng


@pytest.mark.parametrize("options", [{}, {"filtered": True}, {"filtered": True, "attenuation": 0.4},
                                     {"filtered": True, "filter_scale": 1.3, "attenuation": "grid"},
                                     {"filtered": True, "attenuation": "per point"}])
def test_cell_lookup_equals_brute_force_over_all_kernels(options):
    fields, k, pts, rng = _random_setup(1)
    shape = {"grid": fields.shape, "per point": (len(pts),)}.get(options.get("attenuation"))
    if shape is not None:
        options = dict(options, attenuation=rng.uniform(0, 1, shape))
    fast = phasor_complex(k, pts, fields=fields, **options)
    slow = phasor_complex_reference(k, pts, fields=fields, **options)
    for a, b in zip(fast, slow):
        assert np.abs(b).max() > 0.5
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)


def test_filtered_kernels_are_the_gaussian_convolution_of_the_local_phasor_field():
    # Three hand-placed kernels of different frequency and direction around x;
    # (g * phi_x)(0) by brute-force quadrature over delta must equal the
    # closed form times the dropped constant (pi / (a + b))^(3/2).
    F = 1.0
    fields = constant_fields((-10, -10, -10), (10, 10, 10), (1, 1, 1), direction=(1, 0, 0), frequency=F)
    radius = 2.0
    pos = np.array([[0.4, -0.3, 0.2], [-0.6, 0.5, -0.1], [0.2, 0.1, 0.7]])
    freq = np.array([1.0, 1.15, 0.9])
    dv = np.array([[0, 1, 0], [0.3, 0.95, 0.1], [-0.2, 0.97, 0.0]])
    dv /= np.linalg.norm(dv, axis=1)[:, None]
    dw = np.array([[0, 0, -1], [0.1, 0.2, -0.97], [0.0, -0.3, -0.95]])
    dw /= np.linalg.norm(dw, axis=1)[:, None]
    phase_v, phase_w = np.array([0.3, -1.2, 2.0]), np.array([1.0, 0.1, -2.5])
    k = PhasorKernels(origin=np.full(3, -radius), radius=radius, grid=np.array([2, 2, 2]),
                      cell_start=np.array([0, 0, 0, 0, 0, 0, 0, 0, 3]), positions=pos, frequency=freq,
                      direction_v=dv, direction_w=dw, phase_v=phase_v, phase_w=phase_w,
                      spread_u=np.zeros(3))
    x = np.array([0.05, -0.1, 0.15])
    b = k.bandwidth
    a = b / 2.0 ** 2
    h = 0.2  # trapezoid on a Gaussian: error ~ exp(-pi^2 / ((a + b) h^2)), negligible
    axis = np.arange(-6.0, 6.0 + h / 2, h)
    delta = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1).reshape(-1, 3)
    closed = phasor_complex(k, x[None], fields=fields, filtered=True)
    for noise, (d, phase, q) in enumerate(((dv, phase_v, F * np.array([0, 1.0, 0])),
                                           (dw, phase_w, F * np.array([0, 0, -1.0])))):
        field = np.zeros(len(delta), np.complex128)
        for j in range(3):
            r = x + delta - pos[j]
            field += np.exp(-b * np.sum(r * r, axis=1)) * np.exp(1j * (2 * np.pi * freq[j] * (r @ d[j]) + phase[j]))
        local = field * np.exp(-2j * np.pi * (delta @ q))  # phi_x(delta)
        integral = np.sum(np.exp(-a * np.sum(delta * delta, axis=1)) * local) * h ** 3
        want = integral / (np.pi / (a + b)) ** 1.5
        assert abs(closed[noise][0] - want) < 1e-6 * abs(want)


def _peak_frequency(img, pixel, pad=1024):
    """(ku, kv) cycles/mm of the strongest Fourier component of a complex image."""
    spec = np.abs(np.fft.fft2(img, s=(pad, pad)))
    i, j = np.unravel_index(np.argmax(spec), spec.shape)
    f = np.fft.fftfreq(pad, pixel)
    return f[j], f[i]


@pytest.mark.parametrize("degrees", [0.0, 30.0])
def test_constant_fields_give_straight_stripes_of_period_one_over_f_along_v(degrees):
    # Aligned kernels (raw noise passes too, but with ~4 % / ~4 degree errors).
    t = math.radians(degrees)
    F, L = 1.0, 40.0
    fields = constant_fields((0, 0, 0), (L, L, 4), (1, 1, 1), direction=(math.cos(t), math.sin(t), 0), frequency=F)
    k = align_phases(sample_kernels(fields, rng=0))
    plane = SliceGrid.axis_aligned("z", 2.0, 0.25, ((0, L), (0, L)))
    p_v, _ = phasor_slice(k, plane)
    ku, kv = _peak_frequency(np.exp(2j * np.pi * p_v), 0.25)
    assert 1.0 / math.hypot(ku, kv) == pytest.approx(1.0 / F, rel=0.05)
    v = np.array([-math.sin(t), math.cos(t)])  # z x D in the slice plane
    angle = math.degrees(math.atan2(ku * v[1] - kv * v[0], ku * v[0] + kv * v[1]))
    assert abs(angle) < 5.0


def test_diamonds_tile_the_plane_normal_to_d_with_period_one_over_f():
    F, L = 1.0, 40.0
    fields = constant_fields((0, 0, 0), (4, L, L), (1, 1, 1), direction=(1, 0, 0), frequency=F)
    k = align_phases(sample_kernels(fields, rng=1))
    plane = SliceGrid.axis_aligned("x", 2.0, 0.25, ((0, L), (0, L)))  # columns along y, rows along z
    p_v, p_w = phasor_slice(k, plane)
    ku, kv = _peak_frequency(np.exp(2j * np.pi * p_v), 0.25)
    assert ku == pytest.approx(F, rel=0.05) and abs(kv) < 0.05 * F      # v = z x x = +y
    ku, kv = _peak_frequency(np.exp(2j * np.pi * p_w), 0.25)
    assert kv == pytest.approx(-F, rel=0.05) and abs(ku) < 0.05 * F     # w = v x D = -z
    assert diamond_mask(p_v, p_w).mean() == pytest.approx(0.5, abs=0.03)


def test_sawtooth_and_diamond_mask_follow_the_paper():
    p = sawtooth(np.exp(2j * np.pi * np.array([0.0, 0.25, 0.5, 0.75, -1e-18])) * 3.0)
    np.testing.assert_allclose(p, [0.0, 0.25, 0.5, 0.75, 0.0], atol=1e-15)
    assert np.all((p >= 0) & (p < 1)) and sawtooth(0j) == 0.0
    pv = np.array([0.5, 0.0, 0.5, 0.3, 0.74])
    pw = np.array([0.5, 0.0, 0.0, 0.3, 0.5])  # [2] lies on the boundary: outside
    np.testing.assert_array_equal(diamond_mask(pv, pw), [True, False, False, True, True])


def test_slice_grids_put_pixel_centres_where_the_convention_says():
    g = SliceGrid.axis_aligned("z", 1.5, 0.5, ((2.0, 4.0), (-1.0, 0.0)))
    assert g.shape == (2, 4)
    pts = g.points()
    np.testing.assert_allclose(pts[0, 0], [2.25, -0.75, 1.5])
    np.testing.assert_allclose(pts[1, 3], [3.75, -0.25, 1.5])
    np.testing.assert_allclose(g.normal, [0, 0, 1])
    t = SliceGrid.through((1, 1, 1), (0, 1, 1), (1, 0, 0), (2.0 * math.sqrt(2), 3.0), (4, 3))
    np.testing.assert_allclose(t.points()[0, 0], [1.5, 1.25, 1.25])
    assert slice_points(t).shape == (12, 3)
    with pytest.raises(ValueError, match="orthogonal"):
        SliceGrid.through((0, 0, 0), (1, 0, 0), (1, 1, 0), (1, 1), (2, 2))


def test_same_seed_same_slice_bytes_and_progress_can_cancel():
    fields, k, pts, _ = _random_setup(2)
    a = phasor_complex(k, pts, fields=fields, filtered=True)
    b = phasor_complex(k, pts, fields=fields, filtered=True)
    assert a[0].tobytes() == b[0].tobytes() and a[1].tobytes() == b[1].tobytes()
    seen = []
    phasor_complex(k, pts, progress=lambda d, t: seen.append((d, t)) or True)
    assert seen[-1] == (len(pts), len(pts))
    with pytest.raises(Cancelled):
        phasor_complex(k, pts, progress=lambda d, t: d == 0)


def test_filtered_noise_needs_the_fields_and_sane_options():
    _, k, pts, _ = _random_setup(3)
    with pytest.raises(ValueError, match="fields"):
        phasor_complex(k, pts, filtered=True)
    fields = constant_fields((0, 0, 0), (1, 1, 1), (2, 2, 2))
    with pytest.raises(ValueError, match="attenuation"):
        phasor_complex(k, pts, fields=fields, filtered=True, attenuation=1.5)
    with pytest.raises(ValueError, match="filter_scale"):
        phasor_complex(k, pts, fields=fields, filtered=True, filter_scale=0.0)
    with pytest.raises(ValueError, match="points"):
        phasor_complex(k, np.zeros((4, 2)))


def test_a_valid_attenuation_grid_never_fails_on_interpolation_round_off():
    from engine.phasor.fields import constant_fields
    from engine.phasor.noise import attenuation_at

    fields = constant_fields([0, 0, 0], [3, 3, 3], (3, 3, 3))
    grid = np.ones(fields.shape)
    grid[1, 1, 1] = 0.3
    pts = np.random.default_rng(3).uniform(0, 3, size=(5000, 3))
    a = attenuation_at(grid, fields, pts)
    assert a.min() >= 0.0 and a.max() <= 1.0
    bad = grid.copy()
    bad[0, 0, 0] = 1.5
    with pytest.raises(ValueError, match=r"\[0, 1\]"):
        attenuation_at(bad, fields, pts)
