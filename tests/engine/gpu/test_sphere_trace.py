"""The GPU sphere tracer against float64 numpy: exact SDFs written here, a dense
sign-change march that uses no distance bound, and the numpy fixed-step march."""

import math
from dataclasses import dataclass

import numpy as np
import pytest

from engine.gpu._sphere_trace_reference import clip_rays, march_dense, march_fixed
from engine.gpu.camera import Camera
from engine.gpu.sdf_points import evaluate_glsl
from engine.gpu.sphere_trace import render
from engine.implicit.combine import Affine, Intersection, Union
from engine.implicit.values import SDF, as_points, glsl_float


def _vec(v):
    return ", ".join(glsl_float(x) for x in v)


@dataclass(frozen=True, eq=False)
class Sphere(SDF):
    centre: tuple
    radius: float

    def field(self, points):
        return np.linalg.norm(as_points(points) - np.asarray(self.centre), axis=1) - self.radius

    def glsl(self, module):
        return module.function(self, lambda n: (
            f"float {n}(vec3 p) {{ return length(p - vec3({_vec(self.centre)})) - {glsl_float(self.radius)}; }}"))

    def box(self):
        return tuple(np.subtract(self.centre, self.radius)), tuple(np.add(self.centre, self.radius))


@dataclass(frozen=True, eq=False)
class Cuboid(SDF):
    """Exact distance to an axis-aligned box (centre, half sizes)."""

    centre: tuple
    half: tuple

    def field(self, points):
        q = np.abs(as_points(points) - np.asarray(self.centre)) - np.asarray(self.half)
        return np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0)

    def glsl(self, module):
        return module.function(self, lambda n: (
            f"float {n}(vec3 p) {{ vec3 q = abs(p - vec3({_vec(self.centre)})) - vec3({_vec(self.half)});\n"
            f"    return length(max(q, 0.0)) + min(max(q.x, max(q.y, q.z)), 0.0); }}"))

    def box(self):
        return tuple(np.subtract(self.centre, self.half)), tuple(np.add(self.centre, self.half))


@dataclass(frozen=True, eq=False)
class Gyroid(SDF):
    """sin kx cos ky + sin ky cos kz + sin kz cos kx - level.  Each partial derivative is
    k (cos a cos b - sin c sin a), and |cos a cos b| + |sin a sin b| = max |cos(a -+ b)| <= 1,
    so |grad f| <= k sqrt(3)."""

    k: float
    level: float = 0.0

    @property
    def lipschitz(self):
        return self.k * math.sqrt(3.0)

    def field(self, points):
        x, y, z = (self.k * as_points(points)).T
        return (np.sin(x) * np.cos(y) + np.sin(y) * np.cos(z) + np.sin(z) * np.cos(x)) - self.level

    def glsl(self, module):
        return module.function(self, lambda n: (
            f"float {n}(vec3 p) {{ vec3 q = {glsl_float(self.k)} * p;\n"
            f"    return dot(sin(q), cos(q.yzx)) - {glsl_float(self.level)}; }}"))


@dataclass(frozen=True, eq=False)
class TexturedWaves(SDF):
    """A periodic field sampled on an n^3 grid (period `period` mm), read back with
    trilinear interpolation (a 3D texture in GLSL), minus `level`."""

    period: float
    level: float
    n: int = 8

    def samples(self):
        i = np.arange(self.n) * (2 * np.pi / self.n)
        z, y, x = np.meshgrid(i, i, i, indexing="ij")
        return np.cos(x) + np.cos(y) + np.cos(z)           # (nz, ny, nx)

    @property
    def lipschitz(self):
        v = self.samples()
        jump = max(np.abs(np.diff(v, axis=a, append=np.take(v, [0], axis=a))).max() for a in range(3))
        return float(jump * self.n / self.period * math.sqrt(3.0))

    def field(self, points):
        g = as_points(points) / self.period * self.n - 0.5      # texel centres at integers
        i0 = np.floor(g).astype(int)
        f = g - i0
        v = self.samples()
        out = np.zeros(len(g))
        for corner in np.ndindex(2, 2, 2):
            c = np.array(corner)
            wgt = np.prod(np.where(c, f, 1.0 - f), axis=1)
            ix, iy, iz = ((i0 + c) % self.n).T
            out += wgt * v[iz, iy, ix]
        return out - self.level

    def glsl(self, module):
        def make(n):
            tex = module.texture3d(self, self.samples())
            return (f"float {n}(vec3 p) {{ return texture({tex}, p / {glsl_float(self.period)}).r"
                    f" - {glsl_float(self.level)}; }}")
        return module.function(self, make)


