"""Initial D, F and Gamma from a small JSON-able spec (Tricard et al., section 6).

The paper seeds its 64^3 field textures with a script before the designer
paints them.  Here the seed is plain data, one entry per field::

    {
      "D":     {"kind": "spiral", "axis": "z", "centre": [0, 0, 0], "angle_deg": 90},
      "F":     {"kind": "linear", "axis": "z", "from": 1.5, "to": 0.5},
      "Gamma": {"kind": "radial", "centre": [0, 0, 0], "from": 0.0, "to": 0.8, "radius": 20}
    }

A missing field takes its default (D = +x, F = 1 cell/mm, Gamma = 0); a bare
number (F, Gamma) or a 3-list (D) is shorthand for ``{"kind": "constant",
"value": ...}``.  Axes are ``"x" | "y" | "z"`` (optionally with a sign,
``"-z"``) or a 3-list; points are 3-lists in mm; angles of D are in degrees
(``*_deg`` keys); Gamma values are in radians like the field itself.

D kinds
-------
constant        value: vector.
along_axis      axis: D is that axis everywhere.
radial          centre (default box centre), axis (optional), inward (bool):
                D is the unit offset of the cell centre from ``centre`` or, with
                ``axis``, from the line through ``centre`` along ``axis``.  Where
                the offset vanishes (< 1e-9 mm) D takes ``fallback`` (default: a
                unit vector perpendicular to the axis, or +x).
spiral          axis (default "z"), centre, angle_deg, fallback: with r the unit
                offset from the axis line and t = axis x r the tangent going
                counter-clockwise about the axis, D = cos(a) r + sin(a) t.
                a = 0 is radial, 90 circular, in between a logarithmic spiral.
twist           axis, start (vector), angle_deg, range ([s0, s1] mm along the
                axis; default the box extent): D is ``start`` rotated about the
                axis (right-hand rule) by angle_deg * clamp((s - s0)/(s1 - s0)),
                s the cell centre's coordinate along the axis.
surface_normal  inward (bool): the outward unit normal of the mesh face
                nearest to the cell centre (needs ``mesh``).  It jumps across
                the medial axis, where two faces are equally near.

F / Gamma kinds
---------------
constant        value.
linear          axis, from, to, range: value ``from`` at s0 and ``to`` at s1,
                linear between, clamped outside.
radial          centre, axis (optional), from, to, radius (mm; default the
                farthest box corner): ``from`` at the centre (or axis line),
                ``to`` at ``radius`` and beyond.
"""

from __future__ import annotations

import math

import numpy as np

from engine.phasor.domain import mesh_arrays
from engine.phasor.fields import MAX_SPREAD, PhasorFields

__all__ = ["fields_from_spec", "D_KINDS", "SCALAR_KINDS", "DEFAULT_SPEC"]

D_KINDS = ("constant", "along_axis", "radial", "spiral", "twist", "surface_normal")
SCALAR_KINDS = ("constant", "linear", "radial")
DEFAULT_SPEC = {"D": {"kind": "constant", "value": [1.0, 0.0, 0.0]},
                "F": {"kind": "constant", "value": 1.0},
                "Gamma": {"kind": "constant", "value": 0.0}}

_ZERO_OFFSET = 1e-9  # mm; a radial offset shorter than this has no direction
_AXES = {"x": 0, "y": 1, "z": 2}

_D_KEYS = {"constant": {"value"}, "along_axis": {"axis"},
           "radial": {"centre", "axis", "inward", "fallback"},
           "spiral": {"centre", "axis", "angle_deg", "fallback"},
           "twist": {"axis", "start", "angle_deg", "range"},
           "surface_normal": {"inward"}}
_SCALAR_KEYS = {"constant": {"value"}, "linear": {"axis", "from", "to", "range"},
                "radial": {"centre", "axis", "from", "to", "radius"}}


# --- reading the spec ----------------------------------------------------------------

