"""Implicit media nodes (paper 004, sections 3.1 and 3.4): particle suspensions and periodic
functions, each giving an SDF value (port type "SDF") that any SDF node, the SDF Solid node
and the sphere tracer take."""

from __future__ import annotations

from engine.graph.node import NodeType, register
from engine.graph.schema import Param, Port
from engine.implicit.particles import SizeDistribution, Suspension
from engine.implicit.periodic import KINDS, VARIANTS, Periodic
from engine.implicit.shapes import SHAPES
from engine.implicit.volume_fraction import level_for_fraction

from .implicit_common import built

AXES = ("x", "y", "z")


@register
class ParticlesNode(NodeType):
    """A suspension of non-touching particles, one per cell of a cubic grid (paper 004, 3.1):
    random position, size and orientation per cell from a hash of the cell index and the seed
    (the same cloud in the viewport, the tracer and every export), a cell kept with
    probability `density` (Russian roulette; optionally ramped along an axis), surfaces
    offset and the domain warped.  Union two clouds for a multi-phase medium."""

    type_name = "Particles"
    title = "Particles"
    code = "prt"
    family = "implicit"
    outputs = (Port("sdf", "SDF"),)
    params = (
        Param("cell", "float", 1.0, 1e-3, 1e4, unit="mm", doc="grid cell width: one particle per cell at most"),
        Param("shape", "enum", "sphere", choices=tuple(SHAPES), doc="the particle shape (unit proportions)"),
        Param("distribution", "enum", "uniform", choices=("fixed", "uniform", "normal", "lognormal"),
              doc="size distribution: fixed (size a), uniform (a to b), normal (mean a, sd b), "
                  "lognormal (mu a = log of the median in mm, sigma b)"),
        Param("size_a", "float", 0.2, -20.0, 1e4, unit="mm",
              doc="first size parameter (see distribution); the bounding radius must fit half a cell"),
        Param("size_b", "float", 0.4, 0.0, 1e4, unit="mm", doc="second size parameter (see distribution)"),
        Param("jitter", "float", 1.0, 0.0, 1.0,
              doc="0: every particle at its cell centre (a lattice); 1: anywhere it fits in its cell"),
        Param("orient", "bool", True, doc="random particle orientations"),
        Param("density", "float", 1.0, 0.0, 1.0, doc="probability that a cell holds a particle"),
        Param("graded", "bool", False, doc="ramp the density linearly along an axis"),
        Param("density_end", "float", 0.0, 0.0, 1.0, doc="density at the end of the ramp"),
        Param("grade_axis", "enum", "z", choices=AXES, doc="axis of the density ramp"),
        Param("grade_from", "float", 0.0, -1e4, 1e4, unit="mm", doc="coordinate where the ramp starts"),
        Param("grade_to", "float", 10.0, -1e4, 1e4, unit="mm", doc="coordinate where the ramp ends"),
        Param("offset", "float", 0.0, -1e4, 1e4, unit="mm",
              doc="moves every particle surface outwards (< half a cell)"),
        Param("warp_amplitude", "float", 0.0, 0.0, 1e4, unit="mm", doc="domain warp p + a sin(f p.yzx)"),
        Param("warp_frequency", "float", 0.0, 0.0, 1e4, unit="rad/mm", doc="frequency of the domain warp"),
        Param("seed", "int", 1, 0, 2 ** 31 - 1, doc="the cloud's seed: same seed, same cloud"),
    )

    def evaluate(self, inputs, params, ctx):
        def make():
            size = SizeDistribution(params["distribution"], params["size_a"],
                                    params["size_b"] if params["distribution"] != "fixed" else 0.0)
            return Suspension(
                cell=params["cell"], shape=params["shape"], size=size, jitter=params["jitter"],
                orient=params["orient"], density=params["density"],
                density_end=params["density_end"] if params["graded"] else None,
                density_axis=AXES.index(params["grade_axis"]),
                density_span=(params["grade_from"], params["grade_to"]),
                offset=params["offset"], warp_amplitude=params["warp_amplitude"],
                warp_frequency=params["warp_frequency"], seed=params["seed"])
        return {"sdf": built(make, params, {"size distribution parameter": "size_a", "cell width": "cell",
                                            "density_span": "grade_to", "density_end": "density_end"})}


@register
class PeriodicFunctionNode(NodeType):
    """A triply periodic function (paper 004, 3.4): the solid network F < t or the sheet
    |F| < t of a TPMS nodal function, with its level set directly or calibrated to a solid
    volume fraction, optionally graded along an axis (level, and cell size over a finite
    extent).  The field is not a distance; it carries its gradient bound, so tracing and
    meshing stay correct."""

    type_name = "PeriodicFunction"
    title = "Periodic Function"
    code = "per"
    family = "implicit"
    outputs = (Port("sdf", "SDF"),)
    params = (
        Param("kind", "enum", "gyroid", choices=KINDS, doc="the nodal approximation"),
        Param("variant", "enum", "solid", choices=VARIANTS, doc="solid: the network F < t; sheet: |F| < t"),
        Param("cell", "float", 1.0, 1e-3, 1e4, unit="mm", doc="the period"),
        Param("level_by", "enum", "volume fraction", choices=("level", "volume fraction"),
              doc="set the level t directly or from a solid volume fraction"),
        Param("level", "float", 0.0, -10.0, 10.0, doc="the level t (level_by = level)"),
        Param("volume_fraction", "float", 0.3, 0.001, 0.999,
              doc="the solid volume fraction of one cell (level_by = volume fraction)"),
        Param("graded", "bool", False, doc="grade the level (and the cell) linearly along an axis"),
        Param("level_end", "float", 0.5, -10.0, 10.0, doc="level at the end of the grading span (level_by = level)"),
        Param("volume_fraction_end", "float", 0.6, 0.001, 0.999,
              doc="volume fraction at the end of the grading span (level_by = volume fraction; the level "
                  "in between is interpolated linearly)"),
        Param("cell_end", "float", 0.0, 0.0, 1e4, unit="mm",
              doc="cell at the end of the grading span; 0 keeps the cell (a graded cell needs the extent)"),
        Param("grade_axis", "enum", "z", choices=AXES, doc="axis of the grading"),
        Param("grade_from", "float", 0.0, -1e4, 1e4, unit="mm", doc="where the grading starts"),
        Param("grade_to", "float", 10.0, -1e4, 1e4, unit="mm", doc="where the grading ends"),
        Param("extent", "vec3", [10.0, 10.0, 10.0], 1e-3, 1e4, unit="mm",
              doc="a graded cell's box [0, extent] (outside it the pattern is extruded)"),
    )

    def evaluate(self, inputs, params, ctx):
        def make():
            level, level_end = params["level"], params["level_end"]
            if params["level_by"] == "volume fraction":
                level = level_for_fraction(params["kind"], params["volume_fraction"], params["variant"])
                level_end = level_for_fraction(params["kind"], params["volume_fraction_end"], params["variant"])
            graded = params["graded"]
            axis = [0.0, 0.0, 0.0]
            axis[AXES.index(params["grade_axis"])] = 1.0
            cell_end = params["cell_end"] if graded and params["cell_end"] > 0 else None
            return Periodic(
                kind=params["kind"], cell=params["cell"], level=level, variant=params["variant"],
                level_end=level_end if graded else None,
                cell_end=cell_end, grade_axis=tuple(axis),
                grade_span=(params["grade_from"], params["grade_to"]),
                extent=((0.0, 0.0, 0.0), tuple(params["extent"])) if cell_end is not None else None)
        return {"sdf": built(make, params, {"grade_span": "grade_to", "fraction": "volume_fraction"})}
