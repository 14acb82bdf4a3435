"""Implicit functions as values: the SDF tree every implicit node passes on.

An `SDF` is an immutable tree of small value objects (primitives, periodic
functions, particle clouds, Booleans, transforms).  The same tree is
evaluated two ways, so a preview can never show another shape than the
one voxelised, meshed or exported:

* `SDF.field(points)` — numpy, float64, on (n, 3) points in mm;
* `SDF.glsl(module)` — GLSL source for a function ``float NAME(vec3 p)``
  added to a `GlslModule`, from which the sphere tracer
  (`engine.gpu.sphere_trace`) builds its shader.

Every SDF carries a Lipschitz bound ``lipschitz >= sup |grad f|``: then
``|f(p)| / lipschitz`` never exceeds the Euclidean distance from p to the
zero set, the property sphere tracing and narrow-band meshing rely on
(paper 004, section 4).  A non-Euclidean field (a periodic function, a
sheared or warped domain) keeps its raw value in `field` and declares its
bound; `distance` divides by it.  Booleans and offsets combine their
children's `distance`s, so their own bound is 1.

No graph import: nodes in `engine.nodes` build these trees.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

__all__ = ["SDF", "GlslModule", "glsl_float", "as_points", "Box"]

Box = tuple  # ((x0, y0, z0), (x1, y1, z1)) in mm, or None where the medium fills space


def as_points(points) -> np.ndarray:
    """`points` as a C-contiguous (n, 3) float64 array.

    Raises
    ------
    ValueError
        If `points` is not (n, 3) or (3,), or holds NaN / infinite values.
    """
    p = np.ascontiguousarray(points, dtype=np.float64)
    if p.ndim == 1 and p.shape[0] == 3:
        p = p.reshape(1, 3)
    if p.ndim != 2 or p.shape[1] != 3:
        raise ValueError(f"points must be an (n, 3) array in mm, got shape {np.shape(points)}")
    if not np.all(np.isfinite(p)):
        raise ValueError("points hold NaN or infinite coordinates")
    return p


def glsl_float(x: float) -> str:
    """A GLSL float literal for `x` (shortest repr that round-trips in float64).

    Raises
    ------
    ValueError
        If `x` is NaN or infinite (GLSL has no literal for them).
    """
    v = float(x)
    if not math.isfinite(v):
        raise ValueError(f"cannot write {v!r} into a shader")
    s = repr(v)
    return s if ("." in s or "e" in s) else s + ".0"


class GlslModule:
    """The GLSL source of an SDF tree, built by `SDF.glsl`.

    Functions are added once per SDF object (a tree that shares a subtree
    defines it once) and in dependency order: a node asks its children for
    their names before it defines itself.  Helpers (hash functions, shape
    formulas) are added once by name.  3D textures (a sampled field, e.g. a
    unit cell's voxels) are declared as ``uniform sampler3D`` and handed to
    the renderer with their data.
    """

    def __init__(self):
        self._helpers: dict[str, str] = {}
        self._functions: dict[tuple, tuple[str, str]] = {}   # (id(sdf), tag) -> (name, source)
        self._keep: list = []                              # keeps ids valid while the module lives
        self.textures: dict[str, np.ndarray] = {}          # uniform name -> (nz, ny, nx) float32

    def helper(self, name: str, source: str) -> None:
        """Add a helper's `source` once under `name` (later calls with the same name are ignored)."""
        self._helpers.setdefault(name, source)

    def function(self, owner, make: Callable[[str], str], tag: str = "") -> str:
        """The name of `owner`'s GLSL function (one per owner object and `tag`), defining it
        on first call.

        make : called with the chosen name; returns the whole definition
            ``float NAME(vec3 p) { ... }``."""
        key = (id(owner), tag)
        if key not in self._functions:
            name = f"sdf{len(self._functions)}_{type(owner).__name__.lower()}{tag}"
            self._keep.append(owner)
            self._functions[key] = (name, "")             # reserved: recursion sees the name
            self._functions[key] = (name, make(name))
        return self._functions[key][0]

    def texture3d(self, owner, data: np.ndarray) -> str:
        """Declare a 3D texture holding `data` ((nz, ny, nx), read as float32); its uniform name."""
        name = f"tex{len(self.textures)}_{type(owner).__name__.lower()}"
        self._keep.append(owner)
        self.textures[name] = np.ascontiguousarray(data, dtype=np.float32)
        return name

    def source(self) -> str:
        """Texture uniforms, helpers, then functions, each once, dependencies first."""
        parts = [f"uniform sampler3D {name};" for name in self.textures]
        parts += list(self._helpers.values())
        parts += [src for _, src in self._functions.values()]
        return "\n\n".join(parts) + "\n"


@dataclass(frozen=True, eq=False)
class SDF:
    """An implicit function f: R^3 -> R of points in mm, negative inside.

    Subclasses set `lipschitz` and implement `field` and `glsl`; they are
    frozen dataclasses (parameters validated in ``__post_init__`` with a
    `ValueError` that names the parameter and its allowed range)."""

    @property
    def lipschitz(self) -> float:
        """An upper bound of |grad f| over space (1 for an exact distance)."""
        return 1.0

    @property
    def exact(self) -> bool:
        """Whether, outside the surface, `distance` is the Euclidean distance to it (not only a
        lower bound).  Then it is also at least the distance to `box()`, which is what lets an
        offset or a blend widen its child's box by its own amount."""
        return False

    def field(self, points) -> np.ndarray:
        """f at `points` ((n, 3) mm): (n,) float64."""
        raise NotImplementedError

    def distance(self, points) -> np.ndarray:
        """f / lipschitz at `points`: (n,) float64, a lower bound of the distance to the surface
        in magnitude, with f's sign."""
        return self.field(points) / self.lipschitz

    def glsl(self, module: GlslModule) -> str:
        """Define ``float NAME(vec3 p)`` (returning f, float32) in `module`; return NAME."""
        raise NotImplementedError

    def box(self) -> Box | None:
        """An axis-aligned box (mm) outside which the function is positive, or None if the
        medium fills space (a periodic function, a particle cloud)."""
        return None

    @property
    def children(self) -> tuple["SDF", ...]:
        return ()

    def glsl_distance(self, module: GlslModule) -> str:
        """Like `glsl`, but the function returns f / lipschitz (what Booleans combine)."""
        name = self.glsl(module)
        if self.lipschitz == 1.0:
            return name
        inv = glsl_float(1.0 / self.lipschitz)
        return module.function(self, lambda n: (
            f"float {n}(vec3 p) {{ return {name}(p) * {inv}; }}"), tag="_dist")
