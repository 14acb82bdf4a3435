"""Property studies and hint databases of virtual-growth materials (Figs. 3, 4, 6).

``run_study`` grows ``n_samples`` tilings from one set of frequency hints,
homogenizes each and summarises the distribution of ``E_avg`` and
``nu_avg`` (the paper: 100 samples of 20 x 20 per group, Fig. 3B-C).
``sweep_hints`` does the same for hint vectors sampled uniformly on the
simplex with a minimum spacing (Supplementary Text, ``dirichlet_hints``),
producing the paper's kind of database: one row per sample with its hint
vector, realised probabilities and properties.

Output files
------------
``*.csv``: a tag line naming the study's parameters (``# mesoforge-study v1
{...}``; ``engine.batch.study_file``), one header line, then one row per
sample, appended as results arrive (``engine.batch.rows``): an interrupted
run leaves only complete rows (plus at most a partial last line, cut off on
resume) and ``resume=True`` runs only the samples not yet in the file. A
file that is not a study file, or (when resuming) holds another study, is
refused with ``StudyFileError`` before anything is written or grown, and is
left exactly as it was. Columns, in order
(``engine.batch.sample.columns``): ``set, index, seed, tileset, shape
("nx x ny[x nz]"), periodic, availability, hints`` (text ``name=w,...``),
``hint_<block>`` (normalised block hints), ``status`` (ok / singular /
error), ``error``, ``n_defects``, ``p_<block>`` (realised probabilities),
``density, dropped_fraction``, the upper triangle of ``C`` (``C11, C12,
...``; Voigt, engineering shear, tiling axes, units of ``E_s``), the
constants of eqs. 1-8 (``E_x ... nu_avg``), ``E_avg/E_s``, the options
(``E_s, nu_s, resolution, member`` = line width in px (2D) or beam radius in
block units (3D), ``void``), ``iterations, seconds`` and ``config`` (a hash
of everything besides the seed that decides the row).

``*.parquet`` (needs pyarrow): rows are journaled to ``<name>.parquet.rows.csv``
exactly as above and the Parquet file (tagged in its schema metadata) is
rewritten from the journal at the end of every run.

Seeds: sample ``i`` of a study uses ``sample_seed(seed, i)``, sample ``i`` of
hint set ``j`` of a sweep ``sample_seed(seed, j, i)`` (``SeedSequence``
children), so rows do not depend on the scheduler or on arrival order.
"""

from __future__ import annotations

import math
import os
import time
from pathlib import Path

import numpy as np

from engine.growth import TileSet, dirichlet_hints, hint_table, load_tileset
from engine.growth.properties import check_options

from .rows import StudyFileError, read_rows
from .runner import run_samples
from .sample_graph import check_tileset
from .sample import (STATUS_ERROR, STATUS_OK, STATUS_SINGULAR, Sample, StudyConfig, block_hints,
                     columns, evaluate_sample, sample_seed)
from .study_file import check_parquet, parquet_metadata, plan_journal, read_params, study_params

__all__ = ["run_study", "sweep_hints", "read_study", "summarise_rows", "make_config"]


# ------------------------------------------------------------------ inputs

def _resolve_tileset(tileset) -> TileSet:
    if isinstance(tileset, TileSet):
        return tileset
    if not isinstance(tileset, (str, os.PathLike)):
        raise ValueError(f"tileset must be a TileSet, a tile set name or a path; got {tileset!r}")
    return load_tileset(tileset)


def _check_int(name, value, lo):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < lo:
        raise ValueError(f"{name} must be an integer >= {lo}; got {value!r}")
    return int(value)


def _check_real(name, value, lo, hi, *, open_lo=True, open_hi=True):
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool) \
        and math.isfinite(value) and (value > lo if open_lo else value >= lo) \
        and (value < hi if open_hi else value <= hi)
    if not ok:
        lb, rb = "(" if open_lo else "[", ")" if open_hi else "]"
        raise ValueError(f"{name} must be a number in {lb}{lo}, {hi}{rb}; got {value!r}")
    return float(value)


