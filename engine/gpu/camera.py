"""A pinhole camera: the primary rays of an image, in numpy and in GLSL.

Pixel convention (shared by `Camera.rays` and `CAMERA_GLSL`)
------------------------------------------------------------
Pixel ``[row i, column j]`` of a ``height x width`` image (row 0 at the
top, column 0 on the left) looks along

    normalize(forward + x right + y up),
    x = (2 (j + 0.5) / width - 1) tan(fov / 2) width / height,
    y = (1 - 2 (i + 0.5) / height) tan(fov / 2),

where ``forward`` points from the eye to the target, ``right = forward x
up`` and ``up`` is the given up vector made orthogonal to ``forward`` (all
unit).  ``fov_deg`` is the vertical field of view between the top and the
bottom edge of the image.  Every ray starts at the eye.

CLI form
--------
``"EX,EY,EZ,TX,TY,TZ,FOV_DEG"``: eye and target in mm, vertical field of
view in degrees (`parse_camera`, `format_camera`).  The form has no up
vector: +z is up, or +y when the view is along z.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Camera", "parse_camera", "format_camera", "CAMERA_GLSL"]

CAMERA_GLSL = """uniform vec3 u_cam_eye;
uniform vec3 u_cam_forward;
uniform vec3 u_cam_right;   // unit right * tan(fov / 2) * width / height
uniform vec3 u_cam_up;      // unit up * tan(fov / 2)
uniform ivec2 u_cam_size;   // (width, height) in pixels

