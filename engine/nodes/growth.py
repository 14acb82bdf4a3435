"""Virtual growth nodes (Liu, Sun & Daraio 2022): tile set, growth, and the
bridges from a tiling to the rest of the graph (image field, beam skeleton,
stiffness)."""

from __future__ import annotations

import json
import math

import numpy as np

from engine.batch.hints_text import parse_hints
from engine.fileio import file_digest
from engine.graph.errors import NodeInputError
from engine.graph.node import NodeType, register
from engine.graph.schema import Param, Port
from engine.graph.values import Field, LineElement, Skeleton, TilingValue
from engine.growth import grow_tiling, list_tilesets, load_tileset, tiling_beams, tiling_image
from engine.growth.regions import parse_region_hints, parse_region_map, region_hint_field
from engine.growth.regrow import regrow_region, regrowth_start
from engine.growth.tiling import UNASSIGNED
from engine.growth.tiling_io import tiling_from_dict, tiling_to_dict
from engine.geometry.voxel_inputs import SOLVER_BYTES_PER_DOF, memory_estimate_bytes
from engine.growth.properties import DEFAULT_RESOLUTION, VOID_MODES, homogenize_tiling

from .properties import stiffness_from_result

MAX_CELLS = 1_000_000
# Peak bytes per grid cell of a growth: the wave (possible tiles per cell),
# entropies, the recorded steps and the tiling; measured 92-129 B for TL+-
# (11 tiles) and cubic-beams-mixed (71 tiles), so a base plus a little per tile.
GROW_BYTES_PER_CELL = 128
GROW_BYTES_PER_CELL_TILE = 2
REGROW_MARGIN = 1  # cells cleared around a repainted region (square neighbourhood)


def _tileset_names() -> tuple:
    """Set names (not file stems) of the files in resources/tilesets."""
    return tuple(sorted(key for key, path in list_tilesets().items() if _name_of(path) == key))


def _name_of(path) -> str | None:
    try:
        return json.loads(path.read_text(encoding="utf-8")).get("name")
    except (OSError, ValueError, AttributeError):
        return None


TILESET_NAMES = _tileset_names() or ("TL+-",)
DEFAULT_TILESET = "TL+-" if "TL+-" in TILESET_NAMES else TILESET_NAMES[0]


@register
class TileSetNode(NodeType):
    """A tile set of building blocks with adjacency rules: one of the sets in
    resources/tilesets by name, or a tile-set JSON file when `path` is set."""

    type_name = "TileSet"
    title = "Tile Set"
    code = "ts"
    family = "topology"
    outputs = (Port("tileset", "TileSet"),)
    params = (
        Param("name", "enum", DEFAULT_TILESET, choices=TILESET_NAMES,
              doc="a tile set shipped in resources/tilesets"),
        Param("path", "str", "", doc="a tile-set JSON file; overrides name when not empty"),
    )

    @classmethod
    def source_token(cls, params):
        # the set is read from a file the user may edit (Tile Sets dock): its bytes key the cache
        path = params.get("path", "").strip()
        if not path:
            path = list_tilesets().get(params.get("name", ""), "")
        return file_digest(path) if path else ""

    def evaluate(self, inputs, params, ctx):
        source = params["path"].strip() or params["name"]
        try:
            return {"tileset": load_tileset(source)}
        except ValueError as exc:
            raise NodeInputError(str(exc), where="path" if params["path"].strip() else "name") \
                from None


def grid_shape(size, tileset) -> tuple:
    """``[nx, ny(, nz)]`` -> grid shape ``(ny, nx)`` / ``(nz, ny, nx)``."""
    ndim = tileset.ndim
    if len(size) != ndim:
        want = "[nx, ny]" if ndim == 2 else "[nx, ny, nz]"
        raise NodeInputError(f"size {list(size)} has {len(size)} entries but tile set "
                             f"{tileset.name!r} is {ndim}D: give {want}", where="size")
    if math.prod(size) > MAX_CELLS:
        raise NodeInputError(f"size {list(size)} has {math.prod(size)} cells; at most "
                             f"{MAX_CELLS} are allowed", where="size")
    return tuple(int(s) for s in size[::-1])


