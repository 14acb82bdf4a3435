"""Periodic resampling of node-sampled cell fields to another resolution."""

from __future__ import annotations

import numpy as np


def resample_periodic(field: np.ndarray, resolution: int) -> np.ndarray:
    """Trilinear periodic resampling of a node field to ``resolution``^3 nodes.

    Parameters
    ----------
    field : (N, N, N) float array, samples at nodes i/N of the periodic unit cell.
    resolution : int >= 2, nodes per axis of the result (samples at j/resolution).

    Returns
    -------
    (resolution,)*3 float32 array, exactly periodic.
    """
    from scipy.ndimage import map_coordinates

    f = np.asarray(field)
    if f.ndim != 3 or len(set(f.shape)) != 1:
        raise ValueError(f"field must be a cubic 3-D grid; got shape {f.shape}")
    if int(resolution) != resolution or resolution < 2:
        raise ValueError(f"resolution must be an integer >= 2; got {resolution!r}")
    n = f.shape[0]
    if resolution == n:
        return f.astype(np.float32, copy=True)
    axis = np.arange(resolution) * (n / resolution)
    coords = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"))
    return map_coordinates(f.astype(np.float32), coords, order=1, mode="grid-wrap").astype(np.float32)
