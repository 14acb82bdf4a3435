"""Wall polylines of one layer from its binary image (Tricard et al. §3.3).

Each frontier between black and white cells becomes a single thin wall: the
0.5 iso-line of the binary image, restricted to the part. The part outline
gives the perimeter loops, iso-lines of the distance inside the part.

Pixel convention: ``image[i, j]`` is the pixel centred at
``(origin[0] + j * pixel_size, origin[1] + i * pixel_size)`` mm, so rows run
along y and columns along x. The part boundary lies half way between an
inside and an outside pixel centre; the part is taken to end at the image
border.
"""

from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict

import numpy as np

from ._polyline import clip_simplify, flatten, split_flat

_CACHE_SIZE = 4
_cache: "OrderedDict[tuple, np.ndarray]" = OrderedDict()
_cache_lock = threading.Lock()


def _check_layer_inputs(image, domain, pixel_size, origin):
    image = np.asarray(image)
    if image.ndim != 2:
        raise ValueError(f"image must be a 2D (H, W) array, got shape {image.shape}")
    if domain is None:
        domain = np.ones(image.shape, bool)
    domain = np.asarray(domain, dtype=bool)
    if domain.shape != image.shape:
        raise ValueError(f"domain shape {domain.shape} differs from image shape {image.shape}")
    if not (np.isfinite(pixel_size) and pixel_size > 0):
        raise ValueError(f"pixel_size must be a positive length in mm, got {pixel_size!r}")
    origin = np.asarray(origin, dtype=np.float64).reshape(-1)
    if origin.shape != (2,) or not np.all(np.isfinite(origin)):
        raise ValueError(f"origin must be two finite numbers (x, y) in mm, got {origin!r}")
    return image.astype(bool, copy=False), domain, float(pixel_size), origin


def _crop(image, domain, origin, pixel_size):
    """Image and domain cut to the domain's bounding box plus one pixel."""
    rows = np.flatnonzero(domain.any(axis=1))
    cols = np.flatnonzero(domain.any(axis=0))
    i0, i1 = max(rows[0] - 1, 0), min(rows[-1] + 2, domain.shape[0])
    j0, j1 = max(cols[0] - 1, 0), min(cols[-1] + 2, domain.shape[1])
    origin = origin + np.array([j0, i0]) * pixel_size
    return image[i0:i1, j0:j1], domain[i0:i1, j0:j1], origin


def inside_distance(domain, *, pixel_size):
    """Distance inside the part, mm, on the domain padded by one outside pixel.

    Parameters
    ----------
    domain : (H, W) bool
        True inside the part.
    pixel_size : float
        mm per pixel.

    Returns
    -------
    dist : (H + 2, W + 2) float64, read-only
        ``d - pixel_size / 2`` inside, ``-pixel_size / 2`` outside, where
        ``d`` is the Euclidean distance to the nearest outside pixel centre;
        the zero level is the part boundary. Cached on the mask content.
    """
    from scipy.ndimage import distance_transform_edt

    domain = np.ascontiguousarray(domain, dtype=bool)
    key = (domain.shape, float(pixel_size),
           hashlib.blake2b(np.packbits(domain).tobytes(), digest_size=16).digest())
    with _cache_lock:
        hit = _cache.get(key)
        if hit is not None:
            _cache.move_to_end(key)
            return hit
    padded = np.pad(domain, 1)
    dist = (distance_transform_edt(padded) - 0.5) * pixel_size
    dist.flags.writeable = False
    with _cache_lock:
        _cache[key] = dist
        while len(_cache) > _CACHE_SIZE:
            _cache.popitem(last=False)
    return dist


def _to_mm(contours, origin, pixel_size, shift=0.0):
    """(row, col) contour vertices -> flat (x, y) mm array and offsets."""
    flat, offsets = flatten(contours)
    rc = flat - shift
    xy = np.empty_like(rc)
    xy[:, 0] = origin[0] + rc[:, 1] * pixel_size
    xy[:, 1] = origin[1] + rc[:, 0] * pixel_size
    return flat, xy, offsets


