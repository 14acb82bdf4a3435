"""Generated project files: valid documents from the real node types' parameter
schemas, then mutated (wrong types, non-finite numbers, huge integers, deep
nesting, truncation, byte flips).  Either a file loads, and then saves and
reloads to an equal document, or it is refused with a ProjectFileError naming
its path; a load never touches the file and a failed save never damages it."""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from engine.graph import ProjectFileError, all_node_types, document_to_dict, load_project, save_project

FUZZ = settings(max_examples=120, deadline=None, derandomize=True, database=None,
                suppress_health_check=list(HealthCheck))
REAL_TYPES = {name: cls for name, cls in all_node_types().items() if not name.startswith("_")}
BAD = "@@bad@@"  # placeholder replaced in the JSON text by a literal json.dumps cannot write
RAW = ["NaN", "Infinity", "-Infinity", "1e400", "-1e999", "9" * 5001, "1" + "0" * 320, "[" * 100_000,
       "[" * 70 + "]" * 70, "[" * 100_000 + "]" * 100_000, '"\\udc80"', "tru", "0x10"]
JSONISH = st.recursive(st.none() | st.booleans() | st.integers(-10**6, 10**6) | st.floats(allow_nan=False,
                       allow_infinity=False) | st.text(max_size=8),
                       lambda kids: st.lists(kids, max_size=3) | st.dictionaries(st.text(max_size=5), kids,
                                                                                  max_size=3), max_leaves=8)


def _bounded(p, lo=-1e6, hi=1e6):
    return (p.minimum if p.minimum is not None else lo), (p.maximum if p.maximum is not None else hi)


def param_value(p):
    lo, hi = _bounded(p)
    fl = st.floats(lo, hi, allow_nan=False, allow_infinity=False)
    return {"float": fl, "int": st.integers(int(lo), int(hi)), "bool": st.booleans(),
            "enum": st.sampled_from(p.choices or (p.default,)), "vec3": st.lists(fl, min_size=3, max_size=3),
            "str": st.text(max_size=10), "int_list": st.lists(st.integers(int(lo), int(hi)), max_size=3),
            "samples": st.lists(st.tuples(st.floats(0, 1), fl).map(list), min_size=1, max_size=3),
            "json": st.just(p.default) | JSONISH}[p.kind]


@st.composite
def projects(draw):
    """A project dict: real node types, schema-drawn parameters, port-typed acyclic edges."""
    names = draw(st.lists(st.sampled_from(sorted(REAL_TYPES)), min_size=1, max_size=6))
    nodes = []
    for i, name in enumerate(names):
        cls = REAL_TYPES[name]
        params = {p.name: draw(param_value(p)) for p in cls.params if draw(st.booleans())}
        node = {"id": f"n{i}", "type": name, "params": params,
                "position": draw(st.lists(st.floats(-1e4, 1e4), min_size=2, max_size=2))}
        if draw(st.booleans()):
            node["label"] = draw(st.text(max_size=6))
        nodes.append(node)
    edges = []
    for j, dst in enumerate(names):
        for port in REAL_TYPES[dst].inputs:
            sources = [(i, out.name) for i, src in enumerate(names[:j]) for out in REAL_TYPES[src].outputs
                       if out.type == port.type]
            if sources and draw(st.booleans()):
                i, out = draw(st.sampled_from(sources))
                edges.append({"from": [f"n{i}", out], "to": [f"n{j}", port.name]})
    return {"format": "mesoforge-project", "version": draw(st.sampled_from([1, 2])),
            "seed": draw(st.integers(0, 2**64)), "meta": draw(st.dictionaries(st.text(max_size=5), JSONISH,
                                                                              max_size=3)),
            "nodes": nodes, "edges": edges, "node_state": {}}


def _locations(data, path=()):
    yield path
    if isinstance(data, dict):
        for k, v in data.items():
            yield from _locations(v, path + (k,))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            yield from _locations(v, path + (i,))


def _replace(data, path, value):
    if not path:
        return value
    parent = data
    for k in path[:-1]:
        parent = parent[k]
    parent[path[-1]] = value
    return data


@st.composite
def mutated_files(draw) -> bytes:
    data = draw(projects())
    how = draw(st.sampled_from(["none", "value", "raw", "drop", "duplicate", "truncate", "flip"]))
    if how in ("value", "raw", "drop"):
        path = draw(st.sampled_from(list(_locations(data))))
        if how == "drop" and path:
            parent = _replace(data, (), data)
            for k in path[:-1]:
                parent = parent[k]
            del parent[path[-1]]
        else:
            bad = BAD if how == "raw" else draw(JSONISH | st.sampled_from([[], {}, "", -1, 2**70, True]))
            data = _replace(data, path, bad)
    elif how == "duplicate":
        data["nodes"].append(dict(draw(st.sampled_from(data["nodes"]))))
    text = json.dumps(data, indent=draw(st.sampled_from([None, 1])))
    if how == "raw":
        text = text.replace(json.dumps(BAD), draw(st.sampled_from(RAW)))
    raw = text.encode("utf-8")
    if how == "truncate":
        raw = raw[:draw(st.integers(0, len(raw) - 1))]
    elif how == "flip":
        for _ in range(draw(st.integers(1, 4))):
            i = draw(st.integers(0, len(raw) - 1))
            raw = raw[:i] + bytes([raw[i] ^ draw(st.integers(1, 255))]) + raw[i + 1:]
    return raw


@FUZZ
@given(mutated_files())
def test_a_file_loads_and_round_trips_or_is_refused_with_its_path(raw):
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "fuzz.json"
        path.write_bytes(raw)
        os.chmod(path, 0o640)
        before = os.stat(path)
        try:
            doc = load_project(path)
        except ProjectFileError as exc:
            assert str(path) in str(exc) and exc.reason
            assert "unexpected" not in exc.reason, str(exc)
            doc = None
        after = os.stat(path)
        assert path.read_bytes() == raw and (after.st_mtime_ns, after.st_mode) == (before.st_mtime_ns,
                                                                                   before.st_mode)
        if doc is None:
            return
        save_project(doc, path)                            # over the original: mode kept
        assert os.stat(path).st_mode == before.st_mode
        again = load_project(path)
        assert document_to_dict(again) == document_to_dict(doc)
        assert sorted(os.listdir(d)) == ["fuzz.json"]


@FUZZ
@given(projects(), st.sampled_from(["write", "fsync", "fchmod", "replace"]))
def test_a_failed_save_leaves_the_existing_file_intact(data, step):
    import engine.fileio as fileio
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "p.json"
        path.write_text(json.dumps({"format": "mesoforge-project", "version": 2, "nodes": []}))
        before = path.read_bytes()
        src = Path(d) / "src.json"
        src.write_text(json.dumps(data))
        try:
            doc = load_project(src)
        except ProjectFileError:
            return
        src.unlink()

        def boom(*a, **k):
            raise OSError(28, "No space left on device")

        mp = pytest.MonkeyPatch()
        if step == "write":
            mp.setattr(fileio.os, "fdopen", lambda fd, mode: _FailingFile(fd))
        else:
            mp.setattr(os, step, boom)
        try:
            with pytest.raises(OSError):
                save_project(doc, path)
        finally:
            mp.undo()
        assert path.read_bytes() == before and sorted(os.listdir(d)) == ["p.json"]


class _FailingFile:
    """A file object whose write fails half way (disk full)."""

    def __init__(self, fd):
        self.fd = fd

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        os.close(self.fd)

    def fileno(self):
        return self.fd

    def write(self, data):
        os.write(self.fd, data[: len(data) // 2])
        raise OSError(28, "No space left on device")
