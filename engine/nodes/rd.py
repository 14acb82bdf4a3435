"""Reaction-diffusion growth nodes (Garnier, Schmidt & Rohmer 2022).

    TopOpt --design--> RDFields --rdfields--> RDGrow --structures--> RDCompile --field/solid/contour-->

RDFields turns a design (or an imported .npz / .vti) into the growth inputs:
density rho, regularised rotation field R and infill map Gamma.  RDGrow
grows one anisotropic Gray-Scott pattern per principal direction on a finer
grid; RDCompile filters and combines them into the lattice.

Painting is data, as for phasor infill: a solid-region stroke is one
``SetParam(fields, "gamma_c", old + [stamps])`` and a brush edit on the
structure one ``SetParam(grow, "edits", old + [edit])``.  RDGrow is
stateful: when only edits were appended it applies them to its previous
state and regrows locally; the grown state is kept in the project file.
What RDGrow runs is `engine.nodes.rd_session.RDGrowthSession`, the object
the RD dock's live growth and ``mesoforge rd`` (through this node) share.
"""

from __future__ import annotations

import math

import numpy as np

from engine.fileio import file_digest
from engine.graph.errors import NodeInputError
from engine.graph.node import NodeType, register
from engine.graph.schema import Param, Port
from engine.geometry.values import Field, Solid
from engine.rd.values import ContourValue, RDFieldsValue
from engine.progress import stage

from . import rd_state
from .grid_size import grid_shape_of

MAX_FIELD_CELLS = 4_000_000      # growth grid: 2000 x 2000 or 160^3
# Peak bytes per growth-grid cell, by dimension: upsampled fields, the
# diffusion tensors, u and v, the grown pattern per direction (a 2D run
# measured ~300 B per cell, a 3D one ~2.6 kB, compilation included), and of
# the compilation alone.
GROW_BYTES_PER_CELL = {2: 400, 3: 2800}
COMPILE_BYTES_PER_CELL = {2: 100, 3: 700}
DIRECTIONS = ("all", "first", "second", "third")
SEEDS = ("centre", "several")
COMBINE = ("union", "lattice", "membrane")
# paper Table 2: relative thickness per direction (2D: L-beam / bridge; 3D: MBB / chair)
PAPER_MU = {2: (0.15, 0.4), 3: (0.2, 0.25, 0.25)}
FILTER_DELTA = 0.01              # paper Table 1, delta_i


# ------------------------------------------------------------------ brush data

def _point(value, what) -> list:
    if not isinstance(value, list) or len(value) not in (2, 3):
        raise ValueError(f"{what} must be a list of 2 or 3 numbers (x, y[, z]) in cells")
    out = []
    for v in value:
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise ValueError(f"{what} must hold finite numbers")
        out.append(float(v))
    return out


def _positive(value, what) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
        raise ValueError(f"{what} must be a number > 0 (cells)")
    return float(value)


def _canonical_gamma_c(data):
    """``[[{centre, radius, value}, ...], ...]``: one stamp list per stroke."""
    if not isinstance(data, list):
        raise ValueError(f"a list of strokes (each a list of stamps), got {type(data).__name__}")
    out = []
    for i, stroke in enumerate(data):
        if not isinstance(stroke, list) or not stroke:
            raise ValueError(f"stroke {i} must be a non-empty list of stamps {{centre, radius, value}}")
        stamps = []
        for j, st in enumerate(stroke):
            where = f"stroke {i} stamp {j}"
            if not isinstance(st, dict) or set(st) - {"centre", "radius", "value"}:
                raise ValueError(f"{where} must be an object with keys centre, radius, value")
            value = st.get("value", 1.0)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 <= value <= 1.0:
                raise ValueError(f"{where}: value must be a number in [0, 1]")
            stamps.append({"centre": _point(st.get("centre"), f"{where}: centre"),
                           "radius": _positive(st.get("radius"), f"{where}: radius"), "value": float(value)})
        out.append(stamps)
    return out


