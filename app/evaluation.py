"""Headless evaluation of a project for the command line: summary + mesh export."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from engine.graph import EvalReport, Evaluator, GraphDocument, SetParam, UndoStack
from engine.graph.values import Solid, VoxelModel


def result_node(doc: GraphDocument, report: EvalReport, node_id: str | None = None) -> str | None:
    """The node whose solid is "the result": the given one, else the one feeding the
    Voxel node, else the last Solid-producing node in topological order."""
    if node_id is not None:
        if node_id not in doc.nodes:
            raise ValueError(f"--node: no node with id {node_id!r} (nodes: {', '.join(doc.nodes)})")
        return node_id
    for nid, node in doc.nodes.items():
        if node.type_name == "Voxel":
            src = doc.inputs_of(nid, "solid")
            if src:
                return src[0].src
    solids = [n for n in doc.topological_order() if isinstance(_first_output(report, n), (Solid, VoxelModel))]
    return solids[-1] if solids else None


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


@dataclass
class MeshResult:
    vertices: np.ndarray
    faces: np.ndarray
    summary: dict


def tiled_mesh(solid: Solid, tiles=(1, 1, 1)) -> MeshResult:
    """The solid's mesh tiled ``tiles`` cells per axis (copies at multiples of
    the box, ``solid.box`` mm), with its summary; one marching-cubes pass over
    the tiled field, so the block is watertight."""
    from engine.geometry.marching import periodic_mesh
    from engine.geometry.mesh_io import mesh_summary

    tiles = tuple(int(t) for t in tiles)
    if tiles == (1, 1, 1):
        v, f = np.asarray(solid.vertices), np.asarray(solid.faces)
    else:
        v, f = periodic_mesh(np.asarray(solid.sdf), tiles=tiles, cell_size=solid.cell_size,
                             cell=solid.cell)
    s = mesh_summary(v, f)
    cell_volume = solid.cell_size ** 3 if solid.is_unit_cube else float(np.prod(solid.box))
    s["volume_fraction"] = float(s["volume"]) / (cell_volume * np.prod(tiles))
    s["grid_volume_fraction"] = solid.volume_fraction
    s["tiles"] = list(tiles)
    if not solid.is_unit_cube:
        s["cell"] = list(solid.cell)
        s["box_mm"] = solid.box.tolist()
    return MeshResult(v, f, s)


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


def evaluate_document(doc: GraphDocument, *, on_progress=None) -> EvalReport:
    """Evaluate `doc` in a fresh evaluator, starting from the node results stored
    in it (a grown and repainted tiling comes back as it was saved)."""
    evaluator = Evaluator()
    for warning in evaluator.import_state(doc.node_state):
        if warning not in doc.load_warnings:
            doc.load_warnings.append(warning)
    return evaluator.evaluate(doc, on_progress=on_progress)
