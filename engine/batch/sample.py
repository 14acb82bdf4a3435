"""One study sample: grow a tiling, homogenize it, make its row.

``evaluate_sample`` is what the workers run: the sample's graph TileSet →
Grow → TilingProperties (``engine.batch.sample_graph``, the Grow node's
``seed`` parameter set to the sample's seed) evaluated by the Evaluator. It
depends only on its arguments (the study configuration and the sample's
seed and hints) and solves with one numba thread and one BLAS thread, so a
row is bit-for-bit the same whichever scheduler, worker or order produced it
(on machines with the same numpy / scipy builds; the ``seconds`` cell
excepted).
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from dataclasses import dataclass

import numpy as np

from engine.growth import TileSet, hint_table, realised_probabilities
from engine.growth.properties import constant_names, constants_of
from engine.progress import Cancelled

from .hints_text import format_hints
from .sample_graph import GraphSampleError, evaluate_study_graph, study_document

__all__ = ["StudyConfig", "Sample", "sample_seed", "columns", "evaluate_sample",
           "block_hints", "STATUS_OK", "STATUS_SINGULAR", "STATUS_ERROR"]

STATUS_OK = "ok"              # properties computed
STATUS_SINGULAR = "singular"  # the tiling is a mechanism: C not positive definite
STATUS_ERROR = "error"        # growth or solve failed; see the "error" cell


@dataclass(frozen=True)
class StudyConfig:
    """What every sample of a study shares (plain, picklable data).

    shape is the grid shape ``(ny, nx)`` / ``(nz, ny, nx)``; ``availability``
    None means unlimited blocks; the rest are the options of
    ``engine.growth.properties.homogenize_tiling``.
    """

    tileset: TileSet
    shape: tuple
    periodic: bool
    availability: float | None
    E: float
    nu: float
    resolution: int
    line_width: float
    radius: float
    void: str
    tol: float

    @property
    def ndim(self) -> int:
        return len(self.shape)

    def key(self, hints) -> str:
        """Short hash of everything that decides a sample's row besides its seed."""
        ts = self.tileset
        doc = {"tileset": ts.name, "tiles": list(ts.tile_names),
               "allowed": hashlib.sha256(np.ascontiguousarray(ts.allowed).tobytes()).hexdigest(),
               "shape": list(self.shape), "periodic": self.periodic,
               "availability": self.availability, "E": self.E, "nu": self.nu,
               "resolution": self.resolution, "line_width": self.line_width,
               "radius": self.radius, "void": self.void, "tol": self.tol,
               "hints": format_hints(hints)}
        text = json.dumps(doc, sort_keys=True, separators=(",", ":"))
        # the "h" keeps the cell a string when read back (a bare hex string may look numeric)
        return "h" + hashlib.sha256(text.encode()).hexdigest()[:16]


@dataclass(frozen=True)
class Sample:
    """One sample: its place in the study, its seed and its hints.

    hints : mapping block or tile name -> weight, as ``grow_tiling`` takes it.
    """

    set: int
    index: int
    seed: int
    hints: dict


def sample_seed(study_seed: int, *path: int) -> int:
    """Seed of a sample from the study seed and its index path.

    ``numpy.random.SeedSequence(study_seed, spawn_key=path)``: the same child
    ``SeedSequence.spawn`` would hand out, computed directly, so it depends
    only on the study seed and the index (``(i,)`` for a study, ``(set, i)``
    for a hint sweep), never on scheduling. Returns a 63-bit int.
    """
    ss = np.random.SeedSequence(int(study_seed), spawn_key=tuple(int(p) for p in path))
    return int(ss.generate_state(1, dtype=np.uint64)[0] >> np.uint64(1))


def block_hints(tileset: TileSet, hints, shape) -> np.ndarray:
    """(n_blocks,) normalised total hint of each block (its tiles' weights summed)."""
    table = hint_table(tileset, hints, shape).mean(axis=0)
    per_block = np.zeros(tileset.n_blocks)
    np.add.at(per_block, tileset.tile_block, table)
    return per_block / per_block.sum()


