"""Element matrices against numerical quadrature, and the grid numbering."""

import numpy as np
import pytest

from engine.physics.hex_element import element_matrices, isotropic_stiffness, quad_stiffness
from engine.topopt.fe2d import element_dofs_2d, q4_centre_strain, q4_stiffness, q4_stiffness_basis
from engine.topopt.fe3d import element_dofs_3d, h8_centre_strain, h8_stiffness

from ._reference import gauss_q4, plane_stress


def _random_spd(rng, n=3):
    A = rng.normal(size=(n, n))
    return A @ A.T + n * np.eye(n)


@pytest.mark.parametrize("n_gauss", [2, 3])
def test_q4_equals_gauss_quadrature(n_gauss):
    rng = np.random.default_rng(0)
    for D in (plane_stress(2.0, 0.3), plane_stress(1.0, -0.4), _random_spd(rng)):
        np.testing.assert_allclose(q4_stiffness(D), gauss_q4(D, n_gauss), rtol=1e-13, atol=1e-13)


def test_q4_equals_physics_quad_and_has_rigid_modes():
    D = plane_stress(1.0, 0.3)
    K = q4_stiffness(D)
    np.testing.assert_allclose(K, quad_stiffness(1.0, 0.3), atol=1e-14)
    w = np.linalg.eigvalsh(K)
    assert np.sum(np.abs(w) < 1e-12) == 3 and w.min() > -1e-12


def test_q4_basis_is_linear_in_D():
    rng = np.random.default_rng(1)
    D = _random_spd(rng)
    coeff = [D[0, 0], D[1, 1], D[2, 2], D[0, 1], D[0, 2], D[1, 2]]
    np.testing.assert_allclose(np.tensordot(coeff, q4_stiffness_basis(), 1), q4_stiffness(D), atol=1e-13)


def test_centre_strain_is_exact_for_linear_fields():
    rng = np.random.default_rng(2)
    for dim, B, nodes in ((2, q4_centre_strain(0.5), 2), (3, h8_centre_strain(0.5), 3)):
        G = rng.normal(size=(dim, dim))                     # u = G x
        pos = 0.5 * np.array([[(l >> a) & 1 for a in range(dim)] for l in range(2 ** dim)], float)
        u = (pos @ G.T).ravel()
        eps = 0.5 * (G + G.T)
        want = ([eps[0, 0], eps[1, 1], 2 * eps[0, 1]] if dim == 2 else
                [eps[0, 0], eps[1, 1], eps[2, 2], 2 * eps[1, 2], 2 * eps[0, 2], 2 * eps[0, 1]])
        np.testing.assert_allclose(B @ u, want, atol=1e-13)


def test_h8_is_the_physics_hex_and_scales_with_h():
    K = h8_stiffness(1.0, 0.3, 2.0)
    np.testing.assert_allclose(K, element_matrices(isotropic_stiffness(1.0, 0.3), 3, 2.0)[0])
    np.testing.assert_allclose(K, 2.0 * h8_stiffness(1.0, 0.3, 1.0))


@pytest.mark.parametrize("shape", [(3, 4), (2, 3, 4)])
def test_element_dofs_follow_node_coordinates(shape):
    dim = len(shape)
    edofs = element_dofs_2d(*shape) if dim == 2 else element_dofs_3d(*shape)
    nx, ny = shape[-1] + 1, shape[-2] + 1

    def coords(node):                                      # (x, y[, z]) of a node id
        return (node % nx, (node // nx) % ny, node // (nx * ny))[:dim]

    for e, cell in enumerate(np.ndindex(*shape)):
        corner = np.array(cell[::-1])                      # (x, y[, z]) of the cell
        for l in range(2 ** dim):
            bits = np.array([(l >> a) & 1 for a in range(dim)])
            dofs = edofs[e, l * dim:(l + 1) * dim]
            node = dofs[0] // dim
            assert list(dofs) == [dim * node + a for a in range(dim)]
            assert tuple(coords(node)) == tuple(corner + bits)
