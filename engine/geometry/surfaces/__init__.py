"""Surface skeletons spanning closed boundary loops (paper sections 3.1, 4, 5.1, 5.3).

* :mod:`.boundary` -- validated loops of straight, smooth and sliding
  segments, and their sampling;
* :mod:`.mesh_init` -- disc meshes spanning a (skew) polygon;
* :mod:`.plateau` -- discrete minimal surfaces with a fixed boundary
  (Pinkall-Polthier iteration, refinement levels, Richardson extrapolation);
* :mod:`.mixed_minimal` -- minimal surfaces with fixed and sliding segments
  (implicit mean-curvature flow);
* :mod:`.thin_shell` -- direct surfaces: a stretched thin shell over a fixed
  boundary;
* :mod:`.curvature` -- cotan Laplacian, areas, mean curvature, reports;
* :mod:`.fbv` -- fundamental bounding volumes, their fitting to a loop and
  the requirements loops must meet on them;
* :mod:`.conjugate` -- the discrete conjugate of a minimal surface;
* :mod:`.dual_contour` -- the dual polygon of a conjugate loop;
* :mod:`.cscm` -- conjugate surface construction with edge-length
  optimisation (free-boundary patches);
* :mod:`.cscm_starts` -- the starts of its search and the choice between
  solutions (least area);
* :mod:`.fix_boundary` -- FIXBOUNDARY: snapping a patch onto its planes;
* :mod:`.associate` -- associate family members and their periods;
* :mod:`.tiling` -- extending a patch by mirrors and half-turns;
* :mod:`.thickness_profile` -- thickness spread from sparse samples.
"""

from .associate import (BONNET_ANGLE_DEG, AssociateSurface, associate_periods, associate_surface,
                        lattice_basis)
from .boundary import (SEGMENT_MODES, BoundaryLoop, BoundarySamples, boundary_loop,
                       loop_from_chains, sample_loop)
from .conjugate import ConjugateSurface, conjugate_surface
from .cscm import ConjugatePatch, conjugate_surface_construction
from .curvature import cotan_laplacian, mean_curvature, mixed_areas, surface_area, surface_report
from .dual_contour import ContourError
from .fbv import (FBV_KINDS, BoundingVolume, FBVError, FBVFitError, Violation,
                  check_conjugate_loop, conjugate_violations, convex_volume, cuboid, fit_fbv,
                  locate_points, sliding_planes, tetrahedron, triangular_prism)
from .mesh_init import DiscMesh, disc_mesh, midpoint_subdivide
from .mixed_minimal import MixedMinimalSurface, solve_mixed_minimal
from .plateau import MinimalSurface, relax_plateau, richardson_area, solve_plateau
from .thickness_profile import surface_thickness
from .thin_shell import ThinShellSurface, solve_thin_shell
from .tiling import Symmetry, fbv_mirrors, half_turn, mirror, tile_patch

__all__ = [
    "BONNET_ANGLE_DEG", "AssociateSurface", "associate_periods", "associate_surface",
    "lattice_basis",
    "SEGMENT_MODES", "BoundaryLoop", "BoundarySamples", "boundary_loop", "loop_from_chains",
    "sample_loop",
    "ConjugateSurface", "conjugate_surface",
    "ConjugatePatch", "conjugate_surface_construction",
    "cotan_laplacian", "mean_curvature", "mixed_areas", "surface_area", "surface_report",
    "ContourError",
    "FBV_KINDS", "BoundingVolume", "FBVError", "FBVFitError", "Violation", "check_conjugate_loop",
    "conjugate_violations", "convex_volume", "cuboid", "fit_fbv", "locate_points",
    "sliding_planes", "tetrahedron", "triangular_prism",
    "DiscMesh", "disc_mesh", "midpoint_subdivide",
    "MixedMinimalSurface", "solve_mixed_minimal",
    "MinimalSurface", "relax_plateau", "richardson_area", "solve_plateau",
    "surface_thickness",
    "ThinShellSurface", "solve_thin_shell",
    "Symmetry", "fbv_mirrors", "half_turn", "mirror", "tile_patch",
]
