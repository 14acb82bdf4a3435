"""Material Matrix node (paper 6.6): periodic homogenization of the voxelized cell."""

from __future__ import annotations

import numpy as np

from engine.geometry.box_cell import box_grid_shape
from engine.geometry.resample import resample_periodic
from engine.geometry.voxel_inputs import SOLVER_BYTES_PER_DOF, memory_estimate_bytes
from engine.geometry.values import ImportedVoxels
from engine.graph.errors import NodeInputError
from engine.graph.node import NodeType, register
from engine.graph.schema import Param, Port
from engine.physics.values import Stiffness
from engine.physics.elastic import engineering_constants, is_singular, symmetry_class, zener_ratio
from engine.physics.homogenize2d import homogenize_pixels
from engine.physics.homogenize3d import homogenize_voxels


def stiffness_from_result(result, *, E, nu, rho, resolution, grid_shape=None, cell=None) -> Stiffness:
    """Wrap a solver result with its engineering constants.

    A cell that does not connect along every axis (a mechanism, e.g. one
    beam) has a singular C: it is kept, its constants are left out and its
    symmetry is reported as "singular" instead of failing the node.
    """
    C = np.asarray(result.C)
    if is_singular(C):
        constants, sym, zener = {}, "singular", None
    else:
        constants = engineering_constants(C)
        sym = symmetry_class(C, tol=1e-3)
        zener = float(zener_ratio(C)) if sym == "cubic" else None
    return Stiffness(C, E, nu, rho, float(result.density), constants, sym, zener,
                     float(result.dropped_fraction), int(result.iterations), int(resolution),
                     None if grid_shape is None else tuple(int(n) for n in grid_shape),
                     None if cell is None else tuple(float(v) for v in cell))


@register
class MaterialMatrixNode(NodeType):
    """Effective stiffness tensor C of the periodic cell by voxel homogenization
    (trilinear hexes, periodic boundary conditions), with engineering constants.
    A box cell is solved on box voxels (edges ``L_i / n_i``); C is in the box's axes.
    A grid read by a Voxel Import node is solved as it is (its densities; 2D in
    plane stress, a 3x3 C)."""

    type_name = "MaterialMatrix"
    title = "Material Matrix"
    code = "mat"
    family = "property"
    inputs = (Port("voxels", "Voxel"),)
    outputs = (Port("stiffness", "Stiffness"),)
    params = (
        Param("resolution", "int", 64, 0, 256, unit="voxels",
              doc="voxels along the longest cell edge for the solve (0 = the Object grid as is; "
                  "an imported grid is never resampled); the paper used 100"),
    )

    memory_param = "resolution"

    @classmethod
    def memory_estimate(cls, params, inputs_shape_info=None) -> int:
        """The homogenization solve of the grid (``memory_estimate_bytes``, the
        one model ``mesoforge homogenize`` uses too); resolution 0 needs the
        Voxel input's grid, unknown before it is evaluated."""
        vox = (inputs_shape_info or {}).get("voxels")
        if isinstance(vox, ImportedVoxels):
            return memory_estimate_bytes(vox.density.shape, per_dof_bytes=SOLVER_BYTES_PER_DOF)
        n = params["resolution"]
        cell = (1.0, 1.0, 1.0) if vox is None else tuple(vox.solid.cell)
        if n:
            shape = box_grid_shape(cell, n)
        elif vox is not None:
            shape = np.shape(vox.occupancy)
        else:
            return 0
        return memory_estimate_bytes(shape, per_dof_bytes=SOLVER_BYTES_PER_DOF)

    def evaluate(self, inputs, params, ctx):
        vox = inputs["voxels"]
        if isinstance(vox, ImportedVoxels):
            return {"stiffness": imported_stiffness(vox, params["resolution"], progress=ctx.progress)}
        solid = vox.solid
        n = params["resolution"]
        box = None if solid.is_unit_cube else solid.cell
        if box is None:
            if n and n != vox.occupancy.shape[0]:
                occupancy = resample_periodic(solid.sdf, n) < 0
            else:
                occupancy = np.asarray(vox.occupancy)
        else:
            shape = box_grid_shape(box, n) if n else vox.occupancy.shape
            occupancy = (resample_periodic(solid.sdf, shape) < 0 if shape != vox.occupancy.shape
                         else np.asarray(vox.occupancy))
        result = homogenize_voxels(occupancy.astype(np.float64), E=vox.E, nu=vox.nu, progress=ctx.progress,
                                   cell=box)
        return {"stiffness": stiffness_from_result(result, E=vox.E, nu=vox.nu, rho=vox.rho,
                                                   resolution=max(occupancy.shape),
                                                   grid_shape=None if box is None else occupancy.shape,
                                                   cell=box)}


def imported_stiffness(vox: ImportedVoxels, resolution: int, *, progress=None) -> Stiffness:
    """The Stiffness of a grid read by a Voxel Import node, solved on the grid as
    it was read: `homogenize_voxels` for voxels, `homogenize_pixels` (plane
    stress, a 3x3 C, ``grid_shape`` = (rows, columns)) for pixels.

    Raises NodeInputError (where "resolution") when ``resolution`` is neither 0
    nor the grid's size: an imported grid is not resampled.
    """
    grid = vox.density
    if resolution and resolution != max(grid.shape):
        shape = "x".join(map(str, grid.shape))
        raise NodeInputError(f"an imported {shape} grid is solved as it is (no resampling): "
                             f"set resolution to 0", where="resolution")
    solve = homogenize_voxels if vox.kind == "voxels" else homogenize_pixels
    result = solve(grid, E=vox.E, nu=vox.nu, progress=progress)
    return stiffness_from_result(result, E=vox.E, nu=vox.nu, rho=vox.rho, resolution=max(grid.shape),
                                 grid_shape=None if vox.kind == "voxels" else grid.shape)
