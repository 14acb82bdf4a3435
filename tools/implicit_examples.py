"""The implicit media examples (paper 004): particle suspensions, ice with bubbles, gyroid
fibres, a rock pile, an agglomerated porous lattice, a graded gyroid, a suspension blended
with an octet cell and multiscale ice whose bubble density is painted.  Each ends in an SDF
Solid node (what the viewport, the thumbnail and the exports show); the Implicit Media dock traces the SDF nodes themselves.  Written by
tools/make_examples.py."""

from __future__ import annotations

from pathlib import Path
from typing import Callable

from engine.graph import AddNode, Connect, GraphDocument, MoveNode, RemoveNode, UndoStack
from engine.graph.layout import fit_columns, layered_positions
from graph_builder import COLUMN_WIDTH, EDITOR_VIEW, ROW_HEIGHT, write_documents

SOURCE = "Bhaskar et al., procedural multiscale geometry with implicit functions (paper 004)"


def _document(name: str, title: str, description: str, nodes, edges, *, base: GraphDocument | None = None):
    """A document of `nodes` ``(id, type, params)`` joined by `edges` ``(src, port, dst, port)``,
    laid out in readable columns; added to `base` (a unit cell built before) if given."""
    doc = base if base is not None else GraphDocument(seed=0)
    doc.meta = {"example": name, "title": title, "source": SOURCE, "paper_node_count": None,
                "description": description}
    stack = UndoStack(doc)
    old = [(e.src, e.dst) for e in doc.edges]
    ids = list(doc.nodes) + [n[0] for n in nodes]
    links = old + [(e[0], e[2]) for e in edges]
    bands = fit_columns(ids, links, EDITOR_VIEW, column_width=COLUMN_WIDTH, row_height=ROW_HEIGHT)
    pos = layered_positions(ids, links, column_width=COLUMN_WIDTH, row_height=ROW_HEIGHT, max_columns=bands)
    for nid in list(doc.nodes):
        stack.push(MoveNode(nid, pos[nid]))
    for node_id, type_name, params in nodes:
        stack.push(AddNode(type_name, params, pos[node_id], node_id=node_id))
    for edge in edges:
        stack.push(Connect(*edge))
    return doc


def _solid(resolution=128, lo=None, hi=None, periodic=False):
    params = {"resolution": resolution, "periodic": periodic}
    if lo is not None:
        params.update(fit_box=False, box_from=list(lo), box_to=list(hi))
    return params


def implicit_multiphase() -> GraphDocument:
    return _document(
        "implicit_multiphase", "Multi-phase particle suspension",
        "Two particle clouds in one medium (paper 004, sections 3.1 and 10.1): small spheres of "
        "uniform sizes on a 0.25 mm grid, and larger rounded boxes at random orientations on a 0.5 mm "
        "grid with half the cells empty. The Boolean union is the two-phase suspension; the SDF "
        "Solid voxelises a 2 mm box of it. Select a Particles node to trace it in the Implicit "
        "Media dock and see its size histogram.",
        [("spheres", "Particles", {"cell": 0.25, "distribution": "uniform", "size_a": 0.04, "size_b": 0.09,
                                   "seed": 1}),
         ("boxes", "Particles", {"cell": 0.5, "shape": "round_box", "distribution": "uniform", "size_a": 0.15,
                                 "size_b": 0.25, "orient": True, "density": 0.5, "seed": 2}),
         ("mix", "SDFBoolean", {"operation": "union"}),
         ("solid", "SDFSolid", _solid(128, (0, 0, 0), (2, 2, 2)))],
        [("spheres", "sdf", "mix", "a"), ("boxes", "sdf", "mix", "b"), ("mix", "sdf", "solid", "sdf")])


def implicit_ice_bubbles() -> GraphDocument:
    return _document(
        "implicit_ice_bubbles", "Ice with air bubbles",
        "A rounded block of ice with air bubbles (paper 004, Fig. 3): a cloud of spheres on a "
        "0.2 mm grid whose density falls from 1 at the bottom to 0.15 at the top, cut out of the "
        "block by a Boolean difference. Path trace it in the Implicit Media dock (dielectric "
        "surfaces) to see the bubbles scatter.",
        [("ice", "SDFShape", {"shape": "round_box", "extent": [2.0, 2.0, 2.0], "rounding": 0.15,
                              "centre": [1.0, 1.0, 1.0]}),
         ("bubbles", "Particles", {"cell": 0.2, "distribution": "lognormal", "size_a": -3.2, "size_b": 0.35,
                                   "graded": True, "density": 1.0, "density_end": 0.15, "grade_axis": "z",
                                   "grade_from": 0.0, "grade_to": 2.0, "seed": 3}),
         ("cut", "SDFBoolean", {"operation": "difference"}),
         ("solid", "SDFSolid", _solid(128))],
        [("ice", "sdf", "cut", "a"), ("bubbles", "sdf", "cut", "b"), ("cut", "sdf", "solid", "sdf")])


