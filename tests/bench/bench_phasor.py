"""Phasor slice benchmark: the GPU shader vs the CPU references.

Run: .venv/bin/python tests/bench/bench_phasor.py [--size 1024] [--ref-size 128]
     [--brute-size 24] [--reps 3]

Setup (the brief's case): a 50 mm cube, constant fields F = 1 cycle/mm,
D = x, kernels from ``sample_kernels`` (R = c / F = 4.5 mm, 8 per cell, one
cell of margin), random phases.  Times a ``size`` x ``size`` z-slice at
z = 25 mm through ``phasor_slice_gpu`` unfiltered and filtered (s = 2,
attenuation grid of engine.phasor.attenuation), best of ``reps`` after one
warm-up run (shader compile, driver JIT for the image size), and the CPU
references on smaller slices of the same plane scaled per pixel:
``phasor_complex`` (numba, cell walk, one thread) on ``ref-size``^2 and
``phasor_complex_reference`` (plain numpy, every kernel against every
point) on ``brute-size``^2.  Checks that the GPU agrees with the reference
on the reference's pixels, prints a table with the per-pixel ratio.
Asserts nothing about time.  The GPU here is Mesa llvmpipe on the CPU:
wall time depends on how many cores other jobs leave free, so the table
also gives process CPU seconds (all driver threads).
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

from engine.gpu import SlicePlane, gpu_context  # noqa: E402
from engine.phasor.gpu_slice import phasor_slice_gpu  # noqa: E402
from engine.phasor.attenuation import attenuation_grid  # noqa: E402
from engine.phasor.fields import constant_fields  # noqa: E402
from engine.phasor.noise import phasor_complex, phasor_complex_reference  # noqa: E402
from engine.phasor.sampling import sample_kernels  # noqa: E402

CUBE = 50.0
Z = 25.0


def setup():
    fields = constant_fields((0.0, 0.0, 0.0), (CUBE, CUBE, CUBE), (16, 16, 16), direction=(1.0, 0.0, 0.0),
                             frequency=1.0)
    k = sample_kernels(fields, per_cell=8, rng=0)
    rng = np.random.default_rng(0)
    k = k.with_phases(rng.uniform(-np.pi, np.pi, k.n), rng.uniform(-np.pi, np.pi, k.n))
    return fields, k, attenuation_grid(fields, radius=k.radius)


def plane(n):
    """The centre n x n pixels of the z-slice that covers the cube with 1024 x 1024 pixels."""
    half = n * CUBE / 2048
    return SlicePlane.axis_aligned("z", Z, CUBE / 1024, ((CUBE / 2 - half, CUBE / 2 + half),) * 2)


def timed(fn, reps):
    best = (np.inf, np.inf)
    out = None
    for _ in range(reps):
        c0, t0 = os.times(), time.perf_counter()
        out = fn()
        t1, c1 = time.perf_counter(), os.times()
        cpu = (c1.user + c1.system) - (c0.user + c0.system)
        best = min(best, (t1 - t0, cpu))
    return best, out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", type=int, default=1024)
    ap.add_argument("--ref-size", type=int, default=128)
    ap.add_argument("--brute-size", type=int, default=24)
    ap.add_argument("--reps", type=int, default=3)
    a = ap.parse_args()
    fields, k, att = setup()
    ctx = gpu_context()
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.2f}; "
          f"GL: {ctx.info['GL_RENDERER']}; python {platform.python_version()}, numpy {np.__version__}")
    print(f"kernels: {k.n} sites, R = {k.radius:.2f} mm, grid {k.grid.tolist()}; slice z = {Z} mm, "
          f"pixel {CUBE / 1024 * 1000:.1f} um")
    print()
    print("| case | pixels | wall s | cpu s | us / pixel (wall) | GPU speed-up per pixel |")
    print("|---|---|---|---|---|---|")
    for filtered in (False, True):
        opts = dict(fields=fields, filtered=filtered, attenuation=att if filtered else None)
        name = "filtered s=2" if filtered else "unfiltered"
        big = plane(a.size)
        phasor_slice_gpu(k, big, **opts)  # warm-up: compile, driver JIT
        (gpu_t, gpu_c), _ = timed(lambda: phasor_slice_gpu(k, big, **opts), a.reps)
        per_gpu = gpu_t / big.shape[0] / big.shape[1]
        print(f"| GPU shader, {name} | {a.size}^2 | {gpu_t:.3f} | {gpu_c:.2f} | {per_gpu * 1e6:.3f} | 1 |")

        small = plane(a.ref_size)
        phasor_complex(k, plane(4).points(), **opts)  # numba compile / cache load
        (ref_t, ref_c), ref = timed(lambda: phasor_complex(k, small.points(), **opts), 1)
        per_ref = ref_t / small.shape[0] / small.shape[1]
        print(f"| phasor_complex (numba, 1 thread), {name} | {a.ref_size}^2 | {ref_t:.3f} | {ref_c:.2f} | "
              f"{per_ref * 1e6:.2f} | {per_ref / per_gpu:.0f}x |")
        g = phasor_slice_gpu(k, small, **opts)
        err = max(np.abs(g[i] - ref[i]).max() / np.abs(ref[i]).max() for i in (0, 1))

        tiny = plane(a.brute_size)
        (bru_t, bru_c), _ = timed(lambda: phasor_complex_reference(k, tiny.points(), **opts), 1)
        per_bru = bru_t / tiny.shape[0] / tiny.shape[1]
        print(f"| phasor_complex_reference (numpy brute force), {name} | {a.brute_size}^2 | {bru_t:.3f} | "
              f"{bru_c:.2f} | {per_bru * 1e6:.1f} | {per_bru / per_gpu:.0f}x |")
        print(f"|   (GPU vs numba on the {a.ref_size}^2 pixels: max |G - G_ref| / max |G| = {err:.1e}) "
              "| | | | | |")
    print()
    print("Target: 1024^2 slice <= 1 s wall, unfiltered and filtered.")


if __name__ == "__main__":
    main()
