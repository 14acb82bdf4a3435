"""Fixtures shared by the engine tests: `gpu`, the headless OpenGL context (GPU and implicit tests)."""

import pytest

from engine.gpu.context import GpuUnavailable, gpu_context


@pytest.fixture(scope="session")
def gpu():
    """The shared headless context; the GPU tests skip (with the reason) only if EGL fails."""
    try:
        return gpu_context()
    except GpuUnavailable as exc:
        pytest.skip(f"no headless OpenGL 4.3 context through EGL: {exc}")
