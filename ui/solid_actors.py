"""The solid drawn as copies of one cell mesh: one VTK actor per tile, all sharing a mapper.

Shared geometry for tilings: every level of detail of the cell
(`ui.scene_lod`) has one mapper, uploaded to the GPU the first time it is
drawn; a tile is an actor placed at its offset that uses the current
level's mapper.  Switching the tiling adds or removes actors and switching
the level sets the actors' mapper, so neither uploads anything again.  All
actors share one property (colour, opacity).

Before every frame (`choose`, called from the renderer's StartEvent) the
level is picked from the cell's size on screen, each level's deviation from
the full mesh in pixels, and whether the camera is
moving (the interactor raises the render window's desired update rate while a
drag, wheel or key moves the camera and lowers it when it stops) and whether
the shared property is translucent.

The tiles are also placed front to back before every frame (`order_tiles`):
the copies are identical, so which actor stands at which offset is free, and
drawing the nearest first lets the depth test discard the hidden fragments of
the farther tiles before they are shaded.  A 3x3x3 block of a TPMS overlaps
itself many times on screen, and on the software renderer that fragment work,
not the triangles, sets a still frame's cost (about a third less front to
back than back to front, measured).
"""

from __future__ import annotations

from typing import Sequence

import numpy as np
import pyvista as pv
import vtk

from .scene_lod import pick_level, pixels_per_mm
from .scene_prep import PreparedCell

MOVING_RATE = 1.0     # a desired update rate at or above this (frames/s) means the camera is moving


def cell_polydata(cell: PreparedCell) -> pv.PolyData:
    mesh = pv.PolyData.from_regular_faces(cell.vertices, cell.faces)
    mesh.point_data["Normals"] = cell.normals
    mesh.point_data.active_normals_name = "Normals"
    return mesh