EDIT_MODES = ("erase", "draw")


def _canonical_edits(data):
    """``[{mode, centre, radius}, ...]``; a stroke may give ``centres`` (a list of points) instead."""
    if not isinstance(data, list):
        raise ValueError(f"a list of brush edits, got {type(data).__name__}")
    out = []
    for i, e in enumerate(data):
        where = f"edit {i}"
        if not isinstance(e, dict) or set(e) - {"mode", "centre", "centres", "radius"}:
            raise ValueError(f"{where} must be an object with keys mode, centre (or centres), radius")
        if e.get("mode") not in EDIT_MODES:
            raise ValueError(f"{where}: mode must be one of {list(EDIT_MODES)}")
        if ("centre" in e) == ("centres" in e):
            raise ValueError(f"{where} needs exactly one of centre (a point) and centres (a list of points)")
        item = {"mode": e["mode"], "radius": _positive(e.get("radius"), f"{where}: radius")}
        if "centre" in e:
            item["centre"] = _point(e["centre"], f"{where}: centre")
        else:
            pts = e["centres"]
            if not isinstance(pts, list) or not pts:
                raise ValueError(f"{where}: centres must be a non-empty list of points")
            item["centres"] = [_point(p, f"{where}: centres[{k}]") for k, p in enumerate(pts)]
            if len({len(p) for p in item["centres"]}) != 1:
                raise ValueError(f"{where}: centres must all have the same number of coordinates")
        out.append(item)
    return out


# ------------------------------------------------------------------ RDFields