def make_config(tileset, *, shape=(20, 20), periodic=True, availability=None, E=1.0, nu=0.46,
                resolution=None, line_width=None, radius=0.2, void="removed",
                tol=1e-6) -> StudyConfig:
    """Validate the shared options of a study (see :func:`run_study`)."""
    ts = _resolve_tileset(tileset)
    try:
        shp = tuple(int(s) for s in shape)
        ok = len(shp) == ts.ndim and all(s >= 1 and s == v for s, v in zip(shp, shape))
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ValueError(f"shape must be {ts.ndim} integers >= 1 for the {ts.ndim}D tile set "
                         f"{ts.name!r}; got {shape!r}")
    if not isinstance(periodic, (bool, np.bool_)):
        raise ValueError(f"periodic must be true or false; got {periodic!r}")
    if availability is not None:
        availability = _check_real("availability", availability, 0.0, math.inf, open_lo=False,
                                   open_hi=False)
        availability = None if availability == 0 or math.isinf(availability) else availability
    E = _check_real("E", E, 0.0, math.inf)
    nu = _check_real("nu", nu, -1.0, 0.5)
    tol = _check_real("tol", tol, 0.0, 1.0)
    from engine.nodes.growth import PROPERTIES_TOL
    if tol != PROPERTIES_TOL:     # samples are solved by the Tiling Properties node
        raise ValueError(f"tol must be {PROPERTIES_TOL:g}, the solver tolerance of the Tiling "
                         f"Properties node that homogenizes each sample; got {tol!r}")
    check_tileset(ts)             # each sample's graph reads the set from its file
    resolution, line_width, radius = check_options(shp, resolution=resolution,
                                                   line_width=line_width, radius=radius,
                                                   void=void)
    return StudyConfig(ts, shp, bool(periodic), availability, E, nu, resolution, line_width,
                       radius, void, tol)


def _check_hints(ts: TileSet, hints, shape) -> dict:
    if hints is None:
        return {b: 1.0 for b in ts.block_names}       # uniform over blocks
    if not isinstance(hints, dict):
        raise ValueError(f"hints must be None or a dict block (or tile) name -> weight; "
                         f"got {hints!r}")
    hint_table(ts, hints, shape)                      # raises naming the bad key
    return {str(k): float(v) for k, v in hints.items()}


def _out_files(out_path):
    """(journal csv path, parquet path or None) for ``out_path``."""
    if out_path is None:
        return None, None
    p = Path(out_path)
    suffix = p.suffix.lower()
    if suffix == ".csv":
        return p, None
    if suffix == ".parquet":
        try:
            import pyarrow  # noqa: F401
        except ImportError:
            raise ValueError(f"out_path {str(p)!r}: writing Parquet needs pyarrow, which is not "
                             f"installed; use a .csv path") from None
        return p.with_name(p.name + ".rows.csv"), p
    raise ValueError(f"out_path must end in .csv or .parquet; got {str(p)!r}")


def _write_parquet(rows: list, cols: list, path: Path, params: dict) -> None:
    import io

    import pyarrow as pa
    import pyarrow.parquet as pq

    from engine.fileio import write_atomic
    table = pa.table({c: [r.get(c) for r in rows] for c in cols})
    table = table.replace_schema_metadata(parquet_metadata(params))
    buf = io.BytesIO()
    pq.write_table(table, buf)
    write_atomic(path, buf.getvalue())


# ------------------------------------------------------------------ summaries

def _mean_std(values) -> dict:
    v = np.asarray([x for x in values if x is not None and math.isfinite(x)], dtype=np.float64)
    if v.size == 0:
        return {"mean": math.nan, "std": math.nan, "n": 0}
    std = float(np.std(v, ddof=1)) if v.size > 1 else math.nan
    return {"mean": float(np.mean(v)), "std": std, "n": int(v.size)}


def summarise_rows(rows: list, block_names) -> dict:
    """Mean and sample standard deviation (ddof=1) of ``E_avg``, ``nu_avg``,
    ``E_avg/E_s`` over rows with status ok, mean realised probabilities over
    rows that grew, and status counts."""
    ok = [r for r in rows if r["status"] == STATUS_OK]
    grown = [r for r in rows if r["status"] in (STATUS_OK, STATUS_SINGULAR)]
    probs = {b: (float(np.mean([r[f"p_{b}"] for r in grown])) if grown else math.nan)
             for b in block_names}
    return {
        "n_done": len(rows), "n_ok": len(ok),
        "n_singular": sum(r["status"] == STATUS_SINGULAR for r in rows),
        "n_error": sum(r["status"] == STATUS_ERROR for r in rows),
        "E_avg": _mean_std(r["E_avg"] for r in ok),
        "nu_avg": _mean_std(r["nu_avg"] for r in ok),
        "E_avg/E_s": _mean_std(r["E_avg/E_s"] for r in ok),
        "realised_probabilities": probs,
    }


def read_study(path) -> list:
    """Rows of a study or database file (CSV, or a Parquet file's journal), sorted by
    ``(set, index)``; values typed as in ``engine.batch.rows.parse_cell``."""
    p = Path(path)
    if p.suffix.lower() == ".parquet":
        p = p.with_name(p.name + ".rows.csv")
    rows = read_rows(p)
    return sorted(rows, key=lambda r: (r["set"], r["index"]))


