"""The settings of a property study as `Param` schemas: one rule for the Studies
dock's fields and the flags of ``mesoforge study``.

``samples`` (``--n``), ``seed``, ``workers``, ``sweep`` and ``min_distance``
are the study's own; ``resolution`` is the Tiling Properties node's parameter
(`resolution_param`), with the rule its range cannot say (`check_resolution`).
The study seed takes any 64-bit unsigned integer (``numpy.random.SeedSequence``
entropy); a sweep's ``min_distance`` is bounded only by what
``engine.growth.dirichlet_hints`` can place (the simplex's diameter is sqrt 2).
``sample`` picks a sample of a group in the dock's plot (-1: the group's mean),
its maximum set by the data.
"""

from __future__ import annotations

from engine.graph import Param

__all__ = ["SAMPLES", "SEED", "WORKERS", "SWEEP", "MIN_DISTANCE", "SAMPLE", "STUDY_PARAMS",
           "resolution_param", "check_resolution", "expected"]

SAMPLES = Param("samples", "int", 100, 1, None, label="number of samples",
                doc="samples grown for each hint group (or hint vector)")
SEED = Param("seed", "int", 0, 0, 2**64 - 1,
             doc="study seed: sample i grows with sample_seed(seed, i)")
WORKERS = Param("workers", "int", 2, 1, None, doc="worker processes of the local Dask cluster")
SWEEP = Param("sweep", "int", 20, 1, None, label="number of hint vectors",
              doc="hint vectors drawn uniformly on the simplex")
MIN_DISTANCE = Param("min_distance", "float", 0.0, 0.0, None,
                     doc="least distance between two hint vectors of a sweep (at most the "
                         "simplex's diameter, sqrt 2; fewer fit as it grows)")
SAMPLE = Param("sample", "int", -1, -1, 0,
               doc="sample of the group (its index in the study), or -1: the group's mean curve")

STUDY_PARAMS = {p.name: p for p in (SAMPLES, SEED, WORKERS, SWEEP, MIN_DISTANCE)}


def resolution_param() -> Param:
    """The Tiling Properties node's ``resolution`` (pixels or voxels per block edge; 0: default)."""
    from engine.graph import node_type

    return node_type("TilingProperties").param("resolution")


def check_resolution(value) -> None:
    """ValueError unless ``value`` is 0 (the default: 20 in 2D, 10 in 3D) or >= 2."""
    if value == 1:
        raise ValueError("expected 0 (the default: 20 in 2D, 10 in 3D) or >= 2 px")


def expected(param: Param) -> str:
    """What ``param`` takes, in words for a refusal: ``"a number of samples >= 1"``,
    ``"an integer in [0, 18446744073709551615]"``."""
    noun = ("a " + param.label) if param.label else ("an integer" if param.kind == "int" else "a number")
    lo, hi = param.minimum, param.maximum
    fmt = (lambda v: str(int(v))) if param.kind == "int" else (lambda v: f"{v:g}")
    if hi is None:
        return f"{noun} >= {fmt(lo)}"
    return f"{noun} in [{fmt(lo)}, {fmt(hi)}]"
