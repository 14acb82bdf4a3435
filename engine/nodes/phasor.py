"""Phasor infill nodes (Tricard et al. 2020): the part's mesh, the painted
control fields, the aligned phasor noise and its slices.

    MeshImport --mesh--> PhasorFields --fields--> PhasorNoise --infill--> PhasorSlice

Painting is data: every brush stroke in the window is one
``SetParam(node, "strokes", old + [stroke.to_dict()])``.  PhasorFields and
PhasorNoise are stateful, so a stroke appended to the list repaints only its
own cells, and the noise resamples and re-aligns only the kernels there.

What runs is :class:`engine.nodes.phasor_session.PhasorInfillSession` (the
fields from the parameters, sampling, the local update, slices), which the
"Phasor Infill" dock and ``mesoforge phasor`` call too.
"""

from __future__ import annotations

import json
import math

import numpy as np

from engine.graph.errors import NodeInputError
from engine.graph.node import NodeType, register
from engine.graph.schema import Param, Port
from engine.geometry.values import Field, MeshValue
from engine.phasor.values import PhasorFieldsValue
from engine.phasor.field_init import DEFAULT_SPEC
from engine.phasor.strokes import Stroke, stroke_weights

from .phasor_session import (MAX_FIELD_CELLS, NoiseOptions, PhasorInfillSession, fields_box, grid_shape,
                             initial_fields, paint, union_box)

__all__ = ["MeshImportNode", "PhasorFieldsNode", "PhasorNoiseNode", "PhasorSliceNode", "MAX_FIELD_CELLS",
           "grid_shape", "slice_pixels", "print_memory_estimate"]

DEFAULT_SPEC_TEXT = json.dumps(DEFAULT_SPEC)
SHOW = ("diamonds", "p_v", "p_w", "singularity")
SHOW_S_MAX = 10.0  # singularity images are clipped here (inf where G = 0) for display
# Peak bytes per control-field cell (D as a 3x3 frame, F, Gamma, the stroke
# weights and their temporaries) and per slice pixel (the sample points, the
# complex noise of both families, the sawtooth, inside and diamond masks).
FIELD_BYTES_PER_CELL = 160
SLICE_BYTES_PER_PIXEL = 160
# Per layer of a whole print, per pixel along the slice's edges: the toolpaths
# kept for the G-code and the printability emulation.
PRINT_BYTES_PER_EDGE_PIXEL = 64


def slice_pixels(lo, hi, axis: str, pixel: float) -> int:
    """Pixels of the slice normal to ``axis`` over the box lo..hi (mm) at ``pixel`` mm."""
    ext = np.abs(np.asarray(hi, float) - np.asarray(lo, float))
    u, v = [a for a in range(3) if a != "xyz".index(axis)]
    return int(math.ceil(ext[u] / pixel) + 1) * int(math.ceil(ext[v] / pixel) + 1)


def print_memory_estimate(lo, hi, pixel: float, layer_height: float) -> int:
    """Peak bytes of slicing a whole print (every layer of ``layer_height`` mm
    at ``pixel`` mm, as ``mesoforge phasor --gcode`` / ``--printability`` do):
    one z slice at a time, plus the toolpaths kept per layer."""
    ext = np.abs(np.asarray(hi, float) - np.asarray(lo, float))
    layers = int(math.ceil(ext[2] / layer_height))
    edge = int(math.ceil((ext[0] + ext[1]) / pixel))
    return (slice_pixels(lo, hi, "z", pixel) * SLICE_BYTES_PER_PIXEL
            + layers * edge * PRINT_BYTES_PER_EDGE_PIXEL)


def _canonical_strokes(data):
    """A stroke list in canonical form (each stroke through Stroke.from_dict);
    ValueError names the stroke and its key."""
    if not isinstance(data, list):
        raise ValueError(f"a list of brush strokes, got {type(data).__name__}")
    out = []
    for i, item in enumerate(data):
        try:
            out.append(Stroke.from_dict(item).to_dict())
        except (ValueError, TypeError) as exc:
            raise ValueError(f"a list of brush strokes; stroke {i}: {exc}") from None
    return out


def _same_mesh(a, b) -> bool:
    if a is b:
        return True
    if a is None or b is None:
        return False
    return np.array_equal(a.vertices, b.vertices) and np.array_equal(a.faces, b.faces)


def _weight_box(fields, stroke):
    """[z, y, x] box of the cells a stroke paints (non-zero weight), as apply_stroke reports it."""
    w = stroke_weights(fields, stroke) > 0
    if not w.any():
        return (slice(0, 0),) * 3
    box = []
    for axis in range(3):
        hit = np.flatnonzero(w.any(axis=tuple(a for a in range(3) if a != axis)))
        box.append(slice(int(hit[0]), int(hit[-1]) + 1))
    return tuple(box)


