"""Slices to G-code in one pass: per layer image -> toolpaths -> lines."""

from __future__ import annotations

import numpy as np

from .gcode import GcodeSummary, write_gcode
from .print_settings import PrintSettings
from .toolpaths import layer_toolpaths


def _unpack(index, item):
    try:
        z, image, domain, origin, pixel_size = item
    except (TypeError, ValueError):
        raise ValueError(f"layer {index}: expected (z, image, domain, origin, pixel_size), "
                         f"got {type(item).__name__}") from None
    return float(z), image, domain, origin, float(pixel_size)


def layer_stack_toolpaths(layer_images, *, settings=None, order=True, **wall_options):
    """Lazily turn slice images into :class:`~engine.fab.toolpaths.Layer` objects.

    Parameters
    ----------
    layer_images : iterable of (z, image, domain, origin, pixel_size)
        ``z`` mm; ``image`` (H, W) bool black/white cells; ``domain`` (H, W)
        bool inside of the part (or None); ``origin`` (2,) mm centre of pixel
        [0, 0]; ``pixel_size`` mm. Consumed one item at a time, so an image
        can be freed as soon as its toolpaths exist.
    settings : PrintSettings or None
    order : bool
        Order paths for short travel (False keeps contour order).
    **wall_options
        ``tolerance``, ``min_spacing``, ``min_length``
        (see :func:`~engine.fab.toolpaths.layer_walls`).

    Yields
    ------
    Layer
        Each layer starts its ordering where the previous one ended.
    """
    settings = settings or PrintSettings()
    pos = -np.asarray(settings.offset)          # the home position, part coordinates
    for index, item in enumerate(layer_images):
        z, image, domain, origin, pixel_size = _unpack(index, item)
        layer = layer_toolpaths(image, domain, z=z, origin=origin, pixel_size=pixel_size,
                                settings=settings, start=pos, order=order, **wall_options)
        if layer.paths:
            pos = layer.end_point
        yield layer


def layers_to_gcode(layer_images, path, *, settings=None, n_layers=None, progress=None,
                    order=True, **wall_options) -> GcodeSummary:
    """Write the G-code of a stack of slice images.

    Parameters
    ----------
    layer_images : iterable of (z, image, domain, origin, pixel_size)
        See :func:`layer_stack_toolpaths`; bottom layer first.
    path : str or os.PathLike
        Output file, replaced atomically.
    settings : PrintSettings or None
    n_layers : int or None
        Number of layers, for progress (``len(layer_images)`` when available).
    progress : callable or None
        ``progress(done, total) -> bool`` once per layer; False cancels and
        leaves ``path`` untouched.
    order, **wall_options
        See :func:`layer_stack_toolpaths`.

    Returns
    -------
    GcodeSummary
    """
    settings = settings or PrintSettings()
    if n_layers is None and hasattr(layer_images, "__len__"):
        n_layers = len(layer_images)
    layers = layer_stack_toolpaths(layer_images, settings=settings, order=order, **wall_options)
    return write_gcode(layers, path, settings=settings, n_layers=n_layers, progress=progress)
