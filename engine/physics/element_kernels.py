"""Numba kernels on element-by-element operators over a :class:`VoxelMesh`.

Vectors are ``(n_nodes * d, n_rhs)`` C-contiguous arrays: row ``node * d + a``
holds displacement component ``a`` of a node for every load case, so one
sweep over the elements serves all load cases at once.

Two kinds of element operators:

* *scaled* (fine level): element ``e`` has ``sum_g scales[g, e] * K0[g]``; in
  practice one group (the base material) or two (plus soft void, nu = 0);
* *explicit* (Galerkin coarse levels): element ``e`` has its own ``Ke[e]``.

Scatters run slab parity by slab parity (see :mod:`voxel_mesh`) so threads
never write the same node, in two parallel regions per application; the
even phase also zeroes the output. The scaled product is batched: a chunk
of elements is gathered into a (nde, chunk * n_rhs) block and multiplied by
``K0`` with the long chunk axis innermost, which vectorises well for any
element size. :func:`get_kernels` compiles variants with the node count,
dimension and load-case count as constants (cached per combination) so the
gathers and scatters unroll.
"""

from __future__ import annotations

import functools
from types import SimpleNamespace

import numpy as np
from numba import njit, prange

_CHUNK = 128          # elements per batched product
_NBLK = 64            # fixed reduction blocks: results independent of thread count


