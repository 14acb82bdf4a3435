"""3D viewport: the current solid (optionally tiled 3x3x3), its skeleton and the unit cell.

A thin adapter over a pyvistaqt `QtInteractor`; everything here runs on the
GUI thread.  `pick_display_nodes` decides, from an evaluation's outputs,
which node's solid and which skeleton to show, and `pick_stiffness_node`
which Material Matrix result gets its material sphere (paper Fig. 11c)
drawn beside the cell block; both are plain Python.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyvista as pv
from pyvistaqt import QtInteractor
from PySide6 import QtWidgets

from engine.fab import vtk_line_cells
from engine.graph import GraphDocument
from engine.graph.query import nearest_upstream, pick_node, type_of
from engine.geometry.values import Skeleton, Solid, VoxelModel
from engine.physics.values import Stiffness
from engine.physics.material_sphere import material_polar, material_sphere_polydata

SOLID_COLOUR = "#d8cfc0"
LINE_COLOUR = "#4696dc"
POINT_COLOUR = "#e8b03c"
SURFACE_COLOUR = "#6aa8e0"
BOX_COLOUR = "#8a9099"
SPHERE_SUBDIVISIONS = 4      # icosphere: 10 * 4**4 + 2 = 2562 directions
SPHERE_RADIUS = 0.5          # largest radius, as a fraction of the cell block's edge
SPHERE_GAP = 0.3             # free space between block and sphere, same unit
SPHERE_CMAP = "viridis"
SPHERE_BAR_TITLE = "E(d)"


# -- what to show ------------------------------------------------------------------
def solid_of(outputs: dict) -> Solid | None:
    """The Solid among a node's outputs (a VoxelModel carries one too)."""
    for value in outputs.values():
        if isinstance(value, Solid):
            return value
    for value in outputs.values():
        if isinstance(value, VoxelModel):
            return value.solid
    return None


def skeleton_of(outputs: dict) -> Skeleton | None:
    for value in outputs.values():
        if isinstance(value, Skeleton):
            return value
    return None


def _has(outputs: dict, value_of):
    """An ``accept`` predicate for ``engine.graph.query``: the node's outputs hold a value ``value_of`` finds."""
    return lambda nid: nid in outputs and value_of(outputs[nid]) is not None


def pick_display_nodes(doc: GraphDocument, outputs: dict, selected: str | None = None
                       ) -> tuple[str | None, str | None]:
    """(solid node id, skeleton node id) to display.

    The selected node's solid if it has one; otherwise the solid feeding the
    Voxel node, else the last solid in topological order (a Voxel node's
    solid is only shown when it is selected).  The skeleton is the selected
    node's if it is a skeleton node, else the nearest skeleton above the
    shown solid.  Plain calls of ``engine.graph.query``.
    """
    outputs = {k: v for k, v in outputs.items() if k in doc.nodes}
    has_solid, has_skeleton = _has(outputs, solid_of), _has(outputs, skeleton_of)
    solid_id = skel_id = None
    if selected is not None and has_solid(selected):
        solid_id = selected
    elif selected is not None and has_skeleton(selected):
        skel_id = selected
    if solid_id is None:
        voxel = next((nid for nid, node in doc.nodes.items() if node.type_name == "Voxel"), None)
        feeder = nearest_upstream(doc, voxel, lambda _nid: True) if voxel is not None else None
        if feeder is not None and has_solid(feeder):
            solid_id = feeder
        else:
            solid_id = pick_node(doc, None, lambda nid: has_solid(nid) and type_of(doc, nid) != "Voxel")
    if skel_id is None and solid_id is not None:
        skel_id = nearest_upstream(doc, solid_id, has_skeleton)
    return solid_id, skel_id


def stiffness_of(outputs: dict) -> Stiffness | None:
    """The Stiffness among a node's outputs: 3D (6x6, drawn as the material
    sphere) or 2D plane stress (3x3, drawn as its polar curve E(theta))."""
    for value in outputs.values():
        if isinstance(value, Stiffness) and np.shape(value.C) in ((6, 6), (3, 3)):
            return value
    return None


