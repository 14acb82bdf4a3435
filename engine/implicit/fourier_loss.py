"""Fourier losses for reconstruction (paper 004, supplementary eqs. 36 and 39).

Parameter fitting (section 6.1) compares a candidate SDF with an exemplar
in the frequency domain: both are sampled on the same regular grid, their
discrete Fourier transforms F = DFT(pred), G = DFT(target) are split into
amplitudes |F|, |G| and phases arg F, arg G, and the loss is

    L = log(mean((|F| - |G|)^2) + eps) + log(mean(wrap(arg F - arg G)^2) + eps)

(eq. 36; the formula was lost in extraction, this is the form the prose
describes: the log of the MSE of the amplitude spectra plus the log of the
MSE of the phase spectra, eps a small positive constant).  Choices made here:

* the transform is `numpy.fft.rfftn` with ``norm="ortho"`` (real input, so
  the half spectrum holds every coefficient once; orthonormal scaling makes
  amplitudes independent of the grid size, sum |F|^2 = sum f^2);
* the phase difference is wrapped, ``wrap(d) = angle(exp(i d))`` in
  (-pi, pi], so two phases 2 pi apart count as equal;
* a coefficient whose amplitude is at round-off level (below
  ``PHASE_FLOOR`` times the largest amplitude of its spectrum) has no
  meaningful phase and is given phase 0, so the phase term is a
  deterministic function of the fields rather than of FFT rounding.

The amplitude term is invariant to circular shifts of the samples; the phase
term is not: together they see both the spectrum and the placement.

`image_loss` is eq. 39 for analysis by synthesis: the log MSE of the 2D DFT
amplitudes of two images, with an optional SSIM term.
"""

from __future__ import annotations

import numpy as np

__all__ = ["fourier_loss", "amplitude_phase", "image_loss", "PHASE_FLOOR"]

PHASE_FLOOR = 1e-9   # relative amplitude below which a coefficient's phase is taken as 0


def _grids(pred, target, what: str = "sample grid"):
    a = np.asarray(pred, dtype=np.float64)
    b = np.asarray(target, dtype=np.float64)
    if a.shape != b.shape:
        raise ValueError(f"pred and target must have the same {what} shape, got {a.shape} and {b.shape}")
    if a.ndim not in (1, 2, 3) or a.size < 2:
        raise ValueError(f"a {what} must be a 1D, 2D or 3D array of at least 2 samples, got shape {a.shape}")
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise ValueError("pred and target must be finite (no NaN / infinite samples)")
    return a, b


def _check_eps(eps) -> float:
    e = float(eps)
    if not (np.isfinite(e) and e > 0):
        raise ValueError(f"eps must be a finite number > 0, got {eps!r}")
    return e


def amplitude_phase(samples: np.ndarray, axes=None) -> tuple[np.ndarray, np.ndarray]:
    """Amplitude and phase spectra of real `samples` (any shape; over `axes`, default all).

    Returns (amplitude, phase), float64 arrays of the rfftn shape; phase in
    (-pi, pi], 0 where the amplitude is below ``PHASE_FLOOR * max amplitude``."""
    spec = np.fft.rfftn(np.asarray(samples, dtype=np.float64), axes=axes, norm="ortho")
    amp = np.abs(spec)
    top = float(amp.max()) if amp.size else 0.0
    spec = np.where(amp > PHASE_FLOOR * top, spec, 0.0)
    return amp, np.angle(spec)


def fourier_loss(pred, target, eps: float = 1e-8) -> float:
    """Eq. 36: log MSE of the amplitude spectra plus log MSE of the wrapped phase differences.

    Parameters
    ----------
    pred, target : array_like, float, the same 1D, 2D or 3D grid shape
        Samples of the candidate and the exemplar on the same grid (e.g. SDF
        values in mm; `Exemplar.grid()`).
    eps : float > 0
        Added inside both logarithms; identical inputs give ``2 log(eps)``.

    Returns
    -------
    float, in [2 log(eps), inf).

    Raises
    ------
    ValueError
        If the shapes differ, the grid is not 1D-3D with >= 2 samples, a
        sample is not finite, or eps <= 0.
    """
    e = _check_eps(eps)
    a, b = _grids(pred, target)
    amp_a, ph_a = amplitude_phase(a)
    amp_b, ph_b = amplitude_phase(b)
    d_amp = float(np.mean((amp_a - amp_b) ** 2))
    d_ph = float(np.mean(np.angle(np.exp(1j * (ph_a - ph_b))) ** 2))
    return float(np.log(d_amp + e) + np.log(d_ph + e))


def image_loss(img, target, *, eps: float = 1e-8, ssim_weight: float = 0.0,
               data_range: float | None = None) -> float:
    """Eq. 39: log MSE of the 2D DFT amplitudes of two images, plus ``ssim_weight (1 - SSIM)``.

    Parameters
    ----------
    img, target : (h, w) or (h, w, c) float arrays of the same shape (a render and the
        exemplar image; channels transformed separately over the two image axes).
    eps : float > 0, inside the logarithm.
    ssim_weight : float >= 0; with > 0 adds ``ssim_weight * (1 - SSIM)``
        (`skimage.metrics.structural_similarity`, channel axis -1 for colour).
    data_range : float > 0 or None, SSIM's value range (None: the target's max - min,
        or 1 for a constant target).

    Returns
    -------
    float.

    Raises
    ------
    ValueError
        On a shape mismatch, an image that is not (h, w) / (h, w, c) with h, w >= 7
        when SSIM is used (>= 2 otherwise), non-finite pixels, eps <= 0, a negative
        ssim_weight or data_range <= 0.
    """
    e = _check_eps(eps)
    a = np.asarray(img, dtype=np.float64)
    b = np.asarray(target, dtype=np.float64)
    if a.shape != b.shape:
        raise ValueError(f"img and target must have the same shape, got {a.shape} and {b.shape}")
    if a.ndim not in (2, 3) or min(a.shape[:2]) < 2:
        raise ValueError(f"an image must be (h, w) or (h, w, c) with h, w >= 2, got shape {a.shape}")
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise ValueError("img and target must be finite (no NaN / infinite pixels)")
    w = float(ssim_weight)
    if not (np.isfinite(w) and w >= 0):
        raise ValueError(f"ssim_weight must be a finite number >= 0, got {ssim_weight!r}")
    amp_a = np.abs(np.fft.rfftn(a, axes=(0, 1), norm="ortho"))
    amp_b = np.abs(np.fft.rfftn(b, axes=(0, 1), norm="ortho"))
    loss = float(np.log(np.mean((amp_a - amp_b) ** 2) + e))
    if w == 0.0:
        return loss
    if min(a.shape[:2]) < 7:
        raise ValueError(f"SSIM needs images of at least 7 x 7 pixels, got shape {a.shape}")
    if data_range is None:
        span = float(b.max() - b.min())
        data_range = span if span > 0 else 1.0
    elif not (np.isfinite(float(data_range)) and float(data_range) > 0):
        raise ValueError(f"data_range must be a finite number > 0, got {data_range!r}")
    from skimage.metrics import structural_similarity
    ssim = structural_similarity(a, b, data_range=float(data_range),
                                 channel_axis=-1 if a.ndim == 3 else None)
    return loss + w * (1.0 - float(ssim))
