"""SDF Solid: an SDF voxelised over a box and meshed (paper 004 media into the unit-cell
pipeline: the viewport, export, CSG and the Material Matrix take its Solid)."""

from __future__ import annotations

import numpy as np

from engine.geometry.box_cell import box_grid_shape
from engine.graph.errors import NodeInputError
from engine.graph.node import NodeType, register
from engine.graph.schema import Param, Port
from engine.gpu.sdf_voxels import BACKENDS, sample_box
from engine.implicit.voxelize import BYTES_PER_NODE, CHUNK_BYTES, SAMPLE_POINTS, check_box, solid_from_samples

GPU_OVERHEAD = 64 * 2 ** 20     # bytes: the GPU path's read-back buffer and first plane blocks (measured ~50 MB)
from engine.progress import stage

from .implicit_common import built


def sdf_box(sdf, params) -> tuple[np.ndarray, np.ndarray]:
    """The box the node samples (mm): the SDF's own box (grown by 2 % for the caps) when
    `fit_box` is on and the SDF is bounded, else ``[box_from, box_to]``."""
    own = sdf.box() if params["fit_box"] else None
    if own is not None:
        lo, hi = (np.asarray(v, dtype=np.float64) for v in own)
        pad = 0.02 * float((hi - lo).max())
        return lo - pad, hi + pad
    try:
        return check_box(params["box_from"], params["box_to"])
    except ValueError as exc:
        raise NodeInputError(str(exc), where="box_to") from None


@register
class SDFSolidNode(NodeType):
    """Samples an SDF at the nodes of a grid over a box (`resolution` along the longest
    edge) and meshes it by marching cubes.  Periodic: the medium repeats with the box (e.g. a
    periodic function whose cell divides it), the Solid tiles and can be homogenised as a
    unit cell; otherwise the mesh is capped where the medium meets the box."""

    type_name = "SDFSolid"
    title = "SDF Solid"
    code = "sds"
    family = "implicit"
    inputs = (Port("sdf", "SDF"),)
    outputs = (Port("solid", "Solid"),)
    params = (
        Param("resolution", "int", 96, 8, 512, unit="voxels", doc="grid intervals along the longest box edge"),
        Param("fit_box", "bool", True, doc="use the SDF's own box when it has one (a bounded shape)"),
        Param("box_from", "vec3", [0.0, 0.0, 0.0], -1e4, 1e4, unit="mm", doc="box corner (unbounded media)"),
        Param("box_to", "vec3", [1.0, 1.0, 1.0], -1e4, 1e4, unit="mm", doc="opposite box corner"),
        Param("periodic", "bool", False, doc="the medium repeats with the box: a tileable cell"),
        Param("backend", "enum", "auto", choices=BACKENDS,
              doc="evaluate on the GPU (float32, the tracer's shader) or in numpy (float64); auto: GPU if present"),
    )

    memory_param = "resolution"

    @classmethod
    def memory_estimate(cls, params, inputs_shape_info=None) -> int:
        sdf = (inputs_shape_info or {}).get("sdf")
        edges = np.ones(3)
        if sdf is not None:
            try:
                lo, hi = sdf_box(sdf, params)
                edges = hi - lo
            except NodeInputError:
                pass
        else:
            a, b = np.asarray(params["box_from"], float), np.asarray(params["box_to"], float)
            if np.all(b > a):
                edges = b - a
        n = np.array(box_grid_shape(tuple(edges / edges.max()), params["resolution"])) + 1
        chunk = GPU_OVERHEAD if params.get("backend") == "gpu" else CHUNK_BYTES * SAMPLE_POINTS
        return int(np.prod(n, dtype=np.int64)) * BYTES_PER_NODE + chunk

    def evaluate(self, inputs, params, ctx):
        sdf = inputs["sdf"]
        lo, hi = sdf_box(sdf, params)
        samples, _ = sample_box(sdf, lo, hi, params["resolution"], periodic=params["periodic"],
                                backend=params["backend"], progress=stage(ctx.progress, 0.0, 0.5))
        ctx.check()
        if not np.all(np.isfinite(samples)):
            raise NodeInputError("the SDF gave NaN or infinite values in the box", where="sdf")
        solid = built(lambda: solid_from_samples(samples, lo, hi, params["periodic"],
                                                 progress=stage(ctx.progress, 0.5, 0.5)), params,
                      {"nothing of the medium": "box_to", "fills the whole box": "box_to"})
        return {"solid": solid}
