"""Element matrices against closed forms derived by hand and exact integration."""

import itertools

import numpy as np
import pytest

from engine.physics.hex_element import (element_matrices, hex_stiffness, hex_strain_loads,
                                        isotropic_stiffness, plane_stress_stiffness,
                                        quad_stiffness, quad_strain_loads,
                                        unit_strain_displacements)


def _lame(E, nu):
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


def _nodes(dim, h=1.0):
    return h * np.array([[(l >> a) & 1 for a in range(dim)] for l in range(2 ** dim)], float)


def _rigid_modes(dim, h=1.0):
    x = _nodes(dim, h) - 0.37 * h            # off-centre origin on purpose
    modes = []
    for a in range(dim):
        t = np.zeros_like(x)
        t[:, a] = 1.0
        modes.append(t.ravel())
    rots = [(0, 1)] if dim == 2 else [(0, 1), (0, 2), (1, 2)]
    for a, b in rots:
        r = np.zeros_like(x)
        r[:, a], r[:, b] = -x[:, b], x[:, a]
        modes.append(r.ravel())
    return np.array(modes).T


def test_isotropic_closed_forms():
    E, nu = 2.5, 0.3
    C = isotropic_stiffness(E, nu)
    f = E / ((1 + nu) * (1 - 2 * nu))
    np.testing.assert_allclose(np.diag(C)[:3], f * (1 - nu), rtol=1e-14)
    np.testing.assert_allclose(C[0, 1], f * nu, rtol=1e-14)
    np.testing.assert_allclose(np.diag(C)[3:], E / (2 * (1 + nu)), rtol=1e-14)
    P = plane_stress_stiffness(E, nu)
    np.testing.assert_allclose(P, E / (1 - nu ** 2) * np.array(
        [[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu) / 2]]), rtol=1e-14)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("nu", [-0.5, 0.0, 0.3, 0.45, 0.49])
def test_rigid_body_modes_span_the_null_space(dim, nu):
    K = hex_stiffness(1.7, nu, h=0.3) if dim == 3 else quad_stiffness(1.7, nu, h=0.3)
    R = _rigid_modes(dim, 0.3)
    assert np.abs(K @ R).max() < 1e-12 * np.abs(K).max()
    w = np.linalg.eigvalsh(K)
    n_rigid = 6 if dim == 3 else 3
    assert np.all(w[:n_rigid] < 1e-12 * w[-1])
    assert np.all(w[n_rigid:] > 1e-3 * w[-1])
    np.testing.assert_array_equal(K, K.T)


def test_hex_entries_match_hand_integration():
    # N0 = (1-x)(1-y)(1-z) on the unit cube:
    # K[0x,0x] = (lam+2mu)/9 + mu/9 + mu/9,
    # K[0x,0y] = (lam+mu) * int (1-x)(1-y)(1-z)^2 = (lam+mu)/12.
    E, nu = 1.3, 0.27
    lam, mu = _lame(E, nu)
    K = hex_stiffness(E, nu)
    np.testing.assert_allclose(K[0, 0], (lam + 4 * mu) / 9, rtol=1e-13)
    np.testing.assert_allclose(K[0, 1], (lam + mu) / 12, rtol=1e-13)
    # Scaling: K of a voxel of side h is h * K(1).
    np.testing.assert_allclose(hex_stiffness(E, nu, h=0.25), 0.25 * K, rtol=1e-13)


def test_quad_entries_match_hand_integration():
    # Plane stress, N0 = (1-x)(1-y): K[0x,0x] = E/(1-nu^2) (1/2 - nu/6),
    # K[0x,0y] = E/(1-nu^2) (1+nu)/2 * 1/4 = E / (8 (1 - nu)).
    E, nu = 2.0, 0.35
    K = quad_stiffness(E, nu)
    np.testing.assert_allclose(K[0, 0], E / (1 - nu ** 2) * (0.5 - nu / 6), rtol=1e-13)
    np.testing.assert_allclose(K[0, 1], E / (8 * (1 - nu)), rtol=1e-13)
    np.testing.assert_allclose(quad_stiffness(E, nu, h=3.0), K, rtol=1e-13)


