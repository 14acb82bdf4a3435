"""Analysis by synthesis: fit an SDF's parameters to an image by rendering (paper 004, 6.2, 12.2).

Eq. 38 (lost in extraction; this is the form the prose describes): find the
parameters x in the box of a `ParamSpace` minimising

    L(R(make(x), camera), target)

where R sphere-traces the SDF from one fixed view (`engine.gpu.sphere_trace.render`,
here at the target's size) and L is eq. 39, the log MSE of the 2D DFT
amplitudes of the render and the target (`engine.implicit.fourier_loss.image_loss`,
eps `IMAGE_EPS`), optionally plus ``ssim_weight (1 - SSIM)``.  The renderer
is not differentiable, so the paper uses the gradient-free CMA-ES and Powell;
the gradient methods of `engine.implicit.reconstruct` are allowed too (their
finite differences see the render's pixel steps).  The optimiser core is
`engine.implicit.reconstruct.minimise` (budgets, progress, cancel, the best
point seen); an exact match (the loss at ``log IMAGE_EPS``) stops the fit
with "converged".

Images are float64 in [0, 1], (h, w) grey or (h, w, c) with c = 3 (RGB) or
4 (RGBA): uint8 is divided by 255, uint16 by 65535, bool is 0 / 1, floats
are taken as they are.  A render is compared in the target's layout: its
RGB (black where a ray missed), its RGBA (alpha 1 on a hit, 0 on a miss), or
for a grey target its luma ``0.299 R + 0.587 G + 0.114 B`` (PIL's "L").
SSIM uses a data range of 1.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from engine.gpu.camera import Camera
from engine.gpu.sphere_trace import SHADINGS, STEP_MODES, render
from engine.implicit.fourier_loss import image_loss
from engine.implicit.reconstruct import FitResult, ParamSpace, minimise

__all__ = ["fit_image", "render_image", "load_image_exemplar", "as_image", "IMAGE_EPS", "LUMA"]

IMAGE_EPS = 1e-8                       # the eps of eq. 39 used by fit_image
LUMA = (0.299, 0.587, 0.114)           # grey = LUMA . rgb (ITU-R BT.601, as PIL's "L" mode)
MAX_SIDE = 16384                       # the renderer's largest frame side


def as_image(array, source: str = "image") -> np.ndarray:
    """`array` as a float64 image in [0, 1] (module docstring), (h, w) or (h, w, 3 | 4).

    A (h, w, 1) array becomes (h, w).

    Raises
    ------
    ValueError
        Naming `source`: not 2D or 3D, a channel count other than 1, 3 or 4, a side
        below 2 or above 16384 pixels, an unsupported dtype, non-finite floats or
        integers outside 0..65535.
    """
    a = np.asarray(array)
    if a.ndim == 3 and a.shape[2] == 1:
        a = a[..., 0]
    if a.ndim not in (2, 3) or (a.ndim == 3 and a.shape[2] not in (3, 4)):
        raise ValueError(f"{source}: an image must be (h, w) grey or (h, w, 3 | 4) RGB(A), "
                         f"got shape {a.shape}")
    if not (2 <= min(a.shape[:2]) and max(a.shape[:2]) <= MAX_SIDE):
        raise ValueError(f"{source}: image sides must be 2..{MAX_SIDE} pixels, got shape {a.shape}")
    if a.dtype == np.bool_:
        return a.astype(np.float64)
    if a.dtype == np.uint8:
        return a.astype(np.float64) / 255.0
    if a.dtype.kind in "iu":
        if a.min() < 0 or a.max() > 65535:
            raise ValueError(f"{source}: integer pixels must be 8 or 16 bit (0..65535), "
                             f"got {a.min()}..{a.max()} ({a.dtype})")
        return a.astype(np.float64) / 65535.0
    if a.dtype.kind == "f":
        if not np.all(np.isfinite(a)):
            raise ValueError(f"{source}: pixels hold NaN or infinite values")
        return a.astype(np.float64)
    raise ValueError(f"{source}: pixels must be numbers (uint8, uint16, float), got dtype {a.dtype}")


def _layout(rgba: np.ndarray, channels: int) -> np.ndarray:
    """A (h, w, 4) uint8 render in the layout of a target with `channels` (0: grey)."""
    img = rgba.astype(np.float64) / 255.0
    if channels == 0:
        return img[..., :3] @ np.array(LUMA)
    return img[..., :channels]


def render_image(sdf, camera: Camera, width: int, height: int, channels: int = 0, *,
                 step: str = "fixed", shading: str = "lambert", bounds=None, check=None) -> np.ndarray:
    """One render as `fit_image` compares it: (height, width) grey (channels 0) or (h, w, 3 | 4).

    Raises
    ------
    ValueError
        As `render`, or for channels not in (0, 3, 4).
    """
    if channels not in (0, 3, 4):
        raise ValueError(f"channels must be 0 (grey), 3 (RGB) or 4 (RGBA), got {channels!r}")
    frame = render(sdf, camera, width, height, step=step, shading=shading, bounds=bounds, check=check)
    return _layout(frame.rgba, channels)


def fit_image(space: ParamSpace, target, camera: Camera, algorithm: str = "cmaes", budget_s: float = 60.0,
              *, step: str = "fixed", shading: str = "lambert", ssim_weight: float = 0.0, bounds=None,
              x0=None, seed: int = 0, progress=None, check=None, max_evaluations: int | None = None,
              options: dict | None = None) -> FitResult:
    """Fit `space`'s parameters so that the render of ``make(x)`` looks like `target` (eq. 38-39).

    Parameters
    ----------
    space : ParamSpace with a `make`.
    target : (h, w), (h, w, 1), (h, w, 3) or (h, w, 4) uint8 / uint16 / float image (`as_image`).
    camera : Camera, the fixed view the target was taken from.
    algorithm : one of `engine.implicit.reconstruct.ALGORITHMS` (the paper: "cmaes", "powell").
    budget_s : float > 0, seconds of wall time at most (checked before each render).
    step, shading, bounds : passed to `render` (bounds None: each SDF's `box()`).
    ssim_weight : float >= 0, weight of ``1 - SSIM`` added to eq. 39 (needs h, w >= 7).
    x0, seed, progress, check, max_evaluations, options : as for `minimise`; `check` is
        also called between the render's tiles.

    Returns
    -------
    FitResult (loss: eq. 39 of the best render seen).

    Raises
    ------
    ValueError
        On a target of the wrong shape or dtype, a camera that is not a Camera, an unknown
        step or shading, a negative ssim_weight (or SSIM on an image below 7 x 7), a space
        without `make`, and everything `minimise` refuses (budget_s <= 0, ...).
    """
    if not isinstance(space, ParamSpace):
        raise ValueError(f"space must be a ParamSpace, got {type(space).__name__}")
    if space.make is None:
        raise ValueError("space has no make(values) -> SDF to fit")
    tgt = as_image(target, "target")
    if not isinstance(camera, Camera):
        raise ValueError(f"camera must be an engine.gpu.camera.Camera, got {type(camera).__name__}")
    if step not in STEP_MODES:
        raise ValueError(f"step must be one of {STEP_MODES}, got {step!r}")
    if shading not in SHADINGS:
        raise ValueError(f"shading must be one of {SHADINGS}, got {shading!r}")
    w_ssim = float(ssim_weight)
    if not (math.isfinite(w_ssim) and w_ssim >= 0):
        raise ValueError(f"ssim_weight must be a finite number >= 0, got {ssim_weight!r}")
    if w_ssim > 0 and min(tgt.shape[:2]) < 7:
        raise ValueError(f"SSIM (ssim_weight > 0) needs a target of at least 7 x 7 pixels, got {tgt.shape}")
    h, w = tgt.shape[:2]
    channels = 0 if tgt.ndim == 2 else tgt.shape[2]

    def objective(x):
        img = render_image(space.sdf(x), camera, w, h, channels, step=step, shading=shading,
                           bounds=bounds, check=check)
        return image_loss(img, tgt, eps=IMAGE_EPS, ssim_weight=w_ssim, data_range=1.0)

    floor = math.log(IMAGE_EPS) + 1e-12        # identical amplitude spectra (and SSIM 1)
    return minimise(objective, space, algorithm, budget_s, x0=x0, seed=seed, progress=progress,
                    check=check, max_evaluations=max_evaluations, options=options, floor=floor)


def load_image_exemplar(path) -> np.ndarray:
    """A target image from a file: float64 in [0, 1], (h, w) grey or (h, w, 3 | 4) (`as_image`).

    * ``.png`` (and ``.jpg`` / ``.jpeg`` / ``.bmp``) through PIL: modes 1, L, I;16, I, F,
      RGB, RGBA; a palette image is expanded to RGB (RGBA if it has transparency), CMYK,
      YCbCr, LAB and HSV are converted to RGB;
    * ``.tif`` / ``.tiff`` through tifffile: one page, (h, w) or (h, w, 1 | 3 | 4).

    Raises
    ------
    ValueError
        Naming the file: an unknown suffix, a missing or unreadable file, a shape that is
        not a grey or RGB(A) image (e.g. a TIFF stack, two channels), or bad pixels.
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix not in (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff"):
        raise ValueError(f"{p}: unknown image format {p.suffix!r}, expected .png, .tif or .tiff "
                         f"(or .jpg, .bmp)")
    if not p.is_file():
        raise ValueError(f"{p}: no such file")
    try:
        if suffix in (".tif", ".tiff"):
            import tifffile
            array = np.asarray(tifffile.imread(str(p)))
        else:
            from PIL import Image
            with Image.open(p) as im:
                if im.mode == "P":
                    im = im.convert("RGBA" if "transparency" in im.info else "RGB")
                elif im.mode in ("CMYK", "YCbCr", "LAB", "HSV"):
                    im = im.convert("RGB")
                array = np.asarray(im)
    except Exception as exc:              # a corrupt file: name it, keep the reader's reason
        raise ValueError(f"{p}: cannot read it ({type(exc).__name__}: {exc})") from None
    return as_image(array, str(p))
