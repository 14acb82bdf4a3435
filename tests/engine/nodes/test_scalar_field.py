"""The Scalar Field node through the graph engine: a project's graph JSON evaluated by the
Evaluator, values against closed forms, one stroke per SetParam (undo removes it), refusals
located at the parameter, the memory estimate against a measured peak."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import engine.nodes  # noqa: F401  (registers the node types)
from engine.geometry.values import Field
from engine.graph import AddNode, Evaluator, GraphDocument, ParamError, SetParam, UndoStack, node_type
from engine.graph.project import document_from_dict, document_to_dict

STROKE = {"axis": "z", "position": 5.0, "points": [[2.0, 5.0], [8.0, 5.0]], "radius": 1.5, "value": 0.9,
          "strength": 1.0, "falloff": "constant", "depth": None}


def _graph(**params):
    doc = GraphDocument()
    st = UndoStack(doc)
    st.push(AddNode("ScalarField", params, node_id="f"))
    return doc, st


def test_a_graph_json_with_a_scalar_field_evaluates_to_its_ramp_and_strokes():
    doc, _ = _graph(lo=[0, 0, 0], hi=[10, 10, 5], resolution=20, mode="ramp", ramp_axis="z", ramp_from=0.0,
                    ramp_to=5.0, value_from=0.1, value_to=0.6, strokes=[STROKE], clamp=True)
    text = json.dumps(document_to_dict(doc))            # what `mesoforge eval GRAPH` reads
    res = Evaluator().evaluate(document_from_dict(json.loads(text)))
    assert res.ok, res.errors
    f = res.output("f")
    assert isinstance(f, Field) and f.kind == "scalar" and f.values.shape == (10, 20, 20)
    # z centres 0.25, 0.75, ...: ramp 0.1 + 0.5 * z / 5 away from the stroke
    assert f.values[:, 0, 0].tolist() == pytest.approx([0.1 + 0.1 * (k + 0.5) * 0.5 for k in range(10)])
    # the stroke: cells within 1.5 mm (3-D) of the segment y = 5, x in [2, 8] on z = 5 become 0.9;
    # the top layer (z = 4.75) at y = 4.75 / 5.25 and x = 4.75 is 0.35 mm off the plane
    assert f.values[9, 9, 9] == pytest.approx(0.9) and f.values[9, 10, 2] == pytest.approx(0.9)
    assert f.values[9, 9, 19] == pytest.approx(0.1 + 0.5 * 4.75 / 5)      # x = 9.75 is 1.75 mm off the end
    # z = 3.75 lies 1.25 mm below the plane: only cells within sqrt(1.5^2 - 1.25^2) in-plane are painted
    reach = math.sqrt(1.5 ** 2 - 1.25 ** 2)
    ys = (np.arange(20) + 0.5) * 0.5
    painted = np.isclose(f.values[7, :, 10], 0.9)
    assert np.array_equal(painted, np.abs(ys - 5.0) < reach)


def test_one_stroke_is_one_undo_step_and_undo_restores_the_field():
    doc, st = _graph(resolution=10, base=0.2)
    before = Evaluator().evaluate(doc).output("f").values.copy()
    st.push(SetParam("f", "strokes", [STROKE]))
    painted = Evaluator().evaluate(doc).output("f").values
    assert np.count_nonzero(painted != before) > 0
    assert set(np.unique(painted)) == {0.2, 0.9}
    st.undo()
    assert doc.nodes["f"].params["strokes"] == []
    assert np.array_equal(Evaluator().evaluate(doc).output("f").values, before)


def test_a_radial_bump_node_matches_its_closed_form():
    doc, _ = _graph(lo=[-2, -2, -2], hi=[2, 2, 2], resolution=8, mode="radial", centre=[0.25, 0.25, 0.25],
                    radius=1.5, inner=2.0, outer=-1.0, falloff="linear")
    f = Evaluator().evaluate(doc).output("f")
    c = -2 + (np.arange(8) + 0.5) * 0.5
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    s = np.sqrt((x - 0.25) ** 2 + (y - 0.25) ** 2 + (z - 0.25) ** 2) / 1.5
    assert np.allclose(f.values, -1.0 + 3.0 * np.clip(1 - s, 0, None), atol=1e-12)


@pytest.mark.parametrize("params, where", [
    ({"lo": [0, 0, 0], "hi": [1, 0, 1]}, "hi"),
    ({"mode": "ramp", "ramp_from": 2.0, "ramp_to": 2.0}, "ramp_to"),
    ({"clamp": True, "clamp_lo": 1.0, "clamp_hi": 0.0}, "clamp_hi"),
    ({"resolution": 1024}, "resolution"),           # 1024^3 cells exceed the memory budget
])
def test_bad_parameters_are_refused_at_the_parameter(params, where):
    doc, _ = _graph(**params)
    res = Evaluator().evaluate(doc)
    assert not res.ok
    assert res.results["f"].where == where, (res.results["f"].error, res.results["f"].where)


def test_a_bad_stroke_is_refused_at_the_strokes_parameter():
    doc, st = _graph()
    with pytest.raises(ParamError, match=r"stroke 0: FieldStroke\.strength: expected a number in \[0, 1\]"):
        st.push(SetParam("f", "strokes", [dict(STROKE, strength=2.0)]))
    assert doc.nodes["f"].params["strokes"] == []


@pytest.mark.parametrize("mode, strokes", [
    ("constant", []),
    ("radial", []),
    ("ramp", [dict(STROKE, points=[[0.0, 0.0], [10.0, 8.0]], radius=7.0, falloff="smooth")]),  # all cells
])
def test_the_memory_estimate_bounds_the_measured_peak(mode, strokes):
    from .memory_peak import evaluate_traced

    doc, _ = _graph(lo=[0, 0, 0], hi=[10, 8, 6], resolution=64, mode=mode, strokes=strokes)
    res, peak = evaluate_traced(doc)
    assert res.ok, res.errors
    estimate = node_type("ScalarField").memory_estimate(doc.nodes["f"].params)
    assert res.output("f").values.size * 8 < peak <= estimate <= 4 * peak
