"""Project files: one versioned JSON document, validated on load.

Saving is atomic (temp file in the same folder, fsync, rename), so a crash
while saving leaves the previous file intact.  Loading builds a new document
and only returns it when everything checked out; a malformed, truncated or
wrong-version file raises ProjectFileError naming the path, the JSON location
(``nodes[3].position[0]``) and the reason, and whatever the caller had open is
untouched.  Every value is checked on load (finite numbers within a double's
range, nesting at most MAX_DEPTH deep, text), so a document that loads can
always be saved.  Loading is O(V + E): nodes are appended, edges checked in
bulk with one cycle search (`GraphDocument._raw_connect_all`).

Version 2 adds ``node_state``: the stored results of stateful nodes (see
`engine.graph.node_state`), so a tiling grown and repainted by hand reopens
as it was.  A malformed entry there does not refuse the file: it is dropped
and ``doc.load_warnings`` says which node lost its state and why.
"""

from __future__ import annotations

import json
import math
import os
import re
import stat
from pathlib import Path
from typing import Any, Callable

from engine.fileio import write_atomic

from .annotation_file import AnnotationsInvalid, annotations_to_dict, read_annotations
from .document import Edge, GraphDocument, NodeInstance
from .errors import GraphError, ParamError, ProjectFileError
from .node import node_type
from .node_state import parse_state_entry

FORMAT = "mesoforge-project"
VERSION = 2

# Deepest nesting of arrays and objects a project file may have (the shipped
# examples need 8); deeper data is refused on load, so nothing downstream
# (parameter checks, deepcopy, the JSON writer) can run out of stack on it.
MAX_DEPTH = 64
# Integers beyond what a double holds are refused: a float parameter would
# overflow on them and the JSON writer refuses integers of over 4300 digits.
_SAFE_INT = 2**1000
_INT_DIGITS = 400  # longer integer literals are kept as text, refused with their location


class InvalidProject(ValueError):
    """What `document_from_dict` raises: `where` in the data (a JSON location) and the `reason`."""

    def __init__(self, where: str, reason: str):
        super().__init__(f"{where}: {reason}")
        self.where = where
        self.reason = reason


class _LongInteger(str):
    """An integer literal too long to convert; found and refused by `check_json_values`."""


def _parse_int(text: str) -> int | _LongInteger:
    return int(text) if len(text) <= _INT_DIGITS else _LongInteger(text)


def parse_json(text: str) -> Any:
    """`json.loads` that raises InvalidProject (with line and column) for anything it refuses."""
    try:
        return json.loads(text, parse_int=_parse_int)
    except json.JSONDecodeError as exc:
        raise InvalidProject(f"line {exc.lineno}, column {exc.colno}",
                             f"not valid JSON (truncated or corrupt?): {exc.msg}") from None
    except RecursionError:
        raise InvalidProject(_too_deep_at(text), f"nested more than {MAX_DEPTH} levels deep") from None
    except ValueError as exc:
        raise InvalidProject("top level", f"not valid JSON: {exc}") from None


def _too_deep_at(text: str) -> str:
    """Line and column of the bracket that opens nesting level MAX_DEPTH + 1."""
    depth = 0
    for m in re.finditer(r'"(?:[^"\\]|\\.)*"|[\[\]{}]', text):
        if m.group() in ("[", "{"):
            depth += 1
            if depth > MAX_DEPTH:
                line_start = text.rfind("\n", 0, m.start()) + 1
                return f"line {text.count(chr(10), 0, line_start) + 1}, column {m.start() - line_start + 1}"
        elif m.group() in ("]", "}"):
            depth -= 1
    return "top level"