@register
class GrowNode(NodeType):
    """Virtual growth: fills a grid with tiles of the set by minimal-entropy
    wave-function collapse under the adjacency rules and frequency hints.
    The seed comes from the document seed and the node id. Repainting the
    hint regions regrows only the repainted cells; the tiling (with that
    history) is kept in the project file."""

    type_name = "Grow"
    title = "Grow"
    code = "grow"
    family = "topology"
    uses_rng = True
    stateful = True
    inputs = (Port("tileset", "TileSet"),)
    outputs = (Port("tiling", "Tiling"),)
    params = (
        Param("size", "int_list", [20, 20], 1, 1000, unit="blocks",
              doc="grid size [nx, ny] (2D set) or [nx, ny, nz] (3D set)"),
        Param("periodic", "bool", True,
              doc="opposite boundaries are neighbours: the tiling is a periodic cell"),
        Param("hints", "str", "",
              doc="frequency hints 'T=1,L=1,+=2,-=1' per block (or tile 'T@1'); "
                  "empty = the tile set's weights"),
        Param("availability", "float", 0.0, 0.0, 1e6,
              doc="blocks available per cell (paper's N); 0 = unlimited"),
        Param("regions", "str", "",
              doc="painted hint regions (2D): rows top to bottom separated by ';', one label "
                  "0-9/a-z per cell, '.' = 0; empty = no regions"),
        Param("region_hints", "str", "",
              doc="hints per painted label, e.g. '1: T=3,+=1 | 2: L=2'; label 0 uses `hints`"),
    )

    memory_param = "size"

    @classmethod
    def memory_estimate(cls, params, inputs_shape_info=None) -> int:
        ts = (inputs_shape_info or {}).get("tileset")
        n_tiles = 0 if ts is None else len(ts.tile_names)
        return math.prod(params["size"]) * (GROW_BYTES_PER_CELL + GROW_BYTES_PER_CELL_TILE * n_tiles)

    def evaluate(self, inputs, params, ctx):
        ts = inputs["tileset"]
        shape = grid_shape(params["size"], ts)
        try:
            hints = parse_hints(params["hints"], ts)
        except ValueError as exc:
            raise NodeInputError(str(exc), where="hints") from None
        field, labels = self._region_field(ts, shape, hints, params)
        availability = params["availability"] or None
        previous = ctx.previous.get("tiling") if ctx.previous else None
        changed = self._changed_cells(previous, ts, shape, params, labels, field, ctx)
        if changed is not None and not changed.any():
            # the same painted cells (a region text that parses alike, or a result
            # restored from a file under an older cache key): the tiling stays
            tiling = previous.tiling
            return {"tiling": TilingValue(tiling, ts, np.zeros((0, 2), np.int32), tiling.tiles)}
        if changed is not None:
            # Local regrowth (paper's repainting): only repainted cells plus a margin
            # grow again; every other tile stays byte-identical.
            start = regrowth_start(previous.tiling, changed, margin=REGROW_MARGIN)
            tiling = regrow_region(previous.tiling, ts, changed, margin=REGROW_MARGIN,
                                   hints=field if field is not None else hints, rng=ctx.seed,
                                   record_steps=True, progress=ctx.progress)
        else:
            start = np.full(shape, UNASSIGNED, np.int32)
            tiling = grow_tiling(ts, shape, hints=field if field is not None else hints,
                                 periodic=params["periodic"], availability=availability, rng=ctx.seed,
                                 record_steps=True, progress=ctx.progress)
        return {"tiling": TilingValue(tiling, ts, tiling.steps, start)}

    def encode_state(self, outputs):
        tv = outputs["tiling"]
        return {"tiling": tiling_to_dict(tv.tiling, tv.tileset)}

    def decode_state(self, blob, inputs):
        ts = inputs["tileset"]
        if ts is None:
            raise ValueError("no tile set is connected")
        if not isinstance(blob, dict) or not isinstance(blob.get("tiling"), dict):
            raise ValueError("expected {'tiling': <tiling document>}")
        tiling = tiling_from_dict(blob["tiling"], ts, source="stored tiling")
        return {"tiling": TilingValue(tiling, ts)}

    @staticmethod
    def _region_field(ts, shape, hints, params):
        try:
            labels = parse_region_map(params["regions"], shape)
        except ValueError as exc:
            raise NodeInputError(str(exc), where="regions") from None
        if labels is None:
            return None, None
        try:
            per_label = parse_region_hints(params["region_hints"], lambda text: parse_hints(text, ts))
        except ValueError as exc:
            raise NodeInputError(str(exc), where="region_hints") from None
        return region_hint_field(ts, shape, labels, hints, per_label), labels

    @staticmethod
    def _changed_cells(previous, ts, shape, params, labels, field, ctx):
        """Bool mask of the cells to regrow when at most the painted regions
        changed since the last evaluation of this node (same set, size, seed,
        periodicity; all False when nothing did); else None (grow afresh)."""
        prev_params = ctx.previous_params or {}
        same = (previous is not None and previous.tileset is ts and previous.tiling.tiles.shape == tuple(shape)
                and not params["availability"]
                and all(prev_params.get(k) == params[k] for k in ("size", "periodic", "hints", "availability"))
                and ctx.previous_seed == ctx.seed)
        if not same:
            return None
        try:
            old = parse_region_map(prev_params.get("regions", ""), shape)
        except ValueError:
            return None
        old = np.zeros(shape, np.int64) if old is None else old
        new = np.zeros(shape, np.int64) if labels is None else labels
        if prev_params.get("region_hints") != params["region_hints"]:
            changed = (old != new) | (new != 0) | (old != 0)
        else:
            changed = old != new
        return changed


