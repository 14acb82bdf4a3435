"""The implicit media examples evaluate to closed solids, their SDF nodes trace, the porous
lattice homogenises to a cubic stiffness, and the multiscale ice hands its bubbles over from
small to large with height."""

from __future__ import annotations

import pytest

from engine.geometry.mesh_io import mesh_summary
from engine.graph import Evaluator, SetParam, UndoStack, load_project

from .example_files import EXAMPLES_DIR

FILES = sorted(EXAMPLES_DIR.glob("implicit_*.json"))


def test_every_implicit_example_the_builder_makes_ships():
    import sys

    from .example_files import ROOT
    sys.path.insert(0, str(ROOT / "tools"))
    try:
        from implicit_examples import IMPLICIT_EXAMPLES
    finally:
        sys.path.remove(str(ROOT / "tools"))
    assert sorted(IMPLICIT_EXAMPLES) == [p.stem for p in FILES]
    assert len(FILES) >= 8


@pytest.mark.parametrize("path", FILES, ids=[p.stem for p in FILES])
def test_an_implicit_example_evaluates_to_a_closed_solid(path):
    doc = load_project(path)
    stack = UndoStack(doc)
    for nid, node in doc.nodes.items():
        if node.type_name in ("SDFSolid", "Object"):
            stack.push(SetParam(nid, "resolution", 48))
    report = Evaluator().evaluate(doc)
    assert report.ok, report.errors
    (solid_id,) = [n for n, node in doc.nodes.items() if node.type_name == "SDFSolid"]
    solid = report.output(solid_id)
    summary = mesh_summary(solid.vertices, solid.faces)
    assert summary["watertight"], path.stem
    assert 0.02 < solid.volume_fraction < 0.98
    for nid, node in doc.nodes.items():
        if node.type_name == "MaterialMatrix":
            assert report.output(nid).symmetry == "cubic"


def test_the_multiscale_ice_hands_over_from_small_to_large_bubbles_with_height():
    import numpy as np

    doc = load_project(EXAMPLES_DIR / "implicit_multiscale_ice.json")
    report = Evaluator().evaluate(doc, targets=["small", "large", "small_density"])
    assert report.ok, report.errors
    rng = np.random.default_rng(0)

    def air(node, z0, z1):            # fraction of a slab of the block inside the cloud
        p = np.column_stack([rng.uniform(0, 3, 200_000), rng.uniform(0, 3, 200_000), rng.uniform(z0, z1, 200_000)])
        return float(np.mean(report.output(node).field(p) < 0))

    assert air("small", 0.0, 0.5) > 4 * air("small", 2.5, 3.0)       # small bubbles: dense at the bottom
    assert air("large", 2.5, 3.0) > 4 * air("large", 0.0, 0.5)       # large ones: at the top
    # the painted stroke: no small bubble keeps its cell on the band it cleared
    field = report.output("small_density")
    dz = (field.hi[2] - field.lo[2]) / field.values.shape[0]
    k = int((1.2 - field.lo[2]) / dz)                                  # the stroke passes z = 1.2 at x = 1.5
    j = field.values.shape[2] // 2
    assert field.values[k, :, j].max() < 0.05 < field.values[k + 8, :, j].min()
