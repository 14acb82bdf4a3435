"""Linear density filter (Bruns & Tortorelli / Bourdin) over the design cells.

The physical density of a design cell is the weighted mean of the design
variables of the design cells within ``rmin`` (centre distance, in cells),
with cone weights ``w = rmin - d``. Passive cells are neither filtered nor
averaged in, so the cut-out of an L-beam does not thin the material along
its edge. As a linear map ``rho = H x`` with row-normalised ``H``, the
chain rule for sensitivities is ``df/dx = H^T df/drho``.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import scipy.sparse as sp

__all__ = ["DensityFilter"]


class DensityFilter:
    """Row-normalised cone filter restricted to the cells of ``design``.

    Parameters
    ----------
    design : bool cell array, (nely, nelx) or (nelz, nely, nelx)
        Cells carrying a design variable.
    rmin : float > 0
        Radius in cells; ``rmin <= 1`` leaves the densities unfiltered.

    Attributes
    ----------
    H : (n, n) CSR float64, ``n = design.sum()``, rows sum to 1.
    """

    def __init__(self, design, rmin):
        design = np.asarray(design, bool)
        shape = design.shape
        index = np.full(shape, -1, np.int64)
        index[design] = np.arange(int(design.sum()))
        r = max(0, math.ceil(rmin) - 1)
        rows, cols, vals = [], [], []
        for off in itertools.product(range(-r, r + 1), repeat=len(shape)):
            w = rmin - math.sqrt(sum(o * o for o in off))
            if w <= 0:
                continue
            src = tuple(slice(max(0, -o), n - max(0, o)) for o, n in zip(off, shape))
            dst = tuple(slice(max(0, o), n - max(0, -o)) for o, n in zip(off, shape))
            a, b = index[src], index[dst]
            ok = (a >= 0) & (b >= 0)
            rows.append(a[ok])
            cols.append(b[ok])
            vals.append(np.full(int(ok.sum()), w))
        n = int(design.sum())
        H = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))
        H = sp.diags(1.0 / np.asarray(H.sum(axis=1)).ravel()) @ H
        self.H = H.tocsr()
        self.HT = self.H.T.tocsr()

    def __call__(self, x):
        """Filtered densities ``H x``."""
        return self.H @ x

    def backward(self, g):
        """Sensitivity with respect to ``x`` of a function with gradient ``g`` in ``rho``."""
        return self.HT @ g
