"""Cell rules of integer polynomials: numpy against plain Python integers, the GLSL, the presets' shapes."""

import numpy as np
import pytest
from scipy import ndimage

from engine.implicit import congruence as cg
from engine.implicit.congruence import CombinedRule, CongruenceRule
from engine.implicit.values import SDF, as_points


def ref_value(poly, cell):
    return sum(a * cell[0] ** e[0] * cell[1] ** e[1] * cell[2] ** e[2] for a, e in poly)


def ref_keep(rule, cell):
    """The rule on one cell, with Python's unbounded ints and its mathematical %."""
    clauses = []
    lim = rule.index_limit - 1
    for poly, m, lits, inner in zip(rule.polynomials, rule.moduli, rule.classes, rule.inner):
        if m is None:
            v = ref_value(poly, [min(max(c, -lim), lim) for c in cell])
            vals = [(v < t) == (s > 0) for t, s in lits]
        else:
            v = ref_value(poly, cell) % m
            vals = [(v == r) == (s > 0) for r, s in lits]
        clauses.append(any(vals) if inner == "or" else all(vals))
    return any(clauses) if rule.outer == "or" else all(clauses)


def random_rule(rng, inequality_share=0.3):
    n = int(rng.integers(1, 4))
    polys, moduli, classes, inner = [], [], [], []
    for _ in range(n):
        ineq = rng.random() < inequality_share
        terms = []
        for _ in range(int(rng.integers(0, 5))):
            e = rng.multinomial(int(rng.integers(0, 3 if ineq else 5)), [1 / 3] * 3)
            terms.append((int(rng.integers(-40, 41)) if ineq else int(rng.integers(-10 ** 9, 10 ** 9)),
                          tuple(int(v) for v in e)))
        polys.append(tuple(terms))
        if ineq:
            moduli.append(None)
            classes.append(tuple((int(rng.integers(-10 ** 6, 10 ** 6)), int(rng.choice([-1, 1])))
                                 for _ in range(int(rng.integers(1, 3)))))
        else:
            m = int(rng.choice([1, 2, 3, 7, 12, 101, cg.MAX_MODULUS]))
            classes.append(tuple((int(rng.integers(0, m)), int(rng.choice([-1, 1])))
                                 for _ in range(int(rng.integers(1, 4)))))
            moduli.append(m)
        inner.append(str(rng.choice(["or", "and"])))
    return CongruenceRule(tuple(polys), tuple(moduli), tuple(classes), tuple(inner),
                          str(rng.choice(["or", "and"])), index_limit=1000)


