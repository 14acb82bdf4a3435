"""Cell stresses against closed forms."""

import numpy as np
import pytest

from engine.topopt import Problem, element_stress, von_mises
from engine.topopt.assembly import grid_fe
from engine.topopt.problem import node_shape


def _edge_weights(n):
    w = np.ones(n + 1)
    w[[0, -1]] = 0.5
    return w / n                                              # consistent nodal share of a uniform traction


def _bar(shape, h, force):
    """Bar along x on rollers at x = 0, uniform traction on the x = L face."""
    dim = len(shape)
    ns = node_shape(shape)
    fixed = np.zeros(ns + (dim,), bool)
    loads = np.zeros((1,) + ns + (dim,))
    fixed[..., 0, 0] = True                                   # u_x = 0 on the x = 0 face
    if dim == 2:
        fixed[0, 0, 1] = True
        loads[0, :, -1, 0] = force * _edge_weights(shape[0])
    else:
        fixed[:, 0, 0, 1] = True                              # u_y = 0 along the line y = 0 (all z)
        fixed[0, :, 0, 2] = True                              # u_z = 0 along the line z = 0 (all y)
        loads[0, :, :, -1, 0] = force * np.outer(_edge_weights(shape[0]), _edge_weights(shape[1]))
    return Problem(shape=shape, fixed=fixed, loads=loads, volfrac=0.5, h=h, young=2.0, poisson=0.3)


@pytest.mark.parametrize("shape", [(3, 7), (2, 3, 5)])
def test_uniform_bar_carries_force_over_area(shape):
    h, F = 0.5, 3.0
    p = _bar(shape, h, F)
    rho = np.ones(shape)
    U = grid_fe(p).solve(np.ones(p.n_cells), method="direct")
    sigma = element_stress(p, rho, U)
    area = np.prod([n * h for n in shape[:-1]])               # cross-section (unit thickness in 2D)
    want = np.zeros((p.dim, p.dim))
    want[0, 0] = F / area
    np.testing.assert_allclose(sigma[0], np.broadcast_to(want, sigma.shape[1:]), atol=1e-10 * F / area)
    np.testing.assert_allclose(von_mises(sigma[0]), F / area, rtol=1e-10)
    assert sigma.shape == (1,) + shape + (p.dim, p.dim)
    # SIMP interpolation scales the carried stress with E(rho) at a given strain
    half = element_stress(p, np.full(shape, 0.5), U)
    np.testing.assert_allclose(half, sigma * (1e-9 + (1 - 1e-9) * 0.125), rtol=1e-12)
    solid = element_stress(p, np.full(shape, 0.5), U, interpolation="solid")
    np.testing.assert_allclose(solid, sigma, rtol=1e-12)


def test_von_mises_closed_forms():
    rng = np.random.default_rng(7)
    s = rng.normal(size=(5, 2, 2))
    s = s + np.swapaxes(s, -1, -2)
    sxx, syy, sxy = s[:, 0, 0], s[:, 1, 1], s[:, 0, 1]
    np.testing.assert_allclose(von_mises(s), np.sqrt(sxx ** 2 + syy ** 2 - sxx * syy + 3 * sxy ** 2))
    t = rng.normal(size=(5, 3, 3))
    t = t + np.swapaxes(t, -1, -2)
    a, b, c = t[:, 0, 0], t[:, 1, 1], t[:, 2, 2]
    want = np.sqrt(0.5 * ((a - b) ** 2 + (b - c) ** 2 + (c - a) ** 2)
                   + 3 * (t[:, 0, 1] ** 2 + t[:, 1, 2] ** 2 + t[:, 0, 2] ** 2))
    np.testing.assert_allclose(von_mises(t), want)


def test_stress_is_symmetric_and_per_case():
    from engine.topopt import preset, simp_compliance
    p = preset("bridge_2d_multi", 6, objective="compliance")
    r = simp_compliance(p, max_iter=3)
    sigma = element_stress(p, r.rho, r.displacements)
    assert sigma.shape == (5,) + p.shape + (2, 2)
    np.testing.assert_array_equal(sigma, np.swapaxes(sigma, -1, -2))
    with pytest.raises(ValueError, match="rho"):
        element_stress(p, r.rho[:-1], r.displacements)
