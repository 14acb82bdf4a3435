"""A phasor infill as one bundle, and what is made from it: slices and prints.

:class:`PhasorInfill` holds what every evaluator needs (Tricard et al.,
sections 3-5): the aligned kernels of the two noises, the control fields
they came from, the part, whether slices use the filtered kernels, and the
filter attenuation A(x).  The functions below turn it into

* slice images (the two sawtooth noises, the black diamond cells, the part
  mask) on the GPU shader or the numpy reference,
* the singularity measure and energy of a slice (paper eq. 9-10, by finite
  differences of Arg G as in the paper's analysis),
* the layer images of a print and its G-code (through :mod:`engine.fab`).

Noise states
------------
The same kernels give three noises, compared by the singularity energy:

``"raw"``               phases 0, unfiltered (plain phasor noise, section 3.2)
``"aligned"``           aligned phases, unfiltered (section 4.1)
``"aligned+filtered"``  aligned phases, filtered kernels (section 4.2)

An infill's own state is ``"aligned+filtered"`` when ``filtered`` is set,
else ``"aligned"``.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field

import numpy as np

from .fields import PhasorFields
from .kernels import PhasorKernels

log = logging.getLogger(__name__)

__all__ = ["PhasorInfill", "SliceResult", "sample_infill", "STATES", "ENGINES", "MIN_PIXELS_PER_PERIOD",
           "check_pixel", "slice_plane", "slice_noise", "infill_slice",
           "layer_positions", "print_layers", "write_print"]

STATES = ("raw", "aligned", "aligned+filtered")
ENGINES = ("gpu", "numpy")
# A slice must sample each period of the noise with at least this many pixels
# for the diamonds (and the finite differences of the singularity measure) to mean anything.
MIN_PIXELS_PER_PERIOD = 4.0
SINGULARITY_THRESHOLD = 2.0  # q of F_S(q), as in the paper


@dataclass(frozen=True, eq=False)
class PhasorInfill:
    """Kernels, fields and evaluation options of one phasor infill.

    Attributes
    ----------
    kernels : PhasorKernels, aligned phases
    fields : PhasorFields, D, F, Gamma the kernels were sampled from
    domain : object with ``vertices`` (v, 3) and ``faces`` (f, 3), or None
        The closed part, mm; None fills the whole box of the fields.
    filtered : bool, slices use the filtered kernels (eq. 14)
    filter_scale : float, filter radius in kernel radii
    attenuation : (nz, ny, nx) float64 in [0, 1] or None, A(x) on the fields' cells
    iterations : int, alignment sweeps the phases received
    changed_region : ((3,), (3,)) float64 mm or None
        Where slices may differ from the previous infill of the same node
        after a local update (empty, lo > hi, when nothing changed); None
        when the infill was made from scratch.
    """

    kernels: PhasorKernels
    fields: PhasorFields
    domain: object = None
    filtered: bool = True
    filter_scale: float = 2.0
    attenuation: np.ndarray | None = None
    iterations: int = 0
    changed_region: tuple | None = field(default=None)

    def __post_init__(self):
        if self.attenuation is not None:
            a = np.array(self.attenuation, dtype=np.float64)
            if a.shape != self.fields.shape:
                raise ValueError(f"attenuation: expected the fields' grid {self.fields.shape}, got {a.shape}")
            a.setflags(write=False)
            object.__setattr__(self, "attenuation", a)

    @property
    def state(self) -> str:
        """The infill's own noise state (see module docstring)."""
        return "aligned+filtered" if self.filtered else "aligned"

    def noise(self, state: str | None = None) -> tuple:
        """(kernels, filtered) of a noise state; None = the infill's own."""
        state = self.state if state is None else state
        if state not in STATES:
            raise ValueError(f"state: expected one of {', '.join(STATES)}, got {state!r}")
        if state == "raw":
            zeros = np.zeros(self.kernels.n)
            return self.kernels.with_phases(zeros, zeros), False
        return self.kernels, state == "aligned+filtered"