def _c_names(ndim: int) -> list:
    n = 3 if ndim == 2 else 6
    return [f"C{i + 1}{j + 1}" for i in range(n) for j in range(i, n)]


def columns(config: StudyConfig) -> list:
    """Column names of a study file for this configuration, in file order."""
    blocks = config.tileset.block_names
    return (["set", "index", "seed", "tileset", "shape", "periodic", "availability", "hints"]
            + [f"hint_{b}" for b in blocks]
            + ["status", "error", "n_defects"]
            + [f"p_{b}" for b in blocks]
            + ["density", "dropped_fraction"] + _c_names(config.ndim)
            + list(constant_names(config.ndim)) + ["E_avg/E_s"]
            + ["E_s", "nu_s", "resolution", "member", "void", "iterations", "seconds", "config"])


def _grown(row: dict, tiling, ts) -> None:
    row["n_defects"] = tiling.n_defects
    row.update({f"p_{b}": float(p) for b, p in zip(ts.block_names, realised_probabilities(tiling, ts))})


def evaluate_sample(config: StudyConfig, sample: Sample, progress=None) -> dict:
    """Grow and homogenize one sample; return its row (column -> value).

    A failure of growth or solve becomes a row with ``status = "error"`` and
    the message, so one bad sample never stops a study; a cancel
    (``progress`` returned False) propagates as ``Cancelled``.
    """
    t0 = time.perf_counter()
    ts, ndim = config.tileset, config.ndim
    hv = block_hints(ts, sample.hints, config.shape)
    row = {"set": sample.set, "index": sample.index, "seed": sample.seed, "tileset": ts.name,
           "shape": "x".join(str(s) for s in config.shape[::-1]), "periodic": config.periodic,
           "availability": config.availability, "hints": format_hints(sample.hints),
           "E_s": config.E, "nu_s": config.nu, "resolution": config.resolution,
           "member": config.line_width if ndim == 2 else config.radius, "void": config.void,
           "config": config.key(sample.hints)}
    row.update({f"hint_{b}": float(w) for b, w in zip(ts.block_names, hv)})
    nan_cols = ["density", "dropped_fraction", *_c_names(ndim), *constant_names(ndim), "E_avg/E_s"]
    row.update({c: math.nan for c in nan_cols})
    row.update({f"p_{b}": math.nan for b in ts.block_names})
    try:
        doc = study_document(config, sample.hints, sample.seed)
        tv, res = evaluate_study_graph(doc, progress=progress)
    except Cancelled:
        raise
    except GraphSampleError as exc:   # recorded in the row: one bad sample never stops a study
        if exc.value is not None:      # grown, not homogenized
            _grown(row, exc.value.tiling, ts)
        row.update(status=STATUS_ERROR, error=str(exc), seconds=time.perf_counter() - t0)
        return row
    except Exception as exc:          # a value the nodes' schemas refuse
        row.update(status=STATUS_ERROR, error=f"{type(exc).__name__}: {exc}",
                   seconds=time.perf_counter() - t0)
        return row
    _grown(row, tv.tiling, ts)
    C = np.asarray(res.C, dtype=np.float64)
    n = C.shape[0]
    row.update({f"C{i + 1}{j + 1}": float(C[i, j]) for i in range(n) for j in range(i, n)})
    consts = constants_of(C, ndim)
    row.update(consts)
    row["E_avg/E_s"] = consts["E_avg"] / config.E
    row.update(status=STATUS_SINGULAR if math.isnan(consts["E_avg"]) else STATUS_OK, error=None,
               density=float(res.density), dropped_fraction=float(res.dropped_fraction),
               iterations=int(res.iterations), seconds=time.perf_counter() - t0)
    return row
