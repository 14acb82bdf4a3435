"""Bad project files a new user makes: each is refused with the path, the JSON
location and the reason (a ProjectFileError, never another exception); saving
keeps the file's mode and cleans temporaries a killed save left behind."""

from __future__ import annotations

import builtins
import json
import os
import stat
import sys
import time

import pytest

import engine.graph.document as document_mod
from engine.fileio import remove_stale_temps, write_atomic
from engine.graph import (GraphDocument, ProjectFileError, document_from_dict, document_to_dict, load_project,
                          save_project)


def _project(nodes=(), edges=(), **extra):
    return {"format": "mesoforge-project", "version": 2, "seed": 0, "meta": {}, "nodes": list(nodes),
            "edges": list(edges), **extra}


def _vertex(nid, **kw):
    return {"id": nid, "type": "Vertex", "params": {"position": [0, 0, 0]}, "position": [0, 0], **kw}


CHAIN = [_vertex("a"), _vertex("b"), {"id": "e", "type": "EdgeChain", "params": {}}]
CHAIN_EDGES = [{"from": ["a", "point"], "to": ["e", "vertices"]}, {"from": ["b", "point"], "to": ["e", "vertices"]}]


def _refused(path, text: str | bytes) -> ProjectFileError:
    if isinstance(text, str):
        text = text.encode("utf-8")
    path.write_bytes(text)
    with pytest.raises(ProjectFileError) as info:
        load_project(path)
    assert str(path) in str(info.value)
    assert path.read_bytes() == text
    return info.value


@pytest.mark.parametrize("text, where, reason", [
    (json.dumps(_project([_vertex("a")], meta={"x": float("nan")})), "meta.x", "got NaN"),
    (json.dumps(_project([_vertex("a")], meta={"x": [1, float("-inf")]})), "meta.x[1]", "got -Infinity"),
    (json.dumps(_project([_vertex("a"), _vertex("b", position=[1, float("inf")])])), "nodes[1].position[1]",
     "got Infinity"),
    (json.dumps(_project([_vertex("a", position=[1e400, 0])])), "nodes[0].position[0]", "finite number"),
    (json.dumps(_project([{"id": "o", "type": "Object", "params": {"resolution": 1e400}}])).replace(
        "Infinity", "1e400"), "nodes[0].params.resolution", "finite number"),
    (json.dumps(_project([{"id": "o", "type": "Object", "params": {"resolution": "@"}}])).replace(
        '"@"', "Infinity"), "nodes[0].params.resolution", "got Infinity"),
    (json.dumps(_project([{"id": "o", "type": "Object", "params": {"resolution": "@"}}])).replace(
        '"@"', "9" * 5001), "nodes[0].params.resolution", "5001 digits"),
    (json.dumps(_project([{"id": "o", "type": "Object", "params": {"cell_size": "@"}}])).replace(
        '"@"', "9" * 330), "nodes[0].params.cell_size", "beyond a double"),
    (json.dumps(_project(seed="@")).replace('"@"', "1" + "0" * 400), "seed", "beyond a double"),
    (json.dumps(_project(meta={"deep": "@"})).replace('"@"', "[" * 100_000 + "]" * 100_000), "line 1, column",
     "nested more than 64 levels"),
    (json.dumps(_project(meta={"deep": "@"})).replace('"@"', "[" * 200 + "]" * 200), "meta.deep[0][0]",
     "nested more than 64 levels"),
    (json.dumps(_project([_vertex("a"), _vertex("a")])), "nodes[1].id", "already used by nodes[0]"),
    (json.dumps(_project([_vertex("1a")])), "nodes[0].id", "not a valid identifier"),
    (json.dumps(_project(CHAIN, [{"from": ["a", "point"], "to": ["zz", "vertices"]}])), "edges[0]",
     "no node with id 'zz'"),
    (json.dumps(_project(CHAIN, [CHAIN_EDGES[0], {"from": ["b", "nope"], "to": ["e", "vertices"]}])), "edges[1]",
     "no output port 'nope'"),
    (json.dumps(_project(CHAIN, CHAIN_EDGES + CHAIN_EDGES[:1])), "edges[2]", "already connected"),
    (json.dumps(_project(CHAIN, [{"from": ["a", "point"], "to": "e"}])), "edges[0]", "expected {\"from\""),
    (json.dumps(_project([_vertex("a", position=[True, 0])])), "nodes[0].position", "two numbers"),
    (json.dumps(_project([_vertex("a", position="0,0")])), "nodes[0].position", "two numbers"),
    (json.dumps(_project([_vertex("a", label=["x"])])), "nodes[0].label", "a string"),
    (json.dumps(_project([_vertex("a", params=[1])])), "nodes[0].params", "an object"),
    (json.dumps(_project([_vertex("a", params={"position": "up"})])), "nodes[0].params.position", "three numbers"),
    (json.dumps(_project([{"id": 5, "type": "Vertex"}])), "nodes[0].id", "a string"),
    (json.dumps(_project([7])), "nodes[0]", "an object"),
    (json.dumps(_project(meta=[])), "meta", "an object"),
    (json.dumps(_project(seed=-1)), "seed", "non-negative"),
    (json.dumps(_project(seed=True)), "seed", "non-negative"),
    (json.dumps({**_project(), "version": True}), "version", "an integer"),
    (json.dumps({**_project(), "nodes": {}}), "nodes", "a list"),
    (json.dumps({**_project(), "edges": None}), "edges", "a list"),
    (json.dumps(_project(meta={"s": "\ud800"})), "meta.s", "lone surrogate"),
    ('{"format": "mesoforge-project", "version": 2, "nodes": [', "line 1, column", "truncated"),
    (b'{"format": "mesoforge-project", \xff\xfe "version": 2}', "byte 32", "not UTF-8"),
])
def test_bad_values_are_refused_with_location(tmp_path, text, where, reason):
    err = _refused(tmp_path / "bad.json", text)
    assert where in err.where and reason in err.reason, str(err)
    assert f"{err.where}: {err.reason}" in str(err)
    assert "unexpected" not in err.reason


