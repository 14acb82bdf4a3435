"""Periodic and TrigSum: formulas against hand-written evaluations, symmetries, GLSL == numpy,
Lipschitz bounds measured by finite differences, bad input refused."""

import math

import numpy as np
import pytest

from engine.gpu.sdf_points import evaluate_glsl
from engine.implicit.periodic import KINDS, Periodic, TrigSum, TrigTerm

s, c = math.sin, math.cos


def hand(kind, X, Y, Z):
    """The nodal approximations, written out once more for the test."""
    if kind == "gyroid":
        return s(X) * c(Y) + s(Y) * c(Z) + s(Z) * c(X)
    if kind == "schwarz_p":
        return c(X) + c(Y) + c(Z)
    if kind == "schwarz_d":
        return (s(X) * s(Y) * s(Z) + s(X) * c(Y) * c(Z) + c(X) * s(Y) * c(Z)
                + c(X) * c(Y) * s(Z))
    if kind == "neovius":
        return 3 * (c(X) + c(Y) + c(Z)) + 4 * c(X) * c(Y) * c(Z)
    if kind == "iwp":
        return 2 * (c(X) * c(Y) + c(Y) * c(Z) + c(Z) * c(X)) - (c(2 * X) + c(2 * Y) + c(2 * Z))
    if kind == "fischer_koch_s":
        return c(2 * X) * s(Y) * c(Z) + c(X) * c(2 * Y) * s(Z) + s(X) * c(Y) * c(2 * Z)
    if kind == "lidinoid":
        return (0.5 * (s(2 * X) * c(Y) * s(Z) + s(2 * Y) * c(Z) * s(X) + s(2 * Z) * c(X) * s(Y))
                - 0.5 * (c(2 * X) * c(2 * Y) + c(2 * Y) * c(2 * Z) + c(2 * Z) * c(2 * X)) + 0.15)
    if kind == "frd":
        return 4 * c(X) * c(Y) * c(Z) - (c(2 * X) * c(2 * Y) + c(2 * Y) * c(2 * Z)
                                         + c(2 * Z) * c(2 * X))
    raise AssertionError(kind)


def rng(seed=0):
    return np.random.default_rng(seed)


ODD = {"gyroid", "schwarz_d", "fischer_koch_s"}           # F(-x) = -F(x); the others are even
HALF_DIAGONAL = {"gyroid": 1, "iwp": 1, "schwarz_p": -1, "neovius": -1}  # F(x + cell/2 (1,1,1))


@pytest.mark.parametrize("kind", KINDS)
def test_formula_matches_a_hand_evaluation(kind):
    cell = np.array([2.0, 1.5, 3.0])
    pts = rng(1).uniform(-4, 4, (12, 3))
    for variant, level in (("solid", 0.3), ("sheet", 0.2)):
        f = Periodic(kind, cell=cell, level=level, variant=variant).field(pts)
        for p, v in zip(pts, f):
            F = hand(kind, *(2 * math.pi * p / cell))
            assert v == pytest.approx((F if variant == "solid" else abs(F)) - level, abs=1e-12)


@pytest.mark.parametrize("kind", KINDS)
def test_symmetries(kind):
    cell = 1.7
    sdf = Periodic(kind, cell=cell)
    p = rng(2).uniform(-3, 3, (200, 3))
    f = sdf.field(p)
    for axis in range(3):
        shift = np.zeros(3)
        shift[axis] = cell
        np.testing.assert_allclose(sdf.field(p + shift), f, atol=1e-12)
    np.testing.assert_allclose(sdf.field(-p), -f if kind in ODD else f, atol=1e-12)
    np.testing.assert_allclose(sdf.field(p[:, [1, 2, 0]]), f, atol=1e-12)   # cyclic axes
    if kind in HALF_DIAGONAL:
        np.testing.assert_allclose(sdf.field(p + cell / 2), HALF_DIAGONAL[kind] * f, atol=1e-12)


def test_matrix_is_applied_to_the_points():
    m = np.array([[1.0, 0.3, 0.0], [0.0, 0.8, -0.2], [0.1, 0.0, 1.2]])
    pts = rng(3).uniform(-2, 2, (10, 3))
    f = Periodic("gyroid", cell=1.3, matrix=m, level=-0.1).field(pts)
    for p, v in zip(pts, f):
        assert v == pytest.approx(hand("gyroid", *(2 * math.pi * (m @ p) / 1.3)) + 0.1, abs=1e-12)


