"""What the 3D viewport shows, as plain Python: which nodes' values, where the
tiles and the material sphere go.

`pick_display_nodes` decides, from an evaluation's outputs, which node's solid
and which skeleton to show, and `pick_stiffness_node` which Material Matrix
result gets its material sphere (paper Fig. 11c) drawn beside the cell block.
No Qt and no render window here.
"""

from __future__ import annotations

import numpy as np
import pyvista as pv

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


def stiffness_polydata(C: np.ndarray) -> pv.PolyData:
    """The unscaled material surface of C with point array "E": the sphere of a 6x6 C,
    the polar curve of a 3x3 one.  Raises ValueError if C is singular."""
    if np.shape(C) == (3, 3):
        return material_polar_polydata(C)
    return material_sphere_polydata(C, subdivisions=SPHERE_SUBDIVISIONS)


# -- when there is nothing to draw -----------------------------------------------------
EMPTY_GRAPH_HINT = ("nothing to show yet: right-click or press Tab in the node graph to add a node, "
                    "or open an example (File › Example Gallery…)")
NOT_EVALUATED_HINT = "nothing to show yet: the graph has no solid or skeleton node evaluated (F5 evaluates)"
DOCK_OF_TYPE = {
    "TileSet": "Virtual Growth", "Grow": "Virtual Growth", "TilingImage": "Virtual Growth",
    "TilingProperties": "Virtual Growth",
    "PhasorFields": "Phasor Infill", "PhasorNoise": "Phasor Infill", "PhasorSlice": "Phasor Infill",
    "PhasorPreview": "Phasor Infill", "MeshImport": "Phasor Infill",
    "TopOpt": "Reaction Diffusion", "RDFields": "Reaction Diffusion", "RDGrow": "Reaction Diffusion",
    "RDCompile": "Reaction Diffusion",
    "ScalarField": "Implicit Media",
}
"""The dock that shows a node type's 2D results (slices, tilings, fields)."""


def empty_hint(doc: GraphDocument, errors: dict[str, str] | None, has_outputs: bool) -> str:
    """What the viewport says when it has nothing to draw: why, and where to look.

    errors : {node id: message} of the latest evaluation (None before any)."""
    if not doc.nodes:
        return EMPTY_GRAPH_HINT
    if errors:
        failed = sorted(errors)
        more = f" (and {len(failed) - 1} more)" if len(failed) > 1 else ""
        return (f"nothing to show: node {failed[0]!r}{more} failed; hover it in the node graph "
                f"or see the Log for why")
    docks = sorted({DOCK_OF_TYPE[n.type_name] for n in doc.nodes.values() if n.type_name in DOCK_OF_TYPE})
    if docks and has_outputs:
        return f"this graph's results are 2D: see the {' and '.join(docks)} dock{'s' if len(docks) > 1 else ''}"
    return NOT_EVALUATED_HINT