# ------------------------------------------------------------------ driver

def _open_out(journal, parquet, cols, params, wanted, resume):
    """Check the output files (reading only), then open the journal: the run's first write."""
    try:
        plan = plan_journal(journal, cols, params, wanted, resume=resume)
        if parquet is not None:
            check_parquet(parquet, cols, params, resume=resume,
                          journal_exists=plan.scan is not None)
        return plan.open()
    except StudyFileError as exc:
        raise exc.named("out_path") from None


def _execute(config: StudyConfig, samples: list, *, params: dict, out_path, scheduler,
             n_workers, progress, resume) -> dict:
    """Run the samples not yet in ``out_path``; return the rows of all ``samples``.

    ``params`` (``engine.batch.study_file.study_params``) tag the file; every
    check of the output happens before the first byte is written or the
    first sample is grown.
    """
    t0 = time.perf_counter()
    cols = columns(config)
    journal, parquet = _out_files(out_path)
    wanted = {s.seed: (s.set, s.index, config.key(s.hints)) for s in samples}
    rows_by_seed: dict = {}
    writer = None
    if journal is not None:
        writer = _open_out(journal, parquet, cols, params, wanted, resume)
        for r in writer.existing:
            if r["seed"] in wanted:
                rows_by_seed.setdefault(r["seed"], r)
    n_resumed = len(rows_by_seed)
    todo = [s for s in samples if s.seed not in rows_by_seed]

    def on_row(row: dict) -> None:
        if writer is not None:
            writer.append(row)
        rows_by_seed[row["seed"]] = row

    try:
        completed = run_samples(evaluate_sample, config, todo, on_row=on_row, scheduler=scheduler,
                                n_workers=n_workers, progress=progress, done=n_resumed,
                                total=len(samples))
    except BaseException:
        if writer is not None:          # failed before its first row: leave nothing behind
            writer.discard_if_unused()
        raise
    finally:
        if writer is not None:
            writer.close()
    if parquet is not None:
        # the journal's tag: it may list more hint groups than this run
        _write_parquet(read_rows(journal, columns=cols), cols, parquet,
                       read_params(journal) or params)
    rows = sorted(rows_by_seed.values(), key=lambda r: (r["set"], r["index"]))
    return {"rows": rows, "cancelled": not completed, "n_resumed": n_resumed,
            "n_new": len(rows) - n_resumed, "seconds": time.perf_counter() - t0,
            "out_path": None if out_path is None else str(Path(out_path))}


def run_study(tileset, *, hints=None, n_samples: int = 100, shape=(20, 20),
              periodic: bool = True, seed: int = 0, E: float = 1.0, nu: float = 0.46,
              out_path=None, scheduler=None, n_workers: int = 2, progress=None,
              resume: bool = True, availability=None, resolution: int | None = None,
              line_width: float | None = None, radius: float = 0.2, void: str = "removed",
              tol: float = 1e-6) -> dict:
    """Grow and homogenize ``n_samples`` tilings from one set of hints (Fig. 3).

    Parameters
    ----------
    tileset : TileSet, tile set name or path
    hints : dict name -> weight, optional
        Block (``"T"``) or tile (``"T@1"``) weights; None = uniform over blocks.
    n_samples : int >= 1
    shape : (ny, nx) or (nz, ny, nx); 3D grids must be cubic (voxel solver)
    periodic : bool, grow on a torus (a true periodic cell) or a bounded SVE
    seed : int >= 0, study seed; sample ``i`` uses ``sample_seed(seed, i)``
    E, nu : solid's Young's modulus and Poisson ratio (paper: Semiflex, nu = 0.46)
    out_path : ``*.csv`` or ``*.parquet`` (module docstring), or None (rows kept in memory)
    scheduler : None (local cluster of ``n_workers`` processes), ``"synchronous"``
        (in this process), a scheduler address, or a ``distributed.Client``
    progress : callable ``(done, total) -> bool``, optional
        Called as rows arrive and about every 100 ms; False stops submitting,
        cancels pending samples and returns with what was written.
    resume : bool
        Keep the complete rows already in ``out_path`` and run only the missing
        samples (a partial last line is cut off); the file must hold this
        study (same parameters, any number of samples). False starts a study
        file afresh. A file that is not a study file is never written.
    availability : float, optional, blocks per cell (0 / None = unlimited)
    resolution, line_width, radius, void, tol
        As in ``engine.growth.properties.homogenize_tiling``.

    Returns
    -------
    dict
        ``n_samples, n_done, n_ok, n_singular, n_error, n_new, n_resumed,
        cancelled, seconds, out_path, tileset, hints`` (normalised block
        hints), ``E_avg, nu_avg, E_avg/E_s`` (each ``{"mean", "std", "n"}``,
        ``std`` with ddof=1, over status-ok rows), ``realised_probabilities``
        (block -> mean), and ``rows`` (list of dicts) when ``out_path`` is None.
    """
    config = make_config(tileset, shape=shape, periodic=periodic, availability=availability,
                         E=E, nu=nu, resolution=resolution, line_width=line_width,
                         radius=radius, void=void, tol=tol)
    n_samples = _check_int("n_samples", n_samples, 1)
    seed = _check_int("seed", seed, 0)
    h = _check_hints(config.tileset, hints, config.shape)
    samples = [Sample(0, i, sample_seed(seed, i), h) for i in range(n_samples)]
    params = study_params(config, mode="hints", seed=seed, hints=[h])
    run = _execute(config, samples, params=params, out_path=out_path, scheduler=scheduler,
                   n_workers=n_workers, progress=progress, resume=resume)
    ts = config.tileset
    out = {"tileset": ts.name, "n_samples": n_samples,
           "hints": dict(zip(ts.block_names, block_hints(ts, h, config.shape).tolist()))}
    out.update(summarise_rows(run["rows"], ts.block_names))
    out.update({k: run[k] for k in ("cancelled", "n_new", "n_resumed", "seconds", "out_path")})
    if out_path is None:
        out["rows"] = run["rows"]
    return out


