"""Editing tile-set documents: blocks, weights, rules, saving, adjacency reasons.

A tile-set *document* is the decoded JSON object (schema in
``resources/tilesets/README.md``). Every edit here takes a document and
returns a new one without touching its input, and refuses, with a message
naming the block or rule, an edit whose result ``parse_tileset`` rejects.
`TileSetDraft` holds a document with a linear undo history for an editor;
`explain_adjacency` tells why two tiles may or may not be neighbours
(connector labels, or which rule decided). Saving writes to the user's tile
set folder and never into the shipped ``resources/tilesets``.
"""

from __future__ import annotations

import copy
import json
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Mapping

import numpy as np

from engine.fileio import write_atomic

from ._symmetry import face_centres, face_names, face_normals, opposite
from .tileset import TILESET_DIR, TileSet, list_tilesets, parse_tileset

__all__ = [
    "TileSetEditError", "validate", "connectors_from_geometry", "parse_point",
    "parse_polylines", "format_polylines", "add_block", "remove_block",
    "rename_block", "set_weight", "set_name", "add_rule", "remove_rule", "move_rule",
    "rules_referencing", "describe_rule", "PairVerdict", "deciding_rules", "explain_adjacency",
    "block_adjacency", "USER_DIR_ENV", "user_tileset_dir", "is_shipped", "TileSetEntry",
    "browse_tilesets", "read_document", "tileset_json", "save_path_for", "save_tileset",
    "TileSetDraft",
]

USER_DIR_ENV = "MESOFORGE_TILESET_DIR"
RULE_KINDS = ("forbid", "allow")
_TOUCH_TOL = 1e-6   # unit-cell coordinates: how close a vertex must be to a face


class TileSetEditError(ValueError):
    """An edit, a save or a file was refused; the message names what and why."""


def validate(data: Mapping, *, source: str | None = None) -> TileSet:
    """Parse the document, raising `TileSetEditError` with parse_tileset's message."""
    try:
        return parse_tileset(data, source=source)
    except ValueError as exc:
        raise TileSetEditError(str(exc)) from None


def _checked(data: dict, action: str) -> dict:
    try:
        parse_tileset(data)
    except ValueError as exc:
        raise TileSetEditError(f"{action}: {exc}") from None
    return data


def _dim(data: Mapping, action: str) -> int:
    ndim = data.get("dim")
    if ndim not in (2, 3) or isinstance(ndim, bool):
        raise TileSetEditError(f"{action}: the tile set's 'dim' must be 2 or 3; got {ndim!r}")
    return ndim


def _block_list(data: Mapping) -> list:
    blocks = data.get("blocks")
    return blocks if isinstance(blocks, list) else []


def _names(data: Mapping) -> list:
    return [b.get("name") for b in _block_list(data) if isinstance(b, dict)]


def _find_block(data: Mapping, name: str, action: str) -> int:
    for i, spec in enumerate(_block_list(data)):
        if isinstance(spec, dict) and spec.get("name") == name:
            return i
    raise TileSetEditError(f"{action}: there is no block {name!r}; blocks are {_names(data)}")


def _check_block_name(data: Mapping, name, action: str) -> None:
    if not isinstance(name, str) or not name.strip() or "@" in name or name != name.strip():
        raise TileSetEditError(f"{action}: a block name must be a non-empty string without '@' "
                               f"or surrounding spaces; got {name!r}")
    if name in _names(data):
        raise TileSetEditError(f"{action}: there is already a block named {name!r}")


# ------------------------------------------------------------------ blocks

