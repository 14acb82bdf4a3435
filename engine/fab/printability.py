"""Fabricability statistics by emulating the print (Tricard et al. §5.1).

Each layer's paths are rasterised as beads (discs of the nozzle diameter
swept along the path) at a fine pixel size (0.04 mm in the paper). Paths
are cut into pieces of about one nozzle diameter, and each piece is checked
against what is already printed:

* **overhang** -- less than ``min_support`` (40 %) of the piece's footprint
  lies on material of the previous layer (the first layer sits on the bed);
* **overlap** -- the piece's band (footprint without the round end caps) is
  already covered by earlier paths of the same layer over a mean width of
  more than ``max_overlap`` (10 %) of the nozzle diameter. A path does not
  overlap itself (a loop closing on its start, a sharp turn).

Consecutive violating pieces of a path form one violating *segment*; the
paper's histograms (Figs. 20, 21) count these by length.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from engine.progress import report
from ._raster import emulate_layer
from .ordering import is_closed

PIXEL_SIZE = 0.04        # mm, as in the paper
MIN_SUPPORT = 0.4
MAX_OVERLAP = 0.1        # fraction of the nozzle diameter
MAX_PIXELS = 200_000_000


@dataclass(frozen=True, eq=False)
class PrintabilityReport:
    """Per-piece measurements and violation statistics.

    Attributes
    ----------
    segment_layer, segment_path : (S,) int64
        Layer index and path index (within the layer) of each piece.
    segment_length : (S,) float64
        mm along the path.
    segment_start, segment_end : (S, 2) float64
        mm, end points of each piece (for colouring a preview).
    support : (S,) float64
        Fraction of the footprint on the previous layer (1 on the bed).
    overlap_width : (S,) float64
        mm, mean width of the band already covered in the same layer.
    overhang, overlap : (S,) bool
        Violations per piece.
    overhang_segments, overlap_segments : (k,) float64
        mm, lengths of maximal violating stretches of paths.
    overhang_segment_layer, overlap_segment_layer : (k,) int64
    overhang_per_layer, overlap_per_layer : (L,) int64
        Number of violating stretches per layer.
    bin_edges : (B + 1,) float64
        mm, shared by both histograms.
    overhang_histogram, overlap_histogram : (B,) int64
    """

    segment_layer: np.ndarray
    segment_path: np.ndarray
    segment_length: np.ndarray
    segment_start: np.ndarray
    segment_end: np.ndarray
    support: np.ndarray
    overlap_width: np.ndarray
    overhang: np.ndarray
    overlap: np.ndarray
    overhang_segments: np.ndarray
    overhang_segment_layer: np.ndarray
    overlap_segments: np.ndarray
    overlap_segment_layer: np.ndarray
    overhang_per_layer: np.ndarray
    overlap_per_layer: np.ndarray
    bin_edges: np.ndarray
    overhang_histogram: np.ndarray
    overlap_histogram: np.ndarray

    def __post_init__(self):
        for name in self.__dataclass_fields__:
            getattr(self, name).flags.writeable = False

    @property
    def overhang_count(self) -> int:
        return int(self.overhang_per_layer.sum())

    @property
    def overlap_count(self) -> int:
        return int(self.overlap_per_layer.sum())


def split_path(path, piece_length):
    """Cut a polyline into pieces of equal arc length close to ``piece_length``.

    Parameters
    ----------
    path : (m, 2) float64
    piece_length : float

    Returns
    -------
    pts : (n, 2) float64
        Vertices of all pieces; neighbouring pieces share their end point.
    starts : (k + 1,) int64
        Piece ``q`` is ``pts[starts[q]:starts[q + 1]]``.
    lengths : (k,) float64
    """
    path = np.asarray(path, dtype=np.float64)
    d = np.hypot(*np.diff(path, axis=0).T)
    keep = np.concatenate([[True], d > 0])
    path, d = path[keep], d[d > 0]
    if len(d) == 0:
        return np.zeros((0, 2)), np.zeros(1, np.int64), np.zeros(0)
    s = np.concatenate([[0.0], np.cumsum(d)])
    total = s[-1]
    k = max(1, int(round(total / piece_length)))
    b = np.linspace(0.0, total, k + 1)
    near = np.searchsorted(s, b).clip(0, len(s) - 1)
    snap = np.abs(s[near] - b) < 1e-9
    b[snap] = s[near[snap]]
    grid = np.union1d(s, b)
    xy = np.column_stack([np.interp(grid, s, path[:, 0]), np.interp(grid, s, path[:, 1])])
    idx = np.searchsorted(grid, b)
    sizes = np.diff(idx) + 1
    starts = np.zeros(k + 1, np.int64)
    np.cumsum(sizes, out=starts[1:])
    within = np.arange(starts[-1]) - np.repeat(starts[:-1], sizes)
    gather = np.repeat(idx[:-1], sizes) + within
    return xy[gather], starts, np.diff(b)


def _runs(flags, lengths, closed):
    """Lengths of maximal runs of True in ``flags`` (joined across the seam
    of a closed path)."""
    if not flags.any():
        return []
    if flags.all():
        return [float(lengths.sum())]
    edges = np.flatnonzero(np.diff(np.concatenate([[0], flags.astype(np.int8), [0]])))
    runs = [float(lengths[a:b].sum()) for a, b in zip(edges[::2], edges[1::2])]
    if closed and flags[0] and flags[-1] and len(runs) > 1:
        runs[0] += runs.pop()
    return runs


def _grid(layers, margin, pixel_size):
    boxes = [(p.min(axis=0), p.max(axis=0)) for layer in layers for p in layer.paths if len(p)]
    if not boxes:
        return np.zeros(2), (1, 1)
    lo = np.min([b[0] for b in boxes], axis=0) - margin
    hi = np.max([b[1] for b in boxes], axis=0) + margin
    W, H = (np.ceil((hi - lo) / pixel_size).astype(int) + 1)
    if H * W > MAX_PIXELS:
        raise ValueError(f"pixel_size = {pixel_size} mm needs a {H} x {W} grid; "
                         f"use a coarser pixel_size (at most {MAX_PIXELS} pixels)")
    return lo, (int(H), int(W))


def printability(layers, *, nozzle_diameter=0.4, pixel_size=PIXEL_SIZE, piece_length=None,
                 min_support=MIN_SUPPORT, max_overlap=MAX_OVERLAP, bins=None,
                 progress=None) -> PrintabilityReport:
    """Emulate the print of ``layers`` and count overhangs and overlaps.

    Parameters
    ----------
    layers : sequence of Layer (or GcodeLayer)
        Bottom to top; each has ``paths``, a sequence of (m, 2) float64 mm in
        print order. Consecutive layers are one layer height apart.
    nozzle_diameter : float
        mm; bead width.
    pixel_size : float
        mm per pixel of the emulation.
    piece_length : float or None
        mm; paths are cut into pieces of about this length (default: one
        nozzle diameter).
    min_support : float
        A piece with a smaller supported fraction of its footprint is an
        overhang.
    max_overlap : float
        A piece whose band is covered over more than this fraction of the
        nozzle diameter overlaps.
    bins : int, sequence or None
        Histogram bins (as in ``numpy.histogram``); None means bins one
        ``piece_length`` wide from 0 to the longest violating segment.
    progress : callable or None
        ``progress(done, total) -> bool`` per layer; False cancels.

    Returns
    -------
    PrintabilityReport
    """
    for name, value in (("nozzle_diameter", nozzle_diameter), ("pixel_size", pixel_size)):
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a positive length in mm, got {value!r}")
    if not 0 <= min_support <= 1:
        raise ValueError(f"min_support must be a fraction in [0, 1], got {min_support!r}")
    if not max_overlap >= 0:
        raise ValueError(f"max_overlap must be a non-negative fraction, got {max_overlap!r}")
    piece_length = nozzle_diameter if piece_length is None else float(piece_length)
    if not piece_length > 0:
        raise ValueError(f"piece_length must be positive, got {piece_length!r}")
    layers = list(layers)
    radius = 0.5 * nozzle_diameter
    origin, shape = _grid(layers, radius + 2 * pixel_size, pixel_size)
    below = np.ones(shape, bool)                # the bed
    cols = {k: [] for k in ("layer", "path", "length", "start", "end", "support", "width")}
    runs = {"overhang": ([], []), "overlap": ([], [])}
    per_layer = {"overhang": np.zeros(len(layers), np.int64),
                 "overlap": np.zeros(len(layers), np.int64)}
    report(progress, 0, len(layers))
    for li, layer in enumerate(layers):
        canvas = np.zeros(shape, bool)
        pieces = [(pi, path) + split_path(path, piece_length) for pi, path in enumerate(layer.paths)]
        pieces = [p for p in pieces if len(p[4])]
        if pieces:
            pts = np.concatenate([p[2] for p in pieces])
            offs = np.cumsum([0] + [len(p[2]) for p in pieces[:-1]])
            starts = np.concatenate([p[3][:-1] + o for p, o in zip(pieces, offs)] + [[len(pts)]])
            owner = np.concatenate([np.full(len(p[4]), p[0]) for p in pieces])
            lengths = np.concatenate([p[4] for p in pieces])
            counts = emulate_layer((pts - origin) / pixel_size, starts.astype(np.int64),
                                   owner.astype(np.int64), radius / pixel_size, below, canvas)
            support = np.where(counts[:, 0] > 0, counts[:, 1] / np.maximum(counts[:, 0], 1), 1.0)
            width = np.where(counts[:, 2] > 0, counts[:, 3] / np.maximum(counts[:, 2], 1), 0.0)
            width *= nozzle_diameter
            cols["layer"].append(np.full(len(owner), li))
            cols["path"].append(owner)
            cols["length"].append(lengths)
            cols["start"].append(pts[starts[:-1]])
            cols["end"].append(pts[starts[1:] - 1])
            cols["support"].append(support)
            cols["width"].append(width)
            flags = {"overhang": support < min_support,
                     "overlap": width > max_overlap * nozzle_diameter}
            first = 0
            for pi, path, *_ in pieces:
                n = int(np.count_nonzero(owner == pi))
                sl = slice(first, first + n)
                first += n
                for kind, f in flags.items():
                    r = _runs(f[sl], lengths[sl], is_closed(path))
                    runs[kind][0].extend(r)
                    runs[kind][1].extend([li] * len(r))
                    per_layer[kind][li] += len(r)
        below = canvas
        report(progress, li + 1, len(layers))
    return _assemble(cols, runs, per_layer, bins, piece_length, min_support,
                     max_overlap * nozzle_diameter)


def _assemble(cols, runs, per_layer, bins, piece_length, min_support, max_width):
    def cat(key, dtype, shape=(0,)):
        return np.concatenate(cols[key]).astype(dtype) if cols[key] else np.zeros(shape, dtype)

    support, width = cat("support", np.float64), cat("width", np.float64)
    oh = np.array(runs["overhang"][0], np.float64)
    ov = np.array(runs["overlap"][0], np.float64)
    both = np.concatenate([oh, ov])
    if bins is None:
        top = max(1, int(math.ceil(both.max() / piece_length - 1e-9))) if both.size else 1
        edges = piece_length * np.arange(top + 1, dtype=np.float64)
        if both.size:
            edges[-1] = max(edges[-1], float(both.max()))
    else:
        edges = np.histogram_bin_edges(both, bins=bins)
    return PrintabilityReport(
        segment_layer=cat("layer", np.int64), segment_path=cat("path", np.int64),
        segment_length=cat("length", np.float64),
        segment_start=cat("start", np.float64, (0, 2)), segment_end=cat("end", np.float64, (0, 2)),
        support=support, overlap_width=width,
        overhang=support < min_support, overlap=width > max_width,
        overhang_segments=oh, overhang_segment_layer=np.array(runs["overhang"][1], np.int64),
        overlap_segments=ov, overlap_segment_layer=np.array(runs["overlap"][1], np.int64),
        overhang_per_layer=per_layer["overhang"], overlap_per_layer=per_layer["overlap"],
        bin_edges=edges,
        overhang_histogram=np.histogram(oh, bins=edges)[0].astype(np.int64),
        overlap_histogram=np.histogram(ov, bins=edges)[0].astype(np.int64),
    )