def sample_infill(fields: PhasorFields, *, domain=None, per_cell: int = 8, c: float = 4.5,
                  iterations: int = 20, filtered: bool = True, filter_scale: float = 2.0, rng=None,
                  progress=None) -> PhasorInfill:
    """A phasor infill from scratch: sample the kernels, align their phases.

    Parameters
    ----------
    fields : PhasorFields
    domain : the closed part (``vertices``, ``faces``) or None
    per_cell, c : kernels per grid cell, kernel radius in periods of F_min
        (:func:`engine.phasor.sampling.sample_kernels`)
    iterations : alignment sweeps (:func:`engine.phasor.align.align_phases`)
    filtered, filter_scale : evaluation options kept on the infill
    rng : int seed or numpy Generator
    progress : callable(done, total) -> bool or None (the alignment); False cancels
    """
    from .align import align_phases
    from .attenuation import attenuation_grid
    from .sampling import sample_kernels

    kernels = sample_kernels(fields, per_cell=per_cell, c=c, rng=rng)
    kernels = align_phases(kernels, iterations=iterations, progress=progress)
    return PhasorInfill(kernels, fields, domain, bool(filtered), float(filter_scale),
                        attenuation_grid(fields, radius=kernels.radius), int(iterations))


# ---------------------------------------------------------------------- slices

def check_pixel(fields: PhasorFields, pixel: float) -> None:
    """Refuse a pixel too coarse for the highest frequency of the fields.

    Raises ValueError naming the pixel size, the highest F and the highest F
    this pixel can resolve (MIN_PIXELS_PER_PERIOD pixels per period).
    """
    if isinstance(pixel, bool) or not isinstance(pixel, (int, float, np.floating)) \
            or not math.isfinite(pixel) or pixel <= 0:
        raise ValueError(f"pixel: expected a positive length in mm, got {pixel!r}")
    f_max = fields.max_frequency()
    resolvable = 1.0 / (MIN_PIXELS_PER_PERIOD * float(pixel))
    if f_max > resolvable * (1 + 1e-12):
        raise ValueError(
            f"pixel {pixel:g} mm is too coarse for F up to {f_max:.4g} cells/mm: a {pixel:g} mm pixel "
            f"resolves F <= {resolvable:.4g} cells/mm ({MIN_PIXELS_PER_PERIOD:g} pixels per period); "
            f"use a pixel <= {1.0 / (MIN_PIXELS_PER_PERIOD * f_max):.4g} mm or lower F")


def slice_plane(fields: PhasorFields, axis: str, position: float, pixel: float):
    """An axis-aligned :class:`engine.gpu.SlicePlane` over the fields' box.

    The rectangle covers the box's extent on the two in-plane axes (u, v
    as in :mod:`engine.phasor.strokes`), rounded to whole pixels.  Raises
    ValueError when ``position`` lies outside the box along ``axis``.
    """
    from engine.gpu.slice_plane import SlicePlane

    from .strokes import PLANE_AXES

    if axis not in PLANE_AXES:
        raise ValueError(f"axis: expected 'x', 'y' or 'z', got {axis!r}")
    u, v, n = PLANE_AXES[axis]
    lo, hi = fields.lo, fields.hi
    if not isinstance(position, (int, float, np.floating)) or not math.isfinite(position) \
            or not lo[n] <= position <= hi[n]:
        raise ValueError(f"position: {axis} = {position!r} mm lies outside the part's box "
                         f"[{lo[n]:.4g}, {hi[n]:.4g}] mm")
    check_pixel(fields, pixel)
    return SlicePlane.axis_aligned(axis, float(position), float(pixel),
                                   ((lo[u], hi[u]), (lo[v], hi[v])))


def _numpy_noise(kernels, plane, *, fields, filtered, filter_scale, attenuation, progress):
    from .noise import phasor_complex, slice_points

    points = slice_points(plane)
    g_v, g_w = phasor_complex(kernels, points, fields=fields, filtered=filtered,
                              filter_scale=filter_scale, attenuation=attenuation, progress=progress)
    return g_v.reshape(plane.shape), g_w.reshape(plane.shape)