def test_a_directory_a_fifo_and_an_unreadable_file_are_refused(tmp_path, monkeypatch):
    with pytest.raises(ProjectFileError, match="is a directory"):
        load_project(tmp_path)
    fifo = tmp_path / "fifo.json"
    os.mkfifo(fifo)
    with pytest.raises(ProjectFileError, match="not a regular file"):
        load_project(fifo)                               # and does not block reading it
    locked = tmp_path / "locked.json"
    locked.write_text(json.dumps(_project()))
    real = type(locked).read_bytes

    def denied(self):
        if self.name == "locked.json":
            raise PermissionError(13, "Permission denied")
        return real(self)

    monkeypatch.setattr(type(locked), "read_bytes", denied)  # root ignores chmod 000
    with pytest.raises(ProjectFileError, match="permission denied") as info:
        load_project(locked)
    assert str(locked) in str(info.value)
    with pytest.raises(ProjectFileError, match="no such file"):
        load_project(tmp_path / "missing.json")


def test_a_byte_order_mark_is_accepted(tmp_path):
    p = tmp_path / "bom.json"
    p.write_bytes(b"\xef\xbb\xbf" + json.dumps(_project(CHAIN, CHAIN_EDGES)).encode())
    assert list(load_project(p).nodes) == ["a", "b", "e"]


def test_first_edge_closing_a_cycle_is_named(tmp_path):
    nodes = [{"id": f"t{i}", "type": "Transform", "params": {}} for i in range(4)]
    link = [{"from": [f"t{i}", "skeleton"], "to": [f"t{(i + 1) % 4}", "skeleton"]} for i in range(4)]
    err = _refused(tmp_path / "cycle.json", json.dumps(_project(nodes, link)))
    assert err.where == "edges[3]" and "would create a cycle" in err.reason


def test_whatever_loads_saves_even_integers_near_the_limit(tmp_path):
    p = tmp_path / "p.json"
    text = json.dumps(_project(CHAIN, CHAIN_EDGES, meta={"big": "@", "x": 1e308})).replace('"@"', "9" * 300)
    p.write_text(text)
    doc = load_project(p)
    save_project(doc, p)
    assert document_to_dict(load_project(p)) == document_to_dict(doc)


def test_saving_names_the_value_json_cannot_hold_and_leaves_the_file(tmp_path):
    p = tmp_path / "p.json"
    save_project(document_from_dict(_project(CHAIN, CHAIN_EDGES)), p)
    before = p.read_bytes()
    doc = load_project(p)
    doc.meta["oops"] = float("nan")                      # set by code, not by a file
    with pytest.raises(ValueError, match=r"meta\.oops: expected a finite number"):
        save_project(doc, p)
    assert p.read_bytes() == before and os.listdir(tmp_path) == ["p.json"]


def test_editor_positions_and_seeds_a_file_cannot_hold_are_refused():
    from engine.graph import GraphError, MoveNode, SetSeed, UndoStack
    doc = document_from_dict(_project(CHAIN, CHAIN_EDGES))
    stack = UndoStack(doc)
    with pytest.raises(GraphError, match="finite"):
        stack.push(MoveNode("a", (float("nan"), 0.0)))
    with pytest.raises(GraphError, match="non-negative"):
        stack.push(SetSeed(-3))
    assert doc.nodes["a"].position == (0.0, 0.0) and doc.seed == 0


# -- file mode and stale temporaries ---------------------------------------------------

def test_saving_keeps_the_mode_of_the_file_it_replaces(tmp_path):
    p = tmp_path / "p.json"
    doc = document_from_dict(_project(CHAIN, CHAIN_EDGES))
    old_umask = os.umask(0o022)
    try:
        save_project(doc, p)
        assert stat.S_IMODE(p.stat().st_mode) == 0o644   # a new file: 0666 less the umask
        for mode in (0o644, 0o640, 0o664, 0o600):
            os.chmod(p, mode)
            save_project(doc, p)
            assert stat.S_IMODE(p.stat().st_mode) == mode
    finally:
        os.umask(old_umask)