@register
class RDFieldsNode(NodeType):
    """Inputs of reaction-diffusion growth on the design grid: the infill
    density rho, the principal directions R (regularised by the paper's
    Algorithms 1-2 when `regularise`) and the infill map Gamma = max(Gamma_c,
    Gamma_sigma) (eqs. 3-5).  Reads a Design, or an .npz / .vti file
    (`path`) when no design is connected.  `gamma_c` is painted solid
    regions: one list of brush stamps per stroke, centres and radii in cells
    of this grid (x, y[, z])."""

    type_name = "RDFields"
    title = "RD Fields"
    code = "rdf"
    family = "topology"
    inputs = (Port("design", "Design", required=False, doc="a topology-optimised design"),)
    outputs = (Port("rdfields", "RDFields"),)
    params = (
        Param("path", "str", "", doc="an .npz or .vti field file (rho, sigma or R, gamma); used "
                                     "when no design is connected"),
        Param("regularise", "bool", True,
              doc="fill undefined (trivial / isotropic) directions from their neighbours (appendix)"),
        Param("coherence", "bool", True,
              doc="add Gamma_sigma = (1 - a) rho (eq. 4): solid where the directions are incoherent"),
        Param("gamma_c", "json", [], check=_canonical_gamma_c,
              doc="painted solid regions: a list of strokes, each a list of stamps "
                  "{centre: [x, y(, z)], radius, value} in cells; value 1 = solid"),
    )

    @classmethod
    def source_token(cls, params):
        path = params.get("path", "").strip()
        return file_digest(path) if path else ""

    def evaluate(self, inputs, params, ctx):
        from engine.rd.infill_map import gamma_sigma

        design = inputs.get("design")
        if design is not None:
            rho, sigma, raw, values = design.rho, design.sigma_combined, design.rotation, design.principal
            lo, hi, gamma_file = design.lo, design.hi, None
        else:
            rho, sigma, raw, values, lo, hi, gamma_file = self._from_file(params, ctx)
        ctx.check()
        rotation = raw
        if params["regularise"]:
            rotation = self._regularised(values, raw, ctx)
        ctx.check()
        gamma_c = self._painted(gamma_file, rho.shape, params["gamma_c"])
        g_sigma = None
        if params["coherence"]:
            g_sigma = gamma_sigma(raw, np.clip(rho, 0.0, 1.0))
            gamma = np.maximum(gamma_c, g_sigma)
        else:
            gamma = gamma_c
        return {"rdfields": RDFieldsValue(rho, rotation, gamma, lo, hi, sigma=sigma, gamma_sigma=g_sigma,
                                          magnitude=np.abs(values))}

    @staticmethod
    def _from_file(params, ctx):
        from engine.rd.field_io import load_fields
        from engine.rd.tensor_field import principal_decomposition

        path = params["path"].strip()
        if not path:
            raise NodeInputError("no design is connected and no field file is given: connect a TopOpt "
                                 "node or set path to an .npz / .vti file", where="path")
        try:
            f = load_fields(path)
        except ValueError as exc:
            raise NodeInputError(str(exc), where="path") from None
        d = f.ndim
        if f.sigma is not None:
            try:
                values, raw = principal_decomposition(f.sigma, progress=ctx.progress)
            except ValueError as exc:
                raise NodeInputError(f"{path}: {exc}", where="path") from None
        elif f.rotation is not None:
            raw = np.array(f.rotation)
            # no magnitudes: a defined column counts as a clear direction, a zero one as undefined
            defined = np.linalg.norm(raw, axis=-2) > 0.5
            values = np.where(defined, np.arange(d, 0, -1, dtype=np.float64), 0.0)
        else:
            raise NodeInputError(f"{path}: the file holds neither 'sigma' nor 'R': the growth needs "
                                 f"principal directions", where="path")
        lo = np.array(f.origin)
        hi = lo + np.array(f.spacing) * np.array(f.rho.shape[::-1])
        return np.array(f.rho), f.sigma, raw, values, lo, hi, f.gamma

    @staticmethod
    def _regularised(values, raw, ctx):
        from engine.rd.regularise import regularise_orientations

        try:
            reg = regularise_orientations(values, raw, update="simultaneous", progress=ctx.progress)
        except ValueError as exc:
            raise NodeInputError(f"cannot regularise the principal directions: {exc}",
                                 where="regularise") from None
        rotation = np.array(reg.rotation)
        if reg.unfilled.any():
            # nothing to copy from (no defined direction anywhere near): the grid axes
            rotation[reg.unfilled] = np.eye(rotation.shape[-1])
        return rotation

    @staticmethod
    def _painted(gamma_file, shape, strokes) -> np.ndarray:
        from engine.rd.regrow import brush_region

        gamma_c = np.zeros(shape) if gamma_file is None else np.array(gamma_file, dtype=np.float64)
        d = len(shape)
        for i, stroke in enumerate(strokes):
            for st in stroke:
                if len(st["centre"]) != d:
                    raise NodeInputError(f"gamma_c stroke {i}: a stamp centre has {len(st['centre'])} "
                                         f"coordinates; the fields are {d}D", where="gamma_c")
                gamma_c[brush_region(shape, st["centre"], st["radius"])] = st["value"]
        return gamma_c


# ------------------------------------------------------------------ RDGrow

def growth_shape(resolution, fields) -> tuple:
    """``[nx, ny(, nz)]`` (empty: the fields' grid) -> grid shape ``(ny, nx)`` / ``(nz, ny, nx)``."""
    d = fields.ndim
    if not resolution:
        return fields.grid_shape
    return grid_shape_of(resolution, d, MAX_FIELD_CELLS, where="resolution", owner="the fields are",
                         hint=" (or [] for the fields' grid)")


def growth_fields(fields: RDFieldsValue, shape) -> RDFieldsValue:
    """The fields upsampled (or kept) on the growth grid ``shape``."""
    from engine.rd.diffusion import upsample_field, upsample_rotation

    if tuple(shape) == fields.grid_shape:
        return fields
    d = fields.ndim
    mag = None
    if fields.magnitude is not None:
        mag = np.stack([upsample_field(fields.magnitude[..., i], shape) for i in range(d)], axis=-1)
    return RDFieldsValue(upsample_field(fields.rho, shape), upsample_rotation(fields.rotation, shape),
                         np.clip(upsample_field(fields.gamma, shape), 0.0, 1.0), fields.lo, fields.hi,
                         magnitude=mag, source=fields)


