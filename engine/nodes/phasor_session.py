"""The phasor infill of one PhasorFields -> PhasorNoise chain, as it is painted and sliced.

`PhasorInfillSession` is the one way phasor infill runs: the nodes
(``PhasorFieldsNode`` / ``PhasorNoiseNode`` / ``PhasorSliceNode``), the
"Phasor Infill" dock's painting, previews and G-code export, and
``mesoforge phasor`` all call it.  It holds the control fields, the infill
made from them (possibly older than the fields, until `update`), the part
and the noise options, and knows

* how the fields come from the PhasorFields parameters (`painted_fields`:
  the box, the grid, the spec, the strokes),
* how the infill is made from scratch (`sample`) or brought up to repainted
  fields by the local kernel update (`apply_stroke` then `update`),
* how it is sliced (`slice` for a view's pattern, `slice_at` / `energy`
  for a node's or the command line's slice) and printed (`write_print`,
  `toolpaths`, `printability`).

A session is a value: `apply_stroke`, `update` and `sample` return a new
session and leave this one alone, so a drag's intermediate states and a
background update never share mutable state.

No Qt here; the kernels are :mod:`engine.phasor` and :mod:`engine.fab`.
"""

from __future__ import annotations

import io
import json
import math
from dataclasses import dataclass, replace

import numpy as np

from engine.graph.errors import NodeInputError
from engine.phasor.values import SliceEnergy
from engine.phasor.fields import PhasorFields
from engine.phasor.incremental import EMPTY, affected_box, changed_cells, is_empty, update_infill
from engine.phasor.strokes import Stroke, apply_stroke

__all__ = ["MAX_FIELD_CELLS", "grid_shape", "fields_box", "initial_fields", "paint", "painted_fields",
           "NoiseOptions", "PhasorInfillSession", "union_box", "diamonds_png"]

MAX_FIELD_CELLS = 256 ** 3
EXPORT_PIXEL = 0.1   # mm, the G-code export's pixel unless the highest F needs a finer one


# ------------------------------------------------------------------ the fields

def grid_shape(lo, hi, resolution: int) -> tuple:
    """(nz, ny, nx): ``resolution`` cells along the box's longest axis, the
    others in proportion (at least 2)."""
    ext = np.asarray(hi, float) - np.asarray(lo, float)
    n = [max(2, int(round(resolution * e / ext.max()))) for e in ext]
    return tuple(n[::-1])


def union_box(a, b) -> tuple:
    """The ``[z, y, x]`` bounding box of two cell boxes (an empty one adds nothing)."""
    if a[0].stop <= a[0].start:
        return b
    if b[0].stop <= b[0].start:
        return a
    return tuple(slice(min(x.start, y.start), max(x.stop, y.stop)) for x, y in zip(a, b))


def fields_box(domain, params) -> tuple:
    """(lo, hi) (3,) mm of the fields' grid: the part's box plus ``margin``, else
    the PhasorFields ``lo`` .. ``hi``; NodeInputError (where="hi") for unordered corners."""
    if domain is not None:
        from engine.phasor.domain import box_of
        return box_of(domain, params["margin"])
    lo, hi = np.array(params["lo"], float), np.array(params["hi"], float)
    if np.any(hi <= lo):
        raise NodeInputError(f"hi {params['hi']} must exceed lo {params['lo']} on every axis (mm)",
                             where="hi")
    return lo, hi


