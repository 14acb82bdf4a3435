"""Periodic resampling of node-sampled cell fields to another resolution."""

from __future__ import annotations

import numpy as np


def resample_periodic(field: np.ndarray, resolution) -> np.ndarray:
    """Trilinear periodic resampling of a node field to another grid.

    Parameters
    ----------
    field : (N, N, N) float array, samples at nodes i/N of the periodic unit
        cell; or (nx, ny, nz) samples of a box cell (nodes ``i * L / n``)
        when ``resolution`` is a shape.
    resolution : int >= 2, nodes per axis of the result (samples at
        j/resolution), or three ints ``(mx, my, mz)``: the result's shape over
        the same box.

    Returns
    -------
    float32 array of ``(resolution,)*3`` or the given shape, exactly periodic.
    """
    from scipy.ndimage import map_coordinates

    f = np.asarray(field)
    if isinstance(resolution, (tuple, list, np.ndarray)):
        shape = tuple(resolution)
        if f.ndim != 3:
            raise ValueError(f"field must be a 3-D grid; got shape {f.shape}")
        if len(shape) != 3 or any(isinstance(m, bool) or int(m) != m or m < 2 for m in shape):
            raise ValueError(f"resolution must be three integers >= 2; got {resolution!r}")
        shape = tuple(int(m) for m in shape)
    else:
        if f.ndim != 3 or len(set(f.shape)) != 1:
            raise ValueError(f"field must be a cubic 3-D grid; got shape {f.shape}")
        if int(resolution) != resolution or resolution < 2:
            raise ValueError(f"resolution must be an integer >= 2; got {resolution!r}")
        shape = (int(resolution),) * 3
    if shape == f.shape:
        return f.astype(np.float32, copy=True)
    axes = [np.arange(m) * (n / m) for m, n in zip(shape, f.shape)]
    coords = np.stack(np.meshgrid(*axes, indexing="ij"))
    return map_coordinates(f.astype(np.float32), coords, order=1, mode="grid-wrap").astype(np.float32)
