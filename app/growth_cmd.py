"""`mesoforge grow` and `mesoforge study`: virtual growth from the command line.

    mesoforge grow TILESET --size 20x20[x10] [--periodic] [--seed S] --out tiling.json
                   [--png tiling.png] [--hints T=1,L=1,+=2,-=1] [--availability N] [--json]
    mesoforge study TILESET [--hints ...] [--n 100] [--size 20x20] [--out study.csv]
                    [--scheduler ADDRESS|synchronous] [--seed S] [--json]

TILESET is a set name from resources/tilesets (``TL+-``), a file stem
(``tl_basic``) or a path to a tile-set JSON file. Bad input exits with 2 and
a message naming the argument; an interrupted study exits with 130 and keeps
the rows it wrote (run it again to resume).
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

COMMANDS = ("grow", "study")


class _BadInput(ValueError):
    """A command-line value that is refused (exit code 2)."""


def add_parsers(sub) -> None:
    g = sub.add_parser("grow", help="grow an irregular tiling by virtual growth")
    g.add_argument("tileset", help="tile set name (resources/tilesets) or JSON file")
    g.add_argument("--size", required=True, help="grid size NXxNY (2D) or NXxNYxNZ (3D)")
    g.add_argument("--periodic", action="store_true", help="grow on a torus (a periodic cell)")
    g.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    g.add_argument("--out", required=True, help="tiling file to write (tiling.json)")
    g.add_argument("--png", help="also write the pixel image (2D; black = solid)")
    g.add_argument("--hints", default="", help="frequency hints, e.g. T=1,L=1,+=2,-=1")
    g.add_argument("--availability", type=float, default=0.0,
                   help="blocks available per cell (paper's N); 0 = unlimited (default)")
    g.add_argument("--json", action="store_true", help="print a JSON summary")

    s = sub.add_parser("study", help="property distribution of grown samples (Fig. 3)")
    s.add_argument("tileset", help="tile set name (resources/tilesets) or JSON file")
    s.add_argument("--hints", default="", help="frequency hints, e.g. T=1,L=1,+=2,-=1 "
                                              "(default: uniform over blocks)")
    s.add_argument("--n", type=int, default=100, help="number of samples (default 100)")
    s.add_argument("--size", help="grid size (default 20x20 in 2D, 10x10x10 in 3D)")
    s.add_argument("--bounded", action="store_true",
                   help="grow bounded SVEs instead of periodic cells")
    s.add_argument("--out", help="rows file, .csv (or .parquet with pyarrow); resumed if present")
    s.add_argument("--no-resume", action="store_true", help="start --out afresh")
    s.add_argument("--scheduler", help="Dask scheduler address, or 'synchronous' for no Dask "
                                       "(default: a local cluster)")
    s.add_argument("--workers", type=int, default=2, help="local cluster workers (default 2)")
    s.add_argument("--seed", type=int, default=0, help="study seed (default 0)")
    s.add_argument("--E", type=float, default=1.0, help="solid Young's modulus (default 1)")
    s.add_argument("--nu", type=float, default=0.46, help="solid Poisson ratio (default 0.46)")
    s.add_argument("--resolution", type=int,
                   help="pixels / voxels per block edge (default 20 in 2D, 10 in 3D)")
    s.add_argument("--void", choices=("removed", "soft"), default="removed",
                   help="void removed, or soft E_v = 1e-3 E as in the paper")
    s.add_argument("--json", action="store_true", help="print a JSON summary")


# ------------------------------------------------------------------ helpers

def _fail(cmd: str, msg: str, code: int = 2) -> int:
    print(f"mesoforge {cmd}: {msg}", file=sys.stderr)
    return code


def _tileset(text: str):
    from engine.growth import load_tileset
    try:
        return load_tileset(text)
    except ValueError as exc:
        raise _BadInput(f"TILESET {text!r}: {exc}") from None


def parse_size(text: str, ndim: int) -> tuple:
    """``"20x20"`` / ``"20x20x10"`` (nx x ny [x nz]) -> grid shape ``(ny, nx)`` / ``(nz, ny, nx)``."""
    parts = text.lower().replace("*", "x").split("x")
    try:
        n = [int(p) for p in parts]
    except ValueError:
        raise _BadInput(f"--size {text!r}: expected integers like 20x20 or 10x10x10") from None
    if len(n) != ndim:
        want = "NXxNY" if ndim == 2 else "NXxNYxNZ"
        raise _BadInput(f"--size {text!r}: the tile set is {ndim}D, expected {want}")
    if any(v < 1 for v in n):
        raise _BadInput(f"--size {text!r}: every count must be >= 1")
    if math.prod(n) > 4_000_000:
        raise _BadInput(f"--size {text!r}: {math.prod(n)} cells is more than 4000000")
    return tuple(n[::-1])


def _hints(text: str, ts):
    from engine.batch import parse_hints
    try:
        return parse_hints(text, ts)
    except ValueError as exc:
        raise _BadInput(f"--hints: {exc}") from None


def _availability(value: float):
    if math.isnan(value) or value < 0:
        raise _BadInput(f"--availability {value}: expected a number >= 0 (0 = unlimited)")
    return None if value == 0 or math.isinf(value) else float(value)


def _write_png(path: str, image) -> None:
    import numpy as np
    from PIL import Image
    # black = solid, so `mesoforge homogenize tiling.png` reads it back as material
    Image.fromarray(np.where(image > 0, 0, 255).astype(np.uint8)).save(path)


# ------------------------------------------------------------------ grow

def _grow(args) -> int:
    from engine.growth import grow_tiling, realised_probabilities, save_tiling, tiling_image

    ts = _tileset(args.tileset)
    shape = parse_size(args.size, ts.ndim)
    hints = _hints(args.hints, ts)
    availability = _availability(args.availability)
    if args.seed < 0:
        raise _BadInput(f"--seed {args.seed}: expected an integer >= 0")
    if args.png and ts.ndim != 2:
        raise _BadInput(f"--png: tile set {ts.name!r} is 3D; images are for 2D tilings")
    t0 = time.perf_counter()
    tiling = grow_tiling(ts, shape, hints=hints, periodic=args.periodic,
                         availability=availability, rng=args.seed)
    seconds = time.perf_counter() - t0
    try:
        save_tiling(args.out, tiling, ts)
        if args.png:
            _write_png(args.png, tiling_image(tiling, ts))
    except OSError as exc:
        return _fail("grow", f"cannot write output: {exc}", 1)
    probs = realised_probabilities(tiling, ts)
    out = {"tileset": ts.name, "size": args.size, "shape": list(shape), "seed": args.seed,
           "periodic": bool(args.periodic), "hints": hints, "availability": availability,
           "n_defects": tiling.n_defects, "complete": bool(tiling.stats.get("complete", True)),
           "realised_probabilities": dict(zip(ts.block_names, map(float, probs))),
           "seconds": round(seconds, 4), "out": str(Path(args.out).resolve()),
           "png": str(Path(args.png).resolve()) if args.png else None}
    if args.json:
        print(json.dumps(out, indent=1))
    else:
        pr = ", ".join(f"{b} {p:.3f}" for b, p in out["realised_probabilities"].items())
        print(f"grew {ts.name} {args.size} (seed {args.seed}) in {seconds:.3f} s: "
              f"{tiling.n_defects} defects; realised probabilities {pr}; wrote {args.out}")
    return 0


# ------------------------------------------------------------------ study

def _progress_to(stream):
    if not stream.isatty():
        return None
    t0 = time.perf_counter()

    def cb(done, total):
        print(f"\r  study: {done}/{total} samples, {time.perf_counter() - t0:6.1f} s",
              end="", file=stream, flush=True)
        return True
    return cb


def _study(args) -> int:
    from engine.batch import run_study

    ts = _tileset(args.tileset)
    size = args.size or ("20x20" if ts.ndim == 2 else "10x10x10")
    shape = parse_size(size, ts.ndim)
    hints = _hints(args.hints, ts)
    if args.n < 1:
        raise _BadInput(f"--n {args.n}: expected a number of samples >= 1")
    if args.seed < 0:
        raise _BadInput(f"--seed {args.seed}: expected an integer >= 0")
    if args.workers < 1:
        raise _BadInput(f"--workers {args.workers}: expected an integer >= 1")
    progress = _progress_to(sys.stderr)
    try:
        summary = run_study(ts, hints=hints, n_samples=args.n, shape=shape,
                            periodic=not args.bounded, seed=args.seed, E=args.E, nu=args.nu,
                            out_path=args.out, scheduler=args.scheduler, n_workers=args.workers,
                            progress=progress, resume=not args.no_resume,
                            resolution=args.resolution, void=args.void)
    except ValueError as exc:
        raise _BadInput(str(exc)) from None
    except KeyboardInterrupt:
        where = f"; rows so far are in {args.out} (run again to resume)" if args.out else ""
        return _fail("study", f"interrupted{where}", 130)
    finally:
        if progress is not None:
            print(file=sys.stderr)
    summary.pop("rows", None)
    summary["size"] = size
    if args.json:
        print(json.dumps(summary, indent=1, default=float))
    else:
        e, nu = summary["E_avg"], summary["nu_avg"]
        print(f"{ts.name} {size}, {summary['n_done']}/{summary['n_samples']} samples "
              f"({summary['n_ok']} ok, {summary['n_singular']} mechanisms, "
              f"{summary['n_error']} failed) in {summary['seconds']:.1f} s")
        print(f"  E_avg/E_s = {e['mean']:.5g} +- {e['std']:.3g}   "
              f"nu_avg = {nu['mean']:.4f} +- {nu['std']:.3g}   (mean +- std)")
        pr = ", ".join(f"{b} {p:.3f}" for b, p in summary["realised_probabilities"].items())
        print(f"  realised probabilities: {pr}")
        if args.out:
            print(f"  rows in {args.out}")
    return 0


def run(args) -> int:
    try:
        return _grow(args) if args.command == "grow" else _study(args)
    except _BadInput as exc:
        return _fail(args.command, str(exc))