def initial_fields(domain, params) -> PhasorFields:
    """The fields of validated PhasorFields ``params`` before any stroke (from
    ``spec``, on the grid of ``resolution`` over `fields_box`).

    Raises NodeInputError naming ``resolution`` (too many cells) or ``spec``.
    """
    from engine.phasor.field_init import fields_from_spec

    lo, hi = fields_box(domain, params)
    shape = grid_shape(lo, hi, params["resolution"])
    if math.prod(shape) > MAX_FIELD_CELLS:
        raise NodeInputError(f"a grid of {shape[::-1]} cells is more than {MAX_FIELD_CELLS}",
                             where="resolution")
    try:
        spec = json.loads(params["spec"]) if params["spec"].strip() else {}
    except ValueError as exc:
        raise NodeInputError(f"spec is not valid JSON: {exc}", where="spec") from None
    try:
        return fields_from_spec(spec, lo=lo, hi=hi, shape=shape, mesh=domain)
    except ValueError as exc:
        raise NodeInputError(f"spec: {exc}", where="spec") from None


def paint(fields: PhasorFields, strokes, first: int = 0) -> tuple:
    """Apply every Stroke of ``strokes`` in order: (fields, union ``[z, y, x]``
    box of the cells painted by the strokes from index ``first`` on)."""
    changed = EMPTY
    for i, stroke in enumerate(strokes):
        fields, box = apply_stroke(fields, stroke)
        if i >= first:
            changed = union_box(changed, box)
    return fields, changed


def painted_fields(domain, params) -> PhasorFields:
    """The fields of validated PhasorFields ``params``: `initial_fields` with
    every stroke of ``params["strokes"]`` painted."""
    strokes = [Stroke.from_dict(d) for d in params["strokes"]]
    return paint(initial_fields(domain, params), strokes)[0]


# ------------------------------------------------------------------ the noise

@dataclass(frozen=True)
class NoiseOptions:
    """The PhasorNoise parameters a sample or an update needs (values from the
    node's validated params; the defaults and ranges live in its schema).

    per_cell : kernels per grid cell; c : kernel radius in periods of F_min;
    iterations : alignment sweeps; filtered, filter_scale : slice options
    """

    per_cell: int
    c: float
    iterations: int
    filtered: bool
    filter_scale: float

    @classmethod
    def from_params(cls, params) -> "NoiseOptions":
        return cls(int(params["per_cell"]), float(params["c"]), int(params["iterations"]),
                   bool(params["filtered"]), float(params["filter_scale"]))