def _rotation(axis, angle):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


SPHERE = Sphere((0.2, -0.1, 0.3), 1.0)
SCENES = {
    "sphere": (SPHERE, Camera((3.0, -4.0, 2.0), (0.2, -0.1, 0.3), fov_deg=30.0)),
    # a rotation keeps the distance exact; the bounds become the rotated box's wider AABB
    "box": (Affine(Cuboid((0.0, 0.1, 0.0), (0.8, 0.5, 0.6)), _rotation((0.3, -1, 2), 0.6), (0.1, 0, 0)),
            Camera((2.5, -3.0, 2.0), (0, 0, 0), fov_deg=35.0)),
    "union": (Union((Sphere((0.6, 0.0, 0.0), 0.7), Cuboid((-0.5, 0.2, 0.0), (0.5, 0.6, 0.4)))),
              Camera((1.0, -4.0, 2.5), (0, 0, 0), fov_deg=35.0)),
    "affine": (Affine(Sphere((0, 0, 0), 1.0), _rotation((1, 2, 0.5), 0.7) @ np.diag([1.6, 0.6, 1.0]),
                      (0.1, 0.0, -0.2)), Camera((3.0, 3.0, 2.0), (0, 0, 0), fov_deg=40.0)),
    "gyroid": (Intersection((Gyroid(2 * np.pi, 0.3), Cuboid((0, 0, 0), (1.2, 1.2, 1.2)))),
               Camera((3.5, -4.0, 3.0), (0, 0, 0), fov_deg=38.0)),
}
SIZE = 64


def _scene_size(sdf):
    lo, hi = sdf.box()
    return float(np.linalg.norm(np.subtract(hi, lo)))


@pytest.fixture(scope="module")
def traced(gpu):
    """Per scene: the GPU frame (fixed steps) and the rays it used."""
    out = {}
    for name, (sdf, cam) in SCENES.items():
        o, d = cam.rays(SIZE, SIZE)
        out[name] = (render(sdf, cam, SIZE, SIZE, step="fixed", max_steps=2000),
                     o.reshape(-1, 3), d.reshape(-1, 3))
    return out


@pytest.mark.parametrize("sdf", [s for s, _ in SCENES.values()] + [TexturedWaves(1.0, 0.5)],
                         ids=[*SCENES, "textured"])
def test_the_test_fields_glsl_matches_numpy_and_bounds_hold(gpu, sdf):
    rng = np.random.default_rng(3)
    p = rng.uniform(-1.7, 1.7, (4000, 3))
    f = sdf.field(p)
    np.testing.assert_allclose(evaluate_glsl(sdf, p), f, atol=2e-5 * max(1.0, np.abs(f).max()))
    h = 1e-6
    grad = np.stack([(sdf.field(p + h * e) - sdf.field(p - h * e)) / (2 * h) for e in np.eye(3)], axis=1)
    assert np.linalg.norm(grad, axis=1).max() <= sdf.lipschitz * (1 + 1e-4)


@pytest.mark.parametrize("name", list(SCENES))
def test_hit_points_lie_on_the_zero_set(traced, name):
    sdf = SCENES[name][0]
    res, o, d = traced[name]
    hit = res.hit.reshape(-1)
    assert 0.05 * hit.size < hit.sum() < 0.95 * hit.size         # the scene fills part of the frame
    p = o[hit] + res.depth.reshape(-1)[hit, None].astype(np.float64) * d[hit]
    assert np.abs(sdf.distance(p)).max() < 1e-4 * _scene_size(sdf)
    assert np.all(np.isinf(res.depth[~res.hit]))
    t0, t1 = clip_rays(o, d, *res.bounds, res.far)
    np.testing.assert_array_equal(res.steps.reshape(-1) == 0, t0 > t1)    # rays that miss the box


