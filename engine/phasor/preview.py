"""What the paint canvas shows of the phasor fields and where a stroke reaches.

Pure numpy helpers for an axis-aligned slice through the fields' box:

* the slice's pixel grid (an :class:`engine.gpu.SlicePlane` whose pixels
  tile the box's in-plane extent exactly) and sub-rectangles of it with the
  very same pixel centres, so a local re-evaluation can be pasted into the
  full image;
* the painted fields sampled on that grid (F, Gamma; D as a hue of its
  in-plane angle and as short glyphs on a coarse grid);
* the pixels inside a box in mm (where a brush stroke changed the field
  samples, or where the re-aligned kernels reach), as a pixel rectangle;
* the part's outline on a slice and the line geometry of a G-code file.

In-plane coordinates follow :mod:`engine.phasor.strokes`: on the plane
normal to ``axis`` the pixel columns run along u and the rows along v::

    axis "z": (u, v) = (x, y)     axis "y": (u, v) = (x, z)     axis "x": (u, v) = (y, z)

Pixel ``[row i, column j]`` is centred at ``(u0 + (j + 1/2) du, v0 + (i + 1/2) dv)``.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from engine.gpu.slice_plane import SlicePlane
from engine.phasor.fields import PhasorFields
from engine.phasor.strokes import PLANE_AXES

__all__ = ["AXES", "axis_span", "slice_extent", "slice_plane", "view_pixels", "sub_plane", "plane_extent",
           "field_slice", "direction_hue", "direction_glyphs", "region_pixel_rect", "PATTERNS",
           "pattern_slice", "domain_slice", "mask_outline", "GcodePreview", "gcode_preview"]

AXES = ("x", "y", "z")
DEFAULT_MAX_PIXELS = 256


def _axis(axis) -> tuple:
    if axis not in PLANE_AXES:
        raise ValueError(f"axis: expected 'x', 'y' or 'z', got {axis!r}")
    return PLANE_AXES[axis]


def axis_span(lo, hi, axis) -> tuple:
    """(a, b) mm: the box's range along the slice normal ``axis``."""
    n = _axis(axis)[2]
    return float(np.asarray(lo)[n]), float(np.asarray(hi)[n])


def slice_extent(lo, hi, axis) -> np.ndarray:
    """(2, 2) mm ``((u0, u1), (v0, v1))``: the box's in-plane extent."""
    u, v, _ = _axis(axis)
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    return np.array([[lo[u], hi[u]], [lo[v], hi[v]]])


def slice_plane(lo, hi, axis, position, *, max_pixels=DEFAULT_MAX_PIXELS) -> SlicePlane:
    """The pixel grid of the slice normal to ``axis`` at ``position`` mm.

    The pixels tile the box's in-plane extent exactly; the longer side gets
    ``max_pixels`` pixels and the other as many as keep them near square.
    """
    if not isinstance(max_pixels, (int, np.integer)) or max_pixels < 1:
        raise ValueError(f"max_pixels: expected a positive whole number, got {max_pixels!r}")
    position = float(position)
    if not math.isfinite(position):
        raise ValueError(f"position: expected a finite number of mm, got {position!r}")
    u, v, n = _axis(axis)
    ext = slice_extent(lo, hi, axis)
    size = ext[:, 1] - ext[:, 0]
    pixel = float(size.max()) / int(max_pixels)
    res = np.maximum(1, np.round(size / pixel)).astype(np.int64)
    origin = np.zeros(3)
    origin[n], origin[u], origin[v] = position, ext[0, 0], ext[1, 0]
    return SlicePlane(origin, np.eye(3)[u], np.eye(3)[v], size, res)


def view_pixels(fields: PhasorFields, *, least: int = 128, most: int = 768) -> int:
    """Pixels along the longer side of a slice view: enough for
    :data:`engine.phasor.infill.MIN_PIXELS_PER_PERIOD` pixels per period of the
    highest F, within ``least..most``."""
    from engine.phasor.infill import MIN_PIXELS_PER_PERIOD

    longest = float(np.max(fields.hi - fields.lo))
    need = math.ceil(longest * fields.max_frequency() * MIN_PIXELS_PER_PERIOD)
    return int(min(max(need, least), most))


