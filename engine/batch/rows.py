"""Append-only CSV row files that survive interruption.

A study writes one CSV line per sample as its result arrives. Each line is
formatted in full first and handed to the OS in one ``write`` on a file
opened for appending, then flushed and fsynced, so after a crash or a kill
the file holds complete rows plus, at worst, one partial last line. On
resume the partial line (anything after the last newline) is truncated
away; complete rows are kept and their samples are not run again.

Layout: an optional *tag line* (the first line, ``# `` then text saying who
wrote the file and what it holds; ``engine.batch.study_file``), the header
line (column names), then one line per row. A file is created whole: tag and
header go to a temporary sibling that is fsynced and then linked into place,
so a row file never exists with half a header.

Nothing here changes a file it has not read and understood: :func:`scan_rows`
only reads, and :meth:`RowFile.resume` takes a scan, so a file that does not
parse is refused before a byte of it is touched. Whether a file may be
written at all (is it ours?) is decided by the caller.

Cells: integers and strings as they are, floats as ``repr`` (shortest text
that reads back to the same double, ``nan`` / ``inf`` included), booleans as
``true`` / ``false``. Newlines in text are replaced by spaces, so a newline
always ends a row.
"""

from __future__ import annotations

import csv
import io
import os
import stat
import uuid
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["RowFile", "RowScan", "StudyFileError", "scan_rows", "read_rows", "format_row",
           "parse_cell"]

TAG_MARK = b"# "


class StudyFileError(ValueError):
    """A study (row) file that cannot be used as asked; the file is left as it was.

    Attributes
    ----------
    path : str, the file
    reason : str, what is wrong and what to do
    param : str or None, the argument that named the file (``"out_path"``)
    """

    def __init__(self, path, reason: str, *, param: str | None = None):
        self.path = str(path)
        self.reason = reason
        self.param = param
        head = f"{param} {self.path!r}" if param else repr(self.path)
        super().__init__(f"{head}: {reason}")

    def named(self, param: str) -> "StudyFileError":
        """The same error, its message naming the argument ``param``."""
        return StudyFileError(self.path, self.reason, param=param)

    def __reduce__(self):
        return _rebuild_error, (self.path, self.reason, self.param)


def _rebuild_error(path, reason, param):
    return StudyFileError(path, reason, param=param)


# ------------------------------------------------------------------ cells

def _cell(value) -> str:
    if value is None:
        return ""
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    return str(value).replace("\r", " ").replace("\n", " ")


def format_row(values) -> bytes:
    """One CSV line (with its newline) for a sequence of cell values."""
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerow([_cell(v) for v in values])
    return buf.getvalue().encode("utf-8")


def parse_cell(text: str):
    """Read a cell back: int, float, bool, None (empty) or the string itself."""
    if text == "":
        return None
    if text in ("true", "false"):
        return text == "true"
    try:
        return int(text)
    except ValueError:
        pass
    try:
        return float(text)
    except ValueError:
        return text


# ------------------------------------------------------------------ reading

def regular_file_size(path: Path) -> int:
    """Size of ``path`` in bytes; StudyFileError unless it is a regular file
    (a folder, a device or a FIFO is never opened: reading one could block)."""
    try:
        st = os.stat(path)
    except OSError as exc:
        raise StudyFileError(path, f"cannot be read: {exc.strerror}") from None
    if stat.S_ISDIR(st.st_mode):
        raise StudyFileError(path, "is a folder, not a file")
    if not stat.S_ISREG(st.st_mode):
        raise StudyFileError(path, "is not a regular file (a device, FIFO or socket)")
    return st.st_size


def read_head(path: Path, limit: int = 65536) -> bytes:
    """The first ``limit`` bytes of a regular file (read only)."""
    regular_file_size(path)
    try:
        with open(path, "rb") as fh:
            return fh.read(limit)
    except OSError as exc:
        raise StudyFileError(path, f"cannot be read: {exc.strerror}") from None


@dataclass(frozen=True)
class RowScan:
    """What a row file holds, read without changing it.

    tag : str or None, the tag line's text (after ``"# "``, without the newline)
    columns : list of str or None (no complete header line)
    rows : list of dict column -> value, the complete rows
    body : int, byte offset of the header line (0 without a tag line)
    complete : int, bytes in complete lines: where the next row goes
    size : int, bytes in the file (``> complete`` after an interrupted write)
    """

    path: Path
    tag: str | None
    columns: list | None
    rows: list
    body: int
    complete: int
    size: int


def _decode(data: bytes, path: Path) -> str:
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise StudyFileError(path, f"line {line} is not UTF-8 text") from None


