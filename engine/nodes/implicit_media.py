"""Implicit media nodes (paper 004, sections 3.1 and 3.4): particle suspensions and periodic
functions, each giving an SDF value (port type "SDF") that any SDF node, the SDF Solid node
and the sphere tracer take."""

from __future__ import annotations

from engine.graph.errors import NodeInputError
from engine.graph.node import NodeType, register
from engine.graph.schema import Param, Port
from engine.implicit.field_sampling import grid_field_from
from engine.implicit.multiscale import MAX_LAYERS, multiscale_suspension
from engine.implicit.particle_fields import clusters
from engine.implicit.particles import SizeDistribution, Suspension
from engine.implicit.periodic import KINDS, VARIANTS, Periodic
from engine.implicit.shapes import SHAPES
from engine.implicit.volume_fraction import level_for_fraction

from .implicit_common import AXES, built, make_rule, rule_json

CORRELATIONS = ("none", "clusters", "rule")


# when a parameter takes effect (`Param.active`): what a fit may vary
def _graded(p):
    return bool(p["graded"])


def _sized(p):
    return p["distribution"] != "fixed"


def _warp_on(p):
    return p["warp_amplitude"] > 0 and p["warp_frequency"] > 0


def _octaves(p):
    return _warp_on(p) and p["warp_octaves"] > 1


def _by_level(p):
    return p["level_by"] == "level"


def _by_fraction(p):
    return p["level_by"] == "volume fraction"


def _graded_level(p):
    return _graded(p) and _by_level(p)


def _graded_fraction(p):
    return _graded(p) and _by_fraction(p)


def _correlation_rule(params):
    """The cell rule of the node's `correlation` choice (None: no rejection by rule)."""
    kind = params["correlation"]
    if kind == "clusters":
        return clusters(params["cluster_period"], params["cluster_size"])
    if kind == "rule" and params["correlation_rule"]:
        return make_rule(params["correlation_rule"])
    return None


def _grid_field(inputs, port, params):
    """The optional Field on `port` as a GridField (a 2-D field extruded along field_axis)."""
    f = inputs.get(port)
    if f is None:
        return None
    if getattr(f, "kind", None) != "scalar":
        raise NodeInputError(f"{port} needs a scalar Field, got a {getattr(f, 'kind', type(f).__name__)} one",
                             where=port)
    try:
        return grid_field_from(f.values, f.lo, f.hi, extrude_axis=AXES.index(params["field_axis"]))
    except ValueError as exc:
        raise NodeInputError(f"{port} field: {exc}", where=port) from None


def _warp_amplitudes(params):
    """The warp's amplitude matrix diag(warp_amplitude x warp_anisotropy), or None (the scalar
    warp_amplitude) when every factor is 1."""
    factors = [float(v) for v in params["warp_anisotropy"]]
    if factors == [1.0, 1.0, 1.0]:
        return None
    a = float(params["warp_amplitude"])
    return tuple(tuple(a * factors[i] if i == j else 0.0 for j in range(3)) for i in range(3))


