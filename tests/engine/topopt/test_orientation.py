"""Orthotropic orientation optimisation (eq. 19) and the stress-based start angle."""

import numpy as np
import pytest

from engine.physics.elastic import rotate_stiffness
from engine.topopt import element_stress, orthotropic_orientation, preset, stress_orientation
from engine.topopt.assembly import grid_fe
from engine.topopt.design import design_space
from engine.topopt.orientation import orientation_objective, orthotropic_material, rotated_material


def _rot(t):
    return np.array([[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]])


def _voigt(d):
    return np.array([[d[0], d[3], d[4]], [d[3], d[1], d[5]], [d[4], d[5], d[2]]])


def test_rotated_material_matches_tensor_rotation_and_is_three_to_one():
    Q = orthotropic_material(1.0, 0.3)
    S = np.linalg.inv(Q)
    assert (1 / S[0, 0]) / (1 / S[1, 1]) == pytest.approx(3.0)
    for t in (0.0, 0.4, -1.2, 2.9):
        d, dd = rotated_material(Q, np.array([t]))
        np.testing.assert_allclose(_voigt(d[0]), rotate_stiffness(Q, _rot(t)), atol=1e-14)
        h = 1e-6
        fd = (rotated_material(Q, np.array([t + h]))[0] - rotated_material(Q, np.array([t - h]))[0]) / (2 * h)
        np.testing.assert_allclose(dd, fd, atol=1e-8)


def test_objective_gradients_match_finite_differences():
    p = preset("bridge_2d_multi", 4)                                 # 4 x 6 cells, five load cases
    ds = design_space(p)
    rng = np.random.default_rng(10)
    x = rng.uniform(0.3, 0.9, ds.n_design)
    th = rng.uniform(-1.5, 1.5, p.n_cells)
    J, dx, dth, _, comps = orientation_objective(p, x, th)
    assert J == pytest.approx(np.sum(comps ** 8) ** (1 / 8))
    h = 1e-6
    for j in rng.choice(x.size, 4, replace=False):
        e = np.zeros_like(x)
        e[j] = h
        fd = (orientation_objective(p, x + e, th)[0] - orientation_objective(p, x - e, th)[0]) / (2 * h)
        assert dx[j] == pytest.approx(fd, rel=1e-5, abs=1e-8 * np.abs(dx).max())
        e = np.zeros_like(th)
        e[j] = h
        fd = (orientation_objective(p, x, th + e)[0] - orientation_objective(p, x, th - e)[0]) / (2 * h)
        assert dth[j] == pytest.approx(fd, rel=1e-5, abs=1e-8 * np.abs(dth).max())


def test_stress_orientation_finds_the_axis_whatever_the_sign():
    phi = np.array([0.3, -1.0, 1.5])
    n = np.stack([np.cos(phi), np.sin(phi)], axis=-1)
    uni = 2.0 * n[:, :, None] * n[:, None, :]
    small = 0.5 * np.eye(2)[None] * np.ones((3, 1, 1))
    sigma = np.stack([uni + small, -(uni + small)])                  # same axis, opposite sign
    np.testing.assert_allclose(stress_orientation(sigma), phi, atol=1e-12)


def test_single_load_orientation_follows_principal_stress():
    # Pedersen: for one load case the optimal stiff axis is the major principal stress axis.
    p = preset("bridge_2d_single", 16)
    r = orthotropic_orientation(p, max_iter=80)
    Q = orthotropic_material(p.young, p.poisson)
    fe = grid_fe(p)
    U = r.displacements.reshape(1, -1)
    strain = U[0, fe.edofs] @ fe.B.T
    sigma = element_stress(p, r.rho, r.displacements, theta=r.theta)[0].reshape(-1, 2, 2)
    solid = r.rho.ravel() > 0.8
    off = []
    for e in np.flatnonzero(solid):
        t = r.theta.ravel()[e]
        s = rotate_stiffness(Q, _rot(t)) @ strain[e] * r.rho.ravel()[e] ** 3       # independent path
        np.testing.assert_allclose(sigma[e], [[s[0], s[2]], [s[2], s[1]]], rtol=1e-6, atol=1e-12)
        w, v = np.linalg.eigh(sigma[e])
        major = v[:, np.argmax(np.abs(w))]
        off.append(np.degrees(np.arccos(min(1.0, abs(major @ [np.cos(t), np.sin(t)])))))
    assert np.median(off) < 5.0 and np.mean(np.array(off) < 15.0) > 0.8
    assert abs(r.history["volume"][-1] - p.volfrac) < 1e-3


def test_multi_case_design_beats_single_case_design_on_all_cases():
    multi = preset("bridge_2d_multi", 12)
    a = orthotropic_orientation(preset("bridge_2d_single", 12), max_iter=60)
    b = orthotropic_orientation(multi, max_iter=60)
    Ja, _, _, _, ca = orientation_objective(multi, a.x, a.theta.ravel())
    Jb, _, _, _, cb = orientation_objective(multi, b.x, b.theta.ravel())
    assert Jb < 0.8 * Ja and cb.max() / cb.min() < ca.max() / ca.min()
    assert b.theta.shape == multi.shape and np.all(np.abs(b.theta) <= np.pi)


def test_three_dimensional_problem_is_refused():
    with pytest.raises(ValueError, match="2D only"):
        orthotropic_orientation(preset("mbb_3d", 4), max_iter=1)
