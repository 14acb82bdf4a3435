"""Growth: confinement, infill map, stopping, exact save / resume / cancel, refusals."""

import time

import numpy as np
import pytest
from scipy import ndimage

from engine.rd.diffusion import diffusion_tensors, rotation_from_angle
from engine.rd.gray_scott import RDParams, gray_scott_step
from engine.rd.growth import grow, load_state, place_seeds, save_state
from engine.rd.regrow import solid_state

N = 80
P = RDParams(gamma=5.0)                     # stripes ~9 cells apart on this grid


def _disc(n=N, frac=0.45):
    y, x = np.mgrid[:n, :n] + 0.5
    return ((x - n / 2) ** 2 + (y - n / 2) ** 2 <= (frac * n) ** 2).astype(float)


def _rotation(n=N, theta=0.5):
    y, x = np.mgrid[:n, :n] + 0.5
    return rotation_from_angle(theta + 0.3 * x / n)


@pytest.fixture(scope="module")
def grown():
    rho, rot = _disc(), _rotation()
    gmap = np.zeros((N, N))
    gmap[32:48, 30:50] = 1.0
    return rho, rot, gmap, grow(rho, rot, gamma_map=gmap, params=P, max_steps=20_000)


def test_growth_stays_in_the_infill_space_and_fills_gamma_regions_solid(grown):
    rho, _, gmap, res = grown
    assert res.stop_reason == "converged"
    inside = rho >= 0.5
    s = 1.0 - res.u
    # a lattice inside: both phases present, roughly half solid
    assert 0.3 < (s[inside] > 0.5).mean() < 0.8
    # v is absorbed outside: beyond two cells it is negligible, no structure there
    away = ~ndimage.binary_dilation(inside, iterations=2)
    assert res.v[away].max() < 1e-3 and s[away].max() < 0.5
    # Gamma = 1 lowers the kill rate: that block is uniformly solid (the state
    # regrow's "draw" uses), away from its edges
    us, vs = solid_state(res.state.params)
    core = (slice(35, 45), slice(33, 47))
    assert np.allclose(res.u[core], us, atol=0.02) and np.allclose(res.v[core], vs, atol=0.02)
    assert (s[core] > 0.8).all()


def test_stopping_criterion_and_step_limit(grown):
    rho, rot, gmap, res = grown
    h = res.history
    assert res.stop_step == res.steps == int(h[-1, 0]) and res.stop_g == h[-1, 1] < 1e-7
    assert np.all(h[:-1, 1] >= 1e-7)          # it fired at the first check below eps
    assert np.all(np.diff(h[:, 0]) == 50)
    assert h[:20, 1].max() > 1e-4             # growth phase
    assert res.time == pytest.approx(res.steps * res.state.params.dt)
    capped = grow(rho, rot, gamma_map=gmap, params=P, max_steps=1234)
    assert capped.stop_reason == "max_steps" and capped.steps == 1234


def test_skipping_empty_cells_is_exact():
    # grow() only updates the cells the pattern can have reached; the result must
    # equal stepping the whole grid
    rho, rot = _disc(), _rotation()
    start = grow(rho, rot, params=P, max_steps=0, seeds=[(20.5, 30.5)], seed_radius=3)
    assert start.steps == 0 and start.v.sum() > 0
    res = grow(rho, rot, params=P, max_steps=700, seeds=[(20.5, 30.5)], seed_radius=3, check_every=100)
    sigma = diffusion_tensors(rot, direction=0, xi=P.xi)
    u, v = gray_scott_step(start.u, start.v, sigma, inside=rho >= 0.5, params=res.state.params, steps=700)
    assert np.array_equal(res.u, u) and np.array_equal(res.v, v)


def test_save_then_resume_equals_an_uninterrupted_growth(tmp_path):
    rho, rot = _disc(), _rotation()
    whole = grow(rho, rot, params=P, max_steps=1530, eps=1e-12)
    first = grow(rho, rot, params=P, max_steps=1000, eps=1e-12)
    save_state(first.state, tmp_path / "state.npz")
    loaded = load_state(tmp_path / "state.npz")
    assert loaded.params == first.state.params and loaded.step == 1000
    again = grow(rho, rot, state=loaded, max_steps=1530, eps=1e-12)
    assert np.array_equal(again.u, whole.u) and np.array_equal(again.v, whole.v)
    assert np.array_equal(again.history, whole.history) and again.time == whole.time
    with pytest.raises(ValueError, match="different infill space"):
        grow(_disc(frac=0.4), rot, state=loaded, max_steps=1100)
    with pytest.raises(ValueError, match="seeds and state are exclusive"):
        grow(rho, rot, state=loaded, seeds=2)
    (tmp_path / "junk.npz").write_bytes(b"not a state")
    with pytest.raises(ValueError, match="junk.npz: not a reaction/diffusion state"):
        load_state(tmp_path / "junk.npz")


