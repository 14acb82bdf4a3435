"""A turbulence warp of space for multi-phase particle clouds (paper 004, supplementary 10.1).

The particle SDF is evaluated at a transformed point ``p' = p + A T(p)``
(eqs. 14-15): A is an amplitude matrix (mm) and T(p) a turbulence vector made
from the original point as a sum of sine octaves.  Where the local frequency
and direction of the warp change, the particles it carries change shape and
anisotropy smoothly from one region to the next (the phasor-noise-like
"phases" of the cloud).  Here

    T_i(p) = sum_{o < O} g^o sin(l^o f (M p)_{s(i)} + phi_{o,i}),   i = 0, 1, 2,

with O octaves, gain g in (0, 1], lacunarity l in [1, 4], frequency f
(rad / mm), M a 3 x 3 mixing matrix (default the identity), s the cyclic
shift (y, z, x) -> s = (1, 2, 0), and phases phi drawn once per seed from a
seeded numpy Generator (`phase_table`; octave 0 keeps phase 0, so one octave
without a matrix is the single-octave warp ``p + a sin(f p.yzx)``).  A is a
scalar a (A = a I) or a full 3 x 3 matrix.  The numpy `Turbulence.warp` and
the GLSL function `Turbulence.glsl` defines read the same numbers (the
phases and per-octave frequencies are computed once, in float64, and written
into the shader as literals).

Lipschitz bound.  With q = M p, the partial derivatives are

    dT_i / dp_j = c_i M_{s(i), j},   c_i = f sum_o (g l)^o cos(l^o f q_{s(i)} + phi_{o,i}),

i.e. the Jacobian is ``J_T = D P M`` with P the permutation matrix of s
(P_{ik} = 1 iff k = s(i)) and D = diag(c_0, c_1, c_2), where
``|c_i| <= f S``, ``S = sum_{o < O} (g l)^o``.  Since a permutation is
orthogonal and a diagonal matrix's spectral norm is its largest entry,
``||J_T||_2 <= ||D||_2 ||P||_2 ||M||_2 <= f S ||M||_2``.  The warp
``w(p) = p + A T(p)`` has Jacobian ``I + A J_T``, so for any p, r (the
mean-value inequality along the segment between them)

    |w(p) - w(r)| <= (1 + ||A||_2 ||M||_2 f S) |p - r|,

and if an SDF f is L-Lipschitz in the warped frame, ``f o w`` is
``L (1 + ||A||_2 ||M||_2 f S)``-Lipschitz: `Turbulence.lipschitz` is that
factor.  (For one octave, scalar a and no matrix it is today's ``1 + a f``.)

No graph import: a plain value on arrays, used by `particles.Suspension`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .cell_hash import check_seed
from .values import GlslModule, as_points, glsl_float

__all__ = ["Turbulence", "phase_table", "MAX_OCTAVES"]

MAX_OCTAVES = 8
_SHIFT = [1, 2, 0]                  # component i of T reads (M p)_{s(i)}: the swizzle .yzx
_PHASE_STREAM = 0x7475726220       # a fixed word keeping the phase stream apart from other uses of a seed
_NAMES = {k: k for k in ("amplitude", "frequency", "octaves", "gain", "lacunarity", "matrix", "seed")}


def phase_table(seed: int) -> np.ndarray:
    """The phases phi_{o,i} (rad) of a seed: (MAX_OCTAVES, 3) float64, row 0 all zero, the
    others uniform in [0, 2 pi) from a seeded Generator.  An octave's phases do not depend
    on how many octaves are used.

    Raises
    ------
    ValueError
        If `seed` is not an integer.
    """
    rng = np.random.default_rng([_PHASE_STREAM, check_seed(seed) % (1 << 64)])
    table = np.zeros((MAX_OCTAVES, 3))
    table[1:] = rng.uniform(0.0, 2.0 * math.pi, (MAX_OCTAVES - 1, 3))
    return table


def _number(name, v, lo, hi, lo_open=False):
    try:
        x = float(v)
    except (TypeError, ValueError):
        x = math.nan
    if isinstance(v, bool) or not (math.isfinite(x) and (x > lo if lo_open else x >= lo) and x <= hi):
        raise ValueError(f"{name} must be a finite number in {'(' if lo_open else '['}{lo!r}, {hi!r}], "
                         f"got {v!r}")
    return x


def _matrix(name, v, what):
    try:
        m = np.asarray(v, dtype=np.float64)
    except (TypeError, ValueError):
        m = None
    if m is None or m.shape != (3, 3) or not np.all(np.isfinite(m)):
        raise ValueError(f"{name} must be {what}, got {v!r}")
    return tuple(tuple(float(x) for x in row) for row in m)


def _normalised(values: dict, names: dict) -> dict:
    """The turbulence parameters checked and in canonical form (floats, int, tuples of tuples).

    Raises
    ------
    ValueError
        Naming the parameter (as `names` spells it) and its allowed range.
    """
    out = dict(values)
    a = values["amplitude"]
    if np.ndim(a) == 0:
        out["amplitude"] = _number(names["amplitude"], a, 0.0, math.inf)
    else:
        out["amplitude"] = _matrix(names["amplitude"], a, "a number >= 0 (mm) or a 3 x 3 matrix of finite "
                                                          "numbers (mm)")
    out["frequency"] = _number(names["frequency"], values["frequency"], 0.0, math.inf)
    o = values["octaves"]
    if isinstance(o, bool) or not isinstance(o, (int, np.integer)) or not 1 <= o <= MAX_OCTAVES:
        raise ValueError(f"{names['octaves']} must be an int in [1, {MAX_OCTAVES}], got {o!r}")
    out["octaves"] = int(o)
    out["gain"] = _number(names["gain"], values["gain"], 0.0, 1.0, lo_open=True)
    out["lacunarity"] = _number(names["lacunarity"], values["lacunarity"], 1.0, 4.0)
    if values["matrix"] is not None:
        out["matrix"] = _matrix(names["matrix"], values["matrix"], "None or a 3 x 3 matrix of finite numbers")
    s = values["seed"]
    if isinstance(s, bool) or not isinstance(s, (int, np.integer)):
        raise ValueError(f"{names['seed']} must be an int, got {s!r}")
    out["seed"] = int(s)
    return out


@dataclass(frozen=True)
class Turbulence:
    """The warp ``p -> p + A T(p)`` of the module docstring.

    Parameters
    ----------
    amplitude : float, mm (>= 0), A = amplitude * I; or a 3 x 3 matrix A (mm, finite; nested
        sequences or an array, kept as a tuple of tuples).
    frequency : float, rad / mm (>= 0), f of octave 0.
    octaves : int in [1, MAX_OCTAVES], O.
    gain : float in (0, 1], the amplitude ratio g of consecutive octaves.
    lacunarity : float in [1, 4], the frequency ratio l of consecutive octaves.
    matrix : None (the identity) or a 3 x 3 matrix M (finite) mixing the coordinates
        before the octaves read them.
    seed : int, chooses the phases of octaves 1 and up (`phase_table`).

    Raises
    ------
    ValueError
        Naming the parameter and its allowed range (`named` lets a caller choose the names).
    """

    amplitude: float | tuple = 0.0
    frequency: float = 0.0
    octaves: int = 1
    gain: float = 0.5
    lacunarity: float = 2.0
    matrix: tuple | None = None
    seed: int = 0
    phases: tuple = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        values = {k: getattr(self, k) for k in _NAMES}
        for k, v in _normalised(values, _NAMES).items():
            object.__setattr__(self, k, v)
        object.__setattr__(self, "phases", tuple(map(tuple, phase_table(self.seed))))

    @classmethod
    def named(cls, names: dict, **params) -> "Turbulence":
        """A Turbulence whose refusals name its parameters as `names` says (e.g. {"octaves":
        "warp_octaves"}): for owners that expose the parameters under their own names."""
        values = {"amplitude": 0.0, "frequency": 0.0, "octaves": 1, "gain": 0.5, "lacunarity": 2.0,
                  "matrix": None, "seed": 0, **params}
        return cls(**_normalised(values, {**_NAMES, **names}))

    # -- derived numbers ----------------------------------------------------------------

    @property
    def amplitude_matrix(self) -> np.ndarray:
        """A: (3, 3) float64, mm."""
        a = self.amplitude
        return np.array(a) if isinstance(a, tuple) else a * np.eye(3)

    @property
    def is_identity(self) -> bool:
        """Whether the warp moves no point (A = 0)."""
        a = self.amplitude
        return not any(any(row) for row in a) if isinstance(a, tuple) else a == 0.0

    def _octaves(self):
        """(gain^o, l^o f, phases (3,)) of each octave o, float64."""
        return [(self.gain ** o, self.frequency * self.lacunarity ** o, self.phases[o])
                for o in range(self.octaves)]

    @property
    def lipschitz(self) -> float:
        """1 + ||A||_2 ||M||_2 f sum_o (g l)^o: a bound of the warp's Lipschitz constant (the
        module docstring's proof)."""
        a = self.amplitude
        norm_a = float(np.linalg.norm(np.array(a), 2)) if isinstance(a, tuple) else a
        norm_m = 1.0 if self.matrix is None else float(np.linalg.norm(np.array(self.matrix), 2))
        total = sum((self.gain * self.lacunarity) ** o for o in range(self.octaves))
        return 1.0 + norm_a * norm_m * self.frequency * total

    # -- evaluation ---------------------------------------------------------------------

    def turbulence(self, points) -> np.ndarray:
        """T at world points ((n, 3) mm): (n, 3) float64, dimensionless."""
        p = as_points(points)
        q = p if self.matrix is None else p @ np.array(self.matrix).T
        q = q[:, _SHIFT]
        t = np.sin(self.frequency * q)               # octave 0: gain 1, phase 0
        for g, f, phi in self._octaves()[1:]:
            t += g * np.sin(f * q + np.array(phi))
        return t

    def warp(self, points) -> np.ndarray:
        """p + A T(p) at world points ((n, 3) mm): (n, 3) float64 mm (the points themselves,
        as `as_points` gives them, when A = 0)."""
        p = as_points(points)
        if self.is_identity:
            return p
        t = self.turbulence(p)
        a = self.amplitude
        return p + (t @ np.array(a).T if isinstance(a, tuple) else a * t)

    def glsl(self, module: GlslModule) -> str:
        """Define ``vec3 NAME(vec3 p)`` returning the warped point (float32) in `module`; NAME."""
        def mat(m):                                  # GLSL's mat3 constructor takes columns
            return "mat3(" + ", ".join(glsl_float(m[i][j]) for j in range(3) for i in range(3)) + ")"

        q = "p.yzx" if self.matrix is None else f"({mat(self.matrix)} * p).yzx"
        terms = [f"    vec3 t = sin({glsl_float(self.frequency)} * q);"]
        for g, f, phi in self._octaves()[1:]:
            ph = ", ".join(glsl_float(v) for v in phi)
            terms.append(f"    t += {glsl_float(g)} * sin({glsl_float(f)} * q + vec3({ph}));")
        a = self.amplitude
        scale = mat(a) if isinstance(a, tuple) else glsl_float(a)
        body = "\n".join(terms)
        return module.function(self, lambda n: (
            f"vec3 {n}(vec3 p) {{\n    vec3 q = {q};\n{body}\n    return p + {scale} * t;\n}}"))
