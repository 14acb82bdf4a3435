"""Growth study benchmark: Dask LocalCluster vs in-process serial.

Run: .venv/bin/python tests/bench/bench_growth_study.py [--n 100] [--serial-n 20]
     [--size 20x20] [--resolution 20] [--workers 2]

Times ``run_study`` on the 2D set TL+- (uniform hints, periodic, the paper's
20 x 20 SVEs at 20 px per block, void removed, solver tol 1e-6): ``--n``
samples on a LocalCluster of ``--workers`` processes (one thread each), and
the first ``--serial-n`` of the same samples in this process, one after
another (the reference). Prints time per sample, totals and the throughput
ratio, and checks that the rows both produced are identical (the ``seconds``
cell aside). Asserts nothing about time; the target is 100 samples <= 60 s on
a 2-core machine.
"""

from __future__ import annotations

import argparse
import platform
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from engine.batch import read_study, run_study  # noqa: E402


def _timed(**kw):
    t0 = time.perf_counter()
    s = run_study("TL+-", **kw)
    return time.perf_counter() - t0, s


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=100)
    ap.add_argument("--serial-n", type=int, default=20)
    ap.add_argument("--size", default="20x20")
    ap.add_argument("--resolution", type=int, default=20)
    ap.add_argument("--workers", type=int, default=2)
    a = ap.parse_args()
    nx, ny = (int(v) for v in a.size.split("x"))
    common = dict(shape=(ny, nx), resolution=a.resolution, seed=0, periodic=True)
    print(f"machine: {platform.machine()}, python {platform.python_version()}, "
          f"numpy {np.__version__}; TL+- {a.size} at {a.resolution} px/block "
          f"({nx * a.resolution}x{ny * a.resolution} pixels)")
    with tempfile.TemporaryDirectory() as tmp:
        # warm the numba cache in this process so the serial run is not charged for it
        run_study("TL+-", n_samples=1, scheduler="synchronous", shape=(3, 3), resolution=10)
        cl_path, se_path = Path(tmp) / "cluster.csv", Path(tmp) / "serial.csv"
        t_cl, s_cl = _timed(n_samples=a.n, scheduler=None, n_workers=a.workers,
                            out_path=cl_path, **common)
        t_se, s_se = _timed(n_samples=a.serial_n, scheduler="synchronous", out_path=se_path,
                            **common)
        rows_cl = {r["seed"]: r for r in read_study(cl_path)}
        same = all({k: v for k, v in r.items() if k != "seconds"}
                   == {k: v for k, v in rows_cl[r["seed"]].items() if k != "seconds"}
                   for r in read_study(se_path))
        solve = np.array([r["seconds"] for r in read_study(se_path)])
    head = f"{'mode':<36}{'samples':>8}{'total s':>10}{'s/sample':>10}{'ratio':>8}"
    print(head)
    print("-" * len(head))
    per_cl, per_se = t_cl / a.n, t_se / a.serial_n
    print(f"{'in-process serial (reference)':<36}{a.serial_n:>8}{t_se:>10.1f}{per_se:>10.3f}"
          f"{1.0:>7.2f}x")
    print(f"{f'LocalCluster {a.workers} workers x 1 thread':<36}{a.n:>8}{t_cl:>10.1f}"
          f"{per_cl:>10.3f}{per_se / per_cl:>7.2f}x")
    print(f"serial per-sample time: median {np.median(solve):.3f} s, "
          f"min {solve.min():.3f} s, max {solve.max():.3f} s")
    print(f"serial extrapolated to {a.n} samples: {per_se * a.n:.1f} s; "
          f"cluster total incl. start-up: {t_cl:.1f} s (target <= 60 s)")
    print(f"E_avg/E_s = {s_cl['E_avg']['mean']:.4f} +- {s_cl['E_avg']['std']:.4f}, "
          f"nu_avg = {s_cl['nu_avg']['mean']:.4f} +- {s_cl['nu_avg']['std']:.4f} "
          f"({s_cl['n_ok']} ok, {s_cl['n_singular']} mechanisms, {s_cl['n_error']} failed)")
    print(f"rows identical across schedulers: {'yes' if same else 'NO'}")


if __name__ == "__main__":
    main()
