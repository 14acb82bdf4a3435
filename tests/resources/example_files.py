"""Shared by the example tests: load a generator script, evaluate an example
with its Object nodes at a test resolution."""

from __future__ import annotations

import importlib.util
from pathlib import Path

from engine.graph import Evaluator, SetParam, UndoStack, load_project

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES_DIR = ROOT / "resources" / "examples"


def load_tool(stem: str):
    """The module tools/<stem>.py, loaded from its file."""
    spec = importlib.util.spec_from_file_location(stem, ROOT / "tools" / f"{stem}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def evaluate_at(path: Path, resolution: int):
    """(document, report) of the example at ``path`` with every Object node at ``resolution``."""
    doc = load_project(path)
    stack = UndoStack(doc)
    for node_id, node in doc.nodes.items():
        if node.type_name == "Object":
            stack.push(SetParam(node_id, "resolution", resolution))
    return doc, Evaluator().evaluate(doc)


def check_reading_layout(doc, name):
    """Columns by depth wrapped into bands read like text: no two nodes share a place;
    with k columns per band, a node of depth d is in column d % k of band d // k; every
    band lies below the one before; so every edge runs to a later column of its band or
    to a later band."""
    from engine.graph.layout import layer_depths

    places = {nid: tuple(n.position) for nid, n in doc.nodes.items()}
    assert len(set(places.values())) == len(places), f"{name}: nodes on top of each other"
    depth = layer_depths(list(doc.nodes), [(e.src, e.dst) for e in doc.edges])
    xs = sorted({x for x, _ in places.values()})
    k = len(xs)
    for nid, (x, _) in places.items():
        assert xs.index(x) == depth[nid] % k, f"{name}: {nid} (depth {depth[nid]}) in column {xs.index(x)}"
    band = {nid: depth[nid] // k for nid in places}
    for b in range(max(band.values(), default=0)):
        assert max(places[n][1] for n in places if band[n] == b) < \
            min(places[n][1] for n in places if band[n] == b + 1), f"{name}: bands {b} and {b + 1} overlap"
    for e in doc.edges:
        if depth[e.src] < depth[e.dst]:
            assert (band[e.src], places[e.src][0]) < (band[e.dst], places[e.dst][0]), f"{name}: {e.src} -> {e.dst}"
