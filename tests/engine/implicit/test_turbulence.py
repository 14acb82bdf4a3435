"""The turbulence warp against a per-point loop of its formula, the single-octave warp, finite
differences of its Lipschitz bound, and its GLSL twin."""

import math
from dataclasses import dataclass

import numpy as np
import pytest

from engine.implicit.turbulence import MAX_OCTAVES, Turbulence, phase_table
from engine.implicit.values import SDF, GlslModule


def _points(n, lo=-3.0, hi=3.0, seed=0):
    return np.random.default_rng(seed).uniform(lo, hi, (n, 3))


def _loop_warp(p, amplitude, frequency, octaves, gain, lacunarity, matrix, phases):
    """p + A T(p), one point and one term at a time, straight from the formula."""
    a = np.asarray(amplitude, dtype=float)
    a = a * np.eye(3) if a.ndim == 0 else a
    m = np.eye(3) if matrix is None else np.asarray(matrix, dtype=float)
    shift = {0: 1, 1: 2, 2: 0}
    out = np.empty_like(p)
    for n, point in enumerate(p):
        q = [sum(m[r][c] * point[c] for c in range(3)) for r in range(3)]
        t = [0.0, 0.0, 0.0]
        for i in range(3):
            for o in range(octaves):
                t[i] += gain ** o * math.sin(lacunarity ** o * frequency * q[shift[i]] + phases[o][i])
        for i in range(3):
            out[n, i] = point[i] + sum(a[i][j] * t[j] for j in range(3))
    return out


@dataclass(frozen=True, eq=False)
class _Component(SDF):
    """One coordinate of the warped point as a scalar field, to read the warp's GLSL back."""

    turb: Turbulence
    axis: int

    def field(self, points):
        return self.turb.warp(points)[:, self.axis]

    def glsl(self, module):
        name = self.turb.glsl(module)
        return module.function(self, lambda n: f"float {n}(vec3 p) {{ return {name}(p)[{self.axis}]; }}")


def _random_case(rng):
    return dict(amplitude=rng.uniform(-0.3, 0.5, (3, 3)), frequency=rng.uniform(0.5, 4.0),
                octaves=int(rng.integers(1, MAX_OCTAVES + 1)), gain=rng.uniform(0.2, 1.0),
                lacunarity=rng.uniform(1.0, 3.0), matrix=rng.normal(0.0, 1.0, (3, 3)),
                seed=int(rng.integers(-1000, 1000)))


@pytest.mark.parametrize("case", [
    dict(amplitude=0.2, frequency=2.0),
    dict(amplitude=0.15, frequency=3.0, octaves=4, gain=0.6, lacunarity=2.3, seed=5),
    dict(amplitude=[[0.2, 0.05, 0.0], [0.0, 0.1, -0.03], [0.01, 0.0, 0.3]], frequency=1.5, octaves=3,
         matrix=[[1.0, 0.4, 0.0], [-0.2, 0.9, 0.3], [0.1, 0.0, 1.2]], seed=-3),
    dict(amplitude=0.1, frequency=0.0, octaves=2, seed=9),          # f = 0: a constant shift
])
def test_warp_matches_a_per_point_loop(case):
    turb = Turbulence(**case)
    p = _points(300)
    full = {**dict(octaves=1, gain=0.5, lacunarity=2.0, matrix=None, seed=0), **case}
    phases = phase_table(full.pop("seed"))
    ref = _loop_warp(p, phases=phases, **full)
    np.testing.assert_allclose(turb.warp(p), ref, rtol=0, atol=1e-12)


@pytest.mark.parametrize("seed", [0, 7, -4])
def test_one_octave_is_the_single_sine_warp_exactly(seed):
    a, f = 0.15, 3.0
    p = _points(2000, seed=1)
    old = p + a * np.sin(f * p[:, [1, 2, 0]])
    turb = Turbulence(a, f, seed=seed, gain=0.3, lacunarity=3.5)       # gain, lacunarity unused
    np.testing.assert_array_equal(turb.warp(p), old)
    assert turb.lipschitz == 1.0 + a * f


def test_phases_fixed_per_seed_and_octave():
    t0, t1 = phase_table(3), phase_table(3)
    np.testing.assert_array_equal(t0, t1)
    assert np.all(t0[0] == 0.0) and np.all((t0[1:] >= 0) & (t0[1:] < 2 * math.pi))
    assert not np.allclose(t0[1:], phase_table(4)[1:])
    # adding octaves keeps the lower ones: the difference is exactly the added terms
    p = _points(500, seed=2)
    lo = Turbulence(1.0, 2.0, octaves=2, seed=3).turbulence(p)
    hi = Turbulence(1.0, 2.0, octaves=3, seed=3).turbulence(p)
    q = p[:, [1, 2, 0]]
    np.testing.assert_allclose(hi - lo, 0.25 * np.sin(8.0 * q + t0[2]), atol=1e-12)


def test_identity_without_amplitude():
    p = _points(100)
    assert Turbulence(0.0, 5.0, octaves=4).is_identity
    assert Turbulence(np.zeros((3, 3)), 5.0).is_identity
    np.testing.assert_array_equal(Turbulence(0.0, 5.0, octaves=4).warp(p), p)
    assert Turbulence(0.0, 5.0, octaves=4).lipschitz == 1.0


