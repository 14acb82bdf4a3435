"""Recording example graphs and replaying them as undoable commands.

Shared by tools/make_examples.py (unit cells) and tools/surface_examples.py
(shells and TPMS). Each method adds one node and returns its id, so an
example reads like its construction; `document` replays the nodes through
the undo stack as a user would, laid out in readable columns
(engine.graph.layout); `write_documents` adds each example's family and
one-line summary from tools/example_catalogue.py to its meta.
"""

from __future__ import annotations

from pathlib import Path

from engine.graph import AddNode, Connect, GraphDocument, UndoStack, save_project
from engine.graph.layout import fit_columns, layered_positions

from example_catalogue import catalogue_meta

OBJECT_RESOLUTION = 96          # Object node grid, as in the paper's examples
MATERIAL = {"E": 1.0, "nu": 0.45, "rho": 1.0}   # paper section 8.2
COLUMN_WIDTH = 250.0
ROW_HEIGHT = 110.0
EDITOR_VIEW = (420.0, 640.0)   # px: the node graph dock of the default layout on a 1366 x 768 screen

# Output / input port names of the node types the examples use.
_OUT = {"Vertex": "point", "EdgeChain": "chain", "Line": "skeleton", "Surface": "skeleton",
        "DualSurface": "skeleton", "AssociateFamily": "skeleton", "Mirror": "skeleton",
        "Transform": "skeleton", "Group": "skeleton", "Object": "solid", "CSGBoolean": "solid",
        "Voxel": "voxels", "MaterialMatrix": "stiffness"}
_IN = {"EdgeChain": "vertices", "Line": "chains", "Surface": "chains", "DualSurface": "skeleton",
       "AssociateFamily": "skeleton", "Mirror": "skeleton", "Transform": "skeleton",
       "Group": "skeletons", "Object": "skeleton", "CSGBoolean": "solids", "Voxel": "solid",
       "MaterialMatrix": "voxels"}


def r6(x) -> float:
    """A coordinate rounded to 1e-6 of a cell, so the JSON stays readable."""
    v = round(float(x), 6)
    return 0.0 if v == 0 else v


def vec6(p) -> list[float]:
    return [r6(c) for c in p]


