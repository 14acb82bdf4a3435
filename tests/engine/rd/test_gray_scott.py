"""The fused Gray-Scott step against the plain numpy reference, and its inputs."""

import numpy as np
import pytest

from engine.rd.diffusion import (diffusion_tensors, rotation_from_angle, upsample_field,
                                 upsample_rotation)
from engine.rd.gray_scott import RDParams, gray_scott_step, operator_rate, resolve_params, stability_limit
from engine.rd.reference import gray_scott_step_reference


def _random_rotations(rng, shape):
    """Proper rotations, one per cell (QR of Gaussian matrices)."""
    d = len(shape)
    q, r = np.linalg.qr(rng.normal(size=shape + (d, d)))
    q = q * np.sign(np.diagonal(r, axis1=-2, axis2=-1))[..., None, :]
    q[..., :, 0] *= np.sign(np.linalg.det(q))[..., None]
    return q


def _case(shape, seed):
    rng = np.random.default_rng(seed)
    sigma = diffusion_tensors(_random_rotations(rng, shape), direction=int(seed) % len(shape), xi=5.0)
    u = rng.uniform(0.1, 1.0, shape)
    v = rng.uniform(0.0, 0.6, shape)
    inside = rng.random(shape) < 0.7          # cells outside feel the absorbing term
    gamma_map = rng.random(shape)
    return u, v, sigma, inside, gamma_map


@pytest.mark.parametrize("shape", [(13, 17), (6, 7, 9), (1, 5), (9, 1)])
def test_fused_step_equals_the_numpy_reference(shape):
    u, v, sigma, inside, gmap = _case(shape, 3)
    p = RDParams(gamma=2.0, lambda_=1.5)
    fu, fv = gray_scott_step(u, v, sigma, inside=inside, gamma_map=gmap, params=p, steps=1)
    ru, rv = gray_scott_step_reference(u, v, sigma, inside=inside, gamma_map=gmap, params=p)
    assert np.abs(fu - ru).max() < 1e-12 and np.abs(fv - rv).max() < 1e-12
    assert not np.array_equal(fu, u)
    # several steps in one call == the reference iterated
    fu, fv = gray_scott_step(u, v, sigma, inside=inside, gamma_map=gmap, params=p, steps=5)
    ru, rv = u, v
    for _ in range(5):
        ru, rv = gray_scott_step_reference(ru, rv, sigma, inside=inside, gamma_map=gmap, params=p)
    assert np.abs(fu - ru).max() < 1e-12 and np.abs(fv - rv).max() < 1e-12


@pytest.mark.parametrize("shape, box", [((20, 24), ((4, 15), (0, 9))), ((40, 12), ((1, 39), (3, 12))),
                                        ((8, 10, 12), ((0, 5), (3, 10), (2, 12))),
                                        ((20, 9, 7), ((2, 19), (0, 9), (1, 6)))])
def test_inputs_are_not_modified_and_a_box_freezes_the_rest(shape, box):
    u, v, sigma, inside, gmap = _case(shape, 5)
    u0, v0 = u.copy(), v.copy()
    fu, fv = gray_scott_step(u, v, sigma, inside=inside, gamma_map=gmap, steps=1, box=box)
    assert np.array_equal(u, u0) and np.array_equal(v, v0)
    ru, rv = gray_scott_step_reference(u, v, sigma, inside=inside, gamma_map=gmap)
    sl = tuple(slice(a, b) for a, b in box)
    assert np.abs(fu[sl] - ru[sl]).max() < 1e-12 and np.abs(fv[sl] - rv[sl]).max() < 1e-12
    outside = np.ones(u.shape, bool)
    outside[sl] = False
    assert np.array_equal(fu[outside], u[outside]) and np.array_equal(fv[outside], v[outside])
    # several steps: the reference with the outside reset after every step
    fu, fv = gray_scott_step(u, v, sigma, inside=inside, gamma_map=gmap, steps=5, box=box)
    ru, rv = u, v
    for _ in range(5):
        ru, rv = gray_scott_step_reference(ru, rv, sigma, inside=inside, gamma_map=gmap)
        ru[outside], rv[outside] = u[outside], v[outside]
    assert np.abs(fu - ru).max() < 1e-12 and np.abs(fv - rv).max() < 1e-12


def test_zero_flux_boundary_conserves_u_under_pure_diffusion():
    # F = 0 and v = 0 leave only (sigma grad) . grad u; for a grid-aligned
    # tensor its sum is conserved exactly through mirrored edge cells
    rng = np.random.default_rng(1)
    shape = (16, 21)
    sigma = diffusion_tensors(rotation_from_angle(np.full(shape, np.pi / 2)), direction=0)
    sigma[..., 0, 1] = sigma[..., 1, 0] = 0.0
    u = rng.random(shape)
    fu, fv = gray_scott_step(u, np.zeros(shape), sigma, inside=np.ones(shape, bool),
                             params=RDParams(F=0.0, k=0.0), steps=20)
    assert abs(fu.sum() - u.sum()) < 1e-10 * u.size
    assert fu.std() < u.std()                 # it did diffuse
    assert np.all(fv == 0.0)


