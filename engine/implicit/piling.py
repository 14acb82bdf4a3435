"""Granular piles (paper 004, section 3.3, eq. 10): one grain per lattice cell, a deformed grid.

The lattice is the one of `agglomerate` (cell width w, the 27-neighbourhood,
the guard b), with every cell holding a grain centred in its cell (no rule:
a pile has no gaps to carve).  Eq. 10 was lost in extraction; implemented is
the form the prose describes:

* grid deformation ``x' = x + P(s) N(x)``: P a polynomial (mm) of
  ``s = clamp(x_a, lo, hi)`` along `deform_axis` a over `deform_span`
  (the domain of validity; beyond it P keeps its end value) and N a
  gyroid-like trigonometric vector noise ``N = (sin A_x cos A_y,
  sin A_y cos A_z, sin A_z cos A_x)`` with ``A = k x + phi`` (k =
  `noise_frequency`, rad / mm; phases phi from the seed), |N_i| <= 1;
* a rotation per cell about one axis by the angle
  ``theta(c) = 2 pi (Q(c) mod n) / n``, Q an integer polynomial of the cell
  index (`congruence` form) and n = `rotation_steps`: a polynomial angle
  taken modulo a full turn, computed exactly (integer residues) in numpy
  and GLSL;
* a convex-to-concave grain: with g the convex grain (a sphere of radius R,
  or a cube of half-extent R with rounded edges) and k(q) the distance to
  six balls of radius rho = dimple R centred at +-R on the local axes, the
  grain is ``(1 - lam) g + lam max(g, rho - k)``, lam in [0, 1] from
  `concavity` (constant, or a linear ramp between `concavity` and
  `concavity_end` over `concavity_span` along `concavity_axis`, taken at the
  cell centre): lam = 0 is the convex grain, lam = 1 the dimpled (concave)
  one, smoothly in between.

The field is ``f(x) = min( min over the 27 cells around x' of G_c(x'), b(x') )``.

Bounds.  Each G_c is 1-Lipschitz (a convex combination of 1-Lipschitz
functions), so |G_c| is at most the distance to its own zero set, and
``G_c(q) >= |q| - r`` (r the convex grain's bounding radius; the dimples only
remove material), which is all the proof in `agglomerate` uses: in x' the
min is a 1-Lipschitz lower bound of the distance to the grains.  The
deformation phi(x) = x + P N has ``||D phi||_2 <= 1 + |P| ||DN||_2 +
|P'| |N| <= 1 + sqrt(3) (k P_max + P'_max)`` (each row of DN has norm <= k,
|N| <= sqrt(3); P_max, P'_max bound |P|, |P'| over the span, computed as
sum |b_n| h^n of P's coefficients about the span centre, h its half
width), which is the carried `lipschitz`.

Domain of validity.  The deformation must move points by less than half a
cell along each axis, ``P_max < w / 2`` (refused otherwise): then x' lies
within the 27 cells of x, each grain stays among its lattice neighbours and
the pile keeps its order.  When also ``sqrt(3) (k P_max + P'_max) < 1``, phi
is injective and the grains (R <= w / 2) never intersect; beyond that the
field is still a valid lower bound, but grains may fold into each other.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.polynomial import Polynomial

from . import cell_hash, congruence
from .agglomerate import NEIGHBOURS, check_number, guard_distance, guard_glsl
from .shapes import round_box, shape_glsl, sphere
from .values import SDF, as_points, glsl_float

__all__ = ["Pile", "GRAINS"]

GRAINS = ("sphere", "round_box")
_TWO_PI = 2.0 * math.pi
_SQRT3 = math.sqrt(3.0)


def _span(name, span):
    s = np.asarray(span, dtype=np.float64).reshape(-1)
    if not (s.shape == (2,) and np.all(np.isfinite(s)) and s[0] < s[1]):
        raise ValueError(f"{name} must be finite (start, end) mm with start < end, got {span!r}")
    return float(s[0]), float(s[1])


def _axis(name, a):
    if a not in (0, 1, 2):
        raise ValueError(f"{name} must be 0, 1 or 2, got {a!r}")
    return int(a)


def _dimple_distance(q: np.ndarray, R: float) -> np.ndarray:
    """Distance from local points to the nearest of the six points +-R e_a."""
    a = np.abs(q)
    return np.minimum(np.minimum(np.sqrt((a[:, 0] - R) ** 2 + q[:, 1] ** 2 + q[:, 2] ** 2),
                                 np.sqrt(q[:, 0] ** 2 + (a[:, 1] - R) ** 2 + q[:, 2] ** 2)),
                      np.sqrt(q[:, 0] ** 2 + q[:, 1] ** 2 + (a[:, 2] - R) ** 2))


@dataclass(frozen=True, eq=False)
class Pile(SDF):
    """A pile of grains, one per cell of a deformed cubic lattice (see the module docstring).

    Parameters
    ----------
    cell : float, mm (> 0), the cell width w.
    grain : "sphere" or "round_box", the convex grain.
    radius : float, mm (> 0), R: the sphere's radius or the cube's half-extent; the
        grain's bounding radius must be <= w (R <= w / 2 keeps neighbours apart).
    rounding : float in [0, 1], the cube's edge rounding as a fraction of R.
    dimple : float in (0, 1], the dimple balls' radius as a fraction of R.
    concavity : float in [0, 1], lam; with concavity_end (in [0, 1]) a linear ramp
        from ``concavity_span[0]`` to ``[1]`` (mm, start < end) along concavity_axis.
    rotation_axis : 0, 1, 2; rotation_poly : integer polynomial of the cell index
        (empty: no rotation); rotation_steps : int in [1, congruence.MAX_MODULUS].
    deform_poly : tuple of float, the coefficients c_0, c_1, ... (mm^(1 - n)) of
        P(s) = sum c_n s^n (empty: no deformation); deform_axis : 0, 1, 2;
        deform_span : (lo, hi) mm, the domain of s.
    noise_frequency : float, rad / mm (>= 0).
    seed : int, the noise phases.

    Raises
    ------
    ValueError
        Naming the parameter and its allowed range (the deformation with its bound).
    """

    cell: float = 1.0
    grain: str = "sphere"
    radius: float = 0.5
    rounding: float = 0.25
    dimple: float = 0.5
    concavity: float = 0.0
    concavity_end: float | None = None
    concavity_axis: int = 2
    concavity_span: tuple = (0.0, 1.0)
    rotation_axis: int = 2
    rotation_poly: tuple = ()
    rotation_steps: int = 12
    deform_poly: tuple = ()
    deform_axis: int = 2
    deform_span: tuple = (0.0, 1.0)
    noise_frequency: float = 0.0
    seed: int = 0

    def __post_init__(self):
        w = check_number("cell width", self.cell, 0.0, lo_open=True)
        if self.grain not in GRAINS:
            raise ValueError(f"grain must be one of {GRAINS}, got {self.grain!r}")
        R = check_number("radius", self.radius, 0.0, lo_open=True)
        rounding = check_number("rounding", self.rounding, 0.0, 1.0)
        reach = R if self.grain == "sphere" else _SQRT3 * R * (1.0 - rounding) + rounding * R
        if reach > w:
            raise ValueError(f"radius must be at most {R * w / reach!r} mm for a {self.grain} grain in "
                             f"cell width {w!r} mm (bounding radius <= w, the 27-neighbourhood bound), "
                             f"got {R!r}")
        sets = {"cell": w, "radius": R, "rounding": rounding, "_reach": reach,
                "dimple": check_number("dimple", self.dimple, 0.0, 1.0, lo_open=True),
                "concavity": check_number("concavity", self.concavity, 0.0, 1.0),
                "concavity_axis": _axis("concavity_axis", self.concavity_axis),
                "rotation_axis": _axis("rotation_axis", self.rotation_axis),
                "deform_axis": _axis("deform_axis", self.deform_axis),
                "noise_frequency": check_number("noise_frequency", self.noise_frequency, 0.0)}
        if self.concavity_end is not None:
            sets["concavity_end"] = check_number("concavity_end", self.concavity_end, 0.0, 1.0)
            sets["concavity_span"] = _span("concavity_span", self.concavity_span)
        sets["rotation_poly"] = congruence.check_polynomial(self.rotation_poly, "rotation_poly")
        n = self.rotation_steps
        if not (isinstance(n, (int, np.integer)) and not isinstance(n, bool)
                and 1 <= n <= congruence.MAX_MODULUS):
            raise ValueError(f"rotation_steps must be an int in [1, {congruence.MAX_MODULUS}], got {n!r}")
        sets["rotation_steps"] = int(n)
        word = cell_hash.seed_word(self.seed)
        sets["_phases"] = tuple(_TWO_PI * float(cell_hash.cell_uniform(np.uint32(word), r)) for r in range(3))
        sets.update(self._deformation(w))
        for k, v in sets.items():
            object.__setattr__(self, k, v)

    def _deformation(self, w) -> dict:
        coef = np.asarray(self.deform_poly, dtype=np.float64).reshape(-1)
        if coef.size and not np.all(np.isfinite(coef)):
            raise ValueError(f"deform_poly coefficients must be finite, got {self.deform_poly!r}")
        if coef.size > 9:
            raise ValueError(f"deform_poly must have at most 9 coefficients (degree 8), got {coef.size}")
        lo, hi = _span("deform_span", self.deform_span)
        mid, h = 0.5 * (lo + hi), 0.5 * (hi - lo)
        b = Polynomial(coef)(Polynomial([mid, 1.0])).coef[:coef.size] if coef.size else coef
        pmax = float(sum(abs(c) * h ** i for i, c in enumerate(b))) * (1.0 + 1e-12)
        dmax = float(sum(i * abs(c) * h ** (i - 1) for i, c in enumerate(b) if i)) * (1.0 + 1e-12)
        if not pmax < 0.5 * w:
            raise ValueError(f"deformation amplitude: sup |deform_poly| over deform_span ({lo!r}, {hi!r}) "
                             f"is {pmax!r} mm, it must be < w / 2 = {0.5 * w!r} mm (the 27-neighbourhood)")
        return {"deform_poly": tuple(float(c) for c in coef), "deform_span": (lo, hi), "_mid": mid,
                "_shifted": tuple(float(c) for c in b), "_pmax": pmax, "_dmax": dmax}

    @property
    def lipschitz(self):
        if not self._shifted:
            return 1.0
        return 1.0 + _SQRT3 * (self.noise_frequency * self._pmax + self._dmax)

    # -- pieces -----------------------------------------------------------------------

    @property
    def noise_phases(self) -> tuple:
        """The phases phi (rad, in [0, 2 pi)) of the noise, from the seed."""
        return self._phases

    @property
    def deformation_bounds(self) -> tuple:
        """(P_max, P'_max): the bounds of |P| (mm) and |P'| over `deform_span`."""
        return self._pmax, self._dmax

    def deform(self, points) -> np.ndarray:
        """The lattice frame x' = x + P(s) N(x) of world points: (n, 3) mm."""
        x = as_points(points)
        if not self._shifted:
            return x
        u = np.clip(x[:, self.deform_axis], *self.deform_span) - self._mid
        amp = np.zeros(len(x))
        for c in reversed(self._shifted):
            amp = amp * u + c
        a = self.noise_frequency * x + np.asarray(self._phases)
        s, c = np.sin(a), np.cos(a)
        noise = np.stack([s[:, 0] * c[:, 1], s[:, 1] * c[:, 2], s[:, 2] * c[:, 0]], axis=1)
        return x + amp[:, None] * noise

    def angles(self, cells) -> np.ndarray:
        """Rotation angles (rad) of cells ((n, 3) int): (n,) float64."""
        if not self.rotation_poly:
            return np.zeros(len(cells))
        r = congruence.residues(self.rotation_poly, self.rotation_steps, cells)
        return r * (_TWO_PI / self.rotation_steps)

    def concavities(self, cells) -> np.ndarray:
        """lam of cells ((n, 3) int), from their centres: (n,) float64 in [0, 1]."""
        c = np.asarray(cells)
        if self.concavity_end is None:
            return np.full(len(c), self.concavity)
        s0, s1 = self.concavity_span
        t = np.clip(((c[:, self.concavity_axis] + 0.5) * self.cell - s0) / (s1 - s0), 0.0, 1.0)
        return self.concavity * (1.0 - t) + self.concavity_end * t

    def _grain(self, q, lam):
        R = self.radius
        convex = sphere(q, R) if self.grain == "sphere" else round_box(q, R, R, R, self.rounding * R)
        cut = self.dimple * R - _dimple_distance(q, R)
        return convex + lam * np.maximum(cut - convex, 0.0)

    def field(self, points):
        x = self.deform(points)
        base, best = guard_distance(x, self.cell)
        u, v = (self.rotation_axis + 1) % 3, (self.rotation_axis + 2) % 3
        for off in NEIGHBOURS:
            cells = base + off
            q = x - self.cell * (cells + 0.5)
            if self.rotation_poly:
                th = self.angles(cells)
                cs, sn = np.cos(th), np.sin(th)
                qu, qv = q[:, u].copy(), q[:, v].copy()
                q[:, u], q[:, v] = cs * qu + sn * qv, cs * qv - sn * qu
            best = np.minimum(best, self._grain(q, self.concavities(cells)))
        return best

    # -- GLSL -------------------------------------------------------------------------

    def _glsl_deform(self) -> str:
        if not self._shifted:
            return "vec3 x = p;"
        lo, hi = (glsl_float(s) for s in self.deform_span)
        ax = "xyz"[self.deform_axis]
        horner = glsl_float(self._shifted[-1])
        for c in reversed(self._shifted[:-1]):
            horner = f"({horner} * u + {glsl_float(c)})"
        ph = ", ".join(glsl_float(v) for v in self._phases)
        return (f"float u = clamp(p.{ax}, {lo}, {hi}) - {glsl_float(self._mid)};\n"
                f"    vec3 a = {glsl_float(self.noise_frequency)} * p + vec3({ph});\n"
                f"    vec3 x = p + {horner} * vec3(sin(a.x) * cos(a.y), sin(a.y) * cos(a.z), "
                f"sin(a.z) * cos(a.x));")

    def glsl(self, module):
        w = glsl_float(self.cell)
        R = glsl_float(self.radius)
        if self.grain == "sphere":
            convex = f"{shape_glsl(module, 'sphere')}(q, {R})"
        else:
            rd = glsl_float(self.rounding * self.radius)
            convex = f"{shape_glsl(module, 'round_box')}(q, {R}, {R}, {R}, {rd})"
        rotate = ""
        if self.rotation_poly:
            congruence.add_glsl(module)
            steps = self.rotation_steps
            angle = module.function(self, lambda n: congruence.glsl_residue_source(
                n, self.rotation_poly, steps), tag="_angle")
            U, V = "xyz"[(self.rotation_axis + 1) % 3], "xyz"[(self.rotation_axis + 2) % 3]
            rotate = (f"float th = float({angle}(cell)) * {glsl_float(_TWO_PI / steps)};\n"
                      f"        float cs = cos(th);\n        float sn = sin(th);\n"
                      f"        q.{U}{V} = vec2(cs * q.{U} + sn * q.{V}, cs * q.{V} - sn * q.{U});")
        if self.concavity_end is None:
            lam = glsl_float(self.concavity)
        else:
            s0, s1 = self.concavity_span
            ax = "xyz"[self.concavity_axis]
            lam = (f"mix({glsl_float(self.concavity)}, {glsl_float(self.concavity_end)}, clamp(("
                   f"(float(cell.{ax}) + 0.5) * {w} - {glsl_float(s0)}) / {glsl_float(s1 - s0)}, 0.0, 1.0))")

        def make(n):
            return f"""float {n}(vec3 p) {{
    {self._glsl_deform()}
{guard_glsl(w)}
    for (int dz = -1; dz <= 1; ++dz) for (int dy = -1; dy <= 1; ++dy) for (int dx = -1; dx <= 1; ++dx) {{
        ivec3 cell = ib + ivec3(dx, dy, dz);
        vec3 q = x - {w} * (vec3(cell) + 0.5);
        {rotate}
        float g = {convex};
        vec3 aq = abs(q);
        float k = min(min(length(vec3(aq.x - {R}, q.y, q.z)), length(vec3(q.x, aq.y - {R}, q.z))),
                      length(vec3(q.x, q.y, aq.z - {R})));
        float cut = {glsl_float(self.dimple * self.radius)} - k;
        best = min(best, g + ({lam}) * max(cut - g, 0.0));
    }}
    return best;
}}"""
        return module.function(self, make)
