"""Fitting an SDF node's parameters to an exemplar (paper 004, section 6): the engine object
`mesoforge reconstruct` and the Implicit Media dock both run.

`NodeFit` turns chosen float parameters of one SDF node into an
`engine.implicit.reconstruct.ParamSpace` whose ``make`` is the node's own `evaluate`
with those parameters replaced (its inputs evaluated once, kept fixed): what is
fitted is exactly what the node builds.  `fit` then runs one of the optimisers
under a time budget with progress and cancel.
"""

from __future__ import annotations

import math

import numpy as np

from engine.graph.errors import NodeInputError
from engine.graph.node import EvalContext, node_type
from engine.graph.schema import Param
from engine.implicit.reconstruct import ALGORITHMS, FitResult, ParamSpace, fit
from engine.implicit.values import SDF, as_points

__all__ = ["NodeFit", "FIT_PARAMS", "fit_param", "parse_bounds", "load_any_exemplar"]

FIT_PARAMS = (
    Param("algorithm", "enum", "cmaes", choices=tuple(ALGORITHMS),
          doc="cmaes (CMA-ES, gradient-free), powell (local), basinhopping or shgo (scipy)"),
    Param("budget", "float", 30.0, 0.1, 86400.0, unit="s", doc="time budget of the fit"),
    Param("max_evaluations", "int", 0, 0, 10 ** 9, doc="largest number of loss evaluations (0: no limit)"),
    Param("seed", "int", 0, 0, 2 ** 31 - 1, doc="seed of the optimiser"),
    Param("loss", "enum", "fourier", choices=("fourier", "mse"),
          doc="fourier: log MSE of DFT amplitudes and phases (eq. 36); mse: plain"),
)
DEFAULT_SPREAD = 0.5        # default bounds: the current value +- half of it, within the schema


def fit_param(name: str) -> Param:
    return next(p for p in FIT_PARAMS if p.name == name)


IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp")


def load_any_exemplar(path) -> tuple:
    """(exemplar, is an image): a 3D grid (`engine.implicit.exemplar.load_exemplar`: .npy, .vti,
    a .tif stack) or a picture for analysis by synthesis (`engine.gpu.image_fit.load_image_exemplar`:
    .png, .jpg, .bmp, a one-page .tif).

    Raises
    ------
    ValueError
        Naming the file and what was wrong with it.
    """
    from pathlib import Path

    from engine.gpu.image_fit import load_image_exemplar
    from engine.implicit.exemplar import load_exemplar

    suffix = Path(str(path)).suffix.lower()
    try:
        if suffix in IMAGE_SUFFIXES:
            return load_image_exemplar(path), True
        try:
            return load_exemplar(path), False
        except ValueError as grid_error:
            if suffix not in (".tif", ".tiff"):
                raise
            try:
                return load_image_exemplar(path), True
            except ValueError:
                raise grid_error from None
    except OSError as exc:
        raise ValueError(f"{path}: {exc.strerror or exc}") from None


def parse_bounds(text: str) -> tuple[str, float, float]:
    """``"name=lo:hi"`` -> (name, lo, hi).

    Raises
    ------
    ValueError
        Unless the text has that form with finite numbers lo < hi.
    """
    name, sep, rng = str(text).partition("=")
    lo, sep2, hi = rng.partition(":")
    try:
        a, b = float(lo), float(hi)
    except ValueError:
        a = b = math.nan
    if not (sep and sep2 and name.strip() and math.isfinite(a) and math.isfinite(b) and a < b):
        raise ValueError(f"{text!r}: expected NAME=LO:HI with numbers LO < HI, e.g. cell=0.5:2")
    return name.strip(), a, b