def implicit_paper_fibres() -> GraphDocument:
    return _document(
        "implicit_paper_fibres", "Paper fibres from a gyroid",
        "A gyroid sheet flattened four times along z and stretched along x (paper 004, Fig. 9): its "
        "channels become flat, interwoven fibre-like strands, as in a sheet of paper. The transform "
        "is non-uniform, so the field is not a distance any more; it carries its gradient bound and "
        "the tracer and the mesher divide by it.",
        [("gyroid", "PeriodicFunction", {"kind": "gyroid", "variant": "sheet", "cell": 0.5, "level_by": "level",
                                         "level": 0.35}),
         ("press", "SDFTransform", {"scale": [2.0, 1.0, 0.25]}),
         ("solid", "SDFSolid", _solid(160, (0, 0, 0), (2, 2, 0.5)))],
        [("gyroid", "sdf", "press", "sdf"), ("press", "sdf", "solid", "sdf")])


def implicit_rock_pile() -> GraphDocument:
    return _document(
        "implicit_rock_pile", "Rock pile, convex to concave",
        "Grains piled in contact (paper 004, eq. 10, Fig. 6): rounded boxes, one per cell of a "
        "lattice deformed by a noise, each turned by an integer polynomial of its cell index, going "
        "from convex at the bottom to dimpled at the top of a 6 mm pile.",
        [("pile", "Pile", {"cell": 1.0, "grain": "round_box", "radius": 0.45, "rounding": 0.35,
                           "concavity": 0.0, "graded": True, "concavity_end": 1.0, "grade_from": 0.0,
                           "grade_to": 6.0, "deform": [0.15, 0.0, 0.0], "noise_frequency": 3.0}),
         ("solid", "SDFSolid", _solid(160, (0, 0, 0), (6, 6, 6)))],
        [("pile", "sdf", "solid", "sdf")])


def implicit_porous_lattice() -> GraphDocument:
    return _document(
        "implicit_porous_lattice", "Agglomerated porous lattice",
        "A cubic lattice of spheres whose particles are kept only where at least two cell "
        "coordinates are multiples of 4 (paper 004, eq. 9): the kept spheres merge into an open "
        "cubic frame. One period (0.4 mm) is voxelised as a tileable cell and homogenised: the "
        "Material Matrix gives its stiffness.",
        [("frame", "Agglomerate", {"cell": 0.1, "size": 0.07, "structure": "cubic frame", "period": 4}),
         ("solid", "SDFSolid", _solid(64, (0, 0, 0), (0.4, 0.4, 0.4), periodic=True)),
         ("voxel", "Voxel", {"E": 1.0, "nu": 0.3}),
         ("stiffness", "MaterialMatrix", {"resolution": 32})],
        [("frame", "sdf", "solid", "sdf"), ("solid", "solid", "voxel", "solid"),
         ("voxel", "voxels", "stiffness", "voxels")])


def implicit_graded_gyroid() -> GraphDocument:
    return _document(
        "implicit_graded_gyroid", "Graded gyroid",
        "A gyroid network whose solid volume fraction rises from 15 % at the bottom to 50 % at "
        "the top of a 4 mm column (the level interpolated between the calibrated ends, paper 004, "
        "section 3.4).",
        [("gyroid", "PeriodicFunction", {"kind": "gyroid", "cell": 1.0, "volume_fraction": 0.15, "graded": True,
                                         "volume_fraction_end": 0.5, "grade_axis": "z", "grade_from": 0.0,
                                         "grade_to": 4.0}),
         ("solid", "SDFSolid", _solid(128, (0, 0, 0), (2, 2, 4)))],
        [("gyroid", "sdf", "solid", "sdf")])


