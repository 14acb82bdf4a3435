"""A study run in its own process: its arguments and its progress lines.

The window runs studies out of process (Dask stays out of the GUI): it
builds the arguments of ``mesoforge study`` with `study_argv`, starts
`study_process` and reads ``progress DONE TOTAL`` lines (`progress_line`,
`parse_progress_line`) from the child's stderr. The command line
(``app.study_cmd``) prints those lines; both sides import them from here.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

__all__ = ["study_argv", "study_process", "progress_line", "parse_progress_line", "parse_size"]


def progress_line(done: int, total: int) -> str:
    """The line a study prints as rows arrive: ``progress DONE TOTAL``."""
    return f"progress {int(done)} {int(total)}"


def parse_progress_line(line: str):
    """``(done, total)`` from a ``progress DONE TOTAL`` line, else None."""
    parts = line.split()
    if len(parts) == 3 and parts[0] == "progress" and parts[1].isdigit() and parts[2].isdigit():
        return int(parts[1]), int(parts[2])
    return None


def parse_size(text: str, ndim: int) -> tuple:
    """``"20x20"`` / ``"20x20x10"`` (nx x ny [x nz]) -> grid shape ``(ny, nx)`` / ``(nz, ny, nx)``.

    The counts are checked by the Grow node's ``size`` schema and its cell
    limit (MAX_CELLS); ValueError naming ``--size`` otherwise."""
    from engine.graph import ParamError, node_type
    from engine.nodes.growth import MAX_CELLS

    parts = str(text).lower().replace("*", "x").split("x")
    try:
        n = [int(p) for p in parts]
    except ValueError:
        raise ValueError(f"--size {text!r}: expected integers like 20x20 or 10x10x10") from None
    if len(n) != ndim:
        want = "NXxNY" if ndim == 2 else "NXxNYxNZ"
        raise ValueError(f"--size {text!r}: the tile set is {ndim}D, expected {want}")
    param = node_type("Grow").param("size")
    try:
        param.coerce(n)
    except ParamError:
        raise ValueError(f"--size {text!r}: every count must be in [{param.minimum:g}, {param.maximum:g}] "
                         f"(allowed: {param.allowed()})") from None
    if math.prod(n) > MAX_CELLS:
        raise ValueError(f"--size {text!r}: {math.prod(n)} cells is more than {MAX_CELLS} "
                         f"(allowed: at most {MAX_CELLS} cells)")
    return tuple(n[::-1])


def _tileset(text: str):
    from engine.growth import load_tileset
    try:
        return load_tileset(text)
    except ValueError as exc:
        raise ValueError(f"TILESET {text!r}: {exc}") from None


def _check_groups(texts, ts) -> None:
    from .hints_text import parse_hints
    for k, text in enumerate(texts):
        try:
            parse_hints(text, ts)
        except ValueError as exc:
            raise ValueError(f"hint group {k + 1} {text!r}: {exc}") from None


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
    from engine.graph import ParamError, node_type
    from engine.growth import dirichlet_hints

    ts = _tileset(tileset)
    parse_size(size, ts.ndim)
    if (groups is None) == (sweep is None):
        raise ValueError("give either hint groups or a sweep size, not both")
    from .study_params import SAMPLES, SEED, WORKERS, check_resolution, expected, resolution_param

    for flag, param, v in (("--n", SAMPLES, n), ("--seed", SEED, seed), ("--workers", WORKERS, workers),
                           ("--resolution", resolution_param(), resolution or 0)):
        try:                                    # the rules of the dock's fields and the CLI's flags
            if isinstance(v, bool) or not isinstance(v, int):
                raise ParamError(param.name, v, "an integer")
            param.coerce(v)
        except ParamError:
            raise ValueError(f"{flag} {v!r}: expected {expected(param)}") from None
        if flag == "--resolution":
            try:
                check_resolution(v)
            except ValueError as exc:
                raise ValueError(f"{flag} {v!r}: {exc}") from None
    void_param = node_type("TilingProperties").param("void")
    try:
        void_param.coerce(void)
    except ParamError:
        raise ValueError(f"--void {void!r}: expected {' or '.join(map(repr, void_param.choices))}") from None
    argv = ["study", str(tileset), "--n", str(n), "--size", size, "--seed", str(seed)]
    if groups is not None:
        texts = [str(t).strip() for t in groups]
        if not texts:
            raise ValueError("no hint groups: give at least one hint text (empty = uniform)")
        _check_groups(texts, ts)
        for t in texts:
            argv += ["--group", t]
    else:
        if isinstance(sweep, bool) or not isinstance(sweep, int) or sweep < 1:
            raise ValueError(f"--sweep {sweep!r}: expected a number of hint vectors >= 1")
        try:
            dirichlet_hints(ts.n_blocks, sweep, min_distance=float(min_distance), rng=seed)
        except ValueError as exc:
            raise ValueError(f"--sweep {sweep} --min-distance {min_distance}: {exc}") from None
        argv += ["--sweep", str(sweep), "--min-distance", repr(float(min_distance))]
    if not periodic:
        argv.append("--bounded")
    if out:
        if Path(out).suffix.lower() not in (".csv", ".parquet"):
            raise ValueError(f"--out {str(out)!r}: expected a .csv or .parquet file")
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
