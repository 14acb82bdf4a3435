"""Node behaviour through the evaluator, against closed forms."""

import math

import numpy as np
import pytest

from engine.graph import AddNode, Connect, Evaluator, GraphDocument, SetParam, UndoStack


def _graph():
    doc = GraphDocument()
    return doc, UndoStack(doc)


def _vertices(st, pts, prefix="v"):
    ids = []
    for i, p in enumerate(pts):
        nid = f"{prefix}{i}"
        st.push(AddNode("Vertex", {"position": list(p)}, node_id=nid))
        ids.append(nid)
    return ids


def _chain(st, vids, nid="e", **params):
    st.push(AddNode("EdgeChain", params, node_id=nid))
    for v in vids:
        st.push(Connect(v, "point", nid, "vertices"))
    return nid


def test_edge_chain_order_closes_loops_and_refuses_branches():
    doc, st = _graph()
    vids = _vertices(st, [(0, 0, 0), (1, 0, 0), (1, 1, 0)])
    _chain(st, vids, order=[0, 1, 2, 0])
    r = Evaluator().evaluate(doc)
    chain = r.output("e")
    assert chain.closed and len(chain.points) == 3
    st.push(SetParam("e", "order", [0, 1, 0, 2]))
    r = Evaluator().evaluate(doc)
    assert r.results["e"].status == "failed" and "branch-free" in r.results["e"].error
    st.push(SetParam("e", "order", [0, 5]))
    r = Evaluator().evaluate(doc)
    assert "index 5" in r.results["e"].error


def test_line_joins_chains_reversing_as_needed_and_refuses_branches():
    doc, st = _graph()
    a = _vertices(st, [(0, 0, 0), (0.5, 0, 0)], "a")
    b = _vertices(st, [(0.5, 0.5, 0), (0.5, 0, 0)], "b")  # stored backwards
    _chain(st, a, "ea")
    _chain(st, b, "eb")
    st.push(AddNode("Line", node_id="l"))
    st.push(Connect("ea", "chain", "l", "chains"))
    st.push(Connect("eb", "chain", "l", "chains"))
    r = Evaluator().evaluate(doc)
    (line,) = r.output("l").lines
    assert np.allclose(line.polyline[0], [0, 0, 0]) and np.allclose(line.polyline[-1], [0.5, 0.5, 0])
    length = np.linalg.norm(np.diff(line.polyline, axis=0), axis=1).sum()
    assert length == pytest.approx(1.0)
    c = _vertices(st, [(0.5, 0, 0), (0.5, 0, 0.5)], "c")
    _chain(st, c, "ec")
    st.push(Connect("ec", "chain", "l", "chains"))
    r = Evaluator().evaluate(doc)
    assert r.results["l"].status == "failed" and "branch" in r.results["l"].error


def test_line_thickness_profile_is_interpolated_over_arc_length():
    doc, st = _graph()
    v = _vertices(st, [(0, 0, 0), (1, 0, 0)])
    _chain(st, v)
    st.push(AddNode("Line", {"thickness": [[0.0, 0.1], [1.0, 0.3]]}, node_id="l"))
    st.push(Connect("e", "chain", "l", "chains"))
    (line,) = Evaluator().evaluate(doc).output("l").lines
    assert np.allclose(line.thickness, 0.1 + 0.2 * line.polyline[:, 0])


def _beam_with(st, transform_type, params):
    v = _vertices(st, [(0.1, 0.2, 0.3), (0.4, 0.2, 0.3)])
    _chain(st, v)
    st.push(AddNode("Line", {"thickness": [[0.0, 0.1]]}, node_id="l"))
    st.push(Connect("e", "chain", "l", "chains"))
    st.push(AddNode(transform_type, params, node_id="t"))
    st.push(Connect("l", "skeleton", "t", "skeleton"))


def test_mirror_reflects_and_copies():
    doc, st = _graph()
    _beam_with(st, "Mirror", {"direction": [1, 0, 0], "origin": [0.5, 0.5, 0.5]})
    els = Evaluator().evaluate(doc).output("t").lines
    assert len(els) == 2
    assert np.allclose(els[1].polyline[0], [0.9, 0.2, 0.3]) and np.allclose(els[1].polyline[-1], [0.6, 0.2, 0.3])
    st.push(SetParam("t", "do_copy", False))
    assert len(Evaluator().evaluate(doc).output("t").lines) == 1


def test_transform_rotates_scales_translates():
    doc, st = _graph()
    _beam_with(st, "Transform", {"origin": [0, 0, 0], "rotation_axis": [0, 0, 1], "rotation_angle": 90.0,
                                 "scale": 2.0, "translation": [1, 0, 0], "do_copy": False})
    (line,) = Evaluator().evaluate(doc).output("t").lines
    # p -> R(2p) + t with R a quarter turn about z: (x, y, z) -> (-2y + 1, 2x, 2z)
    assert np.allclose(line.polyline[0], [-0.4 + 1, 0.2, 0.6])
    assert np.allclose(line.thickness, 0.2)


