"""A library of saved subgraphs: one JSON file per subgraph in a user folder.

```
{"format": "mesoforge-subgraph", "version": 1, "name": "Strut",
 "fragment": {... engine.graph.clipboard fragment of the members ...},
 "exposed": [{"node": "v1", "param": "position", "label": "end"}]}
```

`SubgraphLibrary.save` writes a document's subgraph (its members with their
inner edges, and its exposed parameters) atomically; `InsertSubgraph` is the
undo command that pastes one into a document under fresh ids (through
`clipboard.PasteFragment`) and groups the copy into a new subgraph with the
same exposed parameters: one undo step.  The folder is given (tests use a
temporary one); `default_library_dir` is the user's.
"""

from __future__ import annotations

import json
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from engine.fileio import write_atomic

from .annotation_commands import MakeSubgraph
from .annotations import ExposedParam
from .clipboard import PasteFragment, fragment_of
from .commands import Command
from .document import GraphDocument
from .errors import GraphError

LIBRARY_FORMAT = "mesoforge-subgraph"
LIBRARY_VERSION = 1


def default_library_dir() -> Path:
    """``$MESOFORGE_SUBGRAPH_DIR``, else ``$XDG_DATA_HOME/mesoforge/subgraphs`` (``~/.local/share/...``)."""
    env = os.environ.get("MESOFORGE_SUBGRAPH_DIR")
    if env:
        return Path(env)
    base = os.environ.get("XDG_DATA_HOME") or str(Path.home() / ".local" / "share")
    return Path(base) / "mesoforge" / "subgraphs"


@dataclass(frozen=True)
class LibrarySubgraph:
    """One saved subgraph: its name, fragment (clipboard format) and exposed parameters."""

    name: str
    fragment: dict
    exposed: tuple[ExposedParam, ...]
    path: Path | None = None

    @property
    def node_ids(self) -> list[str]:
        return [n["id"] for n in self.fragment["nodes"]]


def subgraph_to_library(doc: GraphDocument, subgraph_id: str) -> dict[str, Any]:
    """The library entry (JSON data) of a document's subgraph."""
    sub = doc.annotations.subgraph(subgraph_id)
    if not sub.members:
        raise GraphError(f"subgraph {subgraph_id!r} ({sub.name}) has no nodes left to save", where="members")
    return {"format": LIBRARY_FORMAT, "version": LIBRARY_VERSION, "name": sub.name,
            "fragment": fragment_of(doc, sub.members),
            "exposed": [{"node": e.node_id, "param": e.param, "label": e.label} for e in sub.exposed]}


def subgraph_from_library(data: Any, path: Path | None = None) -> LibrarySubgraph:
    """Check library JSON data; GraphError naming the field (and the file) when malformed."""
    at = f"{str(path)!r}: " if path is not None else ""

    def need(cond: bool, where: str, expected: str) -> None:
        if not cond:
            raise GraphError(f"subgraph library file {at}{where}: expected {expected}", where=where)

    need(isinstance(data, dict), "top level", "a JSON object")
    need(data.get("format") == LIBRARY_FORMAT, "format", repr(LIBRARY_FORMAT))
    need(data.get("version") == LIBRARY_VERSION, "version", str(LIBRARY_VERSION))
    need(isinstance(data.get("name"), str) and data["name"].strip() != "", "name", "non-empty text")
    need(isinstance(data.get("fragment"), dict), "fragment", "an object")
    try:
        PasteFragment(data["fragment"])  # checks the fragment's shape
    except GraphError as exc:
        raise GraphError(f"subgraph library file {at}fragment: {exc}", where="fragment") from None
    exposed = data.get("exposed", [])
    need(isinstance(exposed, list), "exposed", "a list")
    ids = {n["id"] for n in data["fragment"]["nodes"]}
    entries = []
    for i, e in enumerate(exposed):
        need(isinstance(e, dict) and isinstance(e.get("node"), str) and isinstance(e.get("param"), str)
             and isinstance(e.get("label", ""), str), f"exposed[{i}]",
             '{"node": id, "param": name, "label": text}')
        need(e["node"] in ids, f"exposed[{i}].node", f"one of the fragment's nodes {sorted(ids)}")
        entries.append(ExposedParam(e["node"], e["param"], e.get("label", "")))
    return LibrarySubgraph(data["name"], data["fragment"], tuple(entries), path)


def _file_name(name: str) -> str:
    slug = re.sub(r"[^A-Za-z0-9_\-]+", "_", name.strip()).strip("_") or "subgraph"
    return f"{slug[:80]}.json"


class SubgraphLibrary:
    """The saved subgraphs in `directory` (created on first save)."""

    def __init__(self, directory: str | os.PathLike):
        self.directory = Path(directory)

    def path_of(self, name: str) -> Path:
        return self.directory / _file_name(name)

    def save(self, doc: GraphDocument, subgraph_id: str) -> tuple[Path, bool]:
        """Write the subgraph under its name; returns (file, whether one of that name was replaced)."""
        data = subgraph_to_library(doc, subgraph_id)
        path = self.path_of(data["name"])
        replaced = path.exists()
        self.directory.mkdir(parents=True, exist_ok=True)
        write_atomic(path, (json.dumps(data, indent=1, allow_nan=False) + "\n").encode("utf-8"))
        return path, replaced

    def load(self, path: str | os.PathLike) -> LibrarySubgraph:
        """One saved subgraph; GraphError naming the file and what is wrong."""
        p = Path(path)
        try:
            data = json.loads(p.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise GraphError(f"subgraph library file {str(p)!r} cannot be read: {exc}") from None
        return subgraph_from_library(data, p)

    def entries(self) -> tuple[list[LibrarySubgraph], list[str]]:
        """The readable saved subgraphs by name, and a message for each file that is not one."""
        if not self.directory.is_dir():
            return [], []
        found, problems = [], []
        for p in sorted(self.directory.glob("*.json")):
            try:
                found.append(self.load(p))
            except GraphError as exc:
                problems.append(str(exc))
        return sorted(found, key=lambda e: e.name.lower()), problems


class InsertSubgraph(Command):
    """Paste a saved subgraph's nodes (fresh ids, moved by `offset`) and group them
    into a new subgraph exposing the same parameters; one undo step."""

    def __init__(self, entry: LibrarySubgraph, offset=(0.0, 0.0)):
        self.entry = entry
        self.paste = PasteFragment(entry.fragment, offset=offset)
        self.subgraph_id: str | None = None
        self.text = f"insert subgraph {entry.name!r}"
        self._group: MakeSubgraph | None = None

    def do(self, doc):
        self.paste.do(doc)
        try:
            m = self.paste.id_map
            exposed = [ExposedParam(m[e.node_id], e.param, e.label) for e in self.entry.exposed]
            self._group = MakeSubgraph(self.paste.new_ids, self.entry.name, self.subgraph_id, exposed)
            self._group.do(doc)
        except Exception:
            self.paste.undo(doc)
            raise
        self.subgraph_id = self._group.subgraph_id

    def undo(self, doc):
        self._group.undo(doc)
        self.paste.undo(doc)