def selected_directions(choice, d) -> tuple:
    if choice == "all":
        return tuple(range(d))
    i = DIRECTIONS.index(choice) - 1
    if i >= d:
        raise NodeInputError(f"directions {choice!r}: the fields are {d}D and have {d} principal directions",
                             where="directions")
    return (i,)


# parameters of the growth itself: a change of any of them grows afresh (only appended edits regrow)
_GROWTH_KEYS = ("resolution", "iso", "d", "gamma", "F", "k", "alpha", "xi", "eps", "dt", "max_steps",
                "seeds", "n_seeds", "directions")


@register
class RDGrowNode(NodeType):
    """Anisotropic Gray-Scott growth (eqs. 9-14): one pattern per principal
    direction, stripes (2D) / sheets (3D) perpendicular to it, grown from
    seeds inside the infill space rho >= iso on the `resolution` grid
    (fields upsampled) until G^t < eps.  `edits` are brush edits in growth-grid
    cells (x, y[, z]): erase clears a disc and lets the pattern regrow into
    it, draw plants new material there.  Appending edits regrows only around
    them; the grown state is kept in the project file."""

    type_name = "RDGrow"
    title = "RD Grow"
    code = "rdg"
    family = "topology"
    uses_rng = True
    stateful = True
    version = 1
    inputs = (Port("rdfields", "RDFields"),)
    outputs = (Port("structures", "RDStructures"),)
    params = (
        Param("resolution", "int_list", [], 2, 4096, unit="cells",
              doc="growth grid [nx, ny(, nz)]; the fields are upsampled; [] = the fields' grid"),
        Param("iso", "float", 0.5, 0.01, 0.99, doc="infill space: rho >= iso"),
        Param("d", "float", 0.5, 1e-3, 10.0, doc="diffusion ratio D_v / D_u"),
        Param("gamma", "float", 1.0, 1e-3, 100.0, doc="reaction speed: larger, shorter wavelength"),
        Param("F", "float", 0.0395, 0.0, 1.0, doc="feed rate"),
        Param("k", "float", 0.0595, 0.0, 1.0, doc="kill rate"),
        Param("alpha", "float", 0.5, 0.0, 1.0, doc="how much the infill map Gamma lowers k (eq. 10)"),
        Param("xi", "float", 5.0, 1.0, 5.8, doc="anisotropy of the diffusion tensors (eq. 11)"),
        Param("eps", "float", 1e-7, 1e-15, 1.0, doc="stop when G^t (eq. 14) falls below this"),
        Param("dt", "float", 0.0, 0.0, 100.0, doc="time step; 0 = the largest stable step"),
        Param("max_steps", "int", 20000, 1, 10_000_000, doc="step limit per direction"),
        Param("seeds", "enum", "centre", choices=SEEDS,
              doc="centre: one seed at the middle of the infill space; several: n_seeds random seeds"),
        Param("n_seeds", "int", 4, 1, 1000, doc="seeds when seeds = several"),
        Param("directions", "enum", "all", choices=DIRECTIONS, doc="which principal directions to grow"),
        Param("edits", "json", [], check=_canonical_edits,
              doc="brush edits [{mode: erase|draw, centre: [x, y(, z)], radius}] in growth-grid cells"),
    )

    memory_param = "resolution"

    @classmethod
    def memory_estimate(cls, params, inputs_shape_info=None) -> int:
        source = (inputs_shape_info or {}).get("rdfields")
        res = list(params["resolution"])
        if not res and source is None:
            return 0
        shape = res if res else source.grid_shape
        d = len(shape) if len(shape) in (2, 3) else 3
        return math.prod(shape) * GROW_BYTES_PER_CELL[d]

    def evaluate(self, inputs, params, ctx):
        from .rd_session import RDGrowthSession

        source = inputs["rdfields"]
        previous = (ctx.previous or {}).get("structures")
        new_edits = self._appended_edits(previous, source, params, ctx)
        if new_edits == []:
            # nothing changed that the growth sees (e.g. a result restored under an older key)
            return {"structures": previous}
        if new_edits is not None:
            result = RDGrowthSession.of_value(previous, params).regrow(new_edits, progress=ctx.progress)
        else:
            session = RDGrowthSession(source, params, ctx.seed)
            ctx.check()
            result = session.grow(progress=ctx.progress)
        return {"structures": result}

    @staticmethod
    def _appended_edits(previous, source, params, ctx):
        """The edits appended since the previous evaluation when nothing else
        changed (same fields, parameters and seed); None when the growth must
        start over."""
        if previous is None or ctx.previous_seed != ctx.seed or not previous.fields.source_of().same_as(source):
            return None
        prev = ctx.previous_params or {}
        if any(prev.get(k) != params[k] for k in _GROWTH_KEYS):
            return None
        old, new = list(prev.get("edits") or []), params["edits"]
        if len(new) < len(old) or new[:len(old)] != old or list(previous.edits) != old:
            return None
        return new[len(old):]



