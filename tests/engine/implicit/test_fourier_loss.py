"""Fourier losses (eqs. 36, 39) against closed forms and a brute-force DFT."""

import math

import numpy as np
import pytest

from engine.implicit.fourier_loss import amplitude_phase, fourier_loss, image_loss

EPS = 1e-8


def _slow_rdft(x):
    """The orthonormal half-spectrum DFT of a 1D real signal by the defining sum."""
    n = len(x)
    k = np.arange(n // 2 + 1)[:, None]
    j = np.arange(n)[None, :]
    return (np.exp(-2j * np.pi * k * j / n) * x[None, :]).sum(axis=1) / math.sqrt(n)


@pytest.mark.parametrize("shape", [(17,), (8, 9), (6, 5, 7)])
def test_identical_inputs_give_twice_log_eps(shape):
    a = np.random.default_rng(3).normal(size=shape)
    assert fourier_loss(a, a.copy()) == pytest.approx(2 * math.log(EPS), abs=1e-9)
    assert fourier_loss(a, a, eps=1e-4) == pytest.approx(2 * math.log(1e-4), abs=1e-9)


def test_spectra_match_the_defining_sum():
    x = np.random.default_rng(1).normal(size=21)
    amp, ph = amplitude_phase(x)
    ref = _slow_rdft(x)
    np.testing.assert_allclose(amp, np.abs(ref), atol=1e-12)
    np.testing.assert_allclose(np.exp(1j * ph), np.exp(1j * np.angle(ref)), atol=1e-9)


@pytest.mark.parametrize("shift", [1, 5, 11])
def test_amplitude_is_shift_invariant_phase_is_not(shift):
    a = np.random.default_rng(7).normal(size=(10, 12, 8))
    b = np.roll(a, shift, axis=1)
    amp_a, _ = amplitude_phase(a)
    amp_b, _ = amplitude_phase(b)
    np.testing.assert_allclose(amp_a, amp_b, atol=1e-12)
    loss = fourier_loss(b, a)
    # amplitude term at its floor, the phase term well above it
    assert math.log(EPS) + math.log(1e-3) < loss
    assert loss - math.log(EPS) > math.log(EPS) + 10


@pytest.mark.parametrize("k, s", [(5, 3), (5, 10), (3, 7), (9, 2)])
def test_pure_sinusoid_against_its_shift_closed_form(k, s):
    n = 64
    j = np.arange(n)
    a = np.cos(2 * np.pi * k * j / n)
    b = np.cos(2 * np.pi * k * (j - s) / n)
    m = n // 2 + 1
    d = 2 * np.pi * k * s / n
    wrapped = (d + np.pi) % (2 * np.pi) - np.pi       # one coefficient's phase differs
    expect = math.log(EPS) + math.log(wrapped ** 2 / m + EPS)
    assert fourier_loss(b, a) == pytest.approx(expect, rel=1e-9)


@pytest.mark.parametrize("scale", [0.5, 1.7, 3.0])
def test_scaled_sinusoid_amplitude_closed_form(scale):
    n, k = 48, 4
    j = np.arange(n)
    a = np.sin(2 * np.pi * k * j / n)
    m = n // 2 + 1
    # orthonormal DFT: the one coefficient has amplitude sqrt(n) / 2, same phase
    expect = math.log(n * (scale - 1) ** 2 / (4 * m) + EPS) + math.log(EPS)
    assert fourier_loss(scale * a, a) == pytest.approx(expect, rel=1e-9)


def test_phase_difference_wraps():
    # phases pi - 0.1 and -pi + 0.1 differ by 0.2 after wrapping, not by 2 pi - 0.2
    n = 32
    j = np.arange(n)
    a = np.cos(2 * np.pi * j / n + (np.pi - 0.1))
    b = np.cos(2 * np.pi * j / n - (np.pi - 0.1))
    expect = math.log(EPS) + math.log(0.2 ** 2 / (n // 2 + 1) + EPS)
    assert fourier_loss(a, b) == pytest.approx(expect, rel=1e-9)


def test_bad_inputs_refused():
    a = np.zeros((4, 5, 6))
    with pytest.raises(ValueError, match="same sample grid shape"):
        fourier_loss(a, np.zeros((4, 5, 7)))
    with pytest.raises(ValueError, match="1D, 2D or 3D"):
        fourier_loss(np.zeros((2, 2, 2, 2)), np.zeros((2, 2, 2, 2)))
    with pytest.raises(ValueError, match="eps"):
        fourier_loss(a, a, eps=0.0)
    b = a.copy()
    b[1, 1, 1] = np.nan
    with pytest.raises(ValueError, match="finite"):
        fourier_loss(a, b)


def test_image_loss_amplitude_and_ssim():
    rng = np.random.default_rng(5)
    img = rng.uniform(size=(32, 40))
    assert image_loss(img, img) == pytest.approx(math.log(EPS), abs=1e-9)
    # amplitude-only: a circular shift of the image costs nothing
    assert image_loss(np.roll(img, (3, 7), axis=(0, 1)), img) == pytest.approx(math.log(EPS), abs=1e-6)
    # closed form: a constant c added changes only the DC coefficient by c sqrt(h w)
    c = 0.3
    m = 32 * (40 // 2 + 1)
    expect = math.log(c * c * 32 * 40 / m + EPS)
    assert image_loss(img + c, img) == pytest.approx(expect, rel=1e-9)
    # the SSIM term: zero for identical images, linear in its weight, positive otherwise
    assert image_loss(img, img, ssim_weight=2.0) == pytest.approx(math.log(EPS), abs=1e-9)
    other = rng.uniform(size=img.shape)
    base = image_loss(other, img)
    one = image_loss(other, img, ssim_weight=1.0) - base
    two = image_loss(other, img, ssim_weight=2.0) - base
    assert one > 0.5 and two == pytest.approx(2 * one)
    colour = rng.uniform(size=(16, 16, 3))
    assert image_loss(colour, colour, ssim_weight=1.0) == pytest.approx(math.log(EPS), abs=1e-9)


def test_image_loss_refuses_bad_input():
    with pytest.raises(ValueError, match="same shape"):
        image_loss(np.zeros((8, 8)), np.zeros((8, 9)))
    with pytest.raises(ValueError, match="ssim_weight"):
        image_loss(np.zeros((8, 8)), np.zeros((8, 8)), ssim_weight=-1)
    with pytest.raises(ValueError, match="7 x 7"):
        image_loss(np.zeros((5, 5)), np.ones((5, 5)), ssim_weight=1)