def scan_rows(path: str | os.PathLike, *, columns=None) -> RowScan:
    """Read a row file (tag line, header, complete rows) without changing it.

    Parameters
    ----------
    path : a file written by :class:`RowFile`
    columns : sequence of str, optional; the header must equal it

    Raises
    ------
    StudyFileError
        The file is not a regular file, not UTF-8 text, not CSV, has other
        columns, or a complete line with the wrong number of cells.
    """
    p = Path(path)
    regular_file_size(p)
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise StudyFileError(p, f"cannot be read: {exc.strerror}") from None
    cut = data.rfind(b"\n") + 1
    tag, body = None, 0
    if data.startswith(TAG_MARK) and cut:
        body = data.index(b"\n") + 1
        tag = _decode(data[len(TAG_MARK):body - 1], p)
    fields = _parse_lines(_decode(data[body:cut], p), p, first_line=2 if tag is not None else 1)
    if not fields:
        return RowScan(p, tag, None, [], body, cut, len(data))
    header, lines = fields[0][1], fields[1:]
    if columns is not None and header != list(columns):
        raise StudyFileError(
            p, f"has the columns {header[:6]}... ({len(header)} in all); this run writes "
               f"{list(columns)[:6]}... ({len(columns)}): it belongs to a different kind of study")
    rows = []
    for lineno, cells in lines:
        if len(cells) != len(header):
            raise StudyFileError(p, f"line {lineno}: {len(cells)} cells, expected "
                                    f"{len(header)}; the file is damaged")
        rows.append(dict(zip(header, (parse_cell(c) for c in cells))))
    return RowScan(p, tag, header, rows, body, cut, len(data))


def _parse_lines(text: str, path: Path, *, first_line: int) -> list:
    """[(line number, cells)] of CSV text made of complete lines."""
    out = []
    reader = csv.reader(io.StringIO(text, newline=""), strict=True)
    try:
        start = 1
        for cells in reader:
            out.append((start + first_line - 1, cells))
            start = reader.line_num + 1
    except csv.Error as exc:
        raise StudyFileError(path, f"line {reader.line_num + first_line - 1} is not CSV: "
                                   f"{exc}") from None
    return out


def read_rows(path: str | os.PathLike, *, columns=None) -> list:
    """Complete rows of a row file as dicts (the tag line and a trailing partial line
    are skipped; see :func:`scan_rows`).

    Returns
    -------
    list of dict column -> value (see :func:`parse_cell`)
    """
    return scan_rows(path, columns=columns).rows


# ------------------------------------------------------------------ writing

def _tag_line(tag: str | None) -> bytes:
    if tag is None:
        return b""
    if "\n" in tag or "\r" in tag:
        raise ValueError(f"a tag is one line of text; got {tag!r}")
    return TAG_MARK + tag.encode("utf-8") + b"\n"


def _file_bytes(columns, tag: str | None) -> bytes:
    return _tag_line(tag) + format_row(columns)


def _write_sibling(path: Path, data: bytes, mode: int | None) -> Path:
    """``data`` in a new fsynced temporary file next to ``path``; its name."""
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex[:8]}.tmp")
    try:
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
    except OSError as exc:
        raise StudyFileError(path, f"cannot create files in the folder {str(path.parent)!r}: "
                                   f"{exc.strerror}") from None
    try:
        try:
            _write_all(fd, data)
            if mode is not None:
                os.fchmod(fd, mode)
            os.fsync(fd)
        finally:
            os.close(fd)
    except BaseException as exc:
        _unlink_quietly(tmp)
        if isinstance(exc, OSError):
            raise StudyFileError(path, f"cannot write in the folder {str(path.parent)!r}: "
                                       f"{exc.strerror}") from None
        raise
    return tmp


def _put_in_place(tmp: Path, path: Path, *, replace: bool) -> None:
    """Move the finished ``tmp`` to ``path``; without ``replace`` never over a file."""
    try:
        if replace:
            os.replace(tmp, path)
            return
        try:
            os.link(tmp, path)           # fails if path exists: nothing is clobbered
        except FileExistsError:
            raise StudyFileError(path, "appeared while this run was starting; it is left "
                                       "as it is") from None
        except OSError:                  # a file system without hard links
            if os.path.lexists(path):
                raise StudyFileError(path, "appeared while this run was starting; it is "
                                           "left as it is") from None
            os.replace(tmp, path)
            return
        _unlink_quietly(tmp)
    except BaseException:
        _unlink_quietly(tmp)
        raise
    finally:
        _fsync_dir(path.parent)


