"""Sphere tracing of any SDF tree on the headless GPU context (paper 004, sections 4-5).

Each pixel's ray (`engine.gpu.camera`) is clipped to a box and marched by a
compute shader built from the tree's GLSL (`SDF.glsl_distance`, which returns
``D = f / L``, L the tree's Lipschitz bound): since ``|D(p)|`` never exceeds
the distance from p to the surface, a step of length D cannot cross it
(Hart 1996).  Three step rules (``step=``):

``"fixed"``
    ``t += D(p)``: the plain Lipschitz-corrected sphere tracing.
``"bijection"``
    over-relaxed steps ``s = omega D`` (``omega`` in (1, 2)); a step is
    accepted when the two unbounding spheres overlap, ``D(p) + D(p + s) >= s``
    with ``D(p + s) >= 0``, and otherwise retried from the same point with
    the multiplier's excess over 1 halved (a bisection of the multiplier
    towards the always-safe 1; it does not grow back along that ray).  The
    paper names the mode without a formula; this is the standard form
    (Keinert et al. 2014) with the back-off the prose describes.
``"adaptive"``
    the paper's adaptive step: every `adaptive_every` accepted steps the
    local gradient magnitude ``g = |grad D|`` is re-estimated by forward
    differences from the point's D (3 evaluations, step `gradient_h`) and
    the step is ``s = D / g``, with g
    clamped to ``[1 / stretch, 1]`` so ``D <= s <= stretch D``.  A local g
    below the global bound gives longer steps where the medium is coarse
    (section 5).  Such a step may overshoot: a step that ends inside
    (``D(p + s) < 0``, a sign change) is retried from the same point with g
    doubled, i.e. the step halved (a bisection back towards the last
    outside point), down to the safe ``s = D``.  The paper's sparse random
    gradient points (supplementary 11, a polynomial condition) are not
    implemented: the estimate is every N steps.

No missed hits: a ray that ends without a hit under the bijection or the
adaptive rule (it left the box, passed `far` or used `max_steps`) is traced
again from its entry point with the fixed rule, the same march as
``"fixed"``, so no rule misses a hit of the fixed rule.  (An adaptive step
checks only for a sign change and can jump over a piece of surface thinner
than ``s - D``, near a silhouette or where another part of a Boolean takes
over; a bijection step's overlap test can pass by float32 rounding on a
grazing ray.)  The re-trace costs a full fixed march on every ray that truly
misses the surface inside the box; `TraceResult.retraced` marks those rays
and their `steps` include both marches (so up to ``2 max_steps``).  Not
covered: an adaptive ray that skips a sliver and hits a surface behind it
(a hit at a greater depth; on the benchmark none at the defaults, 1 pixel of
164,694 with a gradient every step),
and a ray that grazes the surface within epsilon between two fixed samples
(then another rule may report a hit the fixed rule does not; not seen on the
tests' scenes).  tests/bench/bench_sphere_trace.py counts both.  The
defaults ``adaptive_every = 100, stretch = 3`` were the fastest settings
without either kind of difference there: 0.60 x the fixed rule's steps
(re-trace included), 0.84-0.92 x its frame time on llvmpipe.

Hits, outputs and precision
---------------------------
A ray hits where ``D < epsilon`` (an absolute length in mm, tested before
each step; a ray that enters the box inside the solid, D < 0, hits at the
entry point).  Default ``epsilon = 1e-5 x`` the scene size (the diagonal of
the bounds, or `far` without bounds).  The normal at a hit is the central
difference gradient of D (step ``gradient_h``, default ``1e-4 x`` scene
size), normalised.  Everything on the GPU is float32: positions carry about
``6e-8 |p|`` of rounding, so `epsilon` should stay above ~``1e-6 |p|``.
A miss is ``t > t_end`` (the box exit, or `far`) or `max_steps` trial
evaluations (then `TraceResult.unfinished` is set).

Shader layout (GL 4.3 compute, 8 x 8 work groups, one invocation per pixel):
image 0 rgba32f (t, steps, evaluations, flags: 1 hit, 2 unfinished),
image 1 rgba32f (normal, 1 if re-traced), image 2 rgba8 (the shaded colour); pixel
``(column j, row i)`` with row 0 at the top.  The textures a tree declares
(`GlslModule.textures`) are bound as in `engine.gpu.sdf_points`: R32F,
linear filtering, repeat wrapping, units 0, 1, ... in declaration order.
The frame is drawn in tiles of `TILE` x `TILE` pixels with `check()`
called between them; `frame_ms` sums the tiles' dispatches, each timed
between two ``glFinish``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from engine.gpu._sphere_trace_glsl import CLIP_GLSL, GRADIENT_GLSL, MARCH_GLSL, TRACE_TEMPLATE
from engine.gpu.camera import CAMERA_GLSL, Camera
from engine.gpu.context import gpu_session
from engine.gpu.shader_cache import bind_textures, compute_program
from engine.implicit.values import SDF, GlslModule

__all__ = ["render", "TraceResult", "trace_source", "STEP_MODES", "SHADINGS", "TILE"]

STEP_MODES = ("fixed", "bijection", "adaptive")
SHADINGS = ("normals", "lambert", "depth")
TILE = 256                      # pixels per tile side (one dispatch, then check())
GROUP = 8                       # work group side
AMBIENT = 0.1                   # Lambert: ambient share; the light is fixed in the camera frame
_LIGHT_CAMERA = (-0.45, 0.6, -0.66)   # (right, up, forward) components of the light direction

@dataclass(frozen=True, eq=False)
class TraceResult:
    """One traced frame; arrays are read-only, indexed ``[row from the top, column]``.

    Attributes
    ----------
    rgba : (h, w, 4) uint8, the shaded image (alpha 0 and black where missed)
    depth : (h, w) float32, mm along the unit ray from the eye; inf on a miss
    hit : (h, w) bool
    steps : (h, w) int32, trial evaluations of the SDF by the march (accepted
        and rejected steps, and the fixed re-trace's; 0 where the ray misses
        the bounds)
    evaluations : (h, w) int32, `steps` plus the adaptive gradient estimates
        (3 each); the hit normal's 6 are not counted
    normal : (h, w, 3) float32, unit outward normal at a hit, 0 elsewhere
    unfinished : (h, w) bool, rays stopped by `max_steps` without a hit (in the
        re-trace, for the bijection and adaptive rules)
    retraced : (h, w) bool, rays traced again with the fixed rule after the
        bijection or adaptive rule found no hit (never set for "fixed")
    frame_ms : float, GPU time of the dispatches (ms)
    epsilon, gradient_h, far : float, mm, the values used
    bounds : ((3,), (3,)) float64 mm, the box the rays were clipped to
        (already widened by epsilon / 2), or None
    """

    rgba: np.ndarray
    depth: np.ndarray
    hit: np.ndarray
    steps: np.ndarray
    evaluations: np.ndarray
    normal: np.ndarray
    unfinished: np.ndarray
    retraced: np.ndarray
    frame_ms: float
    epsilon: float
    gradient_h: float
    far: float
    bounds: tuple | None

    @property
    def mean_steps(self) -> float:
        """Mean `steps` over the rays that met the bounds (0 if none did)."""
        marched = self.steps[self.steps > 0]
        return float(marched.mean()) if marched.size else 0.0

    @property
    def retraced_count(self) -> int:
        """The number of re-traced rays."""
        return int(np.count_nonzero(self.retraced))

    @property
    def max_steps(self) -> int:
        """The largest `steps` of any ray."""
        return int(self.steps.max()) if self.steps.size else 0


def trace_source(module: GlslModule, entry: str, *, step: str, shading: str, clip: bool) -> str:
    """The compute shader marching ``float entry(vec3 p)`` (returning f / L) of `module`."""
    return TRACE_TEMPLATE.format(mode=STEP_MODES.index(step), shading=SHADINGS.index(shading),
                                 clip=int(bool(clip)), group=GROUP, camera=CAMERA_GLSL,
                                 library=module.source(), entry=entry, ambient=repr(AMBIENT),
                                 clip_glsl=CLIP_GLSL, march_glsl=MARCH_GLSL, gradient_glsl=GRADIENT_GLSL)


def _real(name: str, value, ok, expected: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.number)) \
            or not (math.isfinite(value) and ok(value)):
        raise ValueError(f"{name}: expected {expected}, got {value!r}")
    return float(value)


def _length(name: str, value, default: float) -> float:
    if value is None:
        return default
    return _real(name, value, lambda v: v > 0, "a positive finite length in mm")


def _count(name: str, value, lo: int, hi: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not lo <= value <= hi:
        raise ValueError(f"{name}: expected an integer in {lo}..{hi}, got {value!r}")
    return int(value)


def _box(bounds, sdf: SDF):
    box = sdf.box() if bounds is None else bounds
    if box is None:
        return None
    try:
        lo, hi = (np.array(b, dtype=np.float64).reshape(3) for b in box)
    except (TypeError, ValueError):
        raise ValueError(f"bounds: expected ((x0, y0, z0), (x1, y1, z1)) in mm, got {box!r}") from None
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) and np.all(hi >= lo)):
        raise ValueError(f"bounds: expected finite corners with lo <= hi, got {box!r}")
    return lo, hi


def _depth_range(eye: np.ndarray, box, far: float) -> tuple[float, float]:
    if box is None:
        return 0.0, far
    lo, hi = box
    near = float(np.linalg.norm(eye - np.clip(eye, lo, hi)))
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    return near, float(np.linalg.norm(corners - eye, axis=1).max())


def render(sdf: SDF, camera: Camera, width: int, height: int, *, step: str = "fixed",
           adaptive_every: int = 100, stretch: float = 3.0, omega: float = 1.6, max_steps: int = 512,
           epsilon: float | None = None, gradient_h: float | None = None, far: float | None = None,
           bounds=None, shading: str = "normals", check=None) -> TraceResult:
    """Sphere-trace `sdf` as seen by `camera` into a ``height x width`` frame.

    Parameters
    ----------
    sdf : SDF, any tree of `engine.implicit` values
    camera : Camera
    width, height : int, pixels (1..16384)
    step : "fixed", "bijection" or "adaptive" (module docstring)
    adaptive_every : int >= 1, accepted steps between gradient estimates ("adaptive")
    stretch : float in [1, 64], the longest adaptive step in units of D ("adaptive")
    omega : float in (1, 2), the over-relaxation multiplier ("bijection")
    max_steps : int in 1..1_000_000, trial evaluations per ray
    epsilon : float > 0, mm, hit tolerance on f / L; default 1e-5 x scene size
    gradient_h : float > 0, mm, central-difference step (normals, adaptive
        gradients); default 1e-4 x scene size
    far : float > 0, mm, the longest ray; default the eye's distance to the
        farthest corner of the bounds, or 1000 mm without bounds
    bounds : None (the sdf's `box()`; unbounded if that is None) or
        ((x0, y0, z0), (x1, y1, z1)) mm: rays are clipped to this box,
        widened by epsilon / 2 (so a face that is the surface is a hit on entry)
    shading : "normals" (rgb = (n + 1) / 2), "lambert" (a light fixed in the
        camera frame, from above left behind the eye; ambient `AMBIENT`) or
        "depth" (white at the bounds' nearest point, black at the farthest)
    check : callable or None, called between tiles (may raise to cancel)

    Returns
    -------
    TraceResult

    Raises
    ------
    ValueError
        For any parameter outside its range.
    engine.gpu.context.GpuUnavailable
        If no OpenGL 4.3 context can be created.
    """
    if not isinstance(sdf, SDF):
        raise ValueError(f"sdf: expected an engine.implicit SDF, got {type(sdf).__name__}")
    if not isinstance(camera, Camera):
        raise ValueError(f"camera: expected an engine.gpu.camera.Camera, got {type(camera).__name__}")
    w = _count("width", width, 1, 16384)
    h = _count("height", height, 1, 16384)
    if step not in STEP_MODES:
        raise ValueError(f"step: expected one of {STEP_MODES}, got {step!r}")
    if shading not in SHADINGS:
        raise ValueError(f"shading: expected one of {SHADINGS}, got {shading!r}")
    every = _count("adaptive_every", adaptive_every, 1, 1 << 30)
    limit = _count("max_steps", max_steps, 1, 1_000_000)
    omega = _real("omega", omega, lambda v: 1.0 < v < 2.0, "a multiplier in (1, 2)")
    stretch = _real("stretch", stretch, lambda v: 1.0 <= v <= 64.0, "a step multiplier in [1, 64]")
    if check is not None and not callable(check):
        raise ValueError(f"check: expected a callable or None, got {type(check).__name__}")
    box = _box(bounds, sdf)
    if box is None:
        far = _length("far", far, 1000.0)
        size = far
    else:
        size = max(float(np.linalg.norm(box[1] - box[0])), 1e-9)
        far = _length("far", far, _depth_range(camera.eye, box, 0.0)[1] * (1.0 + 1e-6) + size * 1e-6)
    eps = _length("epsilon", epsilon, 1e-5 * size)
    dh = _length("gradient_h", gradient_h, 1e-4 * size)
    if box is not None:
        box = (box[0] - 0.5 * eps, box[1] + 0.5 * eps)
        for b in box:
            b.setflags(write=False)

    module = GlslModule()
    entry = sdf.glsl_distance(module)
    source = trace_source(module, entry, step=step, shading=shading, clip=box is not None)
    forward, right, up = camera.basis()
    light = _LIGHT_CAMERA[0] * right + _LIGHT_CAMERA[1] * up + _LIGHT_CAMERA[2] * forward
    uniforms = {**camera.glsl_uniforms(w, h), "u_far": far, "u_eps": eps, "u_h": dh,
                "u_omega": omega, "u_stretch": stretch, "u_max_steps": limit,
                "u_every": every, "u_light": tuple(light / np.linalg.norm(light)),
                "u_depth_range": _depth_range(camera.eye, box, far)}
    if box is not None:
        uniforms.update(u_lo=tuple(box[0]), u_hi=tuple(box[1]))
    frame_s = 0.0
    with gpu_session() as ctx:
        owned = []
        try:
            prog = compute_program(ctx, source)
            bind_textures(ctx, prog, module.textures, owned)
            for name, value in uniforms.items():
                if name in prog:
                    prog[name].value = value
            images = [ctx.texture((w, h), 4, dtype="f4"), ctx.texture((w, h), 4, dtype="f4"),
                      ctx.texture((w, h), 4, dtype="f1")]
            owned.extend(images)
            for unit, img in enumerate(images):
                img.bind_to_image(unit, read=False, write=True)
            for y0 in range(0, h, TILE):
                for x0 in range(0, w, TILE):
                    if check is not None:
                        check()
                    prog["u_offset"].value = (x0, y0)
                    gx, gy = -(-min(TILE, w - x0) // GROUP), -(-min(TILE, h - y0) // GROUP)
                    ctx.finish()
                    t0 = time.perf_counter()
                    prog.run(gx, gy)
                    ctx.finish()
                    frame_s += time.perf_counter() - t0
            ctx.memory_barrier()
            trace = np.frombuffer(images[0].read(), np.float32).reshape(h, w, 4)
            normal4 = np.frombuffer(images[1].read(), np.float32).reshape(h, w, 4)
            normal, retraced = normal4[..., :3].copy(), normal4[..., 3] == 1.0
            rgba = np.frombuffer(images[2].read(), np.uint8).reshape(h, w, 4).copy()
        finally:
            for obj in reversed(owned):
                obj.release()
    flags = trace[..., 3]
    hit = flags == 1.0
    out = dict(rgba=rgba, depth=np.where(hit, trace[..., 0], np.float32(np.inf)).astype(np.float32),
               hit=hit, steps=trace[..., 1].astype(np.int32), evaluations=trace[..., 2].astype(np.int32),
               normal=normal, unfinished=flags == 2.0, retraced=retraced)
    for a in out.values():
        a.setflags(write=False)
    return TraceResult(**out, frame_ms=1e3 * frame_s, epsilon=eps, gradient_h=dh, far=far, bounds=box)
