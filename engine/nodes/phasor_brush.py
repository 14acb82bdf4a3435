"""The settings of the Phasor dock's brush as `Param` schemas, from the stroke's own limits.

The brush makes an `engine.phasor.strokes.Stroke`; its numbers are checked there
(`strokes.LIMITS`).  These schemas give the dock's fields the same rule with a
unit and a default, in the units the dock shows (degrees for Gamma, tilt and
heading, which the stroke takes in radians or as a vector), and ``check`` runs
the stroke's own check on a value for what a range cannot say (``> 0``).
"""

from __future__ import annotations

import math

from engine.graph import Param
from engine.phasor.strokes import LIMITS, check_number

__all__ = ["BRUSH_PARAMS", "brush_param", "brush_check", "brush_rule"]

_DEGREES = ("Gamma", "tilt")     # the dock shows these in degrees, the stroke takes radians


def _bound(name: str, k: int):
    v = LIMITS[name][k]
    if not math.isfinite(v):
        return None
    return math.degrees(v) if name in _DEGREES else v


def _param(name: str, default: float, unit: str, doc: str) -> Param:
    return Param(name, "float", default, _bound(name, 0), _bound(name, 1), unit=unit, doc=doc)


BRUSH_PARAMS = {p.name: p for p in (
    _param("radius", 2.0, "mm", "brush radius in the slice plane"),
    _param("strength", 1.0, "", "how much of the painted value a stroke's centre takes (1: all)"),
    _param("F", 1.0, "cells/mm", "the frequency F painted"),
    _param("Gamma", 30.0, "°", "the angular spread Gamma painted"),
    _param("tilt", 0.0, "°", "D: tilt of the painted direction out of the slice plane, towards +normal"),
    Param("heading", "float", 0.0, -360.0, 360.0, unit="°",
          doc="D (when fixed): the in-plane heading painted, from the plane's first axis"),
    Param("depth", "float", 0.0, 0.0, None, unit="mm",
          doc="how far the brush reaches out of the slice plane (0: as far as its radius)"),
)}


def brush_param(name: str) -> Param:
    """The schema of brush setting ``name`` (radius, strength, F, Gamma, tilt, heading, depth)."""
    return BRUSH_PARAMS[name]


def brush_rule(name: str) -> str:
    """What the stroke's check adds to the range, in words ("> 0"), or ""."""
    if name in LIMITS and LIMITS[name][2]:
        return f"> {LIMITS[name][0]:g}"
    return ""


def brush_check(name: str):
    """callable(value shown by the dock) raising the stroke's ValueError, or None."""
    if name not in LIMITS:
        return None
    to_stroke = math.radians if name in _DEGREES else float
    field = "value" if name in ("F", "Gamma") else None
    return lambda v: check_number(name, to_stroke(v), field=field)
