"""Reaction/diffusion lattice synthesis (Garnier, Schmidt & Rohmer): inputs, growth, compilation.

Growth (this package's kernel side): ``diffusion`` builds the per-cell
tensors of eq. 11 and upsamples coarse fields; ``gray_scott`` holds the
fused explicit step of eqs. 12-13 and its parameters; ``reference`` the
plain numpy step it is tested against; ``growth`` seeds, integrates and
stops on eq. 14, with exact save / resume; ``regrow`` erases or draws a
region and regrows it inside a window; ``orientation`` measures stripe
directions by patch-wise FFT (4.3.1).
"""

from .diffusion import diffusion_tensors, rotation_from_angle, upsample_field, upsample_rotation
from .gray_scott import RDParams, gray_scott_step, stability_limit
from .growth import RDResult, RDState, grow, load_state, place_seeds, save_state
from .orientation import Orientation, axial_difference, local_orientation
from .reference import gray_scott_step_reference
from .regrow import RegrowResult, brush_region, regrow, solid_state

__all__ = [
    "diffusion_tensors", "rotation_from_angle", "upsample_field", "upsample_rotation",
    "RDParams", "gray_scott_step", "stability_limit", "gray_scott_step_reference",
    "grow", "RDResult", "RDState", "place_seeds", "save_state", "load_state",
    "regrow", "RegrowResult", "brush_region", "solid_state",
    "Orientation", "local_orientation", "axial_difference",
]
