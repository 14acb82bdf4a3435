"""Homogenization on a box cell (box voxels h_x x h_y x h_z) against closed
forms: a homogeneous box and exact periodic laminates."""

import math

import numpy as np
import pytest

from engine.physics.elastic import isotropic_stiffness
from engine.physics.hex_element import element_matrices, unit_strain_displacements
from engine.physics.homogenize3d import homogenize_voxels

BOX = (1.0, math.sqrt(3.0), 0.8)


def laminate_stiffness(stiffnesses, fractions, axis):
    """Exact stiffness of a periodic laminate with layers normal to `axis`.

    Strains in the layer plane and tractions on it are continuous, so with
    "O" the Voigt components carrying the traction (normal axis) and "I" the
    in-plane ones: C_OO = <C_OO^-1>^-1, C_IO = <C_IO C_OO^-1> C_OO and
    C_II = <C_II - C_IO C_OO^-1 C_OI> + <C_IO C_OO^-1> C_OO <C_OO^-1 C_OI>.
    """
    out_of_plane = {0: [0, 5, 4], 1: [1, 5, 3], 2: [2, 3, 4]}[axis]
    O = out_of_plane
    I = [i for i in range(6) if i not in O]
    inv = np.linalg.inv

    def avg(f):
        return sum(w * f(np.asarray(C)) for C, w in zip(stiffnesses, fractions))

    Coo = inv(avg(lambda C: inv(C[np.ix_(O, O)])))
    A = avg(lambda C: C[np.ix_(I, O)] @ inv(C[np.ix_(O, O)]))
    Cii = avg(lambda C: C[np.ix_(I, I)] - C[np.ix_(I, O)] @ inv(C[np.ix_(O, O)]) @ C[np.ix_(O, I)]) \
        + A @ Coo @ A.T
    C = np.zeros((6, 6))
    C[np.ix_(O, O)], C[np.ix_(I, I)] = Coo, Cii
    C[np.ix_(I, O)] = A @ Coo
    C[np.ix_(O, I)] = (A @ Coo).T
    return C


def test_box_element_integrates_a_uniform_strain_exactly():
    h = np.array([0.3, 0.7, 0.45])
    D = isotropic_stiffness(2.0, 0.3)
    K, F = element_matrices(D, 3, h)
    U0 = unit_strain_displacements(3, h)
    np.testing.assert_allclose(U0.T @ K @ U0, np.prod(h) * D, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(K @ U0, F, rtol=1e-12, atol=1e-14)
    # rigid translations carry no force
    for a in range(3):
        t = np.zeros(24)
        t[a::3] = 1.0
        assert np.abs(K @ t).max() < 1e-13
    # equal edges are the cubic element
    K1, F1 = element_matrices(D, 3, 0.3)
    Kb, Fb = element_matrices(D, 3, (0.3, 0.3, 0.3))
    np.testing.assert_allclose(Kb, K1, rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(Fb, F1, rtol=1e-14, atol=1e-15)


def test_homogeneous_box_is_the_base_material():
    r = homogenize_voxels(np.ones((6, 10, 5)), E=3.0, nu=0.3, cell=BOX)
    np.testing.assert_allclose(r.C, isotropic_stiffness(3.0, 0.3), rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("axis", [0, 2])
def test_laminate_in_a_box_matches_the_closed_form(axis):
    # 14 x 24 x 10 voxels: large enough that the multigrid path runs.
    shape = (14, 24, 10)
    density = np.ones(shape)
    cut = [slice(None)] * 3
    cut[axis] = slice(0, 4 if axis == 2 else 5)
    density[tuple(cut)] = 0.25
    frac = (4 if axis == 2 else 5) / shape[axis]
    r = homogenize_voxels(density, E=1.0, nu=0.3, cell=BOX, tol=1e-10)
    assert r.levels > 1
    exact = laminate_stiffness([isotropic_stiffness(0.25, 0.3), isotropic_stiffness(1.0, 0.3)],
                               [frac, 1 - frac], axis)
    np.testing.assert_allclose(r.C, exact, atol=1e-8 * exact.max())


def test_cubic_voxels_in_a_box_take_the_plain_path():
    density = np.ones((8, 8, 8))
    density[:, :, :3] = 0.5
    a = homogenize_voxels(density, nu=0.3)
    b = homogenize_voxels(density, nu=0.3, cell=(2, 2, 2))
    assert np.array_equal(a.C, b.C)


@pytest.mark.parametrize("cell, match", [((1, 0, 1), "cell"), ((1, 1), "cell"), (None, "cubic")])
def test_bad_box_is_refused(cell, match):
    with pytest.raises(ValueError, match=match):
        homogenize_voxels(np.ones((4, 4, 5)), cell=cell)
