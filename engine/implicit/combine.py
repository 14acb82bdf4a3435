"""Booleans, smooth blends, offsets and affine transforms of SDFs.

Booleans work on their children's normalised distances (f / lipschitz), so
each result is again a lower bound of the distance and its own bound is 1:
min and max of 1-Lipschitz functions are 1-Lipschitz, and so is the
quadratic smooth minimum (its partial derivatives are non-negative and sum
to 1).  An affine map x -> A x + t composes f with the inverse map, so its
bound is the child's times the largest singular value of A^-1.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .values import SDF, GlslModule, as_points, glsl_float

__all__ = ["Union", "Intersection", "Difference", "SmoothUnion", "SmoothIntersection",
           "SmoothDifference", "Offset", "Shell", "Affine"]


def _check_parts(parts) -> tuple:
    if isinstance(parts, SDF) or not isinstance(parts, (tuple, list)):
        raise ValueError(f"parts must be a tuple or list of SDFs, got a {type(parts).__name__}")
    parts = tuple(parts)
    if not parts:
        raise ValueError("a Boolean needs at least one SDF")
    for i, p in enumerate(parts):
        if not isinstance(p, SDF):
            raise ValueError(f"part {i} is a {type(p).__name__}, not an SDF")
    return parts


def _amount(name: str, value, positive: bool = False) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number (mm), got {value!r}") from None
    if not np.isfinite(v) or (positive and v <= 0):
        raise ValueError(f"{name} must be {'> 0' if positive else 'finite'} (mm), got {value!r}")
    return v


def _widened(box, amount: float, exact: bool):
    """`box` grown by `amount` mm; None (unbounded) unless the child's distance is exact, as a
    lower-bound distance may stay under `amount` far outside the grown box."""
    if box is None or not exact:
        return None
    return (tuple(np.subtract(box[0], amount)), tuple(np.add(box[1], amount)))


def _union_box(boxes):
    if any(b is None for b in boxes):
        return None
    lo = np.min([b[0] for b in boxes], axis=0)
    hi = np.max([b[1] for b in boxes], axis=0)
    return (tuple(lo), tuple(hi))


def _intersect_box(boxes):
    boxes = [b for b in boxes if b is not None]
    if not boxes:
        return None
    lo = np.max([b[0] for b in boxes], axis=0)
    hi = np.min([b[1] for b in boxes], axis=0)
    return (tuple(lo), tuple(np.maximum(hi, lo)))


def _reduce_glsl(module: GlslModule, owner, parts, op: str) -> str:
    names = [p.glsl_distance(module) for p in parts]

    def make(n):
        body = f"{names[0]}(p)"
        for m in names[1:]:
            body = f"{op}({body}, {m}(p))"
        return f"float {n}(vec3 p) {{ return {body}; }}"
    return module.function(owner, make)


@dataclass(frozen=True, eq=False)
class _Reduction(SDF):
    """min (`Union`) or max (`Intersection`) of the parts' distances."""

    parts: tuple
    _numpy = staticmethod(np.min)
    _glsl_op = "min"

    def __post_init__(self):
        object.__setattr__(self, "parts", _check_parts(self.parts))

    @property
    def children(self):
        return self.parts

    def field(self, points):
        p = as_points(points)
        return type(self)._numpy([c.distance(p) for c in self.parts], axis=0)

    def glsl(self, module):
        return _reduce_glsl(module, self, self.parts, self._glsl_op)


class Union(_Reduction):
    """min of the parts' distances: inside any part."""

    _numpy = staticmethod(np.min)
    _glsl_op = "min"

    @property
    def exact(self):
        return all(c.exact for c in self.parts)

    def box(self):
        return _union_box([c.box() for c in self.parts])


class Intersection(_Reduction):
    """max of the parts' distances: inside every part."""

    _numpy = staticmethod(np.max)
    _glsl_op = "max"

    def box(self):
        return _intersect_box([c.box() for c in self.parts])


