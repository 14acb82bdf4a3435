"""SIMP compliance: dense reference, finite differences, textbook layouts, symmetry."""

import numpy as np
import pytest

from engine.progress import Cancelled
from engine.topopt import preset, simp_compliance
from engine.topopt.assembly import grid_fe
from engine.topopt.design import design_space
from engine.topopt.simp import compliance_and_gradient

from ._reference import dense_compliance, reference_simp


def _tiny():
    return preset("cantilever_2d", 4, rmin_fraction=0.5)         # 4 x 8 cells, rmin 2


def test_compliance_and_gradient_match_dense_reference():
    p = _tiny()
    x = np.random.default_rng(3).uniform(0.1, 1.0, p.n_cells)
    c, dc, U, comps = compliance_and_gradient(p, x)
    c_ref, dc_ref = dense_compliance(p, x.reshape(p.shape))
    assert c == pytest.approx(c_ref, rel=1e-10)
    np.testing.assert_allclose(dc, dc_ref, rtol=1e-9, atol=1e-12 * abs(dc_ref).max())


def test_gradient_matches_finite_differences_with_passive_cells():
    p = preset("lbeam_2d", 8)
    ds = design_space(p)
    x = np.random.default_rng(4).uniform(0.2, 0.9, ds.n_design)
    _, dc, _, _ = compliance_and_gradient(p, x)
    h = 1e-6
    for j in np.random.default_rng(5).choice(x.size, 6, replace=False):
        e = np.zeros_like(x)
        e[j] = h
        fd = (compliance_and_gradient(p, x + e)[0] - compliance_and_gradient(p, x - e)[0]) / (2 * h)
        assert dc[j] == pytest.approx(fd, rel=1e-5)


def test_multigrid_solve_equals_direct():
    for p in (preset("cantilever_2d", 40), preset("mbb_3d", 8, aspect=2, depth=0.5)):
        fe, ds = grid_fe(p), design_space(p)
        rho = ds.density(np.random.default_rng(6).uniform(0.0, 1.0, ds.n_design))
        s = ds.stiffness_scale(rho)[0]
        Ud = fe.solve(s, method="direct")
        Um = fe.solve(s, method="mgcg", rtol=1e-10)
        assert np.linalg.norm(Um - Ud) <= 1e-7 * np.linalg.norm(Ud)


def test_cantilever_matches_straightforward_reference_run():
    p = preset("cantilever_2d", 30)                              # 30 x 60
    ours = simp_compliance(p, max_iter=120)
    rho_ref, c_ref, _ = reference_simp(p, max_iter=120)
    assert ours.objective == pytest.approx(c_ref, rel=0.02)
    assert np.mean(np.abs(ours.rho - rho_ref)) < 0.03
    assert abs(ours.rho.mean() - p.volfrac) < 1e-3
    # textbook layout: symmetric about mid-height, solid at both clamped corners
    # and at the load point, most of the plate either void or solid
    assert np.mean(np.abs(ours.rho - ours.rho[::-1])) < 0.02
    assert ours.rho[0, 0] > 0.9 and ours.rho[-1, 0] > 0.9 and ours.rho[14:16, -1].min() > 0.9
    assert np.mean(ours.rho < 0.1) > 0.4 and np.mean(ours.rho > 0.9) > 0.2


@pytest.mark.parametrize("dim", [2, 3])
def test_mbb_half_and_full_agree(dim):
    if dim == 2:
        half = simp_compliance(preset("mbb_2d", 12, volfrac=0.5), max_iter=80)
        full = simp_compliance(preset("mbb_2d", 12, volfrac=0.5, half=False, aspect=6.0), max_iter=80)
    else:
        half = simp_compliance(preset("mbb_3d", 4, aspect=3, depth=1), max_iter=40)
        full = simp_compliance(preset("mbb_3d", 4, aspect=6, depth=1, half=False), max_iter=40)
    rho = full.rho
    assert np.abs(rho - rho[..., ::-1]).max() < 1e-6                 # symmetric problem, symmetric design
    # half the beam under half the load stores half the energy
    assert 2 * half.objective == pytest.approx(full.objective, rel=0.05)
    for r in (half, full):
        assert abs(r.history["volume"][-1] - r.problem.volfrac) < 1e-3
        assert abs(r.rho[r.problem.passive != -1].mean() - r.problem.volfrac) < 1e-3
    if dim == 3:                                                      # depth-symmetric too
        assert np.abs(rho - rho[::-1]).max() < 1e-6


def test_progress_reports_and_cancels():
    p = _tiny()
    seen = []
    simp_compliance(p, max_iter=5, tol=0.0, progress=lambda d, t: seen.append((d, t)) or True)
    assert seen[0] == (0, 5) and seen[-1] == (5, 5)
    with pytest.raises(Cancelled):
        simp_compliance(p, max_iter=50, progress=lambda d, t: d < 3)


def test_same_input_same_bytes_and_read_only_result():
    p = preset("cantilever_2d", 8)
    a, b = simp_compliance(p, max_iter=10), simp_compliance(preset("cantilever_2d", 8), max_iter=10)
    assert a.rho.tobytes() == b.rho.tobytes()
    assert not a.rho.flags.writeable


def test_stall_criterion_stops_early():
    p = preset("cantilever_2d", 20)
    full = simp_compliance(p, max_iter=200)
    early = simp_compliance(p, max_iter=200, ftol=1e-3)
    assert early.info["stop"] == "stall" and early.iterations < full.iterations
    assert early.objective == pytest.approx(full.objective, rel=0.02)
