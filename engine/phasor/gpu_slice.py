"""Phasor noises on a planar slice, evaluated on the GPU.

Tricard et al. 2021 (section 3.3) draw each slice by evaluating the two
sawtooth phasor noises directly from the kernels in a pixel shader.  This
module does the same with the formulas of :mod:`engine.phasor.kernels`
(checked against :mod:`engine.phasor.noise`): each pixel sums both complex
noises G_v and G_w over the kernels within reach (R unfiltered,
R sqrt(1 + s^2) filtered), sharing the distance and, unfiltered, the
Gaussian envelope.  Results are float32 (RGBA32F: Re/Im of both noises).

How the work is laid out
------------------------
The slice is done in tiles (default 256 x 256 pixels), with progress and
cancel between them.  For each tile the kernels whose reach sphere meets
it are projected on the plane (float64, :mod:`engine.phasor._slice_bins`) and
listed per ``bin x bin`` pixel square; a compute-shader work group is one
square and loops over its list.  This differs from the textbook fragment
shader that walks the 3D cells around each pixel, for two reasons measured
on Mesa's llvmpipe (the only "GPU" here): masked-off SIMD lanes still
execute, so an early distance test saves nothing and the 3D-cell walk
pays for 2-5x more kernels than are in reach; and buffer loads at a
per-pixel index are a scalar loop over lanes, while loads at an index that
is the same for the whole work group are one load.  Both choices are
neutral or better on a real GPU.

GPU data layout (per tile, and per chunk of at most ``capacity`` kernels)
-------------------------------------------------------------------------
uniform block 0, ``site[i]``: {int foot; float du, dv, depth} -- the pixel
    nearest the kernel's foot on the plane (tile-relative column in the low
    16 bits, row in the high 16), the foot minus that pixel's centre (mm,
    along u and v) and the signed distance to the plane (mm, along n = u x v)
uniform block 1, ``osc_v[i]``: vec4 -- f_j d_vj in the (u, v, n) basis
    (cycles/mm); w = (phi_vj / 2 pi - g_n depth) mod 1 (cycles)
uniform block 2, ``osc_w[i]``: the same for noise w
storage buffers 3, 4: ``bin_start`` (int CSR offsets per bin) and
    ``bin_items`` (int indices into the blocks)
image 0: RGBA32F tile, accumulated over chunks
Filtered only: 3D textures on the fields grid (texel [z][y][x] = cell
centre), RGBA32F (D_x, D_y, D_z, F) and R32F A(x), read with ``texelFetch``
and blended in the shader exactly as :func:`engine.phasor.fields.trilinear`
(hardware LINEAR filtering uses 8-bit weights on many GPUs, which would
move filtered phases by up to ~0.05 rad where D turns quickly).

Precision
---------
Everything that depends on absolute positions (the kernel's foot, its
depth, the constant part of its phase) is computed in float64 on the CPU;
the shader works in float32 on tile-relative whole pixels (exact) plus
sub-pixel offsets, so ``r = x - x_j`` is off by about ``2^-24 |r|``, and
phases are carried in cycles and reduced to [-1/2, 1/2] before sin/cos.
One kernel's phase is then off by ~``2 pi 2^-24 f |r|`` (~4e-6 rad at
f |r| = 10 cycles) and each term by a few 1e-7; summed in float32 this
leaves ``|G - G_ref| ~ 1e-6 max|G|``, so the wrapped phase error is about
``1e-6 max|G| / |G|`` rad: ~1e-5 rad where |G| > 0.1 max|G| and below
1e-4 rad where |G| > 0.01 max|G| (tests/engine/gpu).  Where |G| is smaller
the phase is ill-conditioned in any precision (a singularity of the
noise).  A kernel within ~1e-6 relative of the truncation sphere may be
counted by one side only (float32 vs float64 distance).
"""

from __future__ import annotations

import math
import threading

import numpy as np

from engine.gpu.context import gpu_session
from engine.gpu.slice_plane import SlicePlane
from engine.progress import report

from ._gpu_slice_glsl import compute_source
from ._slice_bins import bin_lists, plane_basis, project_kernels, tile_members
from .kernels import PhasorKernels
from .sampling import VERTICAL_EPS