def _number(entry, key, where, *, default=None):
    v = entry.get(key, default)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise ValueError(f"{where}.{key}: expected a finite number, got {v!r}")
    return float(v)


def _bool(entry, key, where):
    v = entry.get(key, False)
    if not isinstance(v, bool):
        raise ValueError(f"{where}.{key}: expected true or false, got {v!r}")
    return v


def _vector(v, key, where, *, unit=True):
    try:
        a = np.array(v, dtype=np.float64)
    except (TypeError, ValueError):
        a = None
    if isinstance(v, (str, bytes)) or a is None or a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{where}.{key}: expected 3 finite numbers, got {v!r}")
    if unit:
        n = float(np.linalg.norm(a))
        if n < 1e-12:
            raise ValueError(f"{where}.{key}: {v!r} is a zero vector, so it has no direction")
        a = a / n
    return a


def _axis(entry, key, where, *, default=None):
    v = entry.get(key, default)
    if v is None:
        raise ValueError(f"{where}.{key}: missing; expected 'x', 'y', 'z' (optionally '-x' ...) "
                         "or 3 numbers")
    if isinstance(v, str):
        sign = -1.0 if v.startswith("-") else 1.0
        name = v.lstrip("+-").lower()
        if name not in _AXES:
            raise ValueError(f"{where}.{key}: expected 'x', 'y', 'z' (optionally '-x' ...) "
                             f"or 3 numbers, got {v!r}")
        a = np.zeros(3)
        a[_AXES[name]] = sign
        return a
    return _vector(v, key, where)


def _range(entry, where, axis, lo, hi):
    """(s0, s1) along ``axis``: given, or the box's extent projected on it."""
    if "range" not in entry:
        corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                            for z in (lo[2], hi[2])])
        s = corners @ axis
        return float(s.min()), float(s.max())
    v = entry["range"]
    if (not isinstance(v, (list, tuple)) or len(v) != 2
            or not all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)
                       for x in v)
            or not v[1] > v[0]):
        raise ValueError(f"{where}.range: expected [s0, s1] in mm with s1 > s0, got {v!r}")
    return float(v[0]), float(v[1])


def _check_keys(entry, allowed, where, kind):
    extra = sorted(set(entry) - allowed - {"kind"})
    if extra:
        raise ValueError(f"{where}.{extra[0]}: unknown key for kind {kind!r}; expected "
                         f"{', '.join(sorted(allowed))}")


def _entry(spec, name):
    entry = spec.get(name, DEFAULT_SPEC[name])
    if isinstance(entry, (int, float)) and not isinstance(entry, bool) and name != "D":
        return {"kind": "constant", "value": entry}
    if isinstance(entry, (list, tuple)) and name == "D":
        return {"kind": "constant", "value": list(entry)}
    if not isinstance(entry, dict):
        raise ValueError(f"{name}: expected an object with a 'kind' key, got {entry!r}")
    kinds = D_KINDS if name == "D" else SCALAR_KINDS
    kind = entry.get("kind")
    if kind not in kinds:
        raise ValueError(f"{name}.kind: expected one of {', '.join(kinds)}; got {kind!r}")
    _check_keys(entry, (_D_KEYS if name == "D" else _SCALAR_KEYS)[kind], name, kind)
    return entry


# --- geometry on cell centres ----------------------------------------------------------

def _centres(lo, hi, shape) -> np.ndarray:
    """(nz, ny, nx, 3) cell-centre positions (x, y, z) in mm."""
    nz, ny, nx = shape
    step = (hi - lo) / np.array([nx, ny, nz], dtype=np.float64)
    xs, ys, zs = (lo[a] + (np.arange(n) + 0.5) * step[a] for a, n in enumerate((nx, ny, nz)))
    z, y, x = np.meshgrid(zs, ys, xs, indexing="ij")
    return np.stack([x, y, z], axis=-1)


