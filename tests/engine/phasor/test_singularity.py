import math

import numpy as np
import pytest

from engine.phasor.align import align_phases
from engine.phasor.fields import PhasorFields, constant_fields
from engine.phasor.kernels import replace_kernels
from engine.phasor.noise import SliceGrid, kernel_constants, phasor_sample, slice_points
from engine.phasor.sampling import sample_kernels
from engine.phasor.singularity import (singularity_energy, singularity_measure, singularity_report,
                                       singularity_slice, singularity_slice_fd)


def _rotating_fields(size, height=1.0, turn=math.pi / 2, n=16):
    """D turns about z by ``turn`` across x in [0, size]; F = 1 cycle/mm, Gamma = 0."""
    shape = (1, n, n)
    x = (np.arange(n) + 0.5) / n * size
    d = np.zeros(shape + (3,))
    d[..., 0], d[..., 1] = np.cos(turn * x / size), np.sin(turn * x / size)
    return PhasorFields(d, np.ones(shape), np.zeros(shape), (0, 0, 0), (size, size, height))


def _phased(k, f):
    """All kernels one global wave: f_j = f, phi_j = 2 pi f d . x_j (d_v = +y, d_w = -z)."""
    return replace_kernels(k, frequency=np.full(k.n, f), phase_v=2 * np.pi * f * k.positions[:, 1],
                           phase_w=-2 * np.pi * f * k.positions[:, 2])


def test_a_perfectly_phased_wave_has_s_equal_to_its_relative_frequency_error():
    F = 1.0
    fields = constant_fields((0, 0, 0), (12, 12, 6), (1, 1, 1), direction=(1, 0, 0), frequency=F)
    k = sample_kernels(fields, rng=0)
    pts = np.random.default_rng(1).uniform((2, 2, 2), (10, 10, 4), size=(40, 3))
    for f in (1.0, 1.1):
        s_v, s_w = singularity_measure(_phased(k, f), pts, fields=fields)
        np.testing.assert_allclose(np.concatenate([s_v, s_w]), abs(f - F) / F, atol=1e-9)
        # in a z-slice the w wave runs across the plane: no in-plane deviation
        s_v, s_w = singularity_measure(_phased(k, f), pts, fields=fields, normal=(0, 0, 1))
        np.testing.assert_allclose(s_v, abs(f - F) / F, atol=1e-9)
        np.testing.assert_allclose(s_w, 0.0, atol=1e-9)
    s_v, s_w = singularity_measure(_phased(k, F), pts, fields=fields, filtered=True)
    np.testing.assert_allclose(np.concatenate([s_v, s_w]), 0.0, atol=1e-9)


@pytest.mark.parametrize("filtered", [False, True])
def test_gradient_of_the_kernel_sum_matches_central_differences(filtered):
    rng = np.random.default_rng(2)
    fields = constant_fields((0, 0, 0), (10, 10, 6), (1, 1, 1), direction=(0.6, 0.0, 0.8), spread=0.4)
    k = sample_kernels(fields, rng=2)
    k = k.with_phases(rng.uniform(-3, 3, k.n), rng.uniform(-3, 3, k.n))
    pts = rng.uniform((2, 2, 1), (8, 8, 5), size=(30, 3))
    opts = {"fields": fields, "filtered": filtered, "attenuation": 0.6}
    s = phasor_sample(k, pts, gradient=True, **opts)
    h = 1e-5
    for axis in range(3):
        step = np.zeros(3)
        step[axis] = h
        plus, minus = phasor_sample(k, pts + step, **opts), phasor_sample(k, pts - step, **opts)
        for grad, gp, gm in ((s.grad_v, plus.g_v, minus.g_v), (s.grad_w, plus.g_w, minus.g_w)):
            np.testing.assert_allclose(grad[:, axis], (gp - gm) / (2 * h), rtol=0, atol=1e-6 * np.abs(grad).max())