@dataclass(frozen=True, eq=False)
class Difference(SDF):
    """`a` minus `b`: max(d_a, -d_b)."""

    a: SDF
    b: SDF

    def __post_init__(self):
        _check_parts((self.a, self.b))

    @property
    def children(self):
        return (self.a, self.b)

    def field(self, points):
        p = as_points(points)
        return np.maximum(self.a.distance(p), -self.b.distance(p))

    def glsl(self, module):
        na, nb = self.a.glsl_distance(module), self.b.glsl_distance(module)
        return module.function(self, lambda n: (
            f"float {n}(vec3 p) {{ return max({na}(p), -{nb}(p)); }}"))

    def box(self):
        return self.a.box()


def smooth_min(a: np.ndarray, b: np.ndarray, k: float) -> np.ndarray:
    """Quadratic smooth minimum with blend width `k` (mm); equals min(a, b) where |a - b| >= k."""
    h = np.maximum(k - np.abs(a - b), 0.0) / k
    return np.minimum(a, b) - h * h * k * 0.25


_SMIN_GLSL = """float smooth_min(float a, float b, float k) {
    float h = max(k - abs(a - b), 0.0) / k;
    return min(a, b) - h * h * k * 0.25;
}"""


@dataclass(frozen=True, eq=False)
class _Smooth(SDF):
    a: SDF
    b: SDF
    k: float      # blend width, mm (> 0)

    def __post_init__(self):
        _check_parts((self.a, self.b))
        object.__setattr__(self, "k", _amount("blend width k", self.k, positive=True))

    @property
    def children(self):
        return (self.a, self.b)

    # sign pattern (sa, sb, sr): result = sr * smooth_min(sa * d_a, sb * d_b)
    signs = (1.0, 1.0, 1.0)

    def field(self, points):
        p = as_points(points)
        sa, sb, sr = self.signs
        return sr * smooth_min(sa * self.a.distance(p), sb * self.b.distance(p), float(self.k))

    def glsl(self, module):
        module.helper("smooth_min", _SMIN_GLSL)
        na, nb = self.a.glsl_distance(module), self.b.glsl_distance(module)
        sa, sb, sr = ("-" if s < 0 else "" for s in self.signs)
        k = glsl_float(self.k)
        return module.function(self, lambda n: (
            f"float {n}(vec3 p) {{ return {sr}smooth_min({sa}{na}(p), {sb}{nb}(p), {k}); }}"))


class SmoothUnion(_Smooth):
    """Union of `a` and `b` blended over a width `k` mm (a fillet where they meet)."""

    signs = (1.0, 1.0, 1.0)

    def box(self):
        return _widened(_union_box([self.a.box(), self.b.box()]), self.k, self.a.exact and self.b.exact)


class SmoothIntersection(_Smooth):
    """Intersection of `a` and `b` with the edge rounded over a width `k` mm."""

    signs = (-1.0, -1.0, -1.0)

    def box(self):
        return _intersect_box([self.a.box(), self.b.box()])


class SmoothDifference(_Smooth):
    """`a` minus `b` with the cut edge rounded over a width `k` mm."""

    signs = (-1.0, 1.0, -1.0)

    def box(self):
        return self.a.box()


@dataclass(frozen=True, eq=False)
class Offset(SDF):
    """The child's surface moved outwards by `amount` mm (inwards if negative)."""

    child: SDF
    amount: float

    def __post_init__(self):
        _check_parts((self.child,))
        object.__setattr__(self, "amount", _amount("offset amount", self.amount))

    @property
    def children(self):
        return (self.child,)

    def field(self, points):
        return self.child.distance(points) - float(self.amount)

    def glsl(self, module):
        nc = self.child.glsl_distance(module)
        a = glsl_float(self.amount)
        return module.function(self, lambda n: f"float {n}(vec3 p) {{ return {nc}(p) - {a}; }}")

    @property
    def exact(self):
        return self.child.exact and self.amount >= 0

    def box(self):
        if self.amount <= 0:                     # inwards: inside the child, so inside its box
            return self.child.box()
        return _widened(self.child.box(), self.amount, self.child.exact)


