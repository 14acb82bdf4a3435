"""Suspended particle clouds (paper 004, section 3.1): one particle per cell of a cubic grid.

Space is cut into cubic cells of width w (mm); cell c = (i, j, k) covers
``[c w, (c + 1) w]``.  Each cell draws uniforms u_0 .. u_8 from the hash of
its index and the seed (`cell_hash`), the same numbers in numpy and GLSL:

* u_0: Russian roulette, the particle exists iff ``u_0 < density`` (the
  keep probability, taken at the cell centre: constant or a linear ramp along
  an axis, times an optional `density_field` sampled there), and the cell is
  one an optional congruence `rule` keeps (particle correlation by rejection,
  supplementary 10.2: e.g. `particle_fields.clusters`; the checks of both
  fields and the rule live in `particle_fields`).  The GLSL twin forms the
  probability in float32, so a cell whose u_0 lies within float32 rounding
  of it may differ between numpy and the GPU (the ramp's too);
* u_1, u_2: the size s (mm) from a `SizeDistribution`, clamped to
  ``[0, s_max]`` where ``s_max * bound = w / 2`` (bound: the unit shape's
  bounding radius); a size of 0 gives no particle;
* u_3 .. u_5: the centre ``w (c + 0.5 + jitter (u - 0.5) (1 - 2 r_b / w))``
  with r_b = s * bound, so the bounding sphere stays inside the cell;
* u_6 .. u_8: an optional uniformly random rotation (Shoemake's quaternion).

The particle is the unit shape (`shapes.SHAPES`, parameters `proportions`)
scaled by s and rotated.  A point x (after the optional turbulence warp
``x = p + A T(p)`` of `turbulence.Turbulence`, supplementary 10.1: octaves of
sines of the mixed, cyclically shifted coordinates; one octave with a scalar
amplitude a and no mixing is ``x = p + a sin(f p.yzx)``) lies in one cell of
the dual grid (offset by w / 2); its 2 x 2 x 2 block of nearest cells, from
``floor(x / w - 0.5)``, are the only ones whose particles can reach it
(eq. 4).  The field is

    f(x) = min( min over the block's particles of d_i(x),  b(x) ) - offset - o(x),

with b(x) the distance from x to the outside of the block, at least w / 2,
and o an optional `offset_field` (eq. 6's spatially varying offset).  Why
b: every particle outside the block lies in its own cell, outside the
block, so it is at least b(x) away; hence min(g, b) <= the distance to the
union of all particles (a lower bound, exact wherever that distance is at
most w / 2 and inside particles), it stays finite where the block's cells
are empty, and it is continuous across dual-cell faces (there b = w / 2 and
the particles that leave or enter the block are at least w / 2 away).  The
argument only needs each particle inside its own cell, not which cells are
kept: the roulette, the density field and the rule all decide per cell (the
field read at the cell centre, never at x), so a particle is whole or
absent and the bound, its exactness and continuity hold for any kept set.
A min of 1-Lipschitz functions, min(g, b) is 1-Lipschitz (L_s for a
non-Euclidean shape); o, trilinear in its samples, has ``|grad o| <= L_o``
(`field_sampling`: ``sqrt(Dx^2 + Dy^2 + Dz^2) <= sqrt(3) max_a Da``, Da the
largest sample difference along axis a over the spacing), so f is
``(L_s + L_o)``-Lipschitz in x; the warp multiplies the bound by its own
Lipschitz constant ``1 + ||A||_2 ||M||_2 f sum_o (g l)^o`` (proved in
`turbulence`; ``1 + a f`` for the single-octave warp).  The total offset
``offset + o(x)`` must stay below w / 2 everywhere (o never exceeds its
largest sample) so that b - offset - o > 0: the guard never creates
material away from the particles; then, where
f <= 0, min(g, b) < w / 2 <= b, so f is the particles' own distance minus
the offset and (exact shapes) the solid is ``{x : dist(x, particles) <=
offset + o(x)}``.  There is no lower limit on ``offset + o``: where it is
at most -w / 2 no particle remains (a particle's inner radius is at most its
bounding radius, at most w / 2).  Both fields live in the particles' frame x.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field as dc_field
from typing import NamedTuple

import numpy as np

from . import cell_hash
from .congruence import CombinedRule, CongruenceRule
from .field_sampling import GridField
from .particle_fields import check_density_field, check_offset_field, check_rule
from .shapes import check_shape_params, shape_glsl, shape_spec
from .turbulence import Turbulence
from .values import SDF, glsl_float

__all__ = ["SizeDistribution", "Suspension", "Particles", "shoemake_rotation", "MAX_BOX_CELLS"]

MAX_BOX_CELLS = 4_000_000           # cells `particles_in_box` visits at most
_TWO_PI = 2.0 * math.pi
_PARAMS = {"fixed": ("size",), "uniform": ("lo", "hi"), "normal": ("mean", "sd"),
           "lognormal": ("mu", "sigma")}


@dataclass(frozen=True)
class SizeDistribution:
    """The distribution of a particle's size s (mm; the scale of the unit shape).

    kind : "fixed" (a = size), "uniform" (a = lo, b = hi), "normal" (a = mean,
        b = sd; Box-Muller from two uniforms) or "lognormal" (s = exp(a + b z)
        with z standard normal: a = mu, the log of the median in mm, b = sigma).

    Raises
    ------
    ValueError
        On an unknown kind or a parameter out of range (sizes > 0, lo <= hi,
        sd and sigma >= 0, all finite).
    """

    kind: str = "fixed"
    a: float = 0.3
    b: float = 0.0

    def __post_init__(self):
        if self.kind not in _PARAMS:
            raise ValueError(f"size distribution kind must be one of {sorted(_PARAMS)}, got {self.kind!r}")
        a, b = float(self.a), float(self.b)
        if not (math.isfinite(a) and math.isfinite(b)):
            raise ValueError(f"size distribution parameters must be finite, got a={a!r}, b={b!r}")
        object.__setattr__(self, "a", a)
        object.__setattr__(self, "b", b)
        names = _PARAMS[self.kind]
        if self.kind != "lognormal" and not a > 0:
            raise ValueError(f"size distribution {names[0]} must be > 0 mm, got {a!r}")
        if self.kind == "uniform" and not b >= a:
            raise ValueError(f"size distribution hi must be >= lo = {a!r} mm, got {b!r}")
        if self.kind in ("normal", "lognormal") and not b >= 0:
            raise ValueError(f"size distribution {names[1]} must be >= 0, got {b!r}")

    def nominal(self) -> tuple[str, float]:
        """(name, size in mm) of the parameter that must fit in the cell: the fixed size,
        hi, the mean, or the median exp(mu)."""
        if self.kind == "lognormal":
            return "mu", math.exp(self.a)
        return _PARAMS[self.kind][-1 if self.kind == "uniform" else 0], float(
            self.b if self.kind == "uniform" else self.a)

    def sample(self, u1: np.ndarray, u2: np.ndarray) -> np.ndarray:
        """Sizes (mm, float64, unclamped) from uniforms u1, u2 in [0, 1)."""
        a, b = float(self.a), float(self.b)
        if self.kind == "fixed":
            return np.full(np.shape(u1), a)
        if self.kind == "uniform":
            return a + (b - a) * u1
        z = np.sqrt(-2.0 * np.log(1.0 - u1)) * np.cos(_TWO_PI * u2)
        return a + b * z if self.kind == "normal" else np.exp(a + b * z)

    def glsl(self, u1: str, u2: str) -> str:
        """A GLSL float expression of the size from uniforms named `u1`, `u2`."""
        a, b = glsl_float(self.a), glsl_float(self.b)
        if self.kind == "fixed":
            return a
        if self.kind == "uniform":
            return f"({a} + {glsl_float(self.b - self.a)} * {u1})"
        z = f"(sqrt(-2.0 * log(1.0 - {u1})) * cos({glsl_float(_TWO_PI)} * {u2}))"
        return f"({a} + {b} * {z})" if self.kind == "normal" else f"exp({a} + {b} * {z})"


def shoemake_rotation(u1, u2, u3) -> np.ndarray:
    """Uniformly random rotations from uniforms ((n,) each, [0, 1)): (n, 3, 3) float64.

    The unit quaternion (x, y, z, w) = (sqrt(1-u1) sin 2pi u2, sqrt(1-u1) cos 2pi u2,
    sqrt(u1) sin 2pi u3, sqrt(u1) cos 2pi u3) is uniform on S^3 (Shoemake 1992)."""
    a, b = np.sqrt(1.0 - u1), np.sqrt(u1)
    x, y = a * np.sin(_TWO_PI * u2), a * np.cos(_TWO_PI * u2)
    z, w = b * np.sin(_TWO_PI * u3), b * np.cos(_TWO_PI * u3)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], axis=-1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], axis=-1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], axis=-1),
    ], axis=-2)


_SHOEMAKE_GLSL = f"""mat3 mf_shoemake(float u1, float u2, float u3) {{
    float a = sqrt(1.0 - u1);
    float b = sqrt(u1);
    float x = a * sin({glsl_float(_TWO_PI)} * u2);
    float y = a * cos({glsl_float(_TWO_PI)} * u2);
    float z = b * sin({glsl_float(_TWO_PI)} * u3);
    float w = b * cos({glsl_float(_TWO_PI)} * u3);
    return mat3(1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + z * w), 2.0 * (x * z - y * w),
                2.0 * (x * y - z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z + x * w),
                2.0 * (x * z + y * w), 2.0 * (y * z - x * w), 1.0 - 2.0 * (x * x + y * y));
}}"""


class Particles(NamedTuple):
    """The particles of a set of cells (kept ones only).

    cells : (m, 3) int64; centres : (m, 3) float64 mm; sizes : (m,) float64 mm;
    rotations : (m, 3, 3) float64 (local -> world; identity without orientation);
    radii : (m,) float64 mm, bounding radii."""

    cells: np.ndarray
    centres: np.ndarray
    sizes: np.ndarray
    rotations: np.ndarray
    radii: np.ndarray


def _finite(name, v, lo=-math.inf, hi=math.inf, lo_open=False, hi_open=False):
    v = float(v)
    ok = math.isfinite(v) and (v > lo if lo_open else v >= lo) and (v < hi if hi_open else v <= hi)
    if not ok:
        rng = f"{'(' if lo_open else '['}{lo!r}, {hi!r}{')' if hi_open else ']'}"
        raise ValueError(f"{name} must be a finite number in {rng}, got {v!r}")
    return v


@dataclass(frozen=True, eq=False)
class Suspension(SDF):
    """A cloud of non-touching particles, one per grid cell (see the module docstring).

    Parameters
    ----------
    cell : float, mm (> 0), the grid cell width w.
    shape : str, a key of `shapes.SHAPES`; proportions : its parameters at size 1
        (empty: the shape's default).
    size : SizeDistribution (mm); its nominal size must fit the cell.
    jitter : float in [0, 1], 0 puts every particle at its cell centre (a lattice).
    orient : bool, random particle rotations.
    density : float in [0, 1], the probability a cell holds a particle; with
        `density_end` (in [0, 1]) it ramps linearly from `density` at coordinate
        ``density_span[0]`` to `density_end` at ``density_span[1]`` (mm, start < end)
        along axis `density_axis` (0, 1, 2), constant beyond.
    density_field : GridField (or a Field-like with values, lo, hi; samples in [0, 1]) or
        None: multiplies the keep probability, read at each cell's centre ``w (c + 0.5)``.
    rule : CongruenceRule, CombinedRule or None: only the cells it keeps may hold a
        particle (correlation by rejection; e.g. `particle_fields.clusters`).
    offset : float, mm (< w / 2), moves every surface outwards.
    offset_field : GridField (or a Field-like, mm) or None: added to `offset` at x; the
        total ``offset + max(offset_field)`` must stay < w / 2 (no lower limit: where
        ``offset + o(x) <= -w / 2`` no particle remains).
    warp_amplitude : float, mm (>= 0); warp_frequency : float, rad / mm (>= 0): the warp
        ``x = p + A T(p)`` (`turbulence.Turbulence`) with A = warp_amplitude * I.
    warp_octaves : int in [1, 8]; warp_gain : float in (0, 1]; warp_lacunarity : float in
        [1, 4]: the octaves of T, each `warp_gain` times the amplitude and `warp_lacunarity`
        times the frequency of the one before (octave 0 has phase 0, the others phases fixed
        by `seed`).
    warp_matrix : None or a 3 x 3 matrix M (finite) mixing p before the octaves read it.
    warp_amplitudes : None or a 3 x 3 matrix A (mm, finite) used instead of
        ``warp_amplitude * I``.
    seed : int.

    Raises
    ------
    ValueError
        Naming the parameter and its allowed range (the size parameter with the
        largest size the cell allows).
    """

    cell: float = 1.0
    shape: str = "sphere"
    proportions: tuple = ()
    size: SizeDistribution = dc_field(default_factory=SizeDistribution)
    jitter: float = 1.0
    orient: bool = False
    density: float = 1.0
    density_end: float | None = None
    density_axis: int = 2
    density_span: tuple = (0.0, 1.0)
    density_field: GridField | None = None
    rule: CongruenceRule | CombinedRule | None = None
    offset: float = 0.0
    offset_field: GridField | None = None
    warp_amplitude: float = 0.0
    warp_frequency: float = 0.0
    warp_octaves: int = 1
    warp_gain: float = 0.5
    warp_lacunarity: float = 2.0
    warp_matrix: tuple | None = None
    warp_amplitudes: tuple | None = None
    seed: int = 0

    def __post_init__(self):
        w = _finite("cell width", self.cell, 0.0, lo_open=True)
        props = check_shape_params(self.shape, self.proportions)
        if not isinstance(self.size, SizeDistribution):
            raise ValueError(f"size must be a SizeDistribution, got {type(self.size).__name__}")
        bound = float(shape_spec(self.shape).bound(*props))
        smax = 0.5 * w / bound
        name, nominal = self.size.nominal()
        if nominal > smax:
            if name == "mu":
                given, allowed = self.size.a, f"{math.log(smax)!r} (a median of {smax!r} mm)"
            else:
                given, allowed = nominal, f"{smax!r} mm"
            raise ValueError(f"size distribution parameter {name} = {given!r} is too large for cell "
                             f"width {w!r} mm: at most {allowed}, so that the bounding radius "
                             f"stays <= w / 2")
        object.__setattr__(self, "jitter", _finite("jitter", self.jitter, 0.0, 1.0))
        if not isinstance(self.orient, (bool, np.bool_)):
            raise ValueError(f"orient must be a bool, got {self.orient!r}")
        object.__setattr__(self, "density", _finite("density", self.density, 0.0, 1.0))
        if self.density_end is not None:
            object.__setattr__(self, "density_end", _finite("density_end", self.density_end, 0.0, 1.0))
            if self.density_axis not in (0, 1, 2):
                raise ValueError(f"density_axis must be 0, 1 or 2, got {self.density_axis!r}")
            span = np.asarray(self.density_span, dtype=np.float64).reshape(-1)
            if not (span.shape == (2,) and np.all(np.isfinite(span)) and span[0] < span[1]):
                raise ValueError(f"density_span must be finite (start, end) mm with start < end, "
                                 f"got {self.density_span!r}")
            object.__setattr__(self, "density_span", (float(span[0]), float(span[1])))
        for k, hi, hi_open, lo in (("offset", 0.5 * w, True, -math.inf),
                                   ("warp_amplitude", math.inf, False, 0.0),
                                   ("warp_frequency", math.inf, False, 0.0)):
            object.__setattr__(self, k, _finite(k, getattr(self, k), lo, hi, hi_open=hi_open))
        object.__setattr__(self, "density_field", check_density_field(self.density_field))
        object.__setattr__(self, "offset_field", check_offset_field(self.offset_field, self.offset, w))
        check_rule(self.rule)
        word = cell_hash.seed_word(self.seed)
        warp = self._turbulence_of()
        for k, v in (("cell", w), ("proportions", props), ("_bound", bound), ("_smax", smax),
                     ("_word", word), ("_warp", warp), ("warp_octaves", warp.octaves),
                     ("warp_gain", warp.gain), ("warp_lacunarity", warp.lacunarity),
                     ("warp_matrix", warp.matrix),
                     ("warp_amplitudes", None if self.warp_amplitudes is None else warp.amplitude)):
            object.__setattr__(self, k, v)

    def _turbulence_of(self) -> Turbulence:
        """The warp of the warp_* fields (checked, refusals naming those fields)."""
        full = self.warp_amplitudes is not None
        names = {"amplitude": "warp_amplitudes" if full else "warp_amplitude", "frequency": "warp_frequency",
                 "octaves": "warp_octaves", "gain": "warp_gain", "lacunarity": "warp_lacunarity",
                 "matrix": "warp_matrix"}
        return Turbulence.named(
            names, amplitude=self.warp_amplitudes if full else self.warp_amplitude,
            frequency=self.warp_frequency, octaves=self.warp_octaves, gain=self.warp_gain,
            lacunarity=self.warp_lacunarity, matrix=self.warp_matrix, seed=self.seed)

    @property
    def lipschitz(self):
        """(L_s + L_o) L_w: the shape's bound plus the offset field's, times the warp's
        (`Turbulence.lipschitz`, 1 + a f for the single-octave warp)."""
        l_o = 0.0 if self.offset_field is None else self.offset_field.lipschitz
        return (shape_spec(self.shape).lipschitz + l_o) * self._warp.lipschitz

    # -- the particles of given cells -------------------------------------------------

    def _density_of(self, cells: np.ndarray):
        """The keep probability of each cell ((m, 3) int): scalar or (m,) float64."""
        if self.density_end is None:
            p = float(self.density)
        else:
            s0, s1 = (float(v) for v in self.density_span)
            t = np.clip(((cells[:, self.density_axis] + 0.5) * self.cell - s0) / (s1 - s0), 0.0, 1.0)
            p = self.density * (1.0 - t) + self.density_end * t
        if self.density_field is not None:
            p = p * self.density_field.sample(self.cell * (cells + 0.5))
        return p

    def _particles(self, cells: np.ndarray):
        """keep (m,) bool, sizes (m,), centres (m, 3), rotations (m, 3, 3) or None."""
        stream = cell_hash.cell_stream(cells[:, 0], cells[:, 1], cells[:, 2], self._word)

        def u(r):
            return cell_hash.cell_uniform(stream, r)
        s = np.clip(self.size.sample(u(1), u(2)), 0.0, self._smax)
        keep = (u(0) < self._density_of(cells)) & (s > 0.0)
        if self.rule is not None:
            keep &= self.rule.keep(cells)
        jit = np.stack([u(3), u(4), u(5)], axis=1)
        shrink = 1.0 - 2.0 * s * self._bound / self.cell
        centres = self.cell * (cells + 0.5 + self.jitter * (jit - 0.5) * shrink[:, None])
        rot = shoemake_rotation(u(6), u(7), u(8)) if self.orient else None
        return keep, s, centres, rot

    def particles_in_box(self, lo, hi) -> Particles:
        """Every kept particle whose cell meets the box [lo, hi] (mm, in the particles'
        frame: the warped coordinates x when there is a warp).

        Raises
        ------
        ValueError
            If lo > hi on an axis, or the box spans more than `MAX_BOX_CELLS` cells.
        """
        lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
        if lo.shape != (3,) or hi.shape != (3,) or not np.all(lo <= hi):
            raise ValueError(f"box must be two (3,) corners with lo <= hi, got {lo!r}, {hi!r}")
        c0 = np.floor(lo / self.cell).astype(np.int64)
        c1 = np.floor(hi / self.cell).astype(np.int64)
        count = int(np.prod(c1 - c0 + 1))
        if count > MAX_BOX_CELLS:
            raise ValueError(f"box spans {count} cells, at most {MAX_BOX_CELLS}")
        axes = [np.arange(a, b + 1) for a, b in zip(c0, c1)]
        cells = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
        keep, s, centres, rot = self._particles(cells)
        if rot is None:
            rot = np.broadcast_to(np.eye(3), (len(cells), 3, 3))
        return Particles(cells[keep], centres[keep], s[keep], np.array(rot[keep]),
                         s[keep] * self._bound)

    # -- evaluation -------------------------------------------------------------------

    def warp(self, points) -> np.ndarray:
        """The particles' frame of world points: x = p + A T(p) (`Turbulence.warp`), (n, 3) mm."""
        return self._warp.warp(points)

    def field(self, points):
        x = self.warp(points)
        spec = shape_spec(self.shape)
        g = x / self.cell
        base = np.floor(g - 0.5)
        t = g - base
        best = self.cell * np.min(np.minimum(t, 2.0 - t), axis=1)
        base = base.astype(np.int64)
        for corner in range(8):
            cells = base + np.array([corner & 1, (corner >> 1) & 1, (corner >> 2) & 1])
            keep, s, centres, rot = self._particles(cells)
            q = x - centres
            if rot is not None:
                q = np.einsum("ni,nij->nj", q, rot)
            s = np.where(keep, s, 1.0)
            d = spec.fn(q, *(s * v for v in self.proportions))
            best = np.minimum(best, np.where(keep, d, np.inf))
        if self.offset_field is not None:
            best = best - self.offset_field.sample(x)
        return best - self.offset

    def glsl(self, module):
        cell_hash.add_glsl(module)
        helper = shape_glsl(module, self.shape)
        if self.orient:
            module.helper("mf_shoemake", _SHOEMAKE_GLSL)
        w = glsl_float(self.cell)
        args = ", ".join(f"s * {glsl_float(v)}" for v in self.proportions)
        if self.density_end is None:
            dens = glsl_float(self.density)
        else:
            s0, s1 = (float(v) for v in self.density_span)
            ax = "xyz"[self.density_axis]
            dens = (f"mix({glsl_float(self.density)}, {glsl_float(self.density_end)}, clamp(("
                    f"(float(cell.{ax}) + 0.5) * {w} - {glsl_float(s0)}) / {glsl_float(s1 - s0)}, 0.0, 1.0))")
        # every helper is defined before the cloud's own function (dependencies first)
        if self.density_field is not None:
            dens = f"{dens} * {self.density_field.glsl(module)}({w} * (vec3(cell) + 0.5))"
        ruled = "" if self.rule is None else f"if (!{self.rule.glsl(module)}(cell)) continue;"
        offset = glsl_float(self.offset)
        if self.offset_field is not None:
            offset = f"{offset} + {self.offset_field.glsl(module)}(x)"
        x = "p" if self._warp.is_identity else f"{self._warp.glsl(module)}(p)"
        def u(r):
            return f"mf_cell_uniform(st, {r}u)"
        rotate = f"q = q * mf_shoemake({u(6)}, {u(7)}, {u(8)});" if self.orient else ""
        size = self.size.glsl(u(1), u(2))

        def make(n):
            return f"""float {n}(vec3 p) {{
    vec3 x = {x};
    vec3 g = x / {w};
    vec3 base = floor(g - 0.5);
    vec3 t = g - base;
    vec3 e = min(t, 2.0 - t);
    float best = {w} * min(min(e.x, e.y), e.z);
    ivec3 ib = ivec3(base);
    for (int c = 0; c < 8; ++c) {{
        ivec3 cell = ib + ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
        {ruled}
        uint st = mf_cell_stream(cell, {self._word}u);
        float s = clamp({size}, 0.0, {glsl_float(self._smax)});
        if (!({u(0)} < {dens}) || !(s > 0.0)) continue;
        vec3 jit = vec3({u(3)}, {u(4)}, {u(5)});
        float shrink = 1.0 - 2.0 * s * {glsl_float(self._bound)} / {w};
        vec3 q = x - {w} * (vec3(cell) + 0.5 + {glsl_float(self.jitter)} * (jit - 0.5) * shrink);
        {rotate}
        best = min(best, {helper}(q, {args}));
    }}
    return best - ({offset});
}}"""
        return module.function(self, make)
