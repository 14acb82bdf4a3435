"""The "json" parameter kind: any JSON data, canonical, optionally checked."""

import json

import pytest

from engine.graph import Param, ParamError
from engine.graph.project import document_from_dict, document_to_dict


def _positive_list(data):
    if not isinstance(data, list) or not all(isinstance(v, (int, float)) and v > 0 for v in data):
        raise ValueError("a list of positive numbers")
    return sorted(data)


def test_json_values_come_back_as_plain_data():
    p = Param("data", "json", [])
    value = {"b": (1, 2.5), "a": [None, True, "x", {"k": []}]}
    out = p.coerce(value)
    assert out == {"a": [None, True, "x", {"k": []}], "b": [1, 2.5]}
    assert isinstance(out["b"], list)
    out["a"].append(1)                       # a copy: the caller's data is untouched
    assert value["a"] == [None, True, "x", {"k": []}]
    assert json.loads(json.dumps(out)) == out
    assert p.to_dict()["kind"] == "json" and p.to_dict()["default"] == []


@pytest.mark.parametrize("bad", [float("nan"), [1, float("inf")], {"x": object()}, {1, 2}])
def test_non_json_values_are_refused_by_name(bad):
    with pytest.raises(ParamError) as err:
        Param("data", "json", []).coerce(bad)
    assert err.value.where == "data" and "JSON data" in str(err.value)


def test_the_check_makes_the_canonical_form_and_names_what_it_expects():
    p = Param("sizes", "json", [], check=_positive_list)
    assert p.coerce([3, 1, 2]) == [1, 2, 3]
    with pytest.raises(ParamError, match="expected a list of positive numbers") as err:
        p.coerce([1, -2])
    assert err.value.where == "sizes"
    long = list(range(-1, 500))
    with pytest.raises(ParamError) as err:
        p.coerce(long)
    assert "characters)" in str(err.value) and len(str(err.value)) < 400   # long data is cut short
    with pytest.raises(ValueError, match="only 'json' parameters take a check"):
        Param("n", "int", 0, check=_positive_list)


def test_a_json_parameter_round_trips_through_a_project():
    from engine.graph import AddNode, GraphDocument, UndoStack

    doc = GraphDocument(seed=0)
    stroke = {"field": "F", "axis": "z", "position": 0, "points": [[1, 2]], "radius": 1, "value": 2}
    UndoStack(doc).push(AddNode("PhasorFields", {"strokes": [stroke]}, node_id="f"))
    saved = json.loads(json.dumps(document_to_dict(doc)))
    again = document_from_dict(saved)
    assert again.node("f").params["strokes"] == doc.node("f").params["strokes"]
    assert again.node("f").params["strokes"][0]["position"] == 0.0    # canonical: floats
