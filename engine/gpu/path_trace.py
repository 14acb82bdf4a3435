"""Progressive Monte Carlo path tracing of an SDF tree on the headless GPU (paper 004, sections 4, 7.2).

A compute shader traces, per pixel and frame, `samples_per_frame` paths from
the camera (`engine.gpu.camera`, jittered inside the pixel); numpy averages
the frames.  Every segment of a path is found by sphere tracing with the
safe Lipschitz rule (`engine.gpu._sphere_trace_glsl.MARCH_GLSL`: ``t += D``,
D = f / L) inside the bounds; a segment inside the medium traces -D.  The
only light is the environment, seen by a path that leaves the bounds
outside the medium.

Materials (``material=``):

``"diffuse"``
    an opaque Lambertian surface of reflectance `albedo` (rgb): the next
    direction is drawn from the cosine-weighted hemisphere about the normal,
    so the path weight is multiplied by `albedo` (the BRDF times the cosine
    over the density).
``"dielectric"``
    a smooth interface of refractive index `ior` (outside 1): reflection or
    refraction is chosen with the exact unpolarised Fresnel reflectance
    ``R = (Rs + Rp) / 2`` as probability (so the weight is unchanged),
    refraction by Snell's law, total internal reflection where
    ``sin(theta_t) > 1``.  Inside, the weight decays by Beer-Lambert,
    ``exp(-absorption * length)`` per segment (absorption: rgb, per mm).
    `albedo` is not used (colour comes from `absorption`).

A path ends when it escapes (adding weight x environment), at its
``max_depth + 1``-th surface hit (the depth cap: at most `max_depth`
scattering events), when a segment uses `max_steps` evaluations (counted as
unfinished), or by Russian roulette: after each event the path survives with
probability ``q = min(1, max(weight))`` (the share of energy the absorption
of that event left) and a survivor's weight is divided by q, which keeps the
estimator unbiased.  Normals are central differences of D (step
`gradient_h`), a new segment starts where ``+-D >= 2 epsilon`` on its side.

Random numbers: a PCG hash of (seed, frame, pixel) seeds a per-pixel LCG
stream with a PCG output permutation, so the same inputs give the same bits.
Paths with the same seed and different `max_depth` share their random
numbers up to the cap, so the brightness never falls as the cap rises.

Environments (``environment=``): ``"white"`` (radiance 1 everywhere), an rgb
constant, a pair ``(ground_rgb, sky_rgb)`` (one constant below the horizon
z = 0, another above) or ``"sky"`` (`SKY`: ground below, above a gradient
from the horizon to the zenith, linear in the direction's z).

`depth_study` renders one scene at increasing `max_depth` (paper Figs. 11-12).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from engine.gpu._sphere_trace_glsl import CLIP_GLSL, GRADIENT_GLSL, MARCH_GLSL
from engine.gpu.camera import CAMERA_GLSL, Camera
from engine.gpu.context import gpu_session
from engine.gpu.shader_cache import bind_textures, compute_program
from engine.gpu.sphere_trace import _box, _count, _length, _real
from engine.implicit.values import SDF, GlslModule

__all__ = ["path_trace", "PathTraceResult", "depth_study", "DepthStudy", "MATERIALS", "SKY", "tonemap"]

MATERIALS = ("diffuse", "dielectric")
SKY = {"ground": (0.35, 0.32, 0.28), "horizon": (1.0, 1.0, 1.0), "zenith": (0.35, 0.55, 1.0)}
TILE = 256
GROUP = 8

_SOURCE = """#version 430
#define MATERIAL {material}
#define SKY_GRADIENT {sky}
layout(local_size_x = {group}, local_size_y = {group}) in;
layout(rgba32f, binding = 0) writeonly uniform image2D u_out;
layout(rgba32f, binding = 1) writeonly uniform image2D u_aux;
{camera}
uniform ivec2 u_offset;
uniform vec3 u_lo;
uniform vec3 u_hi;
uniform float u_eps;
uniform float u_h;
uniform int u_max_steps;
uniform int u_max_depth;
uniform int u_spp;
uniform uint u_frame;
uniform uint u_seed;
uniform int u_rr;
uniform vec3 u_albedo;
uniform float u_ior;
uniform vec3 u_sigma;
uniform vec3 u_env_ground;
uniform vec3 u_env_sky;
uniform vec3 u_env_zenith;

