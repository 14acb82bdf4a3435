"""Which files a study may write, and when it may resume one.

A study file says in its first line that Mesoforge wrote it and which study
it holds::

    # mesoforge-study v1 {"mode": "hints", "tileset": "TL+-", "tileset_digest": ..., "seed": 3, ...}
    set,index,seed,tileset,...,config
    0,0,8126...,TL+-,...

The tag line is in the file rather than in a sidecar so the two can never be
separated: a copied, renamed or overwritten file carries (or loses) its
identity with it, and a stale sidecar can never vouch for a stranger's file.
Readers skip it (``engine.batch.rows``); with pandas use ``skiprows=1``.
The parameters (:func:`study_params`) are the study's mode (``hints`` /
``groups`` / ``sweep``), the tile set (name and a digest of its tiles and
rules), shape, periodic, availability, E, nu, resolution, line_width,
radius, void, tol, seed, and the hint texts (``hints``: one for a study,
one per group) or the sweep's ``min_distance``. The number of samples is
not one of them: rerunning with a larger ``n`` extends a study.

Rules, all checked by reading only, before the first byte is written and
before any sample is grown:

1. The folder of ``out_path`` must exist; ``out_path`` must not be a folder,
   a device or a FIFO.
2. An existing file is used only if it is ours: its first line is a tag line,
   or (a study file written before tag lines existed) exactly the header of a
   study. Anything else (other CSV, text, binary data, an empty file) is
   refused and never opened for writing, whatever ``resume`` says.
3. ``resume=True``: the stored parameters must equal this run's (a hint-group
   study may go on with more groups, whose first ones are the file's); the
   first difference is refused, naming the parameter and both values. Every
   complete row of a sample of this run must be that sample's row (seed, set,
   index and configuration hash). Then a partial last line is cut off and
   rows are appended. An older file without a tag line is resumed only when
   all its rows are samples of this run; it then gets its tag line (the file
   is rewritten whole, as when a group study gains groups).
4. ``resume=False``: a file of ours is replaced, whole, by a fresh one; a file
   that is not ours is refused.
5. Parquet output (``x.parquet`` with its journal ``x.parquet.rows.csv``):
   the Parquet file carries the tag in its schema metadata
   (``mesoforge-study``) and is only replaced when it is ours (that key, or
   the study's columns); resuming needs its journal, without which the rows
   in the Parquet file would be dropped.
"""

from __future__ import annotations

import hashlib
import json
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .hints_text import format_hints
from .rows import RowFile, RowScan, StudyFileError, read_head, regular_file_size, scan_rows

__all__ = ["TAG", "FORMAT_VERSION", "study_params", "tag_text", "read_params",
           "JournalPlan", "plan_journal", "check_out_folder", "check_parquet",
           "parquet_metadata"]

TAG = "mesoforge-study"
FORMAT_VERSION = 1
_TAG_HEAD = f"# {TAG} ".encode()
# the first header cells of every study file (engine.batch.sample.columns)
_STUDY_HEAD = b"set,index,seed,tileset,shape,periodic,availability,hints,"
_MODES = ("hints", "groups", "sweep")


# ------------------------------------------------------------------ parameters

def _tileset_digest(ts) -> str:
    h = hashlib.sha256(json.dumps(list(ts.tile_names)).encode())
    allowed = np.ascontiguousarray(ts.allowed)
    h.update(str(allowed.shape).encode())
    h.update(allowed.tobytes())
    return h.hexdigest()[:16]


def study_params(config, *, mode: str, seed: int, hints=None,
                 min_distance: float | None = None) -> dict:
    """The parameters a study file is tagged with (module docstring).

    Parameters
    ----------
    config : engine.batch.sample.StudyConfig
    mode : "hints" (one hint set), "groups" (given hint groups) or "sweep"
    seed : int, the study seed
    hints : sequence of hint dicts, one per set ("hints", "groups")
    min_distance : float, the sweep's least distance between hint vectors ("sweep")
    """
    if mode not in _MODES:
        raise ValueError(f"mode must be one of {_MODES}; got {mode!r}")
    ts = config.tileset
    p = {"mode": mode, "tileset": ts.name, "tileset_digest": _tileset_digest(ts),
         "shape": "x".join(str(s) for s in config.shape[::-1]), "periodic": config.periodic,
         "availability": config.availability, "E": config.E, "nu": config.nu,
         "resolution": config.resolution, "line_width": config.line_width,
         "radius": config.radius, "void": config.void, "tol": config.tol, "seed": int(seed)}
    if mode == "sweep":
        p["min_distance"] = float(min_distance)
    else:
        p["hints"] = [format_hints(h) for h in hints]
    return json.loads(json.dumps(p))        # as it reads back from a file