# ------------------------------------------------------------------ RDCompile

def _canonical_mu(data):
    if not isinstance(data, list) or len(data) not in (0, 2, 3) or not all(
            isinstance(m, (int, float)) and not isinstance(m, bool) and 0 < m < 1 for m in data):
        raise ValueError("[] or 2 / 3 relative thicknesses in (0, 1), one per principal direction")
    return [float(m) for m in data]


@register
class RDCompileNode(NodeType):
    """Structure compilation (section 5): each grown pattern s_i is thresholded
    (at `iso`, or with the paper's relative thicknesses mu_i when `rescale`),
    the families are combined by Booleans (eq. 18: 2D union, 3D pairwise
    intersections then union, or membranes), Gamma regions are made solid and
    the result is cut to the infill space.  Outputs the density as a Field,
    the 3D lattice as a Solid (shown once, never tiled) and the 2D boundary
    as contours, in the units of the fields' box (TopOpt elements): contours
    in box coordinates, the mesh relative to the box's corner lo (the
    viewport draws from the origin).  A 2D structure's `solid` is its pixels
    extruded into a slab one cell thick, for the viewport."""

    type_name = "RDCompile"
    title = "RD Compile"
    code = "rdc"
    family = "solid"
    inputs = (Port("structures", "RDStructures"),)
    outputs = (Port("field", "Field"), Port("solid", "Solid"), Port("contour", "Contour"))
    params = (
        Param("iso", "float", 0.7, 0.01, 0.99,
              doc="member where s_i > iso (without rescale: every direction alike)"),
        Param("rescale", "bool", False,
              doc="thickness filter of eq. 15 with the relative thicknesses `mu` instead of iso"),
        Param("mu", "json", [], check=_canonical_mu,
              doc="relative thickness per direction, e.g. [0.15, 0.4]; [] = the paper's Table 2 "
                  "(2D 0.15, 0.4; 3D 0.2, 0.25, 0.25)"),
        Param("min_member", "float", 0.0, 0.0, 100.0, unit="cells",
              doc="minimum member width (eq. 16): raises mu to min_member / wavelength; 0 = off"),
        Param("variable_thickness", "bool", False,
              doc="eq. 17: mu_i(x) graded by the principal stress magnitude |sigma_i(x)|"),
        Param("combine", "enum", "union", choices=COMBINE,
              doc="union (2D), lattice (3D pairwise intersections then union) or membrane (3D, "
                  "lattice plus the first two families whole)"),
    )

    @classmethod
    def memory_estimate(cls, params, inputs_shape_info=None) -> int:
        st = (inputs_shape_info or {}).get("structures")
        if st is None:
            return 0
        shape = st.fields.grid_shape
        return math.prod(shape) * COMPILE_BYTES_PER_CELL[3 if len(shape) == 3 else 2]

    def evaluate(self, inputs, params, ctx):
        from engine.rd.compile import compile_structure, structure_contours, structure_mesh

        st = inputs["structures"]
        f = st.fields
        d = f.ndim
        mode = params["combine"]
        if d == 3 and mode == "union":
            mode = "lattice"     # the 2D default on a 3D structure: eq. 18's 3D form
        if d == 2 and mode != "union":
            raise NodeInputError(f"combine {params['combine']!r} is for 3D structures; a 2D one is the "
                                 f"union of its directions", where="combine")
        structures = self._per_direction(st)
        mu = self._mu(params, st)
        wavelength = None
        if params["min_member"] > 0:
            wavelength = self._wavelength(st)
        try:
            compiled = compile_structure(
                structures, mu=mu, delta=FILTER_DELTA, rho=f.rho, iso=st.iso, gamma=f.gamma,
                combination="membrane" if mode == "membrane" else "lattice",
                h_min=params["min_member"] or None, wavelength=wavelength,
                progress=stage(ctx.progress, 0.0, 0.5))
        except ValueError as exc:
            raise NodeInputError(str(exc), where="structures") from None
        ctx.check()
        density = compiled.density
        if not (density > 0.5).any():
            raise NodeInputError("the compiled structure has no solid: lower iso (or raise mu) or grow longer",
                                 where="iso")
        field = Field(density, f.lo, f.hi)
        cell = (f.hi - f.lo) / np.array(density.shape[::-1], dtype=np.float64)   # (x, y[, z]) cell size
        if d == 2:
            lines = structure_contours(density, spacing=1.0)
            contour = ContourValue(tuple(f.lo + p * cell for p in lines), f.lo, f.hi)
            # a slab one cell thick: the viewport's picture of a 2D structure
            verts, faces = structure_mesh(np.repeat(density[None], 2, axis=0), spacing=1.0)
            size = np.append(cell, cell.min())
            solid = Solid(0.5 - np.repeat(density[None], 2, axis=0), verts * size, faces,
                          float((f.hi - f.lo).max()), periodic=False)
        else:
            contour = ContourValue((), np.zeros(2), np.ones(2))
            verts, faces = structure_mesh(density, spacing=1.0, progress=stage(ctx.progress, 0.5, 0.5))
            solid = Solid(0.5 - density, verts * cell, faces, float((f.hi - f.lo).max()), periodic=False)
        return {"field": field, "solid": solid, "contour": contour}

    @staticmethod
    def _per_direction(st) -> list:
        """One s field per principal direction (zeros for a direction not grown)."""
        d = st.fields.ndim
        out = [np.zeros(st.fields.grid_shape) for _ in range(d)]
        for i, s in zip(st.directions, st.s):
            out[i] = np.clip(s.astype(np.float64), 0.0, 1.0)
        return out

    @staticmethod
    def _mu(params, st):
        d = st.fields.ndim
        if params["rescale"]:
            given = params["mu"]
            if not given:
                mu = list(PAPER_MU[d])
            elif len(given) != d:
                raise NodeInputError(f"mu {given!r}: the structure is {d}D; give {d} relative thicknesses, "
                                     f"one per direction, or [] for the paper's", where="mu")
            else:
                mu = list(given)
        else:
            mu = [1.0 - params["iso"]] * d
        if params["variable_thickness"]:
            mag = st.fields.magnitude
            if mag is None:
                raise NodeInputError("variable thickness needs the principal stress magnitudes, and these "
                                     "fields have none (rotation imported without sigma)",
                                     where="variable_thickness")
            mu = [rd_state.graded_thickness(mag[..., i], m, st.fields.rho >= st.iso) for i, m in enumerate(mu)]
        return mu

    @staticmethod
    def _wavelength(st) -> float:
        from engine.rd.compile import pattern_wavelength

        mask = st.fields.rho >= st.iso
        try:
            return float(np.mean([pattern_wavelength(s.astype(np.float64), mask=mask) for s in st.s]))
        except ValueError as exc:
            raise NodeInputError(f"cannot measure the pattern wavelength for min_member: {exc}",
                                 where="min_member") from None
