"""Stress-aware L-beam: adjoint gradient and the effect on peak stress."""

import numpy as np
import pytest

from engine.topopt import preset, simp_compliance, stress_aware_simp
from engine.topopt.design import design_space
from engine.topopt.stress_aware import stress_objective


@pytest.mark.parametrize("weight", [0.0, 0.6, 1.0])
def test_gradient_matches_finite_differences(weight):
    p = preset("lbeam_stress_2d", 8)
    ds = design_space(p)
    x = np.random.default_rng(8).uniform(0.2, 0.9, ds.n_design)
    kw = dict(weight=weight, pnorm=8.0, q=0.5, scales=(30.0, 0.5))
    _, dJ, _ = stress_objective(p, x, **kw)
    h = 1e-5
    for j in np.random.default_rng(9).choice(x.size, 6, replace=False):
        e = np.zeros_like(x)
        e[j] = h
        fd = (stress_objective(p, x + e, **kw)[0] - stress_objective(p, x - e, **kw)[0]) / (2 * h)
        assert dJ[j] == pytest.approx(fd, rel=1e-5, abs=1e-7 * np.abs(dJ).max())


def test_stress_aware_design_lowers_the_peak():
    p = preset("lbeam_stress_2d", 40)
    comp = simp_compliance(p.replace(objective="compliance"), max_iter=120)
    aware = stress_aware_simp(p, max_iter=150)
    peak = [stress_objective(p, r.x, weight=1.0)[2]["relaxed"].max() for r in (comp, aware)]
    assert peak[1] < 0.85 * peak[0]
    assert abs(aware.history["volume"][-1] - p.volfrac) < 1e-3
    assert aware.rho[p.passive == -1].max() == 0.0
    assert aware.compliances[0] < 1.5 * comp.compliances[0]     # still a stiff structure