def connectors_from_geometry(ndim: int, *, arms=(), junction=None, polylines=(),
                             skip=(), off_centre: str | None = None) -> dict:
    """Connector labels the way the format derives them from arms.

    ``"1"`` on a face whose centre the geometry reaches, ``"0"`` on a face it
    does not touch. Geometry touching a face anywhere else has no derived
    label: that is refused unless the face is in ``skip`` (its label given)
    or ``off_centre`` is given (then that face gets that label, for previews).

    Parameters
    ----------
    ndim : 2 or 3
    arms : face names, members from ``junction`` to those face centres
    junction : (ndim,) float, unit-cell coordinates; default the centre
    polylines : list of (m, ndim) float, unit-cell coordinates
    skip : face names whose labels the caller supplies

    Returns
    -------
    dict, face name -> "0" or "1" for every face not in ``skip``
    """
    faces = face_names(ndim)
    centres, normals = face_centres(ndim), face_normals(ndim)
    j = np.full(ndim, 0.5) if junction is None else np.asarray(junction, dtype=np.float64)
    members = [np.array([j, centres[faces.index(f)]]) for f in arms if f in faces]
    members += [np.asarray(p, dtype=np.float64).reshape(-1, ndim) for p in polylines]
    out = {f: "0" for f in faces if f not in skip}
    for d, f in enumerate(faces):
        if f in skip:
            continue
        axis = int(np.flatnonzero(normals[d])[0])
        plane = 1.0 if normals[d, axis] > 0 else 0.0
        for pts in members:
            for p in pts[np.abs(pts[:, axis] - plane) <= _TOUCH_TOL]:
                if np.allclose(p, centres[d], atol=_TOUCH_TOL):
                    out[f] = "1" if out[f] != off_centre else out[f]
                elif off_centre is not None:
                    out[f] = off_centre
                else:
                    raise TileSetEditError(
                        f"the geometry touches face {f} at {np.round(p, 6).tolist()}, not at its "
                        f"centre {centres[d].tolist()}; give the connector label of {f} explicitly")
    return out


def add_block(data: Mapping, name: str, *, arms=(), junction=None, polylines=(),
              connectors: Mapping | None = None, weight: float = 1.0, symmetry: str = "full",
              description: str = "") -> dict:
    """A copy of the document with one more block.

    Parameters
    ----------
    name : str, unique, without ``"@"``
    arms : face names; members from ``junction`` to the face centres
    junction : (ndim,) float, unit-cell coordinates, optional
    polylines : list of (m, ndim) float, unit-cell coordinates in [0, 1]
    connectors : mapping face -> label, optional, may be partial
        Faces left out are derived: ``"1"`` where the geometry reaches the
        face centre, ``"0"`` where it does not touch the face. A block with
        only arms and no connectors keeps the format's own derivation.
    weight : float >= 0, the block's default hint
    symmetry : "full", "rotations" or "none"
    """
    action = f"add block {name!r}"
    ndim = _dim(data, action)
    _check_block_name(data, name, action)
    faces = face_names(ndim)
    given = dict(connectors or {})
    unknown = [f for f in given if f not in faces]
    if unknown:
        raise TileSetEditError(f"{action}: unknown faces {unknown} in connectors; "
                               f"expected some of {list(faces)}")
    spec: dict = {"name": name}
    if weight != 1.0:
        spec["weight"] = weight
    if symmetry != "full":
        spec["symmetry"] = symmetry
    if arms:
        spec["arms"] = list(arms)
    if junction is not None:
        spec["junction"] = [float(v) for v in junction]
    if polylines:
        spec["polylines"] = [[[float(v) for v in p] for p in poly] for poly in polylines]
    if polylines or given:
        try:
            derived = connectors_from_geometry(ndim, arms=arms, junction=junction,
                                               polylines=polylines, skip=given)
        except (TileSetEditError, ValueError) as exc:
            raise TileSetEditError(f"{action}: {exc}") from None
        spec["connectors"] = {f: given[f] if f in given else derived[f] for f in faces}
    if description:
        spec["description"] = description
    new = copy.deepcopy(dict(data))
    new["blocks"] = _block_list(new) + [spec]
    return _checked(new, action)


def _operand_block(ref) -> str | None:
    return ref.partition("@")[0] if isinstance(ref, str) else None


def _rule_pair(rule) -> tuple[str | None, list]:
    if not isinstance(rule, dict):
        return None, []
    for kind in RULE_KINDS:
        pair = rule.get(kind)
        if isinstance(pair, list):
            return kind, pair
    return None, []


