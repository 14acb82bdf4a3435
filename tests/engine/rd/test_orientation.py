"""Local FFT orientation (4.3.1), and the orientation of grown stripes.

Convention under test: for ``direction=i`` the stripes run perpendicular to
``rotation[..., :, i]`` (u diffuses fastest along it, so that is the
pattern's wave vector).
"""

import numpy as np
import pytest

from engine.rd.diffusion import rotation_from_angle
from engine.rd.gray_scott import RDParams
from engine.rd.growth import grow
from engine.rd.orientation import axial_difference, local_orientation

N = 128
P = RDParams(gamma=5.0)           # wavelength ~9 cells on this grid


def test_plane_waves_are_read_back():
    y, x = np.mgrid[:N, :N] + 0.5
    for deg in (0, 17, 30, 45, 60, 90, 135):
        t = np.radians(deg)
        k = 2 * np.pi / 8.0                  # wave vector along (cos t, sin t)
        img = np.cos(k * (np.cos(t) * x + np.sin(t) * y))
        o = local_orientation(img, patch=11, oversample=16)
        err = np.degrees(axial_difference(o.angle, t + np.pi / 2))
        assert np.median(err) < 2.0 and err.max() < 6.0
        assert np.median(o.wavelength) == pytest.approx(8.0, rel=0.1)
        assert o.strength.min() > 0.8
    flat = local_orientation(np.ones((22, 22)))
    assert np.isnan(flat.angle).all() and (flat.strength == 0).all()
    with pytest.raises(ValueError, match="patch must be"):
        local_orientation(img, patch=2)


def _setup():
    y, x = np.mgrid[:N, :N] + 0.5
    r2 = (x - N / 2) ** 2 + (y - N / 2) ** 2
    rho = (r2 <= (0.48 * N) ** 2).astype(float)
    # patches whose cells all lie a few cells inside the infill boundary
    interior = r2 <= (0.48 * N - 6) ** 2
    return x, y, rho, interior


def _fraction_within(res, expected, interior, tol_deg=10.0):
    o = local_orientation(1.0 - res.u, patch=11, oversample=16, mask=interior)
    use = o.coverage == 1.0
    exp = expected(o.centre[..., 0], o.centre[..., 1])
    err = np.degrees(axial_difference(o.angle, exp))[use]
    assert use.sum() >= 40
    return (err <= tol_deg).mean()


@pytest.mark.parametrize("deg", [0, 30, 45, 60])
def test_grown_stripes_are_perpendicular_to_a_constant_direction(deg):
    x, y, rho, interior = _setup()
    t = np.radians(deg)
    res = grow(rho, rotation_from_angle(np.full((N, N), t)), params=P, max_steps=8000)
    assert _fraction_within(res, lambda cx, cy: np.full(cx.shape, t + np.pi / 2), interior) >= 0.9


@pytest.mark.parametrize("direction", [0, 1])
def test_grown_stripes_follow_a_smoothly_rotating_field(direction):
    # The main direction turns by 60 degrees across the disc, along the stripes
    # of the grown family, so they bend while keeping their spacing. (A field
    # turning across the stripes makes them fan out: spacing must change, and
    # the pattern does so by dislocations, which this check would count.)
    x, y, rho, interior = _setup()
    t0, span = np.radians(30), np.radians(60)
    e = t0 + np.pi / 2 if direction == 0 else t0      # direction the stripes run in

    def theta(cx, cy):
        return t0 + span * (np.cos(e) * (cx - N / 2) + np.sin(e) * (cy - N / 2)) / N

    res = grow(rho, rotation_from_angle(theta(x, y)), direction=direction, params=P, max_steps=12000)
    # direction 0: perpendicular to column 0; direction 1: perpendicular to column 1 = along column 0
    expected = (lambda cx, cy: theta(cx, cy) + np.pi / 2) if direction == 0 else theta
    assert _fraction_within(res, expected, interior) >= 0.9