def _perpendicular(axis) -> np.ndarray:
    """A fixed unit vector perpendicular to ``axis``."""
    e = np.eye(3)[int(np.argmin(np.abs(axis)))]
    p = e - (e @ axis) * axis
    return p / np.linalg.norm(p)


def _offset(entry, where, p, lo, hi):
    """Offset of ``p`` from the centre point, or from the axis line when one is given."""
    centre = (_vector(entry["centre"], "centre", where, unit=False) if "centre" in entry
              else (lo + hi) / 2)
    off = p - centre
    axis = _axis(entry, "axis", where) if "axis" in entry else None
    if axis is not None:
        off = off - (off @ axis)[..., None] * axis
    return off, axis, centre


def _unit_or_fallback(off, fallback):
    n = np.linalg.norm(off, axis=-1, keepdims=True)
    small = n < _ZERO_OFFSET
    return np.where(small, fallback, off / np.where(small, 1.0, n))


def _fallback(entry, where, axis):
    if "fallback" in entry:
        return _vector(entry["fallback"], "fallback", where)
    return np.array([1.0, 0.0, 0.0]) if axis is None else _perpendicular(axis)


def _rotate(v, axis, theta):
    """Rodrigues: rotate vector ``v`` (3,) about unit ``axis`` by angles ``theta`` (...)."""
    c, s = np.cos(theta)[..., None], np.sin(theta)[..., None]
    return v * c + np.cross(axis, v) * s + axis * (axis @ v) * (1.0 - c)


# --- D ---------------------------------------------------------------------------

def _direction(entry, p, lo, hi, mesh):
    w, kind = "D", entry["kind"]
    if kind == "constant":
        return np.broadcast_to(_vector(entry.get("value"), "value", w), p.shape)
    if kind == "along_axis":
        return np.broadcast_to(_axis(entry, "axis", w), p.shape)
    if kind == "radial":
        off, axis, _ = _offset(entry, w, p, lo, hi)
        d = _unit_or_fallback(off, _fallback(entry, w, axis))
        return -d if _bool(entry, "inward", w) else d
    if kind == "spiral":
        entry = {"axis": "z", **entry}
        off, axis, _ = _offset(entry, w, p, lo, hi)
        r = _unit_or_fallback(off, _fallback(entry, w, axis))
        a = math.radians(_number(entry, "angle_deg", w, default=0.0))
        return math.cos(a) * r + math.sin(a) * np.cross(axis, r)
    if kind == "twist":
        axis = _axis(entry, "axis", w)
        start = _vector(entry.get("start"), "start", w)
        s0, s1 = _range(entry, w, axis, lo, hi)
        t = np.clip((p @ axis - s0) / (s1 - s0), 0.0, 1.0)
        d = _rotate(start, axis, math.radians(_number(entry, "angle_deg", w)) * t)
        return d / np.linalg.norm(d, axis=-1, keepdims=True)
    return _surface_normal(entry, p, mesh)


def _surface_normal(entry, p, mesh):
    import igl

    if mesh is None:
        raise ValueError("D.kind: 'surface_normal' needs the part's mesh; pass mesh=")
    v, f = mesh_arrays(mesh)
    normals = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    volume = float(np.einsum("ij,ij->i", v[f[:, 0]], normals).sum()) / 6.0
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = normals / np.where(length > 0, length, 1.0)
    if volume < 0:  # inside-out winding: outward is the other side
        normals = -normals
    _, face, _ = igl.point_mesh_squared_distance(np.ascontiguousarray(p.reshape(-1, 3)), v, f)
    d = normals[face].reshape(p.shape)
    if np.any(np.linalg.norm(d, axis=-1) < 0.5):
        raise ValueError("D.kind: 'surface_normal' met a degenerate (zero-area) mesh face")
    return -d if _bool(entry, "inward", "D") else d


# --- F and Gamma ----------------------------------------------------------------------

