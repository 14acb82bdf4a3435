"""The node samples of an SDF over a box, on the GPU or in numpy: one front for both.

`sample_box` gives ``f / lipschitz`` at the nodes of `engine.implicit.voxelize.grid_nodes`
by `engine.gpu.sdf_points.evaluate_glsl_grid` (float32, the shader the sphere
tracer draws) or by `engine.implicit.voxelize.sample_nodes` (numpy, float64
rounded to float32).  "auto" takes the GPU and falls back to numpy when no
OpenGL 4.3 context can be made.
"""

from __future__ import annotations

import numpy as np

from engine.implicit.values import SDF
from engine.implicit.voxelize import grid_nodes, sample_nodes

from .context import GpuUnavailable
from .sdf_points import evaluate_glsl_grid

__all__ = ["sample_box", "BACKENDS"]

BACKENDS = ("auto", "gpu", "numpy")


def sample_box(sdf: SDF, lo, hi, resolution: int, *, periodic: bool, backend: str = "auto",
               progress=None) -> tuple[np.ndarray, str]:
    """(samples (nx, ny, nz) float32, the backend that ran) over the box ``[lo, hi]`` mm.

    Raises
    ------
    ValueError
        For an unknown backend or a bad box (see `grid_nodes`).
    engine.gpu.context.GpuUnavailable
        With backend "gpu" and no OpenGL 4.3 context.
    """
    if backend not in BACKENDS:
        raise ValueError(f"backend must be one of {BACKENDS}, got {backend!r}")
    origin, spacing, counts = grid_nodes(lo, hi, resolution, periodic)
    if backend in ("auto", "gpu"):
        try:
            return evaluate_glsl_grid(sdf, origin, spacing, counts, progress=progress), "gpu"
        except GpuUnavailable:
            if backend == "gpu":
                raise
    return sample_nodes(sdf, origin, spacing, counts, progress=progress), "numpy"