def check_json_values(data: Any) -> None:
    """Raise InvalidProject at the first value JSON cannot round-trip.

    data : dict or list, parsed JSON or a document's dict.
    Refused: non-finite numbers (NaN, Infinity, or literals such as 1e400 that
    overflow a double), integers beyond a double's range, nesting deeper than
    MAX_DEPTH, non-string object keys, strings with a lone surrogate escape
    (``"\\ud800"``, not text) and values that are not JSON data.  Iterative
    (deep data cannot exhaust the stack) and O(size of data).
    """
    stack: list[tuple[Any, Any, int]] = [(data, None, 1)]
    while stack:
        value, path, depth = stack.pop()
        if depth > MAX_DEPTH:
            raise InvalidProject(_where(path), f"nested more than {MAX_DEPTH} levels deep")
        if isinstance(value, dict):
            for k in value:
                if type(k) is not str or not k.isascii():
                    if not isinstance(k, str) or not _is_text(k):
                        raise InvalidProject(_where(path), f"object key {shown(k)} is not text")
            items = value.items()
        else:
            items = enumerate(value)
        for k, v in items:
            t = type(v)
            if t is float:
                if not math.isfinite(v):
                    raise InvalidProject(_where((path, k)), _not_finite(v))
            elif t is int:
                if not -_SAFE_INT < v < _SAFE_INT and not _fits_double(v):
                    raise InvalidProject(_where((path, k)), _too_long(_digits(v)))
            elif t is str:
                if not v.isascii() and not _is_text(v):
                    raise InvalidProject(_where((path, k)), _NOT_TEXT)
            elif t is dict or t is list or t is tuple:
                stack.append((v, (path, k), depth + 1))
            elif v is not None and t is not bool:
                problem = _other_value(v, (path, k), depth, stack)
                if problem:
                    raise InvalidProject(_where((path, k)), problem)


_NOT_TEXT = "a string with a lone surrogate escape (\\ud800-\\udfff) is not text"


def _other_value(v: Any, path: Any, depth: int, stack: list) -> str:
    """The problem with a value of no plain JSON type ("" if none): long integer
    literals, subclasses of the JSON types (containers are queued on `stack`)."""
    if isinstance(v, _LongInteger):
        return _too_long(len(v.lstrip("-")))  # exact: the literal's own digits
    if isinstance(v, (dict, list, tuple)):
        stack.append((v, path, depth + 1))
        return ""
    if isinstance(v, bool):
        return ""
    if isinstance(v, float):
        return "" if math.isfinite(v) else _not_finite(v)
    if isinstance(v, int):
        return "" if _fits_double(v) else _too_long(_digits(int(v)))
    if isinstance(v, str):
        return "" if _is_text(v) else _NOT_TEXT
    return f"expected JSON data, got a {type(v).__name__}"


def _digits(v: int) -> int:
    """Decimal digits of |v|, about (str() refuses integers of over 4300 digits)."""
    return int(v.bit_length() * math.log10(2)) + 1


def _not_finite(v: float) -> str:
    return f"expected a finite number (at most ±1.8e308), got {_json_number(v)}"


def _too_long(digits: int) -> str:
    return f"an integer of about {digits} digits is beyond a double's range (±1.8e308)"


def _fits_double(v: int) -> bool:
    try:
        float(v)
    except OverflowError:
        return False
    return True


def _is_text(s: str) -> bool:
    try:
        s.encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True


def _json_number(v: float) -> str:
    return "NaN" if math.isnan(v) else ("Infinity" if v > 0 else "-Infinity")


def _where(path: Any) -> str:
    """``nodes[3].position[0]`` from the linked (parent, key) pairs of `check_json_values`."""
    keys = []
    while path is not None:
        path, k = path
        keys.append(k)
    out = ""
    for k in reversed(keys):
        if isinstance(k, int):
            out += f"[{k}]"
        elif k.isidentifier():
            out += f".{k}" if out else k
        else:
            out += f"[{json.dumps(k[:40] + ('...' if len(k) > 40 else ''))}]"
    return out or "top level"


def shown(value: Any) -> str:
    """A found value as quoted in a message: JSON spelling, long data cut short."""
    try:
        text = json.dumps(value, allow_nan=True)
    except (TypeError, ValueError, RecursionError):
        text = repr(value)
    return text if len(text) <= 80 else f"{text[:80]}... ({len(text)} characters)"