class SolidActors:
    """Tiles of one solid in a renderer.

    levels : the solid's cell meshes (any order of detail); `set_levels` adds more.
    Counters for tests: ``level_switches`` (mapper changes), ``last_moving``,
    ``last_level`` (triangles of the level drawn by the last frame)."""

    def __init__(self, renderer, prop: vtk.vtkProperty, box):
        self.renderer = renderer
        self.prop = prop
        self.box = np.asarray(box, dtype=float)
        self.meshes: list[pv.PolyData] = []
        self.errors: list[float] = []            # each level's deviation from the full mesh, mm
        self.mappers: list[vtk.vtkPolyDataMapper] = []
        self.actors: list[vtk.vtkActor] = []
        self.offsets = np.zeros((0, 3))
        self.complete = False        # every level of the ladder is in
        self.level = 0
        self.level_switches = 0
        self.last_moving = False
        self.last_level = 0
        self.partial = False         # fewer copies drawn than asked (no level fits the budget yet)
        self.in_view = 0             # tiles in the view frustum at the last frame
        self.tile_reorders = 0       # frames that re-placed the tiles front to back

    # -- content ------------------------------------------------------------------------
    def set_levels(self, cells: Sequence[PreparedCell], complete: bool) -> None:
        """Add the levels not yet held (cells are given in build order, growing)."""
        for cell in cells[len(self.meshes):]:
            mesh = cell_polydata(cell)
            mapper = vtk.vtkPolyDataMapper()
            mapper.SetInputData(mesh)
            mapper.ScalarVisibilityOff()
            self.meshes.append(mesh)
            self.errors.append(float(cell.error))
            self.mappers.append(mapper)
        self.complete = complete

    def set_offsets(self, offsets: np.ndarray) -> None:
        """Show one copy of the cell at each row of `offsets` (k, 3) mm."""
        offsets = np.asarray(offsets, dtype=float).reshape(-1, 3)
        self.offsets = offsets
        while len(self.actors) < len(offsets):
            actor = vtk.vtkActor()
            actor.SetProperty(self.prop)
            actor.SetMapper(self.mappers[self.level])
            self.actors.append(actor)
            self.renderer.AddActor(actor)
        while len(self.actors) > len(offsets):
            self.renderer.RemoveActor(self.actors.pop())
        for actor, o in zip(self.actors, offsets):
            if tuple(actor.GetPosition()) != tuple(o):
                actor.SetPosition(*o)
        self.choose(moving=False)

    def remove(self) -> None:
        for actor in self.actors:
            self.renderer.RemoveActor(actor)
        self.actors = []

    def release(self, window) -> None:
        """Remove the tiles and free the levels' GPU buffers (the solid is no longer kept)."""
        self.remove()
        for mapper in self.mappers:
            mapper.ReleaseGraphicsResources(window)

    # -- per frame ------------------------------------------------------------------------
    def pixels_per_mm(self) -> float:
        """Screen pixels per mm at the camera's focal distance."""
        cam = self.renderer.GetActiveCamera()
        height = max(1, self.renderer.GetSize()[1])
        return pixels_per_mm(height, cam.GetDistance(), cam.GetViewAngle(),
                             bool(cam.GetParallelProjection()), cam.GetParallelScale())

    def cell_pixels(self) -> float:
        """The cell's longest edge on screen (pixels) at the camera's focal distance."""
        return float(self.box.max()) * self.pixels_per_mm()

    def choose(self, moving: bool | None = None) -> None:
        """Put every tile on the level for this frame (no upload if it was drawn before)."""
        if not self.actors or not self.mappers:
            return
        if moving is None:
            window = self.renderer.GetRenderWindow()
            moving = window is not None and window.GetDesiredUpdateRate() >= MOVING_RATE
        self.order_tiles()
        counts = [m.n_cells for m in self.meshes]
        self.in_view = self.copies_in_view()
        ppm = self.pixels_per_mm()
        level, fits = pick_level(counts, max(1, self.in_view), float(self.box.max()) * ppm, moving,
                                 translucent=self.prop.GetOpacity() < 1.0,
                                 error_pixels=[e * ppm for e in self.errors])
        self.last_moving, self.last_level = moving, counts[level]
        # a tiling no level fits yet (the coarse levels are being made): only the middle tile
        self.partial = not fits and not self.complete and len(self.offsets) > 1
        for actor, o in zip(self.actors, self.offsets):
            actor.SetVisibility(not self.partial or not np.any(o))
        if level != self.level:
            self.level = level
            self.level_switches += 1
            for actor in self.actors:
                actor.SetMapper(self.mappers[level])

    def order_tiles(self) -> None:
        """Give the actors the offsets in front-to-back order: by depth along the camera's
        direction of projection of each tile's centre (moves actors only when it changes)."""
        if len(self.offsets) <= 1 or not self.meshes:
            return
        cam = self.renderer.GetActiveCamera()
        centre = np.asarray(self.meshes[0].center, dtype=float)
        depth = (self.offsets + centre - np.asarray(cam.GetPosition())) @ np.asarray(cam.GetDirectionOfProjection())
        order = np.argsort(depth, kind="stable")
        if np.array_equal(order, np.arange(len(order))):
            return
        self.offsets = self.offsets[order]
        for actor, o in zip(self.actors, self.offsets):
            actor.SetPosition(*o)
        self.tile_reorders += 1

    def copies_in_view(self) -> int:
        """Tiles whose box meets the camera's view frustum (the others are culled)."""
        if len(self.offsets) <= 1:
            return len(self.offsets)
        cam = self.renderer.GetActiveCamera()
        planes = [0.0] * 24
        cam.GetFrustumPlanes(self.renderer.GetTiledAspectRatio(), planes)
        planes = np.asarray(planes).reshape(6, 4)        # inside: a x + b y + c z + d >= 0
        b = np.asarray(self.meshes[0].bounds).reshape(3, 2)
        corners = np.stack(np.meshgrid(*b, indexing="ij"), axis=-1).reshape(8, 3)
        pts = corners[None, :, :] + self.offsets[:, None, :]                  # (k, 8, 3)
        side = pts @ planes[:, :3].T + planes[:, 3]                           # (k, 8, 6)
        outside = np.any(np.all(side < 0, axis=1), axis=1)                    # all corners behind one plane
        return int(np.count_nonzero(~outside))

    # -- queries --------------------------------------------------------------------------
    def drawn_state(self) -> tuple:
        """(level, visible tiles): what the next frame would draw."""
        return self.level, tuple(bool(a.GetVisibility()) for a in self.actors)

    def drawn_points(self) -> int:
        """Points the visible tiles draw now."""
        n = self.meshes[self.level].n_points if self.meshes else 0
        return n * sum(1 for a in self.actors if a.GetVisibility())

    def drawn_triangles(self) -> int:
        n = self.meshes[self.level].n_cells if self.meshes else 0
        return n * sum(1 for a in self.actors if a.GetVisibility())

    def bounds(self) -> tuple:
        b = vtk.vtkBoundingBox()
        for a in self.actors:
            if a.GetVisibility():
                b.AddBounds(a.GetBounds())
        out = [0.0] * 6
        b.GetBounds(out)
        return tuple(out)
