"""Elastic constants, notation changes, symmetry classes and bounds checked
against closed forms: isotropic Lame relations, textbook cubic (copper)
formulas, orthotropic compliance built from engineering constants, and the
porous Hashin-Shtrikman expressions written out independently."""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from engine.physics.elastic import (
    compliance, directional_young, directional_young_polar, engineering_constants,
    hashin_shtrikman_bounds, inside_hashin_shtrikman, isotropic_plane_stress, isotropic_stiffness,
    mandel_to_voigt, rotate_stiffness, symmetry_class, tensor_to_voigt, universal_anisotropy_index,
    voigt_reuss_moduli, voigt_to_mandel, voigt_to_tensor, zener_ratio)

# Copper, GPa (e.g. Hirth & Lothe): Zener ratio 2*75.4/47 = 3.21
C11, C12, C44 = 168.4, 121.4, 75.4


def cubic(c11, c12, c44):
    c = np.zeros((6, 6))
    c[:3, :3] = c12
    c[np.arange(3), np.arange(3)] = c11
    c[np.arange(3, 6), np.arange(3, 6)] = c44
    return c


def orthotropic_compliance(Ex, Ey, Ez, nu_xy, nu_yz, nu_xz, Gyz, Gxz, Gxy):
    """Textbook orthotropic S (engineering shear): S_ji = -nu_ij / E_i."""
    s = np.zeros((6, 6))
    s[0, 0], s[1, 1], s[2, 2] = 1 / Ex, 1 / Ey, 1 / Ez
    s[0, 1] = s[1, 0] = -nu_xy / Ex
    s[1, 2] = s[2, 1] = -nu_yz / Ey
    s[0, 2] = s[2, 0] = -nu_xz / Ex
    s[3, 3], s[4, 4], s[5, 5] = 1 / Gyz, 1 / Gxz, 1 / Gxy
    return s


def sym_strain(rng, d=3):
    a = rng.normal(size=(d, d))
    return 0.5 * (a + a.T)


def eng_voigt(e):
    if e.shape == (3, 3):
        return np.array([e[0, 0], e[1, 1], e[2, 2], 2 * e[1, 2], 2 * e[0, 2], 2 * e[0, 1]])
    return np.array([e[0, 0], e[1, 1], 2 * e[0, 1]])


def mandel_vec(e):
    r = math.sqrt(2)
    if e.shape == (3, 3):
        return np.array([e[0, 0], e[1, 1], e[2, 2], r * e[1, 2], r * e[0, 2], r * e[0, 1]])
    return np.array([e[0, 0], e[1, 1], r * e[0, 1]])


def random_spd(rng, n):
    a = rng.normal(size=(n, n))
    return a @ a.T + n * np.eye(n)


# ------------------------------------------------------------------ isotropic

@pytest.mark.parametrize("E,nu", [(200.0, 0.3), (1.0, -0.5), (3.5, 0.0), (70e9, 0.49)])
def test_isotropic_round_trip(E, nu):
    C = isotropic_stiffness(E, nu)
    k = engineering_constants(C)
    for key in ("E_x", "E_y", "E_z", "E_avg"):
        assert k[key] == pytest.approx(E, rel=1e-12)
    for key in ("nu_xy", "nu_yx", "nu_yz", "nu_zy", "nu_xz", "nu_zx", "nu_avg"):
        assert k[key] == pytest.approx(nu, rel=1e-12, abs=1e-14)
    for key in ("G_xy", "G_yz", "G_xz", "G_voigt", "G_reuss"):
        assert k[key] == pytest.approx(E / (2 * (1 + nu)), rel=1e-12)
    assert k["K_voigt"] == pytest.approx(E / (3 * (1 - 2 * nu)), rel=1e-12)
    assert k["K_reuss"] == pytest.approx(E / (3 * (1 - 2 * nu)), rel=1e-12)
    assert symmetry_class(C) == "isotropic"
    assert zener_ratio(C) == pytest.approx(1.0, rel=1e-12)
    assert universal_anisotropy_index(C) == pytest.approx(0.0, abs=1e-12)


