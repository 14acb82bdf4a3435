"""A rectangular planar slice through the part, sampled on a pixel grid."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# In-plane axes of the axis-aligned slices: columns run along the first,
# rows along the second.
_IN_PLANE = {0: (1, 2), 1: (0, 2), 2: (0, 1)}
_AXIS_NAMES = {"x": 0, "y": 1, "z": 2}


def _frozen(a, dtype=np.float64) -> np.ndarray:
    out = np.array(a, dtype=dtype, copy=True)
    out.setflags(write=False)
    return out


@dataclass(frozen=True, eq=False)
class SlicePlane:
    """A W x H pixel grid on a plane, in mm.

    Pixel ``[row i, column j]`` has its centre at
    ``origin + (j + 0.5) * pixel_u + (i + 0.5) * pixel_v`` where
    ``pixel_u = u_axis * size[0] / W`` and ``pixel_v = v_axis * size[1] / H``.

    Attributes
    ----------
    origin : (3,) float64, mm, outer corner of pixel [0, 0]
    u_axis, v_axis : (3,) float64, orthonormal in-plane directions of the
        columns and the rows
    size : (2,) float64, mm, width (along u) and height (along v)
    resolution : (2,) int64, pixels (W, H)
    """

    origin: np.ndarray
    u_axis: np.ndarray
    v_axis: np.ndarray
    size: np.ndarray
    resolution: np.ndarray

    def __post_init__(self):
        origin = np.asarray(self.origin, dtype=np.float64)
        if origin.shape != (3,) or not np.all(np.isfinite(origin)):
            raise ValueError(f"slice origin: expected 3 finite numbers (mm), got {self.origin!r}")
        axes = []
        for name in ("u_axis", "v_axis"):
            a = np.asarray(getattr(self, name), dtype=np.float64)
            norm = np.linalg.norm(a) if a.shape == (3,) else 0.0
            if not np.isfinite(norm) or norm < 1e-12:
                raise ValueError(f"slice {name}: expected a non-zero 3-vector, got {getattr(self, name)!r}")
            axes.append(a / norm)
        if abs(float(axes[0] @ axes[1])) > 1e-6:
            raise ValueError(f"slice axes must be orthogonal; u.v = {float(axes[0] @ axes[1]):.3g}")
        size = np.asarray(self.size, dtype=np.float64)
        if size.shape != (2,) or not np.all(np.isfinite(size)) or np.any(size <= 0):
            raise ValueError(f"slice size: expected 2 positive lengths (mm), got {self.size!r}")
        res = np.asarray(self.resolution)
        if res.shape != (2,) or np.any(res < 1) or np.any(res != np.round(res)):
            raise ValueError(f"slice resolution: expected 2 positive pixel counts (W, H), got {self.resolution!r}")
        for name, value, dtype in (("origin", origin, np.float64), ("u_axis", axes[0], np.float64),
                                   ("v_axis", axes[1], np.float64), ("size", size, np.float64),
                                   ("resolution", res, np.int64)):
            object.__setattr__(self, name, _frozen(value, dtype))

    @classmethod
    def axis_aligned(cls, axis, position, pixel_size, extent) -> "SlicePlane":
        """A slice normal to a coordinate axis.

        Parameters
        ----------
        axis : {"x", "y", "z"} or {0, 1, 2}
            The slice normal.  In-plane (columns, rows) run along
            (y, z) for x, (x, z) for y and (x, y) for z.
        position : float, mm, coordinate of the plane along ``axis``
        pixel_size : float, mm
        extent : ((u0, u1), (v0, v1)), mm, ranges of the two in-plane
            coordinates; the pixel counts are ``round((u1 - u0) / pixel_size)``
            (at least 1) and the covered size is adjusted to whole pixels.
        """
        a = _AXIS_NAMES.get(axis, axis) if isinstance(axis, str) else axis
        if a not in _IN_PLANE:
            raise ValueError(f"slice axis: expected 'x', 'y', 'z' or 0, 1, 2, got {axis!r}")
        pixel_size = float(pixel_size)
        if not np.isfinite(pixel_size) or pixel_size <= 0:
            raise ValueError(f"slice pixel_size: expected a positive length in mm, got {pixel_size!r}")
        ext = np.asarray(extent, dtype=np.float64)
        if ext.shape != (2, 2) or np.any(ext[:, 1] <= ext[:, 0]):
            raise ValueError(f"slice extent: expected ((u0, u1), (v0, v1)) with u1 > u0 and v1 > v0, "
                             f"got {extent!r}")
        res = np.maximum(1, np.round((ext[:, 1] - ext[:, 0]) / pixel_size)).astype(np.int64)
        iu, iv = _IN_PLANE[a]
        origin = np.zeros(3)
        origin[a] = float(position)
        origin[iu], origin[iv] = ext[0, 0], ext[1, 0]
        return cls(origin, np.eye(3)[iu], np.eye(3)[iv], res * pixel_size, res)

    @property
    def shape(self) -> tuple:
        """Output array shape ``(H, W)``."""
        return int(self.resolution[1]), int(self.resolution[0])

    @property
    def pixel_u(self) -> np.ndarray:
        """(3,) float64, mm, step from one column to the next."""
        return self.u_axis * (self.size[0] / self.resolution[0])

    @property
    def pixel_v(self) -> np.ndarray:
        """(3,) float64, mm, step from one row to the next."""
        return self.v_axis * (self.size[1] / self.resolution[1])

    def points(self, rows=None, cols=None) -> np.ndarray:
        """Pixel centres, (H, W, 3) float64 mm (or the given index ranges)."""
        h, w = self.shape
        i = np.arange(h, dtype=np.float64) if rows is None else np.asarray(rows, np.float64)
        j = np.arange(w, dtype=np.float64) if cols is None else np.asarray(cols, np.float64)
        return (self.origin + (j[None, :, None] + 0.5) * self.pixel_u
                + (i[:, None, None] + 0.5) * self.pixel_v)