def _clear_of_cutoffs(points, kernels, cutoff, h):
    """Pixels whose FD stencil (+-h) cannot straddle a kernel's truncation sphere.

    Kernels stop at amplitude exp(-pi), so G jumps by a few per cent of one
    kernel on every truncation sphere; a finite difference across one sees
    the jump, the analytic gradient does not.
    """
    centre = points.mean(axis=0)
    reach = cutoff + np.max(np.linalg.norm(points - centre, axis=1)) + h
    near = kernels.positions[np.linalg.norm(kernels.positions - centre, axis=1) < reach]
    clear = np.ones(len(points), dtype=bool)
    for j in range(0, len(near), 100):
        dist = np.linalg.norm(points[:, None, :] - near[None, j:j + 100], axis=-1)
        clear &= ~np.any(np.abs(dist - cutoff) <= h, axis=1)
    return clear


def _max_smooth_difference(s_an, s_fd, clear, limit=1.0):
    """max |S_fd - S_an| where S < limit over the whole 5 x 5 neighbourhood."""
    h, w = s_an.shape
    pad = np.pad(s_an, 2, constant_values=np.inf)
    worst = np.max([pad[i:i + h, j:j + w] for i in range(5) for j in range(5)], axis=0)
    smooth = (worst < limit) & np.isfinite(s_fd) & clear.reshape(h, w)
    assert smooth.sum() > 1000
    return np.abs(s_fd - s_an)[smooth].max()


@pytest.mark.parametrize("filtered", [False, True])
def test_analytic_s_equals_finite_differences_of_the_phase_image_away_from_singularities(filtered):
    if filtered:
        # the FD image is of the filtered field with q(x) per pixel; it equals
        # the analytic S (q held at x) when the fields are constant
        fields = constant_fields((0, 0, 0), (24, 24, 1), (1, 1, 1), direction=(0.8, 0.6, 0.0), spread=0.3)
        opts = {"filtered": True, "attenuation": 0.5}
    else:
        fields, opts = _rotating_fields(24.0), {}
    k = sample_kernels(fields, rng=3)  # raw phases: plenty of singularities
    px = 0.0125
    plane = SliceGrid.axis_aligned("z", 0.5, px, ((9, 10.5), (11, 12.5)))
    clear = _clear_of_cutoffs(slice_points(plane), k, kernel_constants(k, **{"filtered": filtered}).cutoff, px)
    s_an = singularity_slice(k, plane, fields=fields, **opts)
    s_fd = singularity_slice_fd(k, plane, fields=fields, **opts)
    for a, f in zip(s_an, s_fd):
        assert _max_smooth_difference(a, f, clear) < 1e-3


def test_zeros_of_g_are_singular_and_energy_counts_the_fraction_above_q():
    fields = constant_fields((0, 0, 0), (10, 10, 10), (1, 1, 1))
    k = sample_kernels(fields, rng=0)
    s_v, s_w = singularity_measure(k, [[100.0, 100.0, 100.0]], fields=fields)  # no kernel in reach
    assert np.isinf(s_v[0]) and np.isinf(s_w[0])
    assert singularity_energy([np.inf, 0.5, np.nan, 2.0, 3.0]) == pytest.approx(0.5)
    assert singularity_energy([0.5, 1.5], q=1.0) == pytest.approx(0.5)
    with pytest.raises(ValueError, match="measure"):
        singularity_energy([np.nan])


def test_alignment_removes_most_singularities_and_the_filter_more():
    # The paper's kind of example (its fig. 11): D turns by 90 degrees about z
    # across a 64 mm square, F = 1 cycle/mm, Gamma = 0; F_S(2) of p_v or p_w
    # on a z-slice, 0.25 mm pixels, averaged over two seeds.
    size = 64.0
    fields = _rotating_fields(size)
    plane = SliceGrid.axis_aligned("z", 0.5, 0.25, ((0, size), (0, size)))
    energy = np.zeros(3)
    for seed in (0, 1):
        raw = sample_kernels(fields, rng=seed)
        aligned = align_phases(raw)
        energy += [singularity_report(raw, plane, fields=fields)["either"],
                   singularity_report(aligned, plane, fields=fields)["either"],
                   singularity_report(aligned, plane, fields=fields, filtered=True)["either"]]
    energy /= 2
    print(f"\nF_S(2): raw {energy[0]:.5f}, aligned {energy[1]:.5f} (-{1 - energy[1] / energy[0]:.0%}), "
          f"aligned + filtered {energy[2]:.5f} (-{1 - energy[2] / energy[0]:.0%})")
    assert energy[1] <= 0.2 * energy[0]
    assert energy[2] < energy[1]