def rules_referencing(data: Mapping, block: str) -> list:
    """Indices of the rules naming ``block`` or one of its tiles."""
    return [k for k, rule in enumerate(data.get("rules", []) or [])
            if any(_operand_block(ref) == block for ref in _rule_pair(rule)[1])]


def remove_block(data: Mapping, name: str, *, drop_rules: bool = False) -> dict:
    """A copy without block ``name``.

    Rules naming the block are refused unless ``drop_rules``, which removes
    them too.
    """
    action = f"remove block {name!r}"
    i = _find_block(data, name, action)
    if len(_block_list(data)) == 1:
        raise TileSetEditError(f"{action}: it is the only block; a tile set needs at least one")
    refs = rules_referencing(data, name)
    if refs and not drop_rules:
        listed = "; ".join(f"rule {k + 1} ({describe_rule(data['rules'][k])})" for k in refs)
        verb = "refers" if len(refs) == 1 else "refer"
        raise TileSetEditError(f"{action}: {listed} {verb} to it; remove or edit "
                               f"{'it' if len(refs) == 1 else 'them'} first")
    new = copy.deepcopy(dict(data))
    del new["blocks"][i]
    if refs:
        new["rules"] = [r for k, r in enumerate(new["rules"]) if k not in refs]
    return _checked(new, action)


def rename_block(data: Mapping, old: str, new_name: str) -> dict:
    """A copy with block ``old`` called ``new_name``; rule operands follow
    (``"old"`` -> ``"new"``, ``"old@k"`` -> ``"new@k"``)."""
    action = f"rename block {old!r} to {new_name!r}"
    i = _find_block(data, old, action)
    if new_name == old:
        return copy.deepcopy(dict(data))
    _check_block_name(data, new_name, action)
    new = copy.deepcopy(dict(data))
    new["blocks"][i]["name"] = new_name
    for rule in new.get("rules", []) or []:
        kind, pair = _rule_pair(rule)
        if kind is not None:
            rule[kind] = [new_name + ref[len(old):] if _operand_block(ref) == old else ref
                          for ref in pair]
    return _checked(new, action)


def set_weight(data: Mapping, name: str, weight: float) -> dict:
    """A copy with block ``name``'s default hint set to ``weight`` (>= 0)."""
    action = f"set the weight of block {name!r} to {weight!r}"
    i = _find_block(data, name, action)
    new = copy.deepcopy(dict(data))
    new["blocks"][i]["weight"] = weight
    return _checked(new, action)


def set_name(data: Mapping, name: str) -> dict:
    """A copy with the tile set called ``name``."""
    action = f"rename the tile set to {name!r}"
    if not isinstance(name, str) or not name.strip():
        raise TileSetEditError(f"{action}: a tile set name must be a non-empty string")
    new = copy.deepcopy(dict(data))
    new["name"] = name
    return _checked(new, action)


def parse_point(text: str, ndim: int, what: str = "point") -> list:
    """``"0.5 0.25"`` or ``"0.5, 0.25"`` -> ``[0.5, 0.25]`` (ndim numbers)."""
    parts = text.replace(",", " ").split()
    try:
        point = [float(v) for v in parts]
    except ValueError:
        point = []
    if len(point) != ndim:
        raise TileSetEditError(f"{what}: {text.strip()!r} is not {ndim} numbers")
    return point


def parse_polylines(text: str, ndim: int) -> list:
    """Polylines typed one per line, points separated by ``;``.

    ``"0.5 0.5; 1 0.5"`` is one member from the centre to the +x edge
    midpoint. Blank lines are skipped. Returns a list of lists of points.
    """
    out = []
    for n, line in enumerate(text.splitlines(), 1):
        if not line.strip():
            continue
        poly = [parse_point(part, ndim, f"polyline on line {n}")
                for part in line.split(";") if part.strip()]
        if len(poly) < 2:
            raise TileSetEditError(f"polyline on line {n} needs at least 2 points; got {len(poly)}")
        out.append(poly)
    return out


