"""Parameter fitting: recovery of known parameters, budgets, progress, cancel, determinism.

References: the true parameters the exemplars were made with, brute-force scans
of the loss, and closed-form SDFs written here.  Budgets are evaluation counts
(no wall-time asserts)."""

import math
from dataclasses import dataclass

import numpy as np
import pytest

from engine.implicit.exemplar import Exemplar
from engine.implicit.fourier_loss import fourier_loss
from engine.implicit.reconstruct import ParamSpace, fit, minimise, validation_error
from engine.implicit.synthetic import synthetic_case
from engine.implicit.values import SDF, as_points
from engine.progress import Cancelled

FLOOR = 2 * math.log(1e-8)


@dataclass(frozen=True, eq=False)
class _Waves(SDF):
    """(cos X + cos Y + cos Z) c / (2 pi sqrt 3) - t with X = 2 pi x / c: a test-local periodic SDF."""
    c: float = 1.0
    t: float = 0.0

    def field(self, points):
        th = as_points(points) * (2 * np.pi / self.c)
        return np.cos(th).sum(axis=1) * self.c / (2 * np.pi * math.sqrt(3)) - self.t


def _waves_space():
    return ParamSpace(("c", "t"), (0.5, -0.1), (2.0, 0.1), lambda v: _Waves(float(v[0]), float(v[1])))


def _waves_exemplar(c=1.1, t=0.03, seed=0):
    return Exemplar.from_sdf(_Waves(c, t), (0.3, 0.1, -0.2), 2.5, 12, noise_sd=0.01,
                             rotation=None, seed=seed)


@pytest.fixture(scope="module")
def gyroid_1d():
    case = synthetic_case("gyroid_1d")
    return case, case.exemplar(resolution=16)


@pytest.mark.parametrize("algorithm", ["cmaes", "powell"])
def test_gyroid_1d_recovered_within_one_percent(gyroid_1d, algorithm):
    case, ex = gyroid_1d
    r = fit(case.space, ex, algorithm, math.inf, max_evaluations=400)
    assert r.algorithm == algorithm and r.evaluations <= 400
    assert case.relative_errors(r.params)[0] < 0.01
    assert r.stopped_by in ("converged", "budget")


@pytest.mark.parametrize("algorithm", ["basinhopping", "shgo"])
def test_gradient_methods_recover_the_local_waves(algorithm):
    r = fit(_waves_space(), _waves_exemplar(), algorithm, math.inf, max_evaluations=1500)
    np.testing.assert_allclose(r.params, [1.1, 0.03], rtol=0.02)


def test_gyroid_3d_within_two_percent_by_cmaes():
    case = synthetic_case("gyroid_3d")
    r = fit(case.space, case.exemplar(resolution=16), "cmaes", math.inf, max_evaluations=4000, seed=0)
    assert np.all(case.relative_errors(r.params) < 0.02), r.params


def test_loss_minimal_at_truth_along_a_brute_force_scan(gyroid_1d):
    case, ex = gyroid_1d
    cells = np.linspace(0.5, 2.0, 301)                  # includes the true cell, 1.0
    losses = [fourier_loss(case.sdf([c]).distance(ex.points).reshape(ex.shape), ex.grid()) for c in cells]
    best = int(np.argmin(losses))
    assert cells[best] == pytest.approx(1.0)
    assert losses[best] == pytest.approx(FLOOR)
    r = fit(case.space, ex, "powell", math.inf, max_evaluations=400)
    assert r.loss <= np.sort(losses)[1]                  # at least as good as the scan's runner-up
    assert abs(r.params[0] - cells[best]) < 0.5 * (cells[1] - cells[0])


def test_mse_loss_also_fits():
    r = fit(_waves_space(), _waves_exemplar(), "powell", math.inf, loss="mse", max_evaluations=800)
    np.testing.assert_allclose(r.params, [1.1, 0.03], rtol=0.01)
    assert r.loss < 1e-10


def test_progress_monotone_and_complete():
    calls = []
    r = fit(_waves_space(), _waves_exemplar(), "cmaes", math.inf, max_evaluations=120,
            progress=lambda f, loss, x: calls.append((f, loss, np.array(x))))
    assert len(calls) == r.evaluations + 1
    fractions = [c[0] for c in calls]
    losses = [c[1] for c in calls]
    assert all(0 <= f <= 1 for f in fractions) and fractions[-1] == 1.0
    assert all(b <= a for a, b in zip(losses, losses[1:]))
    assert losses[-1] == r.loss
    np.testing.assert_array_equal(calls[-1][2], r.params)
    for _, _, x in calls:
        assert np.all(x >= [0.5, -0.1]) and np.all(x <= [2.0, 0.1])
    # the history holds every improvement, its last one the result
    assert r.history[-1][1] == r.loss and all(b[1] < a[1] for a, b in zip(r.history, r.history[1:]))


