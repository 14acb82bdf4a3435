"""Line node (paper 5.2, 5.3, 6.2): edge chains joined into one path, thickened by a profile."""

from __future__ import annotations

import numpy as np

from engine.geometry.splines import arc_length_parameter, interpolate_chain
from engine.geometry.thickness import thickness_profile
from engine.graph.errors import NodeInputError
from engine.graph.node import NodeType, register
from engine.graph.schema import Param, Port
from engine.geometry.values import LineElement, Skeleton

_TOL = 1e-9


def order_chains(chains: list) -> list[tuple]:
    """Arrange chains into one continuously traversable path.

    Returns a list of (chain, reversed) in path order, or raises
    NodeInputError if the chains branch or fall apart.
    """
    if len(chains) == 1:
        return [(chains[0], False)]
    if any(c.closed for c in chains):
        raise NodeInputError("a closed edge chain cannot be joined with other chains in one line", where="chains")
    ends = [(c.points[0], c.points[-1]) for c in chains]
    # count how many chain ends meet at each point; a branch is 3 or more
    allpts = np.array([p for e in ends for p in e])
    for p in allpts:
        if np.sum(np.linalg.norm(allpts - p, axis=1) < _TOL) > 2:
            raise NodeInputError(f"edge chains branch at {np.round(p, 6).tolist()}: a line must be branch-free",
                                 where="chains")
    remaining = list(range(len(chains)))
    # start at a chain whose start or end touches no other chain (open path), else anywhere (loop)
    def degree(p):
        return np.sum(np.linalg.norm(allpts - p, axis=1) < _TOL)
    start = next((i for i in remaining if degree(ends[i][0]) == 1), None)
    rev = False
    if start is None:
        start = next((i for i in remaining if degree(ends[i][1]) == 1), 0)
        rev = degree(ends[start][1]) == 1
    path = [(chains[start], rev)]
    remaining.remove(start)
    tail = ends[start][0] if rev else ends[start][1]
    while remaining:
        nxt = None
        for i in remaining:
            if np.linalg.norm(ends[i][0] - tail) < _TOL:
                nxt = (i, False)
                break
            if np.linalg.norm(ends[i][1] - tail) < _TOL:
                nxt = (i, True)
                break
        if nxt is None:
            raise NodeInputError("edge chains do not form a single connected path (the end of one chain must be "
                                 f"the start of the next; nothing continues from {np.round(tail, 6).tolist()})",
                                 where="chains")
        i, r = nxt
        path.append((chains[i], r))
        remaining.remove(i)
        tail = ends[i][0] if r else ends[i][1]
    return path


@register
class LineNode(NodeType):
    """Joins edge chains into one branch-free path with a thickness profile over t in [0, 1]."""

    type_name = "Line"
    title = "Line"
    code = "l"
    family = "skeleton"
    inputs = (Port("chains", "EdgeChain", multi=True),)
    outputs = (Port("skeleton", "Skeleton"),)
    params = (
        Param("thickness", "samples", [[0.0, 0.1], [1.0, 0.1]], 1e-4, 2.0, unit="cell",
              doc="beam diameter at sparse positions t along the line, linearly interpolated"),
        Param("samples_per_segment", "int", 16, 2, 256, doc="spline samples between two vertices"),
    )

    def evaluate(self, inputs, params, ctx):
        chains = inputs["chains"]
        path = order_chains(chains)
        pieces, controls = [], []
        if len(path) == 1 and np.ptp(chain_points := path[0][0].points, axis=0).max() < 1e-12:
            # zero-length line: one point, a sphere under spherical extrusion (paper 3.1)
            d = thickness_profile(np.zeros(1), params["thickness"])[0]
            element = LineElement(chain_points[:1].repeat(2, axis=0), np.full(2, d), chain_points[:1])
            return {"skeleton": Skeleton((element,))}
        for chain, rev in path:
            pts = chain.points[::-1] if rev else chain.points
            period = None if chain.period is None else (-chain.period if rev else chain.period)
            poly = interpolate_chain(pts, smooth=chain.smooth, closed=chain.closed, period=period,
                                     samples_per_segment=params["samples_per_segment"])
            pieces.append(poly if not pieces else poly[1:])
            controls.append(pts)
        polyline = np.concatenate(pieces)
        t = arc_length_parameter(polyline)
        thickness = thickness_profile(t, params["thickness"])
        element = LineElement(polyline, thickness, np.concatenate(controls))
        return {"skeleton": Skeleton((element,))}