def format_polylines(polylines) -> str:
    """The inverse of `parse_polylines`: one line per polyline."""
    return "\n".join("; ".join(" ".join(f"{float(v):g}" for v in p) for p in poly)
                     for poly in polylines)


# ------------------------------------------------------------------ rules

def describe_rule(rule) -> str:
    """``"forbid L next to L (any face)"`` or ``"forbid -@1 across +x of T@0"``."""
    kind, pair = _rule_pair(rule)
    if kind is None or len(pair) != 2:
        return repr(rule)
    a, b = pair
    face = rule.get("face")
    return f"{kind} {b} across {face} of {a}" if face else f"{kind} {a} next to {b} (any face)"


def add_rule(data: Mapping, kind: str, a: str, b: str, *, face: str | None = None,
             description: str = "", index: int | None = None) -> dict:
    """A copy with the rule ``{kind: [a, b], "face": face}`` inserted at
    ``index`` (default: last, so it overrides the earlier ones)."""
    rule: dict = {kind: [a, b]}
    if face:
        rule["face"] = face
    if description:
        rule["description"] = description
    action = f"add rule {describe_rule(rule)!r}"
    if kind not in RULE_KINDS:
        raise TileSetEditError(f"{action}: the kind must be one of {list(RULE_KINDS)}; got {kind!r}")
    new = copy.deepcopy(dict(data))
    rules = list(new.get("rules", []) or [])
    rules.insert(len(rules) if index is None else index, rule)
    new["rules"] = rules
    return _checked(new, action)


def _rule_index(data: Mapping, index: int, action: str) -> list:
    rules = list(data.get("rules", []) or [])
    if isinstance(index, bool) or not isinstance(index, int) or not 0 <= index < len(rules):
        raise TileSetEditError(f"{action}: rule index must be in [0, {len(rules) - 1}]; "
                               f"got {index!r}")
    return rules


def remove_rule(data: Mapping, index: int) -> dict:
    """A copy without rule ``index`` (0-based, file order)."""
    action = f"remove rule {index!r}"
    _rule_index(data, index, action)
    new = copy.deepcopy(dict(data))
    del new["rules"][index]
    return _checked(new, action)


def move_rule(data: Mapping, index: int, to: int) -> dict:
    """A copy with rule ``index`` moved to position ``to`` (later rules win)."""
    action = f"move rule {index!r} to {to!r}"
    _rule_index(data, index, action)
    _rule_index(data, to, action)
    new = copy.deepcopy(dict(data))
    rule = new["rules"].pop(index)
    new["rules"].insert(to, rule)
    return _checked(new, action)


# ------------------------------------------------------------------ adjacency

@dataclass(frozen=True)
class PairVerdict:
    """Whether tile ``b`` may sit across face ``face`` of tile ``a``, and why.

    Attributes
    ----------
    a, b : str, tile names
    face : str, a face of ``a``
    allowed : bool, as in ``TileSet.allowed``
    labels : (str, str), ``a``'s label on ``face`` and ``b``'s on the opposite face
    rule : int or None, index (file order) of the rule that decided; None
        when the connector labels decided
    reason : str, one sentence for people
    """

    a: str
    b: str
    face: str
    allowed: bool
    labels: tuple
    rule: int | None
    reason: str

    @property
    def connectors_match(self) -> bool:
        return self.labels[0] == self.labels[1]


def _operand_tiles(ts: TileSet, ref: str) -> np.ndarray:
    if ref in ts.block_names:
        return ts.tiles_of(ref)
    return np.array([ts.tile_index(ref)])


