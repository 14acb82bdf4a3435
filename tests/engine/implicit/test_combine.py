"""Booleans, smooth blends, offsets and affine maps of exact spheres against closed forms and
brute-force distances to densely sampled surfaces; GLSL == numpy; bad input refused."""

from dataclasses import dataclass

import numpy as np
import pytest
from scipy.spatial import cKDTree

from engine.gpu.sdf_points import evaluate_glsl
from engine.implicit.combine import (Affine, Difference, Intersection, Offset, Shell,
                                     SmoothDifference, SmoothIntersection, SmoothUnion, Union)
from engine.implicit.values import SDF, as_points, glsl_float


@dataclass(frozen=True, eq=False)
class Sphere(SDF):
    """The exact distance to a sphere, times `scale` (scale > 1: a non-exact field, bound scale)."""

    centre: tuple = (0.0, 0.0, 0.0)
    radius: float = 1.0
    scale: float = 1.0

    @property
    def lipschitz(self):
        return self.scale

    @property
    def exact(self):
        return True               # field / scale is the Euclidean distance

    def field(self, points):
        return self.scale * (np.linalg.norm(as_points(points) - self.centre, axis=1) - self.radius)

    def glsl(self, module):
        c = ", ".join(glsl_float(v) for v in self.centre)
        return module.function(self, lambda n: (
            f"float {n}(vec3 p) {{ return {glsl_float(self.scale)} * "
            f"(length(p - vec3({c})) - {glsl_float(self.radius)}); }}"))

    def box(self):
        c = np.array(self.centre)
        return (tuple(c - self.radius), tuple(c + self.radius))


A = Sphere((0.0, 0.0, 0.0), 1.0)
B = Sphere((1.2, 0.3, -0.1), 0.8)


def points(n=3000, seed=0, lo=-2.5, hi=3.0):
    return np.random.default_rng(seed).uniform(lo, hi, (n, 3))