# ------------------------------------------------------------------ MeshImport

@register
class MeshImportNode(NodeType):
    """The part to fill: a closed triangle mesh (STL, OBJ, PLY, 3MF) in mm.
    An open, non-manifold or inconsistently wound mesh is refused, naming
    an edge where it fails."""

    type_name = "MeshImport"
    title = "Mesh Import"
    code = "mesh"
    family = "solid"
    outputs = (Port("mesh", "Mesh"),)
    params = (Param("path", "str", "", doc="mesh file (.stl .obj .ply .3mf), mm"),)

    def evaluate(self, inputs, params, ctx):
        from engine.phasor.domain import load_domain_mesh

        path = params["path"].strip()
        if not path:
            raise NodeInputError("no mesh file given: set path to an .stl, .obj, .ply or .3mf file",
                                 where="path")
        try:
            mesh = load_domain_mesh(path)
        except (ValueError, OSError) as exc:
            raise NodeInputError(str(exc), where="path") from None
        return {"mesh": MeshValue(mesh.vertices, mesh.faces, path)}


# ------------------------------------------------------------------ PhasorFields

@register
class PhasorFieldsNode(NodeType):
    """Control fields of phasor infill: direction D, frequency F (cells/mm) and
    angular spread Gamma (radians) on a grid over the part's box (or lo..hi
    without a part), initialised from `spec` and painted by `strokes`.
    Appending strokes repaints only the new strokes' cells."""

    type_name = "PhasorFields"
    title = "Phasor Fields"
    code = "pf"
    family = "topology"
    stateful = True
    inputs = (Port("domain", "Mesh", required=False, doc="the part; its box plus margin is the grid's box"),)
    outputs = (Port("fields", "PhasorFields"),)
    params = (
        Param("lo", "vec3", [-10.0, -10.0, -10.0], unit="mm", doc="box corner without a domain"),
        Param("hi", "vec3", [10.0, 10.0, 10.0], unit="mm", doc="opposite box corner without a domain"),
        Param("margin", "float", 1.0, 0.0, 1000.0, unit="mm", doc="added around the domain's box"),
        Param("resolution", "int", 64, 2, 256, unit="cells",
              doc="cells along the box's longest axis (others in proportion, at least 2)"),
        Param("spec", "str", DEFAULT_SPEC_TEXT,
              doc="initial fields as JSON: {\"D\": ..., \"F\": ..., \"Gamma\": ...} "
                  "(see engine.phasor.field_init)"),
        Param("strokes", "json", [], check=_canonical_strokes,
              doc="painted brush strokes, in order (Stroke.to_dict)"),
    )

    memory_param = "resolution"

    @classmethod
    def memory_estimate(cls, params, inputs_shape_info=None) -> int:
        n = params["resolution"]
        return n ** 3 * FIELD_BYTES_PER_CELL   # the longest axis gets n cells, the others at most n

    def evaluate(self, inputs, params, ctx):
        domain = inputs.get("domain")
        lo, hi = fields_box(domain, params)
        shape = grid_shape(lo, hi, params["resolution"])
        strokes = [Stroke.from_dict(d) for d in params["strokes"]]
        prev = ctx.previous.get("fields") if ctx.previous else None
        pp = ctx.previous_params or {}
        same_base = (prev is not None and _same_mesh(prev.domain, domain)
                     and all(pp.get(k) == params[k] for k in ("lo", "hi", "margin", "resolution", "spec"))
                     and prev.fields.shape == shape)
        if same_base:
            old = pp.get("strokes") or []
            k = 0
            while k < min(len(old), len(params["strokes"])) and old[k] == params["strokes"][k]:
                k += 1
            if k == len(old):
                # the previous strokes are a prefix: paint only the new ones
                fields, changed = paint(prev.fields, strokes[k:], 0)
                return {"fields": PhasorFieldsValue(fields, domain, changed, len(strokes))}
        fields = initial_fields(domain, params)
        if same_base:
            # from scratch, but only cells under the differing strokes differ
            fields, changed = paint(fields, strokes, k)
            for d in old[k:]:
                changed = union_box(changed, _weight_box(fields, Stroke.from_dict(d)))
        else:
            fields, _ = paint(fields, strokes, len(strokes))
            changed = None
        return {"fields": PhasorFieldsValue(fields, domain, changed, len(strokes))}


# ------------------------------------------------------------------ PhasorNoise

