"""Pure numpy/numba geometry kernels: curves, thickness, SDF grids, CSG,
marching cubes and mesh I/O. No Qt, no graph or node imports.

Heavy optional imports (scikit-image, trimesh) happen inside the functions
that need them, so importing this package stays cheap.
"""

from .box_cell import box_grid_shape, check_cell
from engine.progress import Cancelled
from .csg import csg_difference, csg_intersection, csg_reduce, csg_union
from .marching import (boundary_section_match, mesh_volume, mesh_volume_fraction,
                       periodic_mesh, solid_volume_fraction)
from .mesh_io import SUPPORTED_SUFFIXES, export_mesh, load_mesh, mesh_summary
from .sdf_lines import line_sdf_grid, line_sdf_reference
from .sdf_triangles import surface_sdf_grid, surface_sdf_reference
from .splines import arc_length_parameter, interpolate_chain
from .thickness import thickness_profile

__all__ = [
    "Cancelled",
    "interpolate_chain", "arc_length_parameter",
    "thickness_profile",
    "line_sdf_grid", "line_sdf_reference",
    "surface_sdf_grid", "surface_sdf_reference",
    "box_grid_shape", "check_cell",
    "csg_union", "csg_intersection", "csg_difference", "csg_reduce",
    "periodic_mesh", "boundary_section_match", "solid_volume_fraction",
    "mesh_volume_fraction", "mesh_volume",
    "export_mesh", "load_mesh", "mesh_summary", "SUPPORTED_SUFFIXES",
]
