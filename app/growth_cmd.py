"""`mesoforge grow` and `mesoforge study`: virtual growth from the command line.

    mesoforge grow TILESET --size 20x20[x10] [--periodic] [--seed S] --out tiling.json
                   [--png tiling.png] [--hints T=1,L=1,+=2,-=1] [--availability N] [--json]
    mesoforge study TILESET [--hints ... | --group HINTS [--group HINTS ...] | --sweep N]
                    [--n 100] [--size 20x20] [--out study.csv]
                    [--scheduler ADDRESS|synchronous] [--seed S] [--progress-lines] [--json]

TILESET is a set name from resources/tilesets (``TL+-``), a file stem
(``tl_basic``) or a path to a tile-set JSON file. Bad input exits with 2 and
a message naming the argument; an interrupted study exits with 130 and keeps
the rows it wrote (run it again to resume).

A study grows ``--n`` samples from one set of ``--hints``; with ``--group``
(repeated) it grows ``--n`` samples of each hint group into one file (set
``j`` = group ``j``, Fig. 3B); with ``--sweep N`` it grows ``--n`` samples of
each of N hint vectors spread over the simplex (a database, Fig. 4).

While a study runs, SIGTERM asks it to stop: pending samples are cancelled,
the Dask cluster is closed and the command exits with 130, leaving whole rows
in ``--out`` (a second SIGTERM interrupts at once). ``--progress-lines``
prints ``progress DONE TOTAL`` lines on stderr as rows arrive, for the window
(``ui.study_panel``), which builds its command with :func:`study_argv`.
"""

from __future__ import annotations

import json
import math
import signal
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
    s.add_argument("--group", action="append", metavar="HINTS",
                   help="a hint group (repeat for several; '' = uniform): --n samples of each, "
                        "one set per group in --out")
    s.add_argument("--sweep", type=int, metavar="N",
                   help="N hint vectors drawn uniformly on the simplex: --n samples of each")
    s.add_argument("--min-distance", type=float, default=0.0,
                   help="--sweep: least distance between hint vectors (default 0)")
    s.add_argument("--n", type=int, default=100,
                   help="number of samples (per group or hint vector; default 100)")
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
    s.add_argument("--progress-lines", action="store_true",
                   help="print 'progress DONE TOTAL' lines on stderr as rows arrive")
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
    """``"20x20"`` / ``"20x20x10"`` (nx x ny [x nz]) -> grid shape ``(ny, nx)`` / ``(nz, ny, nx)``.

    The counts are checked by the Grow node's ``size`` schema and its cell
    limit (the node that runs the growth in a graph)."""
    from engine.graph import ParamError, node_type
    from engine.nodes.growth import MAX_CELLS

    parts = str(text).lower().replace("*", "x").split("x")
    try:
        n = [int(p) for p in parts]
    except ValueError:
        raise _BadInput(f"--size {text!r}: expected integers like 20x20 or 10x10x10") from None
    if len(n) != ndim:
        want = "NXxNY" if ndim == 2 else "NXxNYxNZ"
        raise _BadInput(f"--size {text!r}: the tile set is {ndim}D, expected {want}")
    param = node_type("Grow").param("size")
    try:
        param.coerce(n)
    except ParamError:
        raise _BadInput(f"--size {text!r}: every count must be in [{param.minimum:g}, {param.maximum:g}] "
                        f"(allowed: {param.allowed()})") from None
    if math.prod(n) > MAX_CELLS:
        raise _BadInput(f"--size {text!r}: {math.prod(n)} cells is more than {MAX_CELLS} "
                        f"(allowed: at most {MAX_CELLS} cells)")
    return tuple(n[::-1])


def _grow_memory(text: str, shape, ts, *, samples: int = 1, resolution=None) -> None:
    """Refuse a --size whose growth (and, for a study, the homogenization of
    each sample, ``samples`` at once) would exceed the memory budget."""
    from app.flags import memory_value
    from engine.graph import node_type

    need = node_type("Grow").memory_estimate({"size": list(shape[::-1])}, {"tileset": ts})
    if resolution is not None:      # each sample is homogenized as the Tiling Properties node does
        from engine.nodes.growth import tiling_properties_bytes
        need += tiling_properties_bytes(shape, resolution)
    lower = "--size" + (" or --resolution" if resolution is not None else "") + (" or --workers" if samples > 1 else "")
    memory_value("--size", text, need * samples, lower=lower)


