"""Homogenization benchmark: Galerkin-multigrid PCG vs homo3D-style and direct solves.

Run as ``OPENBLAS_NUM_THREADS=1 python tests/bench/bench_homogenize.py``
(``--quick`` skips the slow baselines). Every case runs in its own
subprocess so the peak resident memory (``ru_maxrss``, whole process incl.
Python, numpy and numba) belongs to that case alone. JIT code is loaded
(from numba's cache) by a tiny warm-up solve before the clock starts.

Cases
-----
* 3D truss cell, BCC (eight half body diagonals) + cube edges, voxels nearest
  the skeleton up to a 20 % solid fraction, E = 1, nu = 0.3, at 64^3, 100^3:
  ``homogenize_voxels`` against the homo3D-style baseline (all voxels, void
  1e-6 E, scipy Jacobi-PCG one load case at a time, rtol 1e-6). The
  baseline at 100^3 is estimated from the 64^3 run when ``--baseline-max``
  is below 100 (its assembled matrix needs ~10 GB there).
* 2D 400 x 400 pixels (square lattice with round holes + diagonal struts,
  plane stress): ``homogenize_pixels`` against the assembled SuperLU solve.
Prints a table; asserts nothing about the timings.
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))


# ----------------------------------------------------------------- test cells

def _segment_distance(p, a, b):
    ab = b - a
    t = np.clip(((p - a) @ ab) / (ab @ ab), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[..., None] * ab), axis=-1)


def truss_cell(n, fraction=0.2):
    """BCC + edge truss voxels of the unit cell at solid fraction ``fraction``."""
    centre = np.full(3, 0.5)
    segs = [(centre, np.array(k, float)) for k in itertools.product((0, 1), repeat=3)]
    for axis in range(3):
        b = np.zeros(3)
        b[axis] = 1.0
        segs.append((np.zeros(3), b))
    x = (np.arange(n) + 0.5) / n
    P = np.stack(np.meshgrid(x, x, x, indexing="ij"), axis=-1)
    d = np.full((n, n, n), np.inf)
    for a, b in segs:
        for s in itertools.product((-1, 0, 1), repeat=3):
            lo, hi = np.minimum(a, b) + s - 0.3, np.maximum(a, b) + s + 0.3
            if np.any(hi < 0) or np.any(lo > 1):
                continue
            d = np.minimum(d, _segment_distance(P, a + s, b + s))
    k = int(round(fraction * d.size))
    return (d <= np.partition(d.ravel(), k - 1)[k - 1]).astype(np.float64)


def plate_image(n):
    """400^2-style 2D cell: round holes in a square lattice plus diagonal struts."""
    y, x = (np.mgrid[0:n, 0:n] + 0.5) / n
    holes = np.hypot(x - 0.5, y - 0.5) > 0.3
    diag = (np.abs(((x - y) % 1.0) - 0.5) > 0.47) | (np.abs(((x + y) % 1.0) - 0.5) > 0.47)
    return (holes | diag).astype(np.float64)


# -------------------------------------------------------------- child process

def run_case(case, n, threads):
    from engine.physics.homogenize2d import homogenize_pixels
    from engine.physics.homogenize3d import homogenize_voxels
    from engine.physics.reference_solvers import homogenize_baseline, homogenize_direct

    out = {"case": case, "n": n}
    if case in ("fast3d", "baseline3d"):
        cell = truss_cell(n)
    else:
        cell = plate_image(n)
    out["density"] = float(cell.mean())
    t0 = time.perf_counter()
    if case == "fast3d":
        homogenize_voxels(np.random.default_rng(0).random((16, 16, 16)) < 0.5,
                          threads=threads)                     # JIT load (multigrid path)
    elif case == "fast2d":
        homogenize_pixels(np.random.default_rng(0).random((64, 64)) < 0.6, threads=threads)
    out["warmup_s"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    if case == "fast3d":
        r = homogenize_voxels(cell, nu=0.3, threads=threads)
        C, out["iterations"], out["levels"] = r.C, r.iterations, r.levels
    elif case == "fast2d":
        r = homogenize_pixels(cell, nu=0.3, threads=threads)
        C, out["iterations"], out["levels"] = r.C, r.iterations, r.levels
    elif case == "baseline3d":
        C, info = homogenize_baseline(cell, nu=0.3)
        out["iterations"] = int(sum(info["iterations"]))
    elif case == "direct2d":
        grid = np.ascontiguousarray(cell[::-1, :].T)
        C = homogenize_direct(grid, nu=0.3, void_modulus=0.0, method="lu")
        out["iterations"] = 0
    out["seconds"] = time.perf_counter() - t0
    out["peak_rss_gb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024 / 1e9
    out["C"] = np.asarray(C).tolist()
    print(json.dumps(out))


def spawn(case, n, threads):
    cmd = [sys.executable, __file__, "--child", case, str(n), str(threads or 0)]
    env = dict(os.environ, OPENBLAS_NUM_THREADS=os.environ.get("OPENBLAS_NUM_THREADS", "1"))
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if proc.returncode != 0:
        raise RuntimeError(f"{case} {n} failed:\n{proc.stderr[-3000:]}")
    return json.loads(proc.stdout.strip().splitlines()[-1])


# --------------------------------------------------------------------- driver

def _load():
    try:
        return os.getloadavg()[0]
    except OSError:
        return float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    ap.add_argument("--sizes", type=int, nargs="+", default=[64, 100])
    ap.add_argument("--baseline-max", type=int, default=64,
                    help="largest 3D grid on which the baseline really runs")
    ap.add_argument("--threads", type=int, default=0, help="numba threads (0 = default)")
    ap.add_argument("--quick", action="store_true", help="skip baseline and SuperLU runs")
    args = ap.parse_args()
    if args.child:
        case, n, threads = args.child
        run_case(case, int(n), int(threads) or None)
        return

    threads = args.threads or None
    print(f"load average at start: {_load():.2f} (2-core machine; >2 means shared)")
    rows = []
    base_ref = None
    for n in args.sizes:
        fast = spawn("fast3d", n, threads)
        note = f"{fast['levels']} levels, JIT load {fast['warmup_s']:.1f} s"
        rows.append((f"{n}^3", "GMG-PCG, 6 cases together", fast["seconds"],
                     fast["peak_rss_gb"], fast["iterations"], None, note))
        if args.quick:
            continue
        if n <= args.baseline_max:
            base = spawn("baseline3d", n, threads)
            base_ref = (n, base)
            ratio = base["seconds"] / fast["seconds"]
            dC = np.abs(np.array(base["C"]) - np.array(fast["C"])).max() / np.abs(fast["C"]).max()
            rows.append((f"{n}^3", "homo3D-style Jacobi-PCG", base["seconds"], base["peak_rss_gb"],
                         base["iterations"], ratio, f"measured; max |dC|/|C| = {dC:.1e}"))
        elif base_ref is not None:
            n0, b0 = base_ref
            # Work ~ voxels x iterations, Jacobi-CG iterations ~ n.
            est = b0["seconds"] * (n / n0) ** 4
            mem = b0["peak_rss_gb"] * (n / n0) ** 3
            rows.append((f"{n}^3", "homo3D-style Jacobi-PCG", est, mem, None,
                         est / fast["seconds"],
                         f"ESTIMATED from {n0}^3 x (n/{n0})^4 time, ^3 memory"))
    fast = spawn("fast2d", 400, threads)
    rows.append(("400^2", "GMG-PCG (2D, plane stress)", fast["seconds"], fast["peak_rss_gb"],
                 fast["iterations"], None, f"{fast['levels']} levels"))
    if not args.quick:
        ref = spawn("direct2d", 400, threads)
        dC = np.abs(np.array(ref["C"]) - np.array(fast["C"])).max() / np.abs(fast["C"]).max()
        rows.append(("400^2", "assembled SuperLU", ref["seconds"], ref["peak_rss_gb"], 0,
                     ref["seconds"] / fast["seconds"], f"max |dC|/|C| = {dC:.1e}"))

    print(f"\n{'grid':>6} | {'method':<28} | {'seconds':>8} | {'peak GB':>7} | "
          f"{'iters':>6} | {'ratio':>7} | note")
    print("-" * 110)
    for grid, method, sec, mem, its, ratio, note in rows:
        its_s = "-" if its is None else str(its)
        ratio_s = "" if ratio is None else f"{ratio:.1f}x"
        print(f"{grid:>6} | {method:<28} | {sec:8.2f} | {mem:7.2f} | {its_s:>6} | "
              f"{ratio_s:>7} | {note}")
    print(f"\nratio = reference seconds / fast seconds on the same cell. "
          f"load average at end: {_load():.2f}")


if __name__ == "__main__":
    main()