def test_saving_through_a_symlink_replaces_its_target(tmp_path):
    real = tmp_path / "real.json"
    link = tmp_path / "link.json"
    save_project(GraphDocument(seed=1), real)
    link.symlink_to(real)
    save_project(document_from_dict(_project(seed=7)), link)
    assert link.is_symlink() and load_project(real).seed == 7


def _aged(path, seconds=3600.0):
    path.write_bytes(b"half a project")
    t = time.time() - seconds
    os.utime(path, (t, t))
    return path


def test_a_save_removes_only_our_stale_temporaries_of_that_target(tmp_path):
    p = tmp_path / "p.json"
    stale = [_aged(tmp_path / ".p.json.k2x9_a0b.tmp"), _aged(tmp_path / ".p.json.0123abcd.tmp")]
    kept = [_aged(tmp_path / ".q.json.0123abcd.tmp"),        # another target's
            _aged(tmp_path / ".p.json.0123abcd.tmp.bak"),    # not our pattern
            _aged(tmp_path / ".p.json.0123abc.tmp"),
            _aged(tmp_path / "p.json.0123abcd.tmp"),
            _aged(tmp_path / ".p.json.0123abce.tmp", seconds=0.0)]  # fresh: a writer may be at work
    os.symlink(tmp_path / "elsewhere", tmp_path / ".p.json.symlink1.tmp")  # not a regular file
    write_atomic(p, b"{}")
    names = set(os.listdir(tmp_path))
    assert not names & {s.name for s in stale}
    assert {k.name for k in kept} | {"p.json", ".p.json.symlink1.tmp"} == names


def test_a_locked_temporary_belongs_to_a_live_writer_and_stays(tmp_path):
    fcntl = pytest.importorskip("fcntl")
    busy = _aged(tmp_path / ".p.json.feedf00d.tmp")
    with open(busy, "rb") as fh:
        fcntl.flock(fh.fileno(), fcntl.LOCK_EX)
        assert remove_stale_temps(tmp_path / "p.json") == []
    assert busy.exists()
    assert remove_stale_temps(tmp_path / "p.json") == [busy] and not busy.exists()


def test_a_killed_save_leaves_a_temporary_the_next_save_removes(tmp_path):
    import subprocess
    p = tmp_path / "p.json"
    code = ("import os, sys; import engine.fileio as f; "
            "os.replace = lambda *a: os.kill(os.getpid(), 9); f.write_atomic(sys.argv[1], b'{}')")
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
    subprocess.run([sys.executable, "-c", code, str(p)], cwd=root)
    (left,) = [n for n in os.listdir(tmp_path)]
    assert left.startswith(".p.json.") and left.endswith(".tmp")
    t = time.time() - 60
    os.utime(tmp_path / left, (t, t))
    save_project(GraphDocument(seed=2), p)
    assert os.listdir(tmp_path) == ["p.json"]


# -- loading is linear in the size of the graph ----------------------------------------

def chain_project(n_nodes: int) -> dict:
    """Units of Vertex, Vertex -> EdgeChain -> Line -> Group, the Groups chained (deep graph)."""
    nodes, edges = [], []
    for u in range(n_nodes // 5):
        a, b, e, ln, g = (f"{k}{u}" for k in ("va", "vb", "e", "l", "g"))
        nodes += [_vertex(a, position=[0, u]), _vertex(b, position=[50, u]),
                  {"id": e, "type": "EdgeChain", "params": {}}, {"id": ln, "type": "Line", "params": {}},
                  {"id": g, "type": "Group", "params": {}}]
        edges += [{"from": [a, "point"], "to": [e, "vertices"]}, {"from": [b, "point"], "to": [e, "vertices"]},
                  {"from": [e, "chain"], "to": [ln, "chains"]}, {"from": [ln, "skeleton"], "to": [g, "skeletons"]}]
        if u:
            edges.append({"from": [f"g{u - 1}", "skeleton"], "to": [g, "skeletons"]})
    return _project(nodes, edges)


def _operations(data: dict) -> int:
    """Lines executed in engine/graph plus elements copied by list() in document.py."""
    count = 0
    graph_dir = os.path.dirname(document_mod.__file__) + os.sep

    def local(frame, event, arg):
        nonlocal count
        count += event == "line"
        return local

    def counting_list(*args):
        nonlocal count
        out = builtins.list(*args)
        count += len(out)
        return out

    document_mod.list = counting_list
    sys.settrace(lambda frame, event, arg: local if frame.f_code.co_filename.startswith(graph_dir) else None)
    try:
        document_from_dict(data)
    finally:
        sys.settrace(None)
        del document_mod.list
    return count


def test_loading_work_grows_linearly_with_the_node_count():
    document_from_dict(chain_project(10))                  # node modules imported outside the count
    small, large = _operations(chain_project(200)), _operations(chain_project(800))
    # linear: x4; the former per-edge cycle search and per-node dict rebuild gave x13
    assert large < 4.6 * small, (small, large)
