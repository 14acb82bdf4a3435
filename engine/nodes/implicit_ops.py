"""Operations on SDF values (paper 004, sections 3.1 and 4): Booleans and smooth blends,
affine transforms, offsets and shells, and a unit cell's solid as an SDF that tiles space, so
particle media and periodic functions combine with the Object node's lattices."""

from __future__ import annotations

import math

import numpy as np

from engine.graph.errors import NodeInputError
from engine.graph.node import NodeType, register
from engine.graph.schema import Param, Port
from engine.implicit.combine import (Affine, Difference, Intersection, Offset, Shell, SmoothDifference,
                                     SmoothIntersection, SmoothUnion, Union)
from engine.implicit.sampled import Sampled
from engine.implicit.shapes import SHAPES, Primitive

from .implicit_common import built

BOOLEANS = ("union", "intersection", "difference", "smooth union", "smooth intersection",
            "smooth difference")


def shape_params(shape: str, extent, rounding: float) -> tuple:
    """A shape's parameters (mm) from the node's box-like `extent` (full widths along x, y, z)
    and `rounding`: sphere r = x / 2; ellipsoid semi-axes; box half-extents; round box
    half-extents and rounding; torus R = x / 2 - the tube, r = z / 2; capsule, cylinder and
    hexagonal prism along z (half-height z / 2, radius / apothem x / 2)."""
    x, y, z = (0.5 * float(v) for v in extent)
    return {"sphere": (x,), "ellipsoid": (x, y, z), "box": (x, y, z), "round_box": (x, y, z, float(rounding)),
            "torus": (x - z, z), "capsule": (max(z - x, 1e-9), x), "cylinder": (z, x),
            "hex_prism": (z, x)}[shape]


@register
class SDFShapeNode(NodeType):
    """One solid shape (sphere, ellipsoid, box, round box, torus, capsule, cylinder or
    hexagonal prism) sized by its extents along x, y, z and placed at a centre: the block of ice
    a cloud of bubbles is cut from, a mould, a blob to blend a lattice into."""

    type_name = "SDFShape"
    title = "SDF Shape"
    code = "sdp"
    family = "implicit"
    outputs = (Port("sdf", "SDF"),)
    params = (
        Param("shape", "enum", "box", choices=tuple(SHAPES), doc="the shape"),
        Param("extent", "vec3", [1.0, 1.0, 1.0], 1e-4, 1e4, unit="mm",
              doc="full widths along x, y, z (a sphere uses x; z is the axis of torus, capsule, "
                  "cylinder and prism; a torus's tube is z wide)"),
        Param("rounding", "float", 0.05, 0.0, 1e4, unit="mm", doc="edge rounding of a round box"),
        Param("centre", "vec3", [0.5, 0.5, 0.5], -1e4, 1e4, unit="mm", doc="where the shape's centre is"),
    )

    def evaluate(self, inputs, params, ctx):
        def make():
            return Primitive(params["shape"], shape_params(params["shape"], params["extent"], params["rounding"]),
                             centre=tuple(params["centre"]))
        return {"sdf": built(make, params, {"rounding": "rounding", "R ": "extent", "r ": "extent", "h ": "extent"})}


@register
class SDFBooleanNode(NodeType):
    """Union, intersection or difference (a minus b) of two SDFs, hard or blended over a
    width (a fillet where they meet).  Works on the inputs' distances (each divided by its
    gradient bound), so the result is again a lower bound of the distance."""

    type_name = "SDFBoolean"
    title = "SDF Boolean"
    code = "sdb"
    family = "implicit"
    inputs = (Port("a", "SDF"), Port("b", "SDF"))
    outputs = (Port("sdf", "SDF"),)
    params = (
        Param("operation", "enum", "union", choices=BOOLEANS, doc="how a and b combine (difference: a minus b)"),
        Param("blend", "float", 0.1, 1e-6, 1e4, unit="mm", doc="blend width of the smooth operations"),
    )

    def evaluate(self, inputs, params, ctx):
        a, b, op, k = inputs["a"], inputs["b"], params["operation"], params["blend"]

        def make():
            return {"union": lambda: Union((a, b)), "intersection": lambda: Intersection((a, b)),
                    "difference": lambda: Difference(a, b), "smooth union": lambda: SmoothUnion(a, b, k),
                    "smooth intersection": lambda: SmoothIntersection(a, b, k),
                    "smooth difference": lambda: SmoothDifference(a, b, k)}[op]()
        return {"sdf": built(make, params, {"blend width": "blend"})}