@dataclass(frozen=True, eq=False)
class Shell(SDF):
    """A wall of `thickness` mm centred on the child's surface: |d| - thickness / 2."""

    child: SDF
    thickness: float

    def __post_init__(self):
        _check_parts((self.child,))
        object.__setattr__(self, "thickness", _amount("shell thickness", self.thickness, positive=True))

    @property
    def children(self):
        return (self.child,)

    def field(self, points):
        return np.abs(self.child.distance(points)) - 0.5 * float(self.thickness)

    def glsl(self, module):
        nc = self.child.glsl_distance(module)
        h = glsl_float(0.5 * self.thickness)
        return module.function(self, lambda n: f"float {n}(vec3 p) {{ return abs({nc}(p)) - {h}; }}")

    @property
    def exact(self):
        return self.child.exact

    def box(self):
        return _widened(self.child.box(), 0.5 * self.thickness, self.child.exact)


@dataclass(frozen=True, eq=False)
class Affine(SDF):
    """The child mapped by x -> matrix @ x + translation (mm).

    f_new(x) = f(A^-1 (x - t)), so |grad f_new| <= L_child * ||A^-1||_2: the
    bound is carried, the field is not rescaled (a uniform scale s could be
    exact with f * s; kept general so shears and anisotropic scales are right)."""

    child: SDF
    matrix: np.ndarray        # (3, 3), invertible
    translation: np.ndarray   # (3,) mm

    def __post_init__(self):
        _check_parts((self.child,))
        a = np.array(self.matrix, dtype=np.float64).reshape(3, 3)
        t = np.array(self.translation, dtype=np.float64).reshape(3)
        if not (np.all(np.isfinite(a)) and np.all(np.isfinite(t))):
            raise ValueError("affine matrix and translation must be finite")
        s = np.linalg.svd(a, compute_uv=False)
        if s[-1] <= 1e-12 * max(s[0], 1e-300):
            raise ValueError(f"affine matrix is singular (singular values {s.tolist()})")
        inv = np.linalg.inv(a)
        for arr in (a, t, inv):
            arr.setflags(write=False)
        object.__setattr__(self, "matrix", a)
        object.__setattr__(self, "translation", t)
        object.__setattr__(self, "_inverse", inv)
        object.__setattr__(self, "_inv_norm", float(1.0 / s[-1]))

    @property
    def children(self):
        return (self.child,)

    @property
    def lipschitz(self):
        return self.child.lipschitz * self._inv_norm

    @property
    def exact(self):
        """A rotation, translation and uniform scale keep an exact distance exact."""
        s = np.linalg.svd(self.matrix, compute_uv=False)
        return self.child.exact and bool(s[0] - s[-1] <= 1e-12 * s[0])

    def field(self, points):
        p = as_points(points)
        return self.child.field((p - self.translation) @ self._inverse.T)

    def glsl(self, module):
        nc = self.child.glsl(module)
        m = self._inverse
        # GLSL mat3 is column-major: mat3(c0, c1, c2)
        cols = ", ".join(glsl_float(m[r, c]) for c in range(3) for r in range(3))
        t = ", ".join(glsl_float(v) for v in self.translation)
        return module.function(self, lambda n: (
            f"float {n}(vec3 p) {{ return {nc}(mat3({cols}) * (p - vec3({t}))); }}"))

    def box(self):
        b = self.child.box()
        if b is None:
            return None
        corners = np.array([[x, y, z] for x in (b[0][0], b[1][0]) for y in (b[0][1], b[1][1])
                            for z in (b[0][2], b[1][2])])
        mapped = corners @ self.matrix.T + self.translation
        return (tuple(mapped.min(axis=0)), tuple(mapped.max(axis=0)))