def _exact_stiffness(D, dim, h):
    """Independent integration: 3-point Gauss-Legendre per axis (exact for the
    degree-2-per-axis integrands as well) with its own strain operator."""
    pts, wts = np.polynomial.legendre.leggauss(3)
    pts, wts = 0.5 * (pts + 1) * h, 0.5 * wts * h
    nodes = _nodes(dim)
    nde = 2 ** dim * dim
    K = np.zeros((nde, nde))
    for idx in itertools.product(range(3), repeat=dim):
        x = pts[list(idx)] / h
        w = np.prod(wts[list(idx)])
        grad = np.zeros((2 ** dim, dim))
        for l, b in enumerate(nodes):
            f = np.where(b == 1, x, 1 - x)
            df = np.where(b == 1, 1.0, -1.0) / h
            for a in range(dim):
                grad[l, a] = df[a] * np.prod(np.delete(f, a))
        rows = [(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)] if dim == 3 else \
            [(0, 0), (1, 1), (0, 1)]
        B = np.zeros((len(rows), nde))
        for k, (a, b) in enumerate(rows):
            for l in range(2 ** dim):
                if a == b:
                    B[k, l * dim + a] = grad[l, a]
                else:
                    B[k, l * dim + a] = grad[l, b]
                    B[k, l * dim + b] = grad[l, a]
        K += w * B.T @ D @ B
    return K


@pytest.mark.parametrize("dim", [2, 3])
def test_matches_independent_quadrature(dim):
    D = isotropic_stiffness(1.0, 0.41) if dim == 3 else plane_stress_stiffness(1.0, 0.41)
    K, _ = element_matrices(D, dim, h=0.5)
    np.testing.assert_allclose(K, _exact_stiffness(D, dim, 0.5), atol=1e-13 * np.abs(K).max())


@pytest.mark.parametrize("dim", [2, 3])
def test_patch_test_and_homogeneous_energy(dim):
    """A linear field u = A x + c: K u equals the strain loads times its strain,
    and u.K u equals volume * eps.C.eps."""
    rng = np.random.default_rng(3)
    h, E, nu = 0.7, 3.0, 0.33
    D = isotropic_stiffness(E, nu) if dim == 3 else plane_stress_stiffness(E, nu)
    K, F = element_matrices(D, dim, h)
    A = rng.normal(size=(dim, dim))
    u = (_nodes(dim, h) @ A.T + rng.normal(size=dim)).ravel()
    sym = 0.5 * (A + A.T)
    if dim == 3:
        eps = np.array([sym[0, 0], sym[1, 1], sym[2, 2],
                        2 * sym[1, 2], 2 * sym[0, 2], 2 * sym[0, 1]])
    else:
        eps = np.array([sym[0, 0], sym[1, 1], 2 * sym[0, 1]])
    np.testing.assert_allclose(K @ u, F @ eps, atol=1e-12 * np.abs(K @ u).max())
    np.testing.assert_allclose(u @ K @ u, h ** dim * eps @ D @ eps, rtol=1e-12)
    # The unit-strain displacements reproduce the strain loads.
    U0 = unit_strain_displacements(dim, h)
    np.testing.assert_allclose(K @ U0, F, atol=1e-12 * np.abs(F).max())


def test_strain_load_shortcuts():
    np.testing.assert_allclose(hex_strain_loads(2.0, 0.3),
                               element_matrices(isotropic_stiffness(2.0, 0.3), 3)[1])
    np.testing.assert_allclose(quad_strain_loads(2.0, 0.3),
                               element_matrices(plane_stress_stiffness(2.0, 0.3), 2)[1])


@pytest.mark.parametrize("E, nu", [(0.0, 0.3), (-1.0, 0.3), (np.nan, 0.3), (1.0, 0.5),
                                   (1.0, -1.0), (1.0, np.nan)])
def test_bad_material_refused(E, nu):
    with pytest.raises(ValueError, match="E must|nu must"):
        hex_stiffness(E, nu)
