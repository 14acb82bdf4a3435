"""A layer's toolpaths: perimeter loops and frontier walls in print order."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .contours import frontier_walls, perimeter_loops
from .ordering import order_paths
from .print_settings import PrintSettings

PERIMETER = "perimeter"
INFILL = "infill"
KINDS = (PERIMETER, INFILL)

# Defaults as fractions of the nozzle diameter.
MIN_SPACING_FRACTION = 0.1     # merge vertices closer than this
MIN_LENGTH_FRACTION = 0.5      # drop wall pieces shorter than this


@dataclass(frozen=True, eq=False)
class Layer:
    """Extrusion paths of one layer, in print order.

    Attributes
    ----------
    z : float
        mm, height of the nozzle tip (top of the layer).
    paths : tuple of (m, 2) float64
        mm, part coordinates; read-only arrays.
    kinds : tuple of str
        ``"perimeter"`` or ``"infill"`` per path.
    """

    z: float
    paths: tuple
    kinds: tuple

    def __post_init__(self):
        paths = []
        for p in self.paths:
            a = np.array(p, dtype=np.float64)
            if a.ndim != 2 or a.shape[1] != 2 or len(a) < 2:
                raise ValueError(f"each path must be an (m >= 2, 2) array, got shape {a.shape}")
            a.flags.writeable = False
            paths.append(a)
        kinds = tuple(self.kinds)
        if len(kinds) != len(paths):
            raise ValueError(f"{len(kinds)} kinds given for {len(paths)} paths")
        bad = sorted(set(kinds) - set(KINDS))
        if bad:
            raise ValueError(f"unknown path kinds {bad}; expected {KINDS}")
        object.__setattr__(self, "paths", tuple(paths))
        object.__setattr__(self, "kinds", kinds)
        object.__setattr__(self, "z", float(self.z))

    def __len__(self):
        return len(self.paths)

    @property
    def extrusion_length(self) -> float:
        """Total length of the extruded paths, mm."""
        return float(sum(np.hypot(*np.diff(p, axis=0).T).sum() for p in self.paths))

    @property
    def end_point(self):
        """Last nozzle position of the layer, or None when it is empty."""
        return self.paths[-1][-1] if self.paths else None


def layer_walls(image, domain=None, *, origin=(0.0, 0.0), pixel_size, settings=None,
                tolerance=None, min_spacing=None, min_length=None):
    """Unordered perimeter loops and infill walls of one layer.

    Parameters
    ----------
    image : (H, W) bool
        Black/white cells of the slice (see :mod:`engine.fab.contours` for
        the pixel convention).
    domain : (H, W) bool or None
        Inside of the part; None means the whole image.
    origin : (2,) float
        mm, centre of pixel ``[0, 0]``.
    pixel_size : float
        mm per pixel.
    settings : PrintSettings or None
        Nozzle diameter and perimeter count; defaults when None.
    tolerance : float or None
        Douglas-Peucker tolerance, mm; default ``pixel_size / 2``.
    min_spacing, min_length : float or None
        mm; defaults ``0.1`` and ``0.5`` nozzle diameters.

    Returns
    -------
    perimeters, infill : list of (m, 2) float64
        Infill walls stop at the inner edge of the innermost perimeter (half
        a line width inside the part when there is no perimeter), so their
        ends overlap the perimeter bead by half a line width.
    """
    settings = settings or PrintSettings()
    w = settings.line_width
    if min_spacing is None:
        min_spacing = MIN_SPACING_FRACTION * w
    if min_length is None:
        min_length = MIN_LENGTH_FRACTION * w
    opts = dict(origin=origin, pixel_size=pixel_size, tolerance=tolerance,
                min_spacing=min_spacing)
    perims = perimeter_loops(domain if domain is not None else np.ones(np.shape(image), bool),
                             line_width=w, perimeters=settings.perimeters,
                             min_length=min_length, **opts)
    inset = w * max(settings.perimeters, 0.5)
    walls = frontier_walls(image, domain, inset=inset, min_length=min_length, **opts)
    return perims, walls


def order_layer(perimeters, infill, *, z, settings=None, start=(0.0, 0.0), order=True):
    """A :class:`Layer` from unordered paths.

    Perimeters come first (or last when ``settings.perimeters_first`` is
    False); each group is ordered by :func:`engine.fab.ordering.order_paths`
    starting where the previous group ended. ``order=False`` keeps the
    given order and directions.
    """
    settings = settings or PrintSettings()
    groups = [(perimeters, PERIMETER), (infill, INFILL)]
    if not settings.perimeters_first:
        groups.reverse()
    paths, kinds = [], []
    pos = start
    for group, kind in groups:
        ordered = order_paths(group, start=pos) if order else list(group)
        if ordered:
            pos = ordered[-1][-1]
        paths.extend(ordered)
        kinds.extend([kind] * len(ordered))
    return Layer(z=z, paths=tuple(paths), kinds=tuple(kinds))


def layer_toolpaths(image, domain=None, *, z, origin=(0.0, 0.0), pixel_size, settings=None,
                    start=(0.0, 0.0), order=True, tolerance=None, min_spacing=None,
                    min_length=None):
    """Toolpaths of one layer from its binary image: walls, then print order.

    See :func:`layer_walls` for the parameters; ``z`` is the layer height in
    mm and ``start`` the nozzle position before the layer (mm, part
    coordinates).

    Returns
    -------
    Layer
    """
    perims, walls = layer_walls(image, domain, origin=origin, pixel_size=pixel_size,
                                settings=settings, tolerance=tolerance,
                                min_spacing=min_spacing, min_length=min_length)
    return order_layer(perims, walls, z=z, settings=settings, start=start, order=order)
