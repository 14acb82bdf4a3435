"""The preview of an SDF value: what the Implicit Media dock shows and `mesoforge sdf --render`
writes, one engine object for both.

`SDFPreview` frames a view of an SDF (its own box, or a given view box for a medium that fills
space), sphere-traces it (`engine.gpu.sphere_trace.render`) or path-traces it progressively
(`engine.gpu.path_trace`), and measures what the dock lists: the particle sizes of a
suspension and the solid volume fraction of the view box.  The settings, their defaults and
ranges are the `PREVIEW_PARAMS` below, read by the dock's fields and the command's flags.
"""

from __future__ import annotations

import math

import numpy as np

from engine.graph.schema import Param
from engine.gpu.camera import Camera
from engine.gpu.sphere_trace import STEP_MODES, render
from engine.implicit.particles import Suspension
from engine.implicit.values import SDF
from engine.implicit.volume_fraction import volume_fraction
from engine.implicit.voxelize import check_box

__all__ = ["PREVIEW_PARAMS", "SDFPreview", "preview_param", "orbit_direction", "fallback_box_for", "DEFAULT_ORBIT",
           "DEFAULT_VIEW_BOX", "MAX_HISTOGRAM_PARTICLES"]

DEFAULT_VIEW_BOX = ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0))     # mm: an unbounded medium's view without a box
MAX_HISTOGRAM_PARTICLES = 200_000
VIEW_DIRECTION = np.array([1.3, -1.7, 1.1])               # from the box centre towards the default eye

PREVIEW_PARAMS = (
    Param("width", "int", 512, 16, 4096, unit="px", doc="image width"),
    Param("height", "int", 512, 16, 4096, unit="px", doc="image height"),
    Param("step", "enum", "adaptive", choices=STEP_MODES,
          doc="sphere-tracing step rule: fixed (f / L), bijection (over-relaxed, backed off) or "
              "adaptive (local gradient every N steps); none misses a hit of the fixed rule"),
    Param("adaptive_every", "int", 100, 1, 100_000, unit="steps", doc="N: steps between gradient estimates"),
    Param("max_steps", "int", 512, 1, 100_000, doc="trial evaluations per ray"),
    Param("paths", "int", 0, 0, 100_000, unit="frames",
          doc="path-traced frames to accumulate (0: the shaded sphere-traced view)"),
    Param("max_depth", "int", 8, 1, 256, doc="longest light path (bounces) when path tracing"),
    Param("fov", "float", 40.0, 1.0, 170.0, unit="deg", doc="vertical field of view of the default camera"),
)


def orbit_direction(azimuth_deg: float, elevation_deg: float) -> np.ndarray:
    """The unit vector from the target towards the eye at `azimuth` (about +z, from +x) and
    `elevation` (above the xy plane), degrees; elevation is kept within +-89."""
    az = math.radians(float(azimuth_deg))
    el = math.radians(max(-89.0, min(89.0, float(elevation_deg))))
    return np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])


DEFAULT_ORBIT = (-52.6, 27.2)        # degrees: VIEW_DIRECTION as azimuth, elevation


def fallback_box_for(doc, node_id: str | None):
    """The box an SDF node is viewed in when its SDF has none of its own (a medium that fills
    space): the box of the SDF Solid node below it, as ``(lo, hi)``, or None."""
    from engine.graph.query import downstream_of_type

    solid = downstream_of_type(doc, node_id, "SDFSolid") if node_id else None
    if solid is None:
        return None
    params = doc.nodes[solid].params
    lo, hi = params.get("box_from"), params.get("box_to")
    if lo is None or hi is None or any(b <= a for a, b in zip(lo, hi)):
        return None
    return (tuple(lo), tuple(hi))


def preview_param(name: str) -> Param:
    return next(p for p in PREVIEW_PARAMS if p.name == name)