def tag_text(params: dict) -> str:
    """The tag line's text (without ``"# "``) for ``params``."""
    return f"{TAG} v{FORMAT_VERSION} {json.dumps(params, separators=(', ', ': '))}"


def _parse_tag(path: Path, text: str) -> dict:
    head, _, rest = text.partition(" ")
    version, _, doc = rest.partition(" ")
    if head != TAG:
        raise StudyFileError(path, f"its first line is not a {TAG} tag; it is left as it is")
    if version != f"v{FORMAT_VERSION}":
        raise StudyFileError(path, f"is a study file of format {version!r}, this version of "
                                   f"Mesoforge reads v{FORMAT_VERSION}; it is left as it is")
    try:
        params = json.loads(doc)
    except ValueError:
        params = None
    if not isinstance(params, dict) or params.get("mode") not in _MODES:
        raise StudyFileError(path, "its tag line is damaged (no study parameters); it is "
                                   "left as it is")
    return params


def read_params(path) -> dict | None:
    """The study parameters in a study file's tag line; None for an older file
    without one. Raises StudyFileError for a file that is not a study file."""
    p = Path(path)
    kind, first = _kind_of(p)
    if kind == "tagged":
        return _parse_tag(p, first[2:].decode("utf-8", "replace"))
    if kind == "legacy":
        return None
    raise StudyFileError(p, _not_ours(first))


def _mismatch(stored: dict, params: dict) -> str | None:
    """The first parameter where a file's study differs from this run's, in words."""
    for key in [*params, *(k for k in stored if k not in params)]:
        old, new = stored.get(key, "(none)"), params.get(key, "(none)")
        if key == "hints" and params.get("mode") == "groups" and stored.get("mode") == "groups" \
                and isinstance(old, list):
            for j, (a, b) in enumerate(zip(old, new)):
                if a != b:
                    return f"the hints of group {j + 1} are {a!r} in the file, {b!r} in this run"
            continue
        if key == "hints" and isinstance(old, list) and isinstance(new, list) \
                and len(old) == len(new) == 1:
            old, new = old[0], new[0]
        if old != new:
            why = " (the tile set's tiles or rules changed)" if key == "tileset_digest" else ""
            return f"{key} is {old!r} in the file, {new!r} in this run{why}"
    return None


def _merged(stored: dict, params: dict) -> dict:
    """Parameters to keep in the file once this run resumes it."""
    if params["mode"] == "groups" and len(params["hints"]) > len(stored["hints"]):
        return params                       # more groups than the file knew of
    return stored


# ------------------------------------------------------------------ files

def check_out_folder(path: Path) -> None:
    """Refuse a path whose folder is missing, or that is itself a folder or no file."""
    parent = path.parent
    if not parent.exists():
        raise StudyFileError(path, f"the folder {str(parent)!r} does not exist")
    if not parent.is_dir():
        raise StudyFileError(path, f"{str(parent)!r} is not a folder")
    if path.is_dir():
        raise StudyFileError(path, "is a folder, not a file")
    if os.path.lexists(path) and not path.exists():
        raise StudyFileError(path, "is a broken symbolic link; it is left as it is")


def _kind_of(path: Path) -> tuple:
    """("tagged" | "legacy" | "foreign", first line bytes) of an existing file."""
    head = read_head(path)
    if head.startswith(_TAG_HEAD) and b"\n" not in head:
        head = read_head(path, regular_file_size(path))     # a long tag line
    first, newline, _ = head.partition(b"\n")
    if newline and first.startswith(_TAG_HEAD):
        return "tagged", first
    if newline and first.startswith(_STUDY_HEAD) and first.endswith(b",config"):
        return "legacy", first
    return "foreign", first


def _not_ours(first: bytes) -> str:
    if not first:
        what = "it is empty"
    else:
        text = first[:60].decode("utf-8", "replace")
        what = f"its first line is {text!r}{'...' if len(first) > 60 else ''}"
    return (f"is not a study file written by Mesoforge ({what}); it is left as it is: choose "
            f"another file")


@dataclass
class JournalPlan:
    """What :func:`plan_journal` decided; :meth:`open` does it.

    scan : RowScan of the existing file (None: there is none, or it is replaced)
    tag : str or None, the tag line the file will carry (None: keep the file's)
    rows : list of dict, complete rows already there that are kept
    """

    path: Path
    columns: list
    scan: RowScan | None
    tag: str | None
    rows: list
    replace: bool = False

    def open(self) -> RowFile:
        """Create, replace or resume the file; the first write of the run."""
        if self.scan is None:
            return RowFile.create(self.path, self.columns, tag=self.tag, replace=self.replace)
        return RowFile.resume(self.scan, tag=self.tag)