def frontier_walls(image, domain=None, *, origin=(0.0, 0.0), pixel_size,
                   inset=0.0, tolerance=None, min_spacing=0.0, min_length=0.0):
    """One wall polyline per black/white frontier inside the part.

    Parameters
    ----------
    image : (H, W) bool
        The layer's cells, black = True.
    domain : (H, W) bool or None
        True inside the part; None means the whole image.
    origin : (2,) float
        mm, centre of pixel ``[0, 0]``.
    pixel_size : float
        mm per pixel; should be below half the wall width.
    inset : float
        mm; walls are cut where they come closer than this to the part
        boundary (cut points interpolated).
    tolerance : float or None
        Douglas-Peucker tolerance in mm; None means ``pixel_size / 2``;
        0 keeps every marching-squares vertex.
    min_spacing : float
        mm; consecutive vertices closer than this are merged.
    min_length : float
        mm; shorter wall pieces are dropped.

    Returns
    -------
    walls : list of (m, 2) float64
        mm; closed walls repeat their first point at the end.
    """
    from scipy.ndimage import map_coordinates
    from skimage.measure import find_contours

    image, domain, pixel_size, origin = _check_layer_inputs(image, domain, pixel_size, origin)
    if tolerance is None:
        tolerance = 0.5 * pixel_size
    if not domain.any():
        return []
    image, domain, origin = _crop(image, domain, origin, pixel_size)
    if image[domain].all() or not image[domain].any():
        return []
    contours = find_contours(image.astype(np.float32), 0.5, mask=domain)
    if not contours:
        return []
    rc, xy, offsets = _to_mm(contours, origin, pixel_size)
    dist = inside_distance(domain, pixel_size=pixel_size)
    vals = map_coordinates(dist, [rc[:, 0] + 1.0, rc[:, 1] + 1.0], order=1, mode="nearest")
    out, out_off = clip_simplify(xy, vals, offsets, float(inset), float(tolerance),
                                 float(min_spacing), float(min_length))
    return split_flat(out, out_off)


def perimeter_loops(domain, *, origin=(0.0, 0.0), pixel_size, line_width, perimeters=1,
                    tolerance=None, min_spacing=0.0, min_length=0.0):
    """Perimeter loops: iso-distance lines ``(k + 1/2) * line_width`` inside.

    Parameters
    ----------
    domain : (H, W) bool
        True inside the part.
    origin, pixel_size : see :func:`frontier_walls`.
    line_width : float
        mm, extrusion width (the nozzle diameter).
    perimeters : int
        Number of loops per outline (outermost first).
    tolerance, min_spacing, min_length : see :func:`frontier_walls`.

    Returns
    -------
    loops : list of (m, 2) float64
        Closed polylines in mm (first point repeated at the end), ordered by
        depth: every loop at ``line_width / 2`` first.
    """
    from skimage.measure import find_contours

    dummy = np.zeros(np.shape(domain), bool)
    _, domain, pixel_size, origin = _check_layer_inputs(dummy, domain, pixel_size, origin)
    if tolerance is None:
        tolerance = 0.5 * pixel_size
    if not domain.any() or perimeters <= 0:
        return []
    _, domain, origin = _crop(domain, domain, origin, pixel_size)
    dist = inside_distance(domain, pixel_size=pixel_size)
    loops = []
    for k in range(int(perimeters)):
        level = (k + 0.5) * line_width
        if dist.max() <= level:
            break
        contours = find_contours(dist, level)
        if not contours:
            break
        _, xy, offsets = _to_mm(contours, origin, pixel_size, shift=1.0)
        vals = np.full(len(xy), np.inf)
        out, out_off = clip_simplify(xy, vals, offsets, 0.0, float(tolerance),
                                     float(min_spacing), float(min_length))
        loops.extend(split_flat(out, out_off))
    return loops