def test_isotropic_lame_entries():
    E, nu = 10.0, 0.25
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    C = isotropic_stiffness(E, nu)
    assert C[0, 0] == pytest.approx(lam + 2 * mu) and C[0, 1] == pytest.approx(lam)
    assert C[3, 3] == pytest.approx(mu)  # engineering shear: tau = mu * gamma


@pytest.mark.parametrize("E,nu", [(1.0, 0.3), (5.0, -0.8), (2.0, 0.9)])
def test_plane_stress_round_trip(E, nu):
    C = isotropic_plane_stress(E, nu)
    k = engineering_constants(C)
    assert set(k) >= {"E_x", "E_y", "nu_xy", "nu_yx", "G", "E_avg", "nu_avg"}
    assert "E_z" not in k
    assert k["E_x"] == pytest.approx(E) and k["E_y"] == pytest.approx(E)
    assert k["nu_xy"] == pytest.approx(nu) and k["nu_avg"] == pytest.approx(nu)
    assert k["G"] == pytest.approx(E / (2 * (1 + nu)))
    assert k["K_voigt"] == pytest.approx(E / (2 * (1 - nu)))  # 2D area bulk modulus
    assert k["K_reuss"] == pytest.approx(E / (2 * (1 - nu)))
    assert k["G_voigt"] == pytest.approx(k["G"]) and k["G_reuss"] == pytest.approx(k["G"])
    assert symmetry_class(C) == "isotropic"
    assert zener_ratio(C) == pytest.approx(1.0)
    assert universal_anisotropy_index(C) == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("call,words", [
    (lambda: isotropic_stiffness(0.0, 0.3), ["E", "0.0", "> 0"]),
    (lambda: isotropic_stiffness(-2, 0.3), ["E", "-2"]),
    (lambda: isotropic_stiffness(1, 0.5), ["nu", "(-1, 0.5)", "0.5"]),
    (lambda: isotropic_stiffness(1, -1.0), ["nu", "-1.0"]),
    (lambda: isotropic_stiffness(float("nan"), 0.3), ["E", "finite"]),
    (lambda: isotropic_stiffness("stiff", 0.3), ["E", "'stiff'"]),
    (lambda: isotropic_plane_stress(1, 1.0), ["nu", "(-1, 1.0)", "plane stress"]),
    (lambda: isotropic_plane_stress(-1, 0.2), ["E", "-1"]),
])
def test_isotropic_refusals_name_parameter_and_value(call, words):
    with pytest.raises(ValueError) as err:
        call()
    for w in words:
        assert w in str(err.value)


def test_plane_stress_accepts_nu_beyond_three_d_limit():
    assert isotropic_plane_stress(1, 0.7)[0, 1] == pytest.approx(0.7 / (1 - 0.49))


# --------------------------------------------------------------- notations

@pytest.mark.parametrize("n", [6, 3])
def test_tensor_and_mandel_round_trips(n):
    rng = np.random.default_rng(3)
    C = random_spd(rng, n)
    S = np.linalg.inv(C)
    T = voigt_to_tensor(C)
    d = 3 if n == 6 else 2
    assert T.shape == (d,) * 4
    assert np.allclose(T, T.transpose(1, 0, 2, 3)) and np.allclose(T, T.transpose(0, 1, 3, 2))
    assert np.allclose(T, T.transpose(2, 3, 0, 1))
    assert np.allclose(tensor_to_voigt(T), C, rtol=1e-14, atol=0)
    assert np.allclose(tensor_to_voigt(voigt_to_tensor(S, kind="compliance"), kind="compliance"), S)
    assert np.allclose(mandel_to_voigt(voigt_to_mandel(C)), C, rtol=1e-14, atol=0)
    # Mandel is orthonormal: the inverse of the stiffness is the compliance
    assert np.allclose(np.linalg.inv(voigt_to_mandel(C)), voigt_to_mandel(S, kind="compliance"))
    assert np.allclose(mandel_to_voigt(voigt_to_mandel(S, kind="compliance"), kind="compliance"), S)