def transform_matrix(rotate_deg, scale) -> np.ndarray:
    """``Rz @ Ry @ Rx @ diag(scale)``: scale, then rotate about x, y, z (degrees)."""
    m = np.diag(np.asarray(scale, dtype=np.float64))
    for axis, deg in enumerate(rotate_deg):
        c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
        i, j = [(1, 2), (2, 0), (0, 1)][axis]
        r = np.eye(3)
        r[i, i], r[i, j], r[j, i], r[j, j] = c, -s, s, c
        m = r @ m
    return m


@register
class SDFTransformNode(NodeType):
    """Scales (per axis), rotates (about x, then y, then z) and translates an SDF.  A
    non-uniform scale makes the field non-Euclidean: its gradient bound grows by the largest
    stretch of the inverse map, which the tracer and the mesher divide by."""

    type_name = "SDFTransform"
    title = "SDF Transform"
    code = "sdt"
    family = "implicit"
    inputs = (Port("sdf", "SDF"),)
    outputs = (Port("sdf", "SDF"),)
    params = (
        Param("translate", "vec3", [0.0, 0.0, 0.0], -1e4, 1e4, unit="mm", doc="moved by"),
        Param("rotate", "vec3", [0.0, 0.0, 0.0], -360.0, 360.0, unit="deg", doc="rotations about x, y, z"),
        Param("scale", "vec3", [1.0, 1.0, 1.0], 1e-3, 1e3, doc="scale per axis (before rotating)"),
    )

    def evaluate(self, inputs, params, ctx):
        m = transform_matrix(params["rotate"], params["scale"])
        return {"sdf": built(lambda: Affine(inputs["sdf"], m, np.asarray(params["translate"], float)), params)}


@register
class SDFOffsetNode(NodeType):
    """Moves an SDF's surface outwards by an amount (inwards if negative), or makes a shell
    of a thickness centred on it."""

    type_name = "SDFOffset"
    title = "SDF Offset"
    code = "sdo"
    family = "implicit"
    inputs = (Port("sdf", "SDF"),)
    outputs = (Port("sdf", "SDF"),)
    params = (
        Param("mode", "enum", "offset", choices=("offset", "shell"), doc="offset the surface or make a shell"),
        Param("amount", "float", 0.05, -1e4, 1e4, unit="mm", doc="offset distance, or shell thickness (> 0)"),
    )

    def evaluate(self, inputs, params, ctx):
        child, amount = inputs["sdf"], params["amount"]
        if params["mode"] == "shell":
            return {"sdf": built(lambda: Shell(child, amount), params, {"thickness": "amount"})}
        return {"sdf": built(lambda: Offset(child, amount), params)}


@register
class CellSDFNode(NodeType):
    """A unit cell's solid (the Object, CSG or SDF Solid node's output) as an SDF: its
    sampled distance interpolated trilinearly, repeating with the cell over all space (a cell
    that does not tile stays in its box), placed with its corner at `origin`."""

    type_name = "CellSDF"
    title = "Cell SDF"
    code = "csd"
    family = "implicit"
    inputs = (Port("solid", "Solid"),)
    outputs = (Port("sdf", "SDF"),)
    params = (
        Param("origin", "vec3", [0.0, 0.0, 0.0], -1e4, 1e4, unit="mm", doc="where the cell's corner is"),
    )

    def evaluate(self, inputs, params, ctx):
        solid = inputs["solid"]
        values = np.asarray(solid.sdf, dtype=np.float64) * float(solid.cell_size)   # cell units -> mm
        if min(values.shape) < 2:
            raise NodeInputError(f"the solid's grid {values.shape} has fewer than 2 nodes on an axis",
                                 where="solid")
        return {"sdf": built(lambda: Sampled(values, origin=tuple(params["origin"]), spacing=tuple(solid.spacing),
                                             periodic=bool(solid.periodic)), params)}
