"""Virtual growth benchmark: compiled kernel vs the plain-Python reference.

Run: .venv/bin/python tests/bench/bench_growth.py [--seeds2d 100] [--seeds3d 20]
     [--ref-seeds2d 20] [--ref-seeds3d 3]

Times ``grow_tiling`` on a 20x20 grid (TL+-) and a 10x10x10 grid
(cubic-beams), median over seeds, against ``grow_tiling_reference`` on the
first seeds (the reference is slow; it gets fewer seeds), checks that both
give the same tilings, and prints a table with the ratio. Two larger grids
(heap path) are timed without the reference. Asserts nothing about time.
"""

from __future__ import annotations

import argparse
import platform
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from engine.growth import grow_tiling, grow_tiling_reference, load_tileset  # noqa: E402


def _times(fn, ts, shape, seeds, **kw):
    out, tilings = [], []
    for s in seeds:
        t0 = time.perf_counter()
        tilings.append(fn(ts, shape, rng=s, **kw))
        out.append(time.perf_counter() - t0)
    return np.array(out), tilings


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds2d", type=int, default=100)
    ap.add_argument("--seeds3d", type=int, default=20)
    ap.add_argument("--ref-seeds2d", type=int, default=20)
    ap.add_argument("--ref-seeds3d", type=int, default=3)
    a = ap.parse_args()
    cases = [
        ("2D 20x20, TL+-", load_tileset("TL+-"), (20, 20), a.seeds2d, a.ref_seeds2d, {}),
        ("2D 20x20, TL+-, periodic", load_tileset("TL+-"), (20, 20), a.seeds2d,
         a.ref_seeds2d, {"periodic": True}),
        ("3D 10^3, cubic-beams", load_tileset("cubic-beams"), (10, 10, 10), a.seeds3d,
         a.ref_seeds3d, {}),
        ("3D 10^3, cubic-beams-mixed (71 tiles)", load_tileset("cubic-beams-mixed"),
         (10, 10, 10), a.seeds3d, a.ref_seeds3d, {}),
        ("2D 200x200, TL+- (heap path, no ref)", load_tileset("TL+-"), (200, 200), 5, 0, {}),
        ("3D 20^3, cubic-beams (heap path, no ref)", load_tileset("cubic-beams"), (20, 20, 20),
         5, 0, {}),
    ]
    for _, ts, shape, *_ in cases[:4]:
        grow_tiling(ts, shape, rng=0)          # JIT / cache warm-up
    grow_tiling(load_tileset("TL+-"), (50, 50), rng=0)
    print(f"machine: {platform.machine()}, {platform.processor() or '?'}, python "
          f"{platform.python_version()}, numpy {np.__version__}")
    head = (f"{'case':<40}{'fast ms (median)':>18}{'n':>5}{'ref ms (median)':>17}{'n':>4}"
            f"{'ratio':>9}{'defects/cell':>14}{'same':>6}")
    print(head)
    print("-" * len(head))
    for label, ts, shape, nf, nr, kw in cases:
        tf, fast = _times(grow_tiling, ts, shape, range(nf), **kw)
        tr, ref = _times(grow_tiling_reference, ts, shape, range(nr), **kw)
        same = all(np.array_equal(x.tiles, y.tiles) for x, y in zip(fast, ref))
        dens = np.mean([t.n_defects for t in fast]) / np.prod(shape)
        mf = np.median(tf) * 1e3
        if nr:
            mr = np.median(tr) * 1e3
            ref = f"{mr:>17.1f}{nr:>4}{mr / mf:>8.0f}x"
        else:
            ref = f"{'-':>17}{0:>4}{'-':>9}"
        print(f"{label:<40}{mf:>18.3f}{nf:>5}{ref}{dens:>14.4f}{'yes' if same else 'NO':>6}")


if __name__ == "__main__":
    main()
