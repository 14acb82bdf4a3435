"""Cell-centred samples over a box, read by trilinear interpolation in numpy and GLSL alike.

A `GridField` holds samples ``values[z, y, x]`` (the geometry `Field`
convention): the box ``[lo, hi]`` (mm, ``(x, y, z)`` order) is cut into
``nx x ny x nz`` cells of spacing ``h = (hi - lo) / (nx, ny, nz)`` and each
sample sits at its cell's centre ``lo + (i + 0.5) h``.  Between sample
centres the value is the trilinear interpolant; beyond the outermost
centres (the half cell at the box's faces, and all space outside the box)
each coordinate is clamped to the outermost centre, so the value is
extended as a constant along that axis.  An axis with one sample is
constant.  The interpolant never leaves ``[min(values), max(values)]``.

Gradient bound: inside one cell of the centre grid the partial derivative
along x of the trilinear interpolant is a convex combination (weights from
the other two axes) of the four x-differences of the cell's corners divided
by the spacing, so ``|df/dx| <= Dx = max |v[.., i+1] - v[.., i]| / hx``;
where x is clamped, df/dx = 0.  Hence ``|grad f| <= sqrt(Dx^2 + Dy^2 + Dz^2)
<= sqrt(3) max(Dx, Dy, Dz)`` everywhere: `lipschitz` is the first, tighter
form, computed from the samples.  Clamping is continuous, so f is
Lipschitz across the box's faces too.

The GLSL twin (`GridField.glsl`) reads the samples with ``texelFetch`` from
a 3D texture (`GlslModule.texture3d`) and weights them in the shader
exactly as `sample` does (float32), never through the texture unit's
filtering, whose weights may be quantised.

`grid_field_from` makes a GridField of 3-D samples, or of 2-D samples
extruded along an axis (constant along it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .values import GlslModule, as_points, glsl_float

__all__ = ["GridField", "as_grid_field", "grid_field_from"]


@dataclass(frozen=True, eq=False)
class GridField:
    """Cell-centred samples over a box, interpolated trilinearly and clamped (module docstring).

    values : (nz, ny, nx) float, finite, every n >= 1 (read-only float64 after checking).
    lo, hi : (3,) mm, the box corners in (x, y, z) order, hi > lo.

    Raises
    ------
    ValueError
        If `values` is not a 3-D array of finite numbers with at least one sample per
        axis, or lo / hi are not three finite coordinates with hi > lo.
    """

    values: np.ndarray
    lo: tuple
    hi: tuple

    def __post_init__(self):
        try:
            v = np.array(self.values, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError(f"values must be a (nz, ny, nx) array of numbers, got "
                             f"{type(self.values).__name__}") from None
        if v.ndim != 3 or min(v.shape) < 1:
            raise ValueError(f"values must be a (nz, ny, nx) grid (3-D, at least one sample per axis), "
                             f"got shape {v.shape}")
        if not np.all(np.isfinite(v)):
            raise ValueError("values hold NaN or infinite samples")
        lo = np.array(self.lo, dtype=np.float64).reshape(-1)
        hi = np.array(self.hi, dtype=np.float64).reshape(-1)
        if lo.shape != (3,) or hi.shape != (3,) or not np.all(np.isfinite(lo) & np.isfinite(hi)) \
                or not np.all(hi > lo):
            raise ValueError(f"box must be two finite (x, y, z) corners (mm) with hi > lo, "
                             f"got lo={self.lo!r}, hi={self.hi!r}")
        counts = np.array(v.shape[::-1], dtype=np.float64)            # (nx, ny, nz)
        spacing = (hi - lo) / counts
        for arr in (v, lo, hi, spacing):
            arr.setflags(write=False)
        parts = [float(np.abs(np.diff(v, axis=2 - a)).max()) / spacing[a] if v.shape[2 - a] > 1 else 0.0
                 for a in range(3)]
        for k, val in (("values", v), ("lo", lo), ("hi", hi), ("spacing", spacing),
                       ("lipschitz", math.sqrt(sum(d * d for d in parts))),
                       ("minimum", float(v.min())), ("maximum", float(v.max()))):
            object.__setattr__(self, k, val)

    @property
    def counts(self) -> tuple:
        """(nx, ny, nz), samples per axis in (x, y, z) order."""
        return tuple(int(n) for n in self.values.shape[::-1])

    def sample(self, points) -> np.ndarray:
        """The interpolated value at `points` ((n, 3) mm): (n,) float64."""
        p = as_points(points)
        n = np.array(self.counts, dtype=np.float64)
        u = np.clip((p - self.lo) / self.spacing - 0.5, 0.0, n - 1.0)     # sample units
        base = np.minimum(np.floor(u), np.maximum(n - 2.0, 0.0))
        t = u - base
        i0 = base.astype(np.int64)
        i1 = np.minimum(i0 + 1, n.astype(np.int64) - 1)
        out = np.zeros(len(p))
        for corner in range(8):
            s = np.array([corner & 1, (corner >> 1) & 1, (corner >> 2) & 1], dtype=bool)
            idx = np.where(s, i1, i0)
            w = np.prod(np.where(s, t, 1.0 - t), axis=1)
            out += w * self.values[idx[:, 2], idx[:, 1], idx[:, 0]]
        return out

    def glsl(self, module: GlslModule) -> str:
        """Define ``float NAME(vec3 p)`` (the interpolated value, float32) in `module`; return NAME."""
        nx, ny, nz = self.counts
        lo = ", ".join(glsl_float(x) for x in self.lo)
        inv = ", ".join(glsl_float(1.0 / x) for x in self.spacing)

        def make(name):
            tex = module.texture3d(self, self.values)                    # (nz, ny, nx)
            return f"""float {name}(vec3 p) {{
    vec3 n = vec3({glsl_float(nx)}, {glsl_float(ny)}, {glsl_float(nz)});
    vec3 u = clamp((p - vec3({lo})) * vec3({inv}) - 0.5, vec3(0.0), n - 1.0);
    vec3 b = min(floor(u), max(n - 2.0, vec3(0.0)));
    vec3 t = u - b;
    ivec3 i0 = ivec3(b);
    ivec3 i1 = min(i0 + 1, ivec3(n) - 1);
    float v = 0.0;
    for (int c = 0; c < 8; c++) {{
        ivec3 s = ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
        ivec3 idx = ivec3(s.x == 1 ? i1.x : i0.x, s.y == 1 ? i1.y : i0.y, s.z == 1 ? i1.z : i0.z);
        vec3 w = mix(vec3(1.0) - t, t, vec3(s));
        v += w.x * w.y * w.z * texelFetch({tex}, idx, 0).r;
    }}
    return v;
}}"""
        return module.function(self, make, tag="_grid")


def as_grid_field(obj, name: str) -> GridField:
    """`obj` as a `GridField`: a GridField as it is, or anything with ``values``, ``lo`` and
    ``hi`` (e.g. a 3-D scalar ``engine.geometry.values.Field``).

    Raises
    ------
    ValueError
        Prefixed with `name`, if `obj` has no values / lo / hi or they do not form a
        GridField (see `GridField`).
    """
    if isinstance(obj, GridField):
        return obj
    if not all(hasattr(obj, k) for k in ("values", "lo", "hi")):
        raise ValueError(f"{name} must be a GridField (or a Field with values, lo and hi), "
                         f"got {type(obj).__name__}")
    try:
        return GridField(obj.values, obj.lo, obj.hi)
    except ValueError as exc:
        raise ValueError(f"{name}: {exc}") from None


# the in-plane axes of a 2-D field extruded along axis a: its (u, v) become the other two
# axes in increasing order, (x, y) along z, (x, z) along y, (y, z) along x
_PLANE = {0: (1, 2), 1: (0, 2), 2: (0, 1)}


def grid_field_from(values, lo, hi, *, extrude_axis: int = 2, extent=(0.0, 1.0)) -> GridField:
    """A GridField of 3-D samples, or of 2-D samples extruded along an axis.

    values : (nz, ny, nx) with lo, hi (3,) mm in (x, y, z) order: the GridField as it is;
        or (nv, nu) with lo, hi (2,) mm in (u, v) order (a 2-D ``Field``: u its x, v its y),
        extruded along `extrude_axis` (0, 1, 2 = x, y, z).  The field's u and v become the
        two other axes in increasing order: (x, y) for z, (x, z) for y, (y, z) for x.  The
        result has one sample along the extrusion axis, so it is constant along it.
    extent : (start, end) mm, start < end, the box along the extrusion axis (2-D only; the
        values do not depend on it).

    Raises
    ------
    ValueError
        If values is neither 2-D nor 3-D, lo / hi do not have one coordinate per axis of the
        values, extrude_axis is not 0, 1 or 2, or extent is not finite with start < end;
        and as `GridField` does.
    """
    v = np.asarray(values)
    lo = np.asarray(lo, dtype=np.float64).reshape(-1)
    hi = np.asarray(hi, dtype=np.float64).reshape(-1)
    if v.ndim not in (2, 3):
        raise ValueError(f"values must be a 2-D (ny, nx) or 3-D (nz, ny, nx) grid, got shape {v.shape}")
    if lo.shape != (v.ndim,) or hi.shape != (v.ndim,):
        raise ValueError(f"a {v.ndim}-D grid needs {v.ndim} box coordinates, got lo={lo.tolist()}, "
                         f"hi={hi.tolist()}")
    if v.ndim == 3:
        return GridField(v, lo, hi)
    if extrude_axis not in (0, 1, 2) or isinstance(extrude_axis, bool):
        raise ValueError(f"extrude_axis must be 0, 1 or 2 (x, y, z), got {extrude_axis!r}")
    ext = np.asarray(extent, dtype=np.float64).reshape(-1)
    if ext.shape != (2,) or not np.all(np.isfinite(ext)) or not ext[0] < ext[1]:
        raise ValueError(f"extent must be finite (start, end) mm with start < end, got {extent!r}")
    a, (pu, pv) = extrude_axis, _PLANE[extrude_axis]
    lo3, hi3 = np.empty(3), np.empty(3)
    lo3[[pu, pv, a]] = lo[0], lo[1], ext[0]
    hi3[[pu, pv, a]] = hi[0], hi[1], ext[1]
    # values[v, u] -> values3[z, y, x]: the array axis of (x, y, z) axis k is 2 - k
    v3 = np.expand_dims(v, axis=2 - a)
    return GridField(v3, lo3, hi3)