@register
class ParticlesNode(NodeType):
    """A suspension of non-touching particles, one per cell of a cubic grid (paper 004, 3.1):
    random position, size and orientation per cell from a hash of the cell index and the seed
    (the same cloud in the viewport, the tracer and every export), a cell kept with
    probability `density` (Russian roulette; optionally ramped along an axis, times the
    optional `density` Field read at the cell centre), kept only where a correlation rule
    allows (clusters: positive correlation by rejection, paper 004 supp. 10.2), surfaces
    offset (plus the optional `offset` Field) and the domain warped by a turbulence of sine
    octaves (supp. 10.1: regions of different particle shape and anisotropy, blending
    smoothly; a multi-phase cloud).  A 2-D Field (over
    (u, v) = its x, y) is extruded along `field_axis`: u, v become x, y for z, x, z for y and
    y, z for x.  Union two clouds for a multi-phase medium.  With a `cell_width` Field the
    cell width varies over space: `scales` clouds on geometric widths spanning the field's
    range, each kept with a partition-of-unity weight of the local width
    (`engine.implicit.multiscale`); `cell` is then the reference width of the size
    distribution, whose sizes scale with each cloud's width."""

    type_name = "Particles"
    title = "Particles"
    code = "prt"
    family = "implicit"
    inputs = (Port("density", "Field", required=False,
                   doc="scalar field in [0, 1] multiplying the keep probability (read at cell centres)"),
              Port("offset", "Field", required=False,
                   doc="scalar field (mm) added to the offset at each point; offset + its max < half a cell"),
              Port("cell_width", "Field", required=False,
                   doc="scalar field (mm, > 0): the local cell width; the cloud becomes a union of `scales` "
                       "clouds on geometric widths over its range, blended by it (sizes relative to `cell`)"))
    outputs = (Port("sdf", "SDF"),)
    params = (
        Param("cell", "float", 1.0, 1e-3, 1e4, unit="mm", doc="grid cell width: one particle per cell at most"),
        Param("shape", "enum", "sphere", choices=tuple(SHAPES), doc="the particle shape (unit proportions)"),
        Param("distribution", "enum", "uniform", choices=("fixed", "uniform", "normal", "lognormal"),
              doc="size distribution: fixed (size a), uniform (a to b), normal (mean a, sd b), "
                  "lognormal (mu a = log of the median in mm, sigma b)"),
        Param("size_a", "float", 0.2, -20.0, 1e4, unit="mm",
              doc="first size parameter (see distribution); the bounding radius must fit half a cell"),
        Param("size_b", "float", 0.4, 0.0, 1e4, unit="mm", doc="second size parameter (see distribution)", active=_sized),
        Param("jitter", "float", 1.0, 0.0, 1.0,
              doc="0: every particle at its cell centre (a lattice); 1: anywhere it fits in its cell"),
        Param("orient", "bool", True, doc="random particle orientations"),
        Param("density", "float", 1.0, 0.0, 1.0, doc="probability that a cell holds a particle"),
        Param("graded", "bool", False, doc="ramp the density linearly along an axis"),
        Param("density_end", "float", 0.0, 0.0, 1.0, doc="density at the end of the ramp", active=_graded),
        Param("grade_axis", "enum", "z", choices=AXES, doc="axis of the density ramp"),
        Param("grade_from", "float", 0.0, -1e4, 1e4, unit="mm", doc="coordinate where the ramp starts", active=_graded),
        Param("grade_to", "float", 10.0, -1e4, 1e4, unit="mm", doc="coordinate where the ramp ends", active=_graded),
        Param("offset", "float", 0.0, -1e4, 1e4, unit="mm",
              doc="moves every particle surface outwards (< half a cell)"),
        Param("field_axis", "enum", "z", choices=AXES,
              doc="a 2-D density / offset Field is extruded along this axis (its x, y become the "
                  "other two axes in order)"),
        Param("correlation", "enum", "none", choices=CORRELATIONS,
              doc="none; clusters: only cells with every index mod cluster_period below cluster_size "
                  "(cubic clusters); rule: only cells correlation_rule keeps"),
        Param("cluster_period", "int", 4, 2, 46340, unit="cells", doc="period of the clusters"),
        Param("cluster_size", "int", 2, 1, 46339, unit="cells", doc="cluster edge in cells (< cluster_period)"),
        Param("correlation_rule", "json", None, check=rule_json,
              doc="a congruence rule as JSON, the Agglomerate node's format: {\"polynomials\": "
                  "[[[a, [ex, ey, ez]], ...], ...], \"moduli\": [m or null, ...], \"classes\": "
                  "[[[value, sign], ...], ...], \"inner\": \"or\", \"outer\": \"or\"}"),
        Param("warp_amplitude", "float", 0.0, 0.0, 1e4, unit="mm",
              doc="turbulence warp p + A T(p), A = amplitude x diag(anisotropy); one octave: "
                  "p + a sin(f p.yzx)", active=_warp_on),
        Param("warp_frequency", "float", 0.0, 0.0, 1e4, unit="rad/mm", doc="frequency of the warp's first octave", active=_warp_on),
        Param("warp_octaves", "int", 1, 1, 8,
              doc="octaves of the turbulence (sines of rising frequency; phases fixed by the seed)"),
        Param("warp_gain", "float", 0.5, 0.01, 1.0, doc="amplitude ratio of consecutive octaves", active=_octaves),
        Param("warp_lacunarity", "float", 2.0, 1.0, 4.0, doc="frequency ratio of consecutive octaves", active=_octaves),
        Param("warp_anisotropy", "vec3", [1.0, 1.0, 1.0], 0.0, 1.0,
              doc="per-axis factors of the warp amplitude (the diagonal of A over warp_amplitude)"),
        Param("seed", "int", 1, 0, 2 ** 31 - 1, doc="the cloud's seed: same seed, same cloud"),
        Param("scales", "int", 3, 1, MAX_LAYERS,
              doc="clouds blended when the cell_width Field is connected (cloud k has seed + k)"),
    )

    def evaluate(self, inputs, params, ctx):
        params = {**self.default_params(), **params}     # a partial dict (a fit's): the schema's defaults
        density_field = _grid_field(inputs, "density", params)
        offset_field = _grid_field(inputs, "offset", params)
        width_field = _grid_field(inputs, "cell_width", params)

        def make():
            size = SizeDistribution(params["distribution"], params["size_a"],
                                    params["size_b"] if params["distribution"] != "fixed" else 0.0)
            kwargs = dict(
                cell=params["cell"], shape=params["shape"], size=size, jitter=params["jitter"],
                orient=params["orient"], density=params["density"],
                density_end=params["density_end"] if params["graded"] else None,
                density_axis=AXES.index(params["grade_axis"]),
                density_span=(params["grade_from"], params["grade_to"]),
                density_field=density_field, rule=_correlation_rule(params),
                offset=params["offset"], offset_field=offset_field, warp_amplitude=params["warp_amplitude"],
                warp_frequency=params["warp_frequency"], warp_octaves=params["warp_octaves"],
                warp_gain=params["warp_gain"], warp_lacunarity=params["warp_lacunarity"],
                warp_amplitudes=_warp_amplitudes(params), seed=params["seed"])
            if width_field is None:
                return Suspension(**kwargs)
            return multiscale_suspension(kwargs, width_field, params["scales"])
        return {"sdf": built(make, params, {"width_field": "cell_width", "layers": "scales",
                                            "density_field": "density", "offset_field": "offset",
                                            "cluster period": "cluster_period", "cluster size": "cluster_size",
                                            "size distribution parameter": "size_a", "cell width": "cell",
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
        Param("level", "float", 0.0, -10.0, 10.0, doc="the level t (level_by = level)", active=_by_level),
        Param("volume_fraction", "float", 0.3, 0.001, 0.999,
              doc="the solid volume fraction of one cell (level_by = volume fraction)", active=_by_fraction),
        Param("graded", "bool", False, doc="grade the level (and the cell) linearly along an axis"),
        Param("level_end", "float", 0.5, -10.0, 10.0, doc="level at the end of the grading span (level_by = level)", active=_graded_level),
        Param("volume_fraction_end", "float", 0.6, 0.001, 0.999,
              doc="volume fraction at the end of the grading span (level_by = volume fraction; the level "
                  "in between is interpolated linearly)", active=_graded_fraction),
        Param("cell_end", "float", 0.0, 0.0, 1e4, unit="mm",
              doc="cell at the end of the grading span; 0 keeps the cell (a graded cell needs the extent)", active=_graded),
        Param("grade_axis", "enum", "z", choices=AXES, doc="axis of the grading"),
        Param("grade_from", "float", 0.0, -1e4, 1e4, unit="mm", doc="where the grading starts", active=_graded),
        Param("grade_to", "float", 10.0, -1e4, 1e4, unit="mm", doc="where the grading ends", active=_graded),
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
