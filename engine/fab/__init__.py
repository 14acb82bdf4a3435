"""Fabrication: slice images to FFF toolpaths, G-code and printability
statistics (Tricard et al., "Freely orientable microstructures", §3.3, §5.1).

Kernels take binary slice images and part masks, so this package does not
depend on how the images are made (phasor shader, voxels, ...).
"""

from .contours import frontier_walls, inside_distance, perimeter_loops
from .gcode import GcodeLayer, GcodeSummary, read_gcode_paths, write_gcode
from .ordering import order_paths, travel_length
from .pipeline import layer_stack_toolpaths, layers_to_gcode
from .preview import KIND_CODES, KIND_COLOURS, PreviewLines, layer_preview_lines, vtk_line_cells
from .print_settings import PrintSettings
from .printability import PrintabilityReport, printability, split_path
from .toolpaths import INFILL, PERIMETER, Layer, layer_toolpaths, layer_walls, order_layer

__all__ = [
    "PrintSettings",
    "frontier_walls", "perimeter_loops", "inside_distance",
    "order_paths", "travel_length",
    "Layer", "PERIMETER", "INFILL", "layer_walls", "order_layer", "layer_toolpaths",
    "write_gcode", "read_gcode_paths", "GcodeSummary", "GcodeLayer",
    "layer_stack_toolpaths", "layers_to_gcode",
    "printability", "PrintabilityReport", "split_path",
    "layer_preview_lines", "PreviewLines", "KIND_CODES", "KIND_COLOURS", "vtk_line_cells",
]
