"""Object node on an orthorhombic box cell, and what lies downstream of it:
CSG refusals, tiled export, Voxel + Material Matrix on box voxels."""

import math

import numpy as np
import pytest
import trimesh

from engine.tiled_mesh import tiled_mesh
from engine.geometry.marching import boundary_section_match
from engine.graph import AddNode, Connect, Evaluator, GraphDocument, ParamError, SetParam, UndoStack
from engine.graph.project import document_from_dict, document_to_dict

LY = math.sqrt(3.0)
BOX = [1.0, LY, 1.0]


def _strut_graph(p0, p1, *, diameter=0.3, resolution=32, cell=None, cell_size=1.0, tag=""):
    doc = GraphDocument()
    st = UndoStack(doc)
    _add_strut(st, p0, p1, diameter=diameter, resolution=resolution, cell=cell, cell_size=cell_size, tag=tag)
    return doc, st


def _add_strut(st, p0, p1, *, diameter, resolution, cell, cell_size=1.0, tag=""):
    st.push(AddNode("Vertex", {"position": list(p0)}, node_id=f"a{tag}"))
    st.push(AddNode("Vertex", {"position": list(p1)}, node_id=f"b{tag}"))
    st.push(AddNode("EdgeChain", node_id=f"e{tag}"))
    st.push(Connect(f"a{tag}", "point", f"e{tag}", "vertices"))
    st.push(Connect(f"b{tag}", "point", f"e{tag}", "vertices"))
    st.push(AddNode("Line", {"thickness": [[0, diameter]]}, node_id=f"l{tag}"))
    st.push(Connect(f"e{tag}", "chain", f"l{tag}", "chains"))
    params = {"resolution": resolution, "cell_size": cell_size}
    if cell is not None:
        params["cell"] = list(cell)
    st.push(AddNode("Object", params, node_id=f"o{tag}"))
    st.push(Connect(f"l{tag}", "skeleton", f"o{tag}", "skeleton"))


def test_default_cell_is_the_unit_cube_and_old_files_load_with_it():
    doc, st = _strut_graph((0.1, 0.2, 0.3), (0.8, 0.9, 0.6))
    assert doc.nodes["o"].params["cell"] == [1.0, 1.0, 1.0]
    solid = Evaluator().evaluate(doc).output("o")
    assert solid.cell == (1.0, 1.0, 1.0) and solid.is_unit_cube
    assert solid.grid_shape == (32, 32, 32) and solid.resolution == 32
    # a project saved before the parameter existed
    data = document_to_dict(doc)
    for node in data["nodes"]:
        node["params"].pop("cell", None)
    old = document_from_dict(data)
    assert old.nodes["o"].params["cell"] == [1.0, 1.0, 1.0]
    again = Evaluator().evaluate(old).output("o")
    assert np.array_equal(again.sdf, solid.sdf) and np.array_equal(again.vertices, solid.vertices)
    # stating the unit cube explicitly changes nothing
    st.push(SetParam("o", "cell", [1, 1, 1]))
    explicit = Evaluator().evaluate(doc).output("o")
    assert np.array_equal(explicit.sdf, solid.sdf) and np.array_equal(explicit.faces, solid.faces)


@pytest.mark.parametrize("cell", [[0, 1, 1], [1, -0.5, 1], [1, 1, 0.0], [1, 1, 150]])
def test_object_refuses_bad_cell_entries(cell):
    doc, st = _strut_graph((0.1, 0.2, 0.3), (0.8, 0.9, 0.6))
    with pytest.raises(ParamError, match=r"'cell' = \[.*\] is invalid"):
        st.push(SetParam("o", "cell", cell))
    assert doc.nodes["o"].params["cell"] == [1.0, 1.0, 1.0]
    data = document_to_dict(doc)
    next(n for n in data["nodes"] if n["id"] == "o")["params"]["cell"] = cell
    with pytest.raises(ValueError, match=r"node 'o': parameter 'cell' = \["):
        document_from_dict(data)


def test_strut_along_y_through_the_y_faces_is_a_periodic_cylinder():
    r, n = 0.15, 48
    doc, st = _strut_graph((0.5, 0.0, 0.5), (0.5, LY, 0.5), diameter=2 * r, resolution=n, cell=BOX,
                           cell_size=2.0)
    res = Evaluator().evaluate(doc)
    assert res.ok, res.errors
    solid = res.output("o")
    ny, nxz = n, round(n / LY)
    assert solid.grid_shape == (nxz, ny, nxz) and solid.resolution == n
    assert solid.cell == (1.0, LY, 1.0)
    np.testing.assert_allclose(solid.box, [2.0, 2.0 * LY, 2.0])
    # every y plane of the field is the same circle: exactly periodic along y
    sdf = np.asarray(solid.sdf)
    assert np.abs(sdf - sdf[:, :1, :]).max() < 1e-6
    # volume: pi r^2 Ly (cell units), here in mm^3 with cell_size 2
    exact = math.pi * r ** 2 * LY * 2.0 ** 3
    mesh = trimesh.Trimesh(solid.vertices, solid.faces, process=False)
    assert mesh.is_watertight
    assert mesh.volume == pytest.approx(exact, rel=0.02)
    assert solid.volume_fraction == pytest.approx(math.pi * r ** 2 / 1.0, rel=0.06)
    assert boundary_section_match(solid.vertices, solid.faces, cell_size=2.0, cell=solid.cell) < 1e-9