@pytest.mark.parametrize("name", list(SCENES))
def test_hits_agree_with_a_dense_sign_change_march(traced, name):
    sdf = SCENES[name][0]
    res, o, d = traced[name]
    size = _scene_size(sdf)
    t0, t1 = clip_rays(o, d, *res.bounds, res.far)
    t_dense, hit_dense = march_dense(sdf, o, d, t0, t1, dt=1e-3 * size)
    hit, depth = res.hit.reshape(-1), res.depth.reshape(-1).astype(np.float64)
    assert np.count_nonzero(hit & hit_dense) > 0.9 * np.count_nonzero(hit)
    # a ray the tracer misses but the dense march hits may only graze the surface
    missed = np.flatnonzero(~hit & hit_dense)
    assert len(missed) <= 2
    for i in missed:
        assert np.abs(sdf.distance(o[i] + np.linspace(t0[i], t1[i], 20000)[:, None] * d[i])).min() < 1e-4 * size
    # where the tracer stops earlier, it found a sliver or a touching point that the dense
    # march stepped over: a 1000 times finer march near the tracer's depth confirms it
    with np.errstate(invalid="ignore"):                     # inf - inf on rays both miss
        early = np.flatnonzero(hit & ~(np.abs(depth - t_dense) < 1e-3 * t_dense))
    assert len(early) <= 0.01 * np.count_nonzero(hit)
    assert np.all(depth[early] < t_dense[early])
    if len(early):
        lo, hi = depth[early] - 1e-3 * size, depth[early] + 1e-2 * size
        t_fine, _ = march_dense(sdf, o[early], d[early], lo, hi, dt=1e-6 * size, chunk=4096)
        touch = np.abs(sdf.distance(o[early] + depth[early, None] * d[early])) < 2 * res.epsilon
        assert np.all((np.abs(t_fine - depth[early]) < 1e-3 * depth[early]) | touch)


@pytest.mark.parametrize("name", list(SCENES))
def test_depth_matches_the_numpy_fixed_march(traced, name):
    sdf = SCENES[name][0]
    res, o, d = traced[name]
    t0, t1 = clip_rays(o, d, *res.bounds, res.far)
    t_ref, hit_ref, steps_ref = march_fixed(sdf, o, d, t0, t1, epsilon=res.epsilon, max_steps=2000)
    hit = res.hit.reshape(-1)
    assert np.count_nonzero(hit != hit_ref) <= 3
    both = hit & hit_ref
    rel = np.abs(res.depth.reshape(-1)[both] - t_ref[both]) / t_ref[both]
    assert np.count_nonzero(rel > 1e-3) <= 3
    assert np.median(rel) < 1e-5
    # the same march in float32 takes about as many steps
    steps = res.steps.reshape(-1)[both]
    assert abs(steps.mean() - steps_ref[both].mean()) < 0.05 * steps_ref[both].mean()


def test_sphere_normals_are_radial(traced):
    res, o, d = traced["sphere"]
    hit = res.hit.reshape(-1)
    p = o[hit] + res.depth.reshape(-1)[hit, None] * d[hit]
    exact = (p - SPHERE.centre) / SPHERE.radius
    n = res.normal.reshape(-1, 3)[hit]
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-5)
    assert np.degrees(np.arccos(np.clip(np.sum(n * exact, axis=1), -1, 1))).max() < 0.05
    assert np.all(res.normal[~res.hit] == 0.0)


def test_normal_shading_is_the_normal_as_colour(traced):
    res = traced["sphere"][0]
    expect = np.round((res.normal + 1.0) * 0.5 * 255.0)
    assert np.abs(res.rgba[..., :3].astype(float) - expect)[res.hit].max() <= 1.0
    assert np.all(res.rgba[..., 3] == np.where(res.hit, 255, 0))
    assert np.all(res.rgba[~res.hit] == 0)


TEXTURED = (Intersection((TexturedWaves(period=1.0, level=0.5), Cuboid((0, 0, 0), (1.0, 1.0, 1.0)))),
            Camera((2.5, -3.0, 2.2), (0, 0, 0), fov_deg=40.0))
MODES = [("bijection", 10, 3.0), ("adaptive", 1, 3.0), ("adaptive", 10, 3.0), ("adaptive", 100, 3.0),
         ("adaptive", 500, 3.0), ("adaptive", 100, 64.0)]


