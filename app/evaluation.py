"""Headless evaluation of a project for the command line: summary + mesh export."""

from __future__ import annotations

from typing import Any

import numpy as np

from engine.graph import EvalReport, Evaluator, GraphDocument, SetParam, UndoStack, node_type
from engine.graph.errors import GraphError
from engine.graph.query import nearest_upstream, pick_node
from engine.geometry.values import Solid, VoxelModel
from engine.memory import MemoryLimitError, tiled_mesh_bytes


def result_node(doc: GraphDocument, report: EvalReport, node_id: str | None = None) -> str | None:
    """The node whose solid is "the result": the given one, else the one feeding the
    Voxel node, else the last Solid-producing node in topological order
    (``engine.graph.query``)."""
    if node_id is not None:
        if node_id not in doc.nodes:
            raise ValueError(f"--node: no node with id {node_id!r} (nodes: {', '.join(doc.nodes)})")
        return node_id
    voxel = next((nid for nid, node in doc.nodes.items() if node.type_name == "Voxel"), None)
    feeder = nearest_upstream(doc, voxel, lambda _nid: True) if voxel is not None else None
    if feeder is not None:
        return feeder
    return pick_node(doc, None, lambda nid: isinstance(_first_output(report, nid), (Solid, VoxelModel)))


def _first_output(report: EvalReport, nid: str) -> Any:
    outs = report.outputs.get(nid) or {}
    return next(iter(outs.values()), None)


def solid_of(report: EvalReport, nid: str) -> Solid | None:
    v = _first_output(report, nid)
    if isinstance(v, VoxelModel):
        return v.solid
    return v if isinstance(v, Solid) else None


def override_resolution(doc: GraphDocument, resolution: int) -> None:
    """Set every Object node's grid resolution (quick previews / studies)."""
    stack = UndoStack(doc)
    for nid, node in doc.nodes.items():
        if node.type_name == "Object":
            stack.push(SetParam(nid, "resolution", resolution))


# What `eval --json` tells about each Surface node's solve (from its SurfaceReport).
SURFACE_KEYS = ("solver", "iterations", "energy", "area", "max_abs_H", "mean_abs_H", "converged", "warning")


def surface_entry(report: EvalReport, nid: str) -> dict:
    """Solver, iterations, final energy, area and max / mean |H| of a Surface node
    (or its status and error when it produced no report)."""
    r = report.results[nid]
    value = (report.outputs.get(nid) or {}).get("report")
    entry = {"status": r.status}
    if value is None:
        entry["error"] = r.error
        return entry
    summary = value.summary()
    entry.update({k: summary[k] for k in SURFACE_KEYS})
    return entry


def report_json(doc: GraphDocument, report: EvalReport) -> dict:
    nodes = []
    surfaces = {}
    for nid in doc.topological_order():
        r = report.results.get(nid)
        if r is None:
            continue
        if doc.nodes[nid].type_name == "Surface":
            surfaces[nid] = surface_entry(report, nid)
        entry = {"id": nid, "type": doc.nodes[nid].type_name, "status": r.status,
                 "seconds": round(r.seconds, 6)}
        for port, value in (report.outputs.get(nid) or {}).items():
            if hasattr(value, "summary"):  # e.g. a Stiffness: C and its constants
                entry.setdefault("outputs", {})[port] = value.summary()
        if r.error:
            entry["error"] = r.error
            if r.where:
                entry["where"] = r.where
        nodes.append(entry)
    out = {"ok": report.ok, "seconds": round(report.seconds, 6), "cache_hits": report.cache_hits,
           "evaluated": sum(r.status == "evaluated" for r in report.results.values()),
           "failed": sorted(report.errors), "nodes": nodes}
    if surfaces:
        out["surfaces"] = surfaces
    warnings = list(doc.load_warnings) + list(report.warnings.values())
    if warnings:
        out["warnings"] = warnings
    return out


class GraphMemoryError(MemoryLimitError):
    """A node of the graph whose memory estimate exceeds the budget; ``node``
    is its id, ``type_name`` its type."""

    def __init__(self, exc: MemoryLimitError, node: str, type_name: str):
        super().__init__(f"node {node!r} ({type_name}): {exc}", need=exc.need, budget=exc.budget,
                         lower=exc.lower, where=exc.where)
        self.node, self.type_name = node, type_name


def check_graph_memory(doc: GraphDocument) -> None:
    """Refuse a graph any node of which would exceed the memory budget, from
    the parameters alone (``NodeType.check_memory`` without inputs), before
    anything is evaluated.  Nodes with bad parameters are left to the
    evaluator, which reports them."""
    for nid in doc.topological_order():
        node = doc.nodes[nid]
        try:
            cls = node_type(node.type_name)
            params = cls.validate_params(node.params, nid)
        except (KeyError, GraphError):
            continue
        try:
            cls.check_memory(params, None)
        except MemoryLimitError as exc:
            raise GraphMemoryError(exc, nid, node.type_name) from None


def solid_grid_shape(doc: GraphDocument) -> tuple | None:
    """The largest Object grid of the graph (nodes per axis), or None: what a
    tiled mesh of its result is made from."""
    shapes = []
    for nid, node in doc.nodes.items():
        if node.type_name == "Object":
            cls = node_type("Object")
            try:
                shapes.append(cls.grid_shape(cls.validate_params(node.params, nid)))
            except GraphError:
                continue
    return max(shapes, key=lambda s: int(np.prod(s)), default=None)


def graph_tiling_estimate(doc: GraphDocument, tiles) -> int:
    """Peak bytes of tiling the graph's solid ``tiles`` times, before it is
    evaluated (face count bounded from the grid)."""
    shape = solid_grid_shape(doc)
    return 0 if shape is None else tiled_mesh_bytes(shape, tiles)


def evaluate_document(doc: GraphDocument, *, on_progress=None) -> EvalReport:
    """Evaluate `doc` in a fresh evaluator, starting from the node results stored
    in it (a grown and repainted tiling comes back as it was saved)."""
    evaluator = Evaluator()
    for warning in evaluator.import_state(doc.node_state):
        if warning not in doc.load_warnings:
            doc.load_warnings.append(warning)
    return evaluator.evaluate(doc, on_progress=on_progress)