DEFAULT_TILE = 256  # pixels per tile side: ~0.1 s per tile filtered on llvmpipe
# Pixels of a row per shader invocation, unfiltered / filtered: each kernel
# entry loaded serves that many pixels, but more live values spill
# registers (llvmpipe, AVX2); these were the fastest measured.
_PIXELS_PER_INVOCATION = {False: 1, True: 2}
_OUTPUTS = ("complex", "sawtooth", "mask")
_PROGRAMS = {}
_PROGRAMS_LOCK = threading.Lock()


# ------------------------------------------------------------------ helpers

def sawtooth(g) -> np.ndarray:
    """Sawtooth value ``p = (Arg G / 2 pi) mod 1``, float32 in [0, 1), same shape as ``g``."""
    p = np.mod(np.angle(np.asarray(g)).astype(np.float32) / np.float32(2 * math.pi), np.float32(1.0))
    p[p >= 1.0] = 0.0
    return p


def diamond_mask(p_v, p_w) -> np.ndarray:
    """True inside the black diamond cells: ``|1/2 - p_v| + |1/2 - p_w| < 1/2``."""
    return (np.abs(0.5 - np.asarray(p_v)) + np.abs(0.5 - np.asarray(p_w))) < 0.5


def filtered_reach(radius: float, filter_scale: float) -> float:
    """Truncation radius of the filtered kernels, ``R sqrt(1 + s^2)`` mm."""
    return float(radius) * math.sqrt(1.0 + float(filter_scale) ** 2)


def bin_size(reach: float, plane: SlicePlane) -> int:
    """Bin side in pixels: about reach / 12, a power of two in [4, 32]."""
    reach_px = reach / float(np.min(plane.size / plane.resolution))
    return int(np.clip(2 ** round(math.log2(max(reach_px / 12.0, 1.0))), 4, 32))


# ---------------------------------------------------------------- checks

def _check(kernels, plane, fields, filtered, filter_scale, attenuation, out, tile):
    if not isinstance(kernels, PhasorKernels):
        raise TypeError(f"kernels: expected PhasorKernels, got {type(kernels).__name__}")
    if not isinstance(plane, SlicePlane):
        raise TypeError(f"plane: expected a SlicePlane, got {type(plane).__name__}")
    if out not in _OUTPUTS:
        raise ValueError(f"out: expected one of {_OUTPUTS}, got {out!r}")
    if int(tile) < 1:
        raise ValueError(f"tile: expected a positive pixel count, got {tile!r}")
    if not filtered:
        return None
    if fields is None:
        raise ValueError("fields: filtered evaluation needs the PhasorFields (D and F at each pixel)")
    s = float(filter_scale)
    if not math.isfinite(s) or s <= 0:
        raise ValueError(f"filter_scale: expected a positive number (filter radius / kernel radius), got {s!r}")
    if attenuation is None:
        return None
    a = np.asarray(attenuation, dtype=np.float64)
    if a.shape != fields.shape:
        raise ValueError(f"attenuation: expected the fields grid shape {fields.shape}, got {a.shape}")
    if not np.all(np.isfinite(a)) or a.min() < 0 or a.max() > 1:
        raise ValueError("attenuation: values must lie in [0, 1]")
    return a


# --------------------------------------------------------------- GL side

def _program(ctx, filtered: bool, bin_px: int, capacity: int):
    key = (id(ctx), bool(filtered), int(bin_px), int(capacity))
    with _PROGRAMS_LOCK:
        if key not in _PROGRAMS:
            pix = _PIXELS_PER_INVOCATION[bool(filtered)]
            defines = (f"#version 430\n#define BIN {bin_px}\n#define PIX {pix}\n"
                       f"#define GROUP_X {bin_px // pix}\n#define CAPACITY {capacity}\n"
                       f"#define FRAME_EPS {VERTICAL_EPS!r}\n" + ("#define FILTERED\n" if filtered else ""))
            _PROGRAMS[key] = ctx.compute_shader(defines + compute_source(pix, filtered))
        return _PROGRAMS[key]