def deciding_rules(ts: TileSet) -> np.ndarray:
    """(2*ndim, n_tiles, n_tiles) int32: index of the last rule covering each
    ``(face, a, b)``, -1 where no rule applies and the connectors decide."""
    out = np.full(ts.allowed.shape, -1, dtype=np.int32)
    for k, rule in enumerate(ts.rules):
        kind, (x, y) = _rule_pair(rule)
        a_idx, b_idx = _operand_tiles(ts, x), _operand_tiles(ts, y)
        face = rule.get("face")
        for d in (range(2 * ts.ndim) if face is None else [ts.faces.index(face)]):
            out[d][np.ix_(a_idx, b_idx)] = k
            out[opposite(d, ts.ndim)][np.ix_(b_idx, a_idx)] = k
    return out


def _verdict(ts: TileSet, deciders: np.ndarray, d: int, a: int, b: int) -> PairVerdict:
    ta, tb = ts.tiles[a], ts.tiles[b]
    face, back = ts.faces[d], ts.faces[opposite(d, ts.ndim)]
    labels = (ta.connectors[d], tb.connectors[opposite(d, ts.ndim)])
    allowed = bool(ts.allowed[d, a, b])
    k = int(deciders[d, a, b])
    match = labels[0] == labels[1]
    conn = (f"connectors {'match' if match else 'differ'}: {labels[0]!r} on {face} of {ta.name}, "
            f"{labels[1]!r} on {back} of {tb.name}")
    if k < 0:
        reason = f"{'allowed' if allowed else 'forbidden'}: {conn}"
    else:
        reason = (f"{'allowed' if allowed else 'forbidden'} by rule {k + 1} "
                  f"({describe_rule(ts.rules[k])}); {conn}")
    return PairVerdict(ta.name, tb.name, face, allowed, labels, None if k < 0 else k, reason)


def explain_adjacency(ts: TileSet, a: str, b: str, face: str) -> list:
    """Verdicts for every tile of ``a`` against every tile of ``b`` across ``face``.

    Parameters
    ----------
    ts : TileSet
    a, b : str, block names (all their orientations) or tile names ``"B@k"``
    face : str, one of ``ts.faces``, a face of ``a``

    Returns
    -------
    list of PairVerdict, ``a``'s tiles outer, ``b``'s inner
    """
    if face not in ts.faces:
        raise TileSetEditError(f"face must be one of {list(ts.faces)}; got {face!r}")
    try:
        a_idx, b_idx = _operand_tiles(ts, a), _operand_tiles(ts, b)
    except ValueError as exc:
        raise TileSetEditError(str(exc)) from None
    deciders, d = deciding_rules(ts), ts.faces.index(face)
    return [_verdict(ts, deciders, d, int(i), int(j)) for i in a_idx for j in b_idx]


def block_adjacency(ts: TileSet, face: str) -> tuple:
    """Allowed orientation pairs per block pair across ``face``.

    Returns
    -------
    allowed : (n_blocks, n_blocks) int64, pairs (tile of block a, tile of
        block b) with b allowed across ``face`` of a
    total : (n_blocks, n_blocks) int64, orientation pairs of the two blocks
    """
    if face not in ts.faces:
        raise TileSetEditError(f"face must be one of {list(ts.faces)}; got {face!r}")
    onehot = (ts.tile_block[:, None] == np.arange(ts.n_blocks)[None, :]).astype(np.int64)
    allowed = onehot.T @ ts.allowed[ts.faces.index(face)].astype(np.int64) @ onehot
    n = ts.n_orientations.astype(np.int64)
    return allowed, np.outer(n, n)


# ------------------------------------------------------------------ files

def user_tileset_dir() -> Path:
    """The user's tile-set folder: ``$MESOFORGE_TILESET_DIR`` or
    ``~/.local/share/mesoforge/tilesets``."""
    env = os.environ.get(USER_DIR_ENV, "").strip()
    return Path(env).expanduser() if env else Path.home() / ".local/share/mesoforge/tilesets"


def is_shipped(path: str | os.PathLike) -> bool:
    """True for files inside the shipped ``resources/tilesets`` folder."""
    return Path(path).expanduser().resolve().is_relative_to(TILESET_DIR.resolve())