class GraphBuilder:
    """Records the nodes of one example, then replays them (see module docstring).

    ``origin`` is where mirrors and transforms act by default; ``sep`` joins
    a construction's prefix to its node names.
    """

    origin = (0.5, 0.5, 0.5)
    sep = "_"

    def __init__(self, name: str, meta: dict):
        self.name = name
        self.meta = dict(meta)
        self._nodes: list[tuple[str, str, dict, list[str]]] = []

    # -- recording --------------------------------------------------------
    def _node(self, node_id: str, type_name: str, params: dict, inputs: list[str]) -> str:
        if any(n[0] == node_id for n in self._nodes):
            raise ValueError(f"{self.name}: duplicate node id {node_id!r}")
        self._nodes.append((node_id, type_name, params, list(inputs)))
        return node_id

    def vertex(self, node_id: str, position) -> str:
        return self._node(node_id, "Vertex", {"position": vec6(position)}, [])

    def chain(self, node_id: str, vertices: list[str], *, smooth: bool = False,
              order: list[int] | None = None, period=None, closed: bool = False) -> str:
        params: dict = {"smooth": smooth}
        if closed:
            order = list(range(len(vertices))) + [0]
        if order is not None:
            params["order"] = list(order)
        if period is not None:
            params["period"] = vec6(period)
        return self._node(node_id, "EdgeChain", params, vertices)

    def line(self, node_id: str, chains: list[str], thickness, *, samples_per_segment: int | None = None) -> str:
        params: dict = {"thickness": [[r6(t), r6(d)] for t, d in thickness]}
        if samples_per_segment is not None:
            params["samples_per_segment"] = samples_per_segment
        return self._node(node_id, "Line", params, chains)

    def mirror(self, node_id: str, source: str, direction, *, origin=None, copy: bool = True) -> str:
        origin = self.origin if origin is None else origin
        return self._node(node_id, "Mirror", {"direction": vec6(direction), "origin": vec6(origin),
                                              "do_copy": copy}, [source])

    def transform(self, node_id: str, source: str, *, angle: float = 0.0, axis=(0.0, 0.0, 1.0),
                  origin=None, translation=(0.0, 0.0, 0.0), scale: float = 1.0,
                  copy: bool = True) -> str:
        origin = self.origin if origin is None else origin
        return self._node(node_id, "Transform", {
            "origin": vec6(origin), "scale": float(scale), "rotation_angle": float(angle),
            "rotation_axis": vec6(axis), "translation": vec6(translation), "do_copy": copy}, [source])

    def group(self, node_id: str, sources: list[str]) -> str:
        return self._node(node_id, "Group", {}, sources)

    def object(self, node_id: str, skeleton: str, *, extrusion: str = "spherical", cell=None) -> str:
        """``cell``: the box edge lengths of a non-cubic periodic cell (default the unit cube)."""
        params = {"resolution": OBJECT_RESOLUTION, "extrusion": extrusion}
        if cell is not None:
            params["cell"] = vec6(cell)
        return self._node(node_id, "Object", params, [skeleton])

    def csg(self, node_id: str, solids: list[str], operation: str = "union") -> str:
        return self._node(node_id, "CSGBoolean", {"operation": operation}, solids)

    def voxel(self, node_id: str, solid: str) -> str:
        return self._node(node_id, "Voxel", dict(MATERIAL), [solid])

    def material_matrix(self, node_id: str, voxels: str, *, resolution: int) -> str:
        """The stiffness tensor of the voxelized cell (paper 6.6)."""
        return self._node(node_id, "MaterialMatrix", {"resolution": int(resolution)}, [voxels])

    # -- shared constructions ---------------------------------------------
    def threefold(self, prefix: str, source: str) -> str:
        """Copies at 0, 120 and 240 degrees about the body diagonal through
        ``origin`` (x -> y -> z -> x): two rotations of the same input and a
        group, so nothing is duplicated."""
        s, diagonal = self.sep, (1.0, 1.0, 1.0)
        a = self.transform(f"{prefix}{s}rot120", source, angle=120.0, axis=diagonal)
        b = self.transform(f"{prefix}{s}rot240", source, angle=240.0, axis=diagonal, copy=False)
        return self.group(f"{prefix}{s}xyz", [a, b])

    # -- replay -----------------------------------------------------------
    def positions(self) -> dict[str, tuple[float, float]]:
        """Readable columns (engine.graph.layout.layered_positions): a node's
        column is its depth, rows ordered to reduce edge crossings, the columns
        wrapped into bands so the graph reads largest in the default node editor
        (`EDITOR_VIEW`, engine.graph.layout.fit_columns)."""
        edges = [(src, node_id) for node_id, _, _, inputs in self._nodes for src in inputs]
        ids = [n[0] for n in self._nodes]
        bands = fit_columns(ids, edges, EDITOR_VIEW, column_width=COLUMN_WIDTH, row_height=ROW_HEIGHT)
        return layered_positions(ids, edges, column_width=COLUMN_WIDTH, row_height=ROW_HEIGHT,
                                 max_columns=bands)

    def document(self) -> GraphDocument:
        doc = GraphDocument(seed=0)
        doc.meta = dict(self.meta)
        stack = UndoStack(doc)
        pos = self.positions()
        types = {n[0]: n[1] for n in self._nodes}
        for node_id, type_name, params, inputs in self._nodes:
            stack.push(AddNode(type_name, params, pos[node_id], node_id=node_id))
            for src in inputs:
                stack.push(Connect(src, _OUT[types[src]], node_id, _IN[type_name]))
        return doc


def write_documents(builders: dict, out_dir, names=None, *, prefix: str = "") -> dict[Path, GraphDocument]:
    """Save ``builders[name]()`` for each name (all by default) as ``<out_dir>/<prefix><name>.json``."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = {}
    for name in names or builders:
        doc = builders[name]()
        doc.meta.update(catalogue_meta(f"{prefix}{name}"))   # family and one-line summary
        path = out / f"{prefix}{name}.json"
        save_project(doc, path)
        written[path] = doc
    return written