class NodeFit:
    """The fit of some float parameters of one SDF node.

    type_name : the node's type; params : its current parameters (the start point and the
        values of everything not fitted); inputs : its evaluated inputs.
    bounds : {parameter: (lo, hi)}; None fits every float parameter whose value is not 0
        and that takes effect (`Param.is_active`), within ``value * (1 -+ DEFAULT_SPREAD)``
        clipped to its schema range.

    Raises
    ------
    ValueError
        For a node without an SDF output, an unknown or non-float parameter, bounds outside
        the schema range, or nothing to fit.
    """

    def __init__(self, type_name: str, params: dict, inputs: dict | None = None, bounds: dict | None = None):
        cls = node_type(type_name)
        if not any(p.type == "SDF" for p in cls.outputs):
            raise ValueError(f"a {type_name} node has no SDF output to fit")
        self.cls, self.params, self.inputs = cls, dict(params), dict(inputs or {})
        self.bounds = self._bounds(bounds)
        names = tuple(self.bounds)
        lo = np.array([self.bounds[n][0] for n in names])
        hi = np.array([self.bounds[n][1] for n in names])
        self.names = names
        self.space = ParamSpace(names, lo, hi, make=self._candidate)

    def _bounds(self, bounds):
        floats = {p.name: p for p in self.cls.params if p.kind == "float"}
        if bounds is None:
            bounds = {}
            current = {p.name: self.params.get(p.name, p.default) for p in self.cls.params}
            for name, p in floats.items():
                v = float(current[name])
                if v != 0 and p.is_active(current):
                    a, b = sorted((v * (1 - DEFAULT_SPREAD), v * (1 + DEFAULT_SPREAD)))
                    lo = a if p.minimum is None else max(a, p.minimum)
                    hi = b if p.maximum is None else min(b, p.maximum)
                    if lo < hi:
                        bounds[name] = (lo, hi)
        out = {}
        for name, (lo, hi) in bounds.items():
            p = floats.get(name)
            if p is None:
                allowed = ", ".join(floats) or "none"
                raise ValueError(f"{name!r} is not a float parameter of {self.cls.type_name} (fittable: {allowed})")
            if (p.minimum is not None and lo < p.minimum) or (p.maximum is not None and hi > p.maximum) \
                    or not lo < hi:
                raise ValueError(f"bounds {lo!r}:{hi!r} of {name!r} must satisfy lo < hi within "
                                 f"[{p.minimum}, {p.maximum}]")
            out[name] = (float(lo), float(hi))
        if not out:
            raise ValueError(f"nothing to fit on this {self.cls.type_name} node: name parameters and bounds")
        return out

    def sdf(self, values):
        """The node's SDF with the fitted parameters set to `values`."""
        params = dict(self.params)
        for name, v in zip(self.names, values):
            params[name] = float(v)
        try:
            return self.cls().evaluate(self.inputs, params, EvalContext("fit", 0))["sdf"]
        except NodeInputError as exc:
            raise ValueError(str(exc)) from None

    def _candidate(self, values):
        """The SDF at `values`, or one whose every value is NaN (the worst loss) where the node
        refuses them (e.g. particles grown past their cell): the optimiser moves on."""
        try:
            return self.sdf(values)
        except ValueError:
            return _Refused()

    def start(self) -> np.ndarray:
        """The node's current values of the fitted parameters, clipped into their bounds."""
        return np.array([min(max(float(self.params.get(n, self.cls.param(n).default)), lo), hi)
                         for n, (lo, hi) in self.bounds.items()])

    def fit_image(self, target, camera, *, algorithm: str = "cmaes", budget: float = 30.0, max_evaluations: int = 0,
                  seed: int = 0, bounds=None, progress=None, check=None) -> FitResult:
        """Analysis by synthesis (paper 004, section 6.2): fit to an image `target` ((h, w) grey or
        (h, w, 3 | 4), `engine.gpu.image_fit.load_image_exemplar`) rendering each candidate at
        `camera` (sphere tracing, Lambert shading; rays clipped to `bounds`)."""
        from engine.gpu.image_fit import fit_image

        return fit_image(self.space, target, camera, algorithm, budget, x0=self.start(), seed=seed, bounds=bounds,
                         max_evaluations=max_evaluations or None, progress=progress, check=check)

    def fit(self, exemplar, *, algorithm: str = "cmaes", budget: float = 30.0, max_evaluations: int = 0,
            seed: int = 0, loss: str = "fourier", progress=None, check=None) -> FitResult:
        """Run the fit from the node's current values; the best parameters found (see
        `engine.implicit.reconstruct.fit`)."""
        return fit(self.space, exemplar, algorithm, budget, x0=self.start(), seed=seed, loss=loss,
                   max_evaluations=max_evaluations or None, progress=progress, check=check)


class _Refused(SDF):
    """Parameters the node refuses: NaN everywhere, which the fit scores as the worst loss."""

    def field(self, points):
        return np.full(len(as_points(points)), np.nan)
