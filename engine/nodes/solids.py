"""Object (Solidify), CSG Boolean and Voxel nodes (paper 6.5)."""

from __future__ import annotations

import numpy as np

from engine.geometry.box_cell import MAX_EDGE, box_grid_shape
from engine.geometry.csg import csg_reduce
from engine.geometry.marching import periodic_mesh
from engine.geometry.sdf_lines import line_sdf_grid
from engine.geometry.sdf_triangles import surface_sdf_grid
from engine.graph.errors import NodeInputError
from engine.graph.node import NodeType, register
from engine.graph.schema import Param, Port
from engine.geometry.values import Solid, VoxelModel

# Peak bytes per grid point of an Object evaluation: the float64 distance field
# of each batch, their union and the marching-cubes mesh (a beam cell measured
# 24 B at 64^3 and 128^3; doubled for surface batches next to line ones).
OBJECT_BYTES_PER_POINT = 48
# CSG of solids on one grid: the reduced field and its mesh.
CSG_BYTES_PER_POINT = 32


def _solid_from_sdf(sdf: np.ndarray, cell_size: float, progress=None, cell=(1.0, 1.0, 1.0)) -> Solid:
    if not np.any(sdf < 0):
        raise NodeInputError("the result is empty: no grid point lies inside the solid "
                             "(thicken the skeleton or raise the resolution)")
    if np.all(sdf < 0):
        raise NodeInputError("the result fills the whole cell: nothing to mesh")
    verts, faces = periodic_mesh(sdf, cell_size=cell_size, cell=cell, progress=progress)
    return Solid(sdf, verts, faces, cell_size, cell=tuple(cell))


@register
class ObjectNode(NodeType):
    """Thickens every skeleton element on a periodic grid over the cell box
    ``[0, Lx] x [0, Ly] x [0, Lz]`` (the unit cube by default; a box covers
    hexagonal, tetragonal and orthorhombic cells) and unions them; opposite
    faces agree so the cell tiles; marching cubes gives the mesh."""

    type_name = "Object"
    title = "Object"
    code = "obj"
    family = "solid"
    inputs = (Port("skeleton", "Skeleton"),)
    outputs = (Port("solid", "Solid"),)
    params = (
        Param("resolution", "int", 96, 8, 512, unit="voxels",
              doc="grid points along the longest cell edge (the other edges get proportionally fewer)"),
        Param("extrusion", "enum", "spherical", choices=("spherical", "normal"),
              doc="spherical: swept spheres (rounded); normal: offset along normals (flat ends)"),
        Param("cell_size", "float", 1.0, 1e-3, 1e4, unit="mm",
              doc="mm per cell unit (the edge length of a unit-cube cell)"),
        Param("cell", "vec3", [1.0, 1.0, 1.0], 1e-3, MAX_EDGE, unit="cell",
              doc="box edges (Lx, Ly, Lz) of the periodic cell; hexagonal: (1, 1.7320508, c)"),
    )

    memory_param = "resolution"

    @classmethod
    def grid_shape(cls, params) -> tuple:
        """Grid nodes per axis (x, y, z) of the cell box at ``resolution``."""
        # the schema keeps each edge in [1e-3, MAX_EDGE]; direct callers may leave it out
        cell = tuple(float(v) for v in params.get("cell", (1.0, 1.0, 1.0)))
        return box_grid_shape(cell, params["resolution"])

    @classmethod
    def memory_estimate(cls, params, inputs_shape_info=None) -> int:
        return int(np.prod(cls.grid_shape(params), dtype=np.int64)) * OBJECT_BYTES_PER_POINT

    def evaluate(self, inputs, params, ctx):
        skel = inputs["skeleton"]
        if not skel.elements:
            raise NodeInputError("the skeleton is empty", where="skeleton")
        method = params["extrusion"]
        cell = tuple(float(v) for v in params.get("cell", (1.0, 1.0, 1.0)))
        shape = self.grid_shape(params)
        fields = []
        lines = skel.lines
        if lines:
            fields.append(line_sdf_grid([e.polyline for e in lines], [0.5 * e.thickness for e in lines],
                                        resolution=shape, cell=cell, method=method, periodic=True,
                                        progress=ctx.progress))
        for verts, faces, thick in _surface_batches(skel.surfaces, method):
            fields.append(surface_sdf_grid(verts, faces, thick, resolution=shape, cell=cell, method=method,
                                           periodic=True, progress=ctx.progress))
        ctx.check()
        sdf = csg_reduce(fields, "union")
        return {"solid": _solid_from_sdf(sdf, params["cell_size"], ctx.progress, cell)}


