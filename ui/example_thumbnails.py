"""Where an example's thumbnail is, and whether it still shows the example.

A thumbnail is keyed on the example's *content digest*: SHA-256 of what its
evaluation depends on (document seed, each node's id, type and parameters,
the edges in order, stored node state) and nothing it does not (node positions,
labels, meta). ``resources/examples/thumbnails/index.json`` records the
digest each shipped PNG was rendered from (``tools/make_thumbnails.py``
writes both), so a test can tell a stale thumbnail and the gallery never
shows one: it uses a fresh shipped PNG, else one it rendered earlier into
its cache directory (``<stem>-<digest>.png``), else renders one.

No Qt here: the build script and the tests use it too.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path

__all__ = ["THUMBNAILS_DIR", "INDEX_NAME", "ExampleInfo", "content_digest", "example_info", "read_index",
           "shipped_thumbnail", "cached_thumbnail_path", "find_thumbnail"]

EXAMPLES_DIR = Path(__file__).resolve().parents[1] / "resources" / "examples"
THUMBNAILS_DIR = EXAMPLES_DIR / "thumbnails"
INDEX_NAME = "index.json"


def content_digest(project: dict) -> str:
    """Hex SHA-256 of a project file's evaluated content (see the module doc)."""
    nodes = sorted((n["id"], n["type"], n.get("params", {})) for n in project.get("nodes", []))
    edges = list(project.get("edges", []))      # in order: a multi-input port's order counts
    content = {"seed": project.get("seed"), "nodes": nodes, "edges": edges,
               "node_state": project.get("node_state") or {}}
    text = json.dumps(content, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


@dataclass(frozen=True)
class ExampleInfo:
    """One example file as the gallery lists it."""
    path: Path
    stem: str
    title: str
    family: str
    summary: str
    description: str
    digest: str


def example_info(path: str | Path) -> ExampleInfo:
    """The gallery's view of the example file at `path` (read as JSON, not evaluated)."""
    path = Path(path)
    project = json.loads(path.read_text(encoding="utf-8"))
    meta = project.get("meta") or {}
    return ExampleInfo(path, path.stem, meta.get("title") or path.stem.replace("_", " "),
                       meta.get("family") or "other", meta.get("summary") or "",
                       meta.get("description") or "", content_digest(project))


def read_index(thumbnails_dir: str | Path = THUMBNAILS_DIR) -> dict[str, dict]:
    """``{stem: {"digest": ..., "file": ...}}`` of the shipped thumbnails ({} when none)."""
    try:
        data = json.loads((Path(thumbnails_dir) / INDEX_NAME).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return data.get("thumbnails", {}) if isinstance(data, dict) else {}


def shipped_thumbnail(info: ExampleInfo, thumbnails_dir: str | Path = THUMBNAILS_DIR,
                      index: dict | None = None) -> Path | None:
    """The shipped PNG of `info` when it was rendered from the example's current content."""
    entry = (read_index(thumbnails_dir) if index is None else index).get(info.stem)
    if not entry or entry.get("digest") != info.digest:
        return None
    png = Path(thumbnails_dir) / entry.get("file", f"{info.stem}.png")
    return png if png.is_file() else None


def cached_thumbnail_path(info: ExampleInfo, cache_dir: str | Path) -> Path:
    """Where a thumbnail rendered for the example's current content is cached."""
    return Path(cache_dir) / f"{info.stem}-{info.digest[:16]}.png"


def find_thumbnail(info: ExampleInfo, cache_dir: str | Path | None, *,
                   thumbnails_dir: str | Path = THUMBNAILS_DIR, index: dict | None = None) -> Path | None:
    """A thumbnail showing the example as it is now: shipped, else cached, else None."""
    shipped = shipped_thumbnail(info, thumbnails_dir, index)
    if shipped is not None:
        return shipped
    if cache_dir is not None:
        cached = cached_thumbnail_path(info, cache_dir)
        if cached.is_file():
            return cached
    return None