@pytest.mark.parametrize("algorithm", ["cmaes", "powell", "basinhopping", "shgo"])
def test_cancel_returns_the_best_so_far(algorithm):
    space, ex = _waves_space(), _waves_exemplar()
    count = {"n": 0}

    def check():
        count["n"] += 1
        if count["n"] > 25:
            raise Cancelled("stop")

    seen = []
    r = fit(space, ex, algorithm, math.inf, check=check, progress=lambda f, l, x: seen.append(l))
    assert r.stopped_by == "cancel" and r.evaluations == 25
    assert r.loss == min(seen)
    # the returned parameters really have the returned loss (recomputed here)
    pred = _Waves(*r.params).distance(ex.points).reshape(ex.shape)
    assert fourier_loss(pred, ex.grid()) == pytest.approx(r.loss, abs=1e-12)


def test_cancel_before_any_evaluation_returns_x0():
    def check():
        raise Cancelled("now")
    r = fit(_waves_space(), _waves_exemplar(), "powell", 5.0, x0=(1.5, 0.05), check=check)
    assert r.stopped_by == "cancel" and r.evaluations == 0 and r.loss == math.inf
    np.testing.assert_array_equal(r.params, [1.5, 0.05])


def test_evaluation_budget_stops_with_budget():
    r = fit(_waves_space(), _waves_exemplar(), "cmaes", math.inf, max_evaluations=17)
    assert r.stopped_by == "budget" and r.evaluations == 17


def test_other_exceptions_from_check_propagate():
    def check():
        raise RuntimeError("a bug")
    with pytest.raises(RuntimeError, match="a bug"):
        fit(_waves_space(), _waves_exemplar(), "powell", 5.0, check=check)


@pytest.mark.parametrize("algorithm", ["cmaes", "basinhopping"])
def test_same_seed_same_result(algorithm):
    space, ex = _waves_space(), _waves_exemplar()
    a = fit(space, ex, algorithm, math.inf, seed=3, max_evaluations=150)
    b = fit(space, ex, algorithm, math.inf, seed=3, max_evaluations=150)
    c = fit(space, ex, algorithm, math.inf, seed=4, max_evaluations=150)
    assert a.params.tobytes() == b.params.tobytes() and a.history == b.history
    assert a.history != c.history


def test_cmaes_leaves_numpy_global_state_alone():
    np.random.seed(11)
    expect = np.random.random(3)
    np.random.seed(11)
    fit(_waves_space(), _waves_exemplar(), "cmaes", math.inf, max_evaluations=30)
    np.testing.assert_array_equal(np.random.random(3), expect)


def test_bad_input_refused():
    space, ex = _waves_space(), _waves_exemplar()
    for budget in (0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="budget_s"):
            fit(space, ex, "cmaes", budget)
    with pytest.raises(ValueError, match="algorithm"):
        fit(space, ex, "nelder-mead", 1.0)
    with pytest.raises(ValueError, match="'t'"):
        fit(space, ex, "powell", 1.0, x0=(1.0, 0.5))
    with pytest.raises(ValueError, match="loss"):
        fit(space, ex, "powell", 1.0, loss="l1")
    with pytest.raises(ValueError, match="max_evaluations"):
        fit(space, ex, "powell", 1.0, max_evaluations=0)
    with pytest.raises(ValueError, match="seed"):
        fit(space, ex, "cmaes", 1.0, seed=-2)
    with pytest.raises(ValueError, match="unknown cmaes option"):
        fit(space, ex, "cmaes", 1.0, options={"stepsize": 1})
    with pytest.raises(ValueError, match="'b'"):
        ParamSpace(("a", "b"), (0.0, 1.0), (1.0, 1.0))
    with pytest.raises(ValueError, match="'a'"):
        ParamSpace(("a",), (math.nan,), (1.0,))
    with pytest.raises(ValueError, match="make"):
        fit(ParamSpace(("a",), (0.0,), (1.0,)), ex, "powell", 1.0)


def _gyroid_distance(p, cell):
    """The gyroid's nodal function over its gradient bound sqrt(6) 2 pi / cell (written out here)."""
    x, y, z = (2 * np.pi / cell * p).T
    f = np.sin(x) * np.cos(y) + np.sin(y) * np.cos(z) + np.sin(z) * np.cos(x)
    return f / (math.sqrt(6) * 2 * np.pi / cell)


def test_validation_error_against_closed_form():
    case = synthetic_case("gyroid_1d")
    val = case.validation_exemplar(resolution=12)
    same = validation_error(case.space, case.true, case.true, val)
    assert same.mse == 0 and same.relative == 0 and same.fourier == pytest.approx(FLOOR)
    got = validation_error(case.space, [1.03], case.true, val)
    a, b = _gyroid_distance(val.points, 1.03), _gyroid_distance(val.points, 1.0)
    assert got.mse == pytest.approx(np.mean((a - b) ** 2), rel=1e-9)
    assert got.relative == pytest.approx(math.sqrt(np.mean((a - b) ** 2) / np.mean(b ** 2)), rel=1e-9)
    # without true parameters the exemplar's own distances are the reference
    assert validation_error(case.space, [1.03], None, val).mse == pytest.approx(got.mse, rel=1e-9)
    with pytest.raises(ValueError, match="'cell'"):
        validation_error(case.space, [5.0], case.true, val)


