"""Connected pieces of a triangle mesh (vertices joined by triangle edges).

A union-find over the faces compiled with numba ``nogil``: the labelling of a
few million triangles runs without the GIL, where scipy's
``connected_components`` on the edge matrix (building, sorting and
converting it) held it for up to a second and stalled every other thread.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["vertex_components"]


@njit(cache=True, nogil=True)
def _find(parent, i):
    while parent[i] != i:
        parent[i] = parent[parent[i]]          # path halving
        i = parent[i]
    return i


@njit(cache=True, nogil=True)
def _components(faces, n):
    parent = np.arange(n)
    for r in range(faces.shape[0]):
        a = _find(parent, faces[r, 0])
        for c in range(1, 3):
            b = _find(parent, faces[r, c])
            if a != b:
                if a < b:
                    parent[b] = a
                else:
                    parent[a] = b
                    a = b
    label = np.empty(n, np.int64)
    count = 0
    for i in range(n):                          # roots are the smallest index of their piece
        root = _find(parent, i)
        if root == i:
            label[i] = count
            count += 1
        else:
            label[i] = label[root]
    return count, label


def vertex_components(faces, n):
    """Connected pieces of the graph on ``n`` vertices whose edges are the
    triangle edges of ``faces``.

    Parameters
    ----------
    faces : (f, 3) int, indices in [0, n)
    n : int, vertex count (a vertex in no face is a piece of its own)

    Returns
    -------
    count : int
    label : (n,) int64, pieces numbered 0..count-1 in order of their smallest vertex
    """
    f = np.ascontiguousarray(faces, dtype=np.int64)
    count, label = _components(f, int(n))
    return int(count), label
