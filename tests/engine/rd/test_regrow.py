"""Local erase / draw and regrowth inside a window (paper 6.1 T_2%, 6.9)."""

import time

import numpy as np
import pytest
from scipy import ndimage

from engine.rd.diffusion import rotation_from_angle
from engine.rd.gray_scott import RDParams
from engine.rd.growth import grow
from engine.rd.regrow import brush_region, regrow, solid_state

P = RDParams(gamma=5.0)


def cantilever(nx, ny):
    """Half-ellipse clamped at x = 0 with a stress-like orientation: 45 degrees
    on the neutral axis, turning to the x axis at the top and bottom fibres."""
    y, x = np.mgrid[:ny, :nx] + 0.5
    eta = (y - ny / 2) / (ny / 2)
    rho = ((x / nx) ** 2 + eta ** 2 <= 1.0).astype(float)
    theta = np.pi / 4 * (1 - eta ** 2) * (1 - 0.5 * x / nx)
    return rho, rotation_from_angle(theta)


@pytest.fixture(scope="module")
def grown():
    rho, rot = cantilever(256, 128)
    t0 = time.perf_counter()
    res = grow(rho, rot, params=P, max_steps=40_000)
    return rho, rot, res, time.perf_counter() - t0


def _brush_centres(inside, radius, n, seed):
    ok = ndimage.binary_erosion(inside, iterations=int(radius) + 2)
    cells = np.argwhere(ok)
    pick = np.random.default_rng(seed).choice(len(cells), n, replace=False)
    return cells[pick][:, ::-1] + 0.5          # (x, y) cell centres


def test_erasing_two_percent_regrows_fast_and_only_in_the_window(grown):
    rho, rot, full, _ = grown
    assert full.stop_reason == "converged"
    inside = rho >= 0.5
    radius = np.sqrt(0.02 * inside.sum() / np.pi)          # a disc of 2 % of the infill area
    step_ratios = []
    for centre in _brush_centres(inside, radius, 5, seed=0):
        out = regrow(full.state, rho, rot, centre=centre, radius=radius)
        assert out.stop_reason == "converged"
        assert out.region.sum() == pytest.approx(0.02 * inside.sum(), rel=0.1)
        # nothing outside the window moved, byte for byte
        frozen = np.ones(rho.shape, bool)
        frozen[out.box] = False
        assert frozen.sum() > 0.8 * rho.size
        assert np.array_equal(out.state.u[frozen], full.u[frozen])
        assert np.array_equal(out.state.v[frozen], full.v[frozen])
        # the structure reconnected: the erased disc holds a lattice again
        s = 1.0 - out.state.u[out.region]
        assert 0.3 < (s > 0.5).mean() < 0.8
        assert out.state.step == full.steps + out.steps
        step_ratios.append(out.steps / full.steps)
    # paper 6.1: local reconstruction of 2 % is much faster than a full growth.
    # Steps are the machine-independent measure; wall time (median 0.04-0.15
    # of the full growth here) is measured in tests/bench/bench_rd.py.
    assert np.median(step_ratios) <= 0.2


def test_draw_plants_solid_material_in_the_infill_space(grown):
    rho, rot, full, _ = grown
    us, vs = solid_state(P)
    # the uniform steady state of the reaction at kill rate k (1 - alpha)
    kill = P.k * (1 - P.alpha)
    assert us * vs * vs == pytest.approx(P.F * (1 - us))
    assert us * vs * vs == pytest.approx((kill + P.F) * vs)
    out = regrow(full.state, rho, rot, centre=(5.5, 64.5), radius=8, mode="draw", max_steps=0)
    painted = out.region & (rho >= 0.5)
    assert np.all(out.state.u[painted] == us) and np.all(out.state.v[painted] == vs)
    unpainted = out.region & (rho < 0.5)
    assert np.array_equal(out.state.u[unpainted], full.u[unpainted])
    grown_back = regrow(full.state, rho, rot, centre=(128.5, 64.5), radius=6, mode="draw", margin=8)
    assert grown_back.stop_reason == "converged" and grown_back.steps > 0


def test_regrow_refuses_bad_input(grown):
    rho, rot, full, _ = grown
    with pytest.raises(ValueError, match="mode must be"):
        regrow(full.state, rho, rot, centre=(10, 10), radius=3, mode="smudge")
    with pytest.raises(ValueError, match="give either region"):
        regrow(full.state, rho, rot)
    with pytest.raises(ValueError, match="radius must be a positive"):
        regrow(full.state, rho, rot, centre=(10, 10), radius=0)
    with pytest.raises(ValueError, match="different infill space"):
        regrow(full.state, rho, rotation_from_angle(np.zeros(rho.shape)), centre=(10, 10), radius=3)
    with pytest.raises(ValueError, match="hold no cell of the infill space"):
        regrow(full.state, rho, rot, centre=(250.5, 3.5), radius=2, margin=1)
    region = brush_region(rho.shape, (300.0, 300.0), 2.0)
    assert not region.any()
    with pytest.raises(ValueError, match="no cell of the grid"):
        regrow(full.state, rho, rot, region=region)