def plan_journal(path, columns, params: dict, wanted: dict, *, resume: bool) -> JournalPlan:
    """Decide how to write a study's rows to ``path``, reading only.

    Parameters
    ----------
    path : the CSV row file
    columns : list of str, this run's header
    params : dict, this run's :func:`study_params`
    wanted : dict seed -> (set, index, config) of this run's samples
    resume : bool

    Raises
    ------
    StudyFileError
        For any file this run must not write, or must not resume (module docstring).
    """
    p = Path(path)
    check_out_folder(p)
    tag = tag_text(params)
    if not os.path.lexists(p):
        return JournalPlan(p, list(columns), None, tag, [])
    kind, first = _kind_of(p)
    if kind == "foreign":
        raise StudyFileError(p, _not_ours(first))
    stored = _parse_tag(p, first[2:].decode("utf-8", "replace")) if kind == "tagged" else None
    if not resume:
        return JournalPlan(p, list(columns), None, tag, [], replace=True)
    if stored is not None:
        diff = _mismatch(stored, params)
        if diff:
            raise StudyFileError(p, f"holds another study: {diff}; choose another file, or "
                                    f"resume=False to start it afresh")
    scan = scan_rows(p)
    if scan.columns is None:
        raise StudyFileError(p, "has a tag line but no complete header line: the file is "
                                "damaged; it is left as it is")
    if scan.columns != list(columns):
        raise StudyFileError(p, f"has the columns {scan.columns[:6]}... ({len(scan.columns)} "
                                f"in all); this run writes {list(columns)[:6]}... "
                                f"({len(columns)}): it belongs to a different kind of study")
    _check_rows(scan, wanted, legacy=stored is None, first_line=2 if stored is None else 3)
    if stored is None:
        keep = tag                           # an older file gets its tag line
    else:
        merged = _merged(stored, params)
        keep = None if merged is stored else tag_text(merged)
    return JournalPlan(p, list(columns), scan, keep, scan.rows)


def _check_rows(scan: RowScan, wanted: dict, *, legacy: bool, first_line: int) -> None:
    for n, r in enumerate(scan.rows):
        seed = r.get("seed")
        want = wanted.get(seed)
        where = f"line {n + first_line} (sample seed {seed})"
        if want is None:
            if legacy:
                raise StudyFileError(
                    scan.path, f"has no {TAG} tag line (an older study file) and its {where} "
                               f"is not a sample of this run, so the two studies cannot be "
                               f"told apart; choose another file, or resume=False to start "
                               f"it afresh")
            continue
        got = (r.get("set"), r.get("index"), r.get("config"))
        if got != want:
            raise StudyFileError(
                scan.path, f"{where} is not this run's sample of that seed: set, index, config "
                           f"are {got} in the file, {want} in this run; choose another file, "
                           f"or resume=False to start it afresh")


# ------------------------------------------------------------------ parquet

def parquet_metadata(params: dict) -> dict:
    """Schema metadata that marks a Parquet file as this study's."""
    return {TAG.encode(): tag_text(params).encode("utf-8")}


def check_parquet(path, columns, params: dict, *, resume: bool, journal_exists: bool) -> None:
    """Refuse a Parquet output that is not ours, or that resuming would lose rows of."""
    p = Path(path)
    check_out_folder(p)
    if not os.path.lexists(p):
        return
    read_head(p, 0)                          # a regular file?
    try:
        import pyarrow.parquet as pq
        schema = pq.read_schema(p)
    except Exception:                        # pyarrow's errors for a file it cannot read
        raise StudyFileError(p, "is not a Parquet file written by Mesoforge; it is left as "
                                "it is: choose another file") from None
    text = (schema.metadata or {}).get(TAG.encode())
    if text is None and list(schema.names) != list(columns):
        raise StudyFileError(p, "is a Parquet file but not a study written by Mesoforge; it "
                                "is left as it is: choose another file")
    if not resume:
        return
    if not journal_exists:
        raise StudyFileError(p, f"exists without its row journal {p.name + '.rows.csv'!r}: "
                                f"resuming would drop its rows; restore the journal, or "
                                f"resume=False to start afresh")
    if text is not None:
        diff = _mismatch(_parse_tag(p, text.decode("utf-8", "replace")), params)
        if diff:
            raise StudyFileError(p, f"holds another study: {diff}; choose another file, or "
                                    f"resume=False to start it afresh")
