"""Topology-optimisation benchmark: the engine's SIMP against straightforward references.

Run as ``OPENBLAS_NUM_THREADS=1 python tests/bench/bench_topopt.py``
(``--quick`` skips the paper-resolution L-beam and bridge runs).

Cases
-----
* one compliance + gradient evaluation on a tiny 10 x 20 cantilever: the
  engine against the dense reference of the tests (explicit loops,
  ``numpy.linalg.solve``), ratio;
* the whole 30 x 60 cantilever run against the straightforward reference
  SIMP of the tests (loop-built indices, ``spsolve``, OC bisection), ratio;
* one solve on a mid-run design: SuperLU against multigrid CG, for the
  160 x 80 cantilever and the 48 x 16 x 16 half MBB;
* full runs with default settings (tol 0.01 on the max design change,
  200 iterations at most; also with the stall test ``ftol=1e-4``):
  cantilever 160 x 80, MBB 3D half at 24 x 8 x 8 and 48 x 16 x 16, and unless ``--quick`` the paper's L-beam 80 x 80
  (compliance and stress-aware) and 5-load bridge 150 x 100 (one case and
  five cases, orientation).

Prints a table; asserts nothing about the timings.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from engine.topopt import optimise, preset, simp_compliance  # noqa: E402
from engine.topopt.assembly import grid_fe  # noqa: E402
from engine.topopt.design import design_space  # noqa: E402
from engine.topopt.simp import compliance_and_gradient  # noqa: E402
from tests.engine.topopt._reference import dense_compliance, reference_simp  # noqa: E402


def _timed(fn, repeat=1):
    best, out = float("inf"), None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def _row(what, size, seconds, note=""):
    print(f"| {what} | {size} | {seconds:.3f} | {note} |", flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)
    print("| what | size | seconds | note |\n|---|---|---|---|")

    p = preset("cantilever_2d", 10)
    x = np.random.default_rng(0).uniform(0.2, 1.0, p.n_cells)
    compliance_and_gradient(p, x)                                      # build caches, JIT
    t_fast, _ = _timed(lambda: compliance_and_gradient(p, x), 5)
    t_ref, _ = _timed(lambda: dense_compliance(p, x.reshape(p.shape)))
    _row("compliance + gradient, engine", "20 x 10", t_fast)
    _row("compliance + gradient, dense reference", "20 x 10", t_ref, f"engine {t_ref / t_fast:.0f}x faster")

    p = preset("cantilever_2d", 30)
    t_fast, r = _timed(lambda: simp_compliance(p, max_iter=120))
    t_ref, (_, c_ref, it_ref) = _timed(lambda: reference_simp(p, max_iter=120))
    _row("SIMP run, engine", "60 x 30", t_fast, f"{r.iterations} it, c = {r.objective:.3f}")
    _row("SIMP run, straightforward reference", "60 x 30", t_ref,
         f"{it_ref} it, c = {c_ref:.3f} ({100 * (r.objective / c_ref - 1):+.2f} %); engine {t_ref / t_fast:.1f}x faster")

    for name, res, kw in (("cantilever_2d", 80, {}), ("mbb_3d", 16, dict(aspect=3, depth=1))):
        p = preset(name, res, **kw)
        mid = simp_compliance(p, max_iter=15)
        s = design_space(p).stiffness_scale(mid.rho)[0]
        fe = grid_fe(p)
        size = " x ".join(map(str, p.shape[::-1]))
        t_d, Ud = _timed(lambda: fe.solve(s, method="direct"))
        t_m, Um = _timed(lambda: fe.solve(s, method="mgcg"), 2)
        err = np.linalg.norm(Um - Ud) / np.linalg.norm(Ud)
        _row(f"one solve, SuperLU ({fe.free.size} dofs)", size, t_d)
        _row("one solve, multigrid CG (cold start)", size, t_m, f"{t_d / t_m:.1f}x faster, rel. error {err:.1e}")

    runs = [("cantilever_2d", 80, {}, {}), ("cantilever_2d", 80, {}, dict(ftol=1e-4)),
            ("mbb_3d", 8, dict(aspect=3, depth=1), {}),
            ("mbb_3d", 16, dict(aspect=3, depth=1), {}), ("mbb_3d", 16, dict(aspect=3, depth=1), dict(ftol=1e-3))]
    if not args.quick:
        runs += [("lbeam_2d", 80, {}, {}), ("lbeam_stress_2d", 80, {}, {}),
                 ("bridge_2d_single", 100, {}, {}), ("bridge_2d_multi", 100, {}, {})]
    for name, res, kw, opts in runs:
        p = preset(name, res, **kw)
        t, r = _timed(lambda: optimise(p, **opts))
        size = " x ".join(map(str, p.shape[::-1]))
        J = np.asarray(r.history["objective"])
        near = int(np.argmax(np.abs(J - r.objective) <= 1e-3 * abs(r.objective))) + 1
        extra = ", ".join(f"{k}={v}" for k, v in opts.items())
        _row(f"{name} ({p.objective}{', ' + extra if extra else ''}), total", size, t,
             f"{r.iterations} it, {1000 * t / r.iterations:.0f} ms/it, converged {r.converged}, "
             f"J = {r.objective:.4g}, within 0.1 % after {near} it")


if __name__ == "__main__":
    main()
