"""The example graphs in resources/examples: they evaluate, tile and stay in sync.

Every ``resources/examples/*.json`` is loaded, its Object resolution lowered
to keep the run short, and evaluated.  The final solid (the Voxel node's
input) must be a closed mesh that tiles: the single-cell mesh matches across
opposite faces, and a 2x2x2 block is one closed, connected piece.  The node
count must stay within +-30% of the paper's Table 4 (Makatura et al. 2023),
and the files must be exactly what ``tools/make_examples.py`` writes.

Every example (cells, shells, properties, growth, phasor, RD) carries a
family and a one-line summary for the gallery and ships laid out in columns;
the property and growth examples evaluate to a stiffness tensor.
"""

from __future__ import annotations

import functools
import json
from pathlib import Path

import numpy as np
import pytest
import trimesh

from engine.graph import load_project

from .example_files import EXAMPLES_DIR, check_reading_layout, evaluate_at, load_tool

TEST_RESOLUTION = 48

# Table 4, column #all.  BCC is not in the paper; 12 is our own reference
# (the paper's smallest truss graph, the octet, has 12 nodes).
PAPER_NODE_COUNT = {
    "octet": 12,
    "bcc": 12,
    "fcc_lattice": 19,       # "3D FCC lattice"
    "auxetic3d": 17,
    "anti_chiral": 13,
    "assembled": 20,
    "assembled2": 15,
    "assembled3": 15,
    "twist_tilable": 33,
    "six_hole_bcc": 27,      # "6-hole BCC"
    "bandgap": 30,
}
ALL_FILES = sorted(EXAMPLES_DIR.glob("*.json"))
FILES = sorted(p for p in ALL_FILES if p.stem in PAPER_NODE_COUNT)  # unit cells
VOLUME_FRACTION_BAND = (0.02, 0.6)


def _load_generator():
    return load_tool("make_examples")


@functools.lru_cache(maxsize=None)
def _evaluated(path: Path):
    """(document, report, final solid) at the test resolution; cached per file."""
    doc, report = evaluate_at(path, TEST_RESOLUTION)
    voxels = [n for n, node in doc.nodes.items() if node.type_name == "Voxel"]
    solid = None
    if report.ok and len(voxels) == 1:
        (edge,) = doc.inputs_of(voxels[0], "solid")
        solid = report.outputs[edge.src][edge.src_port]
    return doc, report, solid


def _mesh(vertices, faces) -> trimesh.Trimesh:
    # process=False: judge the mesh exactly as the kernel produced it.
    return trimesh.Trimesh(np.asarray(vertices, float), np.asarray(faces, np.int64), process=False)


def _components(mesh: trimesh.Trimesh) -> int:
    return len(mesh.split(only_watertight=False))


@pytest.fixture(params=FILES, ids=[p.stem for p in FILES])
def example(request):
    doc, report, solid = _evaluated(request.param)
    assert report.ok, f"{request.param.name}: failed nodes {report.errors}"
    return request.param.stem, doc, solid


def test_every_generated_example_is_present():
    generator = _load_generator()
    every = sorted(n if n in generator.EXAMPLES or not n in generator.SURFACE_EXAMPLES else "tpms_" + n
                   for builders, _ in generator.all_writers().values() for n in builders)
    assert sorted(p.stem for p in ALL_FILES) == every
    assert sorted(PAPER_NODE_COUNT) == sorted(generator.EXAMPLES)


def test_files_are_what_the_generator_writes(tmp_path):
    generator = _load_generator()
    generator.write_all(tmp_path)
    fresh = {p.name: json.loads(p.read_text()) for p in sorted(tmp_path.glob("*.json"))}
    stored = {p.name: json.loads(p.read_text()) for p in ALL_FILES}
    assert sorted(fresh) == sorted(stored)
    for name in fresh:
        assert fresh[name] == stored[name], f"{name} differs from tools/make_examples.py: regenerate it"


