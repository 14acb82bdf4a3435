"""GPU (OpenGL through a headless EGL context) evaluators; no Qt here."""

from engine.gpu.context import GpuUnavailable, gpu_available, gpu_context, gpu_session
from engine.gpu.phasor_slice import diamond_mask, phasor_slice_gpu, sawtooth
from engine.gpu.slice_plane import SlicePlane

__all__ = ["GpuUnavailable", "SlicePlane", "diamond_mask", "gpu_available", "gpu_context",
           "gpu_session", "phasor_slice_gpu", "sawtooth"]