def plane_extent(plane: SlicePlane) -> np.ndarray:
    """(2, 2) mm ``((u0, u1), (v0, v1))`` covered by an axis-aligned ``plane``."""
    u0 = float(plane.origin @ plane.u_axis)
    v0 = float(plane.origin @ plane.v_axis)
    return np.array([[u0, u0 + plane.size[0]], [v0, v0 + plane.size[1]]])


def sub_plane(plane: SlicePlane, rows, cols) -> SlicePlane:
    """Pixels ``rows = (r0, r1)``, ``cols = (c0, c1)`` of ``plane`` as a plane of their own.

    Its pixel ``[i, j]`` has the centre of ``plane``'s pixel ``[r0 + i, c0 + j]``.
    """
    h, w = plane.shape
    r0, r1 = (int(r) for r in rows)
    c0, c1 = (int(c) for c in cols)
    if not (0 <= r0 < r1 <= h and 0 <= c0 < c1 <= w):
        raise ValueError(f"rows {rows!r}, cols {cols!r}: expected a non-empty rectangle inside "
                         f"the plane's {h} x {w} pixels")
    origin = plane.origin + c0 * plane.pixel_u + r0 * plane.pixel_v
    du, dv = plane.size / plane.resolution
    return SlicePlane(origin, plane.u_axis, plane.v_axis, ((c1 - c0) * du, (r1 - r0) * dv),
                      (c1 - c0, r1 - r0))


# --------------------------------------------------------------------- fields

def field_slice(fields: PhasorFields, name: str, plane: SlicePlane) -> np.ndarray:
    """A painted field sampled trilinearly at the pixel centres of ``plane``.

    Returns
    -------
    "F": (H, W) float64 cells/mm; "Gamma": (H, W) float64 radians;
    "D": (H, W, 3) float64 unit vectors (x, y, z)
    """
    pts = plane.points().reshape(-1, 3)
    h, w = plane.shape
    if name == "F":
        return fields.sample_frequency(pts).reshape(h, w)
    if name == "Gamma":
        return fields.sample_spread(pts).reshape(h, w)
    if name == "D":
        return fields.sample_direction(pts).reshape(h, w, 3)
    raise ValueError(f"field: expected 'D', 'F' or 'Gamma', got {name!r}")


def _hsv_to_rgb(h, s, v) -> np.ndarray:
    """Vectorised HSV (each in [0, 1]) to RGB floats in [0, 1], shape (..., 3)."""
    h6 = (np.asarray(h) % 1.0) * 6.0
    c = v * s
    x = c * (1.0 - np.abs(h6 % 2.0 - 1.0))
    zero = np.zeros_like(c)
    sector = np.minimum(h6.astype(np.int64), 5)
    table = [(c, x, zero), (x, c, zero), (zero, c, x), (zero, x, c), (x, zero, c), (c, zero, x)]
    rgb = np.zeros(np.shape(c) + (3,))
    for k, (r, g, b) in enumerate(table):
        hit = sector == k
        rgb[hit] = np.stack([r[hit], g[hit], b[hit]], axis=-1)
    return rgb + (v - c)[..., None]


def direction_hue(directions, axis) -> np.ndarray:
    """(..., 3) uint8 RGB: hue = angle of D's in-plane part, atan2(v, u), over a full turn
    (D is a direction: d and -d differ by half a turn); saturation = the length of the
    in-plane part, so D along the normal shows white."""
    u, v, _ = _axis(axis)
    d = np.asarray(directions, dtype=np.float64)
    angle = np.arctan2(d[..., v], d[..., u])
    sat = np.clip(np.hypot(d[..., u], d[..., v]), 0.0, 1.0)
    rgb = _hsv_to_rgb(angle / (2 * math.pi), sat, np.full(sat.shape, 0.95))
    return np.clip(np.rint(rgb * 255.0), 0, 255).astype(np.uint8)


