"""`mesoforge study`: property distributions of grown samples (Figs. 3, 4).

    mesoforge study TILESET [--hints ... | --group HINTS [--group HINTS ...] | --sweep N]
                    [--n 100] [--size 20x20] [--out study.csv]
                    [--scheduler ADDRESS|synchronous] [--seed S] [--progress-lines] [--json]

Each sample is the graph TileSet → Grow → Tiling Properties evaluated by the
Evaluator with the Grow node's ``seed`` parameter set to the sample's seed
(``engine.batch``); ``--seed`` is the study seed (sample ``i`` grows with
``sample_seed(seed, i)``). The flags that set node parameters (``--size``,
``--hints``, ``--E``, ``--nu``, ``--resolution``, ``--void``) come from the
nodes' schemas (`app.schema_flags`); the study's own (``--n``, ``--seed``,
``--workers``, ``--sweep``, ``--min-distance``) from
`engine.batch.study_params`, the schemas the Studies dock's fields use.

A study grows ``--n`` samples from one set of ``--hints``; with ``--group``
(repeated) it grows ``--n`` samples of each hint group into one file (set
``j`` = group ``j``, Fig. 3B); with ``--sweep N`` it grows ``--n`` samples of
each of N hint vectors spread over the simplex (a database, Fig. 4).

While a study runs, SIGTERM asks it to stop: pending samples are cancelled,
the Dask cluster is closed and the command exits with 130, leaving whole rows
in ``--out`` (a second SIGTERM interrupts at once). ``--progress-lines``
prints ``progress DONE TOTAL`` lines on stderr as rows arrive, for the window
(``ui.study_panel``), which builds its command with
``engine.batch.study_process.study_argv``.
"""

from __future__ import annotations

import json
import signal
import sys
import time

from app.flags import FlagError

GROW_FLAGS = {"size": "--size", "hints": "--hints"}
PROPERTY_FLAGS = {"E": "--E", "nu": "--nu", "resolution": "--resolution", "void": "--void"}
_flags: dict = {}       # node type -> ParamFlags (set by add_parser)


def add_parser(sub) -> None:
    """Register ``study`` on the subparsers ``sub``."""
    from app.schema_flags import add_param_flags, help_text
    from engine.batch.study_params import MIN_DISTANCE, SAMPLES, SEED, SWEEP, WORKERS

    s = sub.add_parser("study", help="property distribution of grown samples (Fig. 3)")
    s.add_argument("tileset", help="tile set name (resources/tilesets) or JSON file")
    _flags["Grow"] = add_param_flags(s, "Grow", GROW_FLAGS, help_extra={
        "size": "NXxNY or NXxNYxNZ; a study's default is 20x20 in 2D, 10x10x10 in 3D",
        "hints": "one hint set for every sample (empty: uniform over blocks)"})
    s.add_argument("--group", action="append", metavar="HINTS",
                   help="a hint group (repeat for several; '' = uniform): --n samples of each, "
                        "one set per group in --out")
    s.add_argument("--sweep", type=int, metavar="N",
                   help=f"N hint vectors drawn uniformly on the simplex: --n samples of each; "
                        f"allowed: {SWEEP.allowed()}")
    s.add_argument("--min-distance", type=float, default=MIN_DISTANCE.default, metavar="X",
                   help=help_text(MIN_DISTANCE, "--sweep only"))
    s.add_argument("--n", type=int, default=SAMPLES.default, metavar="N",
                   help=help_text(SAMPLES))
    s.add_argument("--bounded", action="store_true",
                   help="grow bounded SVEs instead of periodic cells (the Grow node's periodic off)")
    s.add_argument("--out", help="rows file, .csv (or .parquet with pyarrow); resumed if present")
    s.add_argument("--no-resume", action="store_true", help="start --out afresh")
    s.add_argument("--scheduler", help="Dask scheduler address, or 'synchronous' for no Dask "
                                       "(default: a local cluster)")
    s.add_argument("--workers", type=int, default=WORKERS.default, metavar="N",
                   help=help_text(WORKERS))
    s.add_argument("--seed", type=int, default=SEED.default, metavar="S", help=help_text(SEED))
    # --resolution typed: the window's argv round-trips it as an int
    _flags["TilingProperties"] = add_param_flags(s, "TilingProperties", PROPERTY_FLAGS, typed=("resolution",))
    s.add_argument("--progress-lines", action="store_true",
                   help="print 'progress DONE TOTAL' lines on stderr as rows arrive")
    s.add_argument("--json", action="store_true", help="print a JSON summary")


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
    from engine.batch.study_process import progress_line

    t0 = time.perf_counter()
    last = [None]

    def cb(done, total):
        if lines:
            if (done, total) != last[0]:
                last[0] = (done, total)
                print(progress_line(done, total), file=stream, flush=True)
        elif stream.isatty():
            print(f"\r  study: {done}/{total} samples, {time.perf_counter() - t0:6.1f} s",
                  end="", file=stream, flush=True)
        return not stop.requested
    return cb


def _study_mode(args) -> str:
    given = [name for name, v in (("--hints", args.hints), ("--group", args.group),
                                  ("--sweep", args.sweep is not None)) if v]
    if len(given) > 1:
        raise ValueError(f"{' and '.join(given)}: give only one of --hints, --group "
                         f"(repeated) or --sweep")
    return given[0] if given else "--hints"


