"""Painted hint regions: a label map over the grid and hints per label (paper Fig. 5C).

The map is stored as text so it lives in a node parameter (and so in the
project file and the undo history): rows separated by ";" from the top row
(row 0) down, one character per cell, "0"-"9" / "a"-"z" labels; "." = label 0.
Label 0 takes the node's base hints; other labels take their own.

Painting helpers (``paint_disc``, ``densify_stroke``) work in cell
coordinates ``(x, y)``: cell ``[i, j]`` covers ``x`` in ``[j, j + 1)`` and
``y`` in ``[i, i + 1)``, so its centre is ``(j + 0.5, i + 0.5)``.
"""

from __future__ import annotations

import math
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


def format_region_hints(texts: Mapping[int, str]) -> str:
    """{1: 'T=3,+=1', 2: 'L=2'} -> '1: T=3,+=1 | 2: L=2' (labels in order; empty texts left out).

    Inverse of ``parse_region_hints(text, str.strip)``.
    """
    parts = []
    for label in sorted(texts):
        hints = str(texts[label]).strip()
        if not hints:
            continue
        if not 0 <= int(label) < len(_ALPHABET):
            raise ValueError(f"label must be in [0, {len(_ALPHABET) - 1}]; got {label!r}")
        if "|" in hints:
            raise ValueError(f"hints of label {label_name(label)} contain '|', which separates labels: {hints!r}")
        parts.append(f"{_ALPHABET[int(label)]}: {hints}")
    return " | ".join(parts)


def label_name(label: int) -> str:
    """The character that stands for ``label`` in the text forms ('0'-'9', 'a'-'z')."""
    return _ALPHABET[int(label)]


N_LABELS = len(_ALPHABET)


def paint_disc(labels: np.ndarray, centres, radius: float, label: int) -> np.ndarray:
    """A label map with a round brush applied at each of ``centres``.

    Parameters
    ----------
    labels : (ny, nx) int array, the map before the stroke; not modified
    centres : (k, 2) float, brush centres ``(x, y)`` in cell units
    radius : float >= 0, brush radius in cells
    label : int in [0, 35], the label painted (0 erases)

    Returns
    -------
    (ny, nx) int64, a new array: every cell whose centre lies within
    ``radius`` of a brush centre (distance <= radius), and every cell that
    contains a brush centre (so radius 0 paints single cells), set to
    ``label``; other cells as in ``labels``. Centres off the grid paint the
    cells within reach.
    """
    out = np.array(labels, dtype=np.int64, copy=True)
    if out.ndim != 2:
        raise ValueError(f"labels must be a 2-D label map; got shape {out.shape}")
    pts = np.asarray(centres, dtype=np.float64).reshape(-1, 2) if np.size(centres) else np.zeros((0, 2))
    if not np.all(np.isfinite(pts)):
        raise ValueError("centres must be finite (x, y) cell coordinates")
    if not (isinstance(radius, (int, float, np.integer, np.floating)) and math.isfinite(radius)
            and radius >= 0):
        raise ValueError(f"radius must be a finite number of cells >= 0; got {radius!r}")
    if isinstance(label, bool) or not isinstance(label, (int, np.integer)) \
            or not 0 <= label < len(_ALPHABET):
        raise ValueError(f"label must be an int in [0, {len(_ALPHABET) - 1}]; got {label!r}")
    ny, nx = out.shape
    r = float(radius)
    for x, y in pts:
        # a box holding the rows i with |i + 0.5 - y| <= r (and columns likewise), one
        # cell wider so rounding at its edges cannot drop a cell; the test decides
        i0, i1 = max(0, math.floor(y - r) - 1), min(ny - 1, math.ceil(y + r))
        j0, j1 = max(0, math.floor(x - r) - 1), min(nx - 1, math.ceil(x + r))
        if i0 <= i1 and j0 <= j1:
            di = (np.arange(i0, i1 + 1) + 0.5 - y)[:, None]
            dj = (np.arange(j0, j1 + 1) + 0.5 - x)[None, :]
            block = out[i0:i1 + 1, j0:j1 + 1]
            block[di * di + dj * dj <= r * r] = label
        i, j = math.floor(y), math.floor(x)
        if 0 <= i < ny and 0 <= j < nx:
            out[i, j] = label
    return out


def densify_stroke(points, spacing: float = 0.5) -> np.ndarray:
    """Points along a polyline no farther apart than ``spacing``.

    A mouse drag reports positions far apart when it moves fast; painting a
    disc at each of these points would leave gaps.

    Parameters
    ----------
    points : (k, 2) float, the polyline's vertices in cell units
    spacing : float > 0, largest distance between consecutive output points

    Returns
    -------
    (m, 2) float64 with m >= k: the vertices in order with evenly spaced
    points inserted on every segment longer than ``spacing``.
    """
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    if not (spacing > 0 and math.isfinite(spacing)):
        raise ValueError(f"spacing must be a finite number > 0; got {spacing!r}")
    if len(p) < 2:
        return p.copy()
    out = [p[:1]]
    for a, b in zip(p[:-1], p[1:]):
        n = max(1, math.ceil(float(np.hypot(*(b - a))) / spacing))
        t = (np.arange(1, n + 1) / n)[:, None]
        out.append(a + t * (b - a))
    return np.concatenate(out)
