"""Line geometry of toolpaths for a 3D preview (no pyvista import here)."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

KIND_CODES = {"perimeter": 0, "infill": 1, "travel": 2}
# RGB per kind code, 0-255: perimeters orange, infill walls blue, travel grey.
KIND_COLOURS = np.array([[230, 120, 30], [40, 110, 200], [150, 150, 150]], dtype=np.uint8)
KIND_COLOURS.flags.writeable = False


class PreviewLines(NamedTuple):
    """Line segments of a stack of layers.

    points : (n, 3) float64, mm (x, y, z)
    segments : (k, 2) int64, indices into ``points``
    kinds : (k,) int8, codes of :data:`KIND_CODES`; colours are ``KIND_COLOURS[kinds]``
    layer : (k,) int32, layer index of each segment (for a layer-range filter)
    """

    points: np.ndarray
    segments: np.ndarray
    kinds: np.ndarray
    layer: np.ndarray


def layer_preview_lines(layers, *, travel=False, every=1) -> PreviewLines:
    """Segments of every extruded path (and optionally travel moves).

    Parameters
    ----------
    layers : iterable of Layer or GcodeLayer
        Objects with ``z``, ``paths`` and ``kinds``.
    travel : bool
        Add the travel moves between consecutive paths of a layer.
    every : int
        Keep one layer in ``every`` (a lighter preview of tall parts).

    Returns
    -------
    PreviewLines
    """
    if int(every) < 1:
        raise ValueError(f"every must be a positive whole number, got {every!r}")
    pts, segs, kinds, lay = [], [], [], []
    base = 0
    for li, layer in enumerate(layers):
        if li % int(every):
            continue
        prev_end = None
        for path, kind in zip(layer.paths, layer.kinds):
            p = np.asarray(path, dtype=np.float64)
            m = len(p)
            if m < 2:
                continue
            if travel and prev_end is not None:
                segs.append(np.array([[prev_end, base]]))
                kinds.append(np.full(1, KIND_CODES["travel"], np.int8))
                lay.append(np.full(1, li, np.int32))
            pts.append(np.column_stack([p, np.full(m, layer.z)]))
            idx = base + np.arange(m - 1)
            segs.append(np.column_stack([idx, idx + 1]))
            kinds.append(np.full(m - 1, KIND_CODES.get(kind, KIND_CODES["infill"]), np.int8))
            lay.append(np.full(m - 1, li, np.int32))
            base += m
            prev_end = base - 1
    if not pts:
        return PreviewLines(np.zeros((0, 3)), np.zeros((0, 2), np.int64),
                            np.zeros(0, np.int8), np.zeros(0, np.int32))
    return PreviewLines(np.concatenate(pts), np.concatenate(segs).astype(np.int64),
                        np.concatenate(kinds), np.concatenate(lay))


def vtk_line_cells(segments) -> np.ndarray:
    """VTK ``lines`` connectivity ``[2, i, j, 2, k, l, ...]`` from (k, 2) segments."""
    segments = np.asarray(segments, dtype=np.int64).reshape(-1, 2)
    cells = np.empty((len(segments), 3), np.int64)
    cells[:, 0] = 2
    cells[:, 1:] = segments
    return cells.ravel()