def type_name(value: Any) -> str:
    return {dict: "an object", list: "a list", str: "a string", bool: "true or false", int: "a number",
            float: "a number", type(None): "null"}.get(type(value), type(value).__name__)


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
        # frames and subgraphs (engine.graph.annotation_file); written only when there are any
        **({"annotations": annotations_to_dict(doc.annotations)} if doc.annotations else {}),
    }


def _need(cond: bool, where: str, expected: str, got: Any = None, *, describe=None) -> None:
    """Refuse at `where` unless `cond`: "expected ..., got ..." (the value shown only then)."""
    if not cond:
        raise InvalidProject(where, f"expected {expected}, got {(describe or shown)(got)}")


def _is_int(v: Any) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def migrate(data: dict) -> dict:
    """Bring an older project dict up to VERSION (the migration hook)."""
    version = data.get("version")
    _need(_is_int(version), "version", "an integer", version)
    if version > VERSION:
        raise InvalidProject("version", f"version {version} is newer than this Mesoforge understands "
                                        f"(up to {VERSION})")
    while version < VERSION:
        step = MIGRATIONS.get(version)
        if step is None:
            raise InvalidProject("version", f"no migration from format version {version}")
        data = step(data)
        version = data["version"]
    return data


def document_from_dict(data: Any) -> GraphDocument:
    """Validate `data` and build a document; InvalidProject (a ValueError) says where it is wrong.

    Every value is checked first (`check_json_values`: finite numbers, bounded
    nesting, plain JSON types), so whatever this accepts `save_project` can write.
    """
    _need(isinstance(data, dict), "top level", "a JSON object", data, describe=type_name)
    check_json_values(data)
    _need(data.get("format") == FORMAT, "format", repr(FORMAT), data.get("format"))
    data = migrate(data)
    seed = data.get("seed", 0)
    _need(_is_int(seed) and seed >= 0, "seed", "a non-negative integer", seed)
    doc = GraphDocument(seed=seed)
    meta = data.get("meta", {})
    _need(isinstance(meta, dict), "meta", "an object", meta, describe=type_name)
    doc.meta = meta
    nodes = data.get("nodes")
    _need(isinstance(nodes, list), "nodes", "a list", nodes, describe=type_name)
    first_index: dict[str, int] = {}
    for i, n in enumerate(nodes):
        _add_node(doc, n, f"nodes[{i}]", first_index)
        first_index.setdefault(n["id"], i)
    edges = data.get("edges", [])
    _need(isinstance(edges, list), "edges", "a list", edges, describe=type_name)
    parsed = [_edge(e, f"edges[{i}]") for i, e in enumerate(edges)]
    try:
        doc._raw_connect_all(parsed)
    except GraphError as exc:
        raise InvalidProject(f"edges[{exc.index}]", str(exc)) from None
    doc.node_state, doc.load_warnings = _read_node_state(data.get("node_state", {}), doc)
    if "annotations" in data:  # optional: older files have none
        try:
            read_annotations(data["annotations"], doc.annotations)
        except AnnotationsInvalid as exc:
            raise InvalidProject(exc.where, exc.reason) from None
    return doc