def direction_glyphs(fields: PhasorFields, axis, position, *, count=16) -> tuple:
    """D on a coarse grid of the slice, for line glyphs.

    Parameters
    ----------
    count : int, glyphs along the longer in-plane side

    Returns
    -------
    centres : (k, 2) float64, in-plane mm
    vectors : (k, 2) float64, in-plane part (u, v) of D, length <= 1
    normal : (k,) float64, D's component along ``axis`` (the tilt's sine)
    """
    plane = slice_plane(fields.lo, fields.hi, axis, position, max_pixels=int(count))
    d = field_slice(fields, "D", plane).reshape(-1, 3)
    u, v, n = _axis(axis)
    pts = plane.points().reshape(-1, 3)
    return pts[:, [u, v]], d[:, [u, v]], d[:, n]


# ---------------------------------------------------------- what a stroke changes

def region_pixel_rect(plane: SlicePlane, region) -> tuple | None:
    """(r0, r1, c0, c1): the pixels of an axis-aligned ``plane`` whose centres lie in
    the closed box ``region = (lo, hi)`` (3,) mm (sides may be infinite); None if none do.

    With :func:`engine.phasor.incremental.affected_box` of a stroke's changed cells these
    are the pixels whose field samples can differ; with an infill's ``changed_region``
    those whose pattern can.
    """
    if region is None:
        return None
    lo, hi = (np.asarray(b, dtype=np.float64) for b in region)
    u, v, n = (int(np.argmax(np.abs(a))) for a in (plane.u_axis, plane.v_axis,
                                                    np.cross(plane.u_axis, plane.v_axis)))
    position = float(plane.origin[n])
    if not lo[n] <= position <= hi[n]:
        return None
    ext = plane_extent(plane)
    h, w = plane.shape
    out = []
    for (a0, a1), count, i in ((ext[1], h, v), (ext[0], w, u)):
        step = (a1 - a0) / count
        # pixel k is centred at a0 + (k + 1/2) step
        first = (max(lo[i], a0) - a0) / step - 0.5
        last = (min(hi[i], a1) - a0) / step - 0.5
        k0 = max(int(math.ceil(first - 1e-9)), 0)
        k1 = min(int(math.floor(last + 1e-9)) + 1, count)
        if k1 <= k0:
            return None
        out += [k0, k1]
    return tuple(out)


# ------------------------------------------------------------------- patterns

PATTERNS = ("diamonds", "p_v", "singularity")


def pattern_slice(infill, plane: SlicePlane, show: str = "diamonds", *, engine: str = "gpu",
                  progress=None) -> tuple:
    """The infill's pattern on ``plane`` as float64 (H, W), and the evaluator that made it.

    Parameters
    ----------
    infill : engine.phasor.infill.PhasorInfill (its own noise state)
    plane : SlicePlane (or a sub-rectangle of one, :func:`sub_plane`)
    show : "diamonds" (1 inside the black diamond cells, else 0, over the whole box),
        "p_v" (the sawtooth p_v in [0, 1)) or "singularity" (S = max(S_v, S_w) of
        :func:`engine.phasor.singularity.singularity_slice`, in-plane gradient,
        inf where G vanishes; numpy only)
    engine : "gpu" or "numpy", as :func:`engine.phasor.infill.slice_noise`
    progress : callable(done, total) -> bool or None; False cancels
        (:class:`engine.progress.Cancelled`)

    Returns
    -------
    values : (H, W) float64
    engine : "gpu" | "numpy", what ran
    """
    from engine.phasor.infill import slice_noise
    from engine.phasor.noise import diamond_mask, sawtooth

    if show not in PATTERNS:
        raise ValueError(f"show: expected one of {', '.join(PATTERNS)}, got {show!r}")
    if show == "singularity":
        from engine.phasor.singularity import singularity_slice
        kernels, filtered = infill.noise()
        s_v, s_w = singularity_slice(kernels, plane, fields=infill.fields, filtered=filtered,
                                     filter_scale=infill.filter_scale,
                                     attenuation=infill.attenuation if filtered else None,
                                     progress=progress)
        return np.maximum(s_v, s_w), "numpy"
    g_v, g_w, used = slice_noise(infill, plane, engine=engine, progress=progress)
    p_v = sawtooth(np.asarray(g_v, np.complex128))
    if show == "p_v":
        return p_v, used
    return diamond_mask(p_v, sawtooth(np.asarray(g_w, np.complex128))).astype(np.float64), used