{library}
float scene(vec3 p) {{ return {entry}(p); }}
{clip}
{march}
{gradient}

uint pcg_hash(uint v) {{
    uint s = v * 747796405u + 2891336453u;
    uint w = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return (w >> 22u) ^ w;
}}
uint rng;
float rnd() {{                    // uniform in [0, 1), 24 bits
    rng = rng * 747796405u + 2891336453u;
    uint w = ((rng >> ((rng >> 28u) + 4u)) ^ rng) * 277803737u;
    return float(((w >> 22u) ^ w) >> 8) * (1.0 / 16777216.0);
}}

vec3 environment(vec3 d) {{
    if (d.z < 0.0) return u_env_ground;
#if SKY_GRADIENT
    return mix(u_env_sky, u_env_zenith, d.z);
#else
    return u_env_sky;
#endif
}}

// distance along the ray to the first zero of sgn * scene inside the box, or -1 (none; then
// stuck tells whether max_steps ended the march)
float trace(vec3 ro, vec3 rd, float sgn, out bool stuck) {{
    float t = 0.0;
    float t_end = 3.0e38;
    clip_box(ro, rd, u_lo, u_hi, t, t_end);
    stuck = false;
    if (t > t_end) return -1.0;
    int n;
    float d = march_fixed(ro, rd, t, t_end, sgn, u_eps, u_max_steps, n);
    if (d < u_eps) return t;
    stuck = n >= u_max_steps && t <= t_end;
    return -1.0;
}}

// a point off the surface point p on the side sgn (+1 outside, -1 inside) with sgn * D >= 2 eps
vec3 leave(vec3 p, vec3 n, float sgn) {{
    float delta = 2.0 * u_eps;
    vec3 q = p + sgn * delta * n;
    for (int k = 0; k < 16 && sgn * scene(q) < 2.0 * u_eps; k++) {{
        delta *= 2.0;
        q = p + sgn * delta * n;
    }}
    return q;
}}

