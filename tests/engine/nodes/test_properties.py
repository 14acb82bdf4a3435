"""Material Matrix node: plumbing from graph to solver, against closed forms."""

import numpy as np
import pytest

from engine.graph import AddNode, Connect, Evaluator, GraphDocument, SetParam, UndoStack


def _rod_graph(diameter=0.4, resolution=24, mat_resolution=0):
    doc = GraphDocument()
    st = UndoStack(doc)
    st.push(AddNode("Vertex", {"position": [0, 0.5, 0.5]}, node_id="a"))
    st.push(AddNode("Vertex", {"position": [1, 0.5, 0.5]}, node_id="b"))
    st.push(AddNode("EdgeChain", node_id="e"))
    st.push(Connect("a", "point", "e", "vertices"))
    st.push(Connect("b", "point", "e", "vertices"))
    st.push(AddNode("Line", {"thickness": [[0, diameter]]}, node_id="l"))
    st.push(Connect("e", "chain", "l", "chains"))
    st.push(AddNode("Object", {"resolution": resolution}, node_id="o"))
    st.push(Connect("l", "skeleton", "o", "skeleton"))
    st.push(AddNode("Voxel", {"E": 2.0, "nu": 0.3}, node_id="vox"))
    st.push(Connect("o", "solid", "vox", "solid"))
    st.push(AddNode("MaterialMatrix", {"resolution": mat_resolution}, node_id="mat"))
    st.push(Connect("vox", "voxels", "mat", "voxels"))
    return doc, st


def test_straight_rod_is_in_uniaxial_stress():
    # A prismatic rod along x with free lateral faces carries uniaxial stress
    # under the macro strain e_xx: C11 = E * (solid fraction), exactly, also for
    # trilinear hexes (a homogeneous uniaxial state is in their span).  The cell
    # does not connect along y or z, so C is singular and reported as such.
    doc, st = _rod_graph()
    r = Evaluator().evaluate(doc)
    assert r.ok, r.errors
    s = r.output("mat")
    f = r.output("vox").volume_fraction
    assert s.C[0, 0] == pytest.approx(2.0 * f, rel=1e-6)
    assert s.symmetry == "singular" and s.constants == {}
    assert abs(s.C[1, 1]) < 1e-6 * s.C[0, 0]


def test_resolution_parameter_resamples_the_solid():
    doc, st = _rod_graph(resolution=32, mat_resolution=16)
    r = Evaluator().evaluate(doc)
    s = r.output("mat")
    assert s.resolution == 16
    assert 0.0 < s.C[0, 0] < 2.0
    from engine.graph import ParamError
    with pytest.raises(ParamError, match=r"'mat'.*'resolution' = 300.*\[0, 256\]"):
        st.push(SetParam("mat", "resolution", 300))
