"""Atomic file writing shared by project files and mesh export."""

from __future__ import annotations

import hashlib
import os
import re
import secrets
import stat
import time
from pathlib import Path

try:  # POSIX: a writer holds an advisory lock on its temporary file until the rename
    import fcntl
except ImportError:  # pragma: no cover - not POSIX
    fcntl = None

# A temporary file of ours this much older than its last write belongs to a
# writer that died (killed during a save); the next save of the same target
# removes it -- unless a live writer still holds its lock.
STALE_TEMP_SECONDS = 10.0


def temp_name_pattern(name: str) -> re.Pattern:
    """The names `write_atomic` gives temporary siblings of a file called `name`.

    ``.NAME.XXXXXXXX.tmp`` with eight characters of ``[a-z0-9_]`` (what
    `tempfile.mkstemp` produced in earlier versions, and hex digits now).
    """
    return re.compile(rf"\.{re.escape(name)}\.[a-z0-9_]{{8}}\.tmp")


def write_atomic(path: str | os.PathLike, data: bytes) -> None:
    """Write bytes so that `path` holds either its old or its new content, never a mix.

    The data goes to a temporary sibling, is fsynced and renamed over `path`;
    the folder is created if needed and fsynced so the rename survives a crash.
    An existing file keeps its permission bits (and group, where allowed); a
    new one gets 0666 less the umask, like any file the user creates.  A
    symbolic link is followed: the file it points to is replaced, the link stays.
    Afterwards, temporary files that earlier writes of the same target left
    behind (a killed process) are removed; see `remove_stale_temps`.
    """
    p = Path(os.path.realpath(path)) if os.path.islink(path) else Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    try:
        old = os.stat(p)
    except (FileNotFoundError, NotADirectoryError):
        old = None
    if old is not None and not stat.S_ISREG(old.st_mode):
        old = None  # a directory or device: os.replace refuses it below
    fd, tmp = _create_temp(p)
    try:
        with os.fdopen(fd, "wb") as f:
            if fcntl is not None:
                fcntl.flock(f.fileno(), fcntl.LOCK_EX)
            f.write(data)
            f.flush()
            if old is not None:
                _copy_ownership(f.fileno(), old)
            os.fsync(f.fileno())
            if fcntl is not None:
                os.replace(tmp, p)  # still locked: a cleaner never takes a file mid-rename
        if fcntl is None:  # pragma: no cover - not POSIX
            os.replace(tmp, p)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
    try:
        dfd = os.open(p.parent, os.O_RDONLY)
        try:
            os.fsync(dfd)
        finally:
            os.close(dfd)
    except OSError:
        pass
    try:
        remove_stale_temps(p)
    except OSError:
        pass  # the save itself succeeded; leftovers wait for the next one


def _create_temp(p: Path) -> tuple[int, str]:
    """Open a new temporary sibling of `p` exclusively; mode 0666 less the umask."""
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_NOFOLLOW", 0)
    for _ in range(100):
        tmp = str(p.parent / f".{p.name}.{secrets.token_hex(4)}.tmp")
        try:
            return os.open(tmp, flags, 0o666), tmp
        except FileExistsError:
            continue
    raise FileExistsError(f"no free temporary name for {str(p)!r}")


def _copy_ownership(fd: int, old: os.stat_result) -> None:
    """Give the open temporary file the replaced file's group and permission bits."""
    if hasattr(os, "fchown") and old.st_gid != os.fstat(fd).st_gid:
        try:
            os.fchown(fd, -1, old.st_gid)
        except OSError:
            pass  # not a member of that group: the file keeps ours
    if hasattr(os, "fchmod"):
        os.fchmod(fd, stat.S_IMODE(old.st_mode))


def remove_stale_temps(path: str | os.PathLike, *, older_than: float = STALE_TEMP_SECONDS) -> list[Path]:
    """Remove the temporary files earlier `write_atomic` calls on `path` left behind.

    Only regular files in `path`'s folder named like ours for this very target
    (`temp_name_pattern`), owned by this user, last written more than
    `older_than` seconds ago and not locked by a live writer are removed.
    Returns the removed paths.
    """
    p = Path(path)
    pattern = temp_name_pattern(p.name)
    uid = os.geteuid() if hasattr(os, "geteuid") else None
    now = time.time()
    removed = []
    with os.scandir(p.parent) as entries:
        candidates = [e for e in entries if pattern.fullmatch(e.name)]
    for entry in candidates:
        try:
            st = entry.stat(follow_symlinks=False)
        except OSError:
            continue
        if (not stat.S_ISREG(st.st_mode) or (uid is not None and st.st_uid != uid)
                or now - st.st_mtime < older_than):
            continue
        if _remove_if_unlocked(entry.path, st):
            removed.append(Path(entry.path))
    return removed


def _remove_if_unlocked(name: str, st: os.stat_result) -> bool:
    try:
        fd = os.open(name, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
                     | getattr(os, "O_NONBLOCK", 0))
    except OSError:
        return False
    try:
        if fcntl is not None:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                return False  # a live writer holds it
        now = os.fstat(fd)
        if (now.st_dev, now.st_ino) != (st.st_dev, st.st_ino):
            return False  # the name changed hands since we looked
        os.unlink(name)
        return True
    except OSError:
        return False
    finally:
        os.close(fd)


def file_digest(path: str | os.PathLike) -> str:
    """sha256 hex digest of a file's bytes; "" when it cannot be read."""
    h = hashlib.sha256()
    try:
        with open(path, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):      # 1 MiB at a time: no whole-file copy
                h.update(block)
    except OSError:
        return ""
    return h.hexdigest()
