"""Painted hint regions: a label map over the grid and hints per label (paper Fig. 5C).

The map is stored as text so it lives in a node parameter (and so in the
project file and the undo history): rows separated by ";" from the top row
(row 0) down, one character per cell, "0"-"9" / "a"-"z" labels; "." = label 0.
Label 0 takes the node's base hints; other labels take their own.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import numpy as np

from .hints import hint_table

_ALPHABET = "0123456789abcdefghijklmnopqrstuvwxyz"


def parse_region_map(text: str, shape) -> np.ndarray | None:
    """Label map (ny, nx) int from its text form; None for an empty text.

    Raises ValueError naming the row and what was expected.
    """
    text = text.strip()
    if not text:
        return None
    if len(shape) != 2:
        raise ValueError(f"painted regions are for 2D grids; this grid has shape {tuple(shape)}")
    rows = [r.strip() for r in text.split(";")]
    ny, nx = shape
    if len(rows) != ny:
        raise ValueError(f"the region map has {len(rows)} rows, the grid {ny}")
    out = np.zeros((ny, nx), dtype=np.int64)
    for i, row in enumerate(rows):
        if len(row) != nx:
            raise ValueError(f"row {i} of the region map has {len(row)} cells, the grid {nx}")
        for j, ch in enumerate(row.lower()):
            if ch == ".":
                continue
            if ch not in _ALPHABET:
                raise ValueError(f"row {i}, column {j} of the region map: {ch!r} is not a label (0-9, a-z or .)")
            out[i, j] = _ALPHABET.index(ch)
    return out


def format_region_map(labels: np.ndarray) -> str:
    """Text form of a (ny, nx) label map (inverse of parse_region_map)."""
    lab = np.asarray(labels)
    if lab.ndim != 2 or lab.min(initial=0) < 0 or lab.max(initial=0) >= len(_ALPHABET):
        raise ValueError(f"labels must be a 2-D array of ints in [0, {len(_ALPHABET) - 1}]")
    return ";".join("".join(_ALPHABET[v] for v in row) for row in lab)


def region_hint_field(tileset, shape, labels: np.ndarray, base_hints, label_hints: Mapping[int, object]):
    """Per-cell hint table (ny, nx, n_tiles) from a label map and hints per label."""
    base = hint_table(tileset, base_hints, shape)[0]
    field = np.empty(tuple(shape) + (len(base),))
    field[...] = base
    for label, hints in label_hints.items():
        mask = labels == label
        if mask.any():
            field[mask] = hint_table(tileset, hints, shape)[0]
    return field


def parse_region_hints(text: str, parse: Callable[[str], object]) -> dict[int, object]:
    """'1: T=3,+=1 | 2: L=2' -> {1: parse('T=3,+=1'), 2: parse('L=2')}."""
    out: dict[int, object] = {}
    for part in filter(None, (p.strip() for p in text.split("|"))):
        label, sep, hints = part.partition(":")
        label = label.strip().lower()
        if not sep or len(label) != 1 or label not in _ALPHABET:
            raise ValueError(f"region hints entry {part!r}: expected 'LABEL: name=weight,...' with LABEL 0-9 or a-z")
        out[_ALPHABET.index(label)] = parse(hints)
    return out