def _parse(flag: str, text, ts):
    from engine.batch import parse_hints
    try:
        return parse_hints(text or "", ts)
    except ValueError as exc:
        raise ValueError(f"{flag}: {exc}") from None


def _group_hints(texts, ts) -> list:
    from engine.batch import parse_hints
    out = []
    for k, text in enumerate(texts):
        try:
            out.append(parse_hints(text, ts))
        except ValueError as exc:
            raise ValueError(f"--group {k + 1} {text!r}: {exc}") from None
    return out


def _run_mode(args, mode, ts, common) -> dict:
    from engine.batch import run_study, sweep_hints
    from engine.batch.study_groups import study_hint_groups

    if mode == "--group":
        return study_hint_groups(ts, _group_hints(args.group, ts), samples_per_group=args.n, **common)
    if mode == "--sweep":
        return sweep_hints(ts, n_hint_sets=args.sweep, samples_per_set=args.n,
                           min_distance=args.min_distance, **common)
    return run_study(ts, hints=_parse("--hints", args.hints, ts), n_samples=args.n, **common)


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


def study_flag(flag: str, param, value):
    """``value`` of ``flag`` coerced by the study setting ``param`` (the Studies dock's rule,
    `engine.batch.study_params`); FlagError naming the flag and the allowed range."""
    from engine.graph import ParamError

    try:
        return param.coerce(value)
    except ParamError as exc:
        from engine.batch.study_params import expected
        reason = f"expected {expected(param)}" if param.label else \
            ("out of range" if exc.expected.startswith("a value in") else f"expected {exc.expected}")
        raise FlagError(flag, value, reason, param.allowed()) from None


def _check_study_values(args, mode: str, props: dict) -> None:
    from engine.batch.study_params import (MIN_DISTANCE, SAMPLES, SEED, SWEEP, WORKERS,
                                           check_resolution, resolution_param)

    for flag, param, v in (("--n", SAMPLES, args.n), ("--seed", SEED, args.seed),
                           ("--workers", WORKERS, args.workers),
                           ("--min-distance", MIN_DISTANCE, args.min_distance)):
        study_flag(flag, param, v)
    if mode == "--sweep":
        study_flag("--sweep", SWEEP, args.sweep)
    try:
        check_resolution(props["resolution"])
    except ValueError as exc:
        raise FlagError("--resolution", props["resolution"], str(exc), resolution_param().allowed()) from None


def _check(args, ts) -> tuple:
    """Every refusal before any work: (size text, grid shape, node parameters)."""
    from app.flags import memory_value
    from app.grow_cmd import check_size
    from app.schema_flags import param_values
    from engine.graph import node_type
    from engine.nodes.growth import tiling_properties_bytes

    size = args.size or ("20x20" if ts.ndim == 2 else "10x10x10")
    if args.size is None:
        args.size = size
    grow = param_values(args, _flags["Grow"])
    check_size("--size", size, grow["size"], ts)
    props = param_values(args, _flags["TilingProperties"], only_given=False)   # the node's defaults
    mode = _study_mode(args)
    _check_study_values(args, mode, props)
    if args.hints:
        _parse("--hints", args.hints, ts)
    if args.group:
        _group_hints(args.group, ts)
    shape = tuple(grow["size"][::-1])
    workers = 1 if args.scheduler else args.workers
    need = node_type("Grow").memory_estimate({"size": grow["size"]}, {"tileset": ts})
    need += tiling_properties_bytes(shape, props["resolution"])  # each sample is homogenized
    lower = "--size or --resolution" + (" or --workers" if args.n > 1 and workers > 1 else "")
    memory_value("--size", size, need * max(1, min(workers, args.n)), lower=lower)
    return size, shape, mode, props


def run(args) -> int:
    """``mesoforge study``: exit 0, 2 (bad input), 130 (stopped or interrupted)."""
    from app.flags import output_path
    from app.grow_cmd import tileset_node
    from engine.batch.rows import StudyFileError

    output_path("--out", args.out, (".csv", ".parquet"))
    ts, _ = tileset_node(args.tileset)
    size, shape, mode, props = _check(args, ts)
    stop = _StopOnTerm()
    interactive = args.progress_lines or sys.stderr.isatty()
    common = dict(shape=shape, periodic=not args.bounded, seed=args.seed, out_path=args.out,
                  scheduler=args.scheduler, n_workers=args.workers,
                  progress=_study_progress(sys.stderr, stop, args.progress_lines),
                  resume=not args.no_resume, resolution=props["resolution"] or None,
                  E=props["E"], nu=props["nu"], void=props["void"])
    where = f"; rows so far are in {args.out} (run again to resume)" if args.out else ""
    try:
        with stop:
            summary = _run_mode(args, mode, ts, common)
    except StudyFileError as exc:         # the engine names its argument; the user gave --out
        raise ValueError(f"--out {exc.path}: {exc.reason}") from None
    except KeyboardInterrupt:
        print(f"mesoforge study: interrupted{where}", file=sys.stderr)
        return 130
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
        print(f"mesoforge study: stopped{where}", file=sys.stderr)
        return 130
    return 0
