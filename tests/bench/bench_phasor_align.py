"""Phasor benchmark: phase alignment and slice evaluation against plain references.

Run as ``python tests/bench/bench_phasor_align.py`` (``--quick`` skips the
O(n^2) reference iteration and measures the brute-force slice on fewer
pixels).

Cases
-----
* 50 mm cube, F = 1 cycle/mm (R = 4.5 mm, 8 sites per cell, 21,952 sites),
  D turning 90 degrees about z across x, Gamma = 0.2:
  ``align_phases`` (numba, 27 cells, 20 Jacobi iterations) against one
  iteration of ``alignment_step_reference`` (plain numpy, every site against
  every site) times 20.
* A 256 x 256 z-slice through the middle (0.2 mm pixels): ``phasor_complex``
  (cell lookup) raw and filtered, against ``phasor_complex_reference``
  (brute force over all sites) measured on a subset of pixels and scaled.
JIT code is compiled (or loaded from numba's cache) by a small warm-up run
before the clock starts.  Prints a table; asserts nothing about timings.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from engine.phasor.align import align_phases, alignment_step_reference  # noqa: E402
from engine.phasor.fields import PhasorFields  # noqa: E402
from engine.phasor.noise import (SliceGrid, phasor_complex, phasor_complex_reference,  # noqa: E402
                                 slice_points)
from engine.phasor.sampling import sample_kernels  # noqa: E402

SIZE = 50.0


def cube_fields(n=16) -> PhasorFields:
    shape = (n, n, n)
    x = (np.arange(n) + 0.5) / n * SIZE
    d = np.zeros(shape + (3,))
    turn = np.pi / 2 * x / SIZE
    d[..., 0], d[..., 1] = np.cos(turn), np.sin(turn)
    return PhasorFields(d, np.ones(shape), np.full(shape, 0.2), (0, 0, 0), (SIZE, SIZE, SIZE))


def timed(fn, *args, **kwargs):
    t0 = time.perf_counter()
    out = fn(*args, **kwargs)
    return time.perf_counter() - t0, out


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="skip the O(n^2) reference iteration")
    args = parser.parse_args(argv)

    fields = cube_fields()
    t_sample, kernels = timed(sample_kernels, fields, rng=0)
    warm = sample_kernels(PhasorFields(fields.direction[:2, :2, :2], np.ones((2, 2, 2)), np.zeros((2, 2, 2)),
                                       (0, 0, 0), (5, 5, 5)), rng=0)
    align_phases(warm, iterations=1)
    phasor_complex(warm, np.zeros((4, 3)), fields=fields, filtered=True)

    rows = [("sample_kernels", f"{kernels.n} sites", t_sample, "")]
    t_align, aligned = timed(align_phases, kernels, iterations=20)
    rows.append(("align_phases, 20 iterations", f"{kernels.n} sites", t_align, "target <= 10 s"))
    if not args.quick:
        t_ref, _ = timed(alignment_step_reference, kernels)
        rows.append(("alignment_step_reference, 1 iteration", "all pairs", t_ref, ""))
        rows.append(("reference x 20 (estimate)", "", 20 * t_ref, f"fast path {20 * t_ref / t_align:.0f}x faster"))

    plane = SliceGrid.axis_aligned("z", SIZE / 2, 0.2, ((-0.6, 50.6), (-0.6, 50.6)))
    pts = slice_points(plane)
    assert plane.shape == (256, 256)
    t_raw, _ = timed(phasor_complex, aligned, pts)
    t_filt, _ = timed(phasor_complex, aligned, pts, fields=fields, filtered=True)
    rows.append(("phasor_complex raw", "256 x 256", t_raw, ""))
    rows.append(("phasor_complex filtered", "256 x 256", t_filt, ""))
    subset = pts[np.random.default_rng(0).choice(len(pts), 256 if args.quick else 1024, replace=False)]
    for name, opts, fast in (("raw", {}, t_raw), ("filtered", {"fields": fields, "filtered": True}, t_filt)):
        t_sub, _ = timed(phasor_complex_reference, aligned, subset, **opts)
        scaled = t_sub * len(pts) / len(subset)
        rows.append((f"phasor_complex_reference {name} (scaled)", f"{len(subset)} px measured", scaled,
                     f"cell lookup {scaled / fast:.0f}x faster"))

    print(f"{'what':44s} {'size':18s} {'seconds':>9s}  note")
    for what, size, seconds, note in rows:
        print(f"{what:44s} {size:18s} {seconds:9.3f}  {note}")


if __name__ == "__main__":
    main()