vec3 camera_ray(ivec2 pixel) {   // pixel = (column, row from the top)
    vec2 s = (vec2(pixel) + 0.5) / vec2(u_cam_size);
    return normalize(u_cam_forward + (2.0 * s.x - 1.0) * u_cam_right + (1.0 - 2.0 * s.y) * u_cam_up);
}
"""


def _vector(name: str, value) -> np.ndarray:
    v = np.array(value, dtype=np.float64).reshape(-1)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise ValueError(f"camera {name}: expected 3 finite numbers, got {value!r}")
    v.setflags(write=False)
    return v


def _image_size(width, height) -> tuple[int, int]:
    for name, n in (("width", width), ("height", height)):
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 1 <= n <= 16384:
            raise ValueError(f"image {name}: expected an integer number of pixels in 1..16384, got {n!r}")
    return int(width), int(height)


@dataclass(frozen=True, eq=False)
class Camera:
    """A pinhole camera at `eye` looking at `target`.

    Attributes
    ----------
    eye, target : (3,) float64, mm; distinct points
    up : (3,) float64, the image's up direction (made orthogonal to the view;
        must not be parallel to it); default +z
    fov_deg : float, vertical field of view in degrees, in (0, 180)
    """

    eye: np.ndarray
    target: np.ndarray
    up: np.ndarray = (0.0, 0.0, 1.0)
    fov_deg: float = 40.0

    def __post_init__(self):
        eye, target, up = (_vector(n, getattr(self, n)) for n in ("eye", "target", "up"))
        view = target - eye
        dist = float(np.linalg.norm(view))
        if not dist > 1e-9 * max(1.0, float(np.abs(eye).max())):
            raise ValueError(f"camera target must differ from the eye, both are {eye.tolist()}")
        up_norm = float(np.linalg.norm(up))
        if up_norm == 0.0 or np.linalg.norm(np.cross(view / dist, up / up_norm)) < 1e-6:
            raise ValueError(f"camera up {up.tolist()} must be non-zero and not parallel to the view "
                             f"direction {(view / dist).tolist()}")
        fov = self.fov_deg
        if isinstance(fov, bool) or not isinstance(fov, (int, float, np.number)) \
                or not (math.isfinite(fov) and 0.0 < fov < 180.0):
            raise ValueError(f"camera fov_deg: expected a vertical field of view in (0, 180) degrees, "
                             f"got {fov!r}")
        for name, value in (("eye", eye), ("target", target), ("up", up), ("fov_deg", float(fov))):
            object.__setattr__(self, name, value)

    def basis(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(forward, right, up): orthonormal (3,) float64, right-handed as ``right = forward x up``."""
        forward = self.target - self.eye
        forward = forward / np.linalg.norm(forward)
        right = np.cross(forward, self.up)
        right /= np.linalg.norm(right)
        return forward, right, np.cross(right, forward)

    def rays(self, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
        """Primary rays of a ``height x width`` image.

        Returns
        -------
        origins : (height, width, 3) float64, mm (the eye, repeated)
        directions : (height, width, 3) float64, unit vectors (module docstring
            gives the pixel convention)

        Raises
        ------
        ValueError
            If `width` or `height` is not an integer in 1..16384.
        """
        w, h = _image_size(width, height)
        forward, right, up = self.basis()
        tan_half = math.tan(math.radians(self.fov_deg) / 2.0)
        x = (2.0 * (np.arange(w) + 0.5) / w - 1.0) * tan_half * w / h
        y = (1.0 - 2.0 * (np.arange(h) + 0.5) / h) * tan_half
        d = forward + x[None, :, None] * right + y[:, None, None] * up
        d /= np.linalg.norm(d, axis=2, keepdims=True)
        return np.broadcast_to(self.eye, d.shape).copy(), d

    def glsl_uniforms(self, width: int, height: int) -> dict:
        """Values of the uniforms declared in `CAMERA_GLSL` for a ``height x width`` image.

        Returns
        -------
        dict uniform name -> tuple (float vec3s, int ivec2), to assign to a
        moderngl program's members.
        """
        w, h = _image_size(width, height)
        forward, right, up = self.basis()
        tan_half = math.tan(math.radians(self.fov_deg) / 2.0)
        return {"u_cam_eye": tuple(self.eye), "u_cam_forward": tuple(forward),
                "u_cam_right": tuple(right * tan_half * w / h), "u_cam_up": tuple(up * tan_half),
                "u_cam_size": (w, h)}

    def format(self) -> str:
        """This camera in the CLI form (the up vector is not written)."""
        return format_camera(self)


def parse_camera(text: str) -> Camera:
    """A `Camera` from ``"EX,EY,EZ,TX,TY,TZ,FOV_DEG"`` (mm, mm, degrees; spaces allowed).

    Up is +z, or +y if the view is (nearly) along z.

    Raises
    ------
    ValueError
        If `text` is not seven comma-separated finite numbers, the eye equals
        the target, or the field of view is outside (0, 180) degrees.
    """
    form = "EX,EY,EZ,TX,TY,TZ,FOV_DEG"
    if not isinstance(text, str):
        raise ValueError(f"camera: expected a string {form!r}, got {type(text).__name__}")
    parts = text.split(",")
    if len(parts) != 7:
        raise ValueError(f"camera {text!r}: expected 7 comma-separated numbers {form}, got {len(parts)}")
    try:
        values = [float(p) for p in parts]
    except ValueError:
        raise ValueError(f"camera {text!r}: expected 7 numbers {form}, found a non-number") from None
    if not all(math.isfinite(v) for v in values):
        raise ValueError(f"camera {text!r}: the numbers must be finite")
    eye, target, fov = np.array(values[:3]), np.array(values[3:6]), values[6]
    view = target - eye
    norm = float(np.linalg.norm(view))
    up = (0.0, 0.0, 1.0)
    if norm > 0 and abs(view[2]) / norm > 1.0 - 1e-9:
        up = (0.0, 1.0, 0.0)
    return Camera(eye, target, up, fov)


def format_camera(camera: Camera) -> str:
    """`camera` as ``"EX,EY,EZ,TX,TY,TZ,FOV_DEG"`` (shortest round-tripping numbers; no up vector).

    Raises
    ------
    ValueError
        If `camera` is not a `Camera`.
    """
    if not isinstance(camera, Camera):
        raise ValueError(f"camera: expected a Camera, got {type(camera).__name__}")
    return ",".join(repr(float(v)) for v in (*camera.eye, *camera.target, camera.fov_deg))
