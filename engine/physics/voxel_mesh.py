"""Periodic voxel/pixel meshes with only the elements that carry material.

A periodic grid of ``shape = (n_0, .., n_{dim-1})`` elements has the same
number of nodes: node ``(i, j, k)`` is the lower corner of element
``(i, j, k)``, and element ``(i, j, k)`` uses nodes ``(i + b_0, j + b_1, k + b_2)``
modulo the shape (local node order of :mod:`hex_element`). Only elements
listed in the mesh exist; a node is *active* when an element touches it.
Elements and active nodes are both numbered in grid (C) order, so the
elements of element planes ``i0 <= i < i1`` (axis 0) and the nodes of node
planes ``i0 <= i < i1`` are contiguous index ranges.

Race-free parallel scatter: axis 0 is cut into an even number ``2 S`` of
slabs of at least one element plane each. Element slab ``s`` touches node
planes ``p_s .. p_{s+1}`` (inclusive), so slabs of the same parity never
share a node: the even slabs run in parallel, then the odd ones. That is two
parallel regions per operator application whatever the grid, which matters
on a shared machine where every thread barrier can stall.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["VoxelMesh", "build_mesh", "slab_planes"]


@dataclass(frozen=True)
class VoxelMesh:
    """Active elements and nodes of one periodic grid level.

    Attributes
    ----------
    shape : tuple of int
        Elements (= nodes) per axis.
    elem_coords : (n_elem, dim) int32
        Grid index of each element, in grid order.
    elem_nodes : (n_elem, 2**dim) int32
        Active node index of each local node.
    elem_ptr, node_ptr : (2 S + 1,) int64
        Elements / nodes ``ptr[s] : ptr[s+1]`` lie in slab ``s`` (element
        planes ``p_s <= i < p_{s+1}``, node planes likewise).
    node_coords : (n_nodes, dim) int32
        Grid index of each active node.
    node_index : int32 array of ``shape``
        Active node number per grid node, -1 where inactive.
    """

    shape: tuple
    elem_coords: np.ndarray
    elem_nodes: np.ndarray
    elem_ptr: np.ndarray
    node_ptr: np.ndarray
    node_coords: np.ndarray
    node_index: np.ndarray

    @property
    def dim(self):
        return len(self.shape)

    @property
    def n_elem(self):
        return self.elem_coords.shape[0]

    @property
    def n_nodes(self):
        return self.node_coords.shape[0]


# Slabs per parity; 8 keeps two threads balanced on uneven (truss) planes.
SLABS_PER_PHASE = 8


def slab_planes(n0, slabs_per_phase=SLABS_PER_PHASE):
    """Plane boundaries ``p_0 = 0 < p_1 < .. < p_{2S} = n0`` of the 2 S slabs."""
    S = max(1, min(slabs_per_phase, n0 // 2))
    return np.round(np.arange(2 * S + 1) * n0 / (2 * S)).astype(np.int64)


def _local_offsets(dim):
    return np.array([[(l >> a) & 1 for a in range(dim)] for l in range(2 ** dim)],
                    dtype=np.int64)


def build_mesh(shape, elem_coords):
    """Mesh of the given elements on a periodic grid.

    Parameters
    ----------
    shape : tuple of int
        Elements per axis.
    elem_coords : (n_elem, dim) int
        Grid indices of the elements that exist, each exactly once.

    Returns
    -------
    mesh : VoxelMesh
    order : (n_elem,) int64
        Permutation applied to ``elem_coords`` (so per-element data given in
        input order can be reordered with ``data[order]``).
    """
    shape = tuple(int(n) for n in shape)
    dim = len(shape)
    coords = np.asarray(elem_coords, dtype=np.int64).reshape(-1, dim)
    flat = np.ravel_multi_index(tuple(coords.T), shape)
    order = np.argsort(flat, kind="stable")
    coords = coords[order]
    planes = slab_planes(shape[0])
    elem_ptr = np.searchsorted(coords[:, 0], planes).astype(np.int64)

    offs = _local_offsets(dim)
    node_grid = (coords[:, None, :] + offs[None, :, :]) % np.array(shape)
    node_flat = np.ravel_multi_index(tuple(np.moveaxis(node_grid, -1, 0)), shape)
    used = np.zeros(int(np.prod(shape)), dtype=bool)
    used[node_flat.ravel()] = True
    node_index = np.full(used.size, -1, dtype=np.int32)
    active = np.flatnonzero(used)
    node_index[active] = np.arange(active.size, dtype=np.int32)
    elem_nodes = node_index[node_flat].astype(np.int32)
    node_coords = np.stack(np.unravel_index(active, shape), axis=1).astype(np.int32)
    node_ptr = np.searchsorted(node_coords[:, 0], planes).astype(np.int64)
    mesh = VoxelMesh(shape=shape, elem_coords=coords.astype(np.int32),
                     elem_nodes=np.ascontiguousarray(elem_nodes),
                     elem_ptr=elem_ptr, node_ptr=node_ptr, node_coords=node_coords,
                     node_index=node_index.reshape(shape))
    return mesh, order
