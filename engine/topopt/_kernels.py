"""Numba loop of the solver: the sparse assembly scatter.

Serial on purpose: the scatter is memory-bound and races between threads
would need atomics; ~2.5x faster than ``np.bincount`` over the same slots.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["scatter_scaled"]


@njit(cache=True, nogil=True)
def scatter_scaled(keep, slot, scale, ke, n_entries):
    """``data[slot[t]] += scale[keep[t] // m] * ke[keep[t] % m]`` with ``m = ke.size``."""
    data = np.zeros(n_entries)
    m = ke.size
    for t in range(keep.size):
        f = keep[t]
        data[slot[t]] += scale[f // m] * ke[f % m]
    return data