def test_the_empty_state_is_exact_and_tiny_v_is_flushed():
    shape = (8, 9)
    sigma = diffusion_tensors(rotation_from_angle(np.zeros(shape)), direction=0)
    u, v = np.ones(shape), np.zeros(shape)
    fu, fv = gray_scott_step(u, v, sigma, inside=np.ones(shape, bool), steps=7)
    assert np.all(fu == 1.0) and np.all(fv == 0.0)
    v[4, 4] = 1e-200
    fu, fv = gray_scott_step(u, v, sigma, inside=np.ones(shape, bool), steps=1)
    assert np.all(fv == 0.0)


def test_diffusion_tensors_follow_eq_11():
    theta = np.array([[0.0, 0.5], [1.0, -2.0]])
    r = rotation_from_angle(theta)
    for i in (0, 1):
        s = diffusion_tensors(r, direction=i, xi=5.0)
        assert np.allclose(np.trace(s, axis1=-2, axis2=-1), 1.0)
        main = r[..., :, i]
        assert np.allclose(np.einsum("...ij,...j->...i", s, main), 5.0 / 6.0 * main)
        other = r[..., :, 1 - i]
        assert np.allclose(np.einsum("...ij,...j->...i", s, other), 1.0 / 6.0 * other)
    r3 = _random_rotations(np.random.default_rng(0), (2, 2, 3))
    s3 = diffusion_tensors(r3, direction=2, xi=5.0)
    assert np.allclose(np.linalg.eigvalsh(s3), [1 / 7, 1 / 7, 5 / 7])


def test_upsampling():
    # linear fields are reproduced exactly away from the edges (cell-centred)
    y, x = np.mgrid[:6, :8] + 0.5
    fine = upsample_field(2 * x + 3 * y, (24, 32))
    fy, fx = np.mgrid[:24, :32] + 0.5
    exact = 2 * fx / 4 + 3 * fy / 4
    assert np.allclose(fine[2:-2, 2:-2], exact[2:-2, 2:-2])
    # rotations: interpolate the tensor, re-diagonalise -> orthonormal, det +1,
    # angles in between the coarse ones; sign flips of a column do not matter
    theta = np.linspace(0.0, 1.0, 4)[None, :].repeat(3, axis=0)
    r = rotation_from_angle(theta)
    r[0, 1, :, 0] *= -1                       # same direction, other sign
    r[0, 1, :, 1] *= -1
    up = upsample_rotation(r, (12, 16))
    assert np.allclose(np.swapaxes(up, -1, -2) @ up, np.eye(2), atol=1e-12)
    assert np.allclose(np.linalg.det(up), 1.0)
    angle = np.mod(np.arctan2(up[..., 1, 0], up[..., 0, 0]), np.pi)
    assert np.all(np.diff(angle, axis=1) >= -1e-12)
    assert angle.min() >= -1e-12 and angle.max() <= 1.0 + 1e-12


def test_stability_limit_and_refusals():
    shape = (6, 6)
    sigma = diffusion_tensors(rotation_from_angle(np.full(shape, np.pi / 4)), direction=0)
    # Gershgorin bound of the stencil at 45 degrees: 4 tr + 2 |s_xy| = 4 + 2/3
    assert np.allclose(operator_rate(sigma, 1.0), 4.0 + 2.0 / 3.0)
    dt_max, why = stability_limit(sigma, RDParams())
    assert dt_max == pytest.approx(2.0 / (4.0 + 2.0 / 3.0)) and "diffusion of u" in why
    assert resolve_params(sigma, RDParams()).dt == pytest.approx(0.9 * dt_max)
    assert resolve_params(sigma, RDParams(gamma=5.0)).dt == pytest.approx(0.9 / 5.0)
    # the paper's Table 3 setting (dt = 1.1 at dx = 1.7) is accepted
    resolve_params(sigma, RDParams(dt=1.1, dx=1.7))
    u, v, inside = np.ones(shape), np.zeros(shape), np.ones(shape, bool)
    with pytest.raises(ValueError, match=r"dt = 0.5 is unstable.*diffusion of u"):
        gray_scott_step(u, v, sigma, inside=inside, params=RDParams(dt=0.5))
    with pytest.raises(ValueError, match=r"gamma dt <= 1.35"):
        gray_scott_step(u, v, sigma, inside=inside, params=RDParams(gamma=10.0, dt=0.2))
    bad = sigma.copy()
    bad[2, 3, 0, 1] += 0.1
    with pytest.raises(ValueError, match=r"sigma is not symmetric at cell \[y=2, x=3\]"):
        gray_scott_step(u, v, bad, inside=inside)
    bad = sigma.copy()
    bad[1, 4, 1, 1] = np.nan
    with pytest.raises(ValueError, match=r"sigma has a NaN .* at cell \[y=1, x=4\]"):
        gray_scott_step(u, v, bad, inside=inside)
    with pytest.raises(ValueError, match=r"RDParams.alpha"):
        gray_scott_step(u, v, sigma, inside=inside, params=RDParams(alpha=2.0))
    with pytest.raises(ValueError, match=r"gamma_map"):
        gray_scott_step(u, v, sigma, inside=inside, gamma_map=np.full(shape, 1.5))
