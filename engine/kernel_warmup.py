"""Load the evaluation kernels' shared machinery once, before the window shows.

The first kernel a process runs pays for more than itself: numba fills its
typing and lowering tables (about seventy modules of Python, imported while
holding the GIL) the first time a compiled function is loaded, and
marching cubes imports its Cython modules; the mesh deviation loop that
rates each level of detail is compiled (or read from numba's cache).  Done inside the first evaluation,
on a worker thread, that held the GUI thread off for 170-230 ms (see
BENCHMARKS.md, "A native viewport window").  `warm_up_kernels` does it up
front: a small compiled array kernel is loaded (compiled the first time,
from numba's cache after), the deviation of two tiny meshes is measured
and the marching-cubes module is imported.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _root_sum(values):
    total = 0.0
    for i in range(values.shape[0]):
        total += math.sqrt(abs(values[i]))
    return total


def warm_up_kernels() -> float:
    """Load numba's tables, the deviation loop and the marching-cubes modules; returns
    sum(sqrt(|k|)) for k = 0..3 computed by the compiled kernel (a caller can check it ran)."""
    from skimage.measure import marching_cubes  # noqa: F401  (imports its Cython modules)

    from engine.geometry.mesh_deviation import mesh_deviation
    square = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
    mesh_deviation(square, [[0, 1, 2], [0, 2, 3]], square, [[0, 1, 3], [1, 2, 3]])
    return float(_root_sum(np.arange(4.0)))