@pytest.mark.parametrize("n", [6, 3])
def test_energy_is_the_same_in_every_notation(n):
    rng = np.random.default_rng(11)
    C = random_spd(rng, n)
    d = 3 if n == 6 else 2
    for _ in range(5):
        e = sym_strain(rng, d)
        w_voigt = eng_voigt(e) @ C @ eng_voigt(e)
        w_tensor = np.einsum("ij,ijkl,kl->", e, voigt_to_tensor(C), e)
        w_mandel = mandel_vec(e) @ voigt_to_mandel(C) @ mandel_vec(e)
        assert w_tensor == pytest.approx(w_voigt, rel=1e-12)
        assert w_mandel == pytest.approx(w_voigt, rel=1e-12)
        # complementary energy with the compliance in each notation
        sig_t = np.einsum("ijkl,kl->ij", voigt_to_tensor(C), e)
        sig_v = C @ eng_voigt(e)
        assert np.allclose(sig_v[:d], np.diag(sig_t))
        w_s = np.einsum("ij,ijkl,kl->", sig_t, voigt_to_tensor(np.linalg.inv(C), kind="compliance"), sig_t)
        assert w_s == pytest.approx(sig_v @ np.linalg.inv(C) @ sig_v, rel=1e-10)
        assert w_s == pytest.approx(w_voigt, rel=1e-10)


def test_compliance_convention_shear_factor():
    E, nu = 3.0, 0.2
    S = compliance(isotropic_stiffness(E, nu))
    T = voigt_to_tensor(S, kind="compliance")
    assert S[0, 0] == pytest.approx(T[0, 0, 0, 0]) and S[1, 0] == pytest.approx(T[1, 1, 0, 0])
    assert S[3, 3] == pytest.approx(4 * T[1, 2, 1, 2])
    assert 1 / S[3, 3] == pytest.approx(E / (2 * (1 + nu)))


def test_tensor_without_minor_symmetry_refused():
    T = voigt_to_tensor(isotropic_stiffness(1, 0.3))
    T[0, 1, 0, 0] += 0.1
    with pytest.raises(ValueError, match="minor symmetries"):
        tensor_to_voigt(T)


@pytest.mark.parametrize("bad,words", [
    (np.eye(5), ["shape (5, 5)", "6x6"]),
    (np.array([[1.0, 0.5, 0], [0.0, 1, 0], [0, 0, 1]]), ["symmetric"]),
    (np.diag([1.0, np.nan, 1.0]), ["finite", "(1, 1)"]),
    (np.zeros((6, 6)), ["all zeros"]),
    (np.diag([1.0, 1.0, 0.0]), ["positive definite", "mechanism"]),
    (np.diag([1.0, -1.0, 1.0]), ["positive definite"]),
])
def test_bad_stiffness_refused(bad, words):
    with pytest.raises(ValueError) as err:
        engineering_constants(bad)
    for w in words:
        assert w in str(err.value)


def test_rotation_of_isotropic_is_identity_and_matches_directional_modulus():
    R = Rotation.random(random_state=5).as_matrix()
    C = isotropic_stiffness(2.0, 0.3)
    assert np.allclose(rotate_stiffness(C, R), C, atol=1e-12)
    Cu = cubic(C11, C12, C44)
    Cr = rotate_stiffness(Cu, R)
    d = np.random.default_rng(2).normal(size=(20, 3))
    assert np.allclose(directional_young(Cr, d @ R.T), directional_young(Cu, d), rtol=1e-12)
    with pytest.raises(ValueError, match="orthogonal"):
        rotate_stiffness(Cu, 2 * np.eye(3))


# ------------------------------------------------------------------- cubic