@dataclass(frozen=True)
class TileSetEntry:
    """One tile-set file found by `browse_tilesets`; ``error`` if unreadable."""

    name: str
    path: Path
    shipped: bool
    dim: int | None = None
    n_blocks: int = 0
    error: str = ""


def read_document(path: str | os.PathLike) -> dict:
    """The decoded JSON object of a tile-set file (not validated)."""
    p = Path(path)
    try:
        data = json.loads(p.read_text(encoding="utf-8"))
    except OSError as exc:
        raise TileSetEditError(f"tile set file {str(p)!r} cannot be read: {exc.strerror}") from None
    except ValueError as exc:
        raise TileSetEditError(f"tile set file {str(p)!r} is not valid JSON: {exc}") from None
    if not isinstance(data, dict):
        raise TileSetEditError(f"tile set file {str(p)!r} must hold a JSON object; "
                               f"got {type(data).__name__}")
    return data


def _entries(folder: Path, shipped: bool) -> list:
    out = []
    for p in sorted(folder.glob("*.json")) if folder.is_dir() else []:
        try:
            data = read_document(p)
            ts = validate(data, source=str(p))
            out.append(TileSetEntry(ts.name, p, shipped, ts.ndim, ts.n_blocks))
        except TileSetEditError as exc:
            out.append(TileSetEntry(p.stem, p, shipped, error=str(exc)))
    return sorted(out, key=lambda e: (e.name.lower(), str(e.path)))


def browse_tilesets(user_folder: str | os.PathLike | None = None) -> list:
    """Shipped sets, then the user's, each sorted by name: `TileSetEntry` list."""
    user = Path(user_folder) if user_folder is not None else user_tileset_dir()
    return _entries(TILESET_DIR, True) + _entries(user, False)


def tileset_json(data: Mapping) -> str:
    """The document as JSON text, one block and one rule per line."""
    lines = ["{"]
    keys = [k for k in data if k not in ("blocks", "rules")] + \
        [k for k in ("blocks", "rules") if k in data]
    for n, key in enumerate(keys):
        value, comma = data[key], ("," if n < len(keys) - 1 else "")
        if key in ("blocks", "rules") and isinstance(value, list) and value:
            body = ",\n".join("    " + json.dumps(v, ensure_ascii=False) for v in value)
            lines.append(f"  {json.dumps(key)}: [\n{body}\n  ]{comma}")
        else:
            lines.append(f"  {json.dumps(key)}: {json.dumps(value, ensure_ascii=False)}{comma}")
    return "\n".join(lines + ["}"]) + "\n"