def _hints(text: str, ts):
    from engine.batch import parse_hints
    try:
        return parse_hints(text, ts)
    except ValueError as exc:
        raise _BadInput(f"--hints: {exc}") from None


def _availability(value: float):
    from app.flags import schema_value

    value = schema_value("--availability", value, "Grow", "availability")   # 0 = unlimited
    return None if value == 0 else float(value)


def _write_png(path: str, image) -> None:
    import numpy as np
    from PIL import Image
    # black = solid, so `mesoforge homogenize tiling.png` reads it back as material
    Image.fromarray(np.where(image > 0, 0, 255).astype(np.uint8)).save(path)


# ------------------------------------------------------------------ grow

def _grow(args) -> int:
    from engine.growth import grow_tiling, realised_probabilities, save_tiling, tiling_image

    from app.flags import distinct_outputs, output_path

    output_path("--out", args.out, (".json",))
    output_path("--png", args.png, (".png",))
    distinct_outputs(("--out", args.out), ("--png", args.png))
    ts = _tileset(args.tileset)
    shape = parse_size(args.size, ts.ndim)
    hints = _hints(args.hints, ts)
    availability = _availability(args.availability)
    if args.seed < 0:
        raise _BadInput(f"--seed {args.seed}: expected an integer >= 0 (allowed: 0, 1, 2, ...)")
    if args.png and ts.ndim != 2:
        raise _BadInput(f"--png {args.png}: tile set {ts.name!r} is 3D; images are for 2D tilings "
                        f"(allowed: --png with a 2D tile set)")
    _grow_memory(args.size, shape, ts)
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

class _StopOnTerm:
    """While a study runs, SIGTERM asks it to stop instead of killing the process:
    the progress callback then answers False, the engine cancels what is pending
    and closes its cluster. A second SIGTERM interrupts at once."""

    def __init__(self):
        self.requested = False
        self._previous = None

    def _handle(self, signum, frame):
        if self.requested:
            raise KeyboardInterrupt
        self.requested = True

    def __enter__(self):
        try:
            self._previous = signal.signal(signal.SIGTERM, self._handle)
        except ValueError:          # not the main thread: leave SIGTERM as it is
            self._previous = None
        return self

    def __exit__(self, *exc):
        if self._previous is not None:
            signal.signal(signal.SIGTERM, self._previous)


def _study_progress(stream, stop: _StopOnTerm, lines: bool):
    """``progress(done, total)`` that reports to ``stream`` (a ``\\r`` counter on a
    terminal, or ``progress DONE TOTAL`` lines) and answers False once stopped."""
    t0 = time.perf_counter()
    last = [None]

    def cb(done, total):
        if lines:
            if (done, total) != last[0]:
                last[0] = (done, total)
                print(f"progress {done} {total}", file=stream, flush=True)
        elif stream.isatty():
            print(f"\r  study: {done}/{total} samples, {time.perf_counter() - t0:6.1f} s",
                  end="", file=stream, flush=True)
        return not stop.requested
    return cb


def parse_progress_line(line: str):
    """``(done, total)`` from a ``progress DONE TOTAL`` line, else None."""
    parts = line.split()
    if len(parts) == 3 and parts[0] == "progress" and parts[1].isdigit() and parts[2].isdigit():
        return int(parts[1]), int(parts[2])
    return None


def _study_mode(args) -> str:
    given = [name for name, v in (("--hints", args.hints), ("--group", args.group),
                                  ("--sweep", args.sweep is not None)) if v]
    if len(given) > 1:
        raise _BadInput(f"{' and '.join(given)}: give only one of --hints, --group "
                        f"(repeated) or --sweep")
    return given[0] if given else "--hints"