@dataclass(frozen=True, eq=False)
class PhasorInfillSession:
    """Fields, the infill made from them and how to go on.

    fields : PhasorFields, the current (painted) control fields
    infill : engine.phasor.infill.PhasorInfill or None; made from ``infill.fields``,
        which lag ``fields`` after `apply_stroke` until `update`
    domain : the closed part (``vertices``, ``faces``, mm) or None
    options : NoiseOptions or None (an update keeps the infill's own options)
    painted : ``[z, y, x]`` cells the last `apply_stroke` changed (EMPTY otherwise)
    """

    fields: PhasorFields
    infill: object = None
    domain: object = None
    options: NoiseOptions | None = None
    painted: tuple = EMPTY

    # -- making one ------------------------------------------------------------------------
    @classmethod
    def from_params(cls, fields_params, noise_params=None, *, domain=None, seed=None,
                    progress=None) -> "PhasorInfillSession":
        """The session of validated PhasorFields ``fields_params`` (and, when given,
        PhasorNoise ``noise_params`` sampled with ``seed``): what a fresh evaluation
        of the two nodes gives."""
        session = cls(painted_fields(domain, fields_params), domain=domain,
                      options=None if noise_params is None else NoiseOptions.from_params(noise_params))
        return session if noise_params is None else session.sample(seed, progress=progress)

    @classmethod
    def of_infill(cls, infill, fields: PhasorFields | None = None, domain=None) -> "PhasorInfillSession":
        """A session over an evaluated infill (``fields`` default to the infill's,
        ``domain`` to its part)."""
        return cls(infill.fields if fields is None else fields, infill,
                   infill.domain if domain is None else domain)

    def sample(self, seed, *, progress=None) -> "PhasorInfillSession":
        """The infill from scratch on the current fields: kernels sampled with ``seed``
        (int or Generator), phases aligned.  ValueError when there would be too many
        kernels for the box and F_min."""
        from engine.phasor.infill import sample_infill

        o = self.options
        if o is None:
            raise ValueError("sampling needs the noise options (PhasorNoise parameters)")
        infill = sample_infill(self.fields, domain=self.domain, per_cell=o.per_cell, c=o.c,
                               iterations=o.iterations, filtered=o.filtered, filter_scale=o.filter_scale,
                               rng=seed, progress=progress)
        return replace(self, infill=infill, painted=EMPTY)

    # -- painting ----------------------------------------------------------------------------
    def apply_stroke(self, stroke: Stroke) -> "PhasorInfillSession":
        """The session with ``stroke`` painted on the fields (the infill is not
        touched: `update` brings it along); ``painted`` holds the cells it changed."""
        fields, changed = apply_stroke(self.fields, stroke)
        return replace(self, fields=fields, painted=changed)

    def painted_region(self) -> tuple:
        """(lo, hi) (3,) mm where samples of the fields read a cell of ``painted``."""
        return affected_box(self.fields, self.painted)

    @property
    def touched(self) -> bool:
        """The last `apply_stroke` changed at least one cell."""
        return not is_empty(self.painted)

    def can_update(self) -> bool:
        """The infill can follow the fields locally: same grid, and the kernel radius
        ``c / F_min`` the fields give is the kernels' own."""
        if self.infill is None or changed_cells(self.infill.fields, self.fields) is None:
            return False
        c = self.infill.kernels.info.get("c") if self.options is None else self.options.c
        return c is None or c / self.fields.min_frequency() == self.infill.kernels.radius

    def update(self, *, progress=None) -> "PhasorInfillSession":
        """The infill brought to the current fields by the local update
        (:func:`engine.phasor.incremental.update_infill`: resample the kernels the
        change reaches, re-align the phases near them).  ``infill.changed_region``
        says where slices changed.  ValueError when the fields are on another grid
        or moved the kernel radius (sample from scratch then)."""
        if self.infill is None:
            raise ValueError("no infill to update: sample one first")
        changed = changed_cells(self.infill.fields, self.fields)
        if changed is None:
            raise ValueError("the infill was made on another grid; evaluate to see the pattern")
        o = self.options
        infill = update_infill(self.infill, self.fields, changed, progress=progress,
                               **({} if o is None else {"iterations": o.iterations, "filtered": o.filtered,
                                                        "filter_scale": o.filter_scale}))
        if infill.domain is not self.domain:
            infill = replace(infill, domain=self.domain)
        return replace(self, infill=infill, painted=EMPTY)

    # -- slices ------------------------------------------------------------------------------
    def slice(self, plane, show: str, rect=None, *, engine: str = "gpu", progress=None) -> tuple:
        """The infill's pattern ``show`` ("diamonds", "p_v", "singularity") on
        ``plane`` (a SlicePlane), only in pixel rectangle ``rect`` (r0, r1, c0, c1)
        when given: ((h, w) float64, the engine that ran)."""
        from engine.phasor.preview import pattern_slice, sub_plane

        part = plane if rect is None else sub_plane(plane, rect[:2], rect[2:])
        return pattern_slice(self.infill, part, show, engine=engine, progress=progress)

    def slice_at(self, axis: str, position: float, pixel: float, *, state: str | None = None,
                 engine: str = "gpu", progress=None):
        """The slice normal to ``axis`` at ``position`` mm over the fields' box, ``pixel`` mm
        (:class:`engine.phasor.infill.SliceResult`) of noise ``state`` (None: the
        infill's own).  ValueError for a position outside the box ("position: ...")
        or a pixel too coarse for the highest F ("pixel ...")."""
        from engine.phasor.infill import infill_slice

        return infill_slice(self.infill, axis, position, pixel, state=state, engine=engine, progress=progress)

    def check_slice(self, axis: str, position: float, pixel: float) -> None:
        """Refuse a slice before any work: ValueError as `slice_at` would raise."""
        from engine.phasor.infill import slice_plane

        slice_plane(self.fields, axis, position, pixel)

    def check_pixel(self, pixel: float) -> None:
        """Refuse a pixel too coarse for the fields' highest F (ValueError "pixel ...")."""
        from engine.phasor.infill import check_pixel

        check_pixel(self.fields, pixel)

    def part_mask(self, axis: str, position: float, pixel: float) -> np.ndarray:
        """(H, W) bool: the pixels of the `slice_at` slice inside the part (all without one)."""
        from engine.phasor.infill import slice_plane
        from engine.phasor.preview import domain_slice

        plane = slice_plane(self.fields, axis, position, pixel)
        inside = domain_slice(self.domain, plane)
        return np.ones(plane.shape, dtype=bool) if inside is None else inside

    @staticmethod
    def energy(result) -> SliceEnergy:
        """The singularity energy F_S(2) of a SliceResult (NaN when it misses the part)."""
        from engine.phasor.infill import SINGULARITY_THRESHOLD

        q = SINGULARITY_THRESHOLD
        try:
            e = result.energy(q)
        except ValueError:  # the slice misses the part
            return SliceEnergy(math.nan, math.nan, math.nan, q, 0, result.state, result.engine)
        return SliceEnergy(e["either"], e["v"], e["w"], q, e["pixels"], result.state, result.engine)

    # -- prints ------------------------------------------------------------------------------
    def export_pixel(self) -> float:
        """The G-code export's pixel (mm): 0.1, finer when the highest F needs it."""
        from engine.phasor.infill import MIN_PIXELS_PER_PERIOD

        return min(EXPORT_PIXEL, 1.0 / (MIN_PIXELS_PER_PERIOD * self.infill.fields.max_frequency()))

    def layer_count(self, layer_height: float) -> int:
        """Layers of a print of ``layer_height`` mm."""
        from engine.phasor.infill import layer_positions

        return len(layer_positions(self.infill, layer_height))

    def write_print(self, path, *, settings=None, pixel: float | None = None, engine: str = "gpu",
                    progress=None):
        """Slice every layer and write the G-code to ``path`` (atomically: a cancel or
        an error leaves no file); ``progress`` once per layer.  ``pixel`` None: `export_pixel`.
        Returns engine.fab.GcodeSummary."""
        from engine.phasor.infill import write_print

        pixel = self.export_pixel() if pixel is None else pixel
        return write_print(self.infill, path, settings=settings, pixel=pixel, engine=engine, progress=progress)

    def toolpaths(self, settings=None, *, pixel: float | None = None, engine: str = "gpu",
                  progress=None) -> list:
        """The toolpath layers (engine.fab.Layer) `write_print` writes."""
        from engine.fab import PrintSettings
        from engine.phasor.infill import infill_toolpaths

        pixel = self.export_pixel() if pixel is None else pixel
        return infill_toolpaths(self.infill, settings or PrintSettings(), pixel=pixel, engine=engine,
                                progress=progress)

    def printability(self, settings=None, *, pixel: float | None = None, engine: str = "gpu",
                     progress=None):
        """The emulated print of the toolpaths (engine.fab.PrintabilityReport, paper 5.1)."""
        from engine.fab import PrintSettings, printability

        settings = settings or PrintSettings()
        layers = self.toolpaths(settings, pixel=pixel, engine=engine, progress=progress)
        return printability(layers, nozzle_diameter=settings.nozzle_diameter, progress=progress)


def diamonds_png(diamonds) -> bytes:
    """PNG bytes of a slice's diamond image ((H, W), non-zero = black cell, row i
    along +v): black cells on white, seen from +axis with v upwards."""
    from PIL import Image

    img = np.where(np.asarray(diamonds)[::-1] > 0, 0, 255).astype(np.uint8)
    buf = io.BytesIO()
    Image.fromarray(img).save(buf, format="PNG")
    return buf.getvalue()