def test_tiled_export_places_copies_at_box_offsets():
    doc, st = _strut_graph((0.5, 0.0, 0.5), (0.5, LY, 0.5), resolution=24, cell=BOX, cell_size=2.0)
    solid = Evaluator().evaluate(doc).output("o")
    single = tiled_mesh(solid, (1, 1, 1))
    block = tiled_mesh(solid, (2, 2, 1))
    box = 2.0 * np.array(BOX)
    np.testing.assert_allclose(block.vertices.max(axis=0)[1:2], [2 * box[1]], rtol=1e-6)
    assert block.vertices[:, 0].max() > box[0] + 0.25         # a second column of struts along x
    assert np.all(block.vertices.max(axis=0) <= box * [2, 2, 1] + 1e-6)
    assert block.summary["volume"] == pytest.approx(4 * single.summary["volume"], rel=1e-5)
    assert block.summary["volume_fraction"] == pytest.approx(single.summary["volume_fraction"], rel=1e-5)
    assert single.summary["volume_fraction"] == pytest.approx(solid.volume_fraction, rel=0.06)
    assert block.summary["cell"] == BOX and block.summary["box_mm"] == pytest.approx(box.tolist())
    # the strut centres of the two columns sit one box edge apart in x
    xs = block.vertices[:, 0]
    assert np.mean(xs[xs < box[0]]) == pytest.approx(1.0, abs=1e-3)
    assert np.mean(xs[xs > box[0]]) == pytest.approx(1.0 + box[0], abs=1e-3)


def test_csg_refuses_different_boxes_and_grid_shapes():
    doc = GraphDocument()
    st = UndoStack(doc)
    _add_strut(st, (0.5, 0, 0.5), (0.5, LY, 0.5), diameter=0.3, resolution=16, cell=BOX, tag="1")
    _add_strut(st, (0, 0.5, 0.5), (1, 0.5, 0.5), diameter=0.2, resolution=16, cell=None, tag="2")
    st.push(AddNode("CSGBoolean", {"operation": "union"}, node_id="u"))
    st.push(Connect("o1", "solid", "u", "solids"))
    st.push(Connect("o2", "solid", "u", "solids"))
    res = Evaluator().evaluate(doc)
    err = res.results["u"].error
    assert res.results["u"].status == "failed"
    assert "same cell box" in err and f"[1.0, {LY!r}, 1.0]" in err and "[1.0, 1.0, 1.0]" in err
    st.push(SetParam("o2", "cell", BOX))
    st.push(SetParam("o2", "resolution", 20))
    res = Evaluator().evaluate(doc)
    err = res.results["u"].error
    assert "same grid resolution" in err and "9x16x9" in err and "12x20x12" in err
    st.push(SetParam("o2", "resolution", 16))
    res = Evaluator().evaluate(doc)
    assert res.ok, res.errors
    assert res.output("u").cell == (1.0, LY, 1.0) and res.output("u").grid_shape == (9, 16, 9)


def test_material_matrix_on_a_box_rod_is_uniaxial():
    # A prismatic rod along y carries uniaxial stress under e_yy, so
    # C_yy = E * (solid fraction) exactly, also on the box voxels of a
    # (1, sqrt 3, 1) cell (spacings 1/14, sqrt(3)/24, 1/14).
    doc, st = _strut_graph((0.5, 0.0, 0.5), (0.5, LY, 0.5), diameter=0.4, resolution=24, cell=BOX)
    st.push(AddNode("Voxel", {"E": 2.0, "nu": 0.3}, node_id="vox"))
    st.push(Connect("o", "solid", "vox", "solid"))
    st.push(AddNode("MaterialMatrix", {"resolution": 0}, node_id="mat"))
    st.push(Connect("vox", "voxels", "mat", "voxels"))
    res = Evaluator().evaluate(doc)
    assert res.ok, res.errors
    s = res.output("mat")
    f = res.output("vox").volume_fraction
    assert s.grid_shape == (14, 24, 14) and s.cell == (1.0, LY, 1.0) and s.resolution == 24
    assert s.C[1, 1] == pytest.approx(2.0 * f, rel=1e-6)
    assert s.symmetry == "singular"
    assert abs(s.C[0, 0]) < 1e-6 * s.C[1, 1]
    assert s.summary()["grid_shape"] == [14, 24, 14]
    # resampled for the solve: the longest edge gets the resolution
    st.push(SetParam("mat", "resolution", 16))
    s16 = Evaluator().evaluate(doc).output("mat")
    assert s16.grid_shape == (9, 16, 9) and s16.resolution == 16
    assert s16.C[1, 1] == pytest.approx(2.0 * s16.density, rel=1e-6)