def test_object_beam_volume_matches_cylinder_and_csg_difference():
    doc, st = _graph()
    v = _vertices(st, [(0, 0.5, 0.5), (1, 0.5, 0.5)])
    _chain(st, v)
    st.push(AddNode("Line", {"thickness": [[0.0, 0.3]]}, node_id="l"))
    st.push(Connect("e", "chain", "l", "chains"))
    st.push(AddNode("Object", {"resolution": 64}, node_id="o1"))
    st.push(Connect("l", "skeleton", "o1", "skeleton"))
    w = _vertices(st, [(0.5, 0.5, 0), (0.5, 0.5, 1)], "w")
    _chain(st, w, "e2")
    st.push(AddNode("Line", {"thickness": [[0.0, 0.2]]}, node_id="l2"))
    st.push(Connect("e2", "chain", "l2", "chains"))
    st.push(AddNode("Object", {"resolution": 64}, node_id="o2"))
    st.push(Connect("l2", "skeleton", "o2", "skeleton"))
    st.push(AddNode("CSGBoolean", {"operation": "difference"}, node_id="b"))
    st.push(Connect("o1", "solid", "b", "solids"))
    st.push(Connect("o2", "solid", "b", "solids"))
    r = Evaluator().evaluate(doc)
    assert r.ok, r.errors
    from engine.geometry.mesh_io import mesh_summary
    s1 = mesh_summary(r.output("o1").vertices, r.output("o1").faces)
    assert s1["watertight"] and s1["volume"] == pytest.approx(math.pi * 0.15 ** 2, rel=0.02)
    # Steinmetz: two perpendicular cylinders of radii R > r intersect in a known volume;
    # the difference removes exactly that: V = pi R^2 - V_int, with V_int by quadrature.
    R, rr = 0.15, 0.1
    x = np.linspace(-rr, rr, 20001)
    v_int = np.trapezoid(4 * np.sqrt(np.clip(rr**2 - x**2, 0, None)) * np.sqrt(np.clip(R**2 - x**2, 0, None)), x)
    sb = mesh_summary(r.output("b").vertices, r.output("b").faces)
    assert sb["watertight"] and sb["volume"] == pytest.approx(math.pi * R**2 - v_int, rel=0.03)
    st.push(SetParam("o2", "resolution", 48))
    r = Evaluator().evaluate(doc)
    assert r.results["b"].status == "failed" and "same grid resolution" in r.results["b"].error


def test_voxel_node_carries_material_and_occupancy():
    doc, st = _graph()
    v = _vertices(st, [(0, 0.5, 0.5), (1, 0.5, 0.5)])
    _chain(st, v)
    st.push(AddNode("Line", {"thickness": [[0.0, 0.4]]}, node_id="l"))
    st.push(Connect("e", "chain", "l", "chains"))
    st.push(AddNode("Object", {"resolution": 40}, node_id="o"))
    st.push(Connect("l", "skeleton", "o", "skeleton"))
    st.push(AddNode("Voxel", {"E": 2.0, "nu": 0.3}, node_id="vox"))
    st.push(Connect("o", "solid", "vox", "solid"))
    vm = Evaluator().evaluate(doc).output("vox")
    assert vm.E == 2.0 and vm.nu == 0.3 and vm.occupancy.shape == (40, 40, 40)
    assert vm.volume_fraction == pytest.approx(math.pi * 0.04, rel=0.05)


def test_zero_length_line_is_a_sphere():
    doc, st = _graph()
    v = _vertices(st, [(0.5, 0.5, 0.5), (0.5, 0.5, 0.5)])
    _chain(st, v)
    st.push(AddNode("Line", {"thickness": [[0.0, 0.6]]}, node_id="l"))
    st.push(Connect("e", "chain", "l", "chains"))
    st.push(AddNode("Object", {"resolution": 64}, node_id="o"))
    st.push(Connect("l", "skeleton", "o", "skeleton"))
    r = Evaluator().evaluate(doc)
    assert r.ok, r.errors
    from engine.geometry.mesh_io import mesh_summary
    s = mesh_summary(r.output("o").vertices, r.output("o").faces)
    assert s["watertight"] and s["volume"] == pytest.approx(4 / 3 * math.pi * 0.3**3, rel=0.02)


def test_object_thickens_many_surfaces_in_one_pass_exactly_as_their_union():
    from engine.geometry.csg import csg_reduce
    from engine.geometry.sdf_triangles import surface_sdf_grid
    from engine.geometry.values import Skeleton, SurfaceElement
    from engine.nodes.solids import ObjectNode

    rng = np.random.default_rng(5)
    patches = []
    for k in range(3):
        v = rng.uniform(0.1, 0.9, size=(4, 3))
        patches.append(SurfaceElement(v, np.array([[0, 1, 2], [0, 2, 3]]), np.full(4, 0.04 + 0.01 * k)))
    n = 24
    union = csg_reduce([surface_sdf_grid(p.vertices, p.faces, p.thickness, resolution=n, method="spherical",
                                         periodic=True) for p in patches], "union")

    class _Ctx:
        progress = None

        def check(self):
            pass

    solid = ObjectNode().evaluate({"skeleton": Skeleton(tuple(patches))},
                                  {"resolution": n, "extrusion": "spherical", "cell_size": 1.0}, _Ctx())["solid"]
    np.testing.assert_allclose(solid.sdf, union, atol=1e-6)
