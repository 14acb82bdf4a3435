"""GPU (OpenGL through a headless EGL context): the shared context and the
pixel grid of a slice plane.  No Qt, and no family code: a family's shaders
live in the family (e.g. :mod:`engine.phasor.gpu_slice`).
"""

from engine.gpu.context import GpuUnavailable, gpu_available, gpu_context, gpu_session
from engine.gpu.slice_plane import SlicePlane

__all__ = ["GpuUnavailable", "SlicePlane", "gpu_available", "gpu_context", "gpu_session"]
