"""An SDF tree evaluated at arbitrary points by a GLSL compute shader.

The same tree that `engine.implicit` evaluates in numpy (`SDF.field`) writes
its GLSL (`SDF.glsl` into a `GlslModule`); :func:`evaluate_glsl` wraps that
source in a compute shader and runs it on the shared headless context, so
tests (and the sphere tracer's users) can check that the two agree.

Shader layout (GL 4.3, std430, float32)
---------------------------------------
storage buffer 0, ``pts[3 i + k]``: coordinate k of point i (mm), packed as
    plain floats (a ``vec3`` array would be padded to 16 bytes in std430);
storage buffer 1, ``vals[i]``: f at point i;
uniforms ``u_first`` (index of the dispatch's first point) and ``u_count``;
one ``sampler3D`` per texture the module declared (`GlslModule.texture3d`),
uploaded as R32F with linear filtering and repeat wrapping, on texture
units 0, 1, ... in declaration order.  Texel ``data[z, y, x]`` is at
texture coordinate ``((x, y, z) + 0.5) / (nx, ny, nz)``.

Points are chunked into dispatches of at most `CHUNK_POINTS` (the work-group
count per dimension is limited to 65535 by the GL spec).

:func:`evaluate_glsl_grid` evaluates the nodes of a regular grid without
sending points: the shader makes node ``(i, j, k)`` at ``origin + (i, j, k) *
spacing`` itself, a block of x planes per dispatch (between blocks the
caller's progress is told and may cancel), and writes ``f / lipschitz``.
"""

from __future__ import annotations


import numpy as np

from engine.gpu.context import gpu_session
from engine.gpu.shader_cache import bind_textures, compute_program
from engine.implicit.values import SDF, GlslModule, as_points

from engine.progress import report

__all__ = ["evaluate_glsl", "evaluate_glsl_grid", "compute_source", "grid_source", "GROUP_SIZE",
           "CHUNK_POINTS"]

GROUP_SIZE = 64
CHUNK_POINTS = GROUP_SIZE * 16384   # 1 M points per dispatch

_TEMPLATE = """#version 430
layout(local_size_x = {group}) in;
layout(std430, binding = 0) readonly buffer Points {{ float pts[]; }};
layout(std430, binding = 1) writeonly buffer Values {{ float vals[]; }};
uniform uint u_first;
uniform uint u_count;

{library}
void main() {{
    uint j = gl_GlobalInvocationID.x;
    if (j >= u_count) return;
    uint i = u_first + j;
    vec3 p = vec3(pts[3u * i], pts[3u * i + 1u], pts[3u * i + 2u]);
    vals[i] = {entry}(p);
}}
"""


_GRID_TEMPLATE = """#version 430
layout(local_size_x = {group}) in;
layout(std430, binding = 1) writeonly buffer Values {{ float vals[]; }};
uniform vec3 u_origin;
uniform vec3 u_spacing;
uniform ivec3 u_shape;     // (planes in this block, ny, nz)
uniform int u_first_x;

{library}
void main() {{
    uint j = gl_GlobalInvocationID.x;
    uint count = uint(u_shape.x * u_shape.y * u_shape.z);
    if (j >= count) return;
    int k = int(j % uint(u_shape.z));
    int r = int(j / uint(u_shape.z));
    int y = r % u_shape.y;
    int x = r / u_shape.y + u_first_x;
    vec3 p = u_origin + vec3(x, y, k) * u_spacing;
    vals[j] = {entry}(p);
}}
"""


def grid_source(module: GlslModule, entry: str) -> str:
    """The compute shader evaluating ``float entry(vec3 p)`` at the nodes of a block of grid planes."""
    return _GRID_TEMPLATE.format(group=GROUP_SIZE, library=module.source(), entry=entry)


def compute_source(module: GlslModule, entry: str) -> str:
    """The compute shader evaluating ``float entry(vec3 p)`` of `module` at every point.

    Parameters
    ----------
    module : GlslModule
        Holds `entry` and everything it calls.
    entry : str
        The name `SDF.glsl` returned.

    Returns
    -------
    str, GLSL 4.30 source.
    """
    return _TEMPLATE.format(group=GROUP_SIZE, library=module.source(), entry=entry)


