"""The implicit-media nodes end to end: graphs from SDF nodes to Solids, the Material Matrix
and CSG with unit cells, checked against closed forms and the kernels' own particle lists;
refusals located at the parameter."""

import math

import numpy as np
import pytest

from engine.geometry.marching import mesh_volume
from engine.graph import AddNode, Connect, Evaluator, GraphDocument, SetParam, UndoStack
from engine.graph.project import document_from_dict, document_to_dict
from engine.implicit.particles import Suspension


def _graph():
    doc = GraphDocument()
    return doc, UndoStack(doc)


def _solid(st, source, node_id="solid", **params):
    params.setdefault("backend", "numpy")
    st.push(AddNode("SDFSolid", params, node_id=node_id))
    st.push(Connect(source, "sdf", node_id, "sdf"))


def test_a_periodic_function_cell_hits_its_volume_fraction_and_homogenises():
    doc, st = _graph()
    st.push(AddNode("PeriodicFunction", {"kind": "schwarz_p", "cell": 2.0, "level_by": "volume fraction",
                                         "volume_fraction": 0.3}, node_id="p"))
    _solid(st, "p", resolution=40, fit_box=False, box_from=[0, 0, 0], box_to=[2, 2, 2], periodic=True)
    st.push(AddNode("Voxel", {"E": 1.0, "nu": 0.3}, node_id="vox"))
    st.push(Connect("solid", "solid", "vox", "solid"))
    st.push(AddNode("MaterialMatrix", {"resolution": 0}, node_id="mat"))
    st.push(Connect("vox", "voxels", "mat", "voxels"))
    res = Evaluator().evaluate(doc)
    assert res.ok, res.errors
    solid = res.output("solid")
    assert mesh_volume(solid.vertices, solid.faces) / 8.0 == pytest.approx(0.3, abs=0.01)
    c = res.output("mat").C
    assert c[0, 0] == pytest.approx(c[1, 1], rel=1e-6) == pytest.approx(c[2, 2], rel=1e-6)   # cubic
    assert 0 < c[0, 0] < 0.3                                         # below the Voigt bound E * f


def test_particles_in_a_box_have_the_volume_of_the_clouds_own_particles():
    doc, st = _graph()
    params = {"cell": 1.0, "shape": "sphere", "distribution": "uniform", "size_a": 0.2, "size_b": 0.35,
              "jitter": 1.0, "density": 0.7, "seed": 5}
    st.push(AddNode("Particles", params, node_id="p"))
    _solid(st, "p", resolution=120, fit_box=False, box_from=[0, 0, 0], box_to=[4, 4, 4])
    res = Evaluator().evaluate(doc)
    assert res.ok, res.errors
    cloud = res.output("p")
    assert isinstance(cloud, Suspension) and cloud.seed == 5
    found = cloud.particles_in_box(np.zeros(3), np.full(3, 4.0))
    own = np.all((found.cells >= 0) & (found.cells <= 3), axis=1)       # the box's 64 cells
    found = found._replace(**{k: getattr(found, k)[own] for k in found._fields})
    inside = np.all((found.centres - found.radii[:, None] >= 0) & (found.centres + found.radii[:, None] <= 4), 1)
    assert inside.all()                              # cells of a box of whole cells: no particle is cut
    want = float(np.sum(4 / 3 * math.pi * found.sizes ** 3))
    solid = res.output("solid")
    assert mesh_volume(solid.vertices, solid.faces) == pytest.approx(want, rel=0.02)
    assert 0.5 * 64 < len(found.sizes) < 0.9 * 64    # density 0.7 of 64 cells


def test_a_suspension_blended_with_a_unit_cell_keeps_both():
    doc, st = _graph()
    st.push(AddNode("Vertex", {"position": [0.0, 0.0, 0.0]}, node_id="a"))
    st.push(AddNode("Vertex", {"position": [1.0, 1.0, 1.0]}, node_id="b"))
    st.push(AddNode("EdgeChain", node_id="e"))
    st.push(Connect("a", "point", "e", "vertices"))
    st.push(Connect("b", "point", "e", "vertices"))
    st.push(AddNode("Line", {"thickness": [[0, 0.2]]}, node_id="l"))
    st.push(Connect("e", "chain", "l", "chains"))
    st.push(AddNode("Object", {"resolution": 32}, node_id="o"))
    st.push(Connect("l", "skeleton", "o", "skeleton"))
    st.push(AddNode("CellSDF", node_id="cell"))
    st.push(Connect("o", "solid", "cell", "solid"))
    st.push(AddNode("Particles", {"cell": 0.25, "size_a": 0.04, "size_b": 0.08, "seed": 2}, node_id="p"))
    st.push(AddNode("SDFBoolean", {"operation": "smooth union", "blend": 0.02}, node_id="u"))
    st.push(Connect("cell", "sdf", "u", "a"))
    st.push(Connect("p", "sdf", "u", "b"))
    _solid(st, "u", resolution=48, fit_box=False, box_from=[0, 0, 0], box_to=[1, 1, 1])
    res = Evaluator().evaluate(doc)
    assert res.ok, res.errors
    strut = res.output("o")
    both = res.output("solid")
    v_strut = mesh_volume(strut.vertices, strut.faces)
    v_both = mesh_volume(both.vertices, both.faces)
    assert v_both > 1.1 * v_strut                       # the particles added material
    cell_sdf = res.output("cell")
    p = np.random.default_rng(0).uniform(0, 1, (2000, 3))
    shifted = cell_sdf.field(p + [1.0, -2.0, 3.0])       # the cell repeats over space
    assert np.allclose(shifted, cell_sdf.field(p), atol=1e-9)