def sphere_surface(centre, radius, n=60_000):
    """Fibonacci points on a sphere (spacing ~ radius * sqrt(4 pi / n))."""
    i = np.arange(n) + 0.5
    z = 1 - 2 * i / n
    phi = np.pi * (1 + 5 ** 0.5) * i
    r = np.sqrt(1 - z * z)
    return np.asarray(centre) + radius * np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def near_both(n, seed):
    """Half of the points around both spheres, half in a box around their lens."""
    r = np.random.default_rng(seed)
    return np.vstack([r.uniform(-2.0, 2.8, (n // 2, 3)),
                      r.uniform((0.2, -0.6, -0.8), (1.2, 0.9, 0.6), (n - n // 2, 3))])


def nearest(p, samples):
    """Distance from each of `p` to the nearest sample (a k-d tree: exact nearest neighbour)."""
    return cKDTree(samples).query(p)[0]


def inside(s, p):
    return np.linalg.norm(p - s.centre, axis=1) < s.radius


def exact(s, p):
    return np.linalg.norm(p - s.centre, axis=1) - s.radius


SA, SB = sphere_surface(A.centre, A.radius), sphere_surface(B.centre, B.radius)
GAP = 0.02     # > the largest distance from a surface point to its nearest sample


@pytest.mark.parametrize("op", ["union", "intersection", "difference"])
def test_booleans_of_spheres(op):
    p = near_both(4000, seed=0)
    a, b, ia, ib = exact(A, p), exact(B, p), inside(A, p), inside(B, p)
    in_sa, in_sb = inside(B, SA), inside(A, SB)
    if op == "union":
        sdf, member = Union((A, B)), ia | ib
        surface = np.vstack([SA[~in_sa], SB[~in_sb]])
        exact_where, exact_value = ~member, np.minimum(a, b)      # outside: distance to nearest
    elif op == "intersection":
        sdf, member = Intersection([A, B]), ia & ib
        surface = np.vstack([SA[in_sa], SB[in_sb]])
        exact_where, exact_value = member, np.maximum(a, b)        # inside: depth below nearest
    else:
        sdf, member = Difference(A, B), ia & ~ib
        surface = np.vstack([SA[~in_sa], SB[in_sb]])
        exact_where, exact_value = None, None
    f = sdf.field(p)
    assert sdf.lipschitz == 1.0
    np.testing.assert_array_equal(f < 0, member)
    brute = nearest(p, surface)          # >= the true distance, by at most GAP
    assert np.all(np.abs(f) <= brute + 1e-12)
    if exact_where is not None:
        assert exact_where.sum() > 100
        np.testing.assert_allclose(f[exact_where], exact_value[exact_where], atol=1e-12)
        np.testing.assert_allclose(np.abs(f[exact_where]), brute[exact_where], atol=GAP)


@pytest.mark.parametrize("cls, hard, below", [
    (SmoothUnion, lambda a, b: np.minimum(a, b), True),
    (SmoothIntersection, lambda a, b: np.maximum(a, b), False),
    (SmoothDifference, lambda a, b: np.maximum(a, -b), False),
])
@pytest.mark.parametrize("k", [0.1, 0.6])
def test_smooth_blends_bracket_the_hard_ones(cls, hard, below, k):
    p = near_both(8000, seed=1)
    a, b = exact(A, p), exact(B, p)
    f, h = cls(A, B, k).field(p), hard(a, b)
    gap = np.abs(a - b) if cls is not SmoothDifference else np.abs(a + b)
    far = gap >= k
    assert far.sum() > 100 and (~far).sum() > 100
    np.testing.assert_allclose(f[far], h[far], atol=1e-12)
    if below:
        assert np.all((f <= h + 1e-12) & (f >= h - k / 4 - 1e-12))
    else:
        assert np.all((f >= h - 1e-12) & (f <= h + k / 4 + 1e-12))
    assert np.max(np.abs(f - h)) > 0.2 * k / 4          # the blend does something
    eps = 1e-6
    g = np.linalg.norm(np.stack([(cls(A, B, k).field(p + eps * e) - cls(A, B, k).field(p - eps * e))
                                 for e in np.eye(3)]) / (2 * eps), axis=0)
    assert g.max() <= 1 + 1e-6


def test_offset_and_shell_of_a_sphere():
    p = points(2000, seed=2)
    r = np.linalg.norm(p, axis=1)
    np.testing.assert_allclose(Offset(A, 0.3).field(p), r - 1.3, atol=1e-12)
    np.testing.assert_allclose(Offset(A, -0.4).field(p), r - 0.6, atol=1e-12)
    np.testing.assert_allclose(Shell(A, 0.2).field(p), np.abs(r - 1.0) - 0.1, atol=1e-12)
    loose = Sphere(radius=1.0, scale=3.0)                 # offsets use the normalised distance
    np.testing.assert_allclose(Offset(loose, 0.3).field(p), r - 1.3, atol=1e-12)
    np.testing.assert_allclose(Shell(loose, 0.2).field(p), np.abs(r - 1.0) - 0.1, atol=1e-12)


def rotation(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def test_affine_translate_rotate_scale_a_sphere():
    p = points(2000, seed=3)
    t = np.array([0.5, -1.0, 2.0])
    child = Sphere((0.3, 0.0, -0.2), 0.7)
    moved = Affine(child, np.eye(3), t)
    np.testing.assert_allclose(moved.field(p), np.linalg.norm(p - t - child.centre, axis=1) - 0.7,
                               atol=1e-12)
    rot = rotation((1, 2, -1), 0.8)
    spun = Affine(child, rot, t)                          # the sphere's centre moves to R c + t
    np.testing.assert_allclose(spun.field(p),
                               np.linalg.norm(p - (rot @ child.centre + t), axis=1) - 0.7,
                               atol=1e-12)
    big = Affine(child, 2.5 * rot, t)
    c = 2.5 * rot @ child.centre + t
    assert big.lipschitz == pytest.approx(1 / 2.5)
    np.testing.assert_allclose(big.distance(p), np.linalg.norm(p - c, axis=1) - 2.5 * 0.7,
                               atol=1e-12)


def test_affine_ellipsoid_distance_is_a_lower_bound():
    m = rotation((0.3, 1, 0.2), 1.1) @ np.diag([0.6, 1.0, 1.8]) @ rotation((1, 0, 0), 0.4)
    t = np.array([0.2, -0.3, 0.1])
    child = Sphere(radius=1.0, scale=2.0)
    ell = Affine(child, m, t)
    inv_norm = 1 / np.sqrt(np.linalg.eigvalsh(m.T @ m).min())
    assert ell.lipschitz == pytest.approx(2.0 * inv_norm, rel=1e-12)
    p = points(1000, seed=4, lo=-3.0, hi=3.0)
    y = (p - t) @ np.linalg.inv(m).T
    np.testing.assert_array_equal(ell.field(p) < 0, np.linalg.norm(y, axis=1) < 1)
    surface = sphere_surface((0, 0, 0), 1.0, 150_000) @ m.T + t
    brute = nearest(p, surface)
    d = ell.distance(p)
    assert np.all(np.abs(d) <= brute + 1e-12)
    assert np.max(np.abs(d) / brute) > 0.9                # tight along the shortest axis
    eps = 1e-6
    g = np.linalg.norm(np.stack([ell.field(p + eps * e) - ell.field(p - eps * e)
                                 for e in np.eye(3)]) / (2 * eps), axis=0)
    assert g.max() <= ell.lipschitz * (1 + 1e-6)


def _box(lo, hi):
    return (tuple(float(v) for v in lo), tuple(float(v) for v in hi))


def test_boxes():
    a_box, b_box = (np.array([-1.0] * 3), np.array([1.0] * 3)), \
        (np.array(B.centre) - 0.8, np.array(B.centre) + 0.8)
    union = _box(np.minimum(a_box[0], b_box[0]), np.maximum(a_box[1], b_box[1]))
    inter = _box(np.maximum(a_box[0], b_box[0]), np.minimum(a_box[1], b_box[1]))
    got = lambda s: _box(*s.box())  # noqa: E731
    np.testing.assert_allclose(got(Union((A, B))), union)
    np.testing.assert_allclose(got(Intersection((A, B))), inter)
    np.testing.assert_allclose(got(Difference(A, B)), _box(*a_box))
    np.testing.assert_allclose(got(SmoothUnion(A, B, 0.3)),
                               _box(np.array(union[0]) - 0.3, np.array(union[1]) + 0.3))
    np.testing.assert_allclose(got(SmoothIntersection(A, B, 0.3)), inter)
    np.testing.assert_allclose(got(SmoothDifference(A, B, 0.3)), _box(*a_box))
    np.testing.assert_allclose(got(Offset(A, 0.25)), _box([-1.25] * 3, [1.25] * 3))
    np.testing.assert_allclose(got(Offset(A, -0.25)), _box(*a_box))
    np.testing.assert_allclose(got(Shell(A, 0.4)), _box([-1.2] * 3, [1.2] * 3))
    rot = rotation((0, 0, 1), np.pi / 4)
    np.testing.assert_allclose(got(Affine(A, rot, (1.0, 0, 0))),
                               _box([1 - 2 ** 0.5, -2 ** 0.5, -1], [1 + 2 ** 0.5, 2 ** 0.5, 1]))
    disjoint = Intersection((A, Sphere((5.0, 0, 0), 1.0)))
    lo, hi = disjoint.box()
    assert np.all(np.array(hi) >= np.array(lo))
    assert Union((A, _Everywhere())).box() is None
    np.testing.assert_allclose(got(Intersection((A, _Everywhere()))), _box(*a_box))


@dataclass(frozen=True, eq=False)
class _Everywhere(SDF):
    def field(self, points):
        return np.full(len(as_points(points)), -1.0)

    def glsl(self, module):
        return module.function(self, lambda n: f"float {n}(vec3 p) {{ return -1.0; }}")


ELLIPSOID = Affine(A, np.diag([1.0, 1.0, 10.0]), (0.0, 0.0, 0.0))  # distance 10x short at the tips


def _trees():
    m = rotation((1, 1, 0), 0.5) @ np.diag([0.7, 1.3, 1.0])
    loose = Sphere((0.2, -0.4, 0.5), 0.9, scale=2.5)
    return [
        ("union", Union((A, B, loose))),
        ("intersection", Intersection((A, loose))),
        ("difference", Difference(A, B)),
        ("smooth-union", SmoothUnion(A, loose, 0.4)),
        ("smooth-intersection", SmoothIntersection(loose, B, 0.3)),
        ("smooth-difference", SmoothDifference(A, B, 0.5)),
        ("offset", Offset(loose, -0.2)),
        ("shell", Shell(B, 0.15)),
        ("affine", Affine(loose, m, (0.3, -0.2, 1.0))),
        ("nested", SmoothUnion(Shell(Affine(Union((A, B)), 1.5 * rotation((1, 1, 0), 0.5), (0, 0.5, 0)),
                                     0.1), Offset(B, 0.1), 0.2)),
    ]


TREES = _trees()


@pytest.mark.parametrize("name, sdf", TREES, ids=[n for n, _ in TREES])
def test_glsl_equals_numpy(gpu, name, sdf):
    p = points(4000, seed=5)
    a = sdf.field(p)
    b = evaluate_glsl(sdf, p)
    assert np.max(np.abs(a - b)) <= 1e-5 * np.ptp(a)


@pytest.mark.parametrize("name, sdf", TREES, ids=[n for n, _ in TREES])
def test_outside_the_box_is_positive(name, sdf):
    lo, hi = (np.array(v) for v in sdf.box())
    p = points(20000, seed=6, lo=-6, hi=6)
    out = np.any((p < lo) | (p > hi), axis=1)
    assert np.all(sdf.field(p[out]) > 0)


@pytest.mark.parametrize("make", [lambda: Offset(ELLIPSOID, 1.0), lambda: Shell(ELLIPSOID, 2.0),
                                  lambda: SmoothUnion(ELLIPSOID, ELLIPSOID, 1.0)],
                         ids=["offset", "shell", "smooth-union"])
def test_box_of_a_non_exact_child(make):
    """An ellipsoid as an Affine of a sphere is 10x short near its tips: growing its box by the
    amount would leave material outside, so the box is unbounded (None)."""
    sdf = make()
    assert not ELLIPSOID.exact and sdf.box() is None
    assert Offset(ELLIPSOID, -0.1).box() == ELLIPSOID.box()      # inwards stays in the child's box


@pytest.mark.parametrize("make, match", [
    (lambda: Union(()), "at least one"),
    (lambda: Union((A, 3.0)), "part 1"),
    (lambda: Intersection([A, "sphere"]), "part 1"),
    (lambda: Difference(A, None), "part 1"),
    (lambda: SmoothUnion(A, B, 0.0), "k"),
    (lambda: SmoothIntersection(A, B, -1.0), "k"),
    (lambda: SmoothDifference(A, B, float("nan")), "k"),
    (lambda: SmoothUnion(A, np.eye(3), 0.2), "part 1"),
    (lambda: Shell(A, 0.0), "thickness"),
    (lambda: Shell(A, -0.1), "thickness"),
    (lambda: Offset(A, float("inf")), "amount"),
    (lambda: Offset("A", 0.1), "part 0"),
    (lambda: Affine(A, [[1, 0, 0], [0, 1, 0], [2, 2, 0]], (0, 0, 0)), "singular"),
    (lambda: Affine(A, np.zeros((3, 3)), (0, 0, 0)), "singular"),
    (lambda: Affine(A, np.eye(3), (0, np.nan, 0)), "finite"),
])
def test_bad_input_refused(make, match):
    with pytest.raises(ValueError, match=match):
        make()


@pytest.mark.parametrize("make", [lambda: Union(A), lambda: Offset(A, "a")],
                         ids=["union-of-one", "offset-text"])
def test_unvalidated_types_raise_value_error(make):
    with pytest.raises(ValueError):
        make()