def evaluate_glsl(sdf: SDF, points) -> np.ndarray:
    """f of `sdf` at `points`, computed by its GLSL on the headless GPU context.

    Parameters
    ----------
    sdf : SDF
        Any tree of `engine.implicit` values.
    points : (n, 3) array_like, mm
        Sent to the GPU as float32.

    Returns
    -------
    (n,) float64
        ``sdf.glsl`` evaluated in float32 (the raw field f, not f / lipschitz),
        to compare with ``sdf.field(points)``.

    Raises
    ------
    ValueError
        If `sdf` is not an SDF or `points` is not (n, 3) finite.
    engine.gpu.context.GpuUnavailable
        If no OpenGL 4.3 context can be created.
    """
    if not isinstance(sdf, SDF):
        raise ValueError(f"sdf: expected an engine.implicit SDF, got {type(sdf).__name__}")
    p = as_points(points)
    n = p.shape[0]
    if n == 0:
        return np.zeros(0, dtype=np.float64)
    if n >= 2 ** 31 // 3:
        raise ValueError(f"points: at most {2 ** 31 // 3 - 1} points per call, got {n}")
    module = GlslModule()
    entry = sdf.glsl(module)
    source = compute_source(module, entry)
    with gpu_session() as ctx:
        owned = []
        try:
            prog = compute_program(ctx, source)
            bind_textures(ctx, prog, module.textures, owned)
            pts = ctx.buffer(p.astype(np.float32).tobytes())
            owned.append(pts)
            out = ctx.buffer(reserve=4 * n)
            owned.append(out)
            pts.bind_to_storage_buffer(0)
            out.bind_to_storage_buffer(1)
            for first in range(0, n, CHUNK_POINTS):
                count = min(CHUNK_POINTS, n - first)
                prog["u_first"].value = first
                prog["u_count"].value = count
                prog.run(-(-count // GROUP_SIZE))
            ctx.memory_barrier()
            values = np.frombuffer(out.read(), dtype=np.float32)
        finally:
            for obj in reversed(owned):
                obj.release()
    return values.astype(np.float64)


def evaluate_glsl_grid(sdf: SDF, origin, spacing, shape, *, progress=None) -> np.ndarray:
    """``f / lipschitz`` of `sdf` at the nodes ``origin + (i, j, k) * spacing`` of a grid, on the GPU.

    Parameters
    ----------
    sdf : SDF
    origin : (3,) mm, the node (0, 0, 0); spacing : (3,) mm > 0
    shape : (nx, ny, nz) ints >= 1
    progress : callable(done, total) -> bool, optional; called between blocks of x
        planes; False raises `engine.progress.Cancelled`.

    Returns
    -------
    (nx, ny, nz) float32, the normalised distance (mm) in float32 (as `SDF.distance`).

    Raises
    ------
    ValueError
        For a bad sdf, origin, spacing or shape (more than 2^31 nodes).
    engine.gpu.context.GpuUnavailable
        If no OpenGL 4.3 context can be created.
    """
    if not isinstance(sdf, SDF):
        raise ValueError(f"sdf: expected an engine.implicit SDF, got {type(sdf).__name__}")
    o = np.asarray(origin, dtype=np.float64).reshape(-1)
    h = np.asarray(spacing, dtype=np.float64).reshape(-1)
    n = tuple(int(v) for v in np.asarray(shape).reshape(-1))
    if o.shape != (3,) or not np.all(np.isfinite(o)):
        raise ValueError(f"origin must be three finite coordinates, got {origin!r}")
    if h.shape != (3,) or not np.all(np.isfinite(h)) or np.any(h <= 0):
        raise ValueError(f"spacing must be three lengths > 0, got {spacing!r}")
    if len(n) != 3 or min(n) < 1 or np.prod(n, dtype=np.int64) >= 2 ** 31:
        raise ValueError(f"shape must be three node counts >= 1 (fewer than 2^31 in all), got {shape!r}")
    module = GlslModule()
    entry = sdf.glsl_distance(module)
    source = grid_source(module, entry)
    planes = max(1, CHUNK_POINTS // (n[1] * n[2]))
    out = np.empty(n, dtype=np.float32)
    report(progress, 0, n[0])
    with gpu_session() as ctx:
        owned = []
        try:
            prog = compute_program(ctx, source)
            bind_textures(ctx, prog, module.textures, owned)
            buf = ctx.buffer(reserve=4 * min(planes, n[0]) * n[1] * n[2])
            owned.append(buf)
            buf.bind_to_storage_buffer(1)
            prog["u_origin"].value = tuple(o)
            prog["u_spacing"].value = tuple(h)
            for x0 in range(0, n[0], planes):
                m = min(planes, n[0] - x0)
                count = m * n[1] * n[2]
                prog["u_shape"].value = (m, n[1], n[2])
                prog["u_first_x"].value = x0
                prog.run(-(-count // GROUP_SIZE))
                ctx.memory_barrier()
                out[x0:x0 + m] = np.frombuffer(buf.read(size=4 * count), dtype=np.float32).reshape(m, n[1], n[2])
                report(progress, x0 + m, n[0])
        finally:
            for obj in reversed(owned):
                obj.release()
    return out
