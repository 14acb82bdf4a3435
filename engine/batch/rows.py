"""Append-only CSV row files that survive interruption.

A study writes one CSV line per sample as its result arrives. Each line is
formatted in full first and handed to the OS in one ``write`` on a file
opened for appending, then flushed and fsynced, so after a crash or a kill
the file holds complete rows plus, at worst, one partial last line. On
resume the partial line (anything after the last newline) is truncated
away; complete rows are kept and their samples are not run again.

Cells: integers and strings as they are, floats as ``repr`` (shortest text
that reads back to the same double, ``nan`` / ``inf`` included), booleans as
``true`` / ``false``. Newlines in text are replaced by spaces, so a newline
always ends a row.
"""

from __future__ import annotations

import csv
import io
import os
from pathlib import Path

import numpy as np

__all__ = ["RowFile", "read_rows", "format_row", "parse_cell"]


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


def _split_lines(data: bytes, path: Path, columns) -> list:
    rows = []
    reader = csv.reader(io.StringIO(data.decode("utf-8"), newline=""))
    for lineno, fields in enumerate(reader, start=1):
        if lineno == 1:
            if columns is not None and fields != list(columns):
                raise ValueError(
                    f"{str(path)!r} has the columns {fields[:6]}... ({len(fields)} in all); this "
                    f"run writes {list(columns)[:6]}... ({len(columns)}): it belongs to a "
                    f"different kind of study; choose another file or resume=False")
            columns = fields
            continue
        if len(fields) != len(columns):
            raise ValueError(f"{str(path)!r} line {lineno}: {len(fields)} cells, expected "
                             f"{len(columns)}; the file is damaged")
        rows.append(dict(zip(columns, (parse_cell(f) for f in fields))))
    return rows


def read_rows(path: str | os.PathLike, *, columns=None) -> list:
    """Complete rows of a row file as dicts (a trailing partial line is ignored).

    Parameters
    ----------
    path : CSV file written by :class:`RowFile`
    columns : sequence of str, optional; the header must equal it

    Returns
    -------
    list of dict column -> value (see :func:`parse_cell`)
    """
    p = Path(path)
    data = p.read_bytes()
    cut = data.rfind(b"\n") + 1
    return _split_lines(data[:cut], p, columns) if cut else []


class RowFile:
    """An open row file for appending complete rows.

    Parameters
    ----------
    path : str or path, ``*.csv``; the folder is created if needed
    columns : sequence of str, the header
    resume : bool
        True: keep the complete rows already in the file (a partial last line
        is truncated) and expose them as ``existing``. False: start the file
        afresh.
    """

    def __init__(self, path, columns, *, resume: bool = True):
        self.path = Path(path)
        self.columns = list(columns)
        self.existing: list = []
        self.path.parent.mkdir(parents=True, exist_ok=True)
        if resume and self.path.exists():
            self._repair()
        else:
            self._write_new()
        self._fd = os.open(self.path, os.O_WRONLY | os.O_APPEND)

    def _write_new(self) -> None:
        fd = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        try:
            _write_all(fd, format_row(self.columns))
            os.fsync(fd)
        finally:
            os.close(fd)
        _fsync_dir(self.path.parent)

    def _repair(self) -> None:
        data = self.path.read_bytes()
        cut = data.rfind(b"\n") + 1
        if cut < len(data):                     # an interrupted last line
            os.truncate(self.path, cut)
        if cut == 0:                            # nothing complete, not even the header
            self._write_new()
            return
        self.existing = _split_lines(data[:cut], self.path, self.columns)

    def append(self, row: dict) -> None:
        """Write one complete row (missing columns are empty) and fsync it."""
        unknown = set(row) - set(self.columns)
        if unknown:
            raise ValueError(f"row has columns {sorted(unknown)} not in the file header")
        _write_all(self._fd, format_row(row.get(c) for c in self.columns))
        os.fsync(self._fd)

    def close(self) -> None:
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        n = os.write(fd, view)
        view = view[n:]


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
