"""The GPU path tracer against closed forms: white furnaces (energy conservation, one diffuse
bounce off a convex body), a dielectric slab with Beer-Lambert absorption (multiple internal
reflections summed as a geometric series, exact Fresnel and Snell written here), and the
unbiasedness of Russian roulette (the same mean within Monte Carlo error)."""

import math

import numpy as np
import pytest

from engine.gpu.camera import Camera
from engine.gpu.path_trace import SKY, depth_study, path_trace, tonemap
from engine.implicit.combine import Union
from engine.implicit.shapes import Primitive

SPHERE = Primitive("sphere", (1.0,), (0.0, 0.0, 0.0))
EYE_DISTANCE = 4.0
SPHERE_CAMERA = Camera((0.0, -EYE_DISTANCE, 0.0), (0.0, 0.0, 0.0), fov_deg=40.0)
CLUSTER = Union(tuple(Primitive("sphere", (r,), c) for r, c in (
    (0.6, (0.0, 0.0, 0.0)), (0.45, (0.75, 0.2, 0.3)), (0.4, (-0.6, 0.3, -0.4)), (0.35, (0.1, -0.2, 0.75)),
    (0.5, (0.2, 0.6, -0.5)))))
CLUSTER_CAMERA = Camera((2.2, -3.0, 1.6), (0.05, 0.15, 0.0), fov_deg=40.0)
N = 32


def _pixel_radii(camera, n):
    """Per pixel the least and the largest image-plane radius (units of the focal length) of
    its square: the angle to the view axis grows with it, so these bound the jittered rays."""
    tan_half = math.tan(math.radians(camera.fov_deg) / 2)
    edges = (2.0 * np.arange(n + 1) / n - 1.0) * tan_half          # square image: same in x and y
    lo, hi = edges[:-1], edges[1:]
    near = np.where((lo <= 0) & (hi >= 0), 0.0, np.minimum(np.abs(lo), np.abs(hi)))
    far = np.maximum(np.abs(lo), np.abs(hi))
    return np.hypot(near[:, None], near[None, :]), np.hypot(far[:, None], far[None, :])


def _sphere_cover():
    """(covered, empty) pixel masks of the unit sphere seen from its axis at EYE_DISTANCE."""
    tan_sphere = math.tan(math.asin(1.0 / EYE_DISTANCE))
    near, far = _pixel_radii(SPHERE_CAMERA, N)
    return far < tan_sphere * (1 - 1e-3), near > tan_sphere * (1 + 1e-3)


def _frame_means(**kwargs):
    """The image mean of each frame (independent estimates), from the running means on_frame gets."""
    means = []
    res = path_trace(on_frame=lambda k, img: means.append(float(img.mean()) * k), **kwargs)
    return res, np.diff(np.array([0.0] + means))


def test_white_furnace_albedo_one_is_white(gpu):
    res = path_trace(SPHERE, SPHERE_CAMERA, N, N, frames=2, albedo=(1, 1, 1), environment="white")
    np.testing.assert_allclose(res.radiance, 1.0, atol=1e-6)
    assert res.truncated == 0.0 and res.unfinished == 0.0
    assert np.all(res.rgba == 255)


@pytest.mark.parametrize("material", ["diffuse", "dielectric"])
def test_a_lossless_furnace_returns_every_path_that_is_not_cut(gpu, material):
    """Albedo 1 / no absorption: each path that escapes brings back exactly 1, whatever its
    bounces between the spheres (or internal reflections, total ones included); only paths
    cut by the depth cap or max_steps bring 0."""
    res = path_trace(CLUSTER, CLUSTER_CAMERA, N, N, frames=2, max_depth=64, material=material,
                     albedo=(1, 1, 1), environment="white")
    assert res.truncated + res.unfinished < 1e-3
    assert abs(res.brightness - (1.0 - res.truncated - res.unfinished)) < 1e-5
    assert res.depth.max() > 1.0                     # some paths bounce more than once


