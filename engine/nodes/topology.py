"""Vertex and Edge Chain nodes (paper 6.1)."""

from __future__ import annotations

import numpy as np

from engine.graph.errors import NodeInputError
from engine.graph.node import NodeType, register
from engine.graph.schema import Param, Port
from engine.geometry.values import EdgeChain, Point


@register
class VertexNode(NodeType):
    """Places a vertex at `position` (unit-cell coordinates)."""

    type_name = "Vertex"
    title = "Vertex"
    code = "v"
    family = "topology"
    outputs = (Port("point", "Point"),)
    params = (Param("position", "vec3", [0.0, 0.0, 0.0], -10.0, 10.0, unit="cell",
                    doc="vertex position in unit-cell coordinates"),)

    def evaluate(self, inputs, params, ctx):
        return {"point": Point(np.array(params["position"]))}


@register
class EdgeChainNode(NodeType):
    """An ordered path over the connected vertices, straight or smooth.

    `order` lists indices into the connected vertices (connection order when
    empty); repeating the first index at the end closes the loop.  `period`
    is a translation for curves that continue smoothly into the next cell.
    """

    type_name = "EdgeChain"
    title = "Edge Chain"
    code = "e"
    family = "topology"
    inputs = (Port("vertices", "Point", multi=True),)
    outputs = (Port("chain", "EdgeChain"),)
    params = (
        Param("smooth", "bool", False, doc="natural cubic spline through the vertices instead of straight segments"),
        Param("order", "int_list", [], 0, 10_000, doc="vertex order as indices into the inputs; empty = as connected"),
        Param("period", "vec3", [0.0, 0.0, 0.0], -10.0, 10.0, unit="cell",
              doc="translation to the next period for curves that tile across the cell boundary; zero = none"),
    )

    def evaluate(self, inputs, params, ctx):
        pts = [p.xyz for p in inputs["vertices"]]
        order = params["order"] or list(range(len(pts)))
        bad = [i for i in order if i >= len(pts)]
        if bad:
            raise NodeInputError(f"order refers to vertex index {bad[0]} but only {len(pts)} vertices are connected",
                                 where="order")
        closed = len(order) > 2 and order[0] == order[-1]
        body = order[:-1] if closed else order
        if len(set(body)) != len(body):
            raise NodeInputError(f"order {order} visits a vertex twice: an edge chain must be branch-free",
                                 where="order")
        if len(body) < 2:
            raise NodeInputError(f"an edge chain needs at least two vertices, got {len(body)}", where="vertices")
        points = np.array([pts[i] for i in body])
        gaps = np.linalg.norm(np.diff(points, axis=0), axis=1) < 1e-12
        if np.all(gaps) and not closed:
            # a zero-length chain: thickened spherically it is a sphere (paper 3.1)
            return {"chain": EdgeChain(points[:1].repeat(2, axis=0), False)}
        if np.any(gaps):
            raise NodeInputError("two consecutive vertices of the edge chain coincide", where="vertices")
        period = np.array(params["period"])
        return {"chain": EdgeChain(points, bool(params["smooth"]), closed,
                                   period if np.any(period != 0) else None)}
