"""Particle shapes against brute-force distances to their surfaces.

The reference for each shape is its membership inequality straight from the
geometric definition (e.g. the round box as the points within `rounding` of
the inner box); surface points are found by bisecting every grid edge whose
ends disagree, and the reference distance is the nearest of those points.
"""

import math

import numpy as np
import pytest

from engine.implicit.shapes import SHAPES, Primitive, check_shape_params, shape_spec
from engine.implicit.values import GlslModule

H = 0.02          # reference grid spacing (unit-scale shapes)


def _clip_dist2(q, b):
    return np.sum((q - np.clip(q, -np.asarray(b), np.asarray(b))) ** 2, axis=1)


def _hex_inside(x, y, a):
    return np.all([np.abs(math.cos(t) * x + math.sin(t) * y) <= a
                   for t in np.radians([30.0, 90.0, 150.0])], axis=0)


# name -> (params, membership predicate of local points)
CASES = {
    "sphere": ((0.8,), lambda q: np.sum(q * q, 1) <= 0.64),
    "ellipsoid": ((1.0, 0.6, 0.35), lambda q: np.sum((q / [1.0, 0.6, 0.35]) ** 2, 1) <= 1.0),
    "box": ((0.9, 0.5, 0.3), lambda q: np.all(np.abs(q) <= [0.9, 0.5, 0.3], axis=1)),
    "round_box": ((0.9, 0.6, 0.4, 0.2), lambda q: _clip_dist2(q, [0.7, 0.4, 0.2]) <= 0.04),
    "torus": ((0.8, 0.3), lambda q: (np.hypot(q[:, 0], q[:, 1]) - 0.8) ** 2 + q[:, 2] ** 2 <= 0.09),
    "capsule": ((0.6, 0.3), lambda q: _clip_dist2(q, [0.0, 0.0, 0.6]) <= 0.09),
    "cylinder": ((0.5, 0.7), lambda q: (np.hypot(q[:, 0], q[:, 1]) <= 0.7) & (np.abs(q[:, 2]) <= 0.5)),
    "hex_prism": ((0.4, 0.8), lambda q: _hex_inside(q[:, 0], q[:, 1], 0.8) & (np.abs(q[:, 2]) <= 0.4)),
}
SPINDLE = ((0.3, 0.5), lambda q: (np.hypot(q[:, 0], q[:, 1]) - 0.3) ** 2 + q[:, 2] ** 2 <= 0.25)


def _surface(inside, extent=1.25):
    """Points on the boundary of {inside} by bisection along every grid edge that crosses it."""
    ax = np.arange(-extent, extent + H / 2, H)
    g = np.stack(np.meshgrid(ax, ax, ax, indexing="ij"), axis=-1)
    m = inside(g.reshape(-1, 3)).reshape(g.shape[:3])
    out = []
    for d in range(3):
        sl0 = [slice(None)] * 3
        sl1 = [slice(None)] * 3
        sl0[d], sl1[d] = slice(0, -1), slice(1, None)
        cross = m[tuple(sl0)] != m[tuple(sl1)]
        a, b = g[tuple(sl0)][cross], g[tuple(sl1)][cross]
        ina = m[tuple(sl0)][cross]
        for _ in range(40):
            mid = 0.5 * (a + b)
            same = inside(mid) == ina
            a = np.where(same[:, None], mid, a)
            b = np.where(same[:, None], b, mid)
        out.append(0.5 * (a + b))
    return np.concatenate(out)