def test_furnace_with_albedo_a_convex_body_gives_a(gpu):
    """A convex body: the one diffuse bounce always escapes, so L = a (times the white sky)
    on pixels the sphere covers, 1 where it does not."""
    a = np.array([0.3, 0.6, 0.9])
    covered, empty = _sphere_cover()
    assert covered.sum() > 100 and empty.sum() > 300
    res = path_trace(SPHERE, SPHERE_CAMERA, N, N, frames=2, albedo=a, environment="white",
                     russian_roulette=False)
    np.testing.assert_allclose(res.radiance[covered], np.broadcast_to(a, (covered.sum(), 3)), atol=1e-6)
    np.testing.assert_allclose(res.radiance[empty], 1.0, atol=1e-6)
    assert np.all(res.depth[covered] == 1.0) and np.all(res.depth[empty] == 0.0)
    # with roulette: survival q = max(a) = 0.9 and weight a / q, so a pixel mean has mean a and
    # variance a^2 (1 / q - 1) / samples
    rr = path_trace(SPHERE, SPHERE_CAMERA, N, N, frames=4, samples_per_frame=4, albedo=a,
                    environment="white", russian_roulette=True, seed=5)
    q = a.max()
    n = covered.sum() * rr.samples
    sd = a * math.sqrt(1 / q - 1) / math.sqrt(n)
    err = rr.radiance[covered].mean(axis=0) - a
    assert np.all(np.abs(err) < 5 * sd), (err, sd)
    assert np.all(np.abs(err) > 0)                                    # it is random


def test_russian_roulette_keeps_the_mean_at_high_depth(gpu):
    kw = dict(sdf=CLUSTER, camera=CLUSTER_CAMERA, width=N, height=N, frames=8, samples_per_frame=2,
              max_depth=64, albedo=(0.7, 0.5, 0.3), environment="sky")
    plain, f_plain = _frame_means(russian_roulette=False, seed=1, **kw)
    rr, f_rr = _frame_means(russian_roulette=True, seed=2, **kw)
    se = math.hypot(f_plain.std(ddof=1) / math.sqrt(len(f_plain)), f_rr.std(ddof=1) / math.sqrt(len(f_rr)))
    assert abs(plain.brightness - rr.brightness) < 5 * se
    assert rr.mean_depth < plain.mean_depth                           # roulette ends paths early
    np.testing.assert_allclose(f_plain.mean(), plain.brightness, rtol=1e-5)


def _fresnel(cos_i, n1, n2):
    """Unpolarised Fresnel reflectance (the mean of the s and p parts)."""
    sin_t = n1 / n2 * np.sqrt(1 - cos_i ** 2)
    cos_t = np.sqrt(1 - sin_t ** 2)
    rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t)
    rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t)
    return 0.5 * (rs ** 2 + rp ** 2), cos_t


@pytest.mark.parametrize("theta_deg", [0.0, 50.0])
def test_slab_transmission_with_absorption(gpu, theta_deg):
    """A slab of thickness d under a black sky over a white ground: a pixel sees only the
    light transmitted through the slab, T = (1 - R)^2 tau / (1 - R^2 tau^2) with
    tau = exp(-sigma d / cos theta_t) (the internal reflections summed), R at the angle."""
    d, ior, sigma = 1.0, 1.5, np.array([0.2, 0.7, 1.5])
    slab = Primitive("box", (6.0, 6.0, 0.5 * d), (0.0, 0.0, 0.0))
    th = math.radians(theta_deg)
    eye = 40.0 * np.array([math.sin(th), 0.0, math.cos(th)])
    cam = Camera(eye, (0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0) if theta_deg == 0 else (0.0, 0.0, 1.0), fov_deg=2.0)
    n = 16
    res = path_trace(slab, cam, n, n, frames=8, samples_per_frame=8, max_depth=64, material="dielectric",
                     ior=ior, absorption=sigma, environment=((1, 1, 1), (0, 0, 0)), russian_roulette=False)
    _, dirs = cam.rays(n, n)
    cos_i = np.abs(dirs[..., 2])[..., None]
    R, cos_t = _fresnel(cos_i, 1.0, ior)
    tau = np.exp(-sigma * d / cos_t)
    expect = (1 - R) ** 2 * tau / (1 - R ** 2 * tau ** 2)
    second = (1 - R) ** 2 * tau ** 2 / (1 - R ** 2 * tau ** 4)      # E[X^2]: X = tau^(2m+1) w.p. (1-R)^2 R^2m
    sd = np.sqrt((second - expect ** 2) / res.samples)
    z = (res.radiance - expect) / sd
    assert np.abs(z).max() < 5.0
    assert np.all(np.abs(z.mean(axis=(0, 1))) < 5.0 / n)          # per channel, over n^2 pixels
    assert res.mean_depth > 1.5 and res.truncated == 0.0


