"""Brush strokes on the phasor fields, as data (Tricard et al., section 6).

The designer paints D, F or Gamma on a slice of the part.  A :class:`Stroke`
records one drag: the slice plane, the polyline dragged in it, the brush
shape and what it paints.  :func:`apply_stroke` is a pure function that
returns new fields and the bounding box of the cells it touched, so the
document can keep one undo item per stroke (the old values in that box).

In-plane coordinates and brush weight
-------------------------------------
A stroke on the plane normal to ``axis`` at ``position`` mm has points
``(u, v)`` in mm on the two other axes; each cell centre is weighted
``w = strength * falloff(s)`` by its distance ``s`` to the polyline over the
radius (out of the plane scaled by ``radius / depth``).  Both rules are
`engine.geometry.plane_brush`'s, the brush every painted field shares.

Painting
--------
F and Gamma: ``v <- (1 - w) v + w value``.  D: ``d <- normalise((1 - w) d +
w t)`` where ``t`` is the painted direction: the in-plane ``heading`` if
given, else the drag direction of the polyline segment nearest to the cell,
tilted out of the plane towards ``+axis`` by ``tilt`` radians.  Where the blend
cancels (d = -t, w = 1/2) the cell keeps its old direction.  D is treated as a
direction, not an axis: kernels oriented d and -d give mirrored sawtooth
profiles, and a smooth sign is what phase alignment needs, so the brush does
not silently flip a painted direction to match its neighbours.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass

import numpy as np

from engine.geometry.plane_brush import FALLOFFS, PLANE_AXES, drag_segments, plane_brush
from engine.phasor.fields import MAX_SPREAD, PhasorFields

__all__ = ["Stroke", "apply_stroke", "apply_strokes", "stroke_weights", "check_number", "FALLOFFS",
           "FIELDS", "LIMITS", "PLANE_AXES"]

FIELDS = ("D", "F", "Gamma")
_CANCELLED = 1e-9  # a blended direction shorter than this keeps the old one

# What a stroke's numbers may be: name -> (low, high, low excluded, what is expected).
# Checked here by `Stroke` and shown by the Phasor dock's brush (its `Param`s,
# engine.nodes.phasor_brush, read these limits), so both say the same rule.
LIMITS = {
    "radius": (0.0, math.inf, True, "a finite number > 0 mm"),
    "strength": (0.0, 1.0, False, "a number in [0, 1]"),
    "depth": (0.0, math.inf, True, "a finite number > 0 mm"),
    "F": (0.0, math.inf, True, "a frequency F > 0 cells/mm"),
    "Gamma": (0.0, MAX_SPREAD, False, "an angular spread Gamma in [0, pi/2] radians"),
    "tilt": (-math.pi / 2, math.pi / 2, False, "radians in [-pi/2, pi/2]"),
}


def _finite(v, name, *, positive=False, lo=None, hi=None, what="a finite number"):
    if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)) \
            or not math.isfinite(v):
        raise ValueError(f"Stroke.{name}: expected {what}, got {v!r}")
    v = float(v)
    if (positive and not v > 0) or (lo is not None and v < lo) or (hi is not None and v > hi):
        raise ValueError(f"Stroke.{name}: expected {what}, got {v!r}")
    return v


def check_number(name: str, v, *, field: str | None = None) -> float:
    """``v`` as a float when `LIMITS` [name] allows it, else ValueError naming
    ``Stroke.<field or name>``, the value and what is expected."""
    lo, hi, open_lo, what = LIMITS[name]
    x = _finite(v, field or name, what=what)
    if (open_lo and not x > lo) or x < lo or x > hi:
        raise ValueError(f"Stroke.{field or name}: expected {what}, got {x!r}")
    return x


@dataclass(frozen=True, eq=False)
class Stroke:
    """One brush drag on a slice plane.

    field : "D" | "F" | "Gamma"
    axis : "x" | "y" | "z", the slice plane's normal
    position : float, mm, the plane's coordinate along ``axis``
    points : (k, 2) float64, mm, in-plane (u, v) positions along the drag, k >= 1
    radius : float, mm, > 0
    strength : float in [0, 1]
    falloff : "smooth" | "linear" | "constant"
    value : float or None; F in cells/mm (> 0) or Gamma in radians [0, pi/2]
    heading : (2,) float64 or None; D only: fixed in-plane direction, None = drag direction
    tilt : float, radians in [-pi/2, pi/2]; D only: out of plane towards +axis
    depth : float or None, mm, > 0; reach out of the plane, None = radius
    """

    field: str
    axis: str
    position: float
    points: np.ndarray
    radius: float
    strength: float = 1.0
    falloff: str = "smooth"
    value: float | None = None
    heading: np.ndarray | None = None
    tilt: float = 0.0
    depth: float | None = None

    def __post_init__(self):
        if self.field not in FIELDS:
            raise ValueError(f"Stroke.field: expected one of {', '.join(FIELDS)}, got {self.field!r}")
        if self.axis not in PLANE_AXES:
            raise ValueError(f"Stroke.axis: expected 'x', 'y' or 'z', got {self.axis!r}")
        if self.falloff not in FALLOFFS:
            raise ValueError(f"Stroke.falloff: expected one of {', '.join(FALLOFFS)}, got {self.falloff!r}")
        set_ = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731
        set_("position", _finite(self.position, "position"))
        set_("radius", check_number("radius", self.radius))
        set_("strength", check_number("strength", self.strength))
        if self.depth is not None:
            set_("depth", check_number("depth", self.depth))
        try:
            pts = np.array(self.points, dtype=np.float64)
        except (TypeError, ValueError):
            pts = np.zeros((0, 0))
        if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 1 or not np.all(np.isfinite(pts)):
            raise ValueError(f"Stroke.points: expected a (k, 2) array of finite in-plane mm, k >= 1; "
                             f"got shape {pts.shape}")
        pts.setflags(write=False)
        set_("points", pts)
        self._check_paint()

    def _check_paint(self):
        set_ = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731
        if self.field == "D":
            if self.value is not None:
                raise ValueError(f"Stroke.value: a D stroke paints a direction (heading, tilt), "
                                 f"not a value; got {self.value!r}")
            set_("tilt", check_number("tilt", self.tilt))
            if self.heading is not None:
                h = np.array(self.heading, dtype=np.float64)
                if h.shape != (2,) or not np.all(np.isfinite(h)) or np.linalg.norm(h) < 1e-12:
                    raise ValueError(f"Stroke.heading: expected a non-zero finite in-plane (u, v) "
                                     f"direction, got {self.heading!r}")
                h.setflags(write=False)
                set_("heading", h)
            elif len(drag_segments(self.points)[0]) == 0:
                raise ValueError("Stroke.heading: the stroke never moves, so it has no drag "
                                 "direction; give a heading")
            return
        if self.heading is not None or self.tilt != 0.0:
            raise ValueError(f"Stroke.heading: only D strokes have a heading or tilt "
                             f"(this one paints {self.field})")
        set_("value", check_number(self.field, self.value, field="value"))

    @property
    def reach(self) -> float:
        """How far the brush reaches out of the plane, mm."""
        return self.radius if self.depth is None else self.depth

    def to_dict(self) -> dict:
        """Plain JSON-able data; ``Stroke.from_dict(s.to_dict())`` is exact."""
        return {"field": self.field, "axis": self.axis, "position": self.position,
                "points": self.points.tolist(), "radius": self.radius, "strength": self.strength,
                "falloff": self.falloff, "value": self.value,
                "heading": None if self.heading is None else self.heading.tolist(),
                "tilt": self.tilt, "depth": self.depth}

    def to_json(self) -> str:
        return json.dumps(self.to_dict())

    @classmethod
    def from_dict(cls, data: dict) -> "Stroke":
        if not isinstance(data, dict):
            raise ValueError(f"Stroke: expected an object, got {type(data).__name__}")
        required = ("field", "axis", "position", "points", "radius")
        optional = ("strength", "falloff", "value", "heading", "tilt", "depth")
        for key in required:
            if key not in data:
                raise ValueError(f"Stroke.{key}: missing")
        extra = sorted(set(data) - set(required) - set(optional))
        if extra:
            raise ValueError(f"Stroke.{extra[0]}: unknown key; expected "
                             f"{', '.join(required + optional)}")
        return cls(**data)

    @classmethod
    def from_json(cls, text) -> "Stroke":
        if isinstance(text, dict):
            return cls.from_dict(text)
        try:
            data = json.loads(text)
        except (TypeError, ValueError) as err:
            raise ValueError(f"Stroke: not valid JSON ({err})") from None
        return cls.from_dict(data)


# --- the brush (engine.geometry.plane_brush) ---------------------------------------

def _brush(fields, stroke):
    """Weights (block,) and, for D, the painted directions (block, 3) over the block."""
    ranges, w, which = plane_brush(fields.lo, fields.spacing, fields.shape, axis=stroke.axis,
                                   position=stroke.position, points=stroke.points, radius=stroke.radius,
                                   reach=stroke.reach, strength=stroke.strength, kind=stroke.falloff)
    u, v, n = PLANE_AXES[stroke.axis]
    target = None
    if stroke.field == "D":
        if stroke.heading is not None:
            tangents = (stroke.heading / np.linalg.norm(stroke.heading))[None]
            which = np.zeros(w.shape, dtype=np.intp)
        else:
            starts, ends = drag_segments(stroke.points)
            tangents = (ends - starts) / np.linalg.norm(ends - starts, axis=1, keepdims=True)
        t3 = np.zeros((len(tangents), 3))
        t3[:, u] = math.cos(stroke.tilt) * tangents[:, 0]
        t3[:, v] = math.cos(stroke.tilt) * tangents[:, 1]
        t3[:, n] = math.sin(stroke.tilt)
        target = np.broadcast_to(t3[which], w.shape + (3,))
    return ranges, w, target


def stroke_weights(fields: PhasorFields, stroke: Stroke) -> np.ndarray:
    """(nz, ny, nx) float64 brush weights of ``stroke`` on the grid of ``fields``."""
    ranges, w, _ = _brush(fields, stroke)
    out = np.zeros(fields.shape)
    out[tuple(slice(a, b) for a, b in ranges)] = w
    return out


# --- painting ----------------------------------------------------------------------

def _changed_box(ranges, touched):
    if not touched.any():
        return (slice(0, 0),) * 3
    box = []
    for axis, (start, _) in enumerate(ranges):
        other = tuple(a for a in range(3) if a != axis)
        hit = np.flatnonzero(touched.any(axis=other))
        box.append(slice(start + int(hit[0]), start + int(hit[-1]) + 1))
    return tuple(box)


def apply_stroke(fields: PhasorFields, stroke: Stroke):
    """Paint one stroke.

    Returns
    -------
    fields : PhasorFields
        New fields; ``fields`` itself is unchanged.
    changed : (slice, slice, slice)
        ``[z, y, x]`` bounding box of the cells with non-zero weight (all three
        ``slice(0, 0)`` if none); every cell outside it is byte-identical.
    """
    if not isinstance(stroke, Stroke):
        raise ValueError(f"stroke: expected a Stroke, got {type(stroke).__name__}")
    ranges, w, target = _brush(fields, stroke)
    changed = _changed_box(ranges, w > 0)
    if changed[0].stop == 0:
        return fields, changed
    block = tuple(slice(a, b) for a, b in ranges)
    touched = w > 0
    direction, frequency, spread = fields.direction, fields.frequency, fields.spread
    if stroke.field == "D":
        old = fields.direction[block]
        mixed = (1.0 - w)[..., None] * old + w[..., None] * target
        norm = np.linalg.norm(mixed, axis=-1, keepdims=True)
        ok = touched[..., None] & (norm >= _CANCELLED)
        direction = fields.direction.copy()
        direction[block] = np.where(ok, mixed / np.where(ok, norm, 1.0), old)
    else:
        grid = fields.frequency if stroke.field == "F" else fields.spread
        old = grid[block]
        new = grid.copy()
        new[block] = np.where(touched, (1.0 - w) * old + w * stroke.value, old)
        if stroke.field == "F":
            frequency = new
        else:
            spread = new
    return PhasorFields(direction, frequency, spread, fields.lo, fields.hi), changed


def _union(a, b):
    if a[0].stop == 0:
        return b
    if b[0].stop == 0:
        return a
    return tuple(slice(min(x.start, y.start), max(x.stop, y.stop)) for x, y in zip(a, b))


def apply_strokes(fields: PhasorFields, strokes):
    """Apply ``strokes`` in order; returns (fields, union of the changed boxes)."""
    changed = (slice(0, 0),) * 3
    for stroke in strokes:
        fields, box = apply_stroke(fields, stroke)
        changed = _union(changed, box)
    return fields, changed
