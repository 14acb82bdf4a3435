"""Periodic connected components of solid voxels and percolation.

Two solid voxels (pixels) are connected when their elements share at least
one node: 26-connectivity in 3D, 8-connectivity in 2D, with wrap-around on
every axis. A component *percolates* when it reaches one of its own periodic
images, i.e. a breadth-first walk that carries the unwrapped lattice offset
of each voxel meets an already visited voxel under a different offset.
Only percolating components can carry a macroscopic load; the others are
floating islands that add zero-energy modes to the periodic stiffness and
nothing to the homogenized stiffness, so the solver drops them.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["periodic_components", "keep_percolating"]


def _neighbour_offsets(dim):
    rng = (-1, 0, 1)
    if dim == 3:
        offs = [(a, b, c) for a in rng for b in rng for c in rng]
    else:
        offs = [(a, b, 0) for a in rng for b in rng]
    return np.array([o for o in offs if any(o)], dtype=np.int64)


@njit(cache=True, nogil=True)
def _label_periodic(solid, offsets):
    """BFS labelling with image offsets. solid : (n0, n1, n2) bool."""
    n0, n1, n2 = solid.shape
    labels = np.full(solid.shape, -1, dtype=np.int32)
    shift = np.zeros((n0, n1, n2, 3), dtype=np.int32)
    queue = np.empty(solid.size, dtype=np.int64)
    perc = np.zeros((solid.size + 1, 3), dtype=np.bool_)        # trimmed below
    ncomp = 0
    for s0 in range(n0):
        for s1 in range(n1):
            for s2 in range(n2):
                if not solid[s0, s1, s2] or labels[s0, s1, s2] >= 0:
                    continue
                lab = ncomp
                ncomp += 1
                labels[s0, s1, s2] = lab
                head, tail = 0, 1
                queue[0] = (s0 * n1 + s1) * n2 + s2
                while head < tail:
                    flat = queue[head]
                    head += 1
                    i = flat // (n1 * n2)
                    j = (flat // n2) % n1
                    k = flat % n2
                    for o in range(offsets.shape[0]):
                        ri = i + offsets[o, 0]
                        rj = j + offsets[o, 1]
                        rk = k + offsets[o, 2]
                        wi, wj, wk = ri % n0, rj % n1, rk % n2
                        if not solid[wi, wj, wk]:
                            continue
                        # Image offset gained by crossing the cell boundary.
                        t0 = shift[i, j, k, 0] + (ri - wi) // n0
                        t1 = shift[i, j, k, 1] + (rj - wj) // n1
                        t2 = shift[i, j, k, 2] + (rk - wk) // n2
                        if labels[wi, wj, wk] < 0:
                            labels[wi, wj, wk] = lab
                            shift[wi, wj, wk, 0] = t0
                            shift[wi, wj, wk, 1] = t1
                            shift[wi, wj, wk, 2] = t2
                            queue[tail] = (wi * n1 + wj) * n2 + wk
                            tail += 1
                        else:
                            if t0 != shift[wi, wj, wk, 0]:
                                perc[lab, 0] = True
                            if t1 != shift[wi, wj, wk, 1]:
                                perc[lab, 1] = True
                            if t2 != shift[wi, wj, wk, 2]:
                                perc[lab, 2] = True
    return labels, perc[:ncomp].copy()


def periodic_components(solid):
    """Label the periodic components of a solid mask.

    Parameters
    ----------
    solid : (n0, n1, n2) or (n0, n1) bool
        True where there is material; array axis ``a`` is lattice direction ``a``.

    Returns
    -------
    labels : int32 array, shape of ``solid``
        Component index ``0 .. n_components-1``, ``-1`` on void.
    percolates : (n_components, ndim) bool
        ``percolates[c, a]`` is True when component ``c`` connects to its own
        image shifted along axis ``a`` (possibly combined with other axes).
    """
    solid = np.asarray(solid, dtype=bool)
    if solid.ndim not in (2, 3):
        raise ValueError(f"solid must be a 2D or 3D array; got ndim={solid.ndim}")
    dim = solid.ndim
    grid = solid if dim == 3 else solid[:, :, None]
    labels, perc = _label_periodic(np.ascontiguousarray(grid), _neighbour_offsets(dim))
    if dim == 2:
        labels, perc = labels[:, :, 0], perc[:, :2]
    return labels, perc


def keep_percolating(density, *, return_labels=False):
    """Mask of the material that belongs to percolating components.

    Parameters
    ----------
    density : (n0, n1, n2) or (n0, n1) float or bool
        Material density per voxel; anything > 0 is solid.

    Returns
    -------
    kept : bool array, shape of ``density``
        Solid voxels of percolating components.
    dropped_fraction : float
        Material removed, ``sum(density[solid & ~kept]) / density.size``
        (for a binary cell: the fraction of cell voxels dropped).
    labels : int32 array, only with ``return_labels=True``
        Component index per voxel as from :func:`periodic_components`.
    """
    density = np.asarray(density)
    solid = density > 0
    labels, perc = periodic_components(solid)
    good = np.flatnonzero(perc.any(axis=1))
    kept = np.isin(labels, good) & solid
    dropped = np.where(solid & ~kept, density, 0).astype(np.float64).sum()
    if return_labels:
        return kept, float(dropped / density.size), labels
    return kept, float(dropped / density.size)