class RowFile:
    """An open row file for appending complete rows.

    ``RowFile(path, columns, resume=True, tag=None)`` is :meth:`open`; a file
    is also made by :meth:`create` (a new file) or :meth:`resume` (a scanned
    file). ``existing`` holds the complete rows that were there; ``created``
    says whether this object made the file.
    """

    def __init__(self, path, columns, *, resume: bool = True, tag: str | None = None):
        p = Path(path)
        if resume and os.path.lexists(p):
            made = self.resume(scan_rows(p, columns=columns), tag=tag)
        else:
            made = self.create(p, columns, tag=tag, replace=os.path.lexists(p))
        self.__dict__.update(made.__dict__)

    @classmethod
    def _of(cls, path: Path, columns, fd: int, *, existing=(), created=False) -> "RowFile":
        self = cls.__new__(cls)
        self.path = Path(path)
        self.columns = list(columns)
        self.existing = list(existing)
        self.created = created
        self.n_appended = 0
        self._fd = fd
        self._ino = os.fstat(fd).st_ino
        return self

    @classmethod
    def create(cls, path, columns, *, tag: str | None = None, replace: bool = False,
               mode: int | None = None) -> "RowFile":
        """A new file holding the tag line and the header, put in place whole.

        ``replace`` False refuses to put it over an existing file; True replaces
        one (its permission bits are kept unless ``mode`` is given). The folder
        must exist.
        """
        p = Path(path)
        if replace and mode is None and os.path.exists(p):
            mode = stat.S_IMODE(os.stat(p).st_mode)
        tmp = _write_sibling(p, _file_bytes(columns, tag), mode)
        _put_in_place(tmp, p, replace=replace)
        return cls._of(p, columns, _open_append(p), created=not replace)

    @classmethod
    def resume(cls, scan: RowScan, *, tag: str | None = None) -> "RowFile":
        """Append to a scanned file: a partial last line is cut off; with a ``tag``
        other than the file's, the file is rewritten whole with that tag line."""
        p = scan.path
        if scan.columns is None:
            raise StudyFileError(p, "has no complete header line, so it is not a row file; "
                                    "it is left as it is")
        os.close(_open_append(p))       # writable? (nothing changes yet)
        if tag is not None and tag != scan.tag:
            data = p.read_bytes()
            if len(data) != scan.size:
                raise StudyFileError(p, "changed while this run was reading it; it is left "
                                        "as it is")
            tmp = _write_sibling(p, _tag_line(tag) + data[scan.body:scan.complete],
                                 stat.S_IMODE(os.stat(p).st_mode))
            _put_in_place(tmp, p, replace=True)
            return cls._of(p, scan.columns, _open_append(p), existing=scan.rows)
        fd = _open_append(p)
        try:
            if os.fstat(fd).st_size != scan.size:
                raise StudyFileError(p, "changed while this run was reading it; it is left "
                                        "as it is")
            if scan.complete < scan.size:     # an interrupted last line
                os.ftruncate(fd, scan.complete)
                os.fsync(fd)
        except BaseException:
            os.close(fd)
            raise
        return cls._of(p, scan.columns, fd, existing=scan.rows)

    @classmethod
    def open(cls, path, columns, *, resume: bool = True, tag: str | None = None) -> "RowFile":
        """Resume ``path`` if it exists and ``resume`` (its header must be
        ``columns``; nothing is changed when it is not), else start it afresh
        (replacing a file there: the caller decides whether it may)."""
        return cls(path, columns, resume=resume, tag=tag)

    def append(self, row: dict) -> None:
        """Write one complete row (missing columns are empty) and fsync it."""
        unknown = set(row) - set(self.columns)
        if unknown:
            raise ValueError(f"row has columns {sorted(unknown)} not in the file header")
        _write_all(self._fd, format_row(row.get(c) for c in self.columns))
        os.fsync(self._fd)
        self.n_appended += 1

    def close(self) -> None:
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def discard_if_unused(self) -> None:
        """Close; remove the file if this object created it and wrote no row
        (a run that failed before its first row leaves nothing behind)."""
        self.close()
        if not self.created or self.n_appended:
            return
        try:
            if os.stat(self.path).st_ino == self._ino:
                os.unlink(self.path)
        except OSError:
            pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def _open_append(path: Path) -> int:
    try:
        return os.open(path, os.O_WRONLY | os.O_APPEND)
    except OSError as exc:
        raise StudyFileError(path, f"cannot be written: {exc.strerror}") from None


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        n = os.write(fd, view)
        view = view[n:]


def _unlink_quietly(path: Path) -> None:
    try:
        os.unlink(path)
    except OSError:
        pass


def _fsync_dir(folder: Path) -> None:
    try:
        dfd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(dfd)
    except OSError:
        pass
    finally:
        os.close(dfd)