def material_polar_polydata(C2d: np.ndarray, n: int = 360) -> pv.PolyData:
    """The 2D counterpart of the material sphere: the closed curve E(theta) (1, cos, sin)
    in the z = 0 plane, with point array "E"."""
    theta, E = material_polar(C2d, n=n)
    pts = np.column_stack([E * np.cos(theta), E * np.sin(theta), np.zeros_like(theta)])
    curve = pv.lines_from_points(np.vstack([pts, pts[:1]]))
    curve["E"] = np.append(E, E[0])
    return curve


def pick_stiffness_node(doc: GraphDocument, outputs: dict, selected: str | None = None) -> str | None:
    """Node whose material sphere to draw, by ``engine.graph.query.pick_node``:
    the selected node if it produced a Stiffness, else the nearest such node
    above it, else the last such node in topological order (None if none did)."""
    outputs = {k: v for k, v in outputs.items() if k in doc.nodes}
    return pick_node(doc, selected, _has(outputs, stiffness_of))


# -- geometry helpers ------------------------------------------------------------------
def tile_offsets(tiles: int, cell_size) -> np.ndarray:
    """(tiles**3, 3) translations placing the original cell in the middle.

    cell_size : float (a cube's edge) or (3,) the cell box's edges (``Solid.box``)."""
    r = np.arange(tiles) - (tiles - 1) // 2
    grid = np.stack(np.meshgrid(r, r, r, indexing="ij"), axis=-1).reshape(-1, 3)
    return grid.astype(float) * (cell_size if np.ndim(cell_size) == 0 else np.asarray(cell_size, float))