def test_graded_level_is_linear_in_the_span_and_clamped_outside():
    sdf = Periodic("schwarz_p", cell=1.0, level=-1.0, level_end=2.0, grade_axis=(0, 2.0, 0),
                   grade_span=(1.0, 3.0))
    pts = rng(4).uniform(-2, 6, (300, 3))
    t = -1.0 + 3.0 * np.clip((pts[:, 1] - 1.0) / 2.0, 0, 1)
    F = np.array([hand("schwarz_p", *(2 * math.pi * p)) for p in pts])
    np.testing.assert_allclose(sdf.field(pts), F - t, atol=1e-12)


def test_graded_cell_is_anchored_at_the_extent_centre_and_takes_the_end_cell():
    box = ((-1.0, -2.0, 0.0), (3.0, 2.0, 4.0))
    centre = np.array([1.0, 0.0, 2.0])
    p = rng(5).uniform(box[0], box[1], (300, 3))
    same = Periodic("iwp", cell=0.9, cell_end=0.9, grade_span=(0.0, 4.0), extent=box)
    np.testing.assert_allclose(same.field(p), Periodic("iwp", cell=0.9).field(p - centre),
                               atol=1e-9)
    graded = Periodic("gyroid", cell=1.0, cell_end=0.5, grade_span=(1.0, 2.0), extent=box)
    top = p[p[:, 2] > 2.0]                              # past the span: the end cell, period 0.5
    shifted = top + [0.5, 0.0, 0.0]
    keep = shifted[:, 0] <= box[1][0]
    np.testing.assert_allclose(graded.field(shifted[keep]), graded.field(top[keep]), atol=1e-9)
    low = p[p[:, 2] < 1.0]
    F = [hand("gyroid", *(2 * math.pi * (q - centre))) for q in low]
    np.testing.assert_allclose(graded.field(low), F, atol=1e-9)
    outside = np.array([[10.0, 0.5, 1.5], [-5.0, -7.0, 9.0]])  # clamped into the extent
    np.testing.assert_allclose(graded.field(outside), graded.field(np.clip(outside, *box)))


def _trig_sum():
    return TrigSum([TrigTerm(1.2, (1, 2, 0), (0.1, -0.4, 0.3), ("sin", "cos", "cos")),
                    (-0.5, (3, 1, 1.5), (0.0, 0.7, 0.0), "sin")], width=2.5, level=0.2)


def test_trig_sum_matches_a_hand_evaluation():
    pts = rng(6).uniform(-3, 3, (20, 3))
    f = _trig_sum().field(pts)
    w = 2 * math.pi / 2.5
    for (x, y, z), v in zip(pts, f):
        ref = (1.2 * s(w * x + 0.1) * c(2 * w * y - 0.4) * c(0.3)
               - 0.5 * s(3 * w * x) * s(w * y + 0.7) * s(1.5 * w * z) - 0.2)
        assert v == pytest.approx(ref, abs=1e-12)


def _cases():
    m = np.array([[0.9, 0.4, 0.0], [-0.3, 1.1, 0.2], [0.0, 0.25, 0.7]])
    box = ((-1.5, -1.0, -2.0), (1.5, 2.0, 1.0))
    out = []
    for kind in KINDS:
        out.append((f"{kind}-solid", Periodic(kind, cell=(1.0, 1.4, 0.8), level=0.1)))
        out.append((f"{kind}-sheet", Periodic(kind, cell=1.2, level=0.3, variant="sheet")))
    out += [
        ("graded-level", Periodic("gyroid", cell=1.1, level=-0.5, level_end=0.6,
                                  grade_axis=(1, 1, 0), grade_span=(-1.0, 1.5))),
        ("graded-cell", Periodic("schwarz_d", cell=1.0, cell_end=(0.6, 0.8, 1.5), level=0.2,
                                 level_end=0.5, grade_axis=(0, 0.5, 1), grade_span=(-1, 1),
                                 extent=box, variant="sheet")),
        ("graded-affine", Periodic("frd", cell=1.3, cell_end=0.7, matrix=m, grade_span=(-1, 0.5),
                                   grade_axis=(1, 0, 0), extent=box)),
        ("affine", Periodic("neovius", cell=0.9, matrix=m, level=1.0)),
        ("trigsum", _trig_sum()),
    ]
    return out


