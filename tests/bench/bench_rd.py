"""Reaction/diffusion growth benchmark: the fused Gray-Scott step against the
plain numpy reference, and full growths of a cantilever-like domain.

Run: .venv/bin/python tests/bench/bench_rd.py [--skip-big] [--gamma 2.5] [--seeds 1]

1. Cell updates per second of one explicit step (eq. 13) on 2D and 3D
   grids with random orientations, the absorbing term and an infill map:
   ``Stepper.run`` (numba, two steps per sweep in 2D) with one thread and
   with all, against ``reference_update`` (plain numpy, the arithmetic only,
   no validation) in the same run; best of three.
2. ``grow`` on a 640 x 320 half-ellipse clamped at x = 0 with a smoothly
   varying stress-like orientation (45 degrees on the neutral axis, the x
   axis at the top and bottom fibres), both principal directions, one seed
   at the centroid (paper 6.1), until G < 1e-7 (eq. 14). Target <= 20 s.
3. The same domain at 1280 x 640, one direction. Target <= 60 s.

Wall times depend on what else runs on the machine: the table prints the
load average. ``grow`` picks one or all threads per chunk by measured
throughput, so a busy machine costs less than a fixed thread count would.
Asserts nothing about time.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import numba  # noqa: E402

from engine.rd.diffusion import diffusion_tensors, rotation_from_angle  # noqa: E402
from engine.rd.gray_scott import RDParams, Stepper, kill_rate, resolve_params  # noqa: E402
from engine.rd.growth import grow  # noqa: E402
from engine.rd.reference import reference_update  # noqa: E402


def cantilever(nx, ny):
    """Half-ellipse clamped at x = 0, stress-like rotation field (see the module docstring)."""
    y, x = np.mgrid[:ny, :nx] + 0.5
    eta = (y - ny / 2) / (ny / 2)
    rho = ((x / nx) ** 2 + eta ** 2 <= 1.0).astype(float)
    theta = np.pi / 4 * (1 - eta ** 2) * (1 - 0.5 * x / nx)
    return rho, rotation_from_angle(theta)


def random_case(shape, seed=0):
    rng = np.random.default_rng(seed)
    d = len(shape)
    q, r = np.linalg.qr(rng.normal(size=shape + (d, d)))
    q = q * np.sign(np.diagonal(r, axis1=-2, axis2=-1))[..., None, :]
    q[..., :, 0] *= np.sign(np.linalg.det(q))[..., None]
    sigma = diffusion_tensors(q, direction=0)
    u = rng.uniform(0.2, 1.0, shape)
    v = rng.uniform(0.0, 0.5, shape)
    inside = rng.random(shape) < 0.8
    gamma_map = rng.random(shape) * 0.3
    return u, v, sigma, inside, gamma_map


def step_rates(shape, steps, reps=3):
    """(fused 1 thread, fused all threads, numpy) cell updates per second."""
    u, v, sigma, inside, gmap = random_case(shape)
    p = resolve_params(sigma, RDParams())
    stepper = Stepper(sigma, inside, gmap, p)
    w = stepper.new_state(u, v)
    stepper.run(w, 2)
    out = []
    saved = numba.get_num_threads()
    for threads in (1, saved):
        numba.set_num_threads(threads)
        best = 0.0
        for _ in range(reps):
            t0 = time.perf_counter()
            stepper.run(w, steps)
            best = max(best, u.size * steps / (time.perf_counter() - t0))
        out.append(best)
    numba.set_num_threads(saved)
    omega, kill = inside.astype(float), kill_rate(gmap, p)
    best = 0.0
    for _ in range(reps):
        t0 = time.perf_counter()
        reference_update(u, v, sigma, omega, kill, p)
        best = max(best, u.size / (time.perf_counter() - t0))
    out.append(best)
    return out


def timed_growth(nx, ny, direction, gamma, seeds):
    rho, rot = cantilever(nx, ny)
    kw = {} if seeds == 1 else {"seeds": seeds, "rng": 0}
    t0 = time.perf_counter()
    res = grow(rho, rot, direction=direction, params=RDParams(gamma=gamma), max_steps=200_000, **kw)
    seconds = time.perf_counter() - t0
    return res, seconds


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--skip-big", action="store_true", help="skip the 1280 x 640 growth")
    ap.add_argument("--gamma", type=float, default=2.5, help="reaction speed (wavelength ~11 cells at 2.5)")
    ap.add_argument("--seeds", type=int, default=1, help="1: one seed at the centroid; n: n random spaced seeds")
    args = ap.parse_args()

    print(f"machine: {platform.machine()}, {os.cpu_count()} cores, numba {numba.__version__}, "
          f"{numba.get_num_threads()} threads, load average {os.getloadavg()[0]:.2f}")
    print()
    print("| step | grid | fused 1 thread M/s | fused all threads M/s | numpy M/s | ratio (best fused / numpy) |")
    print("|---|---|---|---|---|---|")
    for shape, steps in (((320, 640), 200), ((640, 1280), 60), ((96, 96, 96), 20)):
        one, many, ref = step_rates(shape, steps)
        print(f"| {len(shape)}D | {'x'.join(map(str, shape[::-1]))} | {one / 1e6:.0f} | {many / 1e6:.0f} | "
              f"{ref / 1e6:.1f} | {max(one, many) / ref:.0f}x |")
    print()
    print(f"growth: gamma = {args.gamma:g}, dt = default (largest stable x 0.9), eps = 1e-7, "
          f"{'one seed' if args.seeds == 1 else f'{args.seeds} seeds'}")
    print()
    print("| domain | direction | steps | stop | seconds | M cell-updates/s | target |")
    print("|---|---|---|---|---|---|---|")
    total = 0.0
    runs = [(640, 320, 0), (640, 320, 1)] + ([] if args.skip_big else [(1280, 640, 0)])
    for nx, ny, d in runs:
        res, seconds = timed_growth(nx, ny, d, args.gamma, args.seeds)
        rate = res.steps * nx * ny / seconds / 1e6
        if nx == 640:
            total += seconds
        target = "both <= 20 s" if nx == 640 else "<= 60 s"
        print(f"| {nx}x{ny} | {d} | {res.steps} | {res.stop_reason} | {seconds:.1f} | {rate:.0f} | {target} |")
    print(f"| 640x320 | both | | | {total:.1f} | | <= 20 s |")
    print(f"\nload average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