@register
class TilingImageNode(NodeType):
    """Binary pixel image of a 2D tiling (1 = solid) as a scalar field over the
    box [0, nx] x [0, ny] in block units; defects are void."""

    type_name = "TilingImage"
    title = "Tiling Image"
    code = "timg"
    family = "topology"
    inputs = (Port("tiling", "Tiling"),)
    outputs = (Port("image", "Field"),)
    params = (
        Param("resolution", "int", 20, 2, 200, unit="px", doc="pixels per block edge (paper: 20)"),
        Param("line_width", "float", 4.0, 0.1, 200.0, unit="px", doc="member width in pixels"),
    )

    def evaluate(self, inputs, params, ctx):
        tv = inputs["tiling"]
        if tv.ndim != 2:
            raise NodeInputError(f"Tiling Image needs a 2D tiling; this one is {tv.ndim}D "
                                 f"(use Tiling Beams for 3D)", where="tiling")
        if params["line_width"] > params["resolution"]:
            raise NodeInputError(f"line_width {params['line_width']} px is wider than a block "
                                 f"({params['resolution']} px)", where="line_width")
        img = tiling_image(tv.tiling, tv.tileset, resolution=params["resolution"],
                           line_width=params["line_width"])
        ny, nx = tv.tiling.shape
        return {"image": Field(img.astype(np.float64), np.zeros(2), np.array([nx, ny], float))}


