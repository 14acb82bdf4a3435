"""Frequency hints written as text: ``"T=1,L=1,+=2,-=1"``.

The form used by the command line, the Grow node and the study files. Each
comma-separated entry is ``name=weight`` with ``name`` a block (``T``) or a
tile (``T@1``) of the tile set and ``weight`` a finite number >= 0; names
left out get weight 0. Whitespace around names and numbers is ignored. An
empty text means "no hints" (the caller's default).
"""

from __future__ import annotations

import math

__all__ = ["parse_hints", "format_hints"]


def parse_hints(text: str, tileset=None) -> dict | None:
    """Parse ``"T=1,L=1,+=2,-=1"`` into ``{"T": 1.0, "L": 1.0, "+": 2.0, "-": 1.0}``.

    Parameters
    ----------
    text : str
    tileset : TileSet, optional
        When given, every name must be one of its blocks or tiles.

    Returns
    -------
    dict name -> float, or None for an empty text.

    Raises
    ------
    ValueError
        Naming the entry (position and text) and what is wrong with it.
    """
    if not isinstance(text, str):
        raise ValueError(f"hints must be a string like 'T=1,L=1,+=2,-=1'; got {text!r}")
    if not text.strip():
        return None
    out: dict = {}
    for k, raw in enumerate(text.split(","), start=1):
        entry = raw.strip()
        where = f"hints entry {k} {entry!r}"
        if "=" not in entry:
            raise ValueError(f"{where}: expected name=weight (e.g. 'T=1')")
        name, _, value = entry.rpartition("=")
        name, value = name.strip(), value.strip()
        if not name:
            raise ValueError(f"{where}: the block name before '=' is empty")
        if tileset is not None and name not in tileset.block_names \
                and name not in tileset.tile_names:
            raise ValueError(f"{where}: {name!r} is not a block of tile set {tileset.name!r} "
                             f"(blocks: {', '.join(tileset.block_names)}; tiles are named "
                             f"like {tileset.tile_names[0]!r})")
        try:
            w = float(value)
        except ValueError:
            raise ValueError(f"{where}: weight {value!r} is not a number") from None
        if not math.isfinite(w) or w < 0:
            raise ValueError(f"{where}: weight must be a finite number >= 0; got {value!r}")
        if name in out:
            raise ValueError(f"{where}: {name!r} is given twice")
        out[name] = w
    if not any(w > 0 for w in out.values()):
        raise ValueError(f"hints {text!r}: at least one weight must be > 0")
    return out


def format_hints(hints) -> str:
    """The text form of a mapping name -> weight (inverse of :func:`parse_hints`)."""
    if not hints:
        return ""
    return ",".join(f"{name}={float(w)!r}" for name, w in hints.items())