def test_copper_closed_forms():
    C = cubic(C11, C12, C44)
    S = compliance(C)
    E100 = (C11 - C12) * (C11 + 2 * C12) / (C11 + C12)
    E111 = 1 / (S[0, 0] - 2 * (S[0, 0] - S[0, 1] - S[3, 3] / 2) / 3)
    # independent textbook form of E_111
    E111_b = 3 * C44 * (C11 + 2 * C12) / (C11 + 2 * C12 + C44)
    assert E111 == pytest.approx(E111_b, rel=1e-12)
    k = engineering_constants(C)
    assert k["E_x"] == pytest.approx(E100, rel=1e-12) and k["E_avg"] == pytest.approx(E100, rel=1e-12)
    assert k["nu_xy"] == pytest.approx(C12 / (C11 + C12), rel=1e-12)
    assert k["G_xy"] == pytest.approx(C44, rel=1e-12)
    assert k["K_voigt"] == pytest.approx((C11 + 2 * C12) / 3) and k["K_reuss"] == pytest.approx((C11 + 2 * C12) / 3)
    e = directional_young(C, [[1, 0, 0], [0, 1, 0], [1, 1, 1], [-1, 1, -1]])
    assert np.allclose(e, [E100, E100, E111, E111], rtol=1e-12)
    assert directional_young(C, [0, 0, 3.0]) == pytest.approx(E100)
    assert directional_young(S, [[1, 1, 1]], kind="compliance")[0] == pytest.approx(E111)
    assert zener_ratio(C) == pytest.approx(2 * C44 / (C11 - C12)) and round(zener_ratio(C), 1) == 3.2
    assert symmetry_class(C) == "cubic"
    gv = (C11 - C12 + 3 * C44) / 5
    gr = 5 * C44 * (C11 - C12) / (4 * C44 + 3 * (C11 - C12))
    assert universal_anisotropy_index(C) == pytest.approx(5 * (gv / gr - 1), rel=1e-12)


def test_rotated_cubic_is_anisotropic_but_quarter_turn_is_cubic():
    C = cubic(C11, C12, C44)
    R = Rotation.random(random_state=7).as_matrix()
    assert symmetry_class(rotate_stiffness(C, R)) == "anisotropic"
    q = Rotation.from_euler("z", 90, degrees=True).as_matrix()
    assert symmetry_class(rotate_stiffness(C, q)) == "cubic"
    # A^U is a rotational invariant
    assert universal_anisotropy_index(rotate_stiffness(C, R)) == pytest.approx(
        universal_anisotropy_index(C), rel=1e-9)


# ------------------------------------------- tetragonal / orthotropic / 2D

def transversely_isotropic_about_z():
    Ep, Ez, nu_p, nu_pz, Gz = 10.0, 30.0, 0.25, 0.1, 4.0
    return np.linalg.inv(orthotropic_compliance(Ep, Ep, Ez, nu_p, nu_pz, nu_pz,
                                                Gz, Gz, Ep / (2 * (1 + nu_p))))


def test_transversely_isotropic_and_tetragonal_detected_on_any_axis():
    C = transversely_isotropic_about_z()
    assert symmetry_class(C) == "tetragonal"
    for perm in ([1, 2, 0, 4, 5, 3], [2, 0, 1, 5, 3, 4]):  # move the axis to x, then y
        P = np.eye(6)[perm]
        assert symmetry_class(P @ C @ P.T) == "tetragonal"
    T = cubic(100, 40, 30)
    T[2, 2], T[5, 5] = 150, 10  # 4/mmm: C66 != (C11-C12)/2
    T[0, 2] = T[2, 0] = T[1, 2] = T[2, 1] = 20
    T[3, 3] = T[4, 4] = 25
    assert symmetry_class(T) == "tetragonal"
    T[3, 3] = 26  # yz and xz shears differ: no 4-fold axis left
    assert symmetry_class(T) == "orthotropic"