def _fibre_set(p, s, z_phase):
    return (np.cos(2 * np.pi * p[:, 0] / s) + np.cos(2 * np.pi * p[:, 2] / s + z_phase) + 1.5) / (4 * np.pi / s)


def test_synthetic_sdfs_against_closed_forms():
    p = np.random.default_rng(8).uniform(-3, 3, size=(2000, 3))
    wall = synthetic_case("gyroid_3d")
    c, m, w = 1.1, 0.2, 0.1
    x, y, z = (2 * np.pi / c * p).T
    f = np.sin(x) * np.cos(y) + np.sin(y) * np.cos(z) + np.sin(z) * np.cos(x)
    expect = np.abs((f - m) / (math.sqrt(6) * 2 * np.pi / c)) - w / 2
    np.testing.assert_allclose(wall.sdf([c, m, w]).distance(p), expect, atol=1e-12)
    fibres = synthetic_case("fibers_2d")
    s, a = 0.9, 0.4
    ca, sa = math.cos(a), math.sin(a)
    q = p @ np.array([[ca, -sa, 0], [sa, ca, 0], [0, 0, 1.0]])        # R^T p, rows
    expect = np.minimum(_fibre_set(p, s, 0.0), _fibre_set(q, s, np.pi))
    np.testing.assert_allclose(fibres.sdf([s, a]).distance(p), expect, atol=1e-12)


def test_spheres_volume_fraction_is_one_sphere_per_cell():
    case = synthetic_case("spheres_2d")
    u = np.random.default_rng(2).uniform(-5, 5, size=(40000, 3))
    for cell, ratio in [(1.0, 0.3), (0.7, 0.4)]:
        p = u * cell                                  # a box of whole cells: no partial spheres at its faces
        inside = np.mean(case.sdf([cell, ratio]).distance(p) < 0)
        assert inside == pytest.approx(4 / 3 * np.pi * ratio ** 3, abs=0.01)


@pytest.mark.parametrize("name", ["gyroid_1d", "gyroid_3d", "gyroid_5d", "spheres_2d", "fibers_2d"])
def test_every_case_is_minimal_at_its_truth_on_axis_scans(name):
    case = synthetic_case(name)
    ex = case.exemplar(resolution=12)
    assert np.all(case.true > case.space.lower) and np.all(case.true < case.space.upper)
    for i in range(case.space.dim):
        values = np.append(np.linspace(case.space.lower[i], case.space.upper[i], 25), case.true[i])
        losses = []
        for v in values:
            x = case.true.copy()
            x[i] = v
            losses.append(fourier_loss(case.sdf(x).distance(ex.points).reshape(ex.shape), ex.grid()))
        others = np.abs(values[:-1] - case.true[i]) > 1e-9
        assert losses[-1] < np.min(np.array(losses[:-1])[others]), case.space.names[i]


def _bowl_space():
    return ParamSpace(("x", "y"), (-1.0, -1.0), (1.0, 2.0))


@pytest.mark.parametrize("algorithm", ["cmaes", "powell", "basinhopping", "shgo"])
def test_minimise_any_objective_finds_a_closed_form_minimum(algorithm):
    seen = []

    def bowl(v):
        seen.append(np.array(v))
        return (v[0] - 0.3) ** 2 + 2 * (v[1] + 0.2) ** 2 + 1.0

    r = minimise(bowl, _bowl_space(), algorithm, math.inf, max_evaluations=600, seed=1)
    np.testing.assert_allclose(r.params, [0.3, -0.2], atol=2e-3)
    assert r.loss == pytest.approx(1.0, abs=1e-5) and r.names == ("x", "y")
    assert len(seen) == r.evaluations
    # the objective sees values inside the box, in parameter (not unit) coordinates
    pts = np.array(seen)
    assert np.all(pts >= [-1.0, -1.0]) and np.all(pts <= [1.0, 2.0]) and pts[:, 0].min() < 0.0


def test_minimise_floor_cancel_inside_and_non_finite():
    space = _bowl_space()
    r = minimise(lambda v: abs(v[0] - 0.5) + abs(v[1]), space, "powell", math.inf, x0=(0.5, 0.0),
                 floor=0.0, max_evaluations=50)
    assert r.stopped_by == "converged" and r.evaluations == 1 and r.loss == 0.0
    calls = {"n": 0}

    def cancelled_inside(v):
        calls["n"] += 1
        if calls["n"] > 4:
            raise Cancelled("from inside the objective")
        return float(v[0] ** 2)

    r = minimise(cancelled_inside, space, "cmaes", math.inf)
    assert r.stopped_by == "cancel" and r.evaluations == 4
    r = minimise(lambda v: math.nan if v[0] > 0 else float(-v[0]), space, "powell", math.inf,
                 x0=(0.5, 0.0), max_evaluations=1)
    assert r.loss == 1e300                                 # a NaN counts as a huge value
    with pytest.raises(ValueError, match="objective"):
        minimise("not callable", space, "powell", 1.0)
    with pytest.raises(ValueError, match="space"):
        minimise(lambda v: 0.0, (("x",), (0,), (1,)), "powell", 1.0)
