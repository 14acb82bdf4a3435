"""3D viewport: the current solid (optionally tiled 3x3x3), its skeleton and the unit cell.

A thin adapter over a native-window plotter (`ui.native_view`).  The scene is kept by actor
(`ui.scene.SceneActors`): a new state replaces only the actors whose value
changed, so selecting another node that shows the same solid touches
nothing.  A solid is drawn as tiles sharing one mesh (`ui.solid_actors`) at
a level of detail chosen every frame from its size on screen and whether the
camera moves (`ui.scene_lod`); the levels (normals, decimated cells) are
prepared off the GUI thread in a `TaskRunner` and kept for the last
`KEPT_SOLIDS` solids, so switching the tiling uploads nothing.  What to show
is decided by the plain functions of `ui.view_content`, re-exported here.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Callable

import numpy as np
import pyvista as pv
from PySide6 import QtCore, QtWidgets

from engine.fab import vtk_line_cells
from engine.geometry.values import Skeleton, Solid
from engine.physics.values import Stiffness

from .qt_wait import process_events_until
from .render_widget import StampedInteractor
from .scene import MIN_FRAMED_PIXELS, Framing, SceneActors
from .scene_prep import skeleton_polydata, surfaces_polydata
from .solid_actors import SolidActors
from .viewport_solid import ViewportSolid, same_key
from .task_runner import TaskRunner
from .view_content import (BOX_COLOUR, LINE_COLOUR, POINT_COLOUR, SOLID_COLOUR, SPHERE_BAR_TITLE, SPHERE_CMAP,
                           SPHERE_GAP, SPHERE_RADIUS, SPHERE_SUBDIVISIONS, SURFACE_COLOUR, block_bounds,
                           material_polar_polydata, pick_display_nodes, pick_stiffness_node, polydata,
                           skeleton_of, solid_of, sphere_placement, stiffness_of, stiffness_polydata,
                           tile_offsets, tiled_arrays)

__all__ = ["Viewport", "block_bounds", "material_polar_polydata", "pick_display_nodes", "pick_stiffness_node",
           "polydata", "skeleton_of", "solid_of", "sphere_placement", "stiffness_of", "tile_offsets",
           "tiled_arrays", "BOX_COLOUR", "LINE_COLOUR", "POINT_COLOUR", "SOLID_COLOUR", "SURFACE_COLOUR",
           "SPHERE_BAR_TITLE", "SPHERE_CMAP", "SPHERE_GAP", "SPHERE_RADIUS", "SPHERE_SUBDIVISIONS"]

HINT = "nothing to show yet: evaluate a graph with a solid or skeleton node"
SKELETON_ACTORS = ("skeleton_lines", "skeleton_surfaces", "control_points")
RENDER_DELAY_MS = 1     # a requested frame waits for the next timer pass (see request_render)


class Viewport(ViewportSolid, QtWidgets.QWidget):
    """Shows a Solid (tiled 1x1x1 or 3x3x3), a Skeleton, the unit-cell box, a
    material sphere and overlays (toolpaths) owned by the node that made them.

    Signals: ``scene_ready()`` once a prepared solid mesh is in its actor; ``closing()``
    when `close_plotter` starts (the window is shutting down)."""

    scene_ready = QtCore.Signal()
    closing = QtCore.Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        layout = QtWidgets.QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        self.plotter = StampedInteractor(self)   # repaints of an unchanged scene do not render
        layout.addWidget(self.plotter.interactor)
        # 4x MSAA triples the software renderer's frame time; lines are drawn as tubes anyway
        self.plotter.render_window.SetMultiSamples(0)
        self.plotter.set_background("#1d1f23", top="#3a3f47")
        self.plotter.add_axes(color="white")
        self.scene = SceneActors(self.plotter)
        self.framing = Framing()
        self.tiles = 1
        self.show_skeleton = True
        self.show_solid = True
        self.show_sphere = True
        self.solid: Solid | None = None
        self.skeleton: Skeleton | None = None
        self.stiffness: Stiffness | None = None
        self.caption = ""
        self.empty_hint = HINT
        self.sphere_caption = ""
        self.skeleton_emphasis = False
        self.toolpaths: pv.PolyData | None = None
        self.toolpath_owner: Any = None
        self.overlay_owner: Callable[[], Any] | None = None  # who owns a new overlay (set by the window)
        self.prepared = 0                 # solids whose levels of detail were all prepared (off the GUI thread)
        self._failed: tuple | None = None    # the (solid, tiles) whose preparation failed
        self._closed = False
        self._render_pending = False      # a frame is asked for (`request_render`)
        self._sphere_points = 0
        self._sphere_base: tuple[bytes | None, Any] = (None, None)   # (C bytes, unscaled surface of C)
        self._sphere_note = ""
        self._wanted_solid: tuple | None = None         # (solid, tiles) the solid actor should show
        self._views: list[tuple[Solid, SolidActors]] = []   # prepared solids, newest last
        self._view: SolidActors | None = None           # the one in the renderer
        self.solid_prop = pv.Property(color=SOLID_COLOUR, specular=0.25, interpolation="phong")
        self.plotter.renderer.AddObserver("StartEvent", self._before_frame)
        self.plotter.render_window.AddObserver("EndEvent", self._after_frame)
        self._first_frame = None            # (solid, Event) set once the new solid is first drawn
        self._shaders_warm = False          # `_warm_up_shaders` ran
        self._prep = TaskRunner(self)
        self._prep.published.connect(self._on_partial)
        self._prep.finished.connect(self._on_done)
        self._prep.failed.connect(self._on_prep_failed)
        self.redraw()

    # -- state --------------------------------------------------------------------
    def show_result(self, solid: Solid | None, skeleton: Skeleton | None, caption: str = "",
                    *, skeleton_emphasis: bool = False, stiffness: Stiffness | None = None,
                    sphere_caption: str = "", empty_hint: str | None = None) -> None:
        """Display `solid`, `skeleton` and the material sphere of `stiffness` (any may be None);
        `sphere_caption` joins the caption while the sphere is drawn; `empty_hint` (when given)
        is what it says while there is nothing to draw.  Only changed actors are replaced; a
        new solid mesh is prepared off the GUI thread."""
        if empty_hint is not None:
            self.empty_hint = empty_hint
        self.solid, self.skeleton, self.caption = solid, skeleton, caption
        self.skeleton_emphasis = skeleton_emphasis
        self.stiffness, self.sphere_caption = stiffness, sphere_caption
        self.redraw()

    def set_tiling(self, tiles: int) -> None:
        if tiles not in (1, 3):
            raise ValueError(f"tiling must be 1 or 3 cells per axis, got {tiles}")
        self.tiles = tiles
        self.redraw()

    def set_show_skeleton(self, on: bool) -> None:
        self.show_skeleton = bool(on)
        self.redraw()

    def set_show_solid(self, on: bool) -> None:
        self.show_solid = bool(on)
        self.redraw()

    def set_show_sphere(self, on: bool) -> None:
        self.show_sphere = bool(on)
        self.redraw()

    def show_toolpaths(self, points, segments, colours, owner: Any = None) -> None:
        """Print preview: line segments (m, 2) between `points` (n, 3) mm, each
        coloured by `colours` (m, 3) uint8 (perimeter, infill, travel...).  The
        overlay belongs to `owner` (default: ``overlay_owner()``), see `drop_overlays`."""
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        segments = np.asarray(segments, dtype=np.int64).reshape(-1, 2)
        if not len(segments):
            self.clear_toolpaths()
            return
        lines = pv.PolyData(points, lines=vtk_line_cells(segments))
        lines.cell_data["rgb"] = np.asarray(colours, dtype=np.uint8).reshape(-1, 3)
        self.toolpaths = lines
        self.toolpath_owner = owner if owner is not None or self.overlay_owner is None else self.overlay_owner()
        self.redraw()

    def clear_toolpaths(self) -> None:
        self.toolpaths, self.toolpath_owner = None, None
        self.redraw()

    def drop_overlays(self, keep: Callable[[Any], bool]) -> None:
        """Remove the overlays whose owner ``keep(owner)`` refuses (its node went, another
        document opened)."""
        if self.toolpaths is not None and not keep(self.toolpath_owner):
            self.clear_toolpaths()

    def toolpath_segment_count(self) -> int:
        return 0 if self.toolpaths is None else int(self.toolpaths.n_cells)

    def sphere_point_count(self) -> int:
        """Number of material-sphere points currently shown (0 when none is)."""
        return self._sphere_points

    def mesh_point_count(self) -> int:
        """Number of solid-mesh points the view shows (all tiles), counting a mesh
        still being prepared; `shown_mesh_point_count` is what the actor holds now."""
        if self._wanted_solid is None:
            return 0
        solid, tiles = self._wanted_solid
        return len(solid.vertices) * tiles ** 3

    def shown_mesh_point_count(self) -> int:
        """Points the solid's visible tiles draw now (at the current level of detail)."""
        return 0 if self._view is None else self._view.drawn_points()

    def solid_view(self) -> SolidActors | None:
        """The tiles of the solid in the renderer (None if no solid is drawn)."""
        return self._view

    def cell_size(self) -> float:
        return float(self.solid.cell_size) if self.solid is not None else 1.0

    def cell_box(self) -> np.ndarray:
        """(3,) mm, the edges of one tile (the solid's box; a unit cube without a solid)."""
        return self.solid.box if self.solid is not None else np.ones(3)

    @property
    def is_ready(self) -> bool:
        """Nothing is being prepared, no frame is waiting and the solid shows what it should."""
        wanted = self._wanted_solid
        shown = wanted is None or self.scene.same("solid", wanted) or same_key(wanted, self._failed)
        return shown and not self._prep.is_busy and not self._render_pending

    def _before_frame(self, *_args) -> None:
        """Renderer StartEvent: the solid's level of detail for this frame."""
        if self._view is not None:
            self._view.choose()

    def wait_ready(self, timeout_ms: int = 60000) -> bool:
        """Process events until `is_ready` (tests, screenshots)."""
        return process_events_until(lambda: self._closed or self.is_ready, lambda: None, timeout_ms=timeout_ms)

    # -- drawing --------------------------------------------------------------------
    def redraw(self) -> None:
        """Bring the actors in line with the state; render once if anything changed."""
        if self._closed:
            return
        self.plotter.suppress_rendering = True
        try:
            changed = self._sync_scene()
        finally:
            self.plotter.suppress_rendering = False
        if self._frame() or changed:
            self.request_render()

    def request_render(self) -> None:
        """Render once, after the events being handled now: the changes of one gesture
        (selection, inspector, docks) coalesce into one frame, and the frame does not
        add to the time of the handler that asked for it.  A timer, not a posted call:
        the widgets the gesture rebuilt paint, and input that arrived meanwhile is
        handled, before the frame (one ~50 ms frame after one ~30 ms repaint, rather
        than both in one stretch of the event loop)."""
        if not self._render_pending:
            self._render_pending = True
            QtCore.QTimer.singleShot(RENDER_DELAY_MS, self, self._render_now)   # dropped if the widget goes first

    def _render_now(self) -> None:
        if self._render_pending and not self._closed:
            self._render_pending = False
            if not self.plotter.frame_is_current():     # the auto-update may have drawn it already
                self.plotter.render()

    def _sync_scene(self) -> bool:
        box = self.cell_box()
        tiles = self.tiles if self.solid is None or self.solid.periodic else 1
        changed = self._sync_solid(tiles)
        changed |= self._sync_skeleton()
        changed |= self._sync_boxes(box, shown=self.has_content)
        changed |= self._sync_sphere(box)
        if self.toolpaths is None:
            changed |= self.scene.drop("toolpaths")
        else:
            changed |= self.scene.put("toolpaths", (self.toolpaths,), lambda: self.plotter.add_mesh(
                self.toolpaths, scalars="rgb", rgb=True, line_width=1.5, name="toolpaths", reset_camera=False))
        sphere_line = self.sphere_caption if self._sphere_points else self._sphere_note
        changed |= self._put_text("caption", "\n".join(t for t in (self.caption, sphere_line) if t), "upper_left",
                                  "white")
        empty = self.solid is None and self.skeleton is None and self.toolpaths is None
        changed |= self._put_text("hint", self.empty_hint if empty else "", "lower_left", "#9aa0a6")
        return changed

    def _put_text(self, name: str, text: str, position: str, colour: str) -> bool:
        if not text:
            return self.scene.drop(name)
        return self.scene.put(name, (text,), lambda: self.plotter.add_text(
            text, position=position, font_size=9, color=colour, name=name))

    def _sync_skeleton(self) -> bool:
        skeleton = self.skeleton if self.show_skeleton else None
        if skeleton is None:
            return any([self.scene.drop(name) for name in SKELETON_ACTORS])
        c = self.cell_size()
        key = (skeleton, c)
        if self.scene.same("skeleton_lines", key):
            return False
        lines = skeleton_polydata([line.polyline * c for line in skeleton.lines])
        surfaces = surfaces_polydata([(s.vertices * c, s.faces) for s in skeleton.surfaces])
        controls = [line.control_points * c for line in skeleton.lines]
        points = np.concatenate(controls) if controls else np.zeros((0, 3))
        add = self.plotter.add_mesh
        for name, mesh, style in (
                ("skeleton_lines", lines, dict(color=LINE_COLOUR, line_width=4, render_lines_as_tubes=True)),
                ("skeleton_surfaces", surfaces, dict(color=SURFACE_COLOUR, opacity=0.6)),
                ("control_points", pv.PolyData(points) if len(points) else None,
                 dict(color=POINT_COLOUR, point_size=12, render_points_as_spheres=True))):
            self.scene.drop(name)
            self.scene.put(name, key, lambda m=mesh, n=name, s=style:
                           None if m is None else add(m, name=n, reset_camera=False, **s))
        return True

    @property
    def has_content(self) -> bool:
        """Anything to draw in the cell's frame (an empty graph draws no empty box)."""
        return any(v is not None for v in (self.solid, self.skeleton, self.toolpaths, self.stiffness))

    def _sync_boxes(self, box: np.ndarray, shown: bool = True) -> bool:
        if not shown:
            return self.scene.drop("cell_box") | self.scene.drop("tiling_box")
        bx, by, bz = (float(v) for v in box)
        changed = self.scene.put("cell_box", (bx, by, bz), lambda: self.plotter.add_mesh(
            pv.Box(bounds=(0, bx, 0, by, 0, bz)), style="wireframe", color=BOX_COLOUR, line_width=1.5,
            name="cell_box", reset_camera=False))
        if self.tiles == 1:
            return self.scene.drop("tiling_box") or changed
        lo, hi = block_bounds(self.tiles, box)
        return self.scene.put("tiling_box", (bx, by, bz, self.tiles), lambda: self.plotter.add_mesh(
            pv.Box(bounds=(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])), style="wireframe", color="#5a6068",
            line_width=1.0, name="tiling_box", reset_camera=False)) or changed

    def _sync_sphere(self, box: np.ndarray) -> bool:
        if not (self.show_sphere and self.stiffness is not None):
            self._sphere_points, self._sphere_note = 0, ""
            return self._drop_sphere()
        C = np.ascontiguousarray(self.stiffness.C)
        key = (C.tobytes(), self.tiles, tuple(float(v) for v in box))
        if self.scene.same("material_sphere", key):
            return False
        self._drop_sphere()
        self.scene.put("material_sphere", key, lambda: self._draw_material_sphere(C, box))
        return True

    def _drop_sphere(self) -> bool:
        if SPHERE_BAR_TITLE in self.plotter.scalar_bars:
            self.plotter.remove_scalar_bar(SPHERE_BAR_TITLE)
        return self.scene.drop("material_sphere")

    def _draw_material_sphere(self, C: np.ndarray, box: np.ndarray):
        self._sphere_points, self._sphere_note = 0, ""
        key = C.tobytes()
        if self._sphere_base[0] != key:         # the surface of C is kept: a new tiling only moves it
            try:
                self._sphere_base = (key, stiffness_polydata(C))
            except ValueError:
                self._sphere_base = (key, None)
        base = self._sphere_base[1]
        if base is None:
            self._sphere_note = "material sphere: none, C is singular (the cell is a mechanism)"
            return None
        radii = np.linalg.norm(base.points, axis=1)
        scale, centre = sphere_placement(self.tiles, box, float(radii.max()))
        mesh = base.copy()
        mesh.points = base.points * scale + centre
        curve = {"line_width": 5, "render_lines_as_tubes": True} if mesh.n_lines else {}
        actor = self.plotter.add_mesh(
            mesh, scalars="E", cmap=SPHERE_CMAP, smooth_shading=True, specular=0.2, name="material_sphere",
            reset_camera=False, **curve,
            scalar_bar_args={"title": SPHERE_BAR_TITLE, "vertical": False, "position_x": 0.55, "position_y": 0.04,
                             "width": 0.4, "height": 0.07, "n_labels": 4, "color": "white", "fmt": "%.3g",
                             "title_font_size": 14, "label_font_size": 11})
        self._sphere_points = int(mesh.n_points)
        return actor

    # -- camera ------------------------------------------------------------------------
    def _has_content(self) -> bool:
        return self._view is not None or any(self.scene.actor(n) is not None
                                             for n in ("toolpaths", *SKELETON_ACTORS))

    def _sized(self) -> bool:
        w = self.plotter.interactor
        return self.isVisible() and min(w.width(), w.height()) >= MIN_FRAMED_PIXELS

    def _frame(self) -> bool:
        """Home the camera if `Framing` asks for it; True if it did."""
        bounds = self.plotter.renderer.ComputeVisiblePropBounds()
        content = self._has_content()
        if not self.framing.wants_home(bounds, has_content=content, sized=self._sized()):
            return False
        self._home_camera()
        self.framing.homed(bounds, has_content=content)
        return True

    def _home_camera(self) -> None:
        # Slightly off the cube diagonal: the exact isometric view hides
        # struts along (1, 1, 1), which lattices are full of.  No render here:
        # the caller renders once.
        ren = self.plotter.renderer
        ren.view_vector((1.0, -1.7, 0.8), viewup=(0.0, 0.0, 1.0), render=False)
        ren.reset_camera(render=False)

    def reset_camera(self) -> None:
        self._home_camera()
        self.framing.homed(self.plotter.renderer.ComputeVisiblePropBounds(), has_content=self._has_content())
        self.plotter.render()

    def showEvent(self, event) -> None:
        super().showEvent(event)
        QtCore.QTimer.singleShot(0, self._frame_when_sized)

    def resizeEvent(self, event) -> None:
        super().resizeEvent(event)
        QtCore.QTimer.singleShot(0, self._frame_when_sized)

    def _frame_when_sized(self) -> None:
        if self._closed:
            return
        framed = self._frame()
        if self._sized() and self._warm_up_shaders():
            framed = True                   # the speck's frames went: draw the scene again
        if framed:
            self.request_render()

    # -- output -------------------------------------------------------------------------
    def save_screenshot(self, path: str | Path) -> Path:
        """Render and write the view as a PNG (once the prepared solid is in); returns the path."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        self.wait_ready()
        self.plotter.render()
        self.plotter.screenshot(str(path))
        return path

    def close_plotter(self) -> None:
        """Stop the preparation thread and release the render window (must happen before the widget goes)."""
        if not self._closed:
            self.closing.emit()
            self._closed = True
            self._prep.shutdown()
            self.plotter.close()
