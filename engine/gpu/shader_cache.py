"""Compute programs and 3D textures of SDF shaders, shared by every SDF shader front
(`sdf_points`, `sphere_trace`, `path_trace`).

`compute_program` keeps the most recently used programs compiled (keyed on the context and the
source text: an SDF tree with other parameters writes other literals, so another program);
`bind_textures` uploads the textures a `GlslModule` declared (R32F, linear filtering, repeat
wrapping) on units 0, 1, ... in declaration order.  Texel ``data[z, y, x]`` is at texture
coordinate ``((x, y, z) + 0.5) / (nx, ny, nz)``; the SDF code reads them with ``texelFetch``.
"""

from __future__ import annotations

import threading
from collections import OrderedDict

import numpy as np

__all__ = ["compute_program", "bind_textures", "CACHE_SIZE"]

CACHE_SIZE = 16                                         # compiled programs kept
_PROGRAMS: "OrderedDict[tuple, object]" = OrderedDict()
_LOCK = threading.Lock()


def compute_program(ctx, source: str):
    """The compiled compute shader of `source` on `ctx` (compiled once, least recently used dropped)."""
    key = (id(ctx), source)
    with _LOCK:
        prog = _PROGRAMS.pop(key, None)
        if prog is None:
            prog = ctx.compute_shader(source)
        _PROGRAMS[key] = prog
        while len(_PROGRAMS) > CACHE_SIZE:
            _PROGRAMS.popitem(last=False)[1].release()
        return prog


def bind_textures(ctx, prog, textures: dict, owned: list) -> None:
    """Upload `textures` ({uniform name: (nz, ny, nx) array}) and bind them for `prog`; the
    textures are appended to `owned` (the caller releases them).

    Raises
    ------
    ValueError
        For an array that is not 3-D with at least one texel per axis.
    """
    for unit, (name, data) in enumerate(textures.items()):
        arr = np.ascontiguousarray(data, dtype=np.float32)
        if arr.ndim != 3 or min(arr.shape) < 1:
            raise ValueError(f"texture {name!r}: expected a (nz, ny, nx) array, got shape {arr.shape}")
        tex = ctx.texture3d(arr.shape[::-1], 1, arr.tobytes(), dtype="f4")
        owned.append(tex)
        tex.filter = (ctx.LINEAR, ctx.LINEAR)
        tex.repeat_x = tex.repeat_y = tex.repeat_z = True
        tex.use(location=unit)
        if name in prog:            # the compiler drops samplers the tree does not read
            prog[name].value = unit
