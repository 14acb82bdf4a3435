"""Autosave files, cleanup and crash recovery (no Qt)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from app.autosave import ENV_VAR, AutosaveManager, default_autosave_dir, pid_alive
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
    code = "import sys, app.autosave; sys.exit('PySide6' in sys.modules)"
    root = Path(__file__).resolve().parents[2]
    assert subprocess.run([sys.executable, "-c", code], cwd=root).returncode == 0
