"""Local orientation of a stripe pattern by patch-wise Fourier analysis (paper 4.3.1).

The image is cut into square patches (11 x 11 cells in the paper); each
patch is shifted to zero mean and Fourier transformed, and the frequency
of largest modulus (other than the constant term) is located. Stripes run
perpendicular to that wave vector, so the patch's orientation is the wave
vector's angle plus 90 degrees.

Angles are axial (defined modulo pi), in radians in [0, pi), measured from
the +x axis towards +y in the grid's (x, y) components: angle ``t`` is the
direction ``(cos t, sin t)``, the convention of the rotation fields'
columns. For a pattern grown with ``direction=i`` the stripes run
perpendicular to ``rotation[..., :, i]``.

An 11-cell patch samples frequencies only every 1/11 cycle per cell, too
coarse to resolve an angle within a few degrees for wavelengths of 6-15
cells (a wavelength of 9 cells peaks ~1.2 bins from the centre), so each
patch is zero-padded to ``oversample`` times its size before the
transform: the same spectrum, sampled finely enough to place its maximum
(16: about 2.5 degrees at that wavelength).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["Orientation", "local_orientation", "axial_difference"]


class Orientation(NamedTuple):
    """Per-patch result of :func:`local_orientation`, arrays of shape (py, px).

    angle : float64, stripe direction in [0, pi) (nan where the patch is flat)
    strength : float64 in [0, 1], 1 for a clean plane wave, ~0 for noise or a flat patch
    wavelength : float64, cells per period of the dominant frequency
    centre : (py, px, 2) float64, patch centres (x, y) in cell units
    coverage : float64 in [0, 1], fraction of the patch inside ``mask`` (1 without one)
    """

    angle: np.ndarray
    strength: np.ndarray
    wavelength: np.ndarray
    centre: np.ndarray
    coverage: np.ndarray


def axial_difference(a, b):
    """Smallest angle between two axial directions (modulo pi), in [0, pi/2]."""
    d = np.mod(np.asarray(a, dtype=np.float64) - np.asarray(b, dtype=np.float64), np.pi)
    return np.minimum(d, np.pi - d)


def local_orientation(image, *, patch=11, oversample=16, mask=None) -> Orientation:
    """Stripe orientation of each ``patch`` x ``patch`` tile of a 2D image.

    Parameters
    ----------
    image : (ny, nx) float, e.g. the structure ``1 - u`` of a grown pattern
    patch : int >= 4, tile size in cells; incomplete tiles at the right / top are dropped
    oversample : int >= 1, zero-padding factor of the transform (1: the plain FFT)
    mask : (ny, nx) bool or None, only to report each tile's coverage

    Returns
    -------
    Orientation
    """
    img = np.asarray(image, dtype=np.float64)
    if img.ndim != 2:
        raise ValueError(f"image must be a 2D [y, x] grid; got shape {img.shape}")
    if not np.isfinite(img).all():
        raise ValueError("image has NaN or infinite values")
    if isinstance(patch, bool) or not isinstance(patch, (int, np.integer)) or patch < 4:
        raise ValueError(f"patch must be an integer >= 4 (cells); got {patch!r}")
    if isinstance(oversample, bool) or not isinstance(oversample, (int, np.integer)) or oversample < 1:
        raise ValueError(f"oversample must be an integer >= 1; got {oversample!r}")
    py, px = img.shape[0] // patch, img.shape[1] // patch
    if py == 0 or px == 0:
        raise ValueError(f"image {img.shape} is smaller than one {patch} x {patch} patch")
    tiles = img[:py * patch, :px * patch].reshape(py, patch, px, patch).swapaxes(1, 2)
    tiles = tiles - tiles.mean(axis=(2, 3), keepdims=True)
    n = patch * oversample
    f = np.fft.fftfreq(n)
    # below half a cycle per patch lies the constant term's lobe, not a stripe
    low = np.hypot(f[None, :], f[:, None]) < 0.5 / patch
    kx, ky, peak = np.empty((py, px)), np.empty((py, px)), np.empty((py, px))
    for j in range(py):              # one row of patches at a time bounds the memory
        spectrum = np.abs(np.fft.fft2(tiles[j], s=(n, n), axes=(1, 2)))
        spectrum[:, low] = 0.0
        flat_index = spectrum.reshape(px, -1).argmax(axis=1)
        iy, ix = np.unravel_index(flat_index, (n, n))
        kx[j], ky[j] = f[ix], f[iy]
        peak[j] = spectrum.reshape(px, -1)[np.arange(px), flat_index]
    energy = (tiles ** 2).sum(axis=(2, 3))
    flat = energy <= 1e-20 * max(float(energy.max()), 1e-300)
    angle = np.mod(np.arctan2(ky, kx) + 0.5 * np.pi, np.pi)
    angle[flat] = np.nan
    # a plane wave puts |F|^2 = N * sum(p^2) / 2 into its peak
    strength = np.where(flat, 0.0, np.sqrt(2.0) * peak / np.sqrt(patch * patch * np.maximum(energy, 1e-300)))
    strength = np.clip(strength, 0.0, 1.0)
    wavelength = 1.0 / np.maximum(np.hypot(kx, ky), 1e-300)
    cy, cx = np.meshgrid((np.arange(py) + 0.5) * patch, (np.arange(px) + 0.5) * patch, indexing="ij")
    centre = np.stack([cx, cy], axis=-1)
    if mask is None:
        coverage = np.ones((py, px))
    else:
        m = np.asarray(mask, dtype=bool)
        if m.shape != img.shape:
            raise ValueError(f"mask must have the image's shape {img.shape}; got {m.shape}")
        coverage = m[:py * patch, :px * patch].reshape(py, patch, px, patch).mean(axis=(1, 3))
    return Orientation(angle, strength, wavelength, centre, coverage)
