"""Virtual growth nodes (Liu, Sun & Daraio 2022): tile set, growth, and the
bridges from a tiling to the rest of the graph (image field, beam skeleton,
stiffness)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from engine.fileio import file_digest
from engine.graph.errors import NodeInputError
from engine.graph.node import NodeType, register
from engine.graph.schema import Param, Port
from engine.geometry.values import Field, LineElement, Skeleton
from engine.growth import list_tilesets, load_tileset, tiling_beams, tiling_image
from engine.geometry.voxel_inputs import SOLVER_BYTES_PER_DOF, memory_estimate_bytes
from engine.growth.properties import DEFAULT_RESOLUTION, VOID_MODES, homogenize_tiling

from .growth_plan import (DERIVED_SEED, MAX_CELLS, REGROW_MARGIN, GrowthPlan, grid_shape,
                          tiling_seed)
from .properties import stiffness_from_result

__all__ = ["TileSetNode", "GrowNode", "TilingImageNode", "TilingBeamsNode", "TilingPropertiesNode",
           "MAX_CELLS", "REGROW_MARGIN", "grid_shape", "tiling_properties_bytes", "tileset_params", "PROPERTIES_TOL"]
# Peak bytes per grid cell of a growth: the wave (possible tiles per cell),
# entropies, the recorded steps and the tiling; measured 92-129 B for TL+-
# (11 tiles) and cubic-beams-mixed (71 tiles), so a base plus a little per tile.
GROW_BYTES_PER_CELL = 128
GROW_BYTES_PER_CELL_TILE = 2
PROPERTIES_TOL = 1e-6  # relative accuracy of the Tiling Properties solve (on the diagonal of C)


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


def tileset_params(source) -> dict:
    """TileSet node parameters that load ``source``: ``{"name": ...}`` for a set
    shipped in resources/tilesets (by set name), else ``{"path": file}`` for a
    file stem, a path or a TileSet read from a file.

    Raises ValueError when ``source`` does not load (the message of
    ``load_tileset``) or is a TileSet held only in memory (no file to read)."""
    from engine.growth import TileSet

    if isinstance(source, TileSet):
        ts = source
    else:
        text = str(source)
        if text in TILESET_NAMES:
            return {"name": text}
        ts = load_tileset(text)
    if ts.source is None:
        raise ValueError(f"tile set {ts.name!r} was not read from a file; save it first")
    shipped = list_tilesets().get(ts.name)
    if shipped is not None and ts.name in TILESET_NAMES and Path(shipped).resolve() == Path(ts.source).resolve():
        return {"name": ts.name}
    return {"path": str(Path(ts.source).resolve())}


@register
class GrowNode(NodeType):
    """Virtual growth: fills a grid with tiles of the set by minimal-entropy
    wave-function collapse under the adjacency rules and frequency hints.
    The seed comes from the document seed and the node id unless the
    ``seed`` parameter gives one. Repainting the hint regions regrows only the
    repainted cells; the tiling (with that history) is kept in the project
    file. What runs is a `GrowthPlan` (engine.nodes.growth_plan), shared with
    the command line and the Virtual Growth dock."""

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
        # 63-bit: study seeds are engine.batch.sample_seed values
        Param("seed", "int", DERIVED_SEED, DERIVED_SEED, 2**63 - 1,
              doc="tiling seed (an integer >= 0) used as is; -1 = derived from the document "
                  "seed and the node id"),
    )

    memory_param = "size"

    @classmethod
    def memory_estimate(cls, params, inputs_shape_info=None) -> int:
        ts = (inputs_shape_info or {}).get("tileset")
        n_tiles = 0 if ts is None else len(ts.tile_names)
        return math.prod(params["size"]) * (GROW_BYTES_PER_CELL + GROW_BYTES_PER_CELL_TILE * n_tiles)

    def evaluate(self, inputs, params, ctx):
        plan = GrowthPlan.from_params(params, inputs["tileset"], tiling_seed(params, ctx.seed))
        previous = ctx.previous.get("tiling") if ctx.previous else None
        prev_params = ctx.previous_params or {}
        prev_seed = None if ctx.previous_seed is None else tiling_seed(prev_params, ctx.previous_seed)
        return {"tiling": plan.evaluate(previous, prev_params, prev_seed, progress=ctx.progress)}



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
                                       tol=PROPERTIES_TOL, progress=ctx.progress)
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
