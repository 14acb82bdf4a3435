"""Parameter fitting of a parametrised SDF to an exemplar (paper 004, sections 6.1, 6.3, 12.1).

Given a `ParamSpace` (named parameters in a box, and ``make(values) -> SDF``)
and an `Exemplar` (signed distances on a grid), `fit` looks for the
parameters whose SDF, sampled at the exemplar's points, is closest to it in
the Fourier loss of eq. 36 (`fourier_loss`) or in plain MSE.

The optimisers work in normalised coordinates u in [0, 1]^d (x = lo + u (hi
- lo)), so one step size suits every parameter:

* ``"cmaes"`` — `cma.CMAEvolutionStrategy`, bounds [0, 1], initial sigma
  0.25, default population; gradient-free, for rugged or discrete problems.
  When it stops (its own tolerances) with budget left it restarts from a
  seeded random point with twice the population (IPOP), up to `restarts`
  times: eq. 36 has local minima (e.g. the mean of the field with the
  wrong sign matches the amplitude spectrum, its phase is off by pi).
  `cma` draws from numpy's global generator, seeded by its ``seed`` option;
  that global state is saved and restored around the run, so a fit neither
  depends on nor disturbs other code's draws (another thread drawing from
  the global generator during a fit is not protected);
* ``"powell"`` — `scipy.optimize.minimize(method="Powell")` with bounds, a
  local method for a close start;
* ``"basinhopping"`` — `scipy.optimize.basinhopping` with an SLSQP local
  minimiser (bounded), temperature 1, step 0.25, a seeded generator; it
  stops after `niter_success` hops without a better minimum;
* ``"shgo"`` — `scipy.optimize.shgo` with Sobol sampling (n = 64, iters = 2)
  and SLSQP local searches.

(Hyperparameters override through ``options``.)

Budget: `minimise` (the core `fit` uses, for any objective of the
parameters, e.g. the image loss of `engine.gpu.image_fit`) wraps the
objective so that it counts evaluations, keeps the best point seen and,
before each evaluation, calls `check` (a raised `engine.progress.Cancelled`,
there or inside the objective, ends the run with ``stopped_by="cancel"``),
compares the evaluation count with `max_evaluations` and the wall clock
with `budget_s` (``"budget"``).  It stops the optimiser by raising a private
exception that it catches; the best point seen is returned either way.
That check is the only place wall time is read.  A value at the objective's
`floor` (for `fit`, 2 log eps for eq. 36, 0 for MSE: an exact fit) also
stops the run, "converged".  An evaluation may overrun the budget by its own
duration.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Callable, NamedTuple

import numpy as np

from engine.progress import Cancelled

from .exemplar import Exemplar
from .fourier_loss import fourier_loss
from .values import SDF

__all__ = ["ParamSpace", "FitResult", "Validation", "fit", "minimise", "validation_error", "ALGORITHMS",
           "LOSSES"]

ALGORITHMS = ("cmaes", "powell", "basinhopping", "shgo")
FOURIER_EPS = 1e-8              # the eps of eq. 36 used by fit
LOSSES = ("fourier", "mse")

_DEFAULTS = {
    "cmaes": {"sigma0": 0.25, "popsize": None, "restarts": 6},
    "powell": {"xtol": 1e-6, "ftol": 1e-9},
    "basinhopping": {"T": 1.0, "stepsize": 0.25, "niter": 200, "niter_success": 15},
    "shgo": {"n": 64, "iters": 2},
}


@dataclass(frozen=True, eq=False)
class ParamSpace:
    """Named parameters in a box [lower, upper] and the SDF they make.

    names : d distinct str; lower, upper : (d,) finite floats, lower < upper;
    make : callable ``make(values: (d,) float64) -> SDF`` (needed by `fit`), or None.

    Raises
    ------
    ValueError
        Naming the parameter whose bounds are not finite or not lower < upper, or on
        mismatched lengths / repeated names.
    """

    names: tuple
    lower: np.ndarray
    upper: np.ndarray
    make: Callable | None = None

    def __post_init__(self):
        names = tuple(str(n) for n in self.names)
        lo = np.array(self.lower, dtype=np.float64).reshape(-1)
        hi = np.array(self.upper, dtype=np.float64).reshape(-1)
        if not names or len(set(names)) != len(names):
            raise ValueError(f"names must be one or more distinct names, got {self.names!r}")
        if lo.shape != (len(names),) or hi.shape != (len(names),):
            raise ValueError(f"lower and upper need one bound per name ({len(names)}), "
                             f"got {lo.shape[0]} and {hi.shape[0]}")
        for n, a, b in zip(names, lo, hi):
            if not (math.isfinite(a) and math.isfinite(b) and a < b):
                raise ValueError(f"parameter {n!r}: bounds must be finite with lower < upper, "
                                 f"got [{a!r}, {b!r}]")
        if self.make is not None and not callable(self.make):
            raise ValueError("make must be a callable values -> SDF, or None")
        lo.setflags(write=False)
        hi.setflags(write=False)
        for k, v in (("names", names), ("lower", lo), ("upper", hi)):
            object.__setattr__(self, k, v)

    @property
    def dim(self) -> int:
        return len(self.names)

    def to_unit(self, values) -> np.ndarray:
        return (np.asarray(values, dtype=np.float64) - self.lower) / (self.upper - self.lower)

    def from_unit(self, u) -> np.ndarray:
        return self.lower + np.clip(np.asarray(u, dtype=np.float64), 0.0, 1.0) * (self.upper - self.lower)

    def check(self, values, what: str = "x0") -> np.ndarray:
        """`values` as (d,) float64 inside the box.

        Raises
        ------
        ValueError
            Naming the first parameter outside its bounds (or not finite).
        """
        x = np.array(values, dtype=np.float64).reshape(-1)
        if x.shape != (self.dim,):
            raise ValueError(f"{what} needs {self.dim} values ({', '.join(self.names)}), got {x.shape[0]}")
        for n, v, a, b in zip(self.names, x, self.lower, self.upper):
            if not (math.isfinite(v) and a <= v <= b):
                raise ValueError(f"{what}: parameter {n!r} = {v!r} is outside its bounds [{a!r}, {b!r}]")
        return x

    def sdf(self, values) -> SDF:
        """``make(values)``, checked to be an SDF.

        Raises
        ------
        ValueError
            If the space has no `make` or it returned something else than an SDF."""
        if self.make is None:
            raise ValueError("this ParamSpace has no make(values) -> SDF")
        s = self.make(np.asarray(values, dtype=np.float64))
        if not isinstance(s, SDF):
            raise ValueError(f"make returned a {type(s).__name__}, not an SDF")
        return s


@dataclass(frozen=True)
class FitResult:
    """The outcome of `fit` / `minimise`.

    params : (d,) float64, the best parameters seen (x0 if no evaluation ran);
    loss : float, their loss (inf if none ran); evaluations : int; seconds : float (wall);
    history : tuple of (evaluations, loss), one entry per improvement of the best loss;
    algorithm : str; stopped_by : "converged", "budget" or "cancel"; names : the
    parameter names."""

    params: np.ndarray
    loss: float
    evaluations: int
    seconds: float
    history: tuple
    algorithm: str
    stopped_by: str
    names: tuple = ()

    def as_dict(self) -> dict:
        return dict(zip(self.names, (float(v) for v in self.params)))


class _Stop(Exception):
    def __init__(self, reason: str):
        super().__init__(reason)
        self.reason = reason


def _mse(pred, target) -> float:
    return float(np.mean((np.asarray(pred) - np.asarray(target)) ** 2))


class _Objective:
    """The objective in unit coordinates, with the evaluation count, the best point and the stops."""

    def __init__(self, space, objective, floor, budget_s, max_evaluations, progress, check):
        self.space, self.objective, self.floor = space, objective, floor
        self.budget_s, self.max_evaluations = budget_s, max_evaluations
        self.progress, self.check = progress, check
        self.evaluations, self.best, self.best_u, self.history = 0, math.inf, None, []
        self.start = time.perf_counter()

    def elapsed(self) -> float:
        return time.perf_counter() - self.start

    def fraction(self) -> float:
        f = self.elapsed() / self.budget_s
        if self.max_evaluations is not None:
            f = max(f, self.evaluations / self.max_evaluations)
        return min(1.0, f)

    def __call__(self, u) -> float:
        if self.check is not None:
            try:
                self.check()
            except Cancelled:
                raise _Stop("cancel") from None
        if self.max_evaluations is not None and self.evaluations >= self.max_evaluations:
            raise _Stop("budget")
        if self.elapsed() >= self.budget_s:
            raise _Stop("budget")
        u = np.clip(np.asarray(u, dtype=np.float64).reshape(-1), 0.0, 1.0)
        try:
            value = float(self.objective(self.space.from_unit(u)))   # a fresh array: the objective's own
        except Cancelled:                       # e.g. a renderer calling check between tiles
            raise _Stop("cancel") from None
        if not math.isfinite(value):
            value = 1e300
        self.evaluations += 1
        if value < self.best:
            self.best, self.best_u = value, u.copy()
            self.history.append((self.evaluations, value))
        if self.progress is not None:
            self.progress(self.fraction(), self.best, self.space.from_unit(self.best_u))
        if value <= self.floor:
            raise _Stop("converged")            # at the objective's least value: nothing left to improve
        return value


def _run_cmaes(obj, u0, seed, opts):
    import cma
    options = {"bounds": [0.0, 1.0], "seed": int(seed) + 1, "verbose": -9, "verb_log": 0,
               "verb_disp": 0, "maxfevals": math.inf}
    if len(u0) == 1:
        # cma 4.5 fails ("not yet initialized") when it caps a 1D step by the bound range
        options["maxstd"] = math.inf
    popsize = None if opts["popsize"] is None else int(opts["popsize"])
    starts = np.random.default_rng(seed).uniform(size=(int(opts["restarts"]), len(u0)))
    state = np.random.get_state()
    try:
        for k in range(int(opts["restarts"]) + 1):
            es = cma.CMAEvolutionStrategy(list(u0 if k == 0 else starts[k - 1]), float(opts["sigma0"]),
                                          dict(options, seed=int(seed) + 1 + k,
                                               **({} if popsize is None else {"popsize": popsize})))
            while not es.stop():
                xs = es.ask()
                es.tell(xs, [obj(x) for x in xs])
            popsize = 2 * es.popsize            # IPOP: a larger population on each restart
    finally:
        np.random.set_state(state)


def _run_powell(obj, u0, seed, opts):
    from scipy.optimize import minimize
    minimize(obj, u0, method="Powell", bounds=[(0.0, 1.0)] * len(u0),
             options={"xtol": opts["xtol"], "ftol": opts["ftol"], "maxfev": 10 ** 9})


def _run_basinhopping(obj, u0, seed, opts):
    import inspect
    from scipy.optimize import basinhopping
    gen = np.random.default_rng(seed)            # scipy >= 1.15 calls the generator rng, older seed
    key = "rng" if "rng" in inspect.signature(basinhopping).parameters else "seed"
    basinhopping(obj, u0, niter=int(opts["niter"]), T=float(opts["T"]),
                 stepsize=float(opts["stepsize"]), niter_success=opts["niter_success"],
                 minimizer_kwargs={"method": "SLSQP", "bounds": [(0.0, 1.0)] * len(u0)},
                 **{key: gen})


def _run_shgo(obj, u0, seed, opts):
    from scipy.optimize import shgo
    shgo(obj, [(0.0, 1.0)] * len(u0), n=int(opts["n"]), iters=int(opts["iters"]),
         sampling_method="sobol", minimizer_kwargs={"method": "SLSQP"})


_RUN = {"cmaes": _run_cmaes, "powell": _run_powell, "basinhopping": _run_basinhopping,
        "shgo": _run_shgo}


def minimise(objective: Callable[[np.ndarray], float], space: ParamSpace, algorithm: str = "cmaes",
             budget_s: float = 10.0, *, x0=None, seed: int = 0, progress=None, check=None,
             max_evaluations: int | None = None, options: dict | None = None,
             floor: float = -math.inf) -> FitResult:
    """Minimise ``objective(values)`` over `space`'s box with one optimiser under a budget.

    Parameters
    ----------
    objective : callable ``objective(values: (d,) float64 inside the box, a fresh copy) -> float``;
        a non-finite value counts as 1e300; a raised `engine.progress.Cancelled` cancels.
    space : ParamSpace (its `make` is not used here).
    algorithm : one of `ALGORITHMS`.
    budget_s : float > 0, seconds of wall time at most (checked before each evaluation).
    x0 : (d,) start inside the box (None: its centre); shgo ignores it.
    seed : int >= 0, for cmaes and basinhopping.
    progress : callable ``progress(done_fraction, best_value, best_params)`` after every
        evaluation (best_value non-increasing; done_fraction the larger of time and
        evaluations used), and once more with 1.0 at the end, or None.
    check : callable or None, called before every evaluation; raising
        `engine.progress.Cancelled` cancels (other exceptions propagate).
    max_evaluations : int >= 1 or None, a budget of objective evaluations.
    options : per-algorithm hyperparameters overriding the defaults (see the module docstring).
    floor : float, the objective's least value: reaching it stops with "converged".

    Returns
    -------
    FitResult (the best point seen, however the run ended).

    Raises
    ------
    ValueError
        On an unknown algorithm, budget_s <= 0, max_evaluations < 1, a bad seed, an
        unknown option, x0 outside the bounds (naming the parameter), a space that is
        not a ParamSpace or an objective that is not callable.
    """
    if algorithm not in _RUN:
        raise ValueError(f"algorithm must be one of {ALGORITHMS}, got {algorithm!r}")
    if not isinstance(space, ParamSpace):
        raise ValueError(f"space must be a ParamSpace, got {type(space).__name__}")
    if not callable(objective):
        raise ValueError(f"objective must be a callable values -> float, got {type(objective).__name__}")
    b = float(budget_s)
    if not (b > 0 and not math.isnan(b)):
        raise ValueError(f"budget_s must be > 0 seconds, got {budget_s!r}")
    if max_evaluations is not None and (not isinstance(max_evaluations, (int, np.integer))
                                        or isinstance(max_evaluations, bool) or max_evaluations < 1):
        raise ValueError(f"max_evaluations must be an int >= 1 or None, got {max_evaluations!r}")
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed must be an int >= 0, got {seed!r}")
    opts = dict(_DEFAULTS[algorithm])
    for k, v in (options or {}).items():
        if k not in opts:
            raise ValueError(f"unknown {algorithm} option {k!r}, expected one of {sorted(opts)}")
        opts[k] = v
    x_start = 0.5 * (space.lower + space.upper) if x0 is None else space.check(x0, "x0")
    obj = _Objective(space, objective, float(floor), b, max_evaluations, progress, check)
    stopped = "converged"
    try:
        _RUN[algorithm](obj, space.to_unit(x_start), int(seed), opts)
    except _Stop as stop:
        stopped = stop.reason
    best_x = x_start if obj.best_u is None else space.from_unit(obj.best_u)
    if progress is not None:
        progress(1.0, obj.best, best_x)
    return FitResult(np.array(best_x), float(obj.best), obj.evaluations, obj.elapsed(),
                     tuple(obj.history), algorithm, stopped, space.names)


def fit(space: ParamSpace, exemplar: Exemplar, algorithm: str = "cmaes", budget_s: float = 10.0, *,
        x0=None, seed: int = 0, progress=None, check=None, loss: str = "fourier",
        max_evaluations: int | None = None, options: dict | None = None) -> FitResult:
    """Fit `space`'s parameters to `exemplar` with one optimiser under a budget (`minimise`).

    Parameters
    ----------
    space : ParamSpace with a `make`.
    exemplar : Exemplar; candidates are sampled at its points (its grid for the DFT).
    loss : "fourier" (eq. 36, eps `FOURIER_EPS`) or "mse" (of the distances).
    algorithm, budget_s, x0, seed, progress, check, max_evaluations, options : as for
        `minimise` (progress reports the best loss).

    Returns
    -------
    FitResult (the best point seen, however the run ended).

    Raises
    ------
    ValueError
        On an unknown algorithm or loss, budget_s <= 0, max_evaluations < 1, a bad seed,
        an unknown option, x0 outside the bounds (naming the parameter), or a space
        without `make`.
    """
    if loss not in LOSSES:
        raise ValueError(f"loss must be one of {LOSSES}, got {loss!r}")
    if not isinstance(space, ParamSpace):
        raise ValueError(f"space must be a ParamSpace, got {type(space).__name__}")
    if space.make is None:
        raise ValueError("space has no make(values) -> SDF to fit")
    if not isinstance(exemplar, Exemplar):
        raise ValueError(f"exemplar must be an Exemplar, got {type(exemplar).__name__}")
    points, target = exemplar.points, exemplar.grid()
    if loss == "fourier":
        compare = lambda a, b: fourier_loss(a, b, FOURIER_EPS)  # noqa: E731
        floor = 2.0 * math.log(FOURIER_EPS) + 1e-12   # an exact fit (FFT round-off stays far below eps)
    else:
        compare, floor = _mse, 0.0

    def objective(x):
        return compare(space.sdf(x).distance(points).reshape(target.shape), target)

    return minimise(objective, space, algorithm, budget_s, x0=x0, seed=seed, progress=progress,
                    check=check, max_evaluations=max_evaluations, options=options, floor=floor)


class Validation(NamedTuple):
    """Fitted vs reference distances on a validation exemplar.

    fourier : the eq. 36 loss; mse : mean squared difference (mm^2); relative : the RMS
    difference over the reference's RMS (0 when equal; about 1.4 for unrelated fields of
    the same spread)."""

    fourier: float
    mse: float
    relative: float


def validation_error(space: ParamSpace, found, true, exemplar_b: Exemplar) -> Validation:
    """Compare the SDF of `found` with the reference on `exemplar_b`'s points.

    true : the true parameters (their SDF is the reference), or None to use
        `exemplar_b`'s own distances (a measured validation set).

    Raises
    ------
    ValueError
        If `found` or `true` is outside the bounds (naming the parameter).
    """
    f = space.check(found, "found")
    pred = space.sdf(f).distance(exemplar_b.points)
    ref = exemplar_b.distances if true is None else space.sdf(space.check(true, "true")).distance(
        exemplar_b.points)
    mse = _mse(pred, ref)
    rms = math.sqrt(float(np.mean(ref ** 2)))
    rel = math.sqrt(mse) / rms if rms > 0 else (0.0 if mse == 0 else math.inf)
    shape = exemplar_b.shape
    return Validation(fourier_loss(pred.reshape(shape), ref.reshape(shape)), mse, rel)