def test_transform_and_offset_nodes_act_on_a_bounded_sdf_and_round_trip_the_project():
    doc, st = _graph()
    st.push(AddNode("Particles", {"cell": 1.0, "distribution": "fixed", "size_a": 0.3, "jitter": 0.0,
                                  "density": 1.0}, node_id="p"))
    st.push(AddNode("SDFTransform", {"scale": [2.0, 1.0, 1.0], "rotate": [0, 0, 90]}, node_id="t"))
    st.push(Connect("p", "sdf", "t", "sdf"))
    st.push(AddNode("SDFOffset", {"mode": "offset", "amount": 0.05}, node_id="off"))
    st.push(Connect("t", "sdf", "off", "sdf"))
    res = Evaluator().evaluate(doc)
    assert res.ok, res.errors
    sdf = res.output("off")
    # the lattice sphere at (0.5, 0.5, 0.5) scaled x2 along x then turned 90 deg about z:
    # an ellipsoid at (-0.5, 1, 0.5) with semi-axes 0.3 along x and 0.6 along y, offset 0.05 outwards
    assert sdf.field([-0.5, 1.0, 0.5])[0] < 0
    # along x (the unscaled axis) the distance is exact: the offset surface is 0.3 + 0.05 out
    assert sdf.distance([-0.5 - 0.36, 1.0, 0.5])[0] == pytest.approx(0.01, abs=1e-9)
    assert sdf.distance([-0.5 - 0.34, 1.0, 0.5])[0] < 0
    # along y (stretched x2) it is a lower bound: half the child's distance, still positive beyond
    assert 0 < sdf.distance([-0.5, 1.0 + 0.6 + 0.2, 0.5])[0] < 0.2 - 0.05
    assert sdf.lipschitz == pytest.approx(1.0)           # the inverse map stretches by at most 1
    again = document_from_dict(document_to_dict(doc))
    assert Evaluator().evaluate(again).output("off").field([0.1, 0.2, 0.3]) == pytest.approx(
        sdf.field([0.1, 0.2, 0.3]))


@pytest.mark.parametrize("node, params, where", [
    ("Particles", {"cell": 0.5, "distribution": "fixed", "size_a": 0.3}, "size_a"),
    ("Particles", {"cell": 1.0, "offset": 0.6}, "offset"),
    ("PeriodicFunction", {"graded": True, "cell_end": 2.0, "grade_from": 5.0, "grade_to": 1.0}, "grade_to"),
    ("PeriodicFunction", {"variant": "sheet", "level_by": "level", "level": -0.2}, "level"),
])
def test_bad_parameters_are_refused_at_the_parameter(node, params, where):
    doc, st = _graph()
    st.push(AddNode(node, params, node_id="n"))
    res = Evaluator().evaluate(doc)
    assert not res.ok
    err = res.results["n"]
    assert err.where == where, (err.error, err.where)


def test_an_empty_box_is_refused_before_any_mesh_and_the_graph_is_kept():
    doc, st = _graph()
    st.push(AddNode("Particles", {"cell": 1.0, "density": 0.0}, node_id="p"))
    _solid(st, "p", resolution=16, fit_box=False, box_from=[0, 0, 0], box_to=[2, 2, 2])
    res = Evaluator().evaluate(doc)
    assert "nothing of the medium" in res.errors["solid"]
    assert res.results["solid"].where == "box_to" and set(doc.snapshot().nodes) == {"p", "solid"}
    st.push(SetParam("p", "density", 1.0))
    assert Evaluator().evaluate(doc).ok


def test_agglomerated_fibres_have_the_volume_of_overlapping_spheres_in_rows():
    """Fibres along z every 4 cells: rows of spheres of radius r = 0.7 w overlapping their
    neighbours; per sphere the ball minus the two caps beyond the half-way planes."""
    w, r, period = 0.1, 0.07, 4
    doc, st = _graph()
    st.push(AddNode("Agglomerate", {"cell": w, "size": r, "structure": "fibres", "period": period,
                                    "axis": "z"}, node_id="a"))
    _solid(st, "a", resolution=160, fit_box=False, box_from=[0, 0, 0], box_to=[0.8, 0.8, 0.8], periodic=True)
    res = Evaluator().evaluate(doc)
    assert res.ok, res.errors
    h = r - w / 2
    per_sphere = 4 / 3 * math.pi * r ** 3 - 2 * math.pi * h * h * (3 * r - h) / 3
    want = per_sphere / (period * period * w ** 3)
    assert res.output("solid").volume_fraction == pytest.approx(want, rel=0.03)