def _add_node(doc: GraphDocument, n: Any, where: str, first_index: dict[str, int]) -> None:
    _need(isinstance(n, dict), where, "an object", n, describe=type_name)
    for key in ("id", "type"):
        _need(isinstance(n.get(key), str), f"{where}.{key}", "a string", n.get(key))
    nid = n["id"]
    if nid in first_index:
        raise InvalidProject(f"{where}.id", f"node id {nid!r} is already used by nodes[{first_index[nid]}]")
    params = n.get("params", {})
    _need(isinstance(params, dict), f"{where}.params", "an object", params, describe=type_name)
    pos = n.get("position", [0.0, 0.0])
    _need(isinstance(pos, list) and len(pos) == 2 and all(_is_number(v) for v in pos),
          f"{where}.position", "[x, y], two numbers", pos)
    label = n.get("label", "")
    _need(label is None or isinstance(label, str), f"{where}.label", "a string", label)
    try:
        node_type(n["type"])
    except KeyError as exc:
        raise InvalidProject(f"{where}.type", exc.args[0]) from None
    node = NodeInstance(nid, n["type"], params, (float(pos[0]), float(pos[1])), label or "")
    try:
        doc._raw_add_node(node)
    except ParamError as exc:
        raise InvalidProject(f"{where}.params.{exc.param}" if exc.param in params else f"{where}.params",
                             str(exc)) from None
    except GraphError as exc:
        raise InvalidProject(f"{where}.{exc.where or 'id'}", str(exc)) from None
    except Exception as exc:  # a node type's own check that failed on odd data: still a refusal
        raise InvalidProject(f"{where}.params", f"node {nid!r} ({n['type']}): parameters refused "
                                               f"({type(exc).__name__}: {exc})") from None


def _edge(e: Any, where: str) -> Edge:
    ok = (isinstance(e, dict) and isinstance(e.get("from"), list) and isinstance(e.get("to"), list)
          and len(e["from"]) == 2 and len(e["to"]) == 2
          and all(isinstance(v, str) for v in e["from"] + e["to"]))
    _need(ok, where, '{"from": [node, port], "to": [node, port]}', e)
    return Edge(e["from"][0], e["from"][1], e["to"][0], e["to"][1])


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
    """Read and validate a project file.

    Raises ProjectFileError -- and no other exception -- naming the path,
    where in the file (a JSON location such as ``nodes[3].position[0]``) and
    the reason.  The file is only read.
    """
    p = Path(path)
    text = _read_text(p)
    try:
        return document_from_dict(parse_json(text))
    except InvalidProject as exc:
        raise ProjectFileError(p, exc.reason, where=exc.where) from None
    except Exception as exc:  # a check that failed in a way nobody foresaw is still a refusal
        raise ProjectFileError(p, f"unexpected {type(exc).__name__} while reading it: {exc}") from None


def _read_text(p: Path) -> str:
    """The file's text; ProjectFileError when it is missing, not a file, unreadable or not UTF-8."""
    try:
        st = p.stat()
        kind = "file" if stat.S_ISREG(st.st_mode) else ("directory" if stat.S_ISDIR(st.st_mode) else "other")
        raw = p.read_bytes() if kind == "file" else b""  # a FIFO or device could block or never end
    except FileNotFoundError:
        raise ProjectFileError(p, "no such file") from None
    except PermissionError:
        raise ProjectFileError(p, "permission denied: the file cannot be read") from None
    except MemoryError:
        raise ProjectFileError(p, "too large to read into memory") from None
    except (OSError, ValueError) as exc:  # ValueError: a path with a NUL byte
        raise ProjectFileError(p, f"unreadable ({exc})") from None
    if kind != "file":
        raise ProjectFileError(p, "is a directory, not a project file" if kind == "directory"
                               else "is not a regular file (a device, pipe or socket?)")
    try:
        text = raw.decode("utf-8-sig")  # a byte-order mark some editors write is not an error
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        raise ProjectFileError(p, f"not UTF-8 text (byte 0x{raw[exc.start]:02x}); corrupt or not a project "
                                  f"file", where=f"byte {exc.start} (line {line})") from None
    if not text.strip():
        raise ProjectFileError(p, "the file is empty")
    return text


def save_project(doc: GraphDocument, path: str | os.PathLike) -> None:
    """Write `doc` atomically; ValueError (naming the location) if it holds a value
    JSON cannot keep -- never the case for a document `load_project` returned."""
    data = document_to_dict(doc)
    check_json_values(data)
    text = json.dumps(data, indent=1, allow_nan=False)
    write_atomic(path, (text + "\n").encode("utf-8"))
