"""Periodic implicit functions: triply periodic minimal surfaces and trigonometric sums.

Paper 004, section 3.4 (its equations were lost in extraction; the standard
forms the prose describes are implemented).  Two value types:

* `Periodic` — a TPMS family member by its nodal approximation F(theta) of
  the phases theta = 2 pi q / cell (q = matrix @ p), as a solid network
  ``F - t`` or a sheet ``|F| - t``, with an optionally graded level t and
  graded cell size along an axis;
* `TrigSum` — eq. 11, a sum of products of sines and cosines of the
  coordinates.

Both are non-Euclidean fields: `field` returns the raw value and
`lipschitz` a rigorous (analytic) upper bound of its gradient, so
`distance` is a lower bound of the distance to the surface.

Lipschitz bounds
----------------
Per kind, ``GRAD_BOUND[kind] >= sup |grad_theta F|``, derived by hand from a
bound on one partial derivative (all kinds are symmetric under a cyclic
permutation of the axes, so the three share it) times sqrt(3).  Inequalities
used: ``|a cos u + b sin u| <= sqrt(a^2 + b^2)`` and the triangle
inequality.  Then ``|grad_p f| <= GRAD_BOUND * ||J||_2 + |grad t|`` with J
the Jacobian of p -> theta.  Without a graded cell ``J = diag(k) M``
(k = 2 pi / cell), whose norm is computed exactly.  With a graded cell,
``theta_i = k_i(s) (q_i - q0_i)`` with s = p . axis, so
``J = diag(k(s)) M + (k'(s) * (q - q0)) axis^T`` and
``||J||_2 <= max k * ||M||_2 + |k' * (q - q0)|``; the second term grows
with |q - q0| without limit (a different period on two parallel planes
means ever more phase difference away from the axis), so a graded cell
needs a bounded `extent`: the point is clamped to that box (a
1-Lipschitz projection) before the phases are computed, and
|q_i - q0_i| <= sum_j |M_ij| h_j there (h the box's half size, q0 = M c,
c its centre, where the phase is anchored).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .values import SDF, GlslModule, as_points, glsl_float

__all__ = ["Periodic", "TrigSum", "TrigTerm", "KINDS", "VARIANTS", "GRAD_BOUND", "nodal_field"]

TWO_PI = 2.0 * math.pi

# Nodal approximations: sum of  amplitude * prod_i trig_i(n_i theta_i)  (trig "s"/"c"; n = 0
# with "c" is a factor 1).  theta has period 2 pi per axis in every kind.
_S, _C = "s", "c"
NODAL: dict[str, tuple] = {
    # sin X cos Y + sin Y cos Z + sin Z cos X
    "gyroid": ((1.0, (1, 1, 0), (_S, _C, _C)), (1.0, (0, 1, 1), (_C, _S, _C)),
               (1.0, (1, 0, 1), (_C, _C, _S))),
    # cos X + cos Y + cos Z
    "schwarz_p": ((1.0, (1, 0, 0), (_C, _C, _C)), (1.0, (0, 1, 0), (_C, _C, _C)),
                  (1.0, (0, 0, 1), (_C, _C, _C))),
    # sX sY sZ + sX cY cZ + cX sY cZ + cX cY sZ
    "schwarz_d": ((1.0, (1, 1, 1), (_S, _S, _S)), (1.0, (1, 1, 1), (_S, _C, _C)),
                  (1.0, (1, 1, 1), (_C, _S, _C)), (1.0, (1, 1, 1), (_C, _C, _S))),
    # 3 (cX + cY + cZ) + 4 cX cY cZ
    "neovius": ((3.0, (1, 0, 0), (_C, _C, _C)), (3.0, (0, 1, 0), (_C, _C, _C)),
                (3.0, (0, 0, 1), (_C, _C, _C)), (4.0, (1, 1, 1), (_C, _C, _C))),
    # 2 (cX cY + cY cZ + cZ cX) - (c2X + c2Y + c2Z)
    "iwp": ((2.0, (1, 1, 0), (_C, _C, _C)), (2.0, (0, 1, 1), (_C, _C, _C)),
            (2.0, (1, 0, 1), (_C, _C, _C)), (-1.0, (2, 0, 0), (_C, _C, _C)),
            (-1.0, (0, 2, 0), (_C, _C, _C)), (-1.0, (0, 0, 2), (_C, _C, _C))),
    # c2X sY cZ + cX c2Y sZ + sX cY c2Z
    "fischer_koch_s": ((1.0, (2, 1, 1), (_C, _S, _C)), (1.0, (1, 2, 1), (_C, _C, _S)),
                       (1.0, (1, 1, 2), (_S, _C, _C))),
    # (s2X cY sZ + sX s2Y cZ + cX sY s2Z) / 2 - (c2X c2Y + c2Y c2Z + c2Z c2X) / 2 + 0.15
    "lidinoid": ((0.5, (2, 1, 1), (_S, _C, _S)), (0.5, (1, 2, 1), (_S, _S, _C)),
                 (0.5, (1, 1, 2), (_C, _S, _S)), (-0.5, (2, 2, 0), (_C, _C, _C)),
                 (-0.5, (0, 2, 2), (_C, _C, _C)), (-0.5, (2, 0, 2), (_C, _C, _C)),
                 (0.15, (0, 0, 0), (_C, _C, _C))),
    # 4 cX cY cZ - (c2X c2Y + c2Y c2Z + c2Z c2X)
    "frd": ((4.0, (1, 1, 1), (_C, _C, _C)), (-1.0, (2, 2, 0), (_C, _C, _C)),
            (-1.0, (0, 2, 2), (_C, _C, _C)), (-1.0, (2, 0, 2), (_C, _C, _C))),
}
KINDS = tuple(NODAL)
VARIANTS = ("solid", "sheet")

_R3 = math.sqrt(3.0)
_FRD_C = (math.sqrt(33.0) - 1.0) / 8.0          # argmax of sin u (1 + 2 cos u): 4c^2 + c - 2 = 0
GRAD_BOUND: dict[str, float] = {
    # dF/dX = cY cX - sZ sX  <= sqrt(2)
    "gyroid": _R3 * math.sqrt(2.0),
    # dF/dX = -sX  <= 1 (attained: sqrt(3) at X = Y = Z = pi/2)
    "schwarz_p": _R3,
    # dF/dX = cX cos(Y - Z) - sX sin(Y + Z)  <= sqrt(2)
    "schwarz_d": _R3 * math.sqrt(2.0),
    # dF/dX = -sX (3 + 4 cY cZ)  <= 7
    "neovius": _R3 * 7.0,
    # dF/dX = 2 sX (2 cX - cY - cZ)  <= 4 |sX| (1 + |cX|) <= 4 * 3 sqrt(3) / 4
    "iwp": _R3 * 3.0 * _R3,
    # dF/dX = -2 s2X sY cZ + (cY c2Z) cX - (c2Y sZ) sX  <= 2 + sqrt(2)
    "fischer_koch_s": _R3 * (2.0 + math.sqrt(2.0)),
    # dF/dX = (cY sZ) c2X + (c2Y + c2Z) s2X + ((s2Y cZ) cX - (sY s2Z) sX) / 2
    #       <= sqrt(1 + 4) + sqrt(2) / 2
    "lidinoid": _R3 * (math.sqrt(5.0) + 0.5 * math.sqrt(2.0)),
    # dF/dX = -4 sX cY cZ + 2 s2X (c2Y + c2Z)  <= 4 |sX| (1 + 2 |cX|)
    "frd": _R3 * 4.0 * math.sqrt(1.0 - _FRD_C ** 2) * (1.0 + 2.0 * _FRD_C),
}


def nodal_field(kind: str, theta: np.ndarray) -> np.ndarray:
    """The nodal approximation F of `kind` at phases `theta` ((n, 3), radians): (n,) float64.

    Raises
    ------
    ValueError
        If `kind` is not one of `KINDS`.
    """
    if kind not in NODAL:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    th = np.asarray(theta, dtype=np.float64)
    cache: dict = {}

    def trig(axis, n, t):
        key = (axis, n, t)
        if key not in cache:
            arg = n * th[:, axis]
            cache[key] = np.sin(arg) if t == _S else np.cos(arg)
        return cache[key]

    out = np.zeros(th.shape[0])
    for amp, ns, ts in NODAL[kind]:
        term = np.full(th.shape[0], amp)
        for axis in range(3):
            if ns[axis] != 0 or ts[axis] == _S:
                term = term * trig(axis, ns[axis], ts[axis])
        out += term
    return out


def _glsl_trig(axis: int, n: int, t: str) -> str:
    comp = "xyz"[axis]
    arg = f"th.{comp}" if n == 1 else f"{glsl_float(n)} * th.{comp}"
    return f"{'sin' if t == _S else 'cos'}({arg})"


def _nodal_glsl(kind: str) -> str:
    terms = []
    for amp, ns, ts in NODAL[kind]:
        factors = [_glsl_trig(a, ns[a], ts[a]) for a in range(3) if ns[a] != 0 or ts[a] == _S]
        terms.append(" * ".join([glsl_float(amp)] + factors))
    return f"float tpms_{kind}(vec3 th) {{\n    return {' + '.join(terms)};\n}}"


def _finite(name: str, value, shape=None) -> np.ndarray:
    try:
        a = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be numeric, got {value!r}") from None
    if shape is not None:
        if a.ndim == 0 and shape == (3,):
            a = np.full(3, float(a))
        if a.shape != shape:
            raise ValueError(f"{name} must have shape {shape}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite, got {value!r}")
    a.setflags(write=False)
    return a


def _cell(name: str, value) -> np.ndarray:
    c = _finite(name, value, (3,))
    if np.any(c <= 0):
        raise ValueError(f"{name} must be > 0 mm (a float or three), got {value!r}")
    return c


@dataclass(frozen=True, eq=False)
class Periodic(SDF):
    """A triply periodic surface: the solid network or the sheet of a TPMS nodal function.

    f(p) = F(theta) - t(p) (variant "solid") or |F(theta)| - t(p) ("sheet"), negative
    inside, with theta = 2 pi (q - q0) / c(p) per axis, q = matrix @ p (q0 = 0 unless the
    cell is graded).  The solid fills F < t; the sheet is the band |F| < t.

    kind : one of `KINDS`: gyroid, schwarz_p, schwarz_d (diamond), neovius, iwp,
        fischer_koch_s, lidinoid, frd (see `NODAL`; amplitudes differ per kind, e.g.
        gyroid in [-1.5, 1.5], schwarz_p in [-3, 3]).
    cell : mm, > 0, a float or (3,) (anisotropic cell), the period of q per axis.
    level : t (at the start of the grading span); any finite value for "solid", >= 0 for
        "sheet".
    variant : "solid" or "sheet".
    matrix : (3, 3) invertible, applied to points before the phases (rotation, shear,
        scale), or None for the identity.
    level_end : t at the end of the grading span (None: not graded).
    cell_end : the cell at the end of the span (None: not graded); needs `extent`.
    grade_axis : (3,) nonzero direction (normalised) along which s = p . axis runs.
    grade_span : (a0, a1) mm, a0 < a1: u = clamp((s - a0) / (a1 - a0), 0, 1) and
        t = level + (level_end - level) u, cell = cell + (cell_end - cell) u.
    extent : ((x0, y0, z0), (x1, y1, z1)) mm, required with a graded cell and refused
        without: points are clamped to it (outside it the pattern is extruded), and the
        phase is anchored at its centre.

    Raises
    ------
    ValueError
        For an unknown kind or variant, a cell <= 0, a NaN / infinite parameter, a
        singular matrix, a negative sheet level, a0 >= a1, a zero axis, or a graded cell
        without an extent.
    """

    kind: str = "gyroid"
    cell: object = 1.0
    level: float = 0.0
    variant: str = "solid"
    matrix: object = None
    level_end: float | None = None
    cell_end: object = None
    grade_axis: tuple = (0.0, 0.0, 1.0)
    grade_span: tuple = (0.0, 1.0)
    extent: object = None

    def __post_init__(self):
        if self.kind not in NODAL:
            raise ValueError(f"kind must be one of {KINDS}, got {self.kind!r}")
        if self.variant not in VARIANTS:
            raise ValueError(f"variant must be one of {VARIANTS}, got {self.variant!r}")
        set_ = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731
        set_("cell", _cell("cell", self.cell))
        t0 = float(_finite("level", self.level))
        t1 = t0 if self.level_end is None else float(_finite("level_end", self.level_end))
        if self.variant == "sheet" and min(t0, t1) < 0:
            raise ValueError(f"a sheet's level (half-width of the band |F| < t) must be >= 0, "
                             f"got {t0!r} .. {t1!r}")
        set_("level", t0)
        set_("level_end", None if self.level_end is None else t1)
        m = np.eye(3) if self.matrix is None else _finite("matrix", self.matrix, (3, 3))
        sv = np.linalg.svd(m, compute_uv=False)
        if sv[-1] <= 1e-12 * sv[0]:
            raise ValueError(f"matrix is singular (singular values {sv.tolist()})")
        m.setflags(write=False)
        set_("matrix", None if self.matrix is None else m)
        axis = _finite("grade_axis", self.grade_axis, (3,))
        norm = float(np.linalg.norm(axis))
        if norm == 0.0:
            raise ValueError("grade_axis must be a nonzero direction")
        axis = axis / norm
        axis.setflags(write=False)
        set_("grade_axis", axis)
        span = _finite("grade_span", self.grade_span, (2,))
        if not span[0] < span[1]:
            raise ValueError(f"grade_span (a0, a1) needs a0 < a1, got {tuple(span)}")
        set_("grade_span", (float(span[0]), float(span[1])))
        c1 = None if self.cell_end is None else _cell("cell_end", self.cell_end)
        set_("cell_end", c1)
        if (c1 is None) != (self.extent is None):
            raise ValueError("extent (a box in mm) is required with a graded cell (cell_end) "
                             "and only allowed with one")
        if self.extent is not None:
            box = _finite("extent", self.extent, (2, 3))
            if np.any(box[1] < box[0]):
                raise ValueError(f"extent needs lo <= hi per axis, got {self.extent!r}")
            set_("extent", (tuple(box[0]), tuple(box[1])))
        set_("_lipschitz", self._bound(m))

    # -- geometry ---------------------------------------------------------------------------
    @property
    def graded_cell(self) -> bool:
        return self.cell_end is not None

    def _bound(self, m: np.ndarray) -> float:
        a0, a1 = self.grade_span
        t1 = self.level if self.level_end is None else self.level_end
        grad_t = abs(t1 - self.level) / (a1 - a0)
        if not self.graded_cell:
            jac = np.linalg.norm((TWO_PI / self.cell)[:, None] * m, 2)
        else:
            c0, c1 = self.cell, self.cell_end
            k_max = TWO_PI / float(np.min(np.minimum(c0, c1)))
            dk = TWO_PI * np.abs(c1 - c0) / ((a1 - a0) * np.minimum(c0, c1) ** 2)
            half = 0.5 * (np.array(self.extent[1]) - np.array(self.extent[0]))
            q_range = np.abs(m) @ half
            jac = k_max * np.linalg.norm(m, 2) + float(np.linalg.norm(dk * q_range))
        return float(GRAD_BOUND[self.kind] * jac + grad_t)

    @property
    def lipschitz(self) -> float:
        return self._lipschitz

    def _grade(self, p: np.ndarray) -> np.ndarray:
        a0, a1 = self.grade_span
        return np.clip((p @ self.grade_axis - a0) / (a1 - a0), 0.0, 1.0)

    def phases(self, points) -> np.ndarray:
        """theta at `points` ((n, 3) mm): (n, 3) radians (not reduced modulo 2 pi)."""
        p = as_points(points)
        if self.extent is not None:
            p = np.clip(p, self.extent[0], self.extent[1])
        q = p if self.matrix is None else p @ self.matrix.T
        if not self.graded_cell:
            return q * (TWO_PI / self.cell)
        centre = 0.5 * (np.array(self.extent[0]) + np.array(self.extent[1]))
        q0 = centre if self.matrix is None else self.matrix @ centre
        u = self._grade(p)[:, None]
        return TWO_PI * (q - q0) / (self.cell + (self.cell_end - self.cell) * u)

    def field(self, points) -> np.ndarray:
        p = as_points(points)
        f = nodal_field(self.kind, self.phases(p))
        if self.variant == "sheet":
            f = np.abs(f)
        if self.level_end is None:
            return f - self.level
        if self.extent is not None:
            p = np.clip(p, self.extent[0], self.extent[1])
        return f - (self.level + (self.level_end - self.level) * self._grade(p))

    # -- GLSL -------------------------------------------------------------------------------
    def glsl(self, module: GlslModule) -> str:
        module.helper(f"tpms_{self.kind}", _nodal_glsl(self.kind))
        return module.function(self, self._glsl_source)

    def _glsl_source(self, name: str) -> str:
        v3 = lambda a: "vec3(" + ", ".join(glsl_float(x) for x in a) + ")"  # noqa: E731
        lines = [f"float {name}(vec3 p) {{"]
        if self.extent is not None:
            lines.append(f"    p = clamp(p, {v3(self.extent[0])}, {v3(self.extent[1])});")
        q = "p"
        if self.matrix is not None:
            cols = ", ".join(glsl_float(self.matrix[r, c]) for c in range(3) for r in range(3))
            lines.append(f"    vec3 q = mat3({cols}) * p;")
            q = "q"
        graded = self.graded_cell or self.level_end is not None
        if graded:
            a0, a1 = self.grade_span
            lines.append(f"    float u = clamp((dot(p, {v3(self.grade_axis)}) - {glsl_float(a0)})"
                         f" * {glsl_float(1.0 / (a1 - a0))}, 0.0, 1.0);")
        if self.graded_cell:
            centre = 0.5 * (np.array(self.extent[0]) + np.array(self.extent[1]))
            q0 = centre if self.matrix is None else self.matrix @ centre
            lines.append(f"    vec3 c = mix({v3(self.cell)}, {v3(self.cell_end)}, u);")
            lines.append(f"    vec3 th = 6.283185307179586 * fract(({q} - {v3(q0)}) / c);")
        else:
            lines.append(f"    vec3 th = 6.283185307179586 * fract({q} * {v3(1.0 / self.cell)});")
        f = f"tpms_{self.kind}(th)"
        if self.variant == "sheet":
            f = f"abs({f})"
        if self.level_end is not None:
            t = f"mix({glsl_float(self.level)}, {glsl_float(self.level_end)}, u)"
        else:
            t = glsl_float(self.level)
        lines.append(f"    return {f} - {t};\n}}")
        return "\n".join(lines)


@dataclass(frozen=True, eq=False)
class TrigTerm:
    """One term of a `TrigSum`: amplitude * prod_i trig_i(freq_i 2 pi x_i / width + phase_i).

    amplitude : finite; freq : (3,) finite (cycles per width); phase : (3,) radians;
    trig : three of "sin" / "cos".

    Raises
    ------
    ValueError
        For a non-finite number or a trig other than "sin" / "cos".
    """

    amplitude: float = 1.0
    freq: tuple = (1.0, 1.0, 1.0)
    phase: tuple = (0.0, 0.0, 0.0)
    trig: tuple = ("sin", "sin", "sin")

    def __post_init__(self):
        object.__setattr__(self, "amplitude", float(_finite("amplitude", self.amplitude)))
        object.__setattr__(self, "freq", _finite("freq", self.freq, (3,)))
        object.__setattr__(self, "phase", _finite("phase", self.phase, (3,)))
        trig = tuple(self.trig) if not isinstance(self.trig, str) else (self.trig,) * 3
        if len(trig) != 3 or any(t not in ("sin", "cos") for t in trig):
            raise ValueError(f"trig must be three of 'sin' / 'cos', got {self.trig!r}")
        object.__setattr__(self, "trig", trig)


@dataclass(frozen=True, eq=False)
class TrigSum(SDF):
    """Eq. 11: f(x) = sum_j a_j prod_i trig_ij(freq_ij 2 pi x_i / width + phase_ij) - level.

    terms : non-empty sequence of `TrigTerm` (or tuples of its arguments).
    width : mm, > 0, the microstructure's width (one cycle at freq 1).
    level : subtracted from the sum (the surface is the sum's `level` set).

    A term's gradient is at most |a| |freq| 2 pi / width, so the bound is their sum.

    Raises
    ------
    ValueError
        For no terms, a term that is not one, width <= 0 or a non-finite level.
    """

    terms: tuple = ()
    width: float = 1.0
    level: float = 0.0

    def __post_init__(self):
        terms = []
        for i, t in enumerate(self.terms):
            if not isinstance(t, (TrigTerm, tuple, list)):
                raise ValueError(f"term {i} is a {type(t).__name__}, not a TrigTerm")
            terms.append(t if isinstance(t, TrigTerm) else TrigTerm(*t))
        terms = tuple(terms)
        if not terms:
            raise ValueError("a TrigSum needs at least one term")
        object.__setattr__(self, "terms", terms)
        w = float(_finite("width", self.width))
        if w <= 0:
            raise ValueError(f"width must be > 0 mm, got {self.width!r}")
        object.__setattr__(self, "width", w)
        object.__setattr__(self, "level", float(_finite("level", self.level)))

    @property
    def lipschitz(self) -> float:
        return float(sum(abs(t.amplitude) * np.linalg.norm(t.freq) for t in self.terms)
                     * TWO_PI / self.width)

    def field(self, points) -> np.ndarray:
        p = as_points(points)
        out = np.full(p.shape[0], -self.level)
        for t in self.terms:
            arg = p * (t.freq * (TWO_PI / self.width)) + t.phase
            term = np.full(p.shape[0], t.amplitude)
            for i in range(3):
                term *= np.sin(arg[:, i]) if t.trig[i] == "sin" else np.cos(arg[:, i])
            out += term
        return out

    def glsl(self, module: GlslModule) -> str:
        def make(name):
            parts = []
            for t in self.terms:
                f = [f"{t.trig[i]}({glsl_float(t.freq[i] * TWO_PI / self.width)} * p.{'xyz'[i]}"
                     f" + {glsl_float(t.phase[i])})" for i in range(3)]
                parts.append(" * ".join([glsl_float(t.amplitude)] + f))
            body = " + ".join(parts)
            return f"float {name}(vec3 p) {{\n    return {body} - {glsl_float(self.level)};\n}}"
        return module.function(self, make)
