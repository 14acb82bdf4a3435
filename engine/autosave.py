"""Autosave and crash recovery of a project document.  Pure Python: no Qt here.

Each running window owns one `AutosaveManager`.  `save` writes the document
to ``<session>.json`` in the autosave folder and a small sidecar
``<session>.meta.json`` naming the project it belongs to, the time and the
process id.  A clean save or a clean exit calls `clear`, which removes both.
Files that survive belong to a process that died: `find_recoverable` lists
those whose process is gone and which are newer than their original project
file, so the next start can offer to recover them.
"""

from __future__ import annotations

import json
import math
import os
import time
import uuid
from dataclasses import dataclass
from pathlib import Path

from engine.fileio import remove_stale_temps
from engine.graph import GraphDocument, load_project, save_project, write_atomic

ENV_VAR = "MESOFORGE_AUTOSAVE_DIR"
META_SUFFIX = ".meta.json"
DOC_SUFFIX = ".json"


def default_autosave_dir() -> Path:
    """``$MESOFORGE_AUTOSAVE_DIR`` if set, else ``~/.local/share/mesoforge/autosave``."""
    env = os.environ.get(ENV_VAR)
    if env:
        return Path(env)
    base = os.environ.get("XDG_DATA_HOME") or os.path.join(os.path.expanduser("~"), ".local", "share")
    return Path(base) / "mesoforge" / "autosave"


def pid_alive(pid: int) -> bool:
    """Whether a process with this id is running (on this machine)."""
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    except (OSError, OverflowError):  # OverflowError: no process id is that large
        return False
    return True


@dataclass(frozen=True)
class RecoveryItem:
    """An autosave left behind by a process that is no longer running.

    original_path : the project file it was autosaved for, or None (untitled).
    saved_at : seconds since the epoch when the autosave was written.
    """

    autosave_path: Path
    meta_path: Path
    original_path: str | None
    saved_at: float
    pid: int

    @property
    def display_name(self) -> str:
        return Path(self.original_path).name if self.original_path else "untitled project"


class AutosaveManager:
    """Writes, clears and finds autosaves of one session.

    Parameters
    ----------
    directory : folder for autosaves; default `default_autosave_dir()`.
    pid : process id recorded in the sidecar (tests may pass a dead one).
    """

    def __init__(self, directory: str | os.PathLike | None = None, *, pid: int | None = None):
        self.directory = Path(directory) if directory is not None else default_autosave_dir()
        self.pid = os.getpid() if pid is None else int(pid)
        self.session = f"autosave-{self.pid}-{uuid.uuid4().hex[:8]}"
        self.last_saved_at: float | None = None

    @property
    def autosave_path(self) -> Path:
        return self.directory / f"{self.session}{DOC_SUFFIX}"

    @property
    def meta_path(self) -> Path:
        return self.directory / f"{self.session}{META_SUFFIX}"

    def save(self, doc: GraphDocument, project_path: str | os.PathLike | None) -> Path:
        """Write `doc` atomically (document first, then its sidecar), as a
        project file with the stateful nodes' results in ``doc.node_state``
        (the window puts ``Evaluator.export_state()`` there first).  A new
        autosave folder is private to the user (0700)."""
        self.directory.mkdir(mode=0o700, parents=True, exist_ok=True)
        save_project(doc, self.autosave_path)
        now = time.time()
        meta = {
            "original_path": None if project_path is None else str(Path(project_path).resolve()),
            "saved_at": now,
            "pid": self.pid,
            "autosave": self.autosave_path.name,
        }
        write_atomic(self.meta_path, (json.dumps(meta, indent=1) + "\n").encode("utf-8"))
        self.last_saved_at = now
        return self.autosave_path

    def clear(self) -> None:
        """Remove this session's autosave (after a clean save or exit)."""
        _remove_quietly(self.meta_path, self.autosave_path)
        self.last_saved_at = None

    # -- recovery ---------------------------------------------------------
    def find_recoverable(self) -> list[RecoveryItem]:
        """Autosaves of dead processes that are newer than their original file, newest first."""
        if not self.directory.is_dir():
            return []
        items = []
        for meta_path in sorted(self.directory.glob(f"*{META_SUFFIX}")):
            item = _read_meta(meta_path)
            if item is None or item.meta_path == self.meta_path or pid_alive(item.pid):
                continue
            if not item.autosave_path.is_file():
                continue
            if item.original_path is not None:
                try:
                    if os.path.getmtime(item.original_path) >= item.saved_at:
                        continue  # the project was saved after this autosave: nothing to recover
                except (OSError, ValueError):  # ValueError: a path with a NUL byte
                    pass  # the original is gone: the autosave is all there is
            items.append(item)
        items.sort(key=lambda it: it.saved_at, reverse=True)
        return items

    @staticmethod
    def load(item: RecoveryItem) -> GraphDocument:
        """The autosaved document; raises ProjectFileError if it is unreadable."""
        return load_project(item.autosave_path)

    @staticmethod
    def discard(item: RecoveryItem) -> None:
        """Remove a recoverable autosave, its sidecar and the temporary files a
        save killed midway left of them.  Best effort: never raises."""
        _remove_quietly(item.meta_path, item.autosave_path)
        for p in (item.meta_path, item.autosave_path):
            try:
                remove_stale_temps(p)
            except OSError:
                pass


def _remove_quietly(*paths: Path) -> None:
    """Unlink what exists; a file that cannot be removed stays (and is retried next time)."""
    for p in paths:
        try:
            p.unlink()
        except OSError:
            pass


def _read_meta(meta_path: Path) -> RecoveryItem | None:
    """Parse a sidecar; None when it is unreadable or malformed (it is skipped)."""
    try:
        meta = json.loads(meta_path.read_text(encoding="utf-8"))
        name = meta["autosave"]
        if not _is_autosave_name(name):
            return None
        original = meta.get("original_path")
        saved_at = float(meta["saved_at"])
        if not math.isfinite(saved_at) or (original is not None and not isinstance(original, str)):
            return None
        return RecoveryItem(
            autosave_path=meta_path.parent / name,
            meta_path=meta_path,
            original_path=original,
            saved_at=saved_at,
            pid=int(meta["pid"]),
        )
    except (OSError, ValueError, KeyError, TypeError, ArithmeticError, RecursionError):
        return None  # RecursionError: JSON nested too deep; ArithmeticError: int(Infinity)


def _is_autosave_name(name) -> bool:
    """A plain file name of an autosave document in the same folder (no path, no sidecar)."""
    return (isinstance(name, str) and name.endswith(DOC_SUFFIX) and not name.endswith(META_SUFFIX)
            and not any(c in name for c in "/\\\0") and not name.startswith("."))