def test_fresnel_from_inside_and_total_internal_reflection(gpu):
    """The eye inside a thin slab looking up at 25..55 degrees from the normal (the critical
    angle is 41.8 degrees), one scattering event allowed: a path sees the white sky only if
    it refracts out at the first hit, so L = 1 - R(theta) from inside, 0 beyond the critical
    angle, a Bernoulli mean."""
    ior = 1.5
    slab = Primitive("box", (10.0, 10.0, 0.5), (0.0, 0.0, 0.0))
    view = math.radians(40.0)
    cam = Camera((0.0, 0.0, 0.0), (math.sin(view), 0.0, math.cos(view)), fov_deg=30.0)
    n = 24
    res = path_trace(slab, cam, n, n, frames=8, samples_per_frame=8, max_depth=1, material="dielectric",
                     ior=ior, environment="white", russian_roulette=False)
    _, dirs = cam.rays(n, n)
    cos_i = dirs[..., 2]
    sin_t = ior * np.sqrt(1 - cos_i ** 2)
    critical = math.asin(1 / ior)
    theta = np.arccos(cos_i)
    pixel = math.radians(30.0) / n
    clear = np.abs(theta - critical) > 1.5 * pixel                  # the jitter stays on one side
    inside = sin_t < 1
    R = np.ones_like(cos_i)
    R[inside] = _fresnel(cos_i[inside], ior, 1.0)[0]
    expect = 1 - R
    got = res.radiance[..., 0]
    assert np.all(got[clear & ~inside] == 0.0)                      # total internal reflection
    sd = np.sqrt(expect * (1 - expect) / res.samples)
    ok = clear & inside
    assert ok.sum() > 100 and (clear & ~inside).sum() > 100
    assert np.all(np.abs(got[ok] - expect[ok]) < 5 * sd[ok] + 1e-6)
    np.testing.assert_array_equal(res.radiance[..., 0], res.radiance[..., 2])


def test_sky_environment_seen_directly(gpu):
    """Rays that miss everything see the sky: the ground colour below the horizon, and above,
    the horizon colour mixed towards the zenith by the ray's z."""
    cam = Camera((0.0, -8.0, 0.0), (0.0, 0.0, 0.0), fov_deg=60.0)
    res = path_trace(SPHERE, cam, 24, 24, frames=1, environment="sky", seed=3)
    _, dirs = cam.rays(24, 24)
    z = dirs[..., 2]
    far = np.abs(dirs[..., 0]) > 0.25                                # away from the sphere
    up, down = far & (z > 0.05), far & (z < -0.05)
    expect = np.asarray(SKY["horizon"]) + z[..., None] * (np.asarray(SKY["zenith"]) - SKY["horizon"])
    np.testing.assert_allclose(res.radiance[up], expect[up], atol=0.02)   # jitter moves z by < 0.02
    np.testing.assert_allclose(res.radiance[down], np.broadcast_to(SKY["ground"], (down.sum(), 3)), atol=1e-6)


def test_same_seed_same_bits_and_the_seed_matters(gpu):
    kw = dict(frames=2, max_depth=8, albedo=(0.7, 0.7, 0.7), environment="sky")
    a = path_trace(CLUSTER, CLUSTER_CAMERA, N, N, seed=7, **kw)
    b = path_trace(CLUSTER, CLUSTER_CAMERA, N, N, seed=7, **kw)
    c = path_trace(CLUSTER, CLUSTER_CAMERA, N, N, seed=8, **kw)
    assert a.radiance.tobytes() == b.radiance.tobytes() and a.rgba.tobytes() == b.rgba.tobytes()
    assert a.radiance.tobytes() != c.radiance.tobytes()
    assert not a.radiance.flags.writeable
    assert len(a.frame_ms) == 2 and a.samples == 2


