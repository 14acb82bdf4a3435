"""A designed and painted scalar field over a box: what drives a spatially varying medium.

Paper 004 (section 3.1) varies a particle cloud's density, surface offset and size through
space (the ice bunny: sparse large bubbles on top, dense small ones below).  This kernel
builds such a field as a geometry `Field` (kind "scalar"): ``values[z, y, x]``, one sample
per cell centre ``lo + (i + 0.5) h`` of the box ``lo..hi`` (mm, ``(x, y, z)``) cut into
``(nx, ny, nz)`` cells of spacing ``h = (hi - lo) / (nx, ny, nz)``.

Building, in order
------------------
1. the profile: a constant ``base``, or a `Ramp` (linear along an axis between two
   coordinates, clamped beyond them), or a `Radial` bump (``inner`` at the centre falling
   to ``outer`` at ``radius`` and beyond, by a brush profile);
2. the painted `FieldStroke` s, in order: each blends ``v <- (1 - w) v + w value`` with the
   weights ``w`` of `engine.geometry.plane_brush` (the brush the phasor fields use too);
3. an optional clamp to ``[lo, hi]`` (a density stays a probability).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass

import numpy as np

from .plane_brush import FALLOFFS, PLANE_AXES, falloff, plane_brush
from .values import Field

__all__ = ["FieldStroke", "Ramp", "Radial", "field_grid_shape", "cell_centres", "profile_values",
           "paint_strokes", "scalar_field", "nearest_layer", "AXES"]

AXES = ("x", "y", "z")


def _number(owner: str, name: str, v, *, positive: bool = False, lo=None, hi=None,
            what: str = "a finite number") -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)) or not math.isfinite(v):
        raise ValueError(f"{owner}.{name}: expected {what}, got {v!r}")
    x = float(v)
    if (positive and not x > 0) or (lo is not None and x < lo) or (hi is not None and x > hi):
        raise ValueError(f"{owner}.{name}: expected {what}, got {v!r}")
    return x


def _axis(owner: str, name: str, axis) -> str:
    if axis not in AXES:
        raise ValueError(f"{owner}.{name}: expected 'x', 'y' or 'z', got {axis!r}")
    return axis


def _box(lo, hi) -> tuple:
    lo = np.asarray(lo, dtype=np.float64).reshape(-1)
    hi = np.asarray(hi, dtype=np.float64).reshape(-1)
    if lo.shape != (3,) or hi.shape != (3,) or not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
        raise ValueError(f"box: lo and hi must be three finite coordinates (mm); got lo={lo.tolist()}, "
                         f"hi={hi.tolist()}")
    if np.any(hi <= lo):
        raise ValueError(f"hi {hi.tolist()} must exceed lo {lo.tolist()} on every axis (mm)")
    return lo, hi


# --- what the field is made of -----------------------------------------------------------

@dataclass(frozen=True)
class Ramp:
    """Linear along ``axis`` from ``value_from`` at coordinate ``start`` to ``value_to`` at
    ``end`` (mm), constant beyond either end; ``end < start`` runs the ramp backwards."""

    axis: str
    start: float
    end: float
    value_from: float
    value_to: float

    def __post_init__(self):
        _axis("Ramp", "axis", self.axis)
        for name in ("start", "end", "value_from", "value_to"):
            object.__setattr__(self, name, _number("Ramp", name, getattr(self, name)))
        if self.end == self.start:
            raise ValueError(f"Ramp.end: expected a coordinate other than the start {self.start!r} mm "
                             f"(a ramp needs a length), got {self.end!r}")

    def values(self, x, y, z) -> np.ndarray:
        c = (x, y, z)[AXES.index(self.axis)]
        t = np.clip((c - self.start) / (self.end - self.start), 0.0, 1.0)
        return self.value_from + t * (self.value_to - self.value_from)


@dataclass(frozen=True)
class Radial:
    """``inner`` at ``centre`` (mm), falling to ``outer`` at distance ``radius`` (mm) and
    beyond: ``outer + (inner - outer) * falloff(|p - centre| / radius)`` with a brush
    profile (`engine.geometry.plane_brush.FALLOFFS`; "smooth" has no kink at the rim)."""

    centre: tuple
    radius: float
    inner: float
    outer: float
    falloff: str = "smooth"

    def __post_init__(self):
        c = tuple(self.centre) if isinstance(self.centre, (list, tuple, np.ndarray)) else ()
        if len(c) != 3:
            raise ValueError(f"Radial.centre: expected three finite coordinates (mm), got {self.centre!r}")
        object.__setattr__(self, "centre", tuple(_number("Radial", "centre", v) for v in c))
        object.__setattr__(self, "radius", _number("Radial", "radius", self.radius, positive=True,
                                                   what="a finite radius > 0 mm"))
        object.__setattr__(self, "inner", _number("Radial", "inner", self.inner))
        object.__setattr__(self, "outer", _number("Radial", "outer", self.outer))
        if self.falloff not in FALLOFFS:
            raise ValueError(f"Radial.falloff: expected one of {', '.join(FALLOFFS)}, got {self.falloff!r}")

    def values(self, x, y, z) -> np.ndarray:
        cx, cy, cz = self.centre
        s = np.sqrt((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2) / self.radius
        return self.outer + (self.inner - self.outer) * falloff(s, self.falloff)


@dataclass(frozen=True, eq=False)
class FieldStroke:
    """One brush drag on a slice plane, painting ``value``.

    axis : "x" | "y" | "z", the plane's normal; position : mm along it
    points : (k, 2) float64, in-plane (u, v) mm (`plane_brush.PLANE_AXES`), k >= 1
    radius : mm, > 0; value : finite, what is painted
    strength : [0, 1]; falloff : one of `FALLOFFS`
    depth : mm, > 0, the reach out of the plane, or None (= radius)
    """

    axis: str
    position: float
    points: np.ndarray
    radius: float
    value: float
    strength: float = 1.0
    falloff: str = "smooth"
    depth: float | None = None

    def __post_init__(self):
        set_ = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731
        _axis("FieldStroke", "axis", self.axis)
        if self.falloff not in FALLOFFS:
            raise ValueError(f"FieldStroke.falloff: expected one of {', '.join(FALLOFFS)}, got {self.falloff!r}")
        set_("position", _number("FieldStroke", "position", self.position, what="a finite coordinate (mm)"))
        set_("radius", _number("FieldStroke", "radius", self.radius, positive=True,
                               what="a finite number > 0 mm"))
        set_("value", _number("FieldStroke", "value", self.value))
        set_("strength", _number("FieldStroke", "strength", self.strength, lo=0.0, hi=1.0,
                                 what="a number in [0, 1]"))
        if self.depth is not None:
            set_("depth", _number("FieldStroke", "depth", self.depth, positive=True,
                                  what="a finite number > 0 mm, or null (= radius)"))
        try:
            pts = np.array(self.points, dtype=np.float64)
        except (TypeError, ValueError):
            pts = np.zeros((0, 0))
        if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 1 or not np.all(np.isfinite(pts)):
            raise ValueError(f"FieldStroke.points: expected a (k, 2) array of finite in-plane mm, k >= 1; "
                             f"got shape {pts.shape}")
        pts.setflags(write=False)
        set_("points", pts)

    @property
    def reach(self) -> float:
        """How far the brush reaches out of the plane, mm."""
        return self.radius if self.depth is None else self.depth

    _KEYS = ("axis", "position", "points", "radius", "value", "strength", "falloff", "depth")

    def to_dict(self) -> dict:
        """Plain JSON-able data; ``FieldStroke.from_dict(s.to_dict())`` is exact."""
        return {"axis": self.axis, "position": self.position, "points": self.points.tolist(),
                "radius": self.radius, "value": self.value, "strength": self.strength,
                "falloff": self.falloff, "depth": self.depth}

    @classmethod
    def from_dict(cls, data) -> "FieldStroke":
        if not isinstance(data, dict):
            raise ValueError(f"FieldStroke: expected an object, got {type(data).__name__}")
        for key in cls._KEYS[:5]:
            if key not in data:
                raise ValueError(f"FieldStroke.{key}: missing")
        extra = sorted(set(data) - set(cls._KEYS))
        if extra:
            raise ValueError(f"FieldStroke.{extra[0]}: unknown key; expected {', '.join(cls._KEYS)}")
        return cls(**data)

    def to_json(self) -> str:
        return json.dumps(self.to_dict())


# --- the grid ----------------------------------------------------------------------------

def field_grid_shape(lo, hi, resolution: int) -> tuple:
    """(nz, ny, nx): ``resolution`` samples along the box's longest side, the others in
    proportion (rounded, at least 1)."""
    lo, hi = _box(lo, hi)
    if isinstance(resolution, bool) or not isinstance(resolution, (int, np.integer)) or resolution < 1:
        raise ValueError(f"resolution: expected an integer >= 1 (samples along the longest side), "
                         f"got {resolution!r}")
    ext = hi - lo
    n = [max(1, int(round(int(resolution) * e / ext.max()))) for e in ext]
    return tuple(n[::-1])


def cell_centres(lo, spacing, shape) -> tuple:
    """Cell-centre x, y, z of a (nz, ny, nx) grid, shaped (1, 1, nx), (1, ny, 1), (nz, 1, 1)."""
    out = []
    for a in range(3):
        n = shape[2 - a]
        c = lo[a] + (np.arange(n) + 0.5) * spacing[a]
        s = [1, 1, 1]
        s[2 - a] = n
        out.append(c.reshape(s))
    return tuple(out)


def profile_values(lo, hi, shape, *, base: float = 0.0, profile: Ramp | Radial | None = None) -> np.ndarray:
    """(nz, ny, nx) float64: ``base`` everywhere, or ``profile`` at every cell centre."""
    lo, hi = _box(lo, hi)
    base = _number("scalar field", "base", base)
    if profile is None:
        return np.full(tuple(shape), base)
    if not isinstance(profile, (Ramp, Radial)):
        raise ValueError(f"profile: expected a Ramp, a Radial or None, got {type(profile).__name__}")
    spacing = (hi - lo) / np.array(shape[::-1], dtype=np.float64)
    x, y, z = cell_centres(lo, spacing, shape)
    return np.ascontiguousarray(np.broadcast_to(profile.values(x, y, z), tuple(shape)), dtype=np.float64)


def paint_strokes(values: np.ndarray, lo, spacing, strokes) -> np.ndarray:
    """``values`` (nz, ny, nx) with ``strokes`` painted in order: ``v <- (1 - w) v + w value``.

    lo, spacing : (3,) mm, ``(x, y, z)``: the grid's corner and cell size (any grid, e.g. one
    layer of a field).  Returns a new array; ``values`` is unchanged.  Only each stroke's block
    (`plane_brush.brush_block`) is touched.
    """
    out = np.array(values, dtype=np.float64)
    lo = np.asarray(lo, dtype=np.float64)
    spacing = np.asarray(spacing, dtype=np.float64)
    for i, stroke in enumerate(strokes):
        if not isinstance(stroke, FieldStroke):
            raise ValueError(f"strokes[{i}]: expected a FieldStroke, got {type(stroke).__name__}")
        ranges, w, _ = plane_brush(lo, spacing, out.shape, axis=stroke.axis, position=stroke.position,
                                   points=stroke.points, radius=stroke.radius, reach=stroke.reach,
                                   strength=stroke.strength, kind=stroke.falloff)
        block = tuple(slice(a, b) for a, b in ranges)
        out[block] = (1.0 - w) * out[block] + w * stroke.value
    return out


def scalar_field(lo, hi, shape, *, base: float = 0.0, profile: Ramp | Radial | None = None,
                 strokes=(), clamp: tuple | None = None) -> Field:
    """The scalar `Field` over the box ``lo..hi`` (mm) on a (nz, ny, nx) ``shape`` grid:
    the profile, then the strokes, then the clamp (module docstring).

    clamp : (low, high) with low <= high, or None.

    Raises
    ------
    ValueError
        Naming the argument: unordered box corners, a bad shape, profile, stroke or clamp.
    """
    lo, hi = _box(lo, hi)
    shape = tuple(int(n) for n in shape)
    if len(shape) != 3 or min(shape) < 1:
        raise ValueError(f"shape: expected (nz, ny, nx) with every n >= 1, got {shape}")
    if clamp is not None:
        c_lo = _number("clamp", "low", clamp[0])
        c_hi = _number("clamp", "high", clamp[1])
        if c_lo > c_hi:
            raise ValueError(f"clamp: the low end {c_lo!r} must not exceed the high end {c_hi!r}")
    strokes = list(strokes)
    values = profile_values(lo, hi, shape, base=base, profile=profile)
    spacing = (hi - lo) / np.array(shape[::-1], dtype=np.float64)
    values = paint_strokes(values, lo, spacing, strokes)
    if clamp is not None:
        np.clip(values, c_lo, c_hi, out=values)
    return Field(values, lo, hi, kind="scalar")


# --- looking at it -----------------------------------------------------------------------

def nearest_layer(field: Field, axis: str, position: float) -> tuple:
    """The layer of cells nearest the plane normal to ``axis`` at ``position`` mm.

    Returns
    -------
    image : (nv, nu) float64 (a view), row i along +v, column j along +u (in-plane axes as in
        `plane_brush.PLANE_AXES`)
    extent : ((u0, u1), (v0, v1)) mm, the box's in-plane extent
    index : int, the layer's cell index along ``axis`` (``position`` clamped into the box)
    """
    _axis("nearest_layer", "axis", axis)
    position = _number("nearest_layer", "position", position)
    u, v, n = PLANE_AXES[axis]
    count = field.grid_shape[2 - n]
    k = int(math.floor((position - field.lo[n]) / field.spacing[n]))
    k = min(max(k, 0), count - 1)
    take = [slice(None)] * 3
    take[2 - n] = k
    # the two axes left, in [z, y, x] order, are (v, u): u < v in (x, y, z) order
    image = field.values[tuple(take)]
    extent = ((float(field.lo[u]), float(field.hi[u])), (float(field.lo[v]), float(field.hi[v])))
    return image, extent, k