def _group_hints(texts, ts, *, label: str = "--group") -> list:
    from engine.batch import parse_hints
    out = []
    for k, text in enumerate(texts):
        try:
            out.append(parse_hints(text, ts))
        except ValueError as exc:
            raise _BadInput(f"{label} {k + 1} {text!r}: {exc}") from None
    return out


def _run_mode(args, mode, ts, common) -> dict:
    from engine.batch import run_study, sweep_hints
    from engine.batch.study_groups import study_hint_groups

    if mode == "--group":
        return study_hint_groups(ts, _group_hints(args.group, ts), samples_per_group=args.n,
                                 **common)
    if mode == "--sweep":
        return sweep_hints(ts, n_hint_sets=args.sweep, samples_per_set=args.n,
                           min_distance=args.min_distance, **common)
    return run_study(ts, hints=_hints(args.hints, ts), n_samples=args.n, **common)


def _print_study(ts, size, summary) -> None:
    print(f"{ts.name} {size}, {summary['n_done']}/{summary['n_samples']} samples "
          f"({summary['n_ok']} ok, {summary['n_singular']} mechanisms, "
          f"{summary['n_error']} failed) in {summary['seconds']:.1f} s")
    for part in summary.get("sets", [summary]):
        e, nu = part["E_avg"], part["nu_avg"]
        head = f"  set {part['set']}: " if "set" in part else "  "
        print(f"{head}E_avg/E_s = {e['mean']:.5g} +- {e['std']:.3g}   "
              f"nu_avg = {nu['mean']:.4f} +- {nu['std']:.3g}   (mean +- std)")
        pr = ", ".join(f"{b} {p:.3f}" for b, p in part["realised_probabilities"].items())
        print(f"  realised probabilities: {pr}")
    if summary["out_path"]:
        print(f"  rows in {summary['out_path']}")


def _study(args) -> int:
    from app.flags import output_path, schema_value
    from engine.batch.rows import StudyFileError

    output_path("--out", args.out, (".csv", ".parquet"))
    ts = _tileset(args.tileset)
    size = args.size or ("20x20" if ts.ndim == 2 else "10x10x10")
    shape = parse_size(size, ts.ndim)
    mode = _study_mode(args)
    if args.n < 1:
        raise _BadInput(f"--n {args.n}: expected a number of samples >= 1 (allowed: 1, 2, ...)")
    if args.seed < 0:
        raise _BadInput(f"--seed {args.seed}: expected an integer >= 0 (allowed: 0, 1, 2, ...)")
    if args.workers < 1:
        raise _BadInput(f"--workers {args.workers}: expected an integer >= 1 (allowed: 1, 2, ...)")
    if mode == "--sweep" and args.sweep < 1:
        raise _BadInput(f"--sweep {args.sweep}: expected a number of hint vectors >= 1 (allowed: 1, 2, ...)")
    if not math.isfinite(args.min_distance) or args.min_distance < 0:
        raise _BadInput(f"--min-distance {args.min_distance}: expected a number >= 0 (allowed: [0, inf))")
    # the solid's material and pixels per block: the TilingProperties node's ranges
    schema_value("--E", args.E, "TilingProperties", "E")
    schema_value("--nu", args.nu, "TilingProperties", "nu")
    if args.resolution is not None:
        schema_value("--resolution", args.resolution, "TilingProperties", "resolution")
    if args.hints:
        _hints(args.hints, ts)
    if args.group:
        _group_hints(args.group, ts)
    workers = 1 if args.scheduler else args.workers
    _grow_memory(size, shape, ts, samples=max(1, min(workers, args.n)),
                 resolution=args.resolution or 0)
    stop = _StopOnTerm()
    interactive = args.progress_lines or sys.stderr.isatty()
    common = dict(shape=shape, periodic=not args.bounded, seed=args.seed, E=args.E, nu=args.nu,
                  out_path=args.out, scheduler=args.scheduler, n_workers=args.workers,
                  progress=_study_progress(sys.stderr, stop, args.progress_lines),
                  resume=not args.no_resume, resolution=args.resolution, void=args.void)
    where = f"; rows so far are in {args.out} (run again to resume)" if args.out else ""
    try:
        with stop:
            summary = _run_mode(args, mode, ts, common)
    except _BadInput:
        raise
    except StudyFileError as exc:         # the engine names its argument; the user gave --out
        raise _BadInput(f"--out {exc.path}: {exc.reason}") from None
    except ValueError as exc:
        raise _BadInput(str(exc)) from None
    except KeyboardInterrupt:
        return _fail("study", f"interrupted{where}", 130)
    finally:
        if interactive and not args.progress_lines:
            print(file=sys.stderr)
    summary.pop("rows", None)
    summary["size"] = size
    if args.json:
        print(json.dumps(summary, indent=1, default=float))
    else:
        _print_study(ts, size, summary)
    if summary["cancelled"]:
        return _fail("study", f"stopped{where}", 130)
    return 0