def test_a_pile_of_grains_goes_from_convex_to_concave_along_its_axis():
    doc, st = _graph()
    st.push(AddNode("Pile", {"grain": "sphere", "radius": 0.45, "deform": [0.0, 0.0, 0.0], "concavity": 0.0,
                             "graded": True, "concavity_end": 1.0, "grade_from": 0.0, "grade_to": 4.0},
                    node_id="p"))
    res = Evaluator().evaluate(doc)
    assert res.ok, res.errors
    pile = res.output("p")
    centre_low, centre_high = np.array([0.5, 0.5, 0.5]), np.array([0.5, 0.5, 3.5])
    probe = np.array([0.0, 0.0, 0.4])                       # inside the ball near its top pole
    assert pile.field(centre_low + probe)[0] < 0             # convex low in the pile
    assert pile.field(centre_high + probe)[0] > 0            # dimpled away high in the pile


def test_a_particle_larger_than_the_lattice_cell_is_refused_at_size():
    doc, st = _graph()
    st.push(AddNode("Agglomerate", {"cell": 0.1, "size": 0.2}, node_id="a"))
    res = Evaluator().evaluate(doc)
    assert res.results["a"].where == "size", res.errors


@pytest.mark.parametrize("shape, volume", [
    ("box", 1.0 * 0.8 * 0.4),
    ("ellipsoid", 4 / 3 * math.pi * 0.5 * 0.4 * 0.2),
    ("cylinder", math.pi * 0.5 ** 2 * 0.4),
    ("torus", 2 * math.pi ** 2 * 0.3 * 0.2 ** 2),          # R = 0.5 - 0.2, tube radius 0.2
])
def test_sdf_shapes_have_their_closed_form_volumes_and_tight_boxes(shape, volume):
    doc, st = _graph()
    st.push(AddNode("SDFShape", {"shape": shape, "extent": [1.0, 0.8, 0.4], "centre": [0.2, -0.1, 0.3]},
                    node_id="s"))
    _solid(st, "s", resolution=128)
    res = Evaluator().evaluate(doc)
    assert res.ok, res.errors
    solid = res.output("solid")
    assert mesh_volume(solid.vertices, solid.faces) == pytest.approx(volume, rel=0.01)
    lo, hi = (np.array(v) for v in res.output("s").box())
    assert np.allclose(hi - lo, [1.0, 0.8 if shape in ("box", "ellipsoid") else 1.0, 0.4])
    p = np.random.default_rng(1).uniform(-2, 2, (50000, 3))
    outside = np.any((p < lo) | (p > hi), axis=1)
    assert np.all(res.output("s").field(p[outside]) > 0)


@pytest.mark.parametrize("backend", ["numpy", "auto"])
def test_the_sdf_solid_memory_estimate_bounds_the_measured_peak(backend):
    from engine.graph import node_type

    from .memory_peak import evaluate_traced

    doc, st = _graph()
    st.push(AddNode("Particles", {"cell": 0.1, "size_a": 0.02, "size_b": 0.04}, node_id="p"))
    _solid(st, "p", resolution=96, fit_box=False, box_from=[0, 0, 0], box_to=[1, 1, 1], backend=backend)
    res, peak = evaluate_traced(doc)
    assert res.ok, res.errors
    estimate = node_type("SDFSolid").memory_estimate(doc.nodes["solid"].params, {"sdf": res.output("p")})
    assert peak <= estimate <= 4 * peak


def test_a_voxelised_sub_box_keeps_its_place_in_every_export():
    """The Solid is box-local (what the viewport shows and tiles) but knows where its box sits:
    the exported mesh of a sphere centred at (5, -3, 2) mm is centred there, within a voxel."""
    from engine.tiled_mesh import tiled_arrays, tiled_mesh

    doc, st = _graph()
    st.push(AddNode("SDFShape", {"shape": "sphere", "extent": [2.0, 2.0, 2.0], "centre": [5.0, -3.0, 2.0]},
                    node_id="s"))
    _solid(st, "s", resolution=64)
    res = Evaluator().evaluate(doc)
    assert res.ok, res.errors
    solid = res.output("solid")
    spacing = float(solid.spacing.max())
    local = np.asarray(solid.vertices)
    assert np.all(local.min(axis=0) > -1e-9)                             # box-local, from 0
    v, _ = tiled_arrays(solid)
    np.testing.assert_allclose(v.min(axis=0), [4.0, -4.0, 1.0], atol=spacing)
    np.testing.assert_allclose(v.max(axis=0), [6.0, -2.0, 3.0], atol=spacing)
    bounds = np.array(tiled_mesh(solid).summary["bounds"])
    np.testing.assert_allclose(bounds.mean(axis=0), [5.0, -3.0, 2.0], atol=spacing)