@register
class TilingBeamsNode(NodeType):
    """Member axes of a tiling as line elements of the given radius, scaled so
    the grid's longest side spans the unit cell: feed it to Object to thicken
    the grown lattice. A 2D tiling lies in the plane z = 0.5."""

    type_name = "TilingBeams"
    title = "Tiling Beams"
    code = "tbeam"
    family = "skeleton"
    inputs = (Port("tiling", "Tiling"),)
    outputs = (Port("skeleton", "Skeleton"),)
    params = (
        Param("radius", "float", 0.2, 0.01, 0.5, unit="block",
              doc="beam radius as a fraction of the block edge (paper: 1 mm in 5 mm blocks)"),
    )

    def evaluate(self, inputs, params, ctx):
        tv = inputs["tiling"]
        polys, radii = tiling_beams(tv.tiling, tv.tileset, cell_size=1.0,
                                    radius=params["radius"], normalize=True)
        if not polys:
            raise NodeInputError("the tiling holds no tiles (only defects)", where="tiling")
        elements = []
        for p, r in zip(polys, radii):
            p = np.asarray(p, dtype=np.float64)
            if p.shape[1] == 2:
                p = np.column_stack([p, np.full(len(p), 0.5)])
            elements.append(LineElement(p, np.full(len(p), 2.0 * r), p))
        ctx.check()
        return {"skeleton": Skeleton(tuple(elements))}


@register
class TilingPropertiesNode(NodeType):
    """Homogenized stiffness of a tiling with periodic boundary conditions:
    2D pixels in plane stress, 3D voxelized beams (cubic grids); a bounded
    tiling is treated as a statistical volume element (paper's SVE)."""

    type_name = "TilingProperties"
    title = "Tiling Properties"
    code = "tprop"
    family = "property"
    inputs = (Port("tiling", "Tiling"),)
    outputs = (Port("stiffness", "Stiffness"),)
    params = (
        Param("E", "float", 1.0, 1e-12, 1e15, unit="Pa", doc="Young's modulus of the solid"),
        Param("nu", "float", 0.46, -0.999, 0.499, doc="Poisson's ratio of the solid (paper: 0.46)"),
        Param("rho", "float", 1.0, 1e-12, 1e6, unit="kg/m^3", doc="density of the solid"),
        Param("resolution", "int", 0, 0, 200, unit="px",
              doc="pixels (2D) / voxels (3D) per block edge; 0 = 20 in 2D, 10 in 3D"),
        Param("line_width", "float", 0.0, 0.0, 200.0, unit="px",
              doc="2D member width; 0 = resolution / 5"),
        Param("radius", "float", 0.2, 0.01, 0.5, unit="block", doc="3D beam radius"),
        Param("void", "enum", "removed", choices=VOID_MODES,
              doc="removed: void carries nothing; soft: E_v = 1e-3 E (paper)"),
    )

    memory_param = "resolution"

    @classmethod
    def memory_estimate(cls, params, inputs_shape_info=None) -> int:
        tv = (inputs_shape_info or {}).get("tiling")
        return 0 if tv is None else tiling_properties_bytes(tv.tiling.shape, params["resolution"])

    def evaluate(self, inputs, params, ctx):
        tv = inputs["tiling"]
        res = params["resolution"] or None
        if res == 1:
            raise NodeInputError("resolution must be 0 (default) or >= 2", where="resolution")
        try:
            result = homogenize_tiling(tv.tiling, tv.tileset, E=params["E"], nu=params["nu"],
                                       resolution=res, line_width=params["line_width"] or None,
                                       radius=params["radius"], void=params["void"],
                                       progress=ctx.progress)
        except ValueError as exc:
            raise NodeInputError(str(exc)) from None
        n = res or (20 if tv.ndim == 2 else 10)
        return {"stiffness": stiffness_from_result(result, E=params["E"], nu=params["nu"],
                                                   rho=params["rho"], resolution=n)}


def tiling_properties_bytes(shape, resolution: int = 0) -> int:
    """Peak bytes of homogenizing a tiling of grid ``shape`` (blocks) at
    ``resolution`` pixels / voxels per block edge (0 = the default): the
    homogenization model of ``engine.geometry.voxel_inputs`` on its image."""
    n = resolution or DEFAULT_RESOLUTION[len(shape)]
    return memory_estimate_bytes(tuple(int(b) * n for b in shape), per_dof_bytes=SOLVER_BYTES_PER_DOF)