@pytest.mark.parametrize("trial", range(6))
def test_finite_differences_never_exceed_the_bound(trial):
    rng = np.random.default_rng(100 + trial)
    turb = Turbulence(**_random_case(rng))
    a = _points(20000, seed=trial)
    worst = 0.0
    for step in (1e-6, 1e-3, 0.3):                 # derivatives, and pairs across whole waves
        b = a + rng.normal(0.0, step, a.shape)
        ratio = np.linalg.norm(turb.warp(a) - turb.warp(b), axis=1) / np.linalg.norm(a - b, axis=1)
        worst = max(worst, ratio.max())
    assert worst <= turb.lipschitz * (1 + 1e-7)
    assert worst > 1.0                             # the warp does stretch space


def test_bound_is_reached_by_the_jacobian_in_a_tight_case():
    # A = a I, M = I, one octave: J = I + a f diag(cos) P; along p.y = 0 (cos = 1) the derivative
    # of x_0 in y is a f, so |J e_y| = sqrt(1 + (a f)^2) <= 1 + a f: the bound holds and is of the
    # right size (not loose by orders of magnitude)
    turb = Turbulence(0.3, 2.0)
    h = 1e-7
    p = np.array([[0.4, 0.0, -0.2]])
    d = (turb.warp(p + [0.0, h, 0.0]) - turb.warp(p)) / h
    np.testing.assert_allclose(np.linalg.norm(d), math.sqrt(1 + 0.6 ** 2), rtol=1e-6)
    assert turb.lipschitz == pytest.approx(1.6)


def test_lipschitz_formula():
    amp = np.diag([0.1, 0.4, 0.2])
    m = np.array([[2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.5]])
    turb = Turbulence(amp, 1.5, octaves=3, gain=0.5, lacunarity=3.0, matrix=m)
    assert turb.lipschitz == pytest.approx(1 + 0.4 * 2.0 * 1.5 * (1 + 1.5 + 2.25))


def test_glsl_source_of_the_single_octave_warp():
    module = GlslModule()
    turb = Turbulence(0.25, 4.0)
    name = turb.glsl(module)
    assert turb.glsl(module) == name                      # defined once per object
    src = module.source()
    assert src.count(f"vec3 {name}(vec3 p)") == 1
    assert "vec3 q = p.yzx;" in src and "sin(4.0 * q)" in src and "return p + 0.25 * t;" in src


@pytest.mark.parametrize("case", [
    dict(amplitude=0.2, frequency=2.0),
    dict(amplitude=0.15, frequency=3.0, octaves=4, gain=0.6, lacunarity=2.3, seed=5),
    dict(amplitude=[[0.2, 0.05, 0.0], [0.0, 0.1, -0.03], [0.01, 0.0, 0.3]], frequency=1.5, octaves=3,
         matrix=[[1.0, 0.4, 0.0], [-0.2, 0.9, 0.3], [0.1, 0.0, 1.2]], seed=-3),
    dict(amplitude=np.diag([0.3, 0.0, 0.1]), frequency=1.0, octaves=8, gain=0.5, lacunarity=1.5, seed=2),
])
def test_glsl_matches_numpy(gpu, case):
    from engine.gpu.sdf_points import evaluate_glsl

    turb = Turbulence(**case)
    p = _points(4000, seed=4).astype(np.float32).astype(np.float64)    # what the GPU reads
    for axis in range(3):
        comp = _Component(turb, axis)
        np.testing.assert_allclose(evaluate_glsl(comp, p), comp.field(p), rtol=0, atol=2e-5)


@pytest.mark.parametrize("kw, match", [
    (dict(amplitude=-0.1), r"amplitude must be a finite number in \[0.0, inf\]"),
    (dict(amplitude=[[1.0, 2.0], [3.0, 4.0]]), "amplitude must be a number >= 0 .* or a 3 x 3 matrix"),
    (dict(amplitude=np.full((3, 3), np.nan)), "amplitude must be"),
    (dict(frequency=math.inf), "frequency must be a finite number"),
    (dict(frequency="fast"), "frequency must be a finite number"),
    (dict(octaves=0), r"octaves must be an int in \[1, 8\]"),
    (dict(octaves=9), r"octaves must be an int in \[1, 8\]"),
    (dict(octaves=2.0), "octaves must be an int"),
    (dict(octaves=True), "octaves must be an int"),
    (dict(gain=0.0), r"gain must be a finite number in \(0.0, 1.0\]"),
    (dict(gain=1.5), "gain"),
    (dict(lacunarity=0.5), r"lacunarity must be a finite number in \[1.0, 4.0\]"),
    (dict(lacunarity=4.5), "lacunarity"),
    (dict(matrix=np.eye(2)), "matrix must be None or a 3 x 3 matrix"),
    (dict(matrix=[[1, 0, 0], [0, math.inf, 0], [0, 0, 1]]), "matrix must be None or a 3 x 3"),
    (dict(seed=1.5), "seed must be an int"),
])
def test_bad_input_refused(kw, match):
    with pytest.raises(ValueError, match=match):
        Turbulence(**{"amplitude": 0.1, "frequency": 1.0, **kw})


def test_named_refusals_use_the_owners_names():
    with pytest.raises(ValueError, match=r"warp_octaves must be an int in \[1, 8\], got 12"):
        Turbulence.named({"octaves": "warp_octaves"}, amplitude=0.1, frequency=1.0, octaves=12)