def _surface_batches(surfaces, method):
    """(vertices, faces, thickness) per distance-field call.  Swept spheres of
    several meshes are the union of each mesh's, so all surfaces go in one
    call (one pass over the grid instead of one per copy); slabs cut at each
    mesh's own boundary are computed mesh by mesh."""
    if method != "spherical" or len(surfaces) < 2:
        return [(s.vertices, s.faces, s.thickness) for s in surfaces]
    offsets = np.cumsum([0] + [len(s.vertices) for s in surfaces[:-1]])
    return [(np.concatenate([s.vertices for s in surfaces]),
             np.concatenate([s.faces + o for s, o in zip(surfaces, offsets)]),
             np.concatenate([s.thickness for s in surfaces]))]


@register
class CSGBooleanNode(NodeType):
    """Union, intersection or difference (first minus the rest) of solids on equal grids."""

    type_name = "CSGBoolean"
    title = "CSG Boolean"
    code = "bool"
    family = "solid"
    inputs = (Port("solids", "Solid", multi=True),)
    outputs = (Port("solid", "Solid"),)
    params = (Param("operation", "enum", "union", choices=("union", "intersection", "difference")),)

    @classmethod
    def memory_estimate(cls, params, inputs_shape_info=None) -> int:
        solids = (inputs_shape_info or {}).get("solids") or []
        return max((int(np.size(s.sdf)) for s in solids), default=0) * CSG_BYTES_PER_POINT

    def evaluate(self, inputs, params, ctx):
        solids = inputs["solids"]
        if len(solids) < 2:
            raise NodeInputError(f"a CSG Boolean needs at least two solids, got {len(solids)}", where="solids")
        _check_same(solids, "cell", "cell box (cell units)")
        shapes = [s.grid_shape for s in solids]
        if len(set(shapes)) != 1:
            i = next(k for k, s in enumerate(shapes) if s != shapes[0])
            raise NodeInputError(f"inputs must have the same grid resolution: solids[0] has a "
                                 f"{_shape_text(shapes[0])} grid, solids[{i}] {_shape_text(shapes[i])}",
                                 where="solids")
        sizes = [s.cell_size for s in solids]
        if len(set(sizes)) != 1:
            raise NodeInputError(f"inputs must have the same cell size, got {sizes}", where="solids")
        sdf = csg_reduce([s.sdf for s in solids], params["operation"])
        return {"solid": _solid_from_sdf(sdf, sizes[0], ctx.progress, solids[0].cell)}


def _shape_text(shape) -> str:
    return "x".join(str(n) for n in shape)


def _check_same(solids, attr, what):
    """Refuse inputs whose `attr` differs, naming the first and the first mismatch."""
    values = [getattr(s, attr) for s in solids]
    for i, v in enumerate(values):
        if v != values[0]:
            raise NodeInputError(f"inputs must have the same {what}: solids[0] has {attr} "
                                 f"{list(values[0])}, solids[{i}] {list(v)}", where="solids")


@register
class VoxelNode(NodeType):
    """Occupancy voxels of a solid with its base material, for property prediction."""

    type_name = "Voxel"
    title = "Voxel"
    code = "vox"
    family = "solid"
    max_per_graph = 1
    inputs = (Port("solid", "Solid"),)
    outputs = (Port("voxels", "Voxel"),)
    params = (
        Param("E", "float", 1.0, 1e-12, 1e15, unit="Pa", doc="Young's modulus of the base material"),
        Param("nu", "float", 0.45, -0.999, 0.499, doc="Poisson's ratio of the base material"),
        Param("rho", "float", 1.0, 1e-12, 1e6, unit="kg/m^3", doc="density of the base material"),
    )

    def evaluate(self, inputs, params, ctx):
        solid = inputs["solid"]
        return {"voxels": VoxelModel(solid.sdf < 0, params["E"], params["nu"], params["rho"], solid)}