def slice_noise(infill: PhasorInfill, plane, *, state: str | None = None, engine: str = "gpu",
                progress=None) -> tuple:
    """The complex noises G_v, G_w (H, W) on ``plane`` for a noise state.

    Parameters
    ----------
    infill : PhasorInfill
    plane : engine.gpu.SlicePlane
    state : one of STATES or None (the infill's own)
    engine : "gpu" (the shader; falls back to numpy, logged, when no EGL
        context can be made) or "numpy" (the float64 reference)
    progress : callable(done, total) -> bool or None; False cancels

    Returns
    -------
    G_v, G_w : (H, W) complex64 (gpu) or complex128 (numpy)
    engine : str, the engine that ran
    """
    if engine not in ENGINES:
        raise ValueError(f"engine: expected one of {', '.join(ENGINES)}, got {engine!r}")
    kernels, filtered = infill.noise(state)
    options = dict(fields=infill.fields, filtered=filtered, filter_scale=infill.filter_scale,
                   attenuation=infill.attenuation if filtered else None, progress=progress)
    if engine == "gpu":
        # looked up on the module at call time (tests replace it: tests/engine/phasor/test_infill.py)
        from engine.gpu import GpuUnavailable
        from engine.phasor import gpu_slice
        try:
            g_v, g_w = gpu_slice.phasor_slice_gpu(kernels, plane, out="complex", **options)
            return g_v, g_w, "gpu"
        except GpuUnavailable as exc:
            log.warning("GPU slice unavailable, using the numpy evaluator: %s", exc)
    g_v, g_w = _numpy_noise(kernels, plane, **options)
    return g_v, g_w, "numpy"


def _inside(infill, plane, axis, position) -> np.ndarray:
    if infill.domain is None:
        return np.ones(plane.shape, dtype=bool)
    from .domain import slice_domain
    from .strokes import PLANE_AXES

    u, v, _ = PLANE_AXES[axis]
    lo = plane.origin[[u, v]]
    return slice_domain(infill.domain, axis, float(position), lo=lo, hi=lo + plane.size,
                        shape=plane.shape)


@dataclass(frozen=True, eq=False)
class SliceResult:
    """One evaluated slice.

    plane : engine.gpu.SlicePlane; axis, position : the plane (mm)
    g_v, g_w : (H, W) complex, the two noises
    inside : (H, W) bool, pixels inside the part
    fields : PhasorFields (F and D give the carriers of the singularity measure)
    state, engine : what was evaluated, and by which evaluator
    """

    plane: object
    axis: str
    position: float
    g_v: np.ndarray
    g_w: np.ndarray
    inside: np.ndarray
    fields: PhasorFields
    state: str
    engine: str

    @property
    def p_v(self) -> np.ndarray:
        """(H, W) float64 sawtooth of p_v in [0, 1)."""
        from .noise import sawtooth
        return sawtooth(self.g_v.astype(np.complex128))

    @property
    def p_w(self) -> np.ndarray:
        from .noise import sawtooth
        return sawtooth(self.g_w.astype(np.complex128))

    @property
    def diamonds(self) -> np.ndarray:
        """(H, W) bool, black diamond cells inside the part (the layer image)."""
        from .noise import diamond_mask
        return diamond_mask(self.p_v, self.p_w) & self.inside

    @property
    def lo(self) -> np.ndarray:
        """(2,) mm, in-plane (u, v) corner of the pixel grid."""
        from .strokes import PLANE_AXES
        u, v, _ = PLANE_AXES[self.axis]
        return np.asarray(self.plane.origin)[[u, v]]

    @property
    def hi(self) -> np.ndarray:
        return self.lo + np.asarray(self.plane.size)

    def singularity(self) -> tuple:
        """(S_v, S_w) (H, W) float64 by finite differences of Arg G (paper 4.2.2):
        NaN on the border pixels and outside the part, inf where G = 0."""
        from .noise import local_oscillators, slice_points
        from .singularity import singularity_fd

        pts = slice_points(self.plane)
        f, e_v, e_w = local_oscillators(self.fields, pts)
        shape = self.plane.shape
        out = []
        for g, e in ((self.g_v, e_v), (self.g_w, e_w)):
            g = np.asarray(g, dtype=np.complex128)
            s = singularity_fd(np.angle(g), (f[:, None] * e).reshape(shape + (3,)), f.reshape(shape),
                               self.plane.pixel_u, self.plane.pixel_v)
            s[g == 0] = np.inf
            s[~self.inside] = np.nan
            out.append(s)
        return tuple(out)

    def energy(self, q: float = SINGULARITY_THRESHOLD) -> dict:
        """F_S(q) over the part's pixels: ``{"v", "w", "either", "pixels"}``.

        ``either`` counts a pixel singular in p_v or in p_w (max of the two
        measures); NaN (border) pixels are left out of |Omega|.
        """
        from .singularity import singularity_energy

        s_v, s_w = self.singularity()
        either = np.fmax(s_v, s_w)
        either[np.isnan(s_v) | np.isnan(s_w)] = np.nan
        pixels = int(np.count_nonzero(~np.isnan(either)))
        if pixels == 0:
            raise ValueError(f"slice {self.axis} = {self.position:g} mm: no pixel inside the part "
                             "away from the slice border, so it has no singularity energy")
        return {"v": singularity_energy(s_v, q), "w": singularity_energy(s_w, q),
                "either": singularity_energy(either, q), "pixels": pixels}