def _capacity(ctx) -> int:
    """Kernels per chunk: one vec4 per kernel in each 64 KB-class uniform block."""
    size = int(ctx.info.get("GL_MAX_UNIFORM_BLOCK_SIZE", 16384))
    return max(256, min(size, 65536) // 16)


def _set(prog, name, value):
    if name in prog:  # the compiler drops uniforms a variant does not use
        prog[name].value = value


def _chunk_arrays(pk, chunk, rect, plane):
    """Uniform-block contents (site, osc_v, osc_w) for the kernels ``pk[chunk]``."""
    r0, c0 = rect[0], rect[1]
    pu, pv = (float(v) for v in plane.size / plane.resolution)
    s, t = pk.col[chunk] - c0, pk.row[chunk] - r0
    fs, ft = np.rint(s), np.rint(t)
    if len(chunk) and max(np.abs(fs).max(), np.abs(ft).max()) >= 2 ** 15:
        raise ValueError("plane: a kernel footprint spans more than 32767 pixels; use larger pixels")
    site = np.zeros(len(chunk), dtype=[("foot", "<i4"), ("du", "<f4"), ("dv", "<f4"), ("depth", "<f4")])
    site["foot"] = (fs.astype(np.int64) & 0xFFFF) | (ft.astype(np.int64) << 16)
    site["du"] = (s - fs) * pu
    site["dv"] = (t - ft) * pv
    site["depth"] = pk.depth[chunk]
    osc_v = np.column_stack([pk.g_v[chunk], pk.c_v[chunk]]).astype(np.float32)
    osc_w = np.column_stack([pk.g_w[chunk], pk.c_w[chunk]]).astype(np.float32)
    return site, osc_v, osc_w


def _field_uniforms(ctx, prog, plane, fields, attenuation, b, s, owned):
    a = b / s ** 2
    _set(prog, "u_delta_coef", math.pi ** 2 / (a + b))
    _set(prog, "u_shift", b / (a + b))
    texel = np.array(fields.shape[::-1], dtype=np.float64) / (fields.hi - fields.lo)
    _set(prog, "u_tex_step_u", tuple(plane.pixel_u * texel))
    _set(prog, "u_tex_step_v", tuple(plane.pixel_v * texel))
    _set(prog, "u_field_n", tuple(int(v) for v in fields.shape[::-1]))
    for name, axis in zip(("u_axis_u", "u_axis_v", "u_axis_n"), plane_basis(plane)):
        _set(prog, name, tuple(axis))
    df = np.concatenate([fields.direction, fields.frequency[..., None]], axis=-1).astype(np.float32)
    att = (np.ones(fields.shape) if attenuation is None else attenuation).astype(np.float32)
    for unit, (name, data, comps) in enumerate((("u_fields", df, 4), ("u_atten", att, 1))):
        tex = ctx.texture3d(data.shape[2::-1], comps, np.ascontiguousarray(data).tobytes(), dtype="f4")
        tex.filter = (ctx.NEAREST, ctx.NEAREST)  # read by texelFetch only
        owned.append(tex)
        tex.use(location=unit)
        _set(prog, name, unit)
    return texel


# ------------------------------------------------------------------ main

def phasor_slice_gpu(kernels, plane, *, fields=None, filtered=False, filter_scale=2.0,
                     attenuation=None, out="complex", tile=DEFAULT_TILE, progress=None):
    """The two phasor noises on a slice, evaluated by the GPU shader.

    Parameters
    ----------
    kernels : PhasorKernels
    plane : SlicePlane
        ``SlicePlane.axis_aligned(axis, position, pixel_size, extent)`` or
        ``SlicePlane(origin, u_axis, v_axis, size, resolution)``.
    fields : PhasorFields, optional
        Needed when ``filtered`` (F(x) and D(x) at each pixel).
    filtered : bool
        Use the filtered kernels (eq. 14-16) instead of the plain ones.
    filter_scale : float
        s: filter radius in kernel radii (a = b / s^2).
    attenuation : (nz, ny, nx) array in [0, 1], optional
        A(x) on the fields grid, sampled trilinearly; ``None`` means A = 1.
    out : {"complex", "sawtooth", "mask"}
        What to return (see Returns).
    tile : int
        Tile side in pixels (rounded up to whole bins); one dispatch (per
        chunk of kernels) and one progress report per tile.
    progress : callable ``progress(done, total) -> bool``, optional
        Called before the first tile and after each; returning ``False``
        raises :class:`engine.progress.Cancelled`.

    Returns
    -------
    "complex": (G_v, G_w), each (H, W) complex64;
    "sawtooth": (p_v, p_w), each (H, W) float32 in [0, 1);
    "mask": (H, W) bool, True in black diamond cells.
    Row i, column j is the pixel centred at
    ``plane.origin + (j + 1/2) plane.pixel_u + (i + 1/2) plane.pixel_v``.

    Raises
    ------
    engine.gpu.context.GpuUnavailable
        If no OpenGL 4.3 context can be created.
    """
    att = _check(kernels, plane, fields, filtered, filter_scale, attenuation, out, tile)
    rgba = _render(kernels, plane, fields, bool(filtered), float(filter_scale), att, int(tile), progress)
    g_v = (rgba[..., 0] + 1j * rgba[..., 1]).astype(np.complex64)
    g_w = (rgba[..., 2] + 1j * rgba[..., 3]).astype(np.complex64)
    if out == "complex":
        return g_v, g_w
    p_v, p_w = sawtooth(g_v), sawtooth(g_w)
    return (p_v, p_w) if out == "sawtooth" else diamond_mask(p_v, p_w)


def _render(kernels, plane, fields, filtered, s, attenuation, tile, progress):
    h, w = plane.shape
    b = kernels.bandwidth
    if filtered:
        reach, env = filtered_reach(kernels.radius, s), b / (1.0 + s ** 2)  # ab / (a + b)
    else:
        reach, env = float(kernels.radius), b
    bin_px = bin_size(reach, plane)
    tile = -(-tile // bin_px) * bin_px
    tiles = [(r0, c0, min(tile, h - r0), min(tile, w - c0))
             for r0 in range(0, h, tile) for c0 in range(0, w, tile)]
    report(progress, 0, len(tiles))
    pk = project_kernels(kernels, plane, reach)
    result = np.zeros((h, w, 4), dtype=np.float32)
    with gpu_session() as ctx:
        owned = []
        try:
            capacity = _capacity(ctx)
            prog = _program(ctx, filtered, bin_px, capacity)
            _set(prog, "u_pixel", tuple(float(v) for v in plane.size / plane.resolution))
            _set(prog, "u_reach2", reach ** 2)
            _set(prog, "u_env", env)
            if filtered:
                texel = _field_uniforms(ctx, prog, plane, fields, attenuation, b, s, owned)
            blocks = [ctx.buffer(reserve=16 * capacity) for _ in range(3)]
            owned.extend(blocks)
            for binding, buf in enumerate(blocks):
                buf.bind_to_uniform_block(binding)
            image = ctx.texture((min(tile, w), min(tile, h)), 4, dtype="f4")
            owned.append(image)
            image.bind_to_image(0, read=True, write=True)
            for done, rect in enumerate(tiles, start=1):
                r0, c0, th, tw = rect
                _set(prog, "u_size", (tw, th))
                if filtered:
                    centre = plane.origin + (c0 + 0.5) * plane.pixel_u + (r0 + 0.5) * plane.pixel_v
                    _set(prog, "u_tile_origin", tuple((centre - fields.lo) * texel - 0.5))
                members = tile_members(pk, plane, rect)
                if not len(members):  # nothing reaches this tile: G = 0
                    report(progress, done, len(tiles))
                    continue
                for n_chunk, first in enumerate(range(0, len(members), capacity)):
                    chunk = members[first:first + capacity]
                    for buf, data in zip(blocks, _chunk_arrays(pk, chunk, rect, plane)):
                        buf.write(data.tobytes())
                    bin_start, items = bin_lists(pk, chunk, plane, rect, bin_px)
                    lists = [ctx.buffer(bin_start.astype(np.int32).tobytes()),
                             ctx.buffer(items.astype(np.int32).tobytes() if items.size else b"\0" * 4)]
                    try:
                        for binding, buf in enumerate(lists, start=3):
                            buf.bind_to_storage_buffer(binding)
                        _set(prog, "u_accumulate", int(n_chunk > 0))
                        ctx.memory_barrier()
                        prog.run(-(-tw // bin_px), -(-th // bin_px))
                    finally:
                        for buf in lists:
                            buf.release()
                ctx.memory_barrier()
                pixels = np.frombuffer(image.read(), np.float32).reshape(image.height, image.width, 4)
                result[r0:r0 + th, c0:c0 + tw] = pixels[:th, :tw]
                report(progress, done, len(tiles))
        finally:
            for obj in reversed(owned):
                obj.release()
    return result
