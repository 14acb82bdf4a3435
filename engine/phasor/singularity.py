"""Singularity measure S and singularity energy F_S (Tricard et al. 2021, 4.2.2).

The local phasor field around x is ``phi_x(delta) = G(x + delta) / omega_x(x + delta)``
with the carrier ``omega_x(y) = exp(2 pi i q . (y - x))``, ``q = F(x) e(x)``.
So at delta = 0

    grad Arg phi_x = grad Arg G(x) - 2 pi q,     S(x) = |grad Arg phi_x| / (2 pi F(x))     (eq. 9)

and ``grad Arg G = Im(conj(G) grad G) / |G|^2``, with grad G summed
analytically over the kernels (:func:`engine.phasor.noise.phasor_sample`).
For the filtered noise the same holds for ``(g * phi_x)(delta)``, the
filtered local field, whose kernels are those of eq. 14 with q(x), A(x)
held at x.  For slice images the gradient is projected into the slice plane.
Where |G| is (nearly) zero Arg is undefined and S = inf.

:func:`singularity_fd` is the paper's own route: finite differences of an
image of Arg G minus the carrier, each difference wrapped into (-pi, pi].

``F_S(q) = |{S > q}| / |Omega|`` (eq. 10), q = 2 in the paper.
"""

from __future__ import annotations

import numpy as np

from .fields import PhasorFields
from .kernels import PhasorKernels
from .noise import (DEFAULT_FILTER_SCALE, TWO_PI, local_oscillators, phasor_complex, phasor_sample,
                    slice_points)

THRESHOLD = 2.0
# |G| below this fraction of the summed kernel magnitudes counts as a zero of G.
ZERO_RELATIVE = 1e-9


def _phase_gradient(g, grad) -> np.ndarray:
    """grad Arg G = Im(conj(G) grad G) / |G|^2, (n, 3); NaN where G = 0."""
    mag2 = np.abs(g) ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.imag(np.conj(g)[:, None] * grad) / mag2[:, None]


