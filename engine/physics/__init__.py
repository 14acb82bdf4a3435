"""Mechanics kernels: periodic homogenization of voxel/pixel cells and the
finite elements, island removal and multigrid solver behind it.

No Qt, no graph or node imports.  Elastic-tensor tools (notation, engineering
constants, symmetry class, bounds) are in :mod:`engine.physics.elastic`, the
material sphere in :mod:`engine.physics.material_sphere`.
"""

from .elastic import (engineering_constants, isotropic_plane_stress, isotropic_stiffness, symmetry_class,
                      zener_ratio)

from .hex_element import hex_stiffness, hex_strain_loads, quad_stiffness, quad_strain_loads
from .homogenize2d import homogenize_pixels
from .homogenize3d import homogenize_voxels
from .islands import keep_percolating, periodic_components
from .periodic_fe import HomogenizationResult, estimate_memory

__all__ = [
    "homogenize_voxels", "homogenize_pixels", "HomogenizationResult", "estimate_memory",
    "keep_percolating", "periodic_components",
    "hex_stiffness", "hex_strain_loads", "quad_stiffness", "quad_strain_loads",
    "engineering_constants", "isotropic_stiffness", "isotropic_plane_stress", "symmetry_class", "zener_ratio",
]
