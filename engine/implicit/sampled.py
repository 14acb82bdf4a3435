"""A signed distance sampled on a regular grid, as an SDF: e.g. a unit cell's solid.

`Sampled` interpolates node samples trilinearly.  A periodic grid (a tileable
cell, like the Object node's solids) repeats over all space; a grid that is
not periodic is clamped to its box and intersected with the box, so outside
it the field is at least the distance to the box.

Lipschitz bound: inside one grid cell the partial derivative along x of the
trilinear interpolant is a convex combination of the four x-differences of
the cell's corners divided by the spacing, so ``|df/dx| <= Dx = max |f[i+1] -
f[i]| / hx`` over the grid (the wrap difference included when periodic) and
``|grad f| <= sqrt(Dx^2 + Dy^2 + Dz^2)``.  For a sampled exact distance Dx <=
1 and the bound is at most sqrt(3); it is computed from the samples, never
assumed.

The GLSL twin reads the samples with ``texelFetch`` and interpolates in the
shader with the same weights as numpy (float32), not by the texture unit's
filtering (whose weights may be quantised).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .values import SDF, GlslModule, as_points, glsl_float

__all__ = ["Sampled"]


def _gradient_bound(values: np.ndarray, spacing: np.ndarray, periodic: bool) -> float:
    parts = []
    for axis in range(3):
        v = values
        if periodic:
            v = np.concatenate([v, np.take(v, [0], axis=axis)], axis=axis)
        d = np.abs(np.diff(v, axis=axis)).max() if v.shape[axis] > 1 else 0.0
        parts.append(float(d) / float(spacing[axis]))
    return math.sqrt(sum(p * p for p in parts))


@dataclass(frozen=True, eq=False)
class Sampled(SDF):
    """Trilinear interpolation of node samples ``values[i, j, k]`` at ``origin + (i, j, k) * spacing``.

    values : (nx, ny, nz) float, signed distance in mm (negative inside), each n >= 2.
    origin : (3,) mm, the first node.
    spacing : (3,) mm > 0, node spacing per axis.
    periodic : the grid is one period (the node after the last is the first again):
        the field tiles space with period ``n * spacing``.  Otherwise nodes span the box
        ``[origin, origin + (n - 1) * spacing]``, points outside are clamped to it and the
        box is intersected (max with the box's distance).

    Raises
    ------
    ValueError
        If `values` is not a 3-D grid with two nodes per axis, holds NaN / infinite
        samples, or `spacing` is not three lengths > 0.
    """

    values: np.ndarray
    origin: tuple = (0.0, 0.0, 0.0)
    spacing: tuple = (1.0, 1.0, 1.0)
    periodic: bool = True

    def __post_init__(self):
        v = np.array(self.values, dtype=np.float64)
        if v.ndim != 3 or min(v.shape) < 2:
            raise ValueError(f"sampled values must be an (nx, ny, nz) grid with at least 2 nodes per "
                             f"axis, got shape {v.shape}")
        if not np.all(np.isfinite(v)):
            raise ValueError("sampled values hold NaN or infinite samples")
        o = np.array(self.origin, dtype=np.float64).reshape(-1)
        h = np.array(self.spacing, dtype=np.float64).reshape(-1)
        if o.shape != (3,) or not np.all(np.isfinite(o)):
            raise ValueError(f"origin must be three finite coordinates (mm), got {self.origin!r}")
        if h.shape != (3,) or not np.all(np.isfinite(h)) or np.any(h <= 0):
            raise ValueError(f"spacing must be three lengths > 0 mm, got {self.spacing!r}")
        for arr in (v, o, h):
            arr.setflags(write=False)
        object.__setattr__(self, "values", v)
        object.__setattr__(self, "origin", o)
        object.__setattr__(self, "spacing", h)
        object.__setattr__(self, "periodic", bool(self.periodic))
        bound = _gradient_bound(v, h, self.periodic)
        object.__setattr__(self, "_bound", max(bound, 1.0) if not self.periodic else max(bound, 1e-12))

    @property
    def lipschitz(self) -> float:
        return self._bound

    @property
    def shape(self) -> tuple:
        return tuple(int(n) for n in self.values.shape)

    def _box(self):
        hi = self.origin + (np.array(self.shape) - 1) * self.spacing
        return self.origin, hi

    def field(self, points) -> np.ndarray:
        p = as_points(points)
        n = np.array(self.shape)
        u = (p - self.origin) / self.spacing                  # node units
        if self.periodic:
            base = np.floor(u)
            t = u - base
            i0 = np.mod(base.astype(np.int64), n)
            i1 = np.mod(i0 + 1, n)
        else:
            u = np.clip(u, 0.0, n - 1.0)
            base = np.minimum(np.floor(u), n - 2)
            t = u - base
            i0 = base.astype(np.int64)
            i1 = i0 + 1
        v = self.values
        out = np.zeros(len(p))
        for cx in (0, 1):
            wx = t[:, 0] if cx else 1.0 - t[:, 0]
            ix = i1[:, 0] if cx else i0[:, 0]
            for cy in (0, 1):
                wy = t[:, 1] if cy else 1.0 - t[:, 1]
                iy = i1[:, 1] if cy else i0[:, 1]
                for cz in (0, 1):
                    wz = t[:, 2] if cz else 1.0 - t[:, 2]
                    iz = i1[:, 2] if cz else i0[:, 2]
                    out += wx * wy * wz * v[ix, iy, iz]
        if not self.periodic:
            lo, hi = self._box()
            q = np.abs(p - 0.5 * (lo + hi)) - 0.5 * (hi - lo)
            box = np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0)
            out = np.maximum(out, box)
        return out

    def glsl(self, module: GlslModule) -> str:
        tex = module.texture3d(self, np.transpose(self.values, (2, 1, 0)))   # (nz, ny, nx)
        o = ", ".join(glsl_float(x) for x in self.origin)
        inv = ", ".join(glsl_float(1.0 / x) for x in self.spacing)
        nx, ny, nz = self.shape
        lo, hi = self._box()
        centre = ", ".join(glsl_float(x) for x in 0.5 * (lo + hi))
        half = ", ".join(glsl_float(x) for x in 0.5 * (hi - lo))
        if self.periodic:
            index = ("vec3 b = floor(u); vec3 t = u - b;\n"
                     "    ivec3 i0 = ivec3(mod(b, n)); ivec3 i1 = ivec3(mod(b + 1.0, n));")
            tail = "return v;"
        else:
            index = ("u = clamp(u, vec3(0.0), n - 1.0); vec3 b = min(floor(u), n - 2.0); vec3 t = u - b;\n"
                     "    ivec3 i0 = ivec3(b); ivec3 i1 = i0 + 1;")
            tail = (f"vec3 q = abs(p - vec3({centre})) - vec3({half});\n"
                    "    return max(v, length(max(q, 0.0)) + min(max(q.x, max(q.y, q.z)), 0.0));")

        def make(name):
            return f"""float {name}(vec3 p) {{
    vec3 n = vec3({glsl_float(nx)}, {glsl_float(ny)}, {glsl_float(nz)});
    vec3 u = (p - vec3({o})) * vec3({inv});
    {index}
    float v = 0.0;
    for (int c = 0; c < 8; c++) {{
        ivec3 s = ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
        ivec3 idx = ivec3(s.x == 1 ? i1.x : i0.x, s.y == 1 ? i1.y : i0.y, s.z == 1 ? i1.z : i0.z);
        vec3 w = mix(vec3(1.0) - t, t, vec3(s));
        v += w.x * w.y * w.z * texelFetch({tex}, idx, 0).r;
    }}
    {tail}
}}"""
        return module.function(self, make)

    def box(self):
        if self.periodic:
            return None
        lo, hi = self._box()
        return (tuple(lo), tuple(hi))