@functools.lru_cache(maxsize=None)
def get_kernels(dim, nrhs):
    """Compiled kernels for ``dim``-D elements and ``nrhs`` load cases."""
    NEN, D, R = 2 ** dim, dim, nrhs
    NDE = NEN * D

    # The kernels must not call other closures: a dispatcher captured in a
    # closure changes identity between processes and defeats numba's cache.
    @njit(parallel=True, cache=True, nogil=True, fastmath=True)
    def matvec_scaled(K0, scales, elem_nodes, elem_ptr, node_ptr, u, y):
        """``y = A u`` for the scaled operator (``y`` is overwritten)."""
        half = (elem_ptr.shape[0] - 1) // 2
        nde = K0.shape[1]
        for phase in range(2):
            for h in prange(half):
                s = 2 * h + phase
                if phase == 0:
                    for i in range(node_ptr[s] * D, node_ptr[s + 2] * D):
                        for r in range(R):
                            y[i, r] = 0.0
                ue = np.empty((NDE, _CHUNK * R), dtype=u.dtype)
                ye = np.empty((NDE, _CHUNK * R), dtype=u.dtype)
                for c0 in range(elem_ptr[s], elem_ptr[s + 1], _CHUNK):
                    c1 = min(elem_ptr[s + 1], c0 + _CHUNK)
                    m = (c1 - c0) * R
                    for i in range(nde):
                        for q in range(m):
                            ye[i, q] = 0.0
                    for g in range(K0.shape[0]):
                        for e in range(c0, c1):
                            col = (e - c0) * R
                            sc = scales[g, e]
                            for l in range(NEN):
                                base = elem_nodes[e, l] * D
                                for a in range(D):
                                    for r in range(R):
                                        ue[l * D + a, col + r] = sc * u[base + a, r]
                        for i in range(nde):
                            for j in range(nde):
                                k = K0[g, i, j]
                                for q in range(m):
                                    ye[i, q] += k * ue[j, q]
                    for e in range(c0, c1):
                        col = (e - c0) * R
                        for l in range(NEN):
                            base = elem_nodes[e, l] * D
                            for a in range(D):
                                for r in range(R):
                                    y[base + a, r] += ye[l * D + a, col + r]

    @njit(parallel=True, cache=True, nogil=True, fastmath=True)
    def matvec_explicit(Ke, elem_nodes, elem_ptr, node_ptr, u, y):
        """``y = A u`` for the explicit operator (``y`` is overwritten)."""
        half = (elem_ptr.shape[0] - 1) // 2
        nde = Ke.shape[1]
        for phase in range(2):
            for h in prange(half):
                s = 2 * h + phase
                if phase == 0:
                    for i in range(node_ptr[s] * D, node_ptr[s + 2] * D):
                        for r in range(R):
                            y[i, r] = 0.0
                ue = np.empty((NDE, R), dtype=u.dtype)
                ye = np.empty((R, NDE), dtype=u.dtype)
                for e in range(elem_ptr[s], elem_ptr[s + 1]):
                    for l in range(NEN):
                        base = elem_nodes[e, l] * D
                        for a in range(D):
                            for r in range(R):
                                ue[l * D + a, r] = u[base + a, r]
                    for r in range(R):
                        for i in range(nde):
                            ye[r, i] = 0.0
                    # K symmetric: row j is column j, contiguous innermost loop.
                    for j in range(nde):
                        for r in range(R):
                            sv = ue[j, r]
                            for i in range(nde):
                                ye[r, i] += Ke[e, j, i] * sv
                    for l in range(NEN):
                        base = elem_nodes[e, l] * D
                        for a in range(D):
                            for r in range(R):
                                y[base + a, r] += ye[r, l * D + a]

    @njit(parallel=True, cache=True, nogil=True)
    def jacobi_update(x, b, Ax, dinv, omega):
        """``x += omega * Dinv (b - Ax)`` with (d x d) node blocks."""
        for n in prange(dinv.shape[0]):
            for a in range(D):
                for r in range(R):
                    acc = 0.0
                    for c in range(D):
                        acc += dinv[n, a, c] * (b[n * D + c, r] - Ax[n * D + c, r])
                    x[n * D + a, r] += omega * acc

    @njit(parallel=True, cache=True, nogil=True)
    def jacobi_start(x, b, dinv, omega):
        """``x = omega * Dinv b`` (one Jacobi step from x = 0)."""
        for n in prange(dinv.shape[0]):
            for a in range(D):
                for r in range(R):
                    acc = 0.0
                    for c in range(D):
                        acc += dinv[n, a, c] * b[n * D + c, r]
                    x[n * D + a, r] = omega * acc

    @njit(parallel=True, cache=True, nogil=True)
    def prolong_add(x_fine, x_coarse, p_idx, p_w):
        """``x_fine += P x_coarse``; fine node n interpolates from p_idx[n] with p_w[n]."""
        for n in prange(p_idx.shape[0]):
            for k in range(NEN):
                w = p_w[n, k]
                if w == 0.0:
                    continue
                cb = p_idx[n, k] * D
                for a in range(D):
                    for r in range(R):
                        x_fine[n * D + a, r] += w * x_coarse[cb + a, r]

    @njit(parallel=True, cache=True, nogil=True)
    def restrict_residual(b, Ax, r_ptr, r_idx, r_w, out):
        """``out = P^T (b - Ax)`` using the coarse-row pattern of P."""
        for c in prange(r_ptr.shape[0] - 1):
            for a in range(D):
                for r in range(R):
                    out[c * D + a, r] = 0.0
            for k in range(r_ptr[c], r_ptr[c + 1]):
                w = r_w[k]
                fb = r_idx[k] * D
                for a in range(D):
                    for r in range(R):
                        out[c * D + a, r] += w * (b[fb + a, r] - Ax[fb + a, r])

    return SimpleNamespace(matvec_scaled=matvec_scaled, matvec_explicit=matvec_explicit,
                           jacobi_update=jacobi_update, jacobi_start=jacobi_start,
                           prolong_add=prolong_add, restrict_residual=restrict_residual)


# ------------------------------------------------------------ setup (serial)

@njit(cache=True, nogil=True)
def scatter_scaled_vectors(Fe, scales, elem_nodes, n_nodes):
    """Assemble ``sum_e sum_g scales[g, e] * Fe[g]`` into a (n_nodes*d, m) array."""
    nen = elem_nodes.shape[1]
    nde, m = Fe.shape[1], Fe.shape[2]
    d = nde // nen
    out = np.zeros((n_nodes * d, m))
    for g in range(Fe.shape[0]):
        F = Fe[g]
        for e in range(elem_nodes.shape[0]):
            s = scales[g, e]
            if s == 0.0:
                continue
            for l in range(nen):
                base = elem_nodes[e, l] * d
                for a in range(d):
                    for r in range(m):
                        out[base + a, r] += s * F[l * d + a, r]
    return out