def test_check_cancels_and_on_frame_reports_progress(gpu):
    seen = []
    res = path_trace(SPHERE, SPHERE_CAMERA, 8, 8, frames=3, on_frame=lambda k, img: seen.append((k, img)))
    assert [k for k, _ in seen] == [1, 2, 3]
    assert seen[-1][1].tobytes() == res.radiance.tobytes()
    calls = []

    def stop():
        calls.append(1)
        if len(calls) == 2:
            raise RuntimeError("cancel")
    with pytest.raises(RuntimeError, match="cancel"):
        path_trace(SPHERE, SPHERE_CAMERA, 8, 8, frames=5, check=stop)
    assert len(calls) == 2


def test_tonemap_is_srgb_of_the_clamped_radiance():
    x = np.array([[[0.0, 0.5, 2.0], [0.002, 0.1, 1.0]]])
    out = tonemap(x)
    assert out.shape == (1, 2, 4) and out.dtype == np.uint8
    np.testing.assert_array_equal(out[0, :, 3], 255)
    np.testing.assert_array_equal(out[0, 0, :3], [0, 188, 255])
    np.testing.assert_array_equal(out[0, 1, :3], [7, 89, 255])         # 6.59, 89.04


def test_depth_study_brightness_rises_then_settles(gpu):
    study = depth_study(CLUSTER, CLUSTER_CAMERA, depths=(1, 2, 4, 8, 16, 32), width=24, height=24,
                        frames=2, material="dielectric", absorption=(0.3, 0.3, 0.3), environment="sky")
    b = study.brightness
    assert np.all(np.diff(b) >= -1e-6)                       # shared random numbers: never darker
    assert b[1] - b[0] > 10 * (b[-1] - b[-2])                # the gain from a deeper cap shrinks
    assert np.all(np.diff(study.mean_depth) >= 0) and np.all(np.diff(study.truncated) <= 1e-9)
    assert study.truncated[0] > 0.1 and study.truncated[-1] < 0.01
    assert study.frame_ms.shape == (6,) and np.all(study.frame_ms > 0)


@pytest.mark.parametrize("kwargs, match", [
    (dict(max_depth=0), "max_depth"), (dict(absorption=(-0.1, 0, 0)), "absorption"), (dict(ior=0.0), "ior"),
    (dict(ior=-1.5), "ior"), (dict(frames=0), "frames"), (dict(samples_per_frame=0), "samples_per_frame"),
    (dict(material="metal"), "material"), (dict(albedo=(1.2, 0, 0)), "albedo"), (dict(seed=-1), "seed"),
    (dict(environment="night"), "environment"), (dict(environment=(-1, 0, 0)), "environment"),
    (dict(russian_roulette=1), "russian_roulette"), (dict(check=3), "check"), (dict(on_frame="x"), "on_frame"),
    (dict(epsilon=0.0), "epsilon"), (dict(max_steps=0), "max_steps"), (dict(width=0), "width"),
])
def test_bad_parameters_are_refused(kwargs, match):
    args = dict(width=8, height=8)
    args.update(kwargs)
    w, h = args.pop("width"), args.pop("height")
    with pytest.raises(ValueError, match=match):
        path_trace(SPHERE, SPHERE_CAMERA, w, h, **args)


def test_bad_scene_camera_and_depths_are_refused():
    with pytest.raises(ValueError, match="sdf"):
        path_trace("sphere", SPHERE_CAMERA, 8, 8)
    with pytest.raises(ValueError, match="camera"):
        path_trace(SPHERE, None, 8, 8)
    with pytest.raises(ValueError, match="depths"):
        depth_study(SPHERE, SPHERE_CAMERA, depths=(4, 2))
    with pytest.raises(ValueError, match="depths"):
        depth_study(SPHERE, SPHERE_CAMERA, depths=())
    with pytest.raises(ValueError, match="max_depth"):
        depth_study(SPHERE, SPHERE_CAMERA, max_depth=3)
