"""G-code benchmark: a 50 mm cube of diamond cells, 0.2 mm layers, 0.1 mm pixels.

Run as ``python tests/bench/bench_gcode.py [--layers 250] [--ref-layers 50]``.

The fast path is what :func:`engine.fab.layers_to_gcode` does (simplified
walls, ordered paths, streamed writing), timed step by step. The reference
keeps every marching-squares vertex and prints paths in contour order; it
runs on ``--ref-layers`` layers and is scaled to the full height. A slab of
``--check-layers`` layers is then emulated (0.04 mm pixels) for the
overhang / overlap statistics of Tricard et al. §5.1.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from engine.fab import PrintSettings, printability, read_gcode_paths, write_gcode  # noqa: E402
from engine.fab.toolpaths import layer_walls, order_layer  # noqa: E402

SIDE = 50.0          # mm
PIXEL = 0.1          # mm
PERIOD = 2.5         # mm, diamond cell period
MARGIN = 1.0         # mm of image around the part


def slice_image(z, xx, yy):
    """Diamond-like cells in the slice at height ``z``: the checkerboard
    |1/2 - frac(u)| + |1/2 - frac(v)| < 1/2 with (u, v) sliding with z."""
    u = np.mod((xx + z) / PERIOD, 1.0)
    v = np.mod((yy - 0.5 * z) / PERIOD, 1.0)
    return (np.abs(0.5 - u) + np.abs(0.5 - v)) < 0.5


class Timed:
    """Per-step wall-clock totals."""

    def __init__(self):
        self.t = {"image": 0.0, "contours": 0.0, "ordering": 0.0}

    def add(self, key, t0):
        now = time.perf_counter()
        self.t[key] += now - t0
        return now


def layers(n_layers, settings, timer, *, simplify=True, order=True, keep=None):
    n = int(round((SIDE + 2 * MARGIN) / PIXEL)) + 1
    origin = (-MARGIN, -MARGIN)
    yy, xx = np.mgrid[0:n, 0:n] * PIXEL + np.array(origin)[::-1, None, None]
    domain = (xx >= 0) & (xx < SIDE) & (yy >= 0) & (yy < SIDE)
    opts = {} if simplify else dict(tolerance=0.0, min_spacing=0.0, min_length=0.0)
    pos = -np.asarray(settings.offset)
    for k in range(n_layers):
        z = settings.layer_height * (k + 1)
        t0 = time.perf_counter()
        image = slice_image(z, xx, yy)
        t0 = timer.add("image", t0)
        perims, walls = layer_walls(image, domain, origin=origin, pixel_size=PIXEL,
                                    settings=settings, **opts)
        t0 = timer.add("contours", t0)
        layer = order_layer(perims, walls, z=z, settings=settings, start=pos, order=order)
        timer.add("ordering", t0)
        if layer.paths:
            pos = layer.end_point
        if keep is not None:
            keep.append(layer)
        yield layer


def run(name, n_layers, settings, path, **kw):
    timer = Timed()
    kept = []
    t0 = time.perf_counter()
    summary = write_gcode(layers(n_layers, settings, timer, keep=kept, **kw), path,
                          settings=settings, n_layers=n_layers)
    total = time.perf_counter() - t0
    timer.t["writing"] = total - sum(timer.t.values())
    n_points = sum(len(p) for layer in kept for p in layer.paths)
    n_paths = sum(len(layer) for layer in kept)
    return dict(name=name, layers=n_layers, total=total, steps=dict(timer.t),
                size=os.path.getsize(path), travel=summary.travel_length,
                extruded=summary.extrusion_length, points=n_points, paths=n_paths,
                kept=kept, summary=summary)


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--layers", type=int, default=250)
    ap.add_argument("--ref-layers", type=int, default=50)
    ap.add_argument("--check-layers", type=int, default=10)
    args = ap.parse_args()
    settings = PrintSettings()

    # JIT warm-up (compile or cache load) outside the timings
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        run("warm-up", 2, settings, Path(tmp) / "w.gcode")
        print(f"warm-up (JIT compile or cache load): {time.perf_counter() - t0:.2f} s")

        fast = run("fast", args.layers, settings, Path(tmp) / "fast.gcode")
        ref = run("reference", args.ref_layers, settings, Path(tmp) / "ref.gcode",
                  simplify=False, order=False)

        t0 = time.perf_counter()
        back = read_gcode_paths(Path(tmp) / "fast.gcode", offset=settings.offset)
        t_read = time.perf_counter() - t0
        assert len(back) == args.layers

        mid = args.layers // 2
        slab = fast["kept"][mid:mid + args.check_layers]
        t0 = time.perf_counter()
        rep = printability(slab, nozzle_diameter=settings.nozzle_diameter)
        t_check = time.perf_counter() - t0

    scale = args.layers / args.ref_layers
    print(f"\n{SIDE:g} mm cube, {args.layers} layers of {settings.layer_height} mm, "
          f"{PIXEL} mm pixels ({int(round((SIDE + 2 * MARGIN) / PIXEL)) + 1}^2 per slice), "
          f"diamond period {PERIOD} mm")
    print(f"{'step':12s} {'fast s':>9s} {'ref s':>9s} {'ref scaled':>11s}  ratio")
    for key in ("image", "contours", "ordering", "writing"):
        f, r = fast["steps"][key], ref["steps"][key]
        print(f"{key:12s} {f:9.2f} {r:9.2f} {r * scale:11.2f}  {r * scale / max(f, 1e-9):5.2f}")
    f, r = fast["total"], ref["total"]
    print(f"{'total':12s} {f:9.2f} {r:9.2f} {r * scale:11.2f}  {r * scale / f:5.2f}")
    print()
    print(f"{'per layer':12s} {'fast':>12s} {'reference':>12s}")
    for key, unit in (("paths", ""), ("points", ""), ("size", " B"), ("travel", " mm"),
                      ("extruded", " mm")):
        a, b = fast[key] / fast["layers"], ref[key] / ref["layers"]
        print(f"{key:12s} {a:12.1f} {b:12.1f}{unit}")
    print(f"G-code: {fast['size'] / 1e6:.1f} MB (reference scaled {ref['size'] * scale / 1e6:.1f} MB); "
          f"estimated print time {fast['summary'].print_time / 3600:.1f} h")
    print(f"read back {args.layers} layers: {t_read:.2f} s")
    print(f"\nprintability of layers {mid}..{mid + len(slab) - 1} at 0.04 mm: {t_check:.2f} s; "
          f"{rep.segment_length.size} pieces, {rep.overhang_count} overhang segments, "
          f"{rep.overlap_count} overlap segments")
    edges = rep.bin_edges
    print("  length bin (mm)   overhangs  overlaps")
    for a, b, oh, ov in zip(edges[:-1], edges[1:], rep.overhang_histogram, rep.overlap_histogram):
        print(f"  {a:5.1f} - {b:5.1f}   {oh:9d} {ov:9d}")


if __name__ == "__main__":
    main()