def _cells(rng, n, span):
    return np.concatenate([rng.integers(-span, span, (n, 3)), rng.integers(-3, 4, (n // 4, 3)),
                           np.array([[0, 0, 0], [-1, -1, -1], [span, -span, 999], [-999, 1000, -1001]])])


def test_numpy_matches_python_integers_on_random_rules():
    rng = np.random.default_rng(0)
    seen = set()
    for trial in range(60):
        rule = random_rule(rng)
        cells = _cells(rng, 200, 5000 if trial % 2 else 2 ** 30)
        got = rule.keep(cells)
        ref = np.array([ref_keep(rule, c) for c in cells.tolist()])
        np.testing.assert_array_equal(got, ref, err_msg=repr(rule))
        seen.add(bool(got.any()) + 2 * bool((~got).any()))
    assert seen == {1, 2, 3}                      # rules keeping nothing, everything and a mix


def test_mathematical_mod_of_negative_cells():
    rule = CongruenceRule((((1, (1, 0, 0)),),), (5,), (((4, 1),),))
    cells = np.array([[-1, 0, 0], [-6, 0, 0], [4, 0, 0], [-5, 0, 0], [-2 ** 31, 0, 0]])
    np.testing.assert_array_equal(rule.keep(cells), [True, True, True, False, (-2 ** 31) % 5 == 4])
    np.testing.assert_array_equal(cg.residues(((1, (1, 0, 0)),), 7, cells), [c % 7 for c in cells[:, 0]])


class _Probe(SDF):
    """1 where the rule keeps the cell floor(p), else 0 (to run a rule's GLSL through evaluate_glsl)."""

    def __init__(self, rule):
        object.__setattr__(self, "rule", rule)

    def field(self, points):
        return self.rule.keep(np.floor(as_points(points)).astype(np.int64)).astype(np.float64)

    def glsl(self, module):
        name = self.rule.glsl(module)
        return module.function(self, lambda n: (
            f"float {n}(vec3 p) {{ return {name}(ivec3(floor(p))) ? 1.0 : 0.0; }}"))


def _glsl_rules():
    rng = np.random.default_rng(7)
    rules = [random_rule(rng) for _ in range(12)]
    big = 2 ** 31 - 1
    rules += [
        # largest modulus, largest coefficients, high degree: every int32 step must stay in range
        CongruenceRule((((big, (3, 2, 3)), (-big, (0, 4, 0)), (46339, (1, 1, 1))),), (cg.MAX_MODULUS,),
                       (((0, -1), (17, -1), (46339, -1)),), inner="and"),
        # an inequality right at its overflow bound: 2 (L - 1)^2 + (L - 1) <= 2^31 - 1
        CongruenceRule((((2, (2, 0, 0)), (1, (0, 1, 0)), (-1, (1, 0, 1))),), (None,), (((7, 1), (-5, -1)),),
                       index_limit=26755),
        cg.fibres(5, axis=0, width=2), cg.laminates(3, axis=1), cg.porous(4, pore=2), cg.cubic_frame(6),
        cg.bezier_gel(), cg.bezier_gel(period=23, a=-3, b=5, c=7, d=2, width=3),
        CombinedRule((cg.laminates(4), cg.fibres(3, axis=1)), "and"),
    ]
    return rules


@pytest.mark.parametrize("i", range(len(_glsl_rules())))
def test_glsl_matches_numpy(gpu, i):
    from engine.gpu.sdf_points import evaluate_glsl
    rule = _glsl_rules()[i]
    rng = np.random.default_rng(i)
    cells = np.concatenate([rng.integers(-60, 60, (3000, 3)), rng.integers(-2 ** 22, 2 ** 22, (3000, 3)),
                            rng.integers(-30000, 30000, (2000, 3))])
    pts = cells + 0.5                              # exact in float32
    got = evaluate_glsl(_Probe(rule), pts)
    np.testing.assert_array_equal(got, rule.keep(cells).astype(np.float64))


class _ResidueProbe(SDF):
    """P(floor(p)) mod m as a float (exact below 2^24), from `glsl_residue_source`."""

    def __init__(self, poly, m):
        object.__setattr__(self, "poly", poly)
        object.__setattr__(self, "m", m)

    def field(self, points):
        return cg.residues(self.poly, self.m, np.floor(as_points(points)).astype(np.int64)).astype(float)

    def glsl(self, module):
        cg.add_glsl(module)
        res = module.function(self, lambda n: cg.glsl_residue_source(n, self.poly, self.m), tag="_res")
        return module.function(self, lambda n: (
            f"float {n}(vec3 p) {{ return float({res}(ivec3(floor(p)))); }}"))


def test_glsl_residues_are_exact_at_the_limits(gpu):
    from engine.gpu.sdf_points import evaluate_glsl
    big = 2 ** 31 - 1
    rng = np.random.default_rng(11)
    cells = np.concatenate([rng.integers(-2 ** 23, 2 ** 23, (4000, 3)), rng.integers(-9, 9, (1000, 3))])
    wide = ((big, (3, 2, 3)), (-big, (0, 4, 0)), (46339, (1, 1, 1)), (-7, (0, 0, 0)))
    for poly, m in [(wide, cg.MAX_MODULUS),
                    (((1, (8, 0, 0)), (-3, (0, 0, 1))), 46327), (((5, (1, 0, 0)),), 1)]:
        ref = np.array([ref_value(poly, c) % m for c in cells.tolist()], dtype=float)
        np.testing.assert_array_equal(cg.residues(poly, m, cells), ref)
        np.testing.assert_array_equal(evaluate_glsl(_ResidueProbe(poly, m), cells + 0.5), ref)


def _block(rule, n=24):
    g = np.stack(np.meshgrid(*[np.arange(n)] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    return rule.keep(g).reshape(n, n, n)


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_fibres_are_straight_lines(axis):
    n, period, width = 24, 6, 2
    kept = _block(cg.fibres(period, axis=axis, width=width), n)
    labels, count = ndimage.label(kept)
    assert count == (n // period) ** 2                      # one component per fibre
    for lab in range(1, count + 1):
        cells = np.argwhere(labels == lab)
        others = [a for a in range(3) if a != axis]
        # a fibre: width x width cross-section, runs through the whole block along the axis
        assert len(cells) == width * width * n
        assert len(np.unique(cells[:, others], axis=0)) == width * width
        assert np.all(cells[:, others] % period < width)
    section = np.moveaxis(kept, axis, 0)[5]
    idx = np.arange(n) % period < width
    np.testing.assert_array_equal(section, idx[:, None] & idx[None, :])


def test_laminates_are_planes():
    kept = _block(cg.laminates(4, axis=1, width=1))
    labels, count = ndimage.label(kept)
    assert count == 6
    for lab in range(1, count + 1):
        y = np.argwhere(labels == lab)[:, 1]
        assert np.all(y == y[0]) and y[0] % 4 == 0 and len(y) == 24 * 24


def test_cubic_frame_and_porous_block():
    frame = _block(cg.cubic_frame(4))
    r = np.indices(frame.shape) % 4 == 0
    np.testing.assert_array_equal(frame, r.sum(axis=0) >= 2)
    assert ndimage.label(frame)[1] == 1                     # one connected frame
    assert ndimage.label(~frame)[1] == 1                    # an open-cell lattice: one pore space
    block = _block(cg.porous(4, pore=2))
    labels, count = ndimage.label(~block)
    assert count == 6 ** 3 and ndimage.label(block)[1] == 1
    sizes = np.bincount(labels.ravel())[1:]
    assert np.all(sizes == 8)                               # closed 2 x 2 x 2 pores


def test_bezier_gel_is_the_documented_construction():
    a, b, c, d, m, width = 2, 5, -3, 3, 13, 2
    rule = cg.bezier_gel(period=m, a=a, b=b, c=c, d=d, width=width)
    cells = np.random.default_rng(3).integers(-500, 500, (4000, 3))

    def q(u, v):
        return a * u * u + 2 * b * u * v + c * v * v
    ref = [any((q(x[u], x[(u + 1) % 3]) + d * x[(u + 2) % 3]) % m < width for u in range(3))
           for x in cells.tolist()]
    kept = rule.keep(cells)
    np.testing.assert_array_equal(kept, ref)
    # each polynomial is linear in its lift coordinate with a unit d: a fraction width / m per clause
    assert abs(kept.mean() - (1 - (1 - width / m) ** 3)) < 0.03
    # the default: a sparse network (edge neighbours) beside many small clusters
    block = _block(cg.bezier_gel(), 30)
    labels, count = ndimage.label(block, structure=ndimage.generate_binary_structure(3, 2))
    sizes = np.bincount(labels.ravel())[1:]
    assert 0.1 < block.mean() < 0.3 and count > 50 and sizes.max() > 0.75 * block.sum()
    spanning = labels == np.argmax(np.bincount(labels.ravel())[1:]) + 1
    assert all(np.any(spanning.take(0, axis=a)) and np.any(spanning.take(-1, axis=a)) for a in range(3))


@pytest.mark.parametrize("kw, match", [
    (dict(moduli=(3, 0)), "polynomial 1: modulus must be an int in"),
    (dict(moduli=(-2, 3)), "polynomial 0: modulus"),
    (dict(moduli=(3, 46341)), "polynomial 1: modulus"),
    (dict(moduli=(3.0, 3)), "polynomial 0: modulus"),
    (dict(classes=(((3, 1),), ((0, 1),))), r"polynomial 0: congruence class must be an int in \[0, 3\)"),
    (dict(classes=(((0, 0),), ((0, 1),))), "sign must be"),
    (dict(classes=((), ((0, 1),))), "at least one"),
    (dict(classes=(((0, 1),),)), "one entry per polynomial"),
    (dict(inner="xor"), "inner reduction of polynomial 0"),
    (dict(outer="nand"), "outer reduction"),
    (dict(polynomials=(((1.5, (1, 0, 0)),), ((1, (0, 1, 0)),))), "polynomial 0 monomial 0: coefficient"),
    (dict(polynomials=(((1, (1, -1, 0)),), ((1, (0, 1, 0)),))), "exponents"),
    (dict(polynomials=(((1, (5, 4, 0)),), ((1, (0, 1, 0)),))), "total degree"),
    (dict(polynomials=(((2 ** 31, (1, 0, 0)),), ((1, (0, 1, 0)),))), "coefficient"),
    (dict(polynomials=()), "non-empty"),
    (dict(index_limit=1), "index_limit"),
    (dict(moduli=(None, 3), classes=(((2 ** 31, 1),), ((0, 1),))), "threshold"),
    (dict(moduli=(None, 3), polynomials=(((3, (2, 0, 0)),), ((1, (0, 1, 0)),))),
     r"polynomial 0 \(inequality\).*at most index_limit 26755"),
])
def test_bad_rules_refused(kw, match):
    args = dict(polynomials=(((1, (1, 0, 0)),), ((1, (0, 1, 0)),)), moduli=(3, 3),
                classes=(((0, 1),), ((0, 1),)))
    args.update(kw)
    with pytest.raises(ValueError, match=match):
        CongruenceRule(**args)


def test_bad_presets_and_cells_refused():
    with pytest.raises(ValueError, match="period"):
        cg.fibres(0)
    with pytest.raises(ValueError, match="width"):
        cg.laminates(3, width=4)
    with pytest.raises(ValueError, match="axis"):
        cg.fibres(3, axis=3)
    with pytest.raises(ValueError, match="pore must be < period"):
        cg.porous(3, pore=3)
    with pytest.raises(ValueError, match="constant b"):
        cg.bezier_gel(b=0.5)
    with pytest.raises(ValueError, match="rule 1"):
        CombinedRule((cg.laminates(3), "x"))
    with pytest.raises(ValueError, match="integer array"):
        cg.laminates(3).keep(np.zeros((4, 3)))
    with pytest.raises(ValueError, match=r"\(n, 3\)"):
        cg.laminates(3).keep(np.zeros((4, 2), dtype=int))