def tiled_arrays(vertices: np.ndarray, faces: np.ndarray, offsets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Translated copies of one mesh, concatenated: ((k*n, 3), (k*m, 3))."""
    n = len(vertices)
    v = (vertices[None, :, :] + offsets[:, None, :]).reshape(-1, 3)
    f = (faces[None, :, :] + (np.arange(len(offsets)) * n)[:, None, None]).reshape(-1, 3)
    return v, f


def block_bounds(tiles: int, cell_size):
    """(lo, hi) of the block of `tiles`**3 cells drawn by the viewport: floats
    (every axis) for a cube's edge `cell_size`, (3,) arrays for a box's edges."""
    if np.ndim(cell_size) != 0:
        box = np.asarray(cell_size, dtype=float)
        lo = -box * ((tiles - 1) // 2)
        return lo, lo + tiles * box
    lo = -cell_size * ((tiles - 1) // 2)
    return lo, lo + tiles * cell_size


def sphere_placement(tiles: int, cell_size, max_radius: float) -> tuple[float, np.ndarray]:
    """(scale, centre) putting a surface of largest radius `max_radius` to the
    right (+x) of the cell block, its largest radius `SPHERE_RADIUS` of the
    block's longest edge (`cell_size`: a cube's edge or a box's three edges)."""
    lo, hi = (np.broadcast_to(np.asarray(b, dtype=float), (3,)) for b in block_bounds(tiles, cell_size))
    edge = float((hi - lo).max())
    radius = SPHERE_RADIUS * edge
    scale = radius / max_radius if max_radius > 0 else 1.0
    mid = 0.5 * (lo + hi)
    return scale, np.array([hi[0] + SPHERE_GAP * edge + radius, mid[1], mid[2]])


def polydata(vertices: np.ndarray, faces: np.ndarray) -> pv.PolyData:
    faces = np.asarray(faces, dtype=np.int64)
    cells = np.hstack([np.full((len(faces), 1), 3, dtype=np.int64), faces]).ravel()
    return pv.PolyData(np.asarray(vertices, dtype=float), cells)


class Viewport(QtWidgets.QWidget):
    """Shows a Solid (tiled 1x1x1 or 3x3x3), a Skeleton and the unit-cell box."""

    def __init__(self, parent=None):
        super().__init__(parent)
        layout = QtWidgets.QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        self.plotter = QtInteractor(self)
        layout.addWidget(self.plotter.interactor)
        self.plotter.set_background("#1d1f23", top="#3a3f47")
        self.plotter.add_axes(color="white")
        self.tiles = 1
        self.show_skeleton = True
        self.show_solid = True
        self.solid: Solid | None = None
        self.skeleton: Skeleton | None = None
        self.stiffness: Stiffness | None = None
        self.sphere_caption = ""
        self.show_sphere = True
        self._sphere_cache: tuple[bytes, pv.PolyData] | None = None
        self._sphere_points = 0
        self._sphere_note = ""
        self.caption = ""
        self.skeleton_emphasis = False
        self._shown_points = 0
        self._camera_key = None
        self._closed = False
        self.toolpaths: pv.PolyData | None = None
        self.redraw()

    # -- state --------------------------------------------------------------------
    def show_result(self, solid: Solid | None, skeleton: Skeleton | None, caption: str = "",
                    *, skeleton_emphasis: bool = False, stiffness: Stiffness | None = None,
                    sphere_caption: str = "") -> None:
        """Display `solid`, `skeleton` and the material sphere of `stiffness` (any may be None);
        `sphere_caption` joins the caption while the sphere is drawn.  Re-renders."""
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

    def show_toolpaths(self, points, segments, colours) -> None:
        """Print preview: line segments (m, 2) between `points` (n, 3) mm, each
        coloured by `colours` (m, 3) uint8 (perimeter, infill, travel...)."""
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        segments = np.asarray(segments, dtype=np.int64).reshape(-1, 2)
        if not len(segments):
            self.clear_toolpaths()
            return
        lines = pv.PolyData(points, lines=vtk_line_cells(segments))
        lines.cell_data["rgb"] = np.asarray(colours, dtype=np.uint8).reshape(-1, 3)
        self.toolpaths = lines
        self.redraw()

    def clear_toolpaths(self) -> None:
        self.toolpaths = None
        self.redraw()

    def toolpath_segment_count(self) -> int:
        return 0 if self.toolpaths is None else int(self.toolpaths.n_cells)

    def sphere_point_count(self) -> int:
        """Number of material-sphere points currently shown (0 when none is)."""
        return self._sphere_points

    def mesh_point_count(self) -> int:
        """Number of solid-mesh points currently shown (all tiles)."""
        return self._shown_points

    def cell_size(self) -> float:
        return float(self.solid.cell_size) if self.solid is not None else 1.0

    def cell_box(self) -> np.ndarray:
        """(3,) mm, the edges of one tile (the solid's box; a unit cube without a solid)."""
        return self.solid.box if self.solid is not None else np.ones(3)

    # -- drawing --------------------------------------------------------------------
    def redraw(self) -> None:
        if self._closed:
            return
        # Every add_mesh would render the window once (~0.1 s each in software
        # GL); build the whole scene first and render it once.
        self.plotter.suppress_rendering = True
        try:
            self._build_scene()
        finally:
            self.plotter.suppress_rendering = False
        self.plotter.render()

    def _build_scene(self) -> None:
        p = self.plotter
        if SPHERE_BAR_TITLE in p.scalar_bars:
            p.remove_scalar_bar(SPHERE_BAR_TITLE)  # clear_actors can leave a bar whose mapper was replaced
        p.clear_actors()
        self._shown_points = 0
        self._sphere_points = 0
        self._sphere_note = ""
        c = self.cell_size()
        box = self.cell_box()
        tileable = self.solid is None or self.solid.periodic
        offsets = tile_offsets(self.tiles if tileable else 1, box)
        if self.show_solid and self.solid is not None and len(self.solid.faces):
            v, f = tiled_arrays(self.solid.vertices, self.solid.faces, offsets)
            mesh = polydata(v, f)
            translucent = self.show_skeleton and self.skeleton is not None and self.skeleton_emphasis
            p.add_mesh(mesh, color=SOLID_COLOUR, smooth_shading=True, specular=0.25, name="solid",
                       opacity=0.35 if translucent else 1.0)
            self._shown_points = int(mesh.n_points)
        if self.show_skeleton and self.skeleton is not None:
            self._draw_skeleton(self.skeleton, c)
        self._draw_cell_boxes(box)
        if self.show_sphere and self.stiffness is not None:
            self._draw_material_sphere(self.stiffness, box)
        if self.toolpaths is not None:
            p.add_mesh(self.toolpaths, scalars="rgb", rgb=True, line_width=1.5, name="toolpaths")
        sphere_line = self.sphere_caption if self._sphere_points else self._sphere_note
        caption = "\n".join(t for t in (self.caption, sphere_line) if t)
        if caption:
            p.add_text(caption, position="upper_left", font_size=9, color="white", name="caption")
        if self.solid is None and self.skeleton is None and self.toolpaths is None:
            p.add_text("nothing to show yet: evaluate a graph with a solid or skeleton node",
                       position="lower_left", font_size=9, color="#9aa0a6", name="hint")
        key = (self.tiles, tuple(np.round(box, 9)), self._sphere_points > 0,
               None if self.toolpaths is None else tuple(np.round(self.toolpaths.bounds, 3)))
        if key != self._camera_key:
            self._camera_key = key
            self._home_camera()

    def _home_camera(self) -> None:
        # Slightly off the cube diagonal: the exact isometric view hides
        # struts along (1, 1, 1), which lattices are full of.
        self.plotter.view_vector((1.0, -1.7, 0.8), viewup=(0.0, 0.0, 1.0))
        self.plotter.reset_camera()

    def _draw_skeleton(self, skeleton: Skeleton, c: float) -> None:
        p = self.plotter
        controls = []
        for i, line in enumerate(skeleton.lines):
            if len(line.polyline) >= 2:
                p.add_mesh(pv.lines_from_points(line.polyline * c), color=LINE_COLOUR, line_width=4,
                           render_lines_as_tubes=True, name=f"line{i}")
            controls.append(line.control_points * c)
        for i, surf in enumerate(skeleton.surfaces):
            if len(surf.faces):
                p.add_mesh(polydata(surf.vertices * c, surf.faces), color=SURFACE_COLOUR, opacity=0.6,
                           name=f"surface{i}")
        if controls:
            pts = np.concatenate(controls)
            if len(pts):
                p.add_mesh(pv.PolyData(pts), color=POINT_COLOUR, point_size=12,
                           render_points_as_spheres=True, name="control_points")

    def _draw_cell_boxes(self, box: np.ndarray) -> None:
        bx, by, bz = (float(v) for v in box)
        self.plotter.add_mesh(pv.Box(bounds=(0, bx, 0, by, 0, bz)), style="wireframe", color=BOX_COLOUR,
                              line_width=1.5, name="cell_box")
        if self.tiles > 1:
            lo, hi = block_bounds(self.tiles, box)
            self.plotter.add_mesh(pv.Box(bounds=(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])), style="wireframe",
                                  color="#5a6068", line_width=1.0, name="tiling_box")

    def _sphere_mesh(self, stiffness: Stiffness) -> pv.PolyData:
        """The unscaled material sphere, recomputed only when C changes."""
        key = np.ascontiguousarray(stiffness.C).tobytes()
        if self._sphere_cache is None or self._sphere_cache[0] != key:
            if np.shape(stiffness.C) == (3, 3):
                mesh = material_polar_polydata(stiffness.C)
            else:
                mesh = material_sphere_polydata(stiffness.C, subdivisions=SPHERE_SUBDIVISIONS)
            self._sphere_cache = (key, mesh)
        return self._sphere_cache[1]

    def _draw_material_sphere(self, stiffness: Stiffness, box: np.ndarray) -> None:
        try:
            base = self._sphere_mesh(stiffness)
        except ValueError:
            self._sphere_note = "material sphere: none, C is singular (the cell is a mechanism)"
            return
        radii = np.linalg.norm(base.points, axis=1)
        scale, centre = sphere_placement(self.tiles, box, float(radii.max()))
        mesh = base.copy()
        mesh.points = base.points * scale + centre
        curve = {"line_width": 5, "render_lines_as_tubes": True} if mesh.n_lines else {}
        self.plotter.add_mesh(
            mesh, scalars="E", cmap=SPHERE_CMAP, smooth_shading=True, specular=0.2, name="material_sphere", **curve,
            scalar_bar_args={"title": SPHERE_BAR_TITLE, "vertical": False, "position_x": 0.55, "position_y": 0.04,
                             "width": 0.4, "height": 0.07, "n_labels": 4, "color": "white", "fmt": "%.3g",
                             "title_font_size": 14, "label_font_size": 11})
        self._sphere_points = int(mesh.n_points)

    def reset_camera(self) -> None:
        self._home_camera()
        self.plotter.render()

    # -- output -------------------------------------------------------------------------
    def save_screenshot(self, path: str | Path) -> Path:
        """Render and write the view as a PNG; returns the path."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        self.plotter.render()
        self.plotter.screenshot(str(path))
        return path

    def close_plotter(self) -> None:
        """Release the render window (must happen before the widget goes)."""
        if not self._closed:
            self._closed = True
            self.plotter.close()
