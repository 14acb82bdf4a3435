"""The codecs of the values stateful nodes keep in project files.

Registered with `engine.graph.codec` when ``engine.nodes`` is imported; the
default ``NodeType.encode_state`` / ``decode_state`` use them, chosen by the
node's output port types.  Each format is the one project files have held
since the node was written (the dicts are byte-for-byte what the nodes'
own encoders gave):

* "Tiling" (TilingValue, Grow): ``{"tiling": <tiling document>}``
  (engine.growth.tiling_io); decoded against the tile set input.
* "RDStructures" (RDStructuresValue, RDGrow): ``engine.nodes.rd_state``'s
  blob; decoded against the RD fields input.
* "PhasorInfill" (PhasorInfill, PhasorNoise): engine.phasor.infill_io's
  dict (phases only; the kernels are resampled); decoded against the
  phasor fields input.

A decoder finds the input it needs by its class (the one input value of
that class), so a codec does not depend on a node's port names.  Port types
without a codec here (e.g. "PhasorFields": the painted fields follow from the
parameters alone) are not kept.
"""

from __future__ import annotations

from engine.graph.codec import register_codec
from engine.growth.tileset import TileSet
from engine.growth.tiling_io import tiling_from_dict, tiling_to_dict
from engine.growth.values import TilingValue
from engine.phasor.infill import PhasorInfill
from engine.phasor.infill_io import infill_from_dict, infill_to_dict
from engine.phasor.values import PhasorFieldsValue
from engine.rd.values import RDFieldsValue, RDStructuresValue

from . import rd_state

__all__ = ["input_of"]


def input_of(inputs: dict, cls: type, missing: str):
    """The one value of class ``cls`` among a node's ``inputs`` ({port: value});
    ValueError(``missing``) when there is none, ValueError when there are several."""
    found = [v for v in inputs.values() if isinstance(v, cls)]
    if not found:
        raise ValueError(missing)
    if len(found) > 1:
        raise ValueError(f"{len(found)} inputs are {cls.__name__}; expected one")
    return found[0]


# ------------------------------------------------------------------ Tiling

def _encode_tiling(value: TilingValue) -> dict:
    return {"tiling": tiling_to_dict(value.tiling, value.tileset)}


def _decode_tiling(blob: dict, inputs: dict) -> TilingValue:
    ts = input_of(inputs, TileSet, "no tile set is connected")
    if not isinstance(blob, dict) or not isinstance(blob.get("tiling"), dict):
        raise ValueError("expected {'tiling': <tiling document>}")
    return TilingValue(tiling_from_dict(blob["tiling"], ts, source="stored tiling"), ts)


# ------------------------------------------------------------------ RDStructures

def _encode_structures(value: RDStructuresValue) -> dict | None:
    return rd_state.encode_structures(value)


def _decode_structures(blob: dict, inputs: dict) -> RDStructuresValue:
    source = input_of(inputs, RDFieldsValue, "no RD fields are connected")
    return rd_state.decode_structures(blob, source)


# ------------------------------------------------------------------ PhasorInfill

def _decode_infill(blob: dict, inputs: dict) -> PhasorInfill:
    fv = input_of(inputs, PhasorFieldsValue, "no fields are connected")
    return infill_from_dict(blob, fv.fields, fv.domain)


register_codec(TilingValue, "Tiling", _encode_tiling, _decode_tiling)
register_codec(RDStructuresValue, "RDStructures", _encode_structures, _decode_structures)
register_codec(PhasorInfill, "PhasorInfill", infill_to_dict, _decode_infill)