def test_cancel_keeps_the_last_complete_step():
    rho, rot = _disc(), _rotation()
    calls = []

    def progress(done, total):
        # slower than the reporting interval, so every chunk reports
        time.sleep(0.05)
        calls.append(done)
        return len(calls) < 3

    res = grow(rho, rot, params=P, max_steps=50_000, progress=progress)
    assert res.stop_reason == "cancelled" and 0 < res.steps == calls[-1] < 50_000
    plain = grow(rho, rot, params=P, max_steps=res.steps)
    assert np.array_equal(res.u, plain.u) and np.array_equal(res.v, plain.v)
    target = res.steps + 300
    resumed = grow(rho, rot, state=res.state, max_steps=target, eps=1e-12)
    straight = grow(rho, rot, params=P, max_steps=target, eps=1e-12)
    assert np.array_equal(resumed.u, straight.u)


def test_seeds():
    inside = _disc() >= 0.5
    a = place_seeds(inside, seeds=6, radius=3.0, rng=7)
    b = place_seeds(inside, seeds=6, radius=3.0, rng=np.random.default_rng(7))
    assert np.array_equal(a, b) and a.shape == (6, 2)
    gaps = np.sqrt(((a[:, None] - a[None]) ** 2).sum(-1))[np.triu_indices(6, 1)]
    assert gaps.min() >= 12.0
    cells = np.floor(a[:, ::-1]).astype(int)
    assert inside[tuple(cells.T)].all()
    centre = place_seeds(inside)
    assert np.allclose(centre, [[40.5, 40.5]], atol=1.0)
    res = grow(_disc(), _rotation(), params=P, seeds=a, seed_radius=3, max_steps=0)
    assert np.array_equal(res.seeds, a) and (res.v == 1.0).sum() == 6 * 29


def test_bad_input_is_refused_with_a_message_naming_it():
    rho, rot = _disc(), _rotation()
    with pytest.raises(ValueError, match=r"infill space \{rho >= iso\} is empty"):
        grow(np.zeros((N, N)), rot)
    with pytest.raises(ValueError, match=r"seeds\[1\] at \(1.5, 1.5\) lies outside the infill space"):
        grow(rho, rot, seeds=[(40.5, 40.5), (1.5, 1.5)])
    with pytest.raises(ValueError, match=r"seeds\[0\] .* outside the grid"):
        grow(rho, rot, seeds=[(-3.0, 40.0)])
    with pytest.raises(ValueError, match=r"RDParams.dt = 0.8 is unstable"):
        grow(rho, rot, params=RDParams(dt=0.8))
    bad = rot.copy()
    bad[5, 6, 0, 0] = np.nan
    with pytest.raises(ValueError, match=r"rotation has a NaN .* cell \[y=5, x=6\]"):
        grow(rho, bad)
    bad = rot.copy()
    bad[7, 2] *= 2.0
    with pytest.raises(ValueError, match=r"rotation is not orthonormal at cell \[y=7, x=2\]"):
        grow(rho, bad)
    with pytest.raises(ValueError, match=r"direction must be"):
        grow(rho, rot, direction=2)
    with pytest.raises(ValueError, match=r"iso must be"):
        grow(rho, rot, iso=1.5)
    with pytest.raises(ValueError, match=r"max_steps must be"):
        grow(rho, rot, max_steps=-1)


def test_3d_growth_makes_sheets():
    n = 24
    rho = np.ones((n, n, n))
    rot = np.broadcast_to(np.eye(3), (n, n, n, 3, 3))
    res = grow(rho, rot, direction=2, params=P, max_steps=1500, seed_radius=3)
    s = 1.0 - res.u
    assert (s > 0.5).any() and (s < 0.5).any()
    # sheets perpendicular to z (fast diffusion along z): s varies along z, hardly within a plane
    centre = s[:, 6:18, 6:18]
    along_z = centre.mean(axis=(1, 2)).std()
    within = centre.std(axis=(1, 2)).mean()
    assert along_z > 3 * within
