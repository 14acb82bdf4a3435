"""Scalar Field node (paper 004, section 3.1): a designed and painted 3-D scalar field
(port type "Field") that drives a spatially varying medium, e.g. a particle cloud's density
or surface offset.

Painting is data, as for PhasorFields: every brush drag in the Implicit Media dock is one
``SetParam(node, "strokes", old + [stroke.to_dict()])``.  The field is cheap (a stroke costs
its own footprint), so the node simply rebuilds it.
"""

from __future__ import annotations

import numpy as np

from engine.geometry.plane_brush import FALLOFFS
from engine.geometry.scalar_field import AXES, FieldStroke, Radial, Ramp, field_grid_shape, scalar_field
from engine.graph.errors import NodeInputError
from engine.graph.node import NodeType, register
from engine.graph.schema import Param, Port

from .implicit_common import built

__all__ = ["ScalarFieldNode", "FIELD_BYTES_PER_CELL", "MODES", "PAINT_PARAMS", "paint_param", "paint_check",
           "paint_rule"]

MODES = ("constant", "ramp", "radial")
# Peak bytes per cell: the float64 values and the Field's read-only copy, plus a stroke's
# float64 temporaries (distance, profile, blend) over its block, which may be the whole grid
# (measured 16 B for a constant field, 33 B radial, 50 B under a stroke covering the box).
FIELD_BYTES_PER_CELL = 64
_BIG = 1e6   # mm / value magnitudes beyond this are typing mistakes


def _canonical_strokes(data):
    """A stroke list in canonical form (each through FieldStroke.from_dict); ValueError names
    the stroke and its key."""
    if not isinstance(data, list):
        raise ValueError(f"a list of brush strokes, got {type(data).__name__}")
    out = []
    for i, item in enumerate(data):
        try:
            out.append(FieldStroke.from_dict(item).to_dict())
        except (ValueError, TypeError) as exc:
            raise ValueError(f"a list of brush strokes; stroke {i}: {exc}") from None
    return out


# The Implicit Media dock's brush for this node: its settings' schemas (what its number
# fields show and refuse), the rest of each rule checked by FieldStroke itself.
PAINT_PARAMS = {p.name: p for p in (
    Param("value", "float", 0.0, -_BIG, _BIG, doc="the value a stroke paints (v <- (1 - w) v + w value)"),
    Param("radius", "float", 1.0, 0.0, _BIG, unit="mm", doc="brush radius in the slice plane"),
    Param("strength", "float", 1.0, 0.0, 1.0, doc="how much of the value a stroke's centre takes (1: all)"),
    Param("depth", "float", 0.0, 0.0, _BIG, unit="mm",
          doc="how far the brush reaches out of the slice plane (0: as far as its radius)"),
)}


def paint_param(name: str) -> Param:
    """The schema of brush setting ``name`` (value, radius, strength, depth)."""
    return PAINT_PARAMS[name]


def paint_rule(name: str) -> str:
    """What the stroke's check adds to the range, in words, or ""."""
    return "> 0" if name == "radius" else ""


def paint_check(name: str):
    """callable(value) raising FieldStroke's ValueError for what a range cannot say, or None."""
    if name != "radius":
        return None
    return lambda v: FieldStroke("z", 0.0, [[0.0, 0.0]], v, 0.0)


