"""PhasorPreview: the diamond cells of a phasor infill in 3D, on a sub-box.

    PhasorNoise --infill--> PhasorPreview --solid--> (viewport)

The cells are the marching-cubes surface of the diamond indicator sampled
on a voxel grid (:mod:`engine.phasor.volume`), clipped to the part when the
infill has one and capped on the sub-box's faces.
"""

from __future__ import annotations

import numpy as np

from engine.graph.errors import NodeInputError
from engine.graph.node import NodeType, register
from engine.graph.schema import Param, Port
from engine.geometry.values import Solid
from engine.progress import stage

AUTO_EDGE = 10.0  # mm, edge of the default sub-box (lo = hi) at the centre of the fields' box
NOISES = ("aligned", "raw")
# Share of the progress bar for sampling the indicator; meshing takes the rest.
SAMPLING_SHARE = 0.9


def auto_sub_box(fields) -> tuple:
    """(lo, hi) (3,) mm: an AUTO_EDGE cube at the centre of the fields' box, clipped to it."""
    centre = 0.5 * (fields.lo + fields.hi)
    half = 0.5 * np.minimum(AUTO_EDGE, fields.hi - fields.lo)
    return centre - half, centre + half


@register
class PhasorPreviewNode(NodeType):
    """The black diamond cells of the infill inside the sub-box lo..hi (mm),
    sampled every `voxel` mm and meshed by marching cubes; the surface is
    closed by caps on the sub-box's faces and clipped to the part.  The
    solid's vertices are relative to lo (the viewport draws from the origin);
    its cell_size is the sub-box's longest edge."""

    type_name = "PhasorPreview"
    title = "Phasor Preview"
    code = "pp"
    family = "solid"
    inputs = (Port("infill", "PhasorInfill"),)
    outputs = (Port("solid", "Solid"),)
    params = (
        Param("lo", "vec3", [0.0, 0.0, 0.0], unit="mm",
              doc=f"sub-box corner; lo = hi: a {AUTO_EDGE:g} mm cube at the centre of the fields' box"),
        Param("hi", "vec3", [0.0, 0.0, 0.0], unit="mm", doc="opposite sub-box corner"),
        Param("voxel", "float", 0.1, 0.005, 10.0, unit="mm",
              doc="node spacing of the sampled indicator (at most 256^3 voxels)"),
        Param("noise", "enum", "aligned", choices=NOISES,
              doc="aligned: the infill's phases (filtered when the infill filters); raw: phases 0"),
        Param("engine", "enum", "gpu", choices=("gpu", "numpy"),
              doc="gpu: the slice shader, plane by plane (numpy when no EGL context can be made)"),
    )

    def evaluate(self, inputs, params, ctx):
        from engine.phasor.volume import diamond_surface, diamond_volume

        infill = inputs["infill"]
        lo, hi = np.array(params["lo"]), np.array(params["hi"])
        if np.array_equal(lo, hi):
            lo, hi = auto_sub_box(infill.fields)
        state = "raw" if params["noise"] == "raw" else None
        try:
            volume = diamond_volume(infill, lo, hi, voxel=params["voxel"], state=state,
                                    engine=params["engine"], progress=stage(ctx.progress, 0.0, SAMPLING_SHARE))
        except ValueError as exc:
            text = str(exc)
            where = next((p for p in ("lo", "hi", "voxel") if text.startswith(p + ":")), "infill")
            raise NodeInputError(text, where=where) from None
        ctx.check()
        if not (volume.indicator < 0).any():
            raise NodeInputError("no diamond cell lies in the sub-box (inside the part): move lo and hi "
                                 "into the part", where="lo")
        verts, faces = diamond_surface(volume, progress=stage(ctx.progress, SAMPLING_SHARE,
                                                              1.0 - SAMPLING_SHARE))
        extent = volume.hi - volume.lo
        return {"solid": Solid(volume.indicator, verts - volume.lo, faces, float(extent.max()), periodic=False,
                                origin=tuple(volume.lo))}
