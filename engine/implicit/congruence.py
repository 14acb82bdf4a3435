"""Which lattice cells hold a particle: congruences of integer polynomials (paper 004, eq. 9).

A rule maps a cell index c = (i, j, k) (integers, any sign) to keep / drop.
It is a two-level reduction over literals of integer polynomials
``P_k(c) = sum_t a_t i^ex_t j^ey_t k^ez_t`` (a polynomial is a tuple of
``(a, (ex, ey, ez))`` monomials with integer coefficients):

* a congruence clause has a modulus m_k >= 1 and literals ``(r, s)``:
  ``P_k(c) mod m_k == r`` for s = +1 (class r included), ``!= r`` for
  s = -1 (class r excluded), with 0 <= r < m_k and the mathematical mod
  (a residue in [0, m_k) for negative values too);
* an inequality clause (modulus None) has literals ``(t, s)``:
  ``P_k(c) < t`` for s = +1, ``P_k(c) >= t`` for s = -1;
* the literals of one clause are reduced by its `inner` operator ("or" /
  "and"), the clauses by the `outer` one.

`CombinedRule` takes the union ("or") or intersection ("and") of rules (the
set operations the paper uses to extract subsets; e.g. a cubic frame is the
union of three fibre bundles).  Presets: `fibres`, `laminates`, `porous`,
`cubic_frame`, `bezier_gel`.  Rational functions (mentioned by the paper)
are not implemented.

Exact integer arithmetic, numpy and GLSL alike
----------------------------------------------
Congruence clauses never form P(c): the coordinates are reduced mod m first
and every product and sum is reduced again, so all intermediates lie in
[0, m^2) and m <= `MAX_MODULUS` = 46340 keeps m^2 < 2^31 (GLSL int32;
numpy uses int64).  The residue of a negative int32 a is computed as
``(m - 1) - ((-1 - a) % m)``, which only takes % of non-negative operands
(GLSL leaves % of negative operands undefined) and never overflows.  These
clauses are exact for every int32 cell index.

Inequality clauses need the value itself.  They are evaluated on the cell
clamped to ``[-(L - 1), L - 1]^3`` (L = `index_limit`, default 2^15, so a
rule is the same everywhere it is documented to be exact: |index| < L), and
the rule is refused unless ``sum_t |a_t| (L - 1)^deg_t <= 2^31 - 1``: then
every partial product (evaluated coefficient first) and partial sum of the
monomials stays within int32.  A quadratic inequality therefore needs a
smaller `index_limit` (the error message gives the largest one allowed).

Bounds: |coefficients| <= 2^31 - 1, total degree <= `MAX_DEGREE` = 8, at most
`MAX_TERMS` = 64 monomials per polynomial.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import reduce

import numpy as np

from .values import GlslModule

__all__ = ["CongruenceRule", "CombinedRule", "INDEX_LIMIT", "MAX_MODULUS", "MAX_DEGREE", "MAX_TERMS",
           "check_polynomial", "residues", "glsl_residue_source", "add_glsl",
           "fibres", "laminates", "porous", "cubic_frame", "bezier_gel", "bezier_form"]

INDEX_LIMIT = 2 ** 15
MAX_MODULUS = 46340                 # 46339^2 < 2^31 - 1: a product of two residues fits int32
MAX_DEGREE = 8
MAX_TERMS = 64
_INT32_MAX = 2 ** 31 - 1
_REDUCTIONS = {"or": ("||", np.logical_or), "and": ("&&", np.logical_and)}

_IMOD_GLSL = """int mf_imod(int a, int m) {
    return a >= 0 ? a % m : (m - 1) - ((-1 - a) % m);
}"""


def _is_int(v) -> bool:
    return isinstance(v, (int, np.integer)) and not isinstance(v, (bool, np.bool_))


def check_polynomial(poly, name: str = "polynomial") -> tuple:
    """`poly` as a tuple of ``(int coefficient, (ex, ey, ez))`` monomials (the zero polynomial if empty).

    Raises
    ------
    ValueError
        If a monomial is not (coefficient, (ex, ey, ez)) with an integer coefficient of
        magnitude <= 2^31 - 1 and integer exponents >= 0 of total degree <= `MAX_DEGREE`,
        or there are more than `MAX_TERMS` monomials.
    """
    try:
        terms = tuple(poly)
    except TypeError:
        raise ValueError(f"{name} must be a sequence of (coefficient, (ex, ey, ez)) monomials, "
                         f"got {poly!r}") from None
    if len(terms) > MAX_TERMS:
        raise ValueError(f"{name} has {len(terms)} monomials, at most {MAX_TERMS}")
    out = []
    for t, term in enumerate(terms):
        try:
            coef, exps = term
            exps = tuple(exps)
        except (TypeError, ValueError):
            raise ValueError(f"{name} monomial {t} must be (coefficient, (ex, ey, ez)), "
                             f"got {term!r}") from None
        if not _is_int(coef) or abs(int(coef)) > _INT32_MAX:
            raise ValueError(f"{name} monomial {t}: coefficient must be an int with |a| <= 2^31 - 1, "
                             f"got {coef!r}")
        if len(exps) != 3 or not all(_is_int(e) and e >= 0 for e in exps) or sum(exps) > MAX_DEGREE:
            raise ValueError(f"{name} monomial {t}: exponents must be 3 ints >= 0 of total degree "
                             f"<= {MAX_DEGREE}, got {exps!r}")
        out.append((int(coef), tuple(int(e) for e in exps)))
    return tuple(out)


def _check_cells(cells) -> np.ndarray:
    c = np.asarray(cells)
    if c.ndim != 2 or c.shape[1] != 3 or not (c.dtype.kind in "iu" or c.size == 0):
        raise ValueError(f"cells must be an (n, 3) integer array, got shape {c.shape}, dtype {c.dtype}")
    return c.astype(np.int64)


def residues(poly, modulus: int, cells) -> np.ndarray:
    """P(c) mod `modulus` of a checked polynomial at cells ((n, 3) int): (n,) int64 in [0, modulus).

    Exact for any int64 cells (every step is reduced; see the module docstring)."""
    c = _check_cells(cells)
    m = int(modulus)
    r = np.mod(c, m)
    v = np.zeros(len(c), dtype=np.int64)
    for coef, exps in poly:
        t = np.full(len(c), coef % m, dtype=np.int64)
        for axis, e in enumerate(exps):
            for _ in range(e):
                t = (t * r[:, axis]) % m
        v = (v + t) % m
    return v


def _values(poly, cells: np.ndarray, limit: int) -> np.ndarray:
    """P at cells clamped to [-(limit - 1), limit - 1]: int64 (bounded by the rule's check)."""
    q = np.clip(cells, -(limit - 1), limit - 1)
    v = np.zeros(len(q), dtype=np.int64)
    for coef, exps in poly:
        t = np.full(len(q), coef, dtype=np.int64)
        for axis, e in enumerate(exps):
            for _ in range(e):
                t = t * q[:, axis]
        v = v + t
    return v


def _glsl_int(v: int) -> str:
    return f"({v})" if v < 0 else str(v)


def glsl_residue_source(name: str, poly, modulus: int) -> str:
    """GLSL ``int name(ivec3 c)`` returning P(c) mod `modulus` exactly (needs `add_glsl`'s mf_imod)."""
    m = int(modulus)
    lines = [f"int {name}(ivec3 c) {{",
             f"    ivec3 r = ivec3(mf_imod(c.x, {m}), mf_imod(c.y, {m}), mf_imod(c.z, {m}));",
             "    int v = 0;", "    int t;"]
    for coef, exps in poly:
        if coef % m == 0:
            continue
        lines.append(f"    t = {coef % m};")
        for axis, e in enumerate(exps):
            lines += [f"    t = (t * r.{'xyz'[axis]}) % {m};"] * e
        lines.append(f"    v = (v + t) % {m};")
    lines += ["    return v;", "}"]
    return "\n".join(lines)


def _glsl_value_source(name: str, poly, limit: int) -> str:
    lines = [f"int {name}(ivec3 c) {{",
             f"    ivec3 q = clamp(c, ivec3({-(limit - 1)}), ivec3({limit - 1}));", "    int v = 0;"]
    for coef, exps in poly:
        factors = [_glsl_int(coef)] + [f"q.{'xyz'[a]}" for a, e in enumerate(exps) for _ in range(e)]
        lines.append(f"    v += {' * '.join(factors)};")
    lines += ["    return v;", "}"]
    return "\n".join(lines)


def add_glsl(module: GlslModule) -> None:
    """Add the GLSL helper ``int mf_imod(int a, int m)`` (the mathematical mod, m > 0) once."""
    module.helper("mf_imod", _IMOD_GLSL)


def _check_reduction(name: str, v) -> str:
    if v not in _REDUCTIONS:
        raise ValueError(f"{name} must be 'or' or 'and', got {v!r}")
    return v


@dataclass(frozen=True)
class CongruenceRule:
    """Keep a cell iff the reduction of eq. 9 holds (see the module docstring).

    Parameters
    ----------
    polynomials : tuple of polynomials (each a tuple of (int a, (ex, ey, ez))).
    moduli : tuple, per polynomial an int in [1, `MAX_MODULUS`] (congruence clause) or
        None (inequality clause).
    classes : tuple, per polynomial a non-empty tuple of (value, sign) literals with sign
        +1 / -1: a residue in [0, m) for a congruence, a threshold int (|t| <= 2^31 - 1)
        for an inequality.
    inner : "or" / "and", or a tuple of them (one per polynomial).
    outer : "or" / "and".
    index_limit : int in [2, 2^24]; inequality clauses see the cell clamped to
        |index| <= index_limit - 1 and must not overflow int32 there.

    Raises
    ------
    ValueError
        Naming the polynomial index and the offending parameter (modulus, classes,
        coefficients, the overflow bound with the largest index_limit allowed).
    """

    polynomials: tuple
    moduli: tuple
    classes: tuple
    inner: object = "or"
    outer: str = "or"
    index_limit: int = INDEX_LIMIT

    def __post_init__(self):
        polys = tuple(self.polynomials) if isinstance(self.polynomials, (tuple, list)) else None
        if not polys:
            raise ValueError(f"polynomials must be a non-empty tuple of polynomials, "
                             f"got {self.polynomials!r}")
        n = len(polys)
        moduli, classes = tuple(self.moduli), tuple(self.classes)
        inner = (self.inner,) * n if isinstance(self.inner, str) else tuple(self.inner)
        for label, seq in (("moduli", moduli), ("classes", classes), ("inner", inner)):
            if len(seq) != n:
                raise ValueError(f"{label} must have one entry per polynomial ({n}), got {len(seq)}")
        lim = self.index_limit
        if not (_is_int(lim) and 2 <= lim <= 2 ** 24):
            raise ValueError(f"index_limit must be an int in [2, 2^24], got {lim!r}")
        polys = tuple(check_polynomial(p, f"polynomial {k}") for k, p in enumerate(polys))
        moduli = tuple(self._check_modulus(k, m) for k, m in enumerate(moduli))
        classes = tuple(self._check_classes(k, c, m) for k, (c, m) in enumerate(zip(classes, moduli)))
        inner = tuple(_check_reduction(f"inner reduction of polynomial {k}", v) for k, v in enumerate(inner))
        _check_reduction("outer reduction", self.outer)
        for k, (p, m) in enumerate(zip(polys, moduli)):
            if m is None:
                self._check_overflow(k, p, int(lim))
        for name, v in (("polynomials", polys), ("moduli", moduli), ("classes", classes),
                        ("inner", inner), ("index_limit", int(lim))):
            object.__setattr__(self, name, v)

    @staticmethod
    def _check_modulus(k, m):
        if m is None:
            return None
        if not (_is_int(m) and 1 <= m <= MAX_MODULUS):
            raise ValueError(f"polynomial {k}: modulus must be an int in [1, {MAX_MODULUS}] "
                             f"(or None for an inequality), got {m!r}")
        return int(m)

    @staticmethod
    def _check_classes(k, lits, m):
        try:
            lits = tuple((v, s) for v, s in lits)
        except (TypeError, ValueError):
            raise ValueError(f"polynomial {k}: classes must be (value, sign) pairs, got {lits!r}") from None
        if not lits:
            raise ValueError(f"polynomial {k}: classes must hold at least one (value, sign) pair")
        for v, s in lits:
            if not (_is_int(s) and s in (1, -1)):
                raise ValueError(f"polynomial {k}: class sign must be +1 or -1, got {s!r}")
            if m is not None and not (_is_int(v) and 0 <= v < m):
                raise ValueError(f"polynomial {k}: congruence class must be an int in [0, {m}) "
                                 f"(the modulus), got {v!r}")
            if m is None and not (_is_int(v) and abs(v) <= _INT32_MAX):
                raise ValueError(f"polynomial {k}: threshold must be an int with |t| <= 2^31 - 1, got {v!r}")
        return tuple((int(v), int(s)) for v, s in lits)

    @staticmethod
    def _check_overflow(k, poly, lim):
        def bound(limit):
            return sum(abs(a) * (limit - 1) ** sum(e) for a, e in poly)
        if bound(lim) <= _INT32_MAX:
            return
        lo, hi = 1, lim                                   # bound(lo) fits (or lo = 1), bound(hi) does not
        while hi - lo > 1:
            mid = (lo + hi) // 2
            lo, hi = (mid, hi) if bound(mid) <= _INT32_MAX else (lo, mid)
        allowed = f"at most index_limit {lo}" if lo >= 2 and bound(lo) <= _INT32_MAX else \
            "no index_limit >= 2 fits"
        raise ValueError(f"polynomial {k} (inequality): sum |a| (index_limit - 1)^degree = "
                         f"{bound(lim)} exceeds 2^31 - 1 for index_limit {lim}; {allowed} "
                         f"with these coefficients")

    def _literals(self, k: int, cells: np.ndarray) -> np.ndarray:
        m = self.moduli[k]
        if m is None:
            v = _values(self.polynomials[k], cells, self.index_limit)
            lits = [(v < t) if s > 0 else (v >= t) for t, s in self.classes[k]]
        else:
            v = residues(self.polynomials[k], m, cells)
            lits = [(v == r) if s > 0 else (v != r) for r, s in self.classes[k]]
        return reduce(_REDUCTIONS[self.inner[k]][1], lits)

    def keep(self, cells) -> np.ndarray:
        """Whether each cell holds a particle: (n, 3) int cells -> (n,) bool.

        Raises
        ------
        ValueError
            If `cells` is not an (n, 3) integer array.
        """
        c = _check_cells(cells)
        clauses = [self._literals(k, c) for k in range(len(self.polynomials))]
        return np.asarray(reduce(_REDUCTIONS[self.outer][1], clauses), dtype=bool)

    def glsl(self, module: GlslModule) -> str:
        """Define ``bool NAME(ivec3 c)`` (the same test in int32) in `module`; return NAME."""
        add_glsl(module)

        def make(n):
            parts, clauses = [], []
            for k, (poly, m) in enumerate(zip(self.polynomials, self.moduli)):
                fn = f"{n}_p{k}"
                if m is None:
                    parts.append(_glsl_value_source(fn, poly, self.index_limit))
                    lits = [f"(v{k} {'<' if s > 0 else '>='} {_glsl_int(t)})" for t, s in self.classes[k]]
                else:
                    parts.append(glsl_residue_source(fn, poly, m))
                    lits = [f"(v{k} {'==' if s > 0 else '!='} {r})" for r, s in self.classes[k]]
                clauses.append((f"int v{k} = {fn}(c);", f" {_REDUCTIONS[self.inner[k]][0]} ".join(lits)))
            body = "\n    ".join(decl for decl, _ in clauses)
            expr = f" {_REDUCTIONS[self.outer][0]} ".join(f"({e})" for _, e in clauses)
            parts.append(f"bool {n}(ivec3 c) {{\n    {body}\n    return {expr};\n}}")
            return "\n\n".join(parts)
        return module.function(self, make)


@dataclass(frozen=True)
class CombinedRule:
    """The union ("or") or intersection ("and") of the cell sets of `rules`.

    Raises
    ------
    ValueError
        If `rules` is empty or holds something other than rules, or `outer` is not "or" / "and".
    """

    rules: tuple
    outer: str = "or"

    def __post_init__(self):
        rules = tuple(self.rules) if isinstance(self.rules, (tuple, list)) else ()
        if not rules:
            raise ValueError(f"rules must be a non-empty tuple of rules, got {self.rules!r}")
        for i, r in enumerate(rules):
            if not isinstance(r, (CongruenceRule, CombinedRule)):
                raise ValueError(f"rule {i} is a {type(r).__name__}, not a CongruenceRule or CombinedRule")
        _check_reduction("outer reduction", self.outer)
        object.__setattr__(self, "rules", rules)

    def keep(self, cells) -> np.ndarray:
        """Whether each cell holds a particle: (n, 3) int cells -> (n,) bool."""
        c = _check_cells(cells)
        return np.asarray(reduce(_REDUCTIONS[self.outer][1], [r.keep(c) for r in self.rules]), dtype=bool)

    def glsl(self, module: GlslModule) -> str:
        """Define ``bool NAME(ivec3 c)`` in `module`; return NAME."""
        names = [r.glsl(module) for r in self.rules]
        op = f" {_REDUCTIONS[self.outer][0]} "
        return module.function(self, lambda n: (
            f"bool {n}(ivec3 c) {{ return {op.join(f'{m}(c)' for m in names)}; }}"))


# -- presets ------------------------------------------------------------------------------

def _coordinate(axis: int) -> tuple:
    return ((1, tuple(int(a == axis) for a in range(3))),)


def _check_preset(period, width, axis=0):
    if not (_is_int(period) and 1 <= period <= MAX_MODULUS):
        raise ValueError(f"period must be an int in [1, {MAX_MODULUS}] cells, got {period!r}")
    if not (_is_int(width) and 1 <= width <= period):
        raise ValueError(f"width must be an int in [1, {period}] (the period), got {width!r}")
    if axis not in (0, 1, 2):
        raise ValueError(f"axis must be 0, 1 or 2, got {axis!r}")


def _band(period, width):
    return tuple((r, 1) for r in range(width))


def fibres(period: int, axis: int = 2, width: int = 1) -> CongruenceRule:
    """Straight fibres along `axis`: cells whose two other coordinates both have residues in
    [0, width) mod `period` (square fibres of width x width cells, `period` cells apart)."""
    _check_preset(period, width, axis)
    others = [a for a in range(3) if a != axis]
    return CongruenceRule(tuple(_coordinate(a) for a in others), (period, period),
                          (_band(period, width),) * 2, inner="or", outer="and")


def laminates(period: int, axis: int = 2, width: int = 1) -> CongruenceRule:
    """Layers normal to `axis`: cells whose `axis` coordinate has a residue in [0, width) mod `period`."""
    _check_preset(period, width, axis)
    return CongruenceRule((_coordinate(axis),), (period,), (_band(period, width),))


def porous(period: int, pore: int = 1) -> CongruenceRule:
    """A solid block with closed cubic pores: every cell except those whose three coordinates all
    have residues in [0, pore) mod `period` (pore < period)."""
    _check_preset(period, pore)
    if pore >= period:
        raise ValueError(f"pore must be < period = {period} (else nothing is kept), got {pore!r}")
    excl = tuple((r, -1) for r in range(pore))
    return CongruenceRule(tuple(_coordinate(a) for a in range(3)), (period,) * 3, (excl,) * 3,
                          inner="and", outer="or")


def cubic_frame(period: int, width: int = 1) -> CombinedRule:
    """An open-cell cubic lattice: cells with at least two coordinates having residues in
    [0, width) mod `period` (the union of the fibres along x, y and z)."""
    return CombinedRule(tuple(fibres(period, axis, width) for axis in range(3)), "or")


def bezier_form(a: int, b: int, c: int, u: tuple, v: tuple) -> tuple:
    """The quadratic form ``a u^2 + 2 b u v + c v^2`` of two cell coordinates (axes u, v given as
    exponent triples), as a polynomial: the Bezier-like form, see `bezier_gel`."""
    def mono(e1, e2):
        return tuple(x + y for x, y in zip(e1, e2))
    return ((a, mono(u, u)), (2 * b, mono(u, v)), (c, mono(v, v)))


def bezier_gel(period: int = 31, a: int = 1, b: int = 3, c: int = 2, d: int = 1,
               width: int = 2) -> CongruenceRule:
    """A gel-like network (paper 004, supplementary 10.3; its equations were lost, this is the
    construction the prose describes, in our own form).

    The quadratic Bezier polynomial with integer control values (a, b, c),
    ``B(t) = a (1 - t)^2 + 2 b t (1 - t) + c t^2`` for t in [0, 1], is made
    integer-valued on the lattice by homogenising it over two cell coordinates
    u, v (t = v / (u + v)): ``(u + v)^2 B = Q(u, v) = a u^2 + 2 b u v + c v^2``.
    Three polynomials cycle the axes, each lifted by the third coordinate
    with the integer constant d::

        P_1 = Q(i, j) + d k,   P_2 = Q(j, k) + d i,   P_3 = Q(k, i) + d j,

    and a cell is kept iff some P_l mod `period` lies in [0, width) (inner and
    outer OR).  Each P_l selects, for every (u, v), about `width` residues of
    the third coordinate: a quadratic sheet folded modulo the period, which is
    continuous where the gradient of Q is small mod the period and breaks up
    into strands and clusters elsewhere.  With the defaults about 18 % of
    the cells are kept; counted with edge neighbours (particles of radius
    > w / sqrt(2) touch them) some 85 % of those form one spanning network
    and the rest hundreds of small clusters, a gel-like structure.

    Raises
    ------
    ValueError
        If a constant is not an int (|.| <= 2^15), period not in [1, MAX_MODULUS] or width
        not in [1, period].
    """
    _check_preset(period, width)
    for name, val in (("a", a), ("b", b), ("c", c), ("d", d)):
        if not (_is_int(val) and abs(val) <= 2 ** 15):
            raise ValueError(f"bezier_gel constant {name} must be an int with |{name}| <= 2^15, got {val!r}")
    e = [tuple(int(x == axis) for x in range(3)) for axis in range(3)]
    polys = tuple(bezier_form(a, b, c, e[u], e[(u + 1) % 3]) + ((d, e[(u + 2) % 3]),) for u in range(3))
    return CongruenceRule(polys, (period,) * 3, (_band(period, width),) * 3, inner="or", outer="or")
