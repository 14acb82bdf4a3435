"""Object-node benchmark: octet truss SDF at 128^3 + marching cubes.

Run as ``python tests/bench/bench_object.py [--resolution 128] [--ref-resolution 32]``.
Prints timings; asserts nothing about them.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from engine.geometry import line_sdf_grid, line_sdf_reference, periodic_mesh  # noqa: E402
from engine.geometry.lattices import octet_segments  # noqa: E402
from engine.geometry.marching import mesh_volume  # noqa: E402

RADIUS = 0.05


def octet_truss():
    """Octet truss in one periodic cell: the 6 face diagonals of the three
    faces through the origin (the opposite faces are their periodic copies)
    and the 12 edges of the octahedron joining the face centres."""
    return octet_segments()


def best_of(repeats, fn):
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--resolution", type=int, default=128)
    ap.add_argument("--ref-resolution", type=int, default=32)
    args = ap.parse_args()
    n, nref = args.resolution, args.ref_resolution
    polys = octet_truss()
    radii = [np.full(2, RADIUS) for _ in polys]
    assert len(polys) == 18

    t0 = time.perf_counter()
    for method in ("spherical", "normal"):
        line_sdf_grid(polys, radii, resolution=8, method=method)
    print(f"JIT warm-up (compile or cache load): {time.perf_counter() - t0:.2f} s")

    rows = []
    fields = {}
    for method in ("spherical", "normal"):
        sec, fields[method] = best_of(3, lambda: line_sdf_grid(polys, radii, resolution=n, method=method))
        rows.append((f"line_sdf_grid {method}", n, sec, ""))
    fast = rows[0][2]
    sec, (verts, faces) = best_of(3, lambda: periodic_mesh(fields["spherical"]))
    rows.append(("periodic_mesh (1 tile)", n, sec, f"{faces.shape[0]} triangles"))
    sec3, (v3, f3) = best_of(1, lambda: periodic_mesh(fields["spherical"], tiles=(3, 3, 3)))
    rows.append(("periodic_mesh (3x3x3 tiles)", n, sec3, f"{f3.shape[0]} triangles"))

    sec, ref = best_of(1, lambda: line_sdf_reference(polys, radii, resolution=nref, method="spherical"))
    scaled = sec * (n / nref) ** 3
    rows.append(("line_sdf_reference spherical", nref, sec, "measured"))
    rows.append((f"line_sdf_reference scaled to {n}^3", n, scaled,
                 f"estimate x(N/{nref})^3; {scaled / fast:.0f}x slower than fast"))

    small = line_sdf_grid(polys, radii, resolution=nref)
    band = 3.0 / nref
    near = np.abs(ref) < band - 1e-3
    agree = float(np.abs(small - ref)[near].max())

    print(f"\noctet truss, {len(polys)} segments, radius {RADIUS}, 2 threads max")
    print(f"{'method':42s} {'N':>5s} {'seconds':>9s}  ratio / note")
    for name, res, secs, note in rows:
        ratio = f"{secs / fast:7.2f}x" if not note.startswith("estimate") else ""
        print(f"{name:42s} {res:5d} {secs:9.4f}  {ratio} {note}")
    print(f"\nsolid fraction (nodes) {np.mean(fields['spherical'] < 0):.4f}, "
          f"mesh volume {mesh_volume(verts, faces):.4f}")
    print(f"fast vs reference at {nref}^3: max |diff| within band = {agree:.2e}")


if __name__ == "__main__":
    main()