@pytest.mark.parametrize("path", FILES, ids=[p.stem for p in FILES])
def test_graph_shape(path):
    doc = load_project(path)
    types = [n.type_name for n in doc.nodes.values()]
    assert types.count("Voxel") == 1
    (vox,) = [n for n in doc.nodes.values() if n.type_name == "Voxel"]
    assert vox.params["E"] == 1.0 and vox.params["nu"] == 0.45 and vox.params["rho"] == 1.0
    objects = [n for n in doc.nodes.values() if n.type_name == "Object"]
    assert objects and all(n.params["resolution"] == 96 for n in objects)
    reference = PAPER_NODE_COUNT[path.stem]
    assert 0.7 * reference <= len(doc.nodes) <= 1.3 * reference, \
        f"{path.stem}: {len(doc.nodes)} nodes, paper {reference}"
    paper = doc.meta.get("paper_node_count")
    assert paper is None or paper == reference
    check_reading_layout(doc, path.stem)


def test_evaluates_to_one_voxel_model(example):
    name, doc, solid = example
    assert solid is not None
    assert solid.resolution == TEST_RESOLUTION


def test_final_solid_is_closed(example):
    from engine.geometry.mesh_io import mesh_summary
    name, doc, solid = example
    summary = mesh_summary(solid.vertices, solid.faces)
    assert summary["watertight"], f"{name}: single-cell mesh is not closed"
    assert summary["volume"] > 0.0


def test_volume_fraction_is_plausible(example):
    name, doc, solid = example
    lo, hi = VOLUME_FRACTION_BAND
    assert lo < solid.volume_fraction < hi, f"{name}: volume fraction {solid.volume_fraction:.3f}"
    mesh = _mesh(solid.vertices, solid.faces)
    # the mesh volume (cell size 1) agrees with the voxel count
    assert abs(mesh.volume - solid.volume_fraction) < 0.25 * solid.volume_fraction + 0.01


def test_cell_faces_match(example):
    from engine.geometry.marching import boundary_section_match
    name, doc, solid = example
    assert boundary_section_match(solid.vertices, solid.faces, cell_size=solid.cell_size) < 1e-6


def test_single_cell_is_connected(example):
    # Every example is designed so that the members inside one cell already
    # hang together (each piece cut by a cell face is attached to the rest).
    name, doc, solid = example
    assert _components(_mesh(solid.vertices, solid.faces)) == 1, f"{name}: cell falls apart"


def test_tiled_block_is_one_closed_piece(example):
    from engine.geometry.marching import periodic_mesh
    name, doc, solid = example
    vertices, faces = periodic_mesh(solid.sdf, cell_size=solid.cell_size, tiles=(2, 2, 2))
    mesh = _mesh(vertices, faces)
    assert mesh.is_watertight, f"{name}: 2x2x2 block is not closed"
    assert _components(mesh) == 1, f"{name}: 2x2x2 block falls apart"
    single = _mesh(solid.vertices, solid.faces)
    assert mesh.volume == pytest.approx(8.0 * single.volume, rel=1e-3)


# ----------------------------------------------------------------- every example: gallery and layout

@pytest.mark.parametrize("path", ALL_FILES, ids=[p.stem for p in ALL_FILES])
def test_meta_names_family_and_one_line_summary(path):
    catalogue = load_tool("example_catalogue")
    meta = load_project(path).meta
    assert meta["family"] in catalogue.FAMILIES, f"{path.stem}: family {meta.get('family')!r}"
    summary = meta["summary"]
    assert summary and "\n" not in summary and len(summary) <= 100, f"{path.stem}: summary {summary!r}"
    assert meta["title"] and meta["description"]


def test_every_family_has_an_example():
    catalogue = load_tool("example_catalogue")
    families = {load_project(p).meta["family"] for p in ALL_FILES}
    assert families == set(catalogue.FAMILIES)


@pytest.mark.parametrize("path", ALL_FILES, ids=[p.stem for p in ALL_FILES])
def test_layout_is_readable_columns(path):
    """The layout of engine.graph.layout, wrapped into bands that fit the default node
    editor (tools/graph_builder.EDITOR_VIEW) at least as well as one long row."""
    from engine.graph.layout import fit_columns

    doc = load_project(path)
    check_reading_layout(doc, path.stem)
    builder = load_tool("make_examples")            # its graph_builder constants
    edges = [(e.src, e.dst) for e in doc.edges]
    xs = {n.position[0] for n in doc.nodes.values()}
    assert len(xs) == fit_columns(list(doc.nodes), edges, builder.EDITOR_VIEW,
                                  column_width=builder.COLUMN_WIDTH, row_height=builder.ROW_HEIGHT)


