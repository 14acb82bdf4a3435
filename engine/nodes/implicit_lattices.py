"""Lattice media nodes (paper 004, sections 3.2 and 3.3): particles of a regular lattice kept
by integer-polynomial congruence rules (fibres, laminates, porous solids, frames, gels), and
grain piles on a deformed lattice."""

from __future__ import annotations

from engine.graph.node import NodeType, register
from engine.graph.schema import Param, Port
from engine.implicit import congruence
from engine.implicit.agglomerate import Agglomerate
from engine.implicit.piling import Pile
from engine.implicit.shapes import SHAPES

from .implicit_common import AXES, built, make_rule, polynomial, rule_json

STRUCTURES = ("all", "fibres", "laminates", "porous", "cubic frame", "gel", "rule")


def structure_rule(params):
    """The congruence rule of the node's `structure` choice (None: every cell kept)."""
    s, period, width, axis = params["structure"], params["period"], params["width"], AXES.index(params["axis"])
    return {"all": lambda: None,
            "fibres": lambda: congruence.fibres(period, axis, width),
            "laminates": lambda: congruence.laminates(period, axis, width),
            "porous": lambda: congruence.porous(period, width),
            "cubic frame": lambda: congruence.cubic_frame(period, width),
            "gel": lambda: congruence.bezier_gel(period=period, width=width),
            "rule": lambda: make_rule(params["rule"]) if params["rule"] else None}[s]()


@register
class AgglomerateNode(NodeType):
    """A regular lattice of particles (one per cell, up to the cell's width: neighbours
    merge), kept or removed per cell by an integer-polynomial congruence rule of the cell
    index (paper 004, eq. 9): straight fibres, laminates, a solid with closed pores, an open
    cubic frame, a gel-like network, or a rule given as JSON."""

    type_name = "Agglomerate"
    title = "Agglomerate"
    code = "agg"
    family = "implicit"
    outputs = (Port("sdf", "SDF"),)
    params = (
        Param("cell", "float", 0.1, 1e-3, 1e4, unit="mm", doc="lattice cell width"),
        Param("shape", "enum", "sphere", choices=tuple(SHAPES), doc="the particle shape"),
        Param("size", "float", 0.06, 1e-4, 1e4, unit="mm",
              doc="particle scale (a sphere's radius); its bounding radius must not exceed the cell"),
        Param("structure", "enum", "fibres", choices=STRUCTURES, doc="which cells keep their particle"),
        Param("period", "int", 4, 1, 46340, unit="cells", doc="modulus of the structure's rule"),
        Param("width", "int", 1, 1, 46340, unit="cells", doc="fibre / layer / pore width (< period)"),
        Param("axis", "enum", "z", choices=AXES, doc="fibre direction / layer normal"),
        Param("rule", "json", None, doc=rule_json.__doc__.split(":", 1)[1].strip(), check=rule_json),
        Param("jitter", "float", 0.0, 0.0, 1.0, doc="random particle displacement within its bound"),
        Param("seed", "int", 1, 0, 2 ** 31 - 1, doc="seed of the jitter"),
    )

    def evaluate(self, inputs, params, ctx):
        def make():
            return Agglomerate(cell=params["cell"], shape=params["shape"], size=params["size"],
                               rule=structure_rule(params), jitter=params["jitter"], seed=params["seed"])
        return {"sdf": built(make, params, {"modulus": "period", "bounding radius": "size",
                                            "polynomial": "rule"})}


@register
class PileNode(NodeType):
    """Grains piled in contact (paper 004, eq. 10): one grain per cell of a cubic lattice,
    the lattice deformed by a polynomial of height times a noise, each grain turned by an
    integer polynomial of its cell index, and the grains going from convex to concave (dimpled)
    along an axis."""

    type_name = "Pile"
    title = "Pile"
    code = "pil"
    family = "implicit"
    outputs = (Port("sdf", "SDF"),)
    params = (
        Param("cell", "float", 1.0, 1e-3, 1e4, unit="mm", doc="lattice cell width"),
        Param("grain", "enum", "round_box", choices=("sphere", "round_box"), doc="the convex grain"),
        Param("radius", "float", 0.45, 1e-4, 1e4, unit="mm", doc="grain radius / half-extent (<= half a cell apart)"),
        Param("rounding", "float", 0.3, 0.0, 1.0, doc="edge rounding of a box grain, fraction of the radius"),
        Param("dimple", "float", 0.5, 0.01, 1.0, doc="radius of the concave dimples, fraction of the radius"),
        Param("concavity", "float", 0.0, 0.0, 1.0, doc="0 convex .. 1 fully dimpled grains"),
        Param("graded", "bool", True, doc="ramp the concavity along an axis"),
        Param("concavity_end", "float", 1.0, 0.0, 1.0, doc="concavity at the end of the ramp"),
        Param("grade_axis", "enum", "z", choices=AXES, doc="axis of the concavity ramp and of the deformation"),
        Param("grade_from", "float", 0.0, -1e4, 1e4, unit="mm", doc="where the ramps start"),
        Param("grade_to", "float", 6.0, -1e4, 1e4, unit="mm", doc="where the ramps end"),
        Param("rotation_axis", "enum", "z", choices=AXES, doc="axis grains turn about"),
        Param("rotation_poly", "json", [[1, [1, 0, 0]], [2, [0, 1, 0]], [3, [0, 0, 1]]],
              doc="integer polynomial of the cell index [[a, [ex, ey, ez]], ...]: the turn is "
                  "2 pi (value mod steps) / steps", check=lambda d: [list(m) for m in polynomial(d)]),
        Param("rotation_steps", "int", 12, 1, 46340, doc="turns come in multiples of 2 pi / steps"),
        Param("deform", "vec3", [0.15, 0.0, 0.0], -1e4, 1e4,
              doc="c0, c1, c2 of the deformation amplitude P(s) = c0 + c1 s + c2 s^2 (mm; s along the "
                  "axis over the span), times the noise"),
        Param("noise_frequency", "float", 3.0, 0.0, 1e4, unit="rad/mm", doc="frequency of the deformation noise"),
        Param("seed", "int", 1, 0, 2 ** 31 - 1, doc="seed of the noise phases"),
    )

    def evaluate(self, inputs, params, ctx):
        def make():
            axis = AXES.index(params["grade_axis"])
            deform = tuple(float(c) for c in params["deform"])
            return Pile(cell=params["cell"], grain=params["grain"], radius=params["radius"],
                        rounding=params["rounding"], dimple=params["dimple"], concavity=params["concavity"],
                        concavity_end=params["concavity_end"] if params["graded"] else None,
                        concavity_axis=axis, concavity_span=(params["grade_from"], params["grade_to"]),
                        rotation_axis=AXES.index(params["rotation_axis"]),
                        rotation_poly=polynomial(params["rotation_poly"]), rotation_steps=params["rotation_steps"],
                        deform_poly=deform if any(deform) else (), deform_axis=axis,
                        deform_span=(params["grade_from"], params["grade_to"]),
                        noise_frequency=params["noise_frequency"], seed=params["seed"])
        return {"sdf": built(make, params, {"concavity_span": "grade_to", "deform_span": "grade_to",
                                            "deformation": "deform", "rotation_poly": "rotation_poly",
                                            "radius": "radius"})}