def test_orthotropic_constants_follow_equation_4():
    Ex, Ey, Ez, nu_xy, nu_yz, nu_xz = 10.0, 20.0, 40.0, 0.3, 0.2, 0.1
    Gyz, Gxz, Gxy = 5.0, 6.0, 7.0
    C = np.linalg.inv(orthotropic_compliance(Ex, Ey, Ez, nu_xy, nu_yz, nu_xz, Gyz, Gxz, Gxy))
    k = engineering_constants(C)
    assert (k["E_x"], k["E_y"], k["E_z"]) == pytest.approx((Ex, Ey, Ez), rel=1e-12)
    assert (k["nu_xy"], k["nu_yz"], k["nu_xz"]) == pytest.approx((nu_xy, nu_yz, nu_xz), rel=1e-12)
    assert k["nu_yx"] == pytest.approx(nu_xy * Ey / Ex, rel=1e-12)
    assert (k["G_yz"], k["G_xz"], k["G_xy"]) == pytest.approx((Gyz, Gxz, Gxy), rel=1e-12)
    assert k["E_avg"] == pytest.approx((Ex + Ey + Ez) / 3)
    nus = [k[n] for n in ("nu_xy", "nu_yx", "nu_yz", "nu_zy", "nu_xz", "nu_zx")]
    assert k["nu_avg"] == pytest.approx(sum(nus) / 6)
    assert symmetry_class(C) == "orthotropic"
    assert universal_anisotropy_index(C) > 0


@pytest.mark.parametrize("C", [
    np.linalg.inv(orthotropic_compliance(10, 20, 40, 0.3, 0.2, 0.1, 5, 6, 7)),
    rotate_stiffness(cubic(C11, C12, C44), Rotation.random(random_state=1).as_matrix()),
])
def test_reciprocity(C):
    k = engineering_constants(C)
    for i, j in (("x", "y"), ("y", "z"), ("x", "z")):
        assert k[f"nu_{i}{j}"] / k[f"E_{i}"] == pytest.approx(k[f"nu_{j}{i}"] / k[f"E_{j}"], rel=1e-10)


def test_two_d_symmetry_classes():
    sq = np.array([[10.0, 3.0, 0.0], [3.0, 10.0, 0.0], [0.0, 0.0, 1.0]])
    assert symmetry_class(sq) == "tetragonal"
    assert zener_ratio(sq) == pytest.approx(2 / 7)
    ortho = sq.copy()
    ortho[1, 1] = 12
    assert symmetry_class(ortho) == "orthotropic"
    c, s = math.cos(0.5), math.sin(0.5)
    assert symmetry_class(rotate_stiffness(sq, [[c, -s], [s, c]])) == "anisotropic"
    assert symmetry_class(rotate_stiffness(isotropic_plane_stress(1, 0.3), [[c, -s], [s, c]])) == "isotropic"
    k = engineering_constants(sq)
    S = np.linalg.inv(sq)
    assert k["E_x"] == pytest.approx(1 / S[0, 0]) and k["G"] == pytest.approx(1.0)
    assert k["nu_xy"] == pytest.approx(3 / 10)


def test_symmetry_tolerance_is_relative_to_the_largest_entry():
    C = cubic(C11, C12, C44)
    C2 = C.copy()
    C2[0, 3] = C2[3, 0] = 1e-5 * C11
    assert symmetry_class(C2) == "anisotropic"
    assert symmetry_class(C2, tol=1e-4) == "cubic"
    with pytest.raises(ValueError, match="tol"):
        symmetry_class(C, tol=-1)


# ------------------------------------------------------------------ bounds