def infill_slice(infill: PhasorInfill, axis: str, position: float, pixel: float, *,
                 state: str | None = None, engine: str = "gpu", progress=None) -> SliceResult:
    """Evaluate one axis-aligned slice of ``infill`` (see :func:`slice_noise`).

    Raises ValueError for a position outside the box or a pixel too coarse
    for the fields' highest frequency (:func:`check_pixel`).
    """
    plane = slice_plane(infill.fields, axis, position, pixel)
    g_v, g_w, used = slice_noise(infill, plane, state=state, engine=engine, progress=progress)
    inside = _inside(infill, plane, axis, position)
    return SliceResult(plane, axis, float(position), g_v, g_w, inside, infill.fields,
                       infill.state if state is None else state, used)


# ---------------------------------------------------------------------- prints

def layer_positions(infill: PhasorInfill, layer_height: float) -> np.ndarray:
    """z (mm, part coordinates) of the middle of each layer, bottom first.

    Layers stack from the bottom of the part (of the box without one);
    the last layer is the highest whole one.
    """
    if not (math.isfinite(layer_height) and layer_height > 0):
        raise ValueError(f"layer_height: expected a positive length in mm, got {layer_height!r}")
    if infill.domain is None:
        z0, z1 = float(infill.fields.lo[2]), float(infill.fields.hi[2])
    else:
        z = np.asarray(infill.domain.vertices)[:, 2]
        z0, z1 = float(z.min()), float(z.max())
    n = max(1, int(math.floor((z1 - z0) / layer_height + 1e-9)))
    return z0 + (np.arange(n) + 0.5) * layer_height


def print_layers(infill: PhasorInfill, *, layer_height: float, pixel: float, engine: str = "gpu",
                 state: str | None = None, progress=None):
    """Lazily yield ``(z, image, domain, origin, pixel)`` per layer for
    :func:`engine.fab.layers_to_gcode`.

    ``z`` is the nozzle height above the bed, ``(k + 1) * layer_height``;
    the slice is taken in the middle of the layer.  ``image`` is the black
    diamond cells, ``domain`` the part's section, ``origin`` the centre of
    pixel [0, 0] (x, y mm).  ``progress(done, total)`` is called after each
    slice; False stops (engine.progress.Cancelled).
    """
    from engine.progress import report

    zs = layer_positions(infill, layer_height)
    check_pixel(infill.fields, pixel)
    for k, z in enumerate(zs):
        result = infill_slice(infill, "z", float(z), pixel, state=state, engine=engine)
        origin = result.lo + 0.5 * pixel
        yield (k + 1) * layer_height, result.diamonds, result.inside, origin, float(pixel)
        report(progress, k + 1, len(zs))


def write_print(infill: PhasorInfill, path, *, settings=None, pixel: float = 0.1, engine: str = "gpu",
                progress=None):
    """Slice every layer and write the G-code (:mod:`engine.fab`).

    The file is written to a temporary sibling and renamed at the end, so a
    cancel (``progress`` returning False), an error or Ctrl-C leaves no
    half-written file and an existing one untouched.

    Returns
    -------
    engine.fab.GcodeSummary
    """
    from engine.fab import PrintSettings, layers_to_gcode

    settings = settings or PrintSettings()
    zs = layer_positions(infill, settings.layer_height)
    layers = print_layers(infill, layer_height=settings.layer_height, pixel=pixel, engine=engine)
    return layers_to_gcode(layers, path, settings=settings, n_layers=len(zs), progress=progress)


def infill_toolpaths(infill, settings, *, pixel, engine="gpu", progress=None) -> list:
    """The toolpath layers :func:`engine.phasor.infill.write_print` writes, as a list
    of :class:`engine.fab.Layer` (``progress`` once per sliced layer)."""
    from engine.fab import layer_stack_toolpaths

    images = print_layers(infill, layer_height=settings.layer_height, pixel=pixel, engine=engine,
                          progress=progress)
    return list(layer_stack_toolpaths(images, settings=settings))
