"""Particle agglomerates (paper 004, section 3.2, eq. 8): a cubic lattice thinned by a cell rule.

Space is cut into cubic cells of width w (mm); cell c = (i, j, k) covers
``[c w, (c + 1) w]``.  Every cell may hold one particle: the unit shape of
`shapes.SHAPES` (parameters `proportions`) scaled by `size`, turned by one
fixed `rotation`, centred at

    w (c + 0.5 + J (2 u - 1)),   J = jitter (1 - r / w),

with r the particle's bounding radius (at most w) and u three uniforms of the
cell (`cell_hash.xorshift_key` of the index folded into the seed by
xorshift32 bit scrambling, section 3.2; then `cell_hash.cell_uniform`).
The cell keeps its particle iff ``rule.keep(c)`` (a
`congruence.CongruenceRule` or `CombinedRule`; None keeps every cell).
Since |J (2 u - 1)| <= 1 - r / w, each particle's bounding sphere lies in
the box ``E_c = [(c - 0.5) w, (c + 1.5) w]^3``, inside the 27 cells around
its own (r <= w is the paper's bound).

The field at a point x in cell c0 = floor(x / w) is

    f(x) = min( min over the kept particles of the 27 cells c0 + {-1, 0, 1}^3 of d_i(x),  b(x) ),

with b(x) the distance from x to the outside of the open box
``A = ((c0 - 0.5) w, (c0 + 1.5) w)^3`` (at least w / 2).

Why it is a lower bound of the distance D to the union of the particles.
A particle of a cell c outside the 27 (|c - c0|_inf >= 2, say c_x >= c0_x + 2)
lies in E_c, where X >= (c_x - 0.5) w >= (c0_x + 1.5) w: outside A, so at
least b(x) from x.  Each shape's d_i is a lower bound of the distance to
its particle (exact for the exact shapes of `SHAPES`), so
min(min_27 d_i, b) <= min(min_27 D_i, D_far) = D.  Where D <= w / 2 (and
inside particles) the nearest particle is one of the 27 and f = D for exact
shapes, because b >= w / 2.  The field stays finite where no cell is kept.

Why it is 1-Lipschitz.  In one cell f is a min of 1-Lipschitz functions.
On a face between c0 and c0 + e_x (x = (c0_x + 1) w) the two formulas agree:
b is w / 2 in x from both sides and the same in y, z; the particles that
leave or enter the 27 (layers c0_x - 1 and c0_x + 2) lie in E_c, at least
w / 2 from the face, and every shape of `SHAPES` satisfies
``d(q) >= |q| - r`` (exact outside for the exact shapes; the ellipsoid's
bound includes that term; the spindle torus is exact outside), so their d_i
are >= w / 2 there and do not change the min.  f is continuous and
piecewise 1-Lipschitz, hence 1-Lipschitz.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import cell_hash
from .congruence import CombinedRule, CongruenceRule
from .particles import MAX_BOX_CELLS, Particles
from .shapes import check_rotation, check_shape_params, mat3_literal, shape_glsl, shape_spec
from .values import SDF, as_points, glsl_float

__all__ = ["Agglomerate", "NEIGHBOURS", "guard_distance", "guard_glsl", "check_number"]

# the 27 offsets, x fastest
NEIGHBOURS = np.array([(dx, dy, dz) for dz in (-1, 0, 1) for dy in (-1, 0, 1) for dx in (-1, 0, 1)],
                      dtype=np.int64)


def guard_distance(x: np.ndarray, cell: float) -> tuple[np.ndarray, np.ndarray]:
    """(cells (n, 3) int64 = floor(x / cell), b (n,) mm): the distance from each point of `x`
    ((n, 3) mm) to the outside of the box ``((c - 0.5) w, (c + 1.5) w)^3`` of its cell c."""
    g = x / cell
    base = np.floor(g)
    t = g - base
    b = cell * np.min(np.minimum(t + 0.5, 1.5 - t), axis=1)
    return base.astype(np.int64), b


def guard_glsl(w: str) -> str:
    """GLSL statements of `guard_distance` for ``vec3 x`` and the cell width literal `w`: they
    declare ``float best`` (= b) and ``ivec3 ib`` (the cell)."""
    return f"""    vec3 g = x / {w};
    vec3 base = floor(g);
    vec3 t = g - base;
    vec3 e = min(t + 0.5, 1.5 - t);
    float best = {w} * min(min(e.x, e.y), e.z);
    ivec3 ib = ivec3(base);"""


def check_number(name: str, v, lo: float = -math.inf, hi: float = math.inf, lo_open: bool = False) -> float:
    """`v` as a float in [lo, hi] (or (lo, hi] with `lo_open`).

    Raises
    ------
    ValueError
        Naming `name` and the range, if `v` is not a finite number in it.
    """
    v = float(v)
    if not (math.isfinite(v) and (v > lo if lo_open else v >= lo) and v <= hi):
        raise ValueError(f"{name} must be a finite number in {'(' if lo_open else '['}{lo!r}, {hi!r}], "
                         f"got {v!r}")
    return v


@dataclass(frozen=True, eq=False)
class Agglomerate(SDF):
    """Particles of a cubic lattice, kept by a cell rule and joined by union (see the module docstring).

    Parameters
    ----------
    cell : float, mm (> 0), the cell width w.
    shape : str, a key of `shapes.SHAPES`; proportions : its parameters at size 1 (empty:
        the shape's default).
    size : float, mm (> 0), the scale of the unit shape; the bounding radius
        ``size * bound`` must be <= w (the 27-neighbourhood bound).
    rule : CongruenceRule, CombinedRule or None (every cell kept).
    jitter : float in [0, 1], the random displacement of the centres (0: a regular lattice).
    rotation : (3, 3) orthogonal matrix or None, the local -> world rotation of every particle.
    seed : int.

    Raises
    ------
    ValueError
        Naming the parameter and its allowed range (size with the largest size the cell allows).
    """

    cell: float = 1.0
    shape: str = "sphere"
    proportions: tuple = ()
    size: float = 0.5
    rule: CongruenceRule | CombinedRule | None = None
    jitter: float = 0.0
    rotation: np.ndarray | None = None
    seed: int = 0

    def __post_init__(self):
        w = check_number("cell width", self.cell, 0.0, lo_open=True)
        props = check_shape_params(self.shape, self.proportions)
        bound = float(shape_spec(self.shape).bound(*props))
        smax = w / bound
        size = float(self.size)
        if not (math.isfinite(size) and 0.0 < size <= smax):
            raise ValueError(f"size must be in (0, {smax!r}] mm for cell width {w!r} mm, so that the "
                             f"bounding radius stays <= w (the 27-neighbourhood bound), got {self.size!r}")
        if self.rule is not None and not isinstance(self.rule, (CongruenceRule, CombinedRule)):
            raise ValueError(f"rule must be a CongruenceRule, a CombinedRule or None, got "
                             f"{type(self.rule).__name__}")
        jitter = check_number("jitter", self.jitter, 0.0, 1.0)
        for k, v in (("cell", w), ("proportions", props), ("size", size), ("jitter", jitter),
                     ("rotation", check_rotation(self.rotation)), ("_word", cell_hash.seed_word(self.seed)),
                     ("_radius", size * bound), ("_params", tuple(size * p for p in props))):
            object.__setattr__(self, k, v)
        object.__setattr__(self, "_reach", jitter * (1.0 - self._radius / w))

    @property
    def bounding_radius(self) -> float:
        """Radius (mm) of the sphere about each centre that holds its particle (<= cell)."""
        return self._radius

    def _keep(self, cells: np.ndarray) -> np.ndarray:
        return np.ones(len(cells), dtype=bool) if self.rule is None else self.rule.keep(cells)

    def centres(self, cells) -> np.ndarray:
        """Particle centres (mm) of cells ((n, 3) int): (n, 3) float64 (kept or not)."""
        c = np.asarray(cells, dtype=np.int64).reshape(-1, 3)
        if self._reach == 0.0:
            return self.cell * (c + 0.5)
        st = cell_hash.xorshift_key(c[:, 0], c[:, 1], c[:, 2], self._word)
        u = np.stack([cell_hash.cell_uniform(st, r) for r in range(3)], axis=1)
        return self.cell * (c + 0.5 + self._reach * (2.0 * u - 1.0))

    def particles_in_box(self, lo, hi) -> Particles:
        """Every kept particle whose cell meets the box [lo, hi] (mm).

        Raises
        ------
        ValueError
            If lo > hi on an axis, or the box spans more than `particles.MAX_BOX_CELLS` cells.
        """
        lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
        if lo.shape != (3,) or hi.shape != (3,) or not np.all(lo <= hi):
            raise ValueError(f"box must be two (3,) corners with lo <= hi, got {lo!r}, {hi!r}")
        c0, c1 = np.floor(lo / self.cell).astype(np.int64), np.floor(hi / self.cell).astype(np.int64)
        count = int(np.prod(c1 - c0 + 1))
        if count > MAX_BOX_CELLS:
            raise ValueError(f"box spans {count} cells, at most {MAX_BOX_CELLS}")
        axes = [np.arange(a, b + 1) for a, b in zip(c0, c1)]
        cells = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
        cells = cells[self._keep(cells)]
        m = len(cells)
        rot = np.eye(3) if self.rotation is None else self.rotation
        return Particles(cells, self.centres(cells), np.full(m, self.size),
                         np.array(np.broadcast_to(rot, (m, 3, 3))), np.full(m, self._radius))

    def field(self, points):
        x = as_points(points)
        base, best = guard_distance(x, self.cell)
        fn = shape_spec(self.shape).fn
        for off in NEIGHBOURS:
            cells = base + off
            idx = np.flatnonzero(self._keep(cells))
            if idx.size == 0:
                continue
            q = x[idx] - self.centres(cells[idx])
            if self.rotation is not None:
                q = q @ self.rotation
            best[idx] = np.minimum(best[idx], fn(q, *self._params))
        return best

    def glsl(self, module):
        helper = shape_glsl(module, self.shape)
        w = glsl_float(self.cell)
        test = "true" if self.rule is None else f"{self.rule.glsl(module)}(cell)"
        if self._reach == 0.0:
            centre = f"{w} * (vec3(cell) + 0.5)"
        else:
            cell_hash.add_glsl(module)
            centre = (f"{w} * (vec3(cell) + 0.5 + {glsl_float(self._reach)} * (2.0 * vec3("
                      + ", ".join(f"mf_cell_uniform(st, {r}u)" for r in range(3)) + ") - 1.0))")
        stream = f"uint st = mf_xorshift_key(cell, {self._word}u);" if self._reach else ""
        rotate = "" if self.rotation is None else f"q = q * {mat3_literal(self.rotation)};"
        args = ", ".join(glsl_float(v) for v in self._params)

        def make(n):
            return f"""float {n}(vec3 p) {{
    vec3 x = p;
{guard_glsl(w)}
    for (int dz = -1; dz <= 1; ++dz) for (int dy = -1; dy <= 1; ++dy) for (int dx = -1; dx <= 1; ++dx) {{
        ivec3 cell = ib + ivec3(dx, dy, dz);
        if (!({test})) continue;
        {stream}
        vec3 q = x - {centre};
        {rotate}
        best = min(best, {helper}(q, {args}));
    }}
    return best;
}}"""
        return module.function(self, make)