def singularity_measure(kernels: PhasorKernels, points, *, fields: PhasorFields, normal=None,
                        filtered=False, filter_scale=DEFAULT_FILTER_SCALE, attenuation=None,
                        progress=None) -> tuple:
    """Analytic S(x) of both noises at ``points`` (n, 3) mm.

    Parameters
    ----------
    kernels, fields : the noise and its control fields (F, D give q(x))
    normal : (3,) or None; when given, the gradient is projected into the
        plane with this normal (S of a slice image)
    filtered, filter_scale, attenuation, progress : as in
        :func:`engine.phasor.noise.phasor_complex`

    Returns
    -------
    S_v, S_w : (n,) float64, dimensionless; inf where G is ~0
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    s = phasor_sample(kernels, pts, fields=fields, filtered=filtered, filter_scale=filter_scale,
                      attenuation=attenuation, gradient=True, progress=progress)
    f, e_v, e_w = local_oscillators(fields, pts)
    if normal is not None:
        n = np.asarray(normal, dtype=np.float64)
        n = n / np.linalg.norm(n)
    out = []
    for g, grad, env, e in ((s.g_v, s.grad_v, s.envelope_v, e_v), (s.g_w, s.grad_w, s.envelope_w, e_w)):
        dev = _phase_gradient(g, grad) - TWO_PI * f[:, None] * e
        if normal is not None:
            dev -= (dev @ n)[:, None] * n
        measure = np.linalg.norm(dev, axis=1) / (TWO_PI * f)
        zero = ~(np.abs(g) > ZERO_RELATIVE * env)
        out.append(np.where(zero | ~np.isfinite(measure), np.inf, measure))
    return tuple(out)


def singularity_slice(kernels: PhasorKernels, plane, *, fields: PhasorFields, **options) -> tuple:
    """Analytic S images ``(S_v, S_w)``, (H, W), of a slice (in-plane gradient).

    ``plane`` is a :class:`engine.phasor.noise.SliceGrid` (or anything with
    ``points()``, ``pixel_u``, ``pixel_v``, ``shape``); ``options`` as in
    :func:`singularity_measure`.
    """
    normal = np.cross(np.asarray(plane.pixel_u, float), np.asarray(plane.pixel_v, float))
    s_v, s_w = singularity_measure(kernels, slice_points(plane), fields=fields, normal=normal, **options)
    return s_v.reshape(plane.shape), s_w.reshape(plane.shape)


def _wrap(a):
    return np.angle(np.exp(1j * a))


def singularity_fd(phase, carrier, frequency, pixel_u, pixel_v) -> np.ndarray:
    """S from finite differences of an image of Arg G (the paper's analysis route).

    Parameters
    ----------
    phase : (H, W) float64, Arg G at the pixel centres, radians
    carrier : (H, W, 3) float64, q = F e at each pixel, cycles/mm
    frequency : (H, W) float64, F at each pixel, cycles/mm
    pixel_u, pixel_v : (3,) mm, steps between columns / rows

    Returns
    -------
    (H, W) float64; NaN on the border pixels.  Each one-sided difference of
    the local phasor field ``Arg G(x +- h) - Arg G(x) -+ 2 pi q(x) . h`` is
    wrapped into (-pi, pi] before the two are averaged.
    """
    phase = np.asarray(phase, dtype=np.float64)
    out = np.full(phase.shape, np.nan)
    parts = []
    for step, axis in ((np.asarray(pixel_u, float), 1), (np.asarray(pixel_v, float), 0)):
        advance = TWO_PI * (np.asarray(carrier) @ step)
        fwd = _wrap(np.roll(phase, -1, axis) - phase - advance)
        bwd = _wrap(phase - np.roll(phase, 1, axis) - advance)
        parts.append((fwd + bwd) / (2.0 * np.linalg.norm(step)))
    inner = (slice(1, -1), slice(1, -1))
    out[inner] = np.hypot(parts[0], parts[1])[inner] / (TWO_PI * np.asarray(frequency)[inner])
    return out


def singularity_slice_fd(kernels: PhasorKernels, plane, *, fields: PhasorFields, **options) -> tuple:
    """Finite-difference S images ``(S_v, S_w)`` of a slice; NaN on the border.

    ``options`` as in :func:`engine.phasor.noise.phasor_complex`.
    """
    pts = slice_points(plane)
    g_v, g_w = phasor_complex(kernels, pts, fields=fields, **options)
    f, e_v, e_w = local_oscillators(fields, pts)
    shape = plane.shape
    f_img = f.reshape(shape)
    return tuple(singularity_fd(np.angle(g).reshape(shape), (f[:, None] * e).reshape(shape + (3,)), f_img,
                                plane.pixel_u, plane.pixel_v)
                 for g, e in ((g_v, e_v), (g_w, e_w)))


def singularity_energy(measure, q: float = THRESHOLD) -> float:
    """F_S(q): fraction of the pixels with S > q (eq. 10); NaN pixels are left out."""
    s = np.asarray(measure, dtype=np.float64)
    valid = ~np.isnan(s)
    if not valid.any():
        raise ValueError("measure: no pixel has a defined singularity measure")
    return float(np.count_nonzero(s[valid] > q) / np.count_nonzero(valid))


def singularity_report(kernels: PhasorKernels, plane, *, fields: PhasorFields, q: float = THRESHOLD,
                       **options) -> dict:
    """F_S(q) of a slice for p_v, p_w and either (a pixel singular in p_v or p_w).

    Returns ``{"v": float, "w": float, "either": float}``; ``options`` as in
    :func:`singularity_measure`.
    """
    s_v, s_w = singularity_slice(kernels, plane, fields=fields, **options)
    return {"v": singularity_energy(s_v, q), "w": singularity_energy(s_w, q),
            "either": singularity_energy(np.maximum(s_v, s_w), q)}
