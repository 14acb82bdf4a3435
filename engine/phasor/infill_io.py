"""A phasor infill as a JSON-able dict (what a project file keeps of a PhasorNoise node).

The oscillators are what a fresh sample of the current fields gives (a
resample reuses the same random draws), so only the phases, which carry the
history of local re-alignments, are stored, with what the sample needs::

    {"n": kernels, "seed": sampling seed, "per_cell": ..., "c": ...,
     "iterations": ..., "filtered": ..., "filter_scale": ...,
     "fields_sha256": "<sha256 hex of D, F, Gamma, lo, hi as float64>",
     "phase_v": "<base64 of zlib of n little-endian float64>", "phase_w": ...}

No graph import here (``engine.nodes.codecs`` registers these as the codec
of port type "PhasorInfill").
"""

from __future__ import annotations

import base64
import hashlib
import zlib

import numpy as np

from .infill import PhasorInfill

__all__ = ["infill_to_dict", "infill_from_dict", "fields_digest"]


def fields_digest(fields) -> str:
    """sha256 hex of a PhasorFields' D, F, Gamma and box (float64 bytes)."""
    h = hashlib.sha256()
    for a in (fields.direction, fields.frequency, fields.spread, fields.lo, fields.hi):
        h.update(np.ascontiguousarray(a, dtype=np.float64).tobytes())
    return h.hexdigest()


def _pack(a) -> str:
    return base64.b64encode(zlib.compress(np.ascontiguousarray(a, "<f8").tobytes(), 6)).decode("ascii")


def _unpack(text, n) -> np.ndarray:
    a = np.frombuffer(zlib.decompress(base64.b64decode(text.encode("ascii"), validate=True)), "<f8")
    if a.shape != (n,):
        raise ValueError(f"expected {n} stored phases, found {a.size}")
    return a.astype(np.float64)


def infill_to_dict(infill: PhasorInfill) -> dict:
    """The JSON-able dict of ``infill`` (see the module docstring)."""
    k = infill.kernels
    return {"n": k.n, "seed": k.seed, "per_cell": k.info.get("per_cell"), "c": k.info.get("c"),
            "iterations": infill.iterations, "filtered": infill.filtered,
            "filter_scale": infill.filter_scale, "fields_sha256": fields_digest(infill.fields),
            "phase_v": _pack(k.phase_v), "phase_w": _pack(k.phase_w)}


def infill_from_dict(blob: dict, fields, domain=None) -> PhasorInfill:
    """The infill `infill_to_dict` stored, resampled on ``fields`` (PhasorFields)
    with the stored phases, over ``domain`` (the part, or None).

    Raises ValueError when the dict is malformed, ``fields`` differ from the
    ones the infill was stored with, or the sample gives another kernel count.
    """
    from .attenuation import attenuation_grid
    from .sampling import sample_kernels

    try:
        n, seed, per_cell, c = int(blob["n"]), int(blob["seed"]), int(blob["per_cell"]), float(blob["c"])
        digest = blob["fields_sha256"]
        options = (int(blob["iterations"]), bool(blob["filtered"]), float(blob["filter_scale"]))
    except (KeyError, TypeError, ValueError) as exc:
        raise ValueError(f"malformed stored noise ({exc!r})") from None
    if digest != fields_digest(fields):
        raise ValueError("the fields changed since the noise was stored")
    kernels = sample_kernels(fields, per_cell=per_cell, c=c, rng=seed)
    if kernels.n != n:
        raise ValueError(f"expected {n} kernels, sampling gives {kernels.n}")
    kernels = kernels.with_phases(_unpack(blob["phase_v"], n), _unpack(blob["phase_w"], n))
    return PhasorInfill(kernels, fields, domain, options[1], options[2],
                        attenuation_grid(fields, radius=kernels.radius), options[0])
