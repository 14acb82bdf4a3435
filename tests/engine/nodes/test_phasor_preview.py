"""PhasorPreview node: the diamond cells of an infill as a Solid on a sub-box;
refusals name the parameter."""

import numpy as np
import pytest
import trimesh

from engine.graph import AddNode, Connect, Evaluator, GraphDocument, SetParam, UndoStack
from engine.geometry.values import Solid
from engine.phasor.volume import diamond_surface, diamond_volume


def _doc(*, box=(8.0, 8.0, 8.0), **preview):
    doc = GraphDocument(seed=2)
    st = UndoStack(doc)
    fields = {"lo": [0.0, 0.0, 0.0], "hi": list(box), "resolution": 8}
    st.push(AddNode("PhasorFields", fields, node_id="f"))
    st.push(AddNode("PhasorNoise", {"iterations": 4}, node_id="n"))
    st.push(Connect("f", "fields", "n", "fields"))
    st.push(AddNode("PhasorPreview", {"voxel": 0.25, **preview}, node_id="p"))
    st.push(Connect("n", "infill", "p", "infill"))
    return doc, st


def test_the_default_sub_box_is_a_10_mm_cube_at_the_centre_clipped_to_the_box():
    doc, st = _doc(box=(20.0, 20.0, 6.0))
    r = Evaluator().evaluate(doc)
    assert r.ok, r.errors
    solid = r.output("p")
    assert isinstance(solid, Solid)
    # centre (10, 10, 3): x, y 5 .. 15 at 0.25 mm -> 41 nodes; z is the whole box 0 .. 6 -> 25
    assert solid.sdf.shape == (41, 41, 25) and solid.cell_size == 10.0
    v = solid.vertices
    assert v.min() >= 0 and np.all(v.max(axis=0) <= [10.0, 10.0, 6.0])
    mesh = trimesh.Trimesh(v, solid.faces, process=False)
    assert mesh.is_watertight and mesh.volume > 0
    # the same cells as the kernel gives on that box, shifted to the sub-box's corner
    infill = r.output("n")
    vol = diamond_volume(infill, [5, 5, 0], [15, 15, 6], voxel=0.25)
    ref_v, ref_f = diamond_surface(vol)
    assert np.array_equal(solid.sdf, vol.indicator) and np.array_equal(solid.faces, ref_f)
    assert np.allclose(solid.vertices, ref_v - [5, 5, 0])


def test_raw_noise_and_an_explicit_box():
    doc, st = _doc(lo=[1.0, 2.0, 3.0], hi=[4.0, 5.0, 5.0])
    ev = Evaluator()
    aligned = ev.evaluate(doc).output("p")
    assert aligned.sdf.shape == (13, 13, 9) and aligned.cell_size == 3.0
    st.push(SetParam("p", "noise", "raw"))
    raw = ev.evaluate(doc).output("p")
    assert raw.sdf.shape == aligned.sdf.shape and not np.array_equal(raw.sdf, aligned.sdf)


@pytest.mark.parametrize("params, where, match", [
    ({"lo": [-1.0, 0.0, 0.0], "hi": [2.0, 2.0, 2.0]}, "lo", "x = -1 mm lies outside the fields' box"),
    ({"lo": [0.0, 0.0, 0.0], "hi": [2.0, 2.0, 9.0]}, "hi", "z = 9 mm lies outside"),
    ({"lo": [1.0, 1.0, 1.0], "hi": [2.0, 0.5, 2.0]}, "hi", "empty along y"),
    ({"voxel": 0.02}, "voxel", "limit of 16,777,216 (256^3)"),
    ({"voxel": 0.5}, "voxel", "too coarse for F up to 1"),
])
def test_refusals_name_the_parameter(params, where, match):
    doc, _ = _doc(**params)
    res = Evaluator().evaluate(doc).results["p"]
    assert res.status == "failed" and res.where == where and match in res.error, res.error


def test_a_sub_box_without_cells_is_refused_naming_lo(tmp_path):
    part = trimesh.creation.box(bounds=[[0.0, 0.0, 0.0], [4.0, 4.0, 4.0]])
    path = tmp_path / "part.stl"
    part.export(path)
    doc, st = _doc(lo=[4.6, 4.6, 4.6], hi=[5.4, 5.4, 5.4])
    st.push(AddNode("MeshImport", {"path": str(path)}, node_id="m"))
    st.push(Connect("m", "mesh", "f", "domain"))
    st.push(SetParam("f", "margin", 2.0))
    res = Evaluator().evaluate(doc).results["p"]
    assert res.status == "failed" and res.where == "lo" and "no diamond cell" in res.error