def hs_porous_3d(K, G, f):
    # upper bounds of a solid (K, G) with void, reduced by hand from
    # K* = K + (1-f) / (-1/K + 3 f / (3K + 4G)) and the shear analogue
    return 4 * G * K * f / (3 * K * (1 - f) + 4 * G), f * G * (9 * K + 8 * G) / (15 * K + 20 * G - 6 * f * (K + 2 * G))


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.45, -0.5])
def test_hashin_shtrikman_three_d(nu):
    E = 2.0
    K, G = E / (3 * (1 - 2 * nu)), E / (2 * (1 + nu))
    b1 = hashin_shtrikman_bounds(E, nu, 1.0)
    assert (b1["E_upper"], b1["nu_upper"], b1["K_upper"], b1["G_upper"]) == pytest.approx((E, nu, K, G))
    b0 = hashin_shtrikman_bounds(E, nu, 0.0)
    assert (b0["K_upper"], b0["G_upper"], b0["E_upper"]) == (0.0, 0.0, 0.0)
    for f in (0.05, 0.3, 0.7):
        b = hashin_shtrikman_bounds(E, nu, f)
        ku, gu = hs_porous_3d(K, G, f)
        assert b["K_upper"] == pytest.approx(ku, rel=1e-12) and b["G_upper"] == pytest.approx(gu, rel=1e-12)
        assert b["E_upper"] == pytest.approx(9 * ku * gu / (3 * ku + gu), rel=1e-12)
        assert b["K_lower"] == 0 and b["G_lower"] == 0
        assert b["E_upper"] < f * E  # strictly inside Voigt for 0 < f < 1


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.8, -0.6])
def test_hashin_shtrikman_two_d_porous_young_is_f_over_3_minus_2f(nu):
    # Known 2D result: the HS upper Young's modulus of a porous sheet is
    # f E / (3 - 2 f) whatever the solid's Poisson's ratio.
    for f in (0.0, 0.1, 0.5, 1.0):
        b = hashin_shtrikman_bounds(1.5, nu, f, dim=2)
        assert b["E_upper"] == pytest.approx(1.5 * f / (3 - 2 * f), rel=1e-12, abs=1e-15)
    assert hashin_shtrikman_bounds(1.5, nu, 1.0, dim=2)["nu_upper"] == pytest.approx(nu)


def test_hashin_shtrikman_soft_void_matches_original_two_phase_formulas():
    E, nu, Ev, nuv, f = 1.0, 0.3, 1e-3, 0.0, 0.4
    K1, G1 = E / (3 * (1 - 2 * nu)), E / (2 * (1 + nu))
    K2, G2 = Ev / (3 * (1 - 2 * nuv)), Ev / (2 * (1 + nuv))
    f1, f2 = f, 1 - f
    ku = K1 + f2 / (1 / (K2 - K1) + 3 * f1 / (3 * K1 + 4 * G1))
    kl = K2 + f1 / (1 / (K1 - K2) + 3 * f2 / (3 * K2 + 4 * G2))
    gu = G1 + f2 / (1 / (G2 - G1) + 6 * (K1 + 2 * G1) * f1 / (5 * G1 * (3 * K1 + 4 * G1)))
    gl = G2 + f1 / (1 / (G1 - G2) + 6 * (K2 + 2 * G2) * f2 / (5 * G2 * (3 * K2 + 4 * G2)))
    b = hashin_shtrikman_bounds(E, nu, f, void_E=Ev, void_nu=nuv)
    assert (b["K_upper"], b["K_lower"], b["G_upper"], b["G_lower"]) == pytest.approx((ku, kl, gu, gl), rel=1e-10)
    with pytest.raises(ValueError, match="stiffer than the solid"):
        hashin_shtrikman_bounds(E, nu, f, void_E=2.0)


@pytest.mark.parametrize("kw,words", [
    (dict(volume_fraction=1.2), ["volume_fraction", "1.2"]),
    (dict(volume_fraction=-0.1), ["volume_fraction", "-0.1"]),
    (dict(volume_fraction=0.5, dim=4), ["dim", "4"]),
])
def test_hashin_shtrikman_refusals(kw, words):
    with pytest.raises(ValueError) as err:
        hashin_shtrikman_bounds(1.0, 0.3, **kw)
    for w in words:
        assert w in str(err.value)


def test_inside_hashin_shtrikman_on_known_cells():
    E, nu, f = 1.0, 0.3, 0.2
    b = hashin_shtrikman_bounds(E, nu, f)
    at_bound = isotropic_stiffness(b["E_upper"], b["nu_upper"])
    assert inside_hashin_shtrikman(at_bound, E, nu, f)
    over = inside_hashin_shtrikman(1.01 * at_bound, E, nu, f)
    assert not over and "Hashin-Shtrikman" in over.reasons[0]
    assert over.bulk_reuss == pytest.approx(1.01 * b["K_upper"])
    # the unattainable Voigt stiffness passes the Voigt test, fails the bulk one
    voigt = inside_hashin_shtrikman(f * isotropic_stiffness(E, nu), E, nu, f)
    assert not voigt and voigt.voigt_excess == pytest.approx(0, abs=1e-12) and len(voigt.reasons) == 1
    too_stiff = inside_hashin_shtrikman(1.05 * f * isotropic_stiffness(E, nu), E, nu, f)
    assert any("Voigt" in r for r in too_stiff.reasons)
    # simple cubic rods along x, y, z: C_ii = (f/3) E, tiny shear for invertibility
    rods = np.diag([f * E / 3] * 3 + [1e-9] * 3)
    assert inside_hashin_shtrikman(rods, E, nu, f)
    # a stack of plates normal to z (plane-stress in-plane, soft elsewhere)
    plates = np.zeros((6, 6))
    plates[:2, :2] = f * isotropic_plane_stress(E, nu)[:2, :2]
    plates[5, 5] = f * E / (2 * (1 + nu))
    plates[2, 2] = plates[3, 3] = plates[4, 4] = 1e-9
    assert inside_hashin_shtrikman(plates, E, nu, f)


