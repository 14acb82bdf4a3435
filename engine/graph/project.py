"""Project files: one versioned JSON document, validated on load.

Saving is atomic (temp file in the same folder, fsync, rename), so a crash
while saving leaves the previous file intact.  Loading builds a new document
and only returns it when everything checked out; a malformed, truncated or
wrong-version file raises ProjectFileError naming the path and the reason,
and whatever the caller had open is untouched.

Version 2 adds ``node_state``: the stored results of stateful nodes (see
`engine.graph.node_state`), so a tiling grown and repainted by hand reopens
as it was.  A malformed entry there does not refuse the file: it is dropped
and ``doc.load_warnings`` says which node lost its state and why.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, Callable

from engine.fileio import write_atomic

from .document import Edge, GraphDocument, NodeInstance
from .errors import GraphError, ProjectFileError
from .node import node_type
from .node_state import parse_state_entry

FORMAT = "mesoforge-project"
VERSION = 2


def _v1_to_v2(data: dict) -> dict:
    return {**data, "version": 2, "node_state": {}}  # version 1 stored no node results


# Migration hook: MIGRATIONS[v] turns a version-v dict into a version-(v+1) dict.
MIGRATIONS: dict[int, Callable[[dict], dict]] = {1: _v1_to_v2}


def _kept_state(doc: GraphDocument) -> dict[str, Any]:
    """doc.node_state for nodes that exist and are stateful (a removed node's goes)."""
    return {nid: entry for nid, entry in doc.node_state.items()
            if nid in doc.nodes and node_type(doc.nodes[nid].type_name).stateful}


def document_to_dict(doc: GraphDocument) -> dict[str, Any]:
    return {
        "format": FORMAT,
        "version": VERSION,
        "seed": doc.seed,
        "meta": doc.meta,
        "nodes": [
            {"id": n.id, "type": n.type_name, "params": n.params,
             "position": list(n.position), **({"label": n.label} if n.label else {})}
            for n in doc.nodes.values()
        ],
        "edges": [{"from": [e.src, e.src_port], "to": [e.dst, e.dst_port]} for e in doc.edges],
        "node_state": _kept_state(doc),
    }


def _need(cond: bool, where: str, what: str) -> None:
    if not cond:
        raise ValueError(f"{where}: {what}")


def migrate(data: dict) -> dict:
    """Bring an older project dict up to VERSION (the migration hook)."""
    version = data.get("version")
    _need(isinstance(version, int), "version", f"expected an integer, got {version!r}")
    if version > VERSION:
        raise ValueError(f"version {version} is newer than this Mesoforge understands (up to {VERSION})")
    while version < VERSION:
        step = MIGRATIONS.get(version)
        if step is None:
            raise ValueError(f"no migration from format version {version}")
        data = step(data)
        version = data["version"]
    return data


def document_from_dict(data: Any) -> GraphDocument:
    """Validate `data` and build a document; ValueError says where it is wrong."""
    _need(isinstance(data, dict), "top level", "expected a JSON object")
    _need(data.get("format") == FORMAT, "format", f"expected {FORMAT!r}, got {data.get('format')!r}")
    data = migrate(data)
    seed = data.get("seed", 0)
    _need(isinstance(seed, int) and not isinstance(seed, bool) and seed >= 0, "seed",
          f"expected a non-negative integer, got {seed!r}")
    doc = GraphDocument(seed=seed)
    meta = data.get("meta", {})
    _need(isinstance(meta, dict), "meta", "expected an object")
    doc.meta = meta
    nodes = data.get("nodes")
    _need(isinstance(nodes, list), "nodes", "expected a list")
    for i, n in enumerate(nodes):
        where = f"nodes[{i}]"
        _need(isinstance(n, dict), where, "expected an object")
        for key in ("id", "type"):
            _need(isinstance(n.get(key), str), f"{where}.{key}", "expected a string")
        params = n.get("params", {})
        _need(isinstance(params, dict), f"{where}.params", "expected an object")
        pos = n.get("position", [0, 0])
        _need(isinstance(pos, list) and len(pos) == 2 and all(isinstance(v, (int, float)) for v in pos),
              f"{where}.position", "expected [x, y]")
        try:
            node_type(n["type"])
        except KeyError as exc:
            raise ValueError(f"{where}.type: {exc.args[0]}") from None
        try:
            doc._raw_add_node(NodeInstance(n["id"], n["type"], params, (pos[0], pos[1]), str(n.get("label", ""))))
        except GraphError as exc:
            raise ValueError(f"{where}: {exc}") from None
    edges = data.get("edges", [])
    _need(isinstance(edges, list), "edges", "expected a list")
    for i, e in enumerate(edges):
        where = f"edges[{i}]"
        ok = (isinstance(e, dict) and isinstance(e.get("from"), list) and isinstance(e.get("to"), list)
              and len(e["from"]) == 2 and len(e["to"]) == 2
              and all(isinstance(v, str) for v in e["from"] + e["to"]))
        _need(ok, where, 'expected {"from": [node, port], "to": [node, port]}')
        try:
            doc._raw_connect(Edge(e["from"][0], e["from"][1], e["to"][0], e["to"][1]))
        except GraphError as exc:
            raise ValueError(f"{where}: {exc}") from None
    doc.node_state, doc.load_warnings = _read_node_state(data.get("node_state", {}), doc)
    return doc


def _read_node_state(states: Any, doc: GraphDocument) -> tuple[dict[str, Any], list[str]]:
    """The well-formed entries of ``node_state`` and a warning for each one dropped."""
    if not isinstance(states, dict):
        return {}, [f"node_state: expected an object, got {type(states).__name__}; "
                    f"stored node results dropped"]
    kept, warnings = {}, []
    for nid, entry in states.items():
        node = doc.nodes.get(nid)
        if node is None:
            warnings.append(f"node_state: no node with id {nid!r}; its stored result dropped")
            continue
        if not node_type(node.type_name).stateful:
            warnings.append(f"node {nid!r} ({node.type_name}) keeps no state; its stored result dropped")
            continue
        try:
            parse_state_entry(entry)
        except ValueError as exc:
            warnings.append(f"node {nid!r} ({node.type_name}): stored result dropped: {exc}")
            continue
        kept[nid] = entry
    return kept, warnings


def load_project(path: str | os.PathLike) -> GraphDocument:
    """Read and validate a project file.  Raises ProjectFileError."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ProjectFileError(p, "no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ProjectFileError(p, f"unreadable ({exc})") from None
    if not text.strip():
        raise ProjectFileError(p, "the file is empty")
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ProjectFileError(p, f"not valid JSON (truncated or corrupt?) at line {exc.lineno}, "
                                  f"column {exc.colno}: {exc.msg}") from None
    try:
        return document_from_dict(data)
    except ValueError as exc:
        raise ProjectFileError(p, str(exc)) from None


def save_project(doc: GraphDocument, path: str | os.PathLike) -> None:
    text = json.dumps(document_to_dict(doc), indent=1, allow_nan=False)
    write_atomic(path, (text + "\n").encode("utf-8"))