# ----------------------------------------------------------------- property and growth examples

PROPERTY_FILES = [EXAMPLES_DIR / "octet_stiffness.json", EXAMPLES_DIR / "schwarz_p_stiffness.json"]
GROWTH_FILES = sorted(EXAMPLES_DIR.glob("growth_*.json"))
PROPERTY_TEST_RESOLUTION = 24       # Object grid and solve grid: enough for a cubic C


def _stiffness_nodes(doc, type_name):
    return [nid for nid, node in doc.nodes.items() if node.type_name == type_name]


@pytest.mark.parametrize("path", PROPERTY_FILES, ids=[p.stem for p in PROPERTY_FILES])
def test_property_example_gives_a_cubic_stiffness(path):
    from engine.graph import Evaluator, SetParam, UndoStack
    from engine.physics.values import Stiffness

    doc = load_project(path)
    (mm,) = _stiffness_nodes(doc, "MaterialMatrix")
    stack = UndoStack(doc)
    for nid, node in doc.nodes.items():
        if node.type_name == "Object":
            stack.push(SetParam(nid, "resolution", PROPERTY_TEST_RESOLUTION))
    stack.push(SetParam(mm, "resolution", PROPERTY_TEST_RESOLUTION))
    report = Evaluator().evaluate(doc)
    assert report.ok, report.errors
    stiffness = report.outputs[mm]["stiffness"]
    assert isinstance(stiffness, Stiffness)
    C = np.asarray(stiffness.C)
    assert C.shape == (6, 6) and np.allclose(C, C.T, atol=1e-8 * abs(C).max())
    assert np.all(np.linalg.eigvalsh(C) > 0)          # a connected cell carries load every way
    # both cells have the cube's symmetry: C11 = C22 = C33 to discretisation
    assert np.ptp(np.diag(C)[:3]) < 0.05 * C[0, 0]
    assert 0.0 < stiffness.density < 1.0


def test_growth_examples_are_present():
    assert len(GROWTH_FILES) >= 3
    assert any(len(load_project(p).node("grow").params["size"]) == 3 for p in GROWTH_FILES)


@pytest.mark.parametrize("path", GROWTH_FILES, ids=[p.stem for p in GROWTH_FILES])
def test_growth_example_grows_and_gives_tiling_properties(path):
    from engine.graph import Evaluator
    from engine.physics.values import Stiffness

    doc = load_project(path)
    (grow,) = _stiffness_nodes(doc, "Grow")
    (props,) = _stiffness_nodes(doc, "TilingProperties")
    assert [e.src for e in doc.inputs_of(props)] == [grow]     # the growth dock finds it downstream
    report = Evaluator().evaluate(doc)
    assert report.ok, report.errors
    tiling = report.outputs[grow]["tiling"].tiling
    assert tuple(tiling.shape[::-1]) == tuple(doc.node(grow).params["size"]) or \
        tuple(tiling.shape) == tuple(doc.node(grow).params["size"])
    stiffness = report.outputs[props]["stiffness"]
    assert isinstance(stiffness, Stiffness)
    C = np.asarray(stiffness.C)
    assert C.shape == ((3, 3) if len(doc.node(grow).params["size"]) == 2 else (6, 6))
    assert np.all(np.linalg.eigvalsh(0.5 * (C + C.T)) > 0)
    assert 0.0 < stiffness.density < 1.0


def test_hints_change_the_grown_mix():
    """The hinted example asks for more + and - blocks than the set's weights and gets them."""
    from engine.graph import Evaluator
    from engine.growth.hints import realised_probabilities

    share = {}
    for stem in ("growth_tl_2d", "growth_tl_hints"):
        tv = Evaluator().evaluate(load_project(EXAMPLES_DIR / f"{stem}.json")).outputs["grow"]["tiling"]
        p = realised_probabilities(tv.tiling, tv.tileset)
        names = list(tv.tileset.block_names)
        share[stem] = p[names.index("+")] + p[names.index("-")]
    assert share["growth_tl_hints"] > share["growth_tl_2d"] + 0.05