void main() {{
    ivec2 px = u_offset + ivec2(gl_GlobalInvocationID.xy);
    if (px.x >= u_cam_size.x || px.y >= u_cam_size.y) return;
    rng = pcg_hash(uint(px.x + px.y * u_cam_size.x) ^ pcg_hash(u_frame ^ pcg_hash(u_seed)));
    vec3 total = vec3(0.0);
    float depth_total = 0.0, stuck_paths = 0.0, capped_paths = 0.0;
    for (int sample_index = 0; sample_index < u_spp; sample_index++) {{
        vec2 s = (vec2(px) + vec2(rnd(), rnd())) / vec2(u_cam_size);
        vec3 rd = normalize(u_cam_forward + (2.0 * s.x - 1.0) * u_cam_right + (1.0 - 2.0 * s.y) * u_cam_up);
        vec3 ro = u_cam_eye;
        float sgn = scene(ro) < 0.0 ? -1.0 : 1.0;      // -1: the segment runs inside the medium
        vec3 weight = vec3(1.0);
        vec3 radiance = vec3(0.0);
        int depth = 0;
        while (true) {{
            bool stuck;
            float t = trace(ro, rd, sgn, stuck);
            if (t < 0.0) {{
                if (stuck) stuck_paths += 1.0;
                else if (sgn > 0.0) radiance += weight * environment(rd);
                break;                 // (inside and out of the box: the box cuts the medium)
            }}
            vec3 p = ro + t * rd;
#if MATERIAL == 1
            if (sgn < 0.0) weight *= exp(-u_sigma * t);
#endif
            if (depth == u_max_depth) {{
                capped_paths += 1.0;
                break;
            }}
            depth++;
            vec3 g = scene_gradient(p, u_h);
            vec3 n = dot(g, g) > 0.0 ? normalize(g) : -rd;        // outward
            vec3 nf = sgn * n;                                    // towards the incident side
            float ci = -dot(rd, nf);
            if (ci < 0.0) {{ nf = -nf; ci = -ci; }}
#if MATERIAL == 0
            weight *= u_albedo;
            float r2 = rnd();
            float phi = 6.283185307179586 * rnd();
            float sz = nf.z >= 0.0 ? 1.0 : -1.0;                  // a basis about nf (Duff et al.)
            float a = -1.0 / (sz + nf.z);
            float b = nf.x * nf.y * a;
            vec3 b1 = vec3(1.0 + sz * nf.x * nf.x * a, sz * b, -sz * nf.x);
            vec3 b2 = vec3(b, sz + nf.y * nf.y * a, -nf.y);
            rd = normalize(sqrt(r2) * (cos(phi) * b1 + sin(phi) * b2) + sqrt(max(1.0 - r2, 0.0)) * nf);
            ro = leave(p, n, sgn);
#else
            float eta = sgn > 0.0 ? 1.0 / u_ior : u_ior;          // n_incident / n_transmitted
            float st2 = eta * eta * max(1.0 - ci * ci, 0.0);
            float R = 1.0;                                        // total internal reflection
            float ct = 0.0;
            if (st2 < 1.0) {{
                ct = sqrt(1.0 - st2);
                float rs = (eta * ci - ct) / (eta * ci + ct);
                float rp = (eta * ct - ci) / (eta * ct + ci);
                R = 0.5 * (rs * rs + rp * rp);
            }}
            if (rnd() < R) {{
                rd = normalize(rd + 2.0 * ci * nf);
            }} else {{
                rd = normalize(eta * rd + (eta * ci - ct) * nf);
                sgn = -sgn;
            }}
            ro = leave(p, n, sgn);
#endif
            if (u_rr == 1) {{
                float q = min(max(weight.x, max(weight.y, weight.z)), 1.0);
                if (rnd() >= q) break;
                weight /= q;
            }}
        }}
        total += radiance;
        depth_total += float(depth);
    }}
    float inv = 1.0 / float(u_spp);
    imageStore(u_out, px, vec4(total * inv, depth_total * inv));
    imageStore(u_aux, px, vec4(stuck_paths * inv, capped_paths * inv, 0.0, 0.0));
}}
"""


@dataclass(frozen=True, eq=False)
class PathTraceResult:
    """The average of the frames; arrays are read-only, indexed ``[row from the top, column]``.

    Attributes
    ----------
    radiance : (h, w, 3) float32, linear rgb, the mean over all paths of a pixel
    rgba : (h, w, 4) uint8, `tonemap` of `radiance`
    frames : int, frames accumulated; samples : int, paths per pixel
    depth : (h, w) float32, mean scattering events per path
    mean_depth : float, `depth` averaged over the pixels
    truncated : float, share of the paths stopped by the depth cap
    unfinished : float, share of the paths stopped by `max_steps` in a segment
    frame_ms : tuple of float, GPU time of each frame's dispatches (ms; on llvmpipe the
        first frame of a new shader includes its compile)
    epsilon, gradient_h : float, mm; bounds : ((3,), (3,)) float64 mm
    """

    radiance: np.ndarray
    rgba: np.ndarray
    frames: int
    samples: int
    depth: np.ndarray
    mean_depth: float
    truncated: float
    unfinished: float
    frame_ms: tuple
    epsilon: float
    gradient_h: float
    bounds: tuple

    @property
    def brightness(self) -> float:
        """The mean of `radiance` over pixels and channels."""
        return float(self.radiance.mean())


def tonemap(radiance) -> np.ndarray:
    """Linear rgb ((h, w, 3)) to sRGB-encoded rgba uint8: clamped to [0, 1], then the sRGB
    transfer curve; alpha 255."""
    x = np.clip(np.asarray(radiance, dtype=np.float64), 0.0, 1.0)
    srgb = np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1.0 / 2.4) - 0.055)
    out = np.full(x.shape[:2] + (4,), 255, np.uint8)
    out[..., :3] = np.round(255.0 * srgb).astype(np.uint8)
    return out


def _rgb(name: str, value, lo: float, hi: float) -> tuple:
    try:
        v = np.broadcast_to(np.asarray(value, dtype=np.float64), (3,))
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected 3 numbers (rgb), got {value!r}") from None
    if isinstance(value, (str, bool)) or not np.all(np.isfinite(v)) or np.any(v < lo) or np.any(v > hi):
        raise ValueError(f"{name}: expected rgb values in [{lo}, {hi}], got {value!r}")
    return tuple(float(c) for c in v)


def _environment(value) -> tuple[bool, tuple, tuple, tuple]:
    """(gradient?, ground, sky, zenith) uniforms for an `environment` argument."""
    if isinstance(value, str):
        if value == "white":
            return False, (1.0,) * 3, (1.0,) * 3, (1.0,) * 3
        if value == "sky":
            return True, SKY["ground"], SKY["horizon"], SKY["zenith"]
        raise ValueError(f"environment: expected 'white', 'sky', an rgb constant or (ground_rgb, sky_rgb), "
                         f"got {value!r}")
    big = 1e6
    if isinstance(value, (tuple, list)) and len(value) == 2 and all(np.ndim(v) == 1 for v in value):
        ground, sky = (_rgb("environment", v, 0.0, big) for v in value)
        return False, ground, sky, sky
    c = _rgb("environment", value, 0.0, big)
    return False, c, c, c


def path_trace(sdf: SDF, camera: Camera, width: int, height: int, *, frames: int = 16,
               samples_per_frame: int = 1, max_depth: int = 8, material: str = "diffuse",
               albedo=(0.8, 0.8, 0.8), ior: float = 1.5, absorption=(0.0, 0.0, 0.0),
               russian_roulette: bool = True, environment="sky", seed: int = 0, max_steps: int = 512,
               epsilon: float | None = None, gradient_h: float | None = None, bounds=None,
               check=None, on_frame=None) -> PathTraceResult:
    """Path-trace `sdf` seen by `camera` into a ``height x width`` image (module docstring).

    Parameters
    ----------
    sdf : SDF; camera : Camera; width, height : int, pixels (1..16384)
    frames : int in 1..1_000_000, frames averaged
    samples_per_frame : int in 1..4096, paths per pixel and frame
    max_depth : int in 1..100_000, the most scattering events of a path
    material : "diffuse" or "dielectric"
    albedo : rgb in [0, 1], the diffuse reflectance
    ior : float > 0, the dielectric's refractive index (the outside is 1)
    absorption : rgb >= 0, per mm, Beer-Lambert coefficient inside the dielectric
    russian_roulette : bool
    environment : "white", "sky", an rgb constant >= 0 or (ground_rgb, sky_rgb)
    seed : int in 0..2**32 - 1
    max_steps : int in 1..1_000_000, evaluations per traced segment
    epsilon : float > 0, mm, hit tolerance on f / L; default 1e-5 x the bounds' diagonal
    gradient_h : float > 0, mm, normals' central-difference step; default 1e-4 x diagonal
    bounds : None (the sdf's `box()`) or ((x0, y0, z0), (x1, y1, z1)) mm, widened by
        epsilon / 2: the medium must lie inside (outside, the path has escaped)
    check : callable or None, called before each frame (may raise to cancel)
    on_frame : callable or None, ``on_frame(k, radiance)`` after frame k (1-based) with the
        mean so far ((h, w, 3) float32, read-only)

    Returns
    -------
    PathTraceResult

    Raises
    ------
    ValueError
        For any parameter outside its range, or no bounds (an sdf without a box and
        ``bounds=None``).
    engine.gpu.context.GpuUnavailable
        If no OpenGL 4.3 context can be created.
    """
    if not isinstance(sdf, SDF):
        raise ValueError(f"sdf: expected an engine.implicit SDF, got {type(sdf).__name__}")
    if not isinstance(camera, Camera):
        raise ValueError(f"camera: expected an engine.gpu.camera.Camera, got {type(camera).__name__}")
    w, h = _count("width", width, 1, 16384), _count("height", height, 1, 16384)
    n_frames = _count("frames", frames, 1, 1_000_000)
    spp = _count("samples_per_frame", samples_per_frame, 1, 4096)
    depth_cap = _count("max_depth", max_depth, 1, 100_000)
    limit = _count("max_steps", max_steps, 1, 1_000_000)
    seed = _count("seed", seed, 0, 2 ** 32 - 1)
    if material not in MATERIALS:
        raise ValueError(f"material: expected one of {MATERIALS}, got {material!r}")
    albedo = _rgb("albedo", albedo, 0.0, 1.0)
    sigma = _rgb("absorption", absorption, 0.0, 1e30)
    ior = _real("ior", ior, lambda v: 0.0 < v <= 100.0, "a refractive index in (0, 100]")
    if not isinstance(russian_roulette, (bool, np.bool_)):
        raise ValueError(f"russian_roulette: expected a bool, got {russian_roulette!r}")
    gradient, ground, sky, zenith = _environment(environment)
    for name, fn in (("check", check), ("on_frame", on_frame)):
        if fn is not None and not callable(fn):
            raise ValueError(f"{name}: expected a callable or None, got {type(fn).__name__}")
    box = _box(bounds, sdf)
    if box is None:
        raise ValueError("bounds: the sdf has no box (it fills space); give bounds "
                         "((x0, y0, z0), (x1, y1, z1)) in mm around the medium")
    size = max(float(np.linalg.norm(box[1] - box[0])), 1e-9)
    eps = _length("epsilon", epsilon, 1e-5 * size)
    dh = _length("gradient_h", gradient_h, 1e-4 * size)
    box = (box[0] - 0.5 * eps, box[1] + 0.5 * eps)

    module = GlslModule()
    entry = sdf.glsl_distance(module)
    source = _SOURCE.format(material=MATERIALS.index(material), sky=int(gradient), group=GROUP,
                            camera=CAMERA_GLSL, library=module.source(), entry=entry, clip=CLIP_GLSL,
                            march=MARCH_GLSL, gradient=GRADIENT_GLSL)
    uniforms = {**camera.glsl_uniforms(w, h), "u_lo": tuple(box[0]), "u_hi": tuple(box[1]), "u_eps": eps,
                "u_h": dh, "u_max_steps": limit, "u_max_depth": depth_cap, "u_spp": spp, "u_seed": seed,
                "u_rr": int(bool(russian_roulette)), "u_albedo": albedo, "u_ior": ior, "u_sigma": sigma,
                "u_env_ground": ground, "u_env_sky": sky, "u_env_zenith": zenith}
    acc = np.zeros((h, w, 4), np.float64)
    aux = np.zeros((h, w, 2), np.float64)
    frame_ms = []
    with gpu_session() as ctx:
        owned = []
        try:
            prog = compute_program(ctx, source)
            bind_textures(ctx, prog, module.textures, owned)
            for name, value in uniforms.items():
                if name in prog:
                    prog[name].value = value
            images = [ctx.texture((w, h), 4, dtype="f4"), ctx.texture((w, h), 4, dtype="f4")]
            owned.extend(images)
            for unit, img in enumerate(images):
                img.bind_to_image(unit, read=False, write=True)
            for k in range(n_frames):
                if check is not None:
                    check()
                prog["u_frame"].value = k
                seconds = 0.0
                for y0 in range(0, h, TILE):
                    for x0 in range(0, w, TILE):
                        prog["u_offset"].value = (x0, y0)
                        gx, gy = -(-min(TILE, w - x0) // GROUP), -(-min(TILE, h - y0) // GROUP)
                        ctx.finish()
                        t0 = time.perf_counter()
                        prog.run(gx, gy)
                        ctx.finish()
                        seconds += time.perf_counter() - t0
                frame_ms.append(1e3 * seconds)
                ctx.memory_barrier()
                acc += np.frombuffer(images[0].read(), np.float32).reshape(h, w, 4)
                aux += np.frombuffer(images[1].read(), np.float32).reshape(h, w, 4)[..., :2]
                if on_frame is not None:
                    so_far = (acc[..., :3] / (k + 1)).astype(np.float32)
                    so_far.setflags(write=False)
                    on_frame(k + 1, so_far)
        finally:
            for obj in reversed(owned):
                obj.release()
    mean = acc / n_frames
    radiance = mean[..., :3].astype(np.float32)
    depth = mean[..., 3].astype(np.float32)
    rgba = tonemap(radiance)
    for a in (radiance, depth, rgba):
        a.setflags(write=False)
    return PathTraceResult(radiance=radiance, rgba=rgba, frames=n_frames, samples=n_frames * spp,
                           depth=depth, mean_depth=float(mean[..., 3].mean()),
                           truncated=float(aux[..., 1].mean() / n_frames),
                           unfinished=float(aux[..., 0].mean() / n_frames), frame_ms=tuple(frame_ms),
                           epsilon=eps, gradient_h=dh, bounds=box)


@dataclass(frozen=True, eq=False)
class DepthStudy:
    """`depth_study`'s table, one entry per cap (arrays (k,), read-only).

    depths : int64, the `max_depth` values; brightness : float64, mean radiance;
    mean_depth : float64, scattering events per path; truncated : float64, share of
    the paths stopped by the cap; frame_ms : float64, the median GPU time of the frames
    (ms; the first frame of a new shader includes the driver's compile)
    """

    depths: np.ndarray
    brightness: np.ndarray
    mean_depth: np.ndarray
    truncated: np.ndarray
    frame_ms: np.ndarray


def depth_study(sdf: SDF, camera: Camera, depths=(1, 2, 4, 8, 16, 32), *, width: int = 32,
                height: int = 32, frames: int = 4, check=None, **options) -> DepthStudy:
    """The mean image brightness as the trace depth cap rises (paper 004, Figs. 11-12).

    Renders `sdf` with `path_trace` once per value of `depths` (each an int >= 1,
    strictly increasing), with the same seed, so the paths share their random numbers
    up to each cap and the brightness does not fall from one cap to the next.

    Parameters
    ----------
    depths : sequence of int, the `max_depth` values
    width, height, frames : as `path_trace` (small defaults)
    check : callable or None, called before each frame of each render
    **options : any other `path_trace` keyword (material, albedo, ior, absorption,
        russian_roulette, environment, seed, samples_per_frame, ...)

    Returns
    -------
    DepthStudy

    Raises
    ------
    ValueError
        If `depths` is empty, not strictly increasing integers >= 1, or `options` holds
        ``max_depth``, ``on_frame`` or a bad `path_trace` parameter.
    """
    ds = list(depths) if isinstance(depths, (tuple, list, np.ndarray)) else None
    if not ds or any(isinstance(d, bool) or not isinstance(d, (int, np.integer)) or d < 1 for d in ds) \
            or any(b <= a for a, b in zip(ds, ds[1:])):
        raise ValueError(f"depths: expected strictly increasing integers >= 1, got {depths!r}")
    for key in ("max_depth", "on_frame"):
        if key in options:
            raise ValueError(f"{key}: set by depth_study, not an option")
    rows = []
    for d in ds:
        r = path_trace(sdf, camera, width, height, frames=frames, max_depth=int(d), check=check, **options)
        rows.append((r.brightness, r.mean_depth, r.truncated, float(np.median(r.frame_ms))))
    cols = [np.asarray(ds, np.int64)] + [np.array(c, np.float64) for c in zip(*rows)]
    for c in cols:
        c.setflags(write=False)
    return DepthStudy(*cols)
