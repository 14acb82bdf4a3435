"""Surface skeletons spanning closed boundary loops (paper sections 3.1, 5.1).

* :mod:`.boundary` -- validated loops of straight, smooth and sliding
  segments, and their sampling;
* :mod:`.mesh_init` -- disc meshes spanning a (skew) polygon;
* :mod:`.plateau` -- discrete minimal surfaces with a fixed boundary
  (Pinkall-Polthier iteration, refinement levels, Richardson extrapolation);
* :mod:`.mixed_minimal` -- minimal surfaces with fixed and sliding segments
  (implicit mean-curvature flow);
* :mod:`.thin_shell` -- direct surfaces: a stretched thin shell over a fixed
  boundary;
* :mod:`.curvature` -- cotan Laplacian, areas, mean curvature, reports.
"""

from .boundary import (SEGMENT_MODES, BoundaryLoop, BoundarySamples, boundary_loop,
                       loop_from_chains, sample_loop)
from .curvature import cotan_laplacian, mean_curvature, mixed_areas, surface_area, surface_report
from .mesh_init import DiscMesh, disc_mesh, midpoint_subdivide
from .mixed_minimal import MixedMinimalSurface, solve_mixed_minimal
from .plateau import MinimalSurface, relax_plateau, richardson_area, solve_plateau
from .thin_shell import ThinShellSurface, solve_thin_shell

__all__ = [
    "SEGMENT_MODES", "BoundaryLoop", "BoundarySamples", "boundary_loop", "loop_from_chains",
    "sample_loop",
    "cotan_laplacian", "mean_curvature", "mixed_areas", "surface_area", "surface_report",
    "DiscMesh", "disc_mesh", "midpoint_subdivide",
    "MixedMinimalSurface", "solve_mixed_minimal",
    "MinimalSurface", "relax_plateau", "richardson_area", "solve_plateau",
    "ThinShellSurface", "solve_thin_shell",
]