# ------------------------------------------------------------------- the part

def domain_slice(domain, plane: SlicePlane) -> np.ndarray | None:
    """(H, W) bool: pixels of an axis-aligned ``plane`` inside the part; None without one.

    ``domain`` is None or a closed mesh (anything with ``vertices`` and ``faces``, or a
    ``(vertices, faces)`` pair), cut by :func:`engine.phasor.domain.slice_domain`.
    """
    if domain is None:
        return None
    from engine.phasor.domain import slice_domain

    n = int(np.argmax(np.abs(np.cross(plane.u_axis, plane.v_axis))))
    ext = plane_extent(plane)
    return slice_domain(domain, AXES[n], float(plane.origin[n]), lo=ext[:, 0], hi=ext[:, 1],
                        shape=plane.shape)


def mask_outline(mask, extent) -> np.ndarray:
    """(m, 2, 2) in-plane mm segments along the pixel edges between inside and outside.

    ``mask`` (H, W) bool with row i along v, column j along u; ``extent``
    ``((u0, u1), (v0, v1))`` mm.  Pixels beyond the image count as outside.
    """
    m = np.pad(np.asarray(mask, dtype=bool), 1)
    h, w = m.shape[0] - 2, m.shape[1] - 2
    ext = np.asarray(extent, dtype=np.float64)
    du, dv = (ext[0, 1] - ext[0, 0]) / w, (ext[1, 1] - ext[1, 0]) / h
    # vertical edges: between columns j-1 and j (j = 0..W), rows i
    vi, vj = np.nonzero(m[1:-1, :-1] != m[1:-1, 1:])
    # horizontal edges: between rows i-1 and i, columns j
    hi_, hj = np.nonzero(m[:-1, 1:-1] != m[1:, 1:-1])
    a = np.concatenate([np.stack([vj, vi], 1), np.stack([hj, hi_], 1)]).astype(np.float64)
    b = np.concatenate([np.stack([vj, vi + 1], 1), np.stack([hj + 1, hi_], 1)]).astype(np.float64)
    seg = np.stack([a, b], axis=1)
    seg[..., 0] = ext[0, 0] + seg[..., 0] * du
    seg[..., 1] = ext[1, 0] + seg[..., 1] * dv
    return seg


# ------------------------------------------------------------------- G-code

class GcodePreview(NamedTuple):
    """Coloured line segments of a G-code file, part coordinates.

    points : (n, 3) float64 mm; segments : (m, 2) int64 into points;
    colours : (m, 3) uint8 RGB; layer : (m,) int32; layers : list of GcodeLayer
    """
    points: np.ndarray
    segments: np.ndarray
    colours: np.ndarray
    layer: np.ndarray
    layers: list


def gcode_preview(path, *, offset=None, travel=False, every=1) -> GcodePreview:
    """Read the extruding paths of a G-code file as coloured lines.

    ``offset`` (2,) mm is the part's placement on the bed that the writer added
    (default: :class:`engine.fab.PrintSettings`' default offset).
    """
    from engine.fab import KIND_COLOURS, PrintSettings, layer_preview_lines, read_gcode_paths

    if offset is None:
        offset = PrintSettings().offset
    try:
        layers = read_gcode_paths(path, offset=offset)
    except OSError as err:
        raise ValueError(f"G-code {str(path)!r}: cannot read ({err.strerror or err})") from None
    lines = layer_preview_lines(layers, travel=travel, every=every)
    return GcodePreview(lines.points, lines.segments, KIND_COLOURS[lines.kinds], lines.layer, layers)