def sweep_hints(tileset, *, n_hint_sets: int, samples_per_set: int, min_distance: float = 0.0,
                seed: int = 0, shape=(20, 20), periodic: bool = True, E: float = 1.0,
                nu: float = 0.46, out_path=None, scheduler=None, n_workers: int = 2,
                progress=None, resume: bool = True, availability=None,
                resolution: int | None = None, line_width: float | None = None,
                radius: float = 0.2, void: str = "removed", tol: float = 1e-6) -> dict:
    """A property database over hint vectors spread on the simplex (Figs. 4, 6).

    ``n_hint_sets`` block-hint vectors come from
    ``dirichlet_hints(n_blocks, n_hint_sets, min_distance=min_distance, rng=seed)``
    (symmetric Dirichlet, kept only if farther than ``min_distance`` from every
    earlier one); each is grown ``samples_per_set`` times. Rows carry their set
    index and hint vector. Other parameters as in :func:`run_study`.

    Returns
    -------
    dict
        ``n_hint_sets, samples_per_set, n_samples``, the status counts,
        ``cancelled, n_new, n_resumed, seconds, out_path`` and ``sets``: per
        hint set ``{"set", "hints", "n_done", "n_ok", "E_avg", "nu_avg",
        "E_avg/E_s", "realised_probabilities"}``; ``rows`` when ``out_path``
        is None.
    """
    config = make_config(tileset, shape=shape, periodic=periodic, availability=availability,
                         E=E, nu=nu, resolution=resolution, line_width=line_width,
                         radius=radius, void=void, tol=tol)
    n_sets = _check_int("n_hint_sets", n_hint_sets, 1)
    per_set = _check_int("samples_per_set", samples_per_set, 1)
    seed = _check_int("seed", seed, 0)
    ts = config.tileset
    vectors = dirichlet_hints(ts.n_blocks, n_sets, min_distance=min_distance, rng=seed)
    hint_sets = [dict(zip(ts.block_names, map(float, v))) for v in vectors]
    samples = [Sample(j, i, sample_seed(seed, j, i), hint_sets[j])
               for j in range(n_sets) for i in range(per_set)]
    params = study_params(config, mode="sweep", seed=seed, min_distance=min_distance)
    run = _execute(config, samples, params=params, out_path=out_path, scheduler=scheduler,
                   n_workers=n_workers, progress=progress, resume=resume)
    by_set: dict = {j: [] for j in range(n_sets)}
    for r in run["rows"]:
        by_set[r["set"]].append(r)
    sets = []
    for j in range(n_sets):
        s = summarise_rows(by_set[j], ts.block_names)
        sets.append({"set": j, "hints": hint_sets[j], "n_done": s["n_done"], "n_ok": s["n_ok"],
                     **{k: s[k] for k in ("E_avg", "nu_avg", "E_avg/E_s",
                                          "realised_probabilities")}})
    total = summarise_rows(run["rows"], ts.block_names)
    out = {"tileset": ts.name, "n_hint_sets": n_sets, "samples_per_set": per_set,
           "n_samples": len(samples),
           **{k: total[k] for k in ("n_done", "n_ok", "n_singular", "n_error")},
           **{k: run[k] for k in ("cancelled", "n_new", "n_resumed", "seconds", "out_path")},
           "sets": sets}
    if out_path is None:
        out["rows"] = run["rows"]
    return out


