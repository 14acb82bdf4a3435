"""Voxel Import node: a periodic cell read from a file -- a voxel grid, a pixel
image or a closed mesh -- with its base material, ready for a Material Matrix
node (what ``mesoforge homogenize GRID`` evaluates).

The file is read by :func:`engine.geometry.voxel_inputs.load_voxel_grid` (the
formats, index conventions and checks are documented there).  The node's
output is an :class:`ImportedVoxels`: a `VoxelModel` that also carries the
float64 density grid as read, which the Material Matrix node homogenizes as it
is (densities between 0 and 1 are kept; a 2D image gives a plane-stress C).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from engine.fileio import file_digest
from engine.geometry.values import ImportedVoxels
from engine.geometry.voxel_inputs import (DEFAULT_MESH_RES, INPUT_SUFFIXES, MAX_RES, MESH_SUFFIXES,
                                          SOLVER_BYTES_PER_DOF, GridTooLarge, check_memory, grid_shape_of,
                                          load_voxel_grid, memory_estimate_bytes, validate_density)
from engine.graph.errors import NodeInputError
from engine.graph.node import NodeType, register
from engine.graph.schema import Param, Port

from .solids import VoxelNode

# the base material: the Voxel node's parameters themselves (one schema, one set of ranges)
MATERIAL_PARAMS = tuple(VoxelNode.param(name) for name in ("E", "nu", "rho"))


@register
class VoxelImportNode(NodeType):
    """A periodic cell read from a file: a ``.npy`` or ``.vti`` voxel grid
    (densities in [0, 1]), a ``.png`` pixel image (2D: dark is solid) or a
    closed mesh (``.stl .obj .ply .3mf``, voxelized over its bounding box),
    with its base material, for a Material Matrix node."""

    type_name = "VoxelImport"
    title = "Voxel Import"
    code = "vim"
    family = "solid"
    outputs = (Port("voxels", "Voxel"),)
    params = (
        Param("path", "str", "", doc="the file: a .npy / .vti voxel grid, a .png pixel image (2D) "
                                     "or a closed mesh (.stl .obj .ply .3mf)"),
        Param("res", "int", DEFAULT_MESH_RES, 2, MAX_RES, unit="voxels",
              doc="voxels per edge when voxelizing a mesh (grids and images are read as they are); "
                  "the paper used 100"),
        Param("invert", "bool", False, doc="swap solid and void"),
        Param("array", "str", "", doc="the .vti array to read (empty: the first cell array, else the "
                                      "first point array)"),
    ) + MATERIAL_PARAMS

    @classmethod
    def source_token(cls, params):
        # the grid is read from a file the user may edit: its bytes key the cache
        path = params.get("path", "").strip()
        return file_digest(path) if path else ""

    @classmethod
    def grid_shape(cls, params) -> tuple | None:
        """The grid shape the file gives, from its header (nothing is loaded);
        None when the file or its header cannot tell."""
        path = params.get("path", "").strip()
        return grid_shape_of(path, res=params["res"]) if path else None

    @classmethod
    def memory_estimate(cls, params, inputs_shape_info=None) -> int:
        """The homogenization of the grid (``memory_estimate_bytes``, the Material
        Matrix node's model), which is what an imported cell is for: a grid
        whose solve would not fit is refused before the file is read."""
        shape = cls.grid_shape(params)
        return 0 if shape is None else memory_estimate_bytes(shape, per_dof_bytes=SOLVER_BYTES_PER_DOF)

    @classmethod
    def check_memory(cls, params, inputs_shape_info=None) -> int:
        """`memory_estimate`, refused with `GridTooLarge` ("a 300^3 grid needs
        about ...", ``where`` = "res" for a mesh, else "path") over the budget."""
        shape = cls.grid_shape(params)
        if shape is None:
            return 0
        try:
            return check_memory(shape, per_dof_bytes=SOLVER_BYTES_PER_DOF)
        except GridTooLarge as exc:
            mesh = Path(params["path"].strip()).suffix.lower() in MESH_SUFFIXES
            raise GridTooLarge(str(exc), need=exc.need, budget=exc.budget, lower="res" if mesh else "",
                               where="res" if mesh else "path") from None

    def evaluate(self, inputs, params, ctx):
        path = params["path"].strip()
        if not path:
            raise NodeInputError("no file: set path to a " + ", ".join(INPUT_SUFFIXES) + " file", where="path")
        suffix = Path(path).suffix.lower()
        array = params["array"].strip() or None
        if array is not None and suffix != ".vti":
            raise NodeInputError(f"array applies to .vti files only; got {suffix or 'no extension'}",
                                 where="array")
        mesh = suffix in MESH_SUFFIXES
        try:
            grid, kind, info = load_voxel_grid(path, res=params["res"] if mesh else None,
                                               invert=params["invert"], array=array,
                                               progress=ctx.progress if mesh else None)
            validate_density(grid, cubic=(kind == "voxels"))
        except (ValueError, OSError) as exc:
            raise NodeInputError(str(exc), where="array" if str(exc).startswith("array ") else "path") from None
        return {"voxels": ImportedVoxels.from_grid(grid, kind, info, E=params["E"], nu=params["nu"],
                                                   rho=params["rho"])}
