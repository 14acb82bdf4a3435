"""Autosave files, cleanup and crash recovery (no Qt)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from engine.autosave import ENV_VAR, AutosaveManager, default_autosave_dir, pid_alive
from engine.graph import GraphDocument, SetSeed, UndoStack, document_to_dict, save_project


def dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    assert not pid_alive(proc.pid)
    return proc.pid


def doc_with_seed(seed: int) -> GraphDocument:
    doc = GraphDocument()
    UndoStack(doc).push(SetSeed(seed))
    doc.meta["note"] = "autosave test"
    return doc


def test_save_writes_document_and_sidecar(tmp_path):
    m = AutosaveManager(tmp_path)
    doc = doc_with_seed(5)
    m.save(doc, tmp_path / "p.json")
    data = json.loads(m.autosave_path.read_text())
    assert data == json.loads(json.dumps(document_to_dict(doc)))
    meta = json.loads(m.meta_path.read_text())
    assert meta["pid"] == os.getpid()
    assert meta["original_path"] == str((tmp_path / "p.json").resolve())
    assert abs(meta["saved_at"] - time.time()) < 60
    assert meta["autosave"] == m.autosave_path.name
    m.save(doc_with_seed(6), None)                      # overwritten in place, no temp files left
    assert json.loads(m.autosave_path.read_text())["seed"] == 6
    assert json.loads(m.meta_path.read_text())["original_path"] is None
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([m.autosave_path.name, m.meta_path.name])


def test_clear_removes_files(tmp_path):
    m = AutosaveManager(tmp_path)
    m.save(doc_with_seed(1), None)
    m.clear()
    assert list(tmp_path.iterdir()) == []
    m.clear()                                            # idempotent


def test_recoverable_only_from_dead_processes(tmp_path):
    alive = AutosaveManager(tmp_path)                    # this process: running
    alive.save(doc_with_seed(1), None)
    crashed = AutosaveManager(tmp_path, pid=dead_pid())
    crashed.save(doc_with_seed(2), None)
    finder = AutosaveManager(tmp_path)
    items = finder.find_recoverable()
    assert [i.pid for i in items] == [crashed.pid]
    assert items[0].original_path is None and items[0].display_name == "untitled project"
    assert document_to_dict(finder.load(items[0])) == document_to_dict(doc_with_seed(2))
    finder.discard(items[0])
    assert finder.find_recoverable() == []
    assert alive.autosave_path.is_file()                 # a live session's files are left alone


def test_recoverable_only_if_newer_than_original(tmp_path):
    project = tmp_path / "lattice.json"
    save_project(doc_with_seed(1), project)
    crashed = AutosaveManager(tmp_path / "auto", pid=dead_pid())
    crashed.save(doc_with_seed(2), project)
    finder = AutosaveManager(tmp_path / "auto")
    (item,) = finder.find_recoverable()
    assert item.original_path == str(project.resolve()) and item.display_name == "lattice.json"
    later = time.time() + 5                              # the project was saved after the autosave
    os.utime(project, (later, later))
    assert finder.find_recoverable() == []
    project.unlink()                                     # the original vanished: the autosave is all there is
    assert len(finder.find_recoverable()) == 1


def test_newest_first_and_malformed_sidecars_skipped(tmp_path):
    pid = dead_pid()
    older = AutosaveManager(tmp_path, pid=pid)
    older.save(doc_with_seed(1), None)
    newer = AutosaveManager(tmp_path, pid=pid)
    newer.save(doc_with_seed(2), None)
    meta = json.loads(older.meta_path.read_text())
    meta["saved_at"] -= 100
    older.meta_path.write_text(json.dumps(meta))
    (tmp_path / "junk.meta.json").write_text("{not json")
    (tmp_path / "evil.meta.json").write_text(json.dumps({"autosave": "../x.json", "saved_at": 1, "pid": pid}))
    orphan = AutosaveManager(tmp_path, pid=pid)          # sidecar whose document is missing
    orphan.save(doc_with_seed(3), None)
    orphan.autosave_path.unlink()
    items = AutosaveManager(tmp_path).find_recoverable()
    assert [i.meta_path for i in items] == [newer.meta_path, older.meta_path]


def test_directory_from_environment(tmp_path, monkeypatch):
    monkeypatch.setenv(ENV_VAR, str(tmp_path / "env"))
    assert default_autosave_dir() == tmp_path / "env"
    assert AutosaveManager().directory == tmp_path / "env"
    assert AutosaveManager(tmp_path / "arg").directory == tmp_path / "arg"
    monkeypatch.delenv(ENV_VAR)
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    monkeypatch.delenv("XDG_DATA_HOME", raising=False)
    assert default_autosave_dir() == tmp_path / "home" / ".local" / "share" / "mesoforge" / "autosave"


def test_missing_directory_finds_nothing(tmp_path):
    assert AutosaveManager(tmp_path / "nope").find_recoverable() == []


def test_autosave_module_does_not_import_qt():
    code = "import sys, engine.autosave; sys.exit('PySide6' in sys.modules)"
    root = Path(__file__).resolve().parents[2]
    assert subprocess.run([sys.executable, "-c", code], cwd=root).returncode == 0


def test_hostile_sidecars_are_skipped_not_raised(tmp_path):
    pid = dead_pid()
    good = AutosaveManager(tmp_path, pid=pid)
    good.save(doc_with_seed(4), None)
    name = good.autosave_path.name
    hostile = {
        "inf_pid.meta.json": '{"autosave": "%s", "saved_at": 1, "pid": Infinity}' % name,
        "big_pid.meta.json": '{"autosave": "%s", "saved_at": 1, "pid": %s}' % (name, "9" * 30),
        "nan_time.meta.json": '{"autosave": "%s", "saved_at": NaN, "pid": 1}' % name,
        "huge_time.meta.json": '{"autosave": "%s", "saved_at": 1e400, "pid": 1}' % name,
        "deep.meta.json": "[" * 100_000 + "]" * 100_000,
        "dotdot.meta.json": json.dumps({"autosave": "..", "saved_at": 1, "pid": pid}),
        "sidecar.meta.json": json.dumps({"autosave": "x.meta.json", "saved_at": 1, "pid": pid}),
        "nul.meta.json": json.dumps({"autosave": name, "saved_at": 1, "pid": pid, "original_path": "a\0b"}),
        "number.meta.json": json.dumps({"autosave": name, "saved_at": 1, "pid": pid, "original_path": 5}),
        "binary.meta.json": b"\xff\xfe\x00",
    }
    for fname, content in hostile.items():
        target = tmp_path / fname
        target.write_bytes(content if isinstance(content, bytes) else content.encode())
    items = AutosaveManager(tmp_path).find_recoverable()
    # a pid no process can have is a dead one; an unusable original path means "the original is gone"
    assert sorted(i.meta_path.name for i in items) == sorted([good.meta_path.name, "big_pid.meta.json",
                                                              "nul.meta.json"])
    for item in items:
        AutosaveManager.discard(item)                    # never raises


def test_pid_alive_of_an_impossible_pid_is_false():
    assert not pid_alive(2**80) and not pid_alive(-5)


def test_discard_removes_temporaries_a_killed_autosave_left(tmp_path):
    crashed = AutosaveManager(tmp_path, pid=dead_pid())
    crashed.save(doc_with_seed(3), None)
    left = tmp_path / f".{crashed.autosave_path.name}.0a1b2c3d.tmp"
    left.write_bytes(b'{"format": "meso')
    os.utime(left, (time.time() - 600, time.time() - 600))
    (item,) = AutosaveManager(tmp_path).find_recoverable()
    AutosaveManager.discard(item)
    assert list(tmp_path.iterdir()) == []


def test_a_new_autosave_folder_is_private(tmp_path):
    m = AutosaveManager(tmp_path / "auto")
    m.save(doc_with_seed(1), None)
    assert (tmp_path / "auto").stat().st_mode & 0o077 == 0


def test_a_document_opened_from_any_loadable_file_autosaves(tmp_path):
    from engine.graph import load_project
    p = tmp_path / "p.json"
    p.write_text(json.dumps({"format": "mesoforge-project", "version": 2, "seed": 2**64,
                             "meta": {"x": 1e308, "n": [[[]]]},
                             "nodes": [{"id": "v", "type": "Vertex", "position": [1, -2]}]}))
    m = AutosaveManager(tmp_path / "auto")
    m.save(load_project(p), p)
    assert document_to_dict(load_project(m.autosave_path)) == document_to_dict(load_project(p))
