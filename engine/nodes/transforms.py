"""Mirror, Transform and Group nodes (paper 6.4)."""

from __future__ import annotations

import numpy as np

from engine.graph.errors import NodeInputError
from engine.graph.node import NodeType, register
from engine.graph.schema import Param, Port
from engine.geometry.values import Skeleton

_DO_COPY = Param("do_copy", "bool", True, doc="keep the input and add the transformed copy")


def rotation_matrix(axis, angle_deg: float) -> np.ndarray:
    """Right-handed rotation about `axis` by `angle_deg` degrees (Rodrigues)."""
    a = np.asarray(axis, float)
    n = np.linalg.norm(a)
    if n < 1e-12:
        raise NodeInputError(f"rotation axis {list(axis)} has zero length", where="rotation_axis")
    k = a / n
    th = np.deg2rad(angle_deg)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * (K @ K)


def mirror_matrix(normal) -> np.ndarray:
    """Householder reflection across the plane with the given normal."""
    n = np.asarray(normal, float)
    length = np.linalg.norm(n)
    if length < 1e-12:
        raise NodeInputError(f"mirror direction {list(normal)} has zero length", where="direction")
    n = n / length
    return np.eye(3) - 2.0 * np.outer(n, n)


def _apply(skeleton: Skeleton, matrix, origin, translation, scale, do_copy) -> Skeleton:
    origin = np.asarray(origin, float)
    offset = origin - (scale * matrix) @ origin + np.asarray(translation, float)
    moved = skeleton.transformed(scale * matrix, offset, scale)
    return skeleton + moved if do_copy else moved


@register
class MirrorNode(NodeType):
    """Reflects a skeleton across the plane through `origin` with normal `direction`."""

    type_name = "Mirror"
    title = "Mirror"
    code = "mirror"
    family = "transform"
    inputs = (Port("skeleton", "Skeleton"),)
    outputs = (Port("skeleton", "Skeleton"),)
    params = (
        Param("direction", "vec3", [1.0, 0.0, 0.0], -1e3, 1e3, doc="normal of the mirror plane"),
        Param("origin", "vec3", [0.5, 0.5, 0.5], -10.0, 10.0, unit="cell", doc="a point on the mirror plane"),
        _DO_COPY,
    )

    def evaluate(self, inputs, params, ctx):
        m = mirror_matrix(params["direction"])
        return {"skeleton": _apply(inputs["skeleton"], m, params["origin"], (0, 0, 0), 1.0, params["do_copy"])}


@register
class TransformNode(NodeType):
    """Scales about `origin`, rotates about `rotation_axis` through `origin`, then translates."""

    type_name = "Transform"
    title = "Transform"
    code = "t"
    family = "transform"
    inputs = (Port("skeleton", "Skeleton"),)
    outputs = (Port("skeleton", "Skeleton"),)
    params = (
        Param("origin", "vec3", [0.5, 0.5, 0.5], -10.0, 10.0, unit="cell"),
        Param("scale", "float", 1.0, 1e-3, 1e3, doc="uniform scale about the origin (thickness scales too)"),
        Param("rotation_angle", "float", 0.0, -360.0, 360.0, unit="deg"),
        Param("rotation_axis", "vec3", [0.0, 0.0, 1.0], -1e3, 1e3),
        Param("translation", "vec3", [0.0, 0.0, 0.0], -10.0, 10.0, unit="cell"),
        _DO_COPY,
    )

    def evaluate(self, inputs, params, ctx):
        r = rotation_matrix(params["rotation_axis"], params["rotation_angle"])
        return {"skeleton": _apply(inputs["skeleton"], r, params["origin"], params["translation"],
                                   params["scale"], params["do_copy"])}


@register
class GroupNode(NodeType):
    """Combines several skeletons into one."""

    type_name = "Group"
    title = "Group"
    code = "g"
    family = "transform"
    inputs = (Port("skeletons", "Skeleton", multi=True),)
    outputs = (Port("skeleton", "Skeleton"),)

    def evaluate(self, inputs, params, ctx):
        out = Skeleton()
        for s in inputs["skeletons"]:
            out = out + s
        return {"skeleton": out}