@pytest.mark.parametrize("name", [*SCENES, "textured"])
def test_all_step_modes_give_the_same_hit_mask(gpu, traced, name):
    """No rule misses a pixel the fixed rule hits (the re-trace) and none hits one it misses."""
    sdf, cam = TEXTURED if name == "textured" else SCENES[name]
    fixed = traced[name][0] if name in traced else render(sdf, cam, SIZE, SIZE, max_steps=2000)
    assert not fixed.retraced.any()
    for step, every, stretch in MODES:
        res = render(sdf, cam, SIZE, SIZE, step=step, adaptive_every=every, stretch=stretch, max_steps=2000)
        key = (step, every, stretch)
        assert not res.unfinished.any()
        assert np.count_nonzero(res.hit != fixed.hit) == 0, key
        # a re-traced ray is the fixed march again: the same depth, bit for bit, and its
        # steps count both marches
        r = res.retraced
        assert np.array_equal(res.depth[r], fixed.depth[r]), key
        assert np.all(res.steps[r] > fixed.steps[r]), key
        assert np.all(res.evaluations >= res.steps)
        # every ray that misses inside the box was re-traced (or was the fixed march itself)
        assert np.all(r | res.hit | (res.steps == 0) | (res.steps == fixed.steps)), key
        both = res.hit & fixed.hit
        rel = np.abs(res.depth[both] - fixed.depth[both]) / fixed.depth[both]
        allowed = 3 if stretch > 3.0 else 0                 # a sliver skipped with long steps
        assert np.count_nonzero(rel > 1e-3) <= allowed, key


def test_the_retrace_recovers_hits_that_long_adaptive_steps_jump_over(gpu, traced):
    sdf, cam = SCENES["gyroid"]
    fixed = traced["gyroid"][0]
    res = render(sdf, cam, SIZE, SIZE, step="adaptive", adaptive_every=100, stretch=64.0, max_steps=2000)
    recovered = res.retraced & res.hit
    assert recovered.sum() >= 3 and np.all(fixed.hit[recovered])
    missing_in_box = (fixed.steps > 0) & ~fixed.hit
    assert np.array_equal(res.retraced & ~res.hit, missing_in_box)


def test_adaptive_steps_on_an_exact_distance_are_the_fixed_march(gpu, traced):
    """|grad D| = 1 for a sphere: the adaptive rule makes fixed steps, so no re-trace is needed
    and depths are the fixed rule's bits; only the gradient estimates are added."""
    sdf, cam = SCENES["sphere"]
    fixed = traced["sphere"][0]
    res = render(sdf, cam, SIZE, SIZE, step="adaptive", adaptive_every=10)
    assert res.retraced_count == 0
    assert res.depth.tobytes() == fixed.depth.tobytes()
    assert np.array_equal(res.steps, fixed.steps)
    assert np.all(res.evaluations[res.steps > 0] >= res.steps[res.steps > 0] + 3)


def test_relaxed_and_adaptive_steps_are_fewer_on_the_periodic_scene(gpu, traced):
    sdf, cam = SCENES["gyroid"]
    fixed = traced["gyroid"][0]
    relaxed = render(sdf, cam, SIZE, SIZE, step="bijection")
    adaptive = render(sdf, cam, SIZE, SIZE, step="adaptive")
    for res in (relaxed, adaptive):
        first = fixed.hit & ~res.retraced            # hit by the first march alone
        assert res.steps[first].mean() < 0.9 * fixed.steps[first].mean()
    # with the re-trace of the rays that miss, the adaptive rule still makes fewer steps
    assert adaptive.mean_steps < 0.9 * fixed.mean_steps


def test_a_textured_field_traces_onto_its_trilinear_surface(gpu):
    sdf, cam = TEXTURED
    res = render(sdf, cam, 48, 48, max_steps=2000)
    o, d = cam.rays(48, 48)
    hit = res.hit.reshape(-1)
    assert hit.sum() > 0.2 * hit.size
    p = o.reshape(-1, 3)[hit] + res.depth.reshape(-1)[hit, None] * d.reshape(-1, 3)[hit]
    # (a driver whose texture unit filters with 8-bit weights would need a looser bound)
    assert np.abs(sdf.distance(p)).max() < 1e-4 * _scene_size(sdf)


