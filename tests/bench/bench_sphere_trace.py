"""Sphere tracing benchmark: the paper's Table 2 (fixed, bijection, adaptive steps) on llvmpipe.

The scene is a multiscale periodic medium in a box: a gyroid whose cell size
varies 4x across the box (each coordinate warped by a smooth monotone map),
so its global Lipschitz bound is set by the finest cells and is pessimistic
in the coarse ones, the case the paper's adaptive step is for (section 5,
Fig. 7).  For each step rule the frame is drawn at ``--size`` (default 512 x
512) with Lambert shading; the table gives the best GPU time of
``--repeats`` frames (after one warm-up; the rules take turns), the mean march steps and SDF
evaluations per ray (evaluations add the adaptive gradient estimates; both
include the fixed re-trace of rays the rule found no hit on), the pixels
that the fixed rule hits and this rule misses ("missed", 0 by construction),
the pixels this rule hits and the fixed rule does not ("extra"), the pixels
both hit where this rule's depth is more than 0.1 % greater ("deeper": a
skipped sliver), the re-traced rays, and the time ratio to the fixed rule
(re-trace included), next to the paper's RT (ms, OptiX on an RTX 4090).
The adaptive rows use stretch 3 (the default) unless the label says otherwise.

Then the numpy float64 reference march (`engine.gpu._sphere_trace_reference`)
against the GPU fixed rule on a ``--ref-size`` image, with the ratio.

Run as ``python tests/bench/bench_sphere_trace.py [--size 512] [--repeats 7] [--ref-size 128]``.
Prints the tables; asserts nothing.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from engine.gpu._sphere_trace_reference import clip_rays, march_fixed  # noqa: E402
from engine.gpu.camera import Camera  # noqa: E402
from engine.gpu.context import gpu_context  # noqa: E402
from engine.gpu.sphere_trace import render  # noqa: E402
from engine.implicit.combine import Intersection  # noqa: E402
from engine.implicit.values import SDF, as_points, glsl_float  # noqa: E402

# Table 2 of the paper: step length -> RT (ms)
PAPER = {"fixed": 9.3, "bijection": 9.0, "adaptive N=1": 44.1, "adaptive N=10": 11.5,
         "adaptive N=100": 8.1, "adaptive N=500": 8.1}
ROWS = [  # (label, step, N, stretch)
    ("fixed", "fixed", 1, 3.0),
    ("bijection", "bijection", 1, 3.0),
    ("adaptive N=1", "adaptive", 1, 3.0),
    ("adaptive N=10", "adaptive", 10, 3.0),
    ("adaptive N=100", "adaptive", 100, 3.0),
    ("adaptive N=500", "adaptive", 500, 3.0),
    ("adaptive N=100 stretch 2", "adaptive", 100, 2.0),
    ("adaptive N=100 stretch 4", "adaptive", 100, 4.0),
]


@dataclass(frozen=True, eq=False)
class GradedGyroid(SDF):
    """Gyroid of the warped coordinates phi(x_i), phi(s) = k (s + b w log cosh(s / w)):
    phi' = k (1 + b tanh(s / w)) runs from k (1 - b) to k (1 + b), so the cells shrink
    along the diagonal and |grad f| <= sqrt(3) k (1 + b) (each term's partial is at most 1
    in the warped coordinates)."""

    k: float
    b: float
    w: float
    level: float

    @property
    def lipschitz(self):
        return math.sqrt(3.0) * self.k * (1.0 + self.b)

    def field(self, points):
        s = as_points(points) / self.w
        a = np.abs(s)
        q = self.k * self.w * (s + self.b * (a + np.log1p(np.exp(-2 * a)) - math.log(2.0)))
        x, y, z = q.T
        return np.sin(x) * np.cos(y) + np.sin(y) * np.cos(z) + np.sin(z) * np.cos(x) - self.level

    def glsl(self, module):
        k, b, w, lv = (glsl_float(v) for v in (self.k, self.b, self.w, self.level))
        return module.function(self, lambda n: (
            f"float {n}(vec3 p) {{ vec3 s = p / {w}; vec3 a = abs(s);\n"
            f"    vec3 q = {k} * {w} * (s + {b} * (a + log(1.0 + exp(-2.0 * a)) - 0.6931471805599453));\n"
            f"    return dot(sin(q), cos(q.yzx)) - {lv}; }}"))


@dataclass(frozen=True, eq=False)
class Cube(SDF):
    half: float

    def field(self, points):
        q = np.abs(as_points(points)) - self.half
        return np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0)

    def glsl(self, module):
        h = glsl_float(self.half)
        return module.function(self, lambda n: (
            f"float {n}(vec3 p) {{ vec3 q = abs(p) - {h};\n"
            f"    return length(max(q, 0.0)) + min(max(q.x, max(q.y, q.z)), 0.0); }}"))

    def box(self):
        return (-self.half,) * 3, (self.half,) * 3


SCENE = Intersection((GradedGyroid(k=2 * math.pi * 1.6, b=0.6, w=0.8, level=0.2), Cube(1.5)))
CAMERA = Camera((4.2, -5.0, 3.6), (0.0, 0.0, 0.0), fov_deg=36.0)


def best_frames(size, repeats, settings):
    """The fastest of `repeats` frames per setting; the settings take turns, so a burst of
    load from other processes on the shared cores does not fall on one row only."""
    best = [render(SCENE, CAMERA, size, size, **kw) for kw in settings]     # compile + warm up
    for _ in range(repeats):
        for i, kw in enumerate(settings):
            r = render(SCENE, CAMERA, size, size, **kw)
            if r.frame_ms < best[i].frame_ms:
                best[i] = r
    return best


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--ref-size", type=int, default=128)
    args = ap.parse_args()
    ctx = gpu_context()
    print(f"GL renderer: {ctx.info['GL_RENDERER']}; scene: graded gyroid (cells 4x finer towards +xyz) "
          f"in a cube, {args.size} x {args.size}, Lambert")
    print(f"{'step length':26s} {'ms':>8s} {'fps':>6s} {'steps':>6s} {'evals':>6s} {'max':>5s} "
          f"{'missed':>6s} {'extra':>6s} {'deeper':>6s} {'retraced':>8s} {'/fixed':>7s} {'paper ms':>9s}")
    settings = [dict(step=step, adaptive_every=every, stretch=stretch, shading="lambert", max_steps=2000)
                for _, step, every, stretch in ROWS]
    frames = best_frames(args.size, args.repeats, settings)
    fixed = frames[0]
    for (label, *_), r in zip(ROWS, frames):
        missed = int(np.count_nonzero(fixed.hit & ~r.hit))
        extra = int(np.count_nonzero(r.hit & ~fixed.hit))
        both = r.hit & fixed.hit
        deeper = int(np.count_nonzero(r.depth[both] > fixed.depth[both] * (1 + 1e-3)))
        evals = float(r.evaluations[r.steps > 0].mean())
        paper = PAPER.get(label)
        print(f"{label:26s} {r.frame_ms:8.1f} {1e3 / r.frame_ms:6.2f} {r.mean_steps:6.2f} {evals:6.2f} "
              f"{r.max_steps:5d} {missed:6d} {extra:6d} {deeper:6d} {r.retraced_count:8d} "
              f"{r.frame_ms / fixed.frame_ms:7.2f} {'' if paper is None else f'{paper:9.1f}'}")
    print(f"hit pixels (fixed): {int(fixed.hit.sum())}; epsilon {fixed.epsilon:.2e} mm")

    n = args.ref_size
    gpu, = best_frames(n, args.repeats, [dict(step="fixed", max_steps=2000)])
    o, d = CAMERA.rays(n, n)
    o, d = o.reshape(-1, 3), d.reshape(-1, 3)
    t0 = time.perf_counter()
    ta, tb = clip_rays(o, d, *gpu.bounds, gpu.far)
    t_ref, hit_ref, _ = march_fixed(SCENE, o, d, ta, tb, epsilon=gpu.epsilon, max_steps=2000)
    ref_ms = 1e3 * (time.perf_counter() - t0)
    hit = gpu.hit.reshape(-1)
    both = hit & hit_ref
    rel = np.abs(gpu.depth.reshape(-1)[both] - t_ref[both]) / t_ref[both]
    print(f"\nfixed rule at {n} x {n}: GPU {gpu.frame_ms:.1f} ms, numpy reference {ref_ms:.0f} ms, "
          f"ratio reference / GPU {ref_ms / gpu.frame_ms:.1f}")
    print(f"  hit masks differ on {int(np.count_nonzero(hit != hit_ref))} pixels; "
          f"depth: median rel. difference {np.median(rel):.1e}, max {rel.max():.1e}")


if __name__ == "__main__":
    main()