def _scalar_value(entry, key, name):
    v = _number(entry, key, name)
    if name == "F" and not v > 0:
        raise ValueError(f"F.{key}: expected a number > 0 cells/mm, got {v!r}")
    if name == "Gamma" and not 0.0 <= v <= MAX_SPREAD:
        raise ValueError(f"Gamma.{key}: expected radians in [0, pi/2], got {v!r}")
    return v


def _scalar(name, entry, p, lo, hi):
    kind = entry["kind"]
    if kind == "constant":
        return np.full(p.shape[:-1], _scalar_value(entry, "value", name))
    v0, v1 = _scalar_value(entry, "from", name), _scalar_value(entry, "to", name)
    if kind == "linear":
        axis = _axis(entry, "axis", name)
        s0, s1 = _range(entry, name, axis, lo, hi)
        t = np.clip((p @ axis - s0) / (s1 - s0), 0.0, 1.0)
    else:
        off, axis, centre = _offset(entry, name, p, lo, hi)
        if "radius" in entry:
            radius = _number(entry, "radius", name)
            if not radius > 0:
                raise ValueError(f"{name}.radius: expected a number > 0 mm, got {radius!r}")
        else:
            corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                                for z in (lo[2], hi[2])])
            c_off, _, _ = _offset(entry, name, corners, lo, hi)
            radius = max(float(np.linalg.norm(c_off, axis=-1).max()), _ZERO_OFFSET)
        t = np.clip(np.linalg.norm(off, axis=-1) / radius, 0.0, 1.0)
    return v0 + (v1 - v0) * t


# --- entry point ----------------------------------------------------------------------

def fields_from_spec(spec: dict, *, lo, hi, shape=(64, 64, 64), mesh=None) -> PhasorFields:
    """Evaluate a field spec at the cell centres of a ``shape`` grid over ``lo..hi``.

    Parameters
    ----------
    spec : dict
        JSON-able; keys among ``"D"``, ``"F"``, ``"Gamma"`` (see the module
        docstring for the kinds and their keys).
    lo, hi : (3,) float, box corners (x, y, z) in mm, hi > lo.
    shape : (nz, ny, nx) int, grid size (the paper uses 64^3).
    mesh : trimesh.Trimesh or (vertices, faces), optional
        Needed only for ``D.kind == "surface_normal"``.

    Returns
    -------
    PhasorFields
        direction (nz, ny, nx, 3), frequency and spread (nz, ny, nx), float64.

    Raises
    ------
    ValueError
        Naming the field and the key, e.g. ``"F.from: expected a number > 0
        cells/mm, got -1.0"``.
    """
    if not isinstance(spec, dict):
        raise ValueError(f"spec: expected an object with keys D, F, Gamma, got {spec!r}")
    extra = sorted(set(spec) - set(DEFAULT_SPEC))
    if extra:
        raise ValueError(f"spec.{extra[0]}: unknown field; expected D, F, Gamma")
    lo = np.asarray(lo, dtype=np.float64)
    hi = np.asarray(hi, dtype=np.float64)
    if lo.shape != (3,) or hi.shape != (3,) or not np.all(np.isfinite(lo)) or not np.all(np.isfinite(hi)) \
            or np.any(hi <= lo):
        raise ValueError(f"box: lo and hi must be 3 finite numbers each with hi > lo; got {lo!r}, {hi!r}")
    shape = tuple(int(s) for s in shape)
    if len(shape) != 3 or min(shape) < 1:
        raise ValueError(f"shape: expected (nz, ny, nx) positive integers, got {shape!r}")
    p = _centres(lo, hi, shape)
    d = _direction(_entry(spec, "D"), p, lo, hi, mesh)
    f = _scalar("F", _entry(spec, "F"), p, lo, hi)
    g = _scalar("Gamma", _entry(spec, "Gamma"), p, lo, hi)
    return PhasorFields(np.ascontiguousarray(d), f, g, lo, hi)