def study_argv(tileset: str, *, n: int, size: str, groups=None, sweep: int | None = None,
               min_distance: float = 0.0, periodic: bool = True, out: str | None = None,
               seed: int = 0, workers: int = 2, scheduler: str | None = None,
               resolution: int | None = None, void: str = "removed", resume: bool = True,
               progress_lines: bool = True) -> list:
    """The arguments of a ``mesoforge study`` run (after ``mesoforge``), checked first.

    ``groups`` is a list of hint texts (``"T=1,L=1,+=2,-=1"``; ``""`` = uniform),
    one per group; or ``sweep`` a number of hint vectors drawn on the simplex.
    Raises ValueError naming the value that would be refused (a hint text by its
    group number and text), so nothing is launched that fails at once.
    """
    from engine.growth import dirichlet_hints

    ts = _tileset(tileset)
    parse_size(size, ts.ndim)
    if (groups is None) == (sweep is None):
        raise _BadInput("give either hint groups or a sweep size, not both")
    for name, v, lo in (("--n", n, 1), ("--seed", seed, 0), ("--workers", workers, 1),
                        ("--resolution", resolution or 0, 0)):
        if isinstance(v, bool) or not isinstance(v, int) or v < lo:
            raise _BadInput(f"{name} {v!r}: expected an integer >= {lo}")
    if void not in ("removed", "soft"):
        raise _BadInput(f"--void {void!r}: expected 'removed' or 'soft'")
    argv = ["study", str(tileset), "--n", str(n), "--size", size, "--seed", str(seed)]
    if groups is not None:
        texts = [str(t).strip() for t in groups]
        if not texts:
            raise _BadInput("no hint groups: give at least one hint text (empty = uniform)")
        _group_hints(texts, ts, label="hint group")
        for t in texts:
            argv += ["--group", t]
    else:
        if isinstance(sweep, bool) or not isinstance(sweep, int) or sweep < 1:
            raise _BadInput(f"--sweep {sweep!r}: expected a number of hint vectors >= 1")
        try:
            dirichlet_hints(ts.n_blocks, sweep, min_distance=float(min_distance), rng=seed)
        except ValueError as exc:
            raise _BadInput(f"--sweep {sweep} --min-distance {min_distance}: {exc}") from None
        argv += ["--sweep", str(sweep), "--min-distance", repr(float(min_distance))]
    if not periodic:
        argv.append("--bounded")
    if out:
        if Path(out).suffix.lower() not in (".csv", ".parquet"):
            raise _BadInput(f"--out {str(out)!r}: expected a .csv or .parquet file")
        argv += ["--out", str(out)]
    if scheduler:
        argv += ["--scheduler", scheduler]
    else:
        argv += ["--workers", str(workers)]
    if resolution:
        argv += ["--resolution", str(int(resolution))]
    if void != "removed":
        argv += ["--void", void]
    if not resume:
        argv.append("--no-resume")
    if progress_lines:
        argv.append("--progress-lines")
    return argv + ["--json"]


def study_process(argv) -> tuple:
    """``(program, arguments)`` running ``mesoforge`` with ``argv`` in a fresh Python
    process (the window runs studies out of process: Dask stays out of the GUI)."""
    return sys.executable, ["-m", "app.cli", *argv]


def run(args) -> int:
    from app.flags import FlagError

    try:
        return _grow(args) if args.command == "grow" else _study(args)
    except (_BadInput, FlagError) as exc:
        return _fail(args.command, str(exc))
