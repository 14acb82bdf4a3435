"""Trace-depth study of the path tracer (paper 004, section 7.2, Figs. 11-12) on llvmpipe.

The scene is a particulate medium: a `Suspension` of dielectric spheres
(refractive index 1.5, a faint absorption) cut by a 3 mm cube
(`Intersection` with a box primitive), under the "sky" environment, at three
number densities (the share of grid cells holding a particle).  For each
density `depth_study` renders the frame at every maximum trace depth of
``--depths``; the table gives the mean image brightness, the mean number of
scattering events per path, the share of paths the cap cut, and the GPU time
per frame (the median over the frames; the first frame of a new shader also
pays the driver's compile).  Brightness rises with the cap (paths cut early
are dark) and settles once few paths reach it (Fig. 11); the time per frame
grows with the cap, and levels off with it (Fig. 12).

A PNG with both plots goes to the path given on the command line.

Run as ``python tests/bench/bench_path_trace.py [OUT.png] [--size 64] [--frames 8]
[--depths 1,2,4,8,16,32,64,128,256]``.  Prints the table; asserts nothing.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from engine.gpu.camera import Camera  # noqa: E402
from engine.gpu.context import gpu_context  # noqa: E402
from engine.gpu.path_trace import depth_study  # noqa: E402
from engine.implicit.combine import Intersection  # noqa: E402
from engine.implicit.particles import SizeDistribution, Suspension  # noqa: E402
from engine.implicit.shapes import Primitive  # noqa: E402

DENSITIES = (0.25, 0.5, 1.0)
CAMERA = Camera((3.6, -4.6, 3.2), (0.0, 0.0, 0.0), fov_deg=34.0)
OPTIONS = dict(material="dielectric", ior=1.5, absorption=(0.05, 0.08, 0.12), environment="sky",
               russian_roulette=True, seed=11)


def scene(density: float):
    cloud = Suspension(cell=0.25, shape="sphere", size=SizeDistribution("uniform", 0.07, 0.12), jitter=1.0,
                       density=density, seed=4)
    return Intersection((cloud, Primitive("box", (1.5, 1.5, 1.5))))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default="/tmp/depth_study.png")
    ap.add_argument("--size", type=int, default=64)
    ap.add_argument("--frames", type=int, default=8)
    ap.add_argument("--depths", default="1,2,4,8,16,32,64,128,256")
    args = ap.parse_args()
    depths = tuple(int(d) for d in args.depths.split(","))
    ctx = gpu_context()
    print(f"GL renderer: {ctx.info['GL_RENDERER']}; {args.size} x {args.size}, {args.frames} frames of 1 path "
          f"per pixel; dielectric spheres (cell 0.25 mm, radius 0.07-0.12 mm) in a 3 mm cube, sky")
    studies = {}
    for density in DENSITIES:
        st = depth_study(scene(density), CAMERA, depths, width=args.size, height=args.size,
                         frames=args.frames, **OPTIONS)
        studies[density] = st
        print(f"\nnumber density {density}")
        print(f"{'max depth':>9s} {'brightness':>10s} {'events':>7s} {'cut %':>6s} {'ms/frame':>9s}")
        for d, b, m, c, ms in zip(st.depths, st.brightness, st.mean_depth, st.truncated, st.frame_ms):
            print(f"{d:9d} {b:10.4f} {m:7.2f} {100 * c:6.2f} {ms:9.1f}")

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 3.6))
    for density, st in studies.items():
        ax1.plot(st.depths, st.brightness, "o-", label=f"density {density}")
        ax2.plot(st.depths, st.frame_ms, "o-", label=f"density {density}")
    for ax, ylabel in ((ax1, "mean brightness"), (ax2, "GPU ms per frame")):
        ax.set_xscale("log", base=2)
        ax.set_xlabel("maximum trace depth")
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    ax1.set_title("brightness vs trace depth (cf. Fig. 11)")
    ax2.set_title("render time vs trace depth (cf. Fig. 12)")
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    print(f"\nplot written to {args.out}")
    return np.array([st.brightness for st in studies.values()])


if __name__ == "__main__":
    main()