def test_inside_hashin_shtrikman_two_d_and_soft_void():
    E, nu, f = 1.0, 0.3, 0.3
    b = hashin_shtrikman_bounds(E, nu, f, dim=2)
    assert inside_hashin_shtrikman(isotropic_plane_stress(b["E_upper"], b["nu_upper"]), E, nu, f)
    assert not inside_hashin_shtrikman(isotropic_plane_stress(1.02 * b["E_upper"], b["nu_upper"]), E, nu, f)
    square_bars = np.diag([f * E / 2, f * E / 2, 1e-9])  # bars along x and y
    assert inside_hashin_shtrikman(square_bars, E, nu, f)
    # with an ersatz void the Reuss lower bound applies: a too-compliant C fails it
    soft = inside_hashin_shtrikman(1e-6 * isotropic_stiffness(E, nu), E, nu, f, void_E=1e-3)
    assert not soft and any("Reuss" in r for r in soft.reasons)


# ------------------------------------------------------ directional modulus

def test_directional_young_isotropic_and_polar():
    C = isotropic_stiffness(7.0, 0.2)
    d = np.random.default_rng(0).normal(size=(50, 3))
    assert np.allclose(directional_young(C, d), 7.0, rtol=1e-12)
    t = np.linspace(0, 2 * np.pi, 17)
    assert np.allclose(directional_young_polar(isotropic_plane_stress(7.0, 0.2), t), 7.0, rtol=1e-12)
    sq = np.array([[10.0, 3.0, 0.0], [3.0, 10.0, 0.0], [0.0, 0.0, 1.0]])
    S = np.linalg.inv(sq)
    assert directional_young_polar(sq, 0.0) == pytest.approx(1 / S[0, 0])
    assert directional_young_polar(sq, np.pi / 4) == pytest.approx(4 / (S[0, 0] + S[1, 1] + 2 * S[0, 1] + S[2, 2]))


def test_directional_young_refusals():
    C = isotropic_stiffness(1.0, 0.3)
    with pytest.raises(ValueError, match="row 1 is zero"):
        directional_young(C, [[1, 0, 0], [0, 0, 0]])
    with pytest.raises(ValueError, match=r"\(n, 3\)"):
        directional_young(C, [[1, 0]])
    with pytest.raises(ValueError, match="directional_young_polar"):
        directional_young(isotropic_plane_stress(1, 0.3), [[1, 0, 0]])
    with pytest.raises(ValueError, match="3x3"):
        directional_young_polar(C, [0.0])
    with pytest.raises(ValueError, match="kind"):
        directional_young(C, [[1, 0, 0]], kind="stifness")


def test_voigt_reuss_order():
    C = rotate_stiffness(cubic(C11, C12, C44), Rotation.random(random_state=3).as_matrix())
    m = voigt_reuss_moduli(C)
    assert m["K_reuss"] <= m["K_voigt"] * (1 + 1e-12) and m["G_reuss"] <= m["G_voigt"]


def test_inputs_not_modified():
    C = cubic(C11, C12, C44)
    keep = C.copy()
    engineering_constants(C), symmetry_class(C), rotate_stiffness(C, np.eye(3)), voigt_to_mandel(C)
    assert np.array_equal(C, keep)