@register
class ScalarFieldNode(NodeType):
    """A scalar field sampled at the cell centres of a box: a constant `base`, a linear ramp
    along an axis (clamped beyond its ends) or a radial bump, then painted brush strokes
    (each blends v <- (1 - w) v + w value), then optionally clamped to [clamp_lo, clamp_hi]
    (a density stays in [0, 1]).  Paint it in the Implicit Media dock."""

    type_name = "ScalarField"
    title = "Scalar Field"
    code = "sfld"
    family = "implicit"
    outputs = (Port("field", "Field", doc="kind 'scalar', values [z, y, x] at the cell centres of lo..hi"),)
    params = (
        Param("lo", "vec3", [0.0, 0.0, 0.0], -_BIG, _BIG, unit="mm", doc="box corner"),
        Param("hi", "vec3", [10.0, 10.0, 10.0], -_BIG, _BIG, unit="mm", doc="opposite box corner (> lo)"),
        Param("resolution", "int", 32, 1, 1024, unit="samples",
              doc="samples along the box's longest side (the others in proportion, at least 1)"),
        Param("mode", "enum", "constant", choices=MODES,
              doc="constant: base everywhere; ramp: linear along ramp_axis; radial: a bump around centre"),
        Param("base", "float", 1.0, -_BIG, _BIG, doc="the value everywhere (mode constant)"),
        Param("ramp_axis", "enum", "z", choices=AXES, doc="ramp: the axis it runs along"),
        Param("ramp_from", "float", 0.0, -_BIG, _BIG, unit="mm", doc="ramp: coordinate of value_from"),
        Param("ramp_to", "float", 10.0, -_BIG, _BIG, unit="mm",
              doc="ramp: coordinate of value_to (not ramp_from; below ramp_from runs it backwards)"),
        Param("value_from", "float", 1.0, -_BIG, _BIG, doc="ramp: the value at ramp_from and before it"),
        Param("value_to", "float", 0.0, -_BIG, _BIG, doc="ramp: the value at ramp_to and beyond it"),
        Param("centre", "vec3", [5.0, 5.0, 5.0], -_BIG, _BIG, unit="mm", doc="radial: the bump's centre"),
        Param("radius", "float", 5.0, 1e-6, _BIG, unit="mm", doc="radial: where the value reaches outer"),
        Param("inner", "float", 1.0, -_BIG, _BIG, doc="radial: the value at the centre"),
        Param("outer", "float", 0.0, -_BIG, _BIG, doc="radial: the value at radius and beyond"),
        Param("falloff", "enum", "smooth", choices=FALLOFFS,
              doc="radial: profile from inner to outer (smooth: 1 - 3s^2 + 2s^3 of s = distance / radius)"),
        Param("strokes", "json", [], check=_canonical_strokes,
              doc="painted brush strokes, in order (FieldStroke.to_dict), applied after the mode"),
        Param("clamp", "bool", False, doc="clamp the result to [clamp_lo, clamp_hi]"),
        Param("clamp_lo", "float", 0.0, -_BIG, _BIG, doc="lowest value when clamped"),
        Param("clamp_hi", "float", 1.0, -_BIG, _BIG, doc="highest value when clamped (>= clamp_lo)"),
    )

    memory_param = "resolution"

    @classmethod
    def grid_shape(cls, params) -> tuple:
        """(nz, ny, nx) of the field; NodeInputError (``hi``) for unordered corners."""
        lo, hi = np.array(params["lo"], float), np.array(params["hi"], float)
        if np.any(hi <= lo):
            raise NodeInputError(f"hi {list(params['hi'])} must exceed lo {list(params['lo'])} on every "
                                 f"axis (mm)", where="hi")
        return field_grid_shape(lo, hi, params["resolution"])

    @classmethod
    def memory_estimate(cls, params, inputs_shape_info=None) -> int:
        try:
            shape = cls.grid_shape(params)
        except NodeInputError:
            return 0          # evaluate() reports the box
        return int(np.prod(shape, dtype=np.int64)) * FIELD_BYTES_PER_CELL

    def evaluate(self, inputs, params, ctx):
        shape = self.grid_shape(params)
        if params["clamp"] and params["clamp_lo"] > params["clamp_hi"]:
            raise NodeInputError(f"clamp_lo {params['clamp_lo']!r} must not exceed clamp_hi "
                                 f"{params['clamp_hi']!r}", where="clamp_hi")

        def make():
            mode = params["mode"]
            profile = None
            if mode == "ramp":
                profile = Ramp(params["ramp_axis"], params["ramp_from"], params["ramp_to"],
                               params["value_from"], params["value_to"])
            elif mode == "radial":
                profile = Radial(tuple(params["centre"]), params["radius"], params["inner"], params["outer"],
                                 params["falloff"])
            strokes = [FieldStroke.from_dict(d) for d in params["strokes"]]
            clamp = (params["clamp_lo"], params["clamp_hi"]) if params["clamp"] else None
            return scalar_field(params["lo"], params["hi"], shape, base=params["base"], profile=profile,
                                strokes=strokes, clamp=clamp)

        field = built(make, params, {"Ramp.end": "ramp_to", "Radial.radius": "radius",
                                     "FieldStroke": "strokes"})
        ctx.check()
        return {"field": field}