CASES = _cases()


@pytest.mark.parametrize("name, sdf", CASES, ids=[n for n, _ in CASES])
def test_glsl_equals_numpy(gpu, name, sdf):
    pts = rng(7).uniform(-2.5, 2.5, (4000, 3))
    a = sdf.field(pts)
    b = evaluate_glsl(sdf, pts)
    assert np.max(np.abs(a - b)) <= 1e-5 * np.ptp(a)


@pytest.mark.parametrize("name, sdf", CASES, ids=[n for n, _ in CASES])
def test_lipschitz_bounds_the_gradient(name, sdf):
    p = rng(8).uniform(-2.5, 2.5, (20000, 3))
    h = 1e-6
    grad = np.stack([(sdf.field(p + h * e) - sdf.field(p - h * e)) / (2 * h) for e in np.eye(3)])
    g = np.linalg.norm(grad, axis=0)
    assert g.max() <= sdf.lipschitz * (1 + 1e-6)
    assert g.max() >= 0.15 * sdf.lipschitz                 # a bound, not an absurd one


@pytest.mark.parametrize("name, sdf", [CASES[0], CASES[3], CASES[-4], CASES[-3], CASES[-1]],
                         ids=lambda v: v if isinstance(v, str) else "")
def test_distance_is_a_lower_bound(name, sdf):
    """No point of the ball of radius |distance(p)| around p lies on the other side."""
    r = rng(9)
    centres = r.uniform(-2, 2, (150, 3))
    d = sdf.distance(centres)
    sign = np.sign(sdf.field(centres))
    dirs = r.normal(size=(150, 400, 3))
    dirs /= np.linalg.norm(dirs, axis=2, keepdims=True)
    radii = np.abs(d)[:, None] * r.uniform(0, 1, (150, 400)) ** (1 / 3)
    probe = (centres[:, None, :] + dirs * radii[..., None]).reshape(-1, 3)
    f = sdf.field(probe).reshape(150, 400)
    assert np.all(f * sign[:, None] >= -1e-12)


def test_box_is_none():
    assert Periodic("gyroid").box() is None
    assert _trig_sum().box() is None


@pytest.mark.parametrize("kwargs, match", [
    (dict(kind="sphere"), "kind"),
    (dict(variant="network"), "variant"),
    (dict(cell=0.0), "cell"),
    (dict(cell=(1.0, -1.0, 1.0)), "cell"),
    (dict(cell=float("nan")), "cell"),
    (dict(cell=(1.0, 2.0)), "cell"),
    (dict(level=float("nan")), "level"),
    (dict(level=-0.1, variant="sheet"), "sheet"),
    (dict(level=0.1, level_end=-0.2, variant="sheet"), "sheet"),
    (dict(matrix=[[1, 0, 0], [0, 1, 0], [1, 1, 0]]), "singular"),
    (dict(matrix=[[1, 0, 0], [0, np.inf, 0], [0, 0, 1]]), "matrix"),
    (dict(cell_end=0.5), "extent"),
    (dict(extent=((0, 0, 0), (1, 1, 1))), "extent"),
    (dict(cell_end=0.5, extent=((0, 0, 0), (1, -1, 1))), "extent"),
    (dict(cell_end=0.0, extent=((0, 0, 0), (1, 1, 1))), "cell_end"),
    (dict(level_end=1.0, grade_span=(1.0, 1.0)), "grade_span"),
    (dict(level_end=1.0, grade_axis=(0, 0, 0)), "grade_axis"),
])
def test_bad_periodic_refused(kwargs, match):
    with pytest.raises(ValueError, match=match):
        Periodic(**kwargs)


@pytest.mark.parametrize("kwargs, match", [
    (dict(terms=()), "term"),
    (dict(terms=(5.0,)), "term 0"),
    (dict(terms=((1.0, (1, 1, 1), (0, 0, 0), "tan"),)), "trig"),
    (dict(terms=((np.nan, (1, 1, 1)),)), "amplitude"),
    (dict(terms=((1.0, (1, np.nan, 1)),)), "freq"),
    (dict(terms=((1.0,),), width=0.0), "width"),
    (dict(terms=((1.0,),), level=np.inf), "level"),
])
def test_bad_trig_sum_refused(kwargs, match):
    with pytest.raises(ValueError, match=match):
        TrigSum(**kwargs)