def _slug(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("._") or "tileset"


def _name_in_file(p: Path):
    try:
        return read_document(p).get("name")
    except TileSetEditError:
        return None


def save_path_for(name: str, folder: str | os.PathLike | None = None) -> Path:
    """Where a set called ``name`` is saved in ``folder`` (default the user
    folder): ``<slug>.json``, or ``<slug>_2.json`` ... when a file of that
    name already holds a different set."""
    folder = Path(folder) if folder is not None else user_tileset_dir()
    stem = _slug(name)
    for k in range(1, 10_000):
        p = folder / (f"{stem}.json" if k == 1 else f"{stem}_{k}.json")
        if not p.exists() or _name_in_file(p) == name:
            return p
    raise TileSetEditError(f"no free file name for tile set {name!r} in {str(folder)!r}")


def save_tileset(data: Mapping, path: str | os.PathLike | None = None, *,
                 folder: str | os.PathLike | None = None, overwrite: bool = False) -> Path:
    """Validate and write the document atomically; returns the path written.

    Parameters
    ----------
    path : optional, the file; default ``save_path_for(name, folder)``
    folder : optional, default `user_tileset_dir`
    overwrite : replace an existing file

    Refused: invalid documents, any path inside ``resources/tilesets``, a
    set name or file stem that a shipped set already uses (save a copy
    under a new name), an existing file unless ``overwrite``.
    """
    ts = validate(data)
    target = Path(path) if path is not None else save_path_for(ts.name, folder)
    target = target.expanduser().absolute()     # a TileSet node's `path` must not depend on cwd
    if is_shipped(target):
        raise TileSetEditError(f"save tile set {ts.name!r}: {str(target)!r} is in the shipped "
                               f"folder {str(TILESET_DIR)!r}; save a copy to the user folder")
    if ts.name in list_tilesets():
        raise TileSetEditError(f"save tile set {ts.name!r}: that name belongs to a shipped set; "
                               f"give the copy a new name")
    if target.exists() and not overwrite:
        raise TileSetEditError(f"save tile set {ts.name!r}: {str(target)!r} already exists")
    write_atomic(target, tileset_json(data).encode("utf-8"))
    return target


# ------------------------------------------------------------------ the draft

class TileSetDraft:
    """A tile-set document being edited, with undo and redo.

    Edits go through `apply`, which runs one of this module's operations on
    the current document; a refused edit raises and changes nothing. The
    document may be invalid as opened (``error`` says why); each edit must
    leave it valid.

    Parameters
    ----------
    data : mapping, the document
    source : path of the file it came from, optional
    """

    def __init__(self, data: Mapping, *, source: str | os.PathLike | None = None,
                 limit: int = 500):
        self._data = copy.deepcopy(dict(data))
        self._saved = self._data
        self.source = Path(source) if source is not None else None
        self.limit = limit
        self._done: list = []      # (text, document before)
        self._undone: list = []    # (text, document after)
        self._listeners: list = []
        self._parsed: tuple | None = None

    @classmethod
    def open(cls, path: str | os.PathLike) -> "TileSetDraft":
        return cls(read_document(path), source=path)

    def subscribe(self, callback: Callable[[], None]) -> None:
        self._listeners.append(callback)

    def _changed(self) -> None:
        self._parsed = None
        for cb in list(self._listeners):
            cb()

    @property
    def data(self) -> dict:
        """A copy of the current document."""
        return copy.deepcopy(self._data)

    @property
    def name(self) -> str:
        return str(self._data.get("name", ""))

    def _parse(self) -> tuple:
        if self._parsed is None:
            try:
                self._parsed = (validate(self._data, source=str(self.source or "") or None), "")
            except TileSetEditError as exc:
                self._parsed = (None, str(exc))
        return self._parsed

    @property
    def tileset(self) -> TileSet | None:
        """The parsed document, None when it is invalid."""
        return self._parse()[0]

    @property
    def error(self) -> str:
        """Why the document does not parse; empty when it does."""
        return self._parse()[1]

    @property
    def shipped(self) -> bool:
        return self.source is not None and is_shipped(self.source)

    @property
    def dirty(self) -> bool:
        return self._data is not self._saved

    def apply(self, text: str, op: Callable, *args, **kwargs) -> None:
        """Run ``op(document, *args, **kwargs)`` and record it as one undo step."""
        new = op(self._data, *args, **kwargs)
        self._done.append((text, self._data))
        del self._done[:-self.limit]
        self._undone.clear()
        self._data = new
        self._changed()

    def undo(self) -> bool:
        if not self._done:
            return False
        text, before = self._done.pop()
        self._undone.append((text, self._data))
        self._data = before
        self._changed()
        return True

    def redo(self) -> bool:
        if not self._undone:
            return False
        text, after = self._undone.pop()
        self._done.append((text, self._data))
        self._data = after
        self._changed()
        return True

    @property
    def can_undo(self) -> bool:
        return bool(self._done)

    @property
    def can_redo(self) -> bool:
        return bool(self._undone)

    def undo_text(self) -> str:
        return self._done[-1][0] if self._done else ""

    def redo_text(self) -> str:
        return self._undone[-1][0] if self._undone else ""

    def save(self, path: str | os.PathLike | None = None, *,
             folder: str | os.PathLike | None = None, overwrite: bool = False) -> Path:
        """`save_tileset` the document; it then counts as saved, from that file."""
        target = save_tileset(self._data, path, folder=folder, overwrite=overwrite)
        self.source, self._saved = target, self._data
        self._changed()
        return target