class SDFPreview:
    """The preview of one SDF value over a view box.

    sdf : the SDF (any engine.implicit tree).
    view_box : ((x0, y0, z0), (x1, y1, z1)) mm, the box viewed; None: the SDF's own box, else
        `fallback_box` (for a medium that fills space, e.g. `fallback_box_for` the node), else
        `DEFAULT_VIEW_BOX`.

    Raises
    ------
    ValueError
        For a value that is not an SDF or a box that is not three edges > 0.
    """

    def __init__(self, sdf: SDF, view_box=None, fallback_box=None):
        if not isinstance(sdf, SDF):
            raise ValueError(f"expected an SDF value, got {type(sdf).__name__}")
        self.sdf = sdf
        box = view_box or sdf.box() or fallback_box or DEFAULT_VIEW_BOX
        lo, hi = check_box(*box)
        self.box = (lo, hi)

    def camera(self, fov: float = 40.0, direction=None, zoom: float = 1.0) -> Camera:
        """A camera looking at the view box's centre from `direction` (default from the front
        right, above), far enough for the box's bounding sphere to fit the field of view, then
        `zoom` times closer."""
        lo, hi = self.box
        centre = 0.5 * (lo + hi)
        radius = 0.5 * float(np.linalg.norm(hi - lo))
        d = np.asarray(VIEW_DIRECTION if direction is None else direction, dtype=np.float64)
        d = d / np.linalg.norm(d)
        distance = 1.05 * radius / math.sin(math.radians(0.5 * float(fov))) / float(zoom)
        up = (0.0, 0.0, 1.0) if abs(d[2]) < 0.999 else (0.0, 1.0, 0.0)
        return Camera(centre + distance * d, centre, up, float(fov))

    def trace(self, camera: Camera | None = None, *, width: int = 512, height: int = 512,
              step: str = "adaptive", adaptive_every: int = 100, max_steps: int = 512, fov: float = 40.0,
              shading: str = "lambert", check=None):
        """The sphere-traced frame (`engine.gpu.sphere_trace.TraceResult`), rays clipped to the box."""
        cam = camera if camera is not None else self.camera(fov)
        lo, hi = self.box
        return render(self.sdf, cam, int(width), int(height), step=step, adaptive_every=int(adaptive_every),
                      max_steps=int(max_steps), bounds=(tuple(lo), tuple(hi)), shading=shading, check=check)

    def path_trace(self, camera: Camera | None = None, *, width: int = 512, height: int = 512, paths: int = 16,
                   max_depth: int = 8, fov: float = 40.0, check=None, on_frame=None, **material):
        """The progressively path-traced image (`engine.gpu.path_trace`) after `paths` frames."""
        from engine.gpu.path_trace import path_trace

        cam = camera if camera is not None else self.camera(fov)
        lo, hi = self.box
        return path_trace(self.sdf, cam, int(width), int(height), frames=int(paths), max_depth=int(max_depth),
                          bounds=(tuple(lo), tuple(hi)), check=check, on_frame=on_frame, **material)

    def particle_sizes(self) -> np.ndarray | None:
        """The sizes (mm) of the suspension's particles in the view box (its first suspension
        found in the tree), None if the tree has none; at most `MAX_HISTOGRAM_PARTICLES`."""
        cloud = _first_suspension(self.sdf)
        if cloud is None:
            return None
        lo, hi = self.box
        cells = float(np.prod(np.ceil((hi - lo) / cloud.cell) + 2))
        if cells > MAX_HISTOGRAM_PARTICLES:                         # a centred sub-box of that many cells
            c, half = 0.5 * (lo + hi), 0.5 * cloud.cell * MAX_HISTOGRAM_PARTICLES ** (1 / 3) - cloud.cell
            lo, hi = np.maximum(lo, c - half), np.minimum(hi, c + half)
        return np.asarray(cloud.particles_in_box(lo, hi).sizes, dtype=np.float64)

    def volume_fraction(self, resolution: int = 64) -> float:
        """The share of the view box inside the SDF (cell-centred samples, `resolution` per axis)."""
        lo, hi = self.box
        return volume_fraction(self.sdf, (tuple(lo), tuple(hi)), resolution)


def _first_suspension(sdf: SDF):
    stack = [sdf]
    while stack:
        s = stack.pop(0)
        if isinstance(s, Suspension):
            return s
        stack.extend(s.children)
    return None
