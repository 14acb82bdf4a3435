import json
import os

import pytest

from engine.graph import (AddNode, Connect, GraphDocument, ProjectFileError, UndoStack, document_to_dict,
                          load_project, save_project)
from engine.graph import project as project_mod


def _doc():
    doc = GraphDocument(seed=11)
    st = UndoStack(doc)
    st.push(AddNode("Vertex", {"position": [0, 0, 0]}, node_id="v1", position=(0, 0)))
    st.push(AddNode("Vertex", {"position": [1, 1, 1]}, node_id="v2", position=(0, 80)))
    st.push(AddNode("EdgeChain", {"smooth": True}, node_id="e1", position=(200, 40)))
    st.push(Connect("v1", "point", "e1", "vertices"))
    st.push(Connect("v2", "point", "e1", "vertices"))
    return doc


def test_round_trip(tmp_path):
    doc = _doc()
    p = tmp_path / "a.json"
    save_project(doc, p)
    back = load_project(p)
    assert document_to_dict(back) == document_to_dict(doc)


@pytest.mark.parametrize("content, reason", [
    ("", "empty"),
    ('{"format": "mesoforge-project", "version": 1, "nodes": [', "not valid JSON"),
    ('[1, 2]', "top level"),
    ('{"format": "other", "version": 1, "nodes": []}', "format"),
    ('{"format": "mesoforge-project", "version": 99, "nodes": []}', "newer"),
    ('{"format": "mesoforge-project", "version": 1, "nodes": [{"id": "x", "type": "Nope"}]}', "unknown node type"),
    ('{"format": "mesoforge-project", "version": 1, "nodes": [{"id": "x", "type": "Vertex", '
     '"params": {"position": [0, 0]}}]}', "position"),
    ('{"format": "mesoforge-project", "version": 1, "nodes": [], "edges": [{"from": ["a", "p"], "to": ["b", "q"]}]}',
     "no node with id"),
])
def test_bad_files_are_refused_with_path_and_reason(tmp_path, content, reason):
    p = tmp_path / "bad.json"
    p.write_text(content)
    with pytest.raises(ProjectFileError) as info:
        load_project(p)
    assert str(p) in str(info.value) and reason in str(info.value)


def test_truncated_real_file_is_refused(tmp_path):
    p = tmp_path / "t.json"
    save_project(_doc(), p)
    data = p.read_bytes()
    p.write_bytes(data[: len(data) // 2])
    with pytest.raises(ProjectFileError, match="truncated"):
        load_project(p)


def test_save_is_atomic_when_writing_fails(tmp_path, monkeypatch):
    p = tmp_path / "a.json"
    save_project(_doc(), p)
    before = p.read_bytes()

    def boom(*a, **k):
        raise OSError("disk full")

    monkeypatch.setattr(os, "fsync", boom)
    with pytest.raises(OSError):
        save_project(GraphDocument(seed=1), p)
    assert p.read_bytes() == before
    assert [f.name for f in tmp_path.iterdir()] == ["a.json"]


def test_migration_hook_runs(tmp_path, monkeypatch):
    monkeypatch.setattr(project_mod, "VERSION", 2)
    monkeypatch.setitem(project_mod.MIGRATIONS, 1, lambda d: {**d, "version": 2, "seed": 5})
    p = tmp_path / "old.json"
    p.write_text(json.dumps({"format": "mesoforge-project", "version": 1, "seed": 0, "nodes": []}))
    assert load_project(p).seed == 5