def implicit_suspension_octet() -> GraphDocument:
    from make_examples import octet

    base = octet().document()
    (obj,) = [nid for nid, n in base.nodes.items() if n.type_name == "Object"]
    for nid in [nid for nid, n in base.nodes.items() if n.type_name in ("Voxel", "MaterialMatrix")]:
        UndoStack(base).push(RemoveNode(nid))
    return _document(
        "implicit_suspension_octet", "Suspension blended with an octet cell",
        "The octet truss cell as an SDF (Cell SDF: its sampled distance, tiled) blended with a "
        "cloud of small spheres by a smooth union: particles stuck to the struts with fillets. "
        "One unit cell is voxelised.",
        [("cell_sdf", "CellSDF", {}),
         ("grains", "Particles", {"cell": 0.125, "distribution": "uniform", "size_a": 0.02, "size_b": 0.045,
                                  "seed": 5}),
         ("blend", "SDFBoolean", {"operation": "smooth union", "blend": 0.03}),
         ("solid", "SDFSolid", _solid(128, (0, 0, 0), (1, 1, 1)))],
        [(obj, "solid", "cell_sdf", "solid"), ("cell_sdf", "sdf", "blend", "a"), ("grains", "sdf", "blend", "b"),
         ("blend", "sdf", "solid", "sdf")], base=base)


def implicit_multiscale_ice() -> GraphDocument:
    return _document(
        "implicit_multiscale_ice", "Multiscale ice, density painted",
        "Ice whose air bubbles change scale with height (paper 004, teaser and section 3.1): two "
        "clouds on different grids, small bubbles on a 0.2 mm grid and large ones on a 0.75 mm grid, "
        "each kept cell by cell with the probability its Scalar Field gives at the cell centre. The "
        "small bubbles' field ramps from 1 at the bottom to 0 at the top, the large ones' the other way, "
        "so the two scales hand over smoothly; a painted stroke clears a bubble-free band through the "
        "small bubbles. Select a Scalar Field to paint it in the Implicit Media dock (each stroke is one "
        "undo step). The SDF Solid shows the air (the block intersected with both clouds); the ice "
        "itself, the block minus the clouds, is the node ice_with_air: select it to trace it.",
        [("ice", "SDFShape", {"shape": "round_box", "extent": [3.0, 3.0, 3.0], "rounding": 0.2,
                              "centre": [1.5, 1.5, 1.5]}),
         ("small_density", "ScalarField", {
             "lo": [0.0, 0.0, 0.0], "hi": [3.0, 3.0, 3.0], "resolution": 24, "mode": "ramp", "ramp_axis": "z",
             "ramp_from": 0.0, "ramp_to": 3.0, "value_from": 1.0, "value_to": 0.0, "clamp": True,
             "strokes": [{"axis": "y", "position": 1.5, "points": [[0.0, 0.6], [1.5, 1.2], [3.0, 0.9]],
                          "radius": 0.25, "value": 0.0, "strength": 1.0, "falloff": "smooth", "depth": 30.0}]}),
         ("large_density", "ScalarField", {
             "lo": [0.0, 0.0, 0.0], "hi": [3.0, 3.0, 3.0], "resolution": 12, "mode": "ramp", "ramp_axis": "z",
             "ramp_from": 0.5, "ramp_to": 3.0, "value_from": 0.0, "value_to": 0.7, "clamp": True}),
         ("small", "Particles", {"cell": 0.2, "distribution": "uniform", "size_a": 0.03, "size_b": 0.07,
                                 "seed": 4}),
         ("large", "Particles", {"cell": 0.75, "distribution": "uniform", "size_a": 0.12, "size_b": 0.28,
                                 "seed": 5}),
         ("bubbles", "SDFBoolean", {"operation": "union"}),
         ("air", "SDFBoolean", {"operation": "intersection"}),
         ("ice_with_air", "SDFBoolean", {"operation": "difference"}),
         ("solid", "SDFSolid", _solid(160))],
        [("small_density", "field", "small", "density"), ("large_density", "field", "large", "density"),
         ("small", "sdf", "bubbles", "a"), ("large", "sdf", "bubbles", "b"),
         ("ice", "sdf", "air", "a"), ("bubbles", "sdf", "air", "b"),
         ("ice", "sdf", "ice_with_air", "a"), ("bubbles", "sdf", "ice_with_air", "b"),
         ("air", "sdf", "solid", "sdf")])


IMPLICIT_EXAMPLES: dict[str, Callable[[], GraphDocument]] = {
    "implicit_multiphase": implicit_multiphase,
    "implicit_ice_bubbles": implicit_ice_bubbles,
    "implicit_paper_fibres": implicit_paper_fibres,
    "implicit_rock_pile": implicit_rock_pile,
    "implicit_porous_lattice": implicit_porous_lattice,
    "implicit_graded_gyroid": implicit_graded_gyroid,
    "implicit_suspension_octet": implicit_suspension_octet,
    "implicit_multiscale_ice": implicit_multiscale_ice,
}


def write_implicit_examples(out_dir: str | Path, names=None) -> dict[Path, GraphDocument]:
    """Build the implicit media examples (all, or `names`) as ``<out_dir>/<name>.json``."""
    return write_documents(IMPLICIT_EXAMPLES, out_dir, names)