def _nearest(points, surf):
    best = np.full(len(points), np.inf)
    for s in np.array_split(surf, max(1, len(surf) // 4000)):
        d2 = np.sum((points[:, None, :] - s[None, :, :]) ** 2, axis=2)
        best = np.minimum(best, d2.min(axis=1))
    return np.sqrt(best)


def _check_against_reference(name, params, inside, exact):
    spec = SHAPES[name]
    surf = _surface(inside)
    rng = np.random.default_rng(11)
    pts = rng.uniform(-1.5, 1.5, (300, 3))
    pts = np.concatenate([pts, surf[rng.choice(len(surf), 100)] + rng.normal(0, 0.05, (100, 3))])
    f = spec.fn(pts, *params)
    ref = _nearest(pts, surf)
    ins = inside(pts)
    far = ref > 2 * H
    assert np.all((f[far] < 0) == ins[far]), "sign disagrees with the membership test"
    assert np.all(np.abs(f) <= ref + 1e-7), "not a lower bound of the distance"
    if exact:
        np.testing.assert_allclose(np.abs(f), ref, atol=1.5 * H)
    # zero on the surface, and the bounding sphere holds it
    assert np.abs(spec.fn(surf, *params)).max() < 1e-6
    r = spec.bound(*params)
    norms = np.linalg.norm(surf, axis=1)
    assert norms.max() <= r + 1e-9 and norms.max() >= r - 2 * H


@pytest.mark.parametrize("name", sorted(CASES))
def test_distance_matches_brute_force(name):
    params, inside = CASES[name]
    _check_against_reference(name, params, inside, SHAPES[name].exact or name == "torus")


def test_spindle_torus_is_a_bound():
    _check_against_reference("torus", *SPINDLE, exact=False)


@pytest.mark.parametrize("name", sorted(SHAPES))
def test_lipschitz_bound(name):
    params = CASES[name][0]
    spec = SHAPES[name]
    rng = np.random.default_rng(5)
    a = rng.uniform(-1.5, 1.5, (20000, 3))
    for step in (1e-5, 0.3):
        b = a + rng.normal(0, step, a.shape)
        ratio = np.abs(spec.fn(a, *params) - spec.fn(b, *params)) / np.linalg.norm(a - b, axis=1)
        assert ratio.max() <= spec.lipschitz * (1 + 1e-5)


def test_parameters_broadcast_per_point():
    rng = np.random.default_rng(2)
    q = rng.uniform(-1, 1, (50, 3))
    s = rng.uniform(0.5, 2.0, 50)
    for name, spec in SHAPES.items():
        params = CASES[name][0]
        per_point = spec.fn(q, *(s * v for v in params))
        one_by_one = [spec.fn(q[i:i + 1], *(s[i] * v for v in params))[0] for i in range(50)]
        np.testing.assert_allclose(per_point, one_by_one, rtol=0, atol=1e-12)
        # exact scaling: d_s(q) = s d_1(q / s)
        np.testing.assert_allclose(per_point, s * spec.fn(q / s[:, None], *params), atol=1e-12)


def _rotation(seed):
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    return q * np.sign(np.diag(r))


def test_primitive_places_the_shape():
    rot, c = _rotation(3), np.array([0.5, -1.0, 2.0])
    prim = Primitive("box", (0.9, 0.5, 0.3), tuple(c), rot)
    rng = np.random.default_rng(4)
    local = rng.uniform(-1.5, 1.5, (500, 3))
    world = local @ rot.T + c
    # closed form of the axis-aligned box in its own frame
    d = np.abs(local) - [0.9, 0.5, 0.3]
    ref = np.linalg.norm(np.maximum(d, 0), axis=1) + np.minimum(d.max(axis=1), 0)
    np.testing.assert_allclose(prim.field(world), ref, atol=1e-12)
    lo, hi = prim.box()
    corners = np.array([[x, y, z] for x in (-.9, .9) for y in (-.5, .5) for z in (-.3, .3)]) @ rot.T + c
    assert np.all(corners >= np.array(lo) - 1e-12) and np.all(corners <= np.array(hi) + 1e-12)
    assert prim.lipschitz == 1.0 and prim.children == ()


@pytest.mark.parametrize("name", sorted(SHAPES))
def test_glsl_matches_numpy(gpu, name):
    from engine.gpu.sdf_points import evaluate_glsl
    prim = Primitive(name, tuple(2.0 * v for v in CASES[name][0]), (0.3, -0.2, 1.1), _rotation(7))
    pts = np.random.default_rng(8).uniform(-3, 3, (4000, 3)) + [0.3, -0.2, 1.1]
    scale = prim.bounding_radius
    np.testing.assert_allclose(evaluate_glsl(prim, pts), prim.field(pts), rtol=0, atol=1e-5 * scale)
    plain = Primitive(name, CASES[name][0])
    np.testing.assert_allclose(evaluate_glsl(plain, pts), plain.field(pts), rtol=0, atol=1e-5)


def test_one_glsl_helper_per_shape():
    m = GlslModule()
    a, b = Primitive("round_box", ()), Primitive("round_box", (1, 1, 1, 0.5))
    a.glsl(m)
    b.glsl(m)
    src = m.source()
    assert src.count("float mf_shape_round_box(") == 1 and src.count("float mf_shape_box(") == 1


def test_defaults_and_registry():
    for name, spec in SHAPES.items():
        assert len(spec.default) == len(spec.params)
        assert check_shape_params(name, ()) == spec.default
        assert spec.glsl_name in spec.glsl


@pytest.mark.parametrize("args, match", [
    (("cone", ()), "unknown particle shape"),
    (("sphere", (1.0, 2.0)), "takes parameters"),
    (("sphere", (-1.0,)), "r must be"),
    (("box", (1.0, 0.0, 1.0)), "by must be"),
    (("round_box", (1.0, 0.5, 1.0, 0.6)), r"rounding must be in \[0, 0.5\]"),
    (("capsule", (-0.1, 0.3)), "h must be"),
    (("torus", (math.nan, 0.3)), "R must be"),
])
def test_bad_parameters_refused(args, match):
    with pytest.raises(ValueError, match=match):
        Primitive(*args)


def test_bad_placement_refused():
    with pytest.raises(ValueError, match="orthogonal"):
        Primitive("sphere", (1.0,), (0, 0, 0), np.diag([1.0, 2.0, 1.0]))
    with pytest.raises(ValueError, match="centre"):
        Primitive("sphere", (1.0,), (0, 0, math.inf))
    with pytest.raises(ValueError, match="unknown"):
        shape_spec("blob")