def test_user_bounds_clip_the_rays(gpu):
    sdf, cam = SCENES["sphere"]
    lo, hi = np.array(SPHERE.centre) - 2.0, np.array(SPHERE.centre) + 2.0
    wide = render(sdf, cam, 32, 32, bounds=(lo, hi))
    np.testing.assert_allclose(wide.bounds[0], lo - 0.5 * wide.epsilon)
    # a box beside the sphere sees nothing
    empty = render(sdf, cam, 32, 32, bounds=(lo + 3.5, hi + 3.5))
    assert not empty.hit.any() and wide.hit.sum() > 100


def test_lambert_and_depth_shading(gpu):
    sdf, cam = SCENES["sphere"]
    lam = render(sdf, cam, 32, 32, shading="lambert")
    grey = lam.rgba[..., :3][lam.hit]
    assert np.all(grey[:, 0] == grey[:, 1]) and grey.min() >= round(0.1 * 255) - 1 and grey.max() > 200
    dep = render(sdf, cam, 32, 32, shading="depth")
    g = dep.rgba[..., 0][dep.hit].astype(float)
    z = dep.depth[dep.hit]
    assert np.corrcoef(g, z)[0, 1] < -0.99          # nearer is brighter


def test_same_inputs_give_the_same_bytes(gpu, traced):
    sdf, cam = SCENES["gyroid"]
    again = render(sdf, cam, SIZE, SIZE, step="fixed", max_steps=2000)
    first = traced["gyroid"][0]
    for name in ("rgba", "depth", "steps", "normal"):
        assert getattr(again, name).tobytes() == getattr(first, name).tobytes()
    assert not again.depth.flags.writeable


def test_max_steps_leaves_rays_unfinished(gpu):
    sdf, cam = SCENES["sphere"]
    res = render(sdf, cam, 32, 32, max_steps=3)
    assert res.unfinished.any() and not (res.unfinished & res.hit).any()
    assert np.all(res.steps[res.unfinished] == 3) and res.max_steps == 3
    assert not render(sdf, cam, 32, 32, max_steps=2000).unfinished.any()
    # adaptive: the re-trace has its own max_steps, and its steps are added
    sdf, cam = SCENES["gyroid"]
    res = render(sdf, cam, 32, 32, step="adaptive", max_steps=3)
    u = res.unfinished
    assert u.any() and np.all(res.retraced[u]) and not (u & res.hit).any()
    assert np.all((res.steps[u] >= 4) & (res.steps[u] <= 6)) and res.max_steps == 6


def test_check_is_called_between_tiles_and_may_cancel(gpu):
    sdf, cam = SCENES["sphere"]
    calls = []
    render(sdf, cam, 300, 20, check=lambda: calls.append(1))
    assert len(calls) == 2

    def stop():
        raise RuntimeError("cancel")
    with pytest.raises(RuntimeError, match="cancel"):
        render(sdf, cam, 16, 16, check=stop)


@pytest.mark.parametrize("kwargs, match", [
    (dict(step="newton"), "step"), (dict(shading="phong"), "shading"), (dict(adaptive_every=0), "adaptive_every"),
    (dict(max_steps=0), "max_steps"), (dict(epsilon=-1.0), "epsilon"), (dict(omega=2.0), "omega"),
    (dict(far=float("inf")), "far"), (dict(bounds=((0, 0), (1, 1))), "bounds"),
    (dict(bounds=((1, 1, 1), (0, 0, 0))), "bounds"), (dict(gradient_h=0.0), "gradient_h"),
    (dict(width=0), "width"), (dict(check=3), "check"), (dict(stretch=0.5), "stretch"),
])
def test_bad_parameters_are_refused(kwargs, match):
    sdf, cam = SCENES["sphere"]
    args = dict(width=8, height=8)
    args.update(kwargs)
    w, h = args.pop("width"), args.pop("height")
    with pytest.raises(ValueError, match=match):
        render(sdf, cam, w, h, **args)
    with pytest.raises(ValueError, match="sdf"):
        render("sphere", cam, 8, 8)
    with pytest.raises(ValueError, match="camera"):
        render(sdf, (0, 0, 0), 8, 8)