@njit(cache=True, nogil=True)
def block_diagonal_scaled(K0, scales, elem_nodes, n_nodes):
    """(n_nodes, d, d) node blocks of the scaled operator's diagonal."""
    nen = elem_nodes.shape[1]
    d = K0.shape[1] // nen
    out = np.zeros((n_nodes, d, d))
    for g in range(K0.shape[0]):
        K = K0[g]
        for e in range(elem_nodes.shape[0]):
            s = scales[g, e]
            for l in range(nen):
                n = elem_nodes[e, l]
                for a in range(d):
                    for b in range(d):
                        out[n, a, b] += s * K[l * d + a, l * d + b]
    return out


@njit(cache=True, nogil=True)
def block_diagonal_explicit(Ke, elem_nodes, n_nodes):
    """(n_nodes, d, d) node blocks of the explicit operator's diagonal."""
    nen = elem_nodes.shape[1]
    d = Ke.shape[1] // nen
    out = np.zeros((n_nodes, d, d))
    for e in range(elem_nodes.shape[0]):
        for l in range(nen):
            n = elem_nodes[e, l]
            for a in range(d):
                for b in range(d):
                    out[n, a, b] += Ke[e, l * d + a, l * d + b]
    return out


# ----------------------------------------------------------- vector kernels

@njit(cache=True, nogil=True)
def remove_mean(x, node_label, n_labels, d):
    """Subtract, per component label and displacement component, the mean
    over the nodes of that label (the rigid translations of each piece)."""
    nrhs = x.shape[1]
    sums = np.zeros((n_labels, d, nrhs))
    counts = np.zeros(n_labels)
    for n in range(node_label.shape[0]):
        lab = node_label[n]
        counts[lab] += 1.0
        for a in range(d):
            for r in range(nrhs):
                sums[lab, a, r] += x[n * d + a, r]
    for lab in range(n_labels):
        if counts[lab] > 0:
            for a in range(d):
                for r in range(nrhs):
                    sums[lab, a, r] /= counts[lab]
    for n in range(node_label.shape[0]):
        lab = node_label[n]
        for a in range(d):
            for r in range(nrhs):
                x[n * d + a, r] -= sums[lab, a, r]


@njit(parallel=True, cache=True, nogil=True)
def column_dots(a, b, c):
    """Per-column ``(a . b, a . c)`` (pass ``c = b`` if only one is needed)."""
    nrhs = a.shape[1]
    n = a.shape[0]
    part = np.zeros((_NBLK, 2, nrhs))
    step = (n + _NBLK - 1) // _NBLK
    for k in prange(_NBLK):
        for i in range(k * step, min(n, (k + 1) * step)):
            for r in range(nrhs):
                part[k, 0, r] += a[i, r] * b[i, r]
                part[k, 1, r] += a[i, r] * c[i, r]
    out = np.zeros((2, nrhs))
    for k in range(_NBLK):
        for j in range(2):
            for r in range(nrhs):
                out[j, r] += part[k, j, r]
    return out[0], out[1]


@njit(parallel=True, cache=True, nogil=True)
def cg_step(x, r, p, q, alpha, b):
    """``x += alpha p``, ``r -= alpha q`` column-wise; returns ``(|r|^2, b . x)``."""
    nrhs = x.shape[1]
    n = x.shape[0]
    part = np.zeros((_NBLK, 2, nrhs))
    step = (n + _NBLK - 1) // _NBLK
    for k in prange(_NBLK):
        for i in range(k * step, min(n, (k + 1) * step)):
            for c in range(nrhs):
                xv = x[i, c] + alpha[c] * p[i, c]
                x[i, c] = xv
                v = r[i, c] - alpha[c] * q[i, c]
                r[i, c] = v
                part[k, 0, c] += v * v
                part[k, 1, c] += b[i, c] * xv
    out = np.zeros((2, nrhs))
    for k in range(_NBLK):
        for j in range(2):
            for c in range(nrhs):
                out[j, c] += part[k, j, c]
    return out[0], out[1]


@njit(parallel=True, cache=True, nogil=True)
def update_direction(p, z, beta):
    """``p = z + beta p`` column-wise."""
    for i in prange(p.shape[0]):
        for c in range(p.shape[1]):
            p[i, c] = z[i, c] + beta[c] * p[i, c]
