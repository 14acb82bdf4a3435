"""Plain numpy step of eq. 13, written to be read, for tests and the benchmark.

Each term of the equation is one array expression: the grid is padded by
one cell replicating the edge (zero-flux boundary), derivatives are
central differences, and the update is literally
``u + dt (L_sigma u / dx^2 + gamma f)`` and
``v + dt (d / dim lap v / dx^2 + gamma g 1_Omega - lambda (1 - 1_Omega) v)``.
The fused kernel in :mod:`engine.rd.gray_scott` must agree with it to
round-off.
"""

from __future__ import annotations

import numpy as np

from .gray_scott import TINY, RDParams, check_fields, kill_rate, resolve_params

__all__ = ["gray_scott_step_reference", "reference_update", "second_derivative"]


def second_derivative(u, i, j):
    """Central-difference ``d_i d_j u`` times ``dx^2`` at every cell.

    ``i, j`` are component indices in (x, y[, z]) order; component ``c``
    runs along array axis ``ndim - 1 - c``. Outside the grid a cell reads
    as the edge cell (zero flux).
    """
    nd = u.ndim
    p = np.pad(u, 1, mode="edge")

    def shifted(offsets):
        # offsets: {component: +-1}; returns u displaced by those cells
        index = [slice(1, -1)] * nd
        for comp, o in offsets.items():
            axis = nd - 1 - comp
            index[axis] = slice(1 + o, p.shape[axis] - 1 + o)
        return p[tuple(index)]

    if i == j:
        return shifted({i: 1}) - 2.0 * u + shifted({i: -1})
    return (shifted({i: 1, j: 1}) - shifted({i: 1, j: -1})
            - shifted({i: -1, j: 1}) + shifted({i: -1, j: -1})) / 4.0


def gray_scott_step_reference(u, v, sigma, *, inside, gamma_map=None, params: RDParams = RDParams()):
    """One explicit step of eq. 13 in plain numpy; same arguments as
    :func:`engine.rd.gray_scott.gray_scott_step` with ``steps=1``.

    Returns
    -------
    (u, v) : new float64 arrays
    """
    u, v, sigma, inside, gamma_map = check_fields(u, v, sigma, inside, gamma_map)
    p = resolve_params(sigma, params)
    return reference_update(u, v, sigma, inside.astype(np.float64), kill_rate(gamma_map, p), p)


def reference_update(u, v, sigma, omega, kill, p: RDParams):
    """The arithmetic of one step on validated arrays (``omega`` 0/1 float,
    ``kill`` = k(x) per cell, ``p`` resolved); what the benchmark times."""
    dim = u.ndim
    # sum_ij sigma_ij d_i d_j u with sigma symmetric: the off-diagonal pairs twice
    lap_sigma_u = sum(sigma[..., i, i] * second_derivative(u, i, i) for i in range(dim))
    lap_sigma_u = lap_sigma_u + sum(2.0 * sigma[..., i, j] * second_derivative(u, i, j)
                                    for i in range(dim) for j in range(i + 1, dim))
    lap_v = sum(second_derivative(v, i, i) for i in range(dim))
    f = -u * v ** 2 + p.F * (1.0 - u)
    g = u * v ** 2 - (kill + p.F) * v
    u_next = u + (lap_sigma_u / p.dx ** 2 + p.gamma * f) * p.dt
    v_next = v + (p.d / dim * lap_v / p.dx ** 2 + p.gamma * g * omega - p.lambda_ * (1.0 - omega) * v) * p.dt
    v_next[np.abs(v_next) < TINY] = 0.0
    return u_next, v_next