@register
class PhasorNoiseNode(NodeType):
    """Two phasor noises p_v, p_w from kernels sampled on the fields (8 per
    cell of edge c / F_min), their phases aligned by `iterations` sweeps;
    slices of the result use the filtered kernels when `filtered`. A repaint
    resamples and re-aligns only the kernels near the repainted cells."""

    type_name = "PhasorNoise"
    title = "Phasor Noise"
    code = "pn"
    family = "topology"
    uses_rng = True
    stateful = True
    inputs = (Port("fields", "PhasorFields"),)
    outputs = (Port("infill", "PhasorInfill"),)
    params = (
        Param("per_cell", "int", 8, 1, 64, doc="kernels per grid cell (paper: 8)"),
        Param("c", "float", 4.5, 0.5, 20.0, doc="kernel radius in periods of the lowest frequency "
                                                "(paper: 4.5)"),
        Param("iterations", "int", 20, 0, 200, doc="phase-alignment sweeps (paper: 20)"),
        Param("filtered", "bool", True, doc="slices use the filtered kernels (fewer singularities)"),
        Param("filter_scale", "float", 2.0, 0.1, 10.0, doc="filter radius in kernel radii"),
    )

    def evaluate(self, inputs, params, ctx):
        fv = inputs["fields"]
        prev = ctx.previous.get("infill") if ctx.previous else None
        pp = ctx.previous_params or {}
        session = PhasorInfillSession(fv.fields, prev, fv.domain, NoiseOptions.from_params(params))
        if (prev is not None and ctx.previous_seed == ctx.seed
                and all(pp.get(k) == params[k] for k in ("per_cell", "c", "iterations"))
                and session.can_update()):
            return {"infill": session.update(progress=ctx.progress).infill}
        try:
            session = session.sample(ctx.seed, progress=ctx.progress)
        except ValueError as exc:  # too many kernels for the box and F_min
            raise NodeInputError(str(exc), where="per_cell") from None
        return {"infill": session.infill}



# ------------------------------------------------------------------ PhasorSlice

@register
class PhasorSliceNode(NodeType):
    """One axis-aligned slice of the infill, evaluated by the GPU shader (or
    the numpy reference): the black diamond cells inside the part, either
    sawtooth noise, or the singularity measure S; and the slice's
    singularity energy F_S(2)."""

    type_name = "PhasorSlice"
    title = "Phasor Slice"
    code = "ps"
    family = "property"
    inputs = (Port("infill", "PhasorInfill"),)
    outputs = (Port("image", "Field"), Port("energy", "Energy"))
    params = (
        Param("axis", "enum", "z", choices=("x", "y", "z"), doc="the slice plane's normal"),
        Param("position", "float", 0.0, unit="mm", doc="the plane's coordinate along axis"),
        Param("pixel", "float", 0.1, 0.001, 10.0, unit="mm", doc="pixel size"),
        Param("show", "enum", "diamonds", choices=SHOW,
              doc="diamonds: 1 in black cells inside the part; p_v, p_w: sawtooth in [0, 1); "
                  f"singularity: max(S_v, S_w), clipped at {SHOW_S_MAX:g}"),
        Param("engine", "enum", "gpu", choices=("gpu", "numpy"),
              doc="gpu: the shader (numpy when no EGL context can be made, logged); numpy: reference"),
    )

    memory_param = "pixel"

    @classmethod
    def memory_estimate(cls, params, inputs_shape_info=None) -> int:
        infill = (inputs_shape_info or {}).get("infill")
        if infill is None:
            return 0   # the box comes with the infill
        f = infill.fields
        return slice_pixels(f.lo, f.hi, params["axis"], params["pixel"]) * SLICE_BYTES_PER_PIXEL

    def evaluate(self, inputs, params, ctx):
        from engine.phasor.infill import check_pixel

        infill = inputs["infill"]
        try:
            check_pixel(infill.fields, params["pixel"])
        except ValueError as exc:
            raise NodeInputError(str(exc), where="pixel") from None
        session = PhasorInfillSession.of_infill(infill)
        try:
            result = session.slice_at(params["axis"], params["position"], params["pixel"],
                                      engine=params["engine"], progress=ctx.progress)
        except ValueError as exc:
            where = "position" if str(exc).startswith("position") else "infill"
            raise NodeInputError(str(exc), where=where) from None
        ctx.check()
        energy = session.energy(result)
        show = params["show"]
        if show == "diamonds":
            values = result.diamonds.astype(np.float64)
        elif show in ("p_v", "p_w"):
            values = getattr(result, show)
        else:
            s_v, s_w = result.singularity()
            values = np.nan_to_num(np.clip(np.fmax(s_v, s_w), 0.0, SHOW_S_MAX), nan=0.0)
        return {"image": Field(values, result.lo, result.hi), "energy": energy}
