"""Particle shapes as signed distance functions of local points, in numpy and GLSL.

Every shape is centred at the origin of its local frame (axis of symmetry
along z where it has one) and written twice: a numpy function
``fn(q, *params) -> (n,)`` of local points ``q`` ((n, 3) float64, mm) whose
parameters are floats or (n,) arrays, and a GLSL helper
``float mf_shape_NAME(vec3 q, float param, ...)`` computing the same
formula in float32.  All are 1-Lipschitz; all but two are exact Euclidean
signed distances:

* the ellipsoid is a lower bound: the larger of ``rmin (|q / r| - 1)``
  (directional scaling, paper 004 section 3.1.2, made 1-Lipschitz by the
  factor rmin) and ``|q| - rmax`` (the distance to the bounding sphere),
  both 1-Lipschitz, zero or negative on the surface, so their maximum
  vanishes exactly on the ellipsoid and never exceeds the distance;
* the spindle torus (tube radius r > R) is exact outside and a lower
  bound inside.

`SHAPES` maps a name to a `ShapeSpec`; `Primitive` is one placed solid.
The formulas are the standard ones for these solids (distance to the
nearest boundary piece after folding by the shape's symmetries).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, NamedTuple

import numpy as np

from .values import SDF, GlslModule, as_points, glsl_float

__all__ = ["ShapeSpec", "SHAPES", "shape_spec", "check_shape_params", "shape_glsl", "check_rotation",
           "mat3_literal", "Primitive",
           "sphere", "ellipsoid", "box", "round_box", "torus", "capsule", "cylinder", "hex_prism"]

_SQRT3 = math.sqrt(3.0)


def _norm(*cs):
    return np.sqrt(sum(c * c for c in cs))


def _extrude(d2, dz):
    """Signed distance of a z-extrusion from the 2D distance d2 and the slab distance dz."""
    return np.minimum(np.maximum(d2, dz), 0.0) + _norm(np.maximum(d2, 0.0), np.maximum(dz, 0.0))


def sphere(q, r):
    """Sphere of radius r (mm): |q| - r, exact."""
    return _norm(q[:, 0], q[:, 1], q[:, 2]) - r


def ellipsoid(q, a, b, c):
    """Ellipsoid with semi-axes a, b, c (mm) along x, y, z: a 1-Lipschitz lower bound
    (see the module docstring)."""
    rmin = np.minimum(np.minimum(a, b), c)
    rmax = np.maximum(np.maximum(a, b), c)
    scaled = rmin * (_norm(q[:, 0] / a, q[:, 1] / b, q[:, 2] / c) - 1.0)
    return np.maximum(scaled, _norm(q[:, 0], q[:, 1], q[:, 2]) - rmax)


def box(q, bx, by, bz):
    """Axis-aligned box with half-extents bx, by, bz (mm), exact."""
    dx, dy, dz = np.abs(q[:, 0]) - bx, np.abs(q[:, 1]) - by, np.abs(q[:, 2]) - bz
    inner = np.minimum(np.maximum(np.maximum(dx, dy), dz), 0.0)
    return inner + _norm(np.maximum(dx, 0.0), np.maximum(dy, 0.0), np.maximum(dz, 0.0))


def round_box(q, bx, by, bz, rounding):
    """Box with outer half-extents bx, by, bz (mm) and edges rounded with radius
    `rounding` (mm, at most the smallest half-extent), exact."""
    return box(q, bx - rounding, by - rounding, bz - rounding) - rounding


def torus(q, R, r):
    """Torus around the z axis: ring radius R, tube radius r (mm)."""
    return _norm(_norm(q[:, 0], q[:, 1]) - R, q[:, 2]) - r


def capsule(q, h, r):
    """Capsule along z: the segment z in [-h, h] thickened by r (mm), exact."""
    z = q[:, 2] - np.clip(q[:, 2], -h, h)
    return _norm(q[:, 0], q[:, 1], z) - r


def cylinder(q, h, r):
    """Capped cylinder along z: half-height h, radius r (mm), exact."""
    return _extrude(_norm(q[:, 0], q[:, 1]) - r, np.abs(q[:, 2]) - h)


def hex_prism(q, h, a):
    """Hexagonal prism along z: half-height h, apothem a (mm; flat sides at y = +-a), exact.

    The hexagon is folded into the wedge between 60 and 90 degrees (mirror in
    both axes, then in the line at 60 degrees), where the nearest side is the
    top one, y = a with |x| <= a / sqrt(3)."""
    x, y = np.abs(q[:, 0]), np.abs(q[:, 1])
    nx, ny = -0.5 * _SQRT3, 0.5                       # normal of the 60-degree mirror
    t = np.minimum(nx * x + ny * y, 0.0)
    x, y = x - 2.0 * t * nx, y - 2.0 * t * ny
    half = a / _SQRT3
    d2 = _norm(x - np.clip(x, -half, half), y - a) * np.sign(y - a)
    return _extrude(d2, np.abs(q[:, 2]) - h)


class ShapeSpec(NamedTuple):
    """One entry of `SHAPES`.

    fn : numpy distance ``fn(q, *params)``.
    glsl : GLSL source of the helper ``float glsl_name(vec3 q, float ...)``.
    params : parameter names, in order (all mm).
    bound : ``bound(*params)``, the radius of a sphere about the origin holding the shape.
    lipschitz : bound of |grad fn| (1 for all shapes here).
    glsl_name : name of the GLSL helper.
    default : parameters of the unit-scale shape (a particle scales them by its size).
    exact : True if fn is the exact signed distance everywhere.
    check : ``check(*params)`` raising ValueError on a bad parameter.
    """

    fn: Callable
    glsl: str
    params: tuple
    bound: Callable
    lipschitz: float
    glsl_name: str
    default: tuple
    exact: bool
    check: Callable


def _positive(names, values):
    for n, v in zip(names, values):
        if not (math.isfinite(v) and v > 0):
            raise ValueError(f"shape parameter {n} must be a finite number > 0 mm, got {v!r}")


def _check_all_positive(names):
    return lambda *v: _positive(names, v)


def _check_round_box(bx, by, bz, rounding):
    _positive(("bx", "by", "bz"), (bx, by, bz))
    m = min(bx, by, bz)
    if not (math.isfinite(rounding) and 0 <= rounding <= m):
        raise ValueError(f"shape parameter rounding must be in [0, {m!r}] mm (the smallest "
                         f"half-extent), got {rounding!r}")


def _check_capsule(h, r):
    if not (math.isfinite(h) and h >= 0):
        raise ValueError(f"shape parameter h must be a finite number >= 0 mm, got {h!r}")
    _positive(("r",), (r,))


_LEN2 = "length(vec2(max(d2, 0.0), max(dz, 0.0)))"
_GLSL = {
    "sphere": "float mf_shape_sphere(vec3 q, float r) { return length(q) - r; }",
    "ellipsoid": """float mf_shape_ellipsoid(vec3 q, float a, float b, float c) {
    float rmin = min(min(a, b), c);
    float rmax = max(max(a, b), c);
    return max(rmin * (length(q / vec3(a, b, c)) - 1.0), length(q) - rmax);
}""",
    "box": """float mf_shape_box(vec3 q, float bx, float by, float bz) {
    vec3 d = abs(q) - vec3(bx, by, bz);
    return min(max(max(d.x, d.y), d.z), 0.0) + length(max(d, 0.0));
}""",
    "round_box": """float mf_shape_round_box(vec3 q, float bx, float by, float bz, float rounding) {
    return mf_shape_box(q, bx - rounding, by - rounding, bz - rounding) - rounding;
}""",
    "torus": """float mf_shape_torus(vec3 q, float R, float r) {
    return length(vec2(length(q.xy) - R, q.z)) - r;
}""",
    "capsule": """float mf_shape_capsule(vec3 q, float h, float r) {
    return length(vec3(q.xy, q.z - clamp(q.z, -h, h))) - r;
}""",
    "cylinder": f"""float mf_shape_cylinder(vec3 q, float h, float r) {{
    float d2 = length(q.xy) - r;
    float dz = abs(q.z) - h;
    return min(max(d2, dz), 0.0) + {_LEN2};
}}""",
    "hex_prism": f"""float mf_shape_hex_prism(vec3 q, float h, float a) {{
    vec2 v = abs(q.xy);
    vec2 n = vec2(-0.8660254037844386, 0.5);
    v -= 2.0 * min(dot(n, v), 0.0) * n;
    float half_side = a * 0.5773502691896258;
    float d2 = length(vec2(v.x - clamp(v.x, -half_side, half_side), v.y - a)) * sign(v.y - a);
    float dz = abs(q.z) - h;
    return min(max(d2, dz), 0.0) + {_LEN2};
}}""",
}


def _spec(fn, params, bound, default, check, exact=True):
    name = fn.__name__
    return ShapeSpec(fn=fn, glsl=_GLSL[name], params=params, bound=bound, lipschitz=1.0,
                     glsl_name=f"mf_shape_{name}", default=default, exact=exact, check=check)


SHAPES: dict[str, ShapeSpec] = {
    "sphere": _spec(sphere, ("r",), lambda r: r, (1.0,), _check_all_positive(("r",))),
    "ellipsoid": _spec(ellipsoid, ("a", "b", "c"), lambda a, b, c: max(a, b, c), (1.0, 0.7, 0.5),
                       _check_all_positive(("a", "b", "c")), exact=False),
    "box": _spec(box, ("bx", "by", "bz"), lambda bx, by, bz: math.hypot(bx, by, bz),
                 (0.6, 0.6, 0.6), _check_all_positive(("bx", "by", "bz"))),
    "round_box": _spec(round_box, ("bx", "by", "bz", "rounding"),
                       lambda bx, by, bz, rd: math.hypot(bx - rd, by - rd, bz - rd) + rd,
                       (0.6, 0.6, 0.6, 0.15), _check_round_box),
    "torus": _spec(torus, ("R", "r"), lambda R, r: R + r, (0.7, 0.3), _check_all_positive(("R", "r")),
                   exact=False),
    "capsule": _spec(capsule, ("h", "r"), lambda h, r: h + r, (0.5, 0.5), _check_capsule),
    "cylinder": _spec(cylinder, ("h", "r"), lambda h, r: math.hypot(h, r), (0.6, 0.8),
                      _check_all_positive(("h", "r"))),
    "hex_prism": _spec(hex_prism, ("h", "a"), lambda h, a: math.hypot(h, 2.0 * a / _SQRT3), (0.5, 0.7),
                       _check_all_positive(("h", "a"))),
}


def shape_spec(name: str) -> ShapeSpec:
    """The `ShapeSpec` of `name`.

    Raises
    ------
    ValueError
        If `name` is not a key of `SHAPES`.
    """
    if name not in SHAPES:
        raise ValueError(f"unknown particle shape {name!r}; expected one of {sorted(SHAPES)}")
    return SHAPES[name]


def check_shape_params(name: str, params) -> tuple:
    """`params` of shape `name` as a tuple of floats (the shape's default if empty).

    Raises
    ------
    ValueError
        If the shape is unknown, the count is wrong or a value is out of range.
    """
    spec = shape_spec(name)
    p = tuple(float(v) for v in params) if params is not None and len(params) else spec.default
    if len(p) != len(spec.params):
        raise ValueError(f"shape {name!r} takes parameters {spec.params}, got {len(p)} values")
    spec.check(*p)
    return p


def shape_glsl(module: GlslModule, name: str) -> str:
    """Add the GLSL helper of shape `name` (and what it calls) to `module`; its name."""
    if name == "round_box":
        module.helper("mf_shape_box", _GLSL["box"])
    spec = shape_spec(name)
    module.helper(spec.glsl_name, spec.glsl)
    return spec.glsl_name


def check_rotation(rotation, name: str = "rotation"):
    """`rotation` as a read-only orthogonal (3, 3) float64 matrix, or None.

    Raises
    ------
    ValueError
        If it is not (3, 3), not finite, or R^T R differs from I by more than 1e-9.
    """
    if rotation is None:
        return None
    m = np.array(rotation, dtype=np.float64)
    if m.shape != (3, 3) or not np.all(np.isfinite(m)):
        raise ValueError(f"{name} must be a finite (3, 3) matrix, got shape {m.shape}")
    err = float(np.abs(m.T @ m - np.eye(3)).max())
    if err > 1e-9:
        raise ValueError(f"{name} must be orthogonal (|R^T R - I| <= 1e-9), got deviation {err:.3g}")
    m.setflags(write=False)
    return m


def mat3_literal(m) -> str:
    """A GLSL ``mat3(...)`` literal of the (3, 3) matrix m (GLSL is column-major)."""
    return "mat3(" + ", ".join(glsl_float(m[r, c]) for c in range(3) for r in range(3)) + ")"


@dataclass(frozen=True, eq=False)
class Primitive(SDF):
    """One solid of a `SHAPES` shape placed in the world.

    World point x maps to the shape's local frame as ``R^T (x - centre)``
    (R maps local axes to world axes), so the field is the shape's distance,
    with the shape's Lipschitz bound (1).

    Parameters
    ----------
    shape : str, a key of `SHAPES`.
    params : tuple of float, mm, the shape's parameters (`ShapeSpec.params`);
        empty for the shape's unit-scale default.
    centre : (3,) float, mm.
    rotation : (3, 3) orthogonal matrix or None (no rotation).

    Raises
    ------
    ValueError
        On an unknown shape, bad parameters, a non-finite centre or a
        non-orthogonal rotation.
    """

    shape: str = "sphere"
    params: tuple = ()
    centre: tuple = (0.0, 0.0, 0.0)
    rotation: np.ndarray | None = None

    def __post_init__(self):
        object.__setattr__(self, "params", check_shape_params(self.shape, self.params))
        c = np.array(self.centre, dtype=np.float64).reshape(-1)
        if c.shape != (3,) or not np.all(np.isfinite(c)):
            raise ValueError(f"centre must be 3 finite coordinates in mm, got {self.centre!r}")
        object.__setattr__(self, "centre", tuple(float(v) for v in c))
        object.__setattr__(self, "rotation", check_rotation(self.rotation))

    @property
    def lipschitz(self):
        return shape_spec(self.shape).lipschitz

    @property
    def exact(self):
        return bool(shape_spec(self.shape).exact)

    @property
    def bounding_radius(self) -> float:
        """Radius (mm) of a sphere about `centre` holding the solid."""
        return float(shape_spec(self.shape).bound(*self.params))

    def field(self, points):
        q = as_points(points) - np.asarray(self.centre)
        if self.rotation is not None:
            q = q @ self.rotation
        return shape_spec(self.shape).fn(q, *self.params)

    def glsl(self, module):
        helper = shape_glsl(module, self.shape)
        args = ", ".join(glsl_float(v) for v in self.params)
        c = ", ".join(glsl_float(v) for v in self.centre)
        q = f"(p - vec3({c}))"
        if self.rotation is not None:
            q = f"(transpose({mat3_literal(self.rotation)}) * {q})"
        return module.function(self, lambda n: (
            f"float {n}(vec3 p) {{ return {helper}({q}, {args}); }}"))

    def box(self):
        """Centre +- the shape's half-extents when it is not rotated and they are known (box,
        round box, ellipsoid, sphere, cylinder, capsule, torus), else +- the bounding radius."""
        half = None if self.rotation is not None else _half_extents(self.shape, self.params)
        if half is None:
            half = (self.bounding_radius,) * 3
        return (tuple(c - h for c, h in zip(self.centre, half)), tuple(c + h for c, h in zip(self.centre, half)))


def _half_extents(shape: str, p: tuple):
    """The axis-aligned half-extents of an unrotated shape, or None where not worked out."""
    if shape in ("box", "round_box", "ellipsoid"):
        return tuple(p[:3])
    if shape == "sphere":
        return (p[0],) * 3
    if shape == "cylinder":
        return (p[1], p[1], p[0])
    if shape == "capsule":
        return (p[1], p[1], p[0] + p[1])
    if shape == "torus":
        return (p[0] + p[1], p[0] + p[1], p[1])
    return None
