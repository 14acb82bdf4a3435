"""One codec interface for the values kept in project files (engine.graph.codec,
registrations in engine.nodes.codecs).

The stateful nodes (Grow, RDGrow, PhasorNoise) have no encode_state /
decode_state of their own: the default NodeType methods store their results
through the codecs, in the formats project files already hold (the nodes
used to write them by hand), restore equal values, and re-save unchanged.
"""

from __future__ import annotations

import json
from collections import namedtuple
from dataclasses import dataclass

import numpy as np
import pytest
from scipy.ndimage import distance_transform_edt

import engine.graph.codec as codec
from engine.graph import (AddNode, Connect, Evaluator, GraphDocument, SetParam, UndoStack, load_project,
                          node_type, save_project)
from engine.graph.node import NodeType
from engine.growth.regions import format_region_map
from engine.growth.values import TilingValue
from engine.rd.values import RDStructuresValue

STATEFUL = ("Grow", "RDGrow", "PhasorNoise")


# ------------------------------------------------------------------ the registry


# a port as the codecs read it (name, type), for test types the schema does not know
Port = namedtuple("Port", "name type")


@dataclass(frozen=True)
class _Box:
    x: float


@pytest.fixture
def registry(monkeypatch):
    """A private copy of the registry, so test codecs do not outlive the test."""
    monkeypatch.setattr(codec, "_BY_NAME", dict(codec._BY_NAME))
    codec.register_codec(_Box, "TestBox", lambda v: {"x": v.x},
                         lambda blob, inputs: _Box(float(blob["x"]) + inputs.get("offset", 0.0)))
    return codec


def test_one_output_stores_the_bare_dict_several_store_one_per_port(registry):
    one = (Port("box", "TestBox"),)
    assert registry.encode_outputs({"box": _Box(1.5)}, one) == {"x": 1.5}
    assert registry.decode_outputs({"x": 1.5}, {"offset": 1.0}, one) == {"box": _Box(2.5)}
    two = (Port("a", "TestBox"), Port("b", "TestBox"))
    blob = registry.encode_outputs({"a": _Box(1.0), "b": _Box(2.0)}, two)
    assert blob == {"a": {"x": 1.0}, "b": {"x": 2.0}}
    assert registry.decode_outputs(blob, {}, two) == {"a": _Box(1.0), "b": _Box(2.0)}
    with pytest.raises(ValueError, match=r"no stored value for output\(s\) \['b'\]"):
        registry.decode_outputs({"a": {"x": 1.0}}, {}, two)


def test_types_without_a_codec_are_not_stored_and_refuse_to_decode(registry):
    ports = (Port("box", "TestBox"), Port("other", "NoSuchType"))
    assert registry.encode_outputs({"box": _Box(1.0), "other": 3}, ports) is None
    assert registry.encode_outputs({}, ()) is None
    with pytest.raises(ValueError, match="NoSuchType"):
        registry.decode_outputs({}, {}, ports)
    with pytest.raises(TypeError, match="expected _Box, got int"):
        registry.encode_outputs({"box": 3}, (Port("box", "TestBox"),))


def test_a_port_type_has_one_value_class(registry):
    registry.register_codec(_Box, "TestBox", lambda v: {}, lambda b, i: _Box(0.0))  # same class: replaced
    with pytest.raises(ValueError, match="already has a codec for _Box"):
        registry.register_codec(dict, "TestBox", lambda v: {}, lambda b, i: {})


def test_the_default_node_methods_use_the_codecs(registry):
    class BoxNode(NodeType):
        type_name = "TestBoxNode"
        outputs = (Port("box", "TestBox"),)

    class PlainNode(NodeType):
        type_name = "TestPlainNode"
        outputs = (Port("n", "NoSuchType"),)

    assert BoxNode().encode_state({"box": _Box(4.0)}) == {"x": 4.0}
    assert BoxNode().decode_state({"x": 4.0}, {}) == {"box": _Box(4.0)}
    assert PlainNode().encode_state({"n": 1}) is None
    with pytest.raises(ValueError, match="'TestPlainNode' cannot restore a stored state"):
        PlainNode().decode_state({}, {})


def test_the_stateful_nodes_output_types_have_codecs_and_painted_fields_none():
    for t in STATEFUL:
        assert codec.has_codecs(node_type(t).outputs), t
    # PhasorFields is stateful but keeps nothing (its fields follow from the parameters)
    assert node_type("PhasorFields").stateful and not codec.has_codecs(node_type("PhasorFields").outputs)


# ------------------------------------------------------------------ real evaluated outputs


def _grow_doc():
    doc = GraphDocument(seed=4)
    st = UndoStack(doc)
    st.push(AddNode("TileSet", node_id="ts"))
    st.push(AddNode("Grow", {"size": [12, 12]}, node_id="g"))
    st.push(Connect("ts", "tileset", "g", "tileset"))
    return doc, st


def _regrown(doc, st, ev):
    ev.evaluate(doc)
    labels = np.zeros((12, 12), int)
    labels[4:8, 4:8] = 1
    st.push(SetParam("g", "region_hints", "1: +=50,T=1,L=1,-=1"))
    st.push(SetParam("g", "regions", format_region_map(labels)))


def _rd_doc():
    doc = GraphDocument(seed=0)
    st = UndoStack(doc)
    st.push(AddNode("TopOpt", {"preset": "cantilever", "resolution": [32, 16], "max_iter": 15}, node_id="to"))
    st.push(AddNode("RDFields", {}, node_id="f"))
    st.push(AddNode("RDGrow", {"resolution": [64, 32], "gamma": 4.0, "max_steps": 600}, node_id="g"))
    st.push(Connect("to", "design", "f", "design"))
    st.push(Connect("f", "rdfields", "g", "rdfields"))
    return doc, st


def _rd_edited(doc, st, ev):
    grown = ev.evaluate(doc).output("g")
    inside = grown.fields.rho >= grown.iso
    ys, xs = np.nonzero(distance_transform_edt(inside) >= 3)
    i = len(ys) // 3                                   # a point well inside the infill space
    edit = {"mode": "erase", "centre": [float(xs[i]) + 0.5, float(ys[i]) + 0.5], "radius": 4.0}
    st.push(SetParam("g", "edits", [edit]))            # a local regrowth: history in the state


def _phasor_doc():
    spec = {"D": {"kind": "spiral", "axis": "z", "angle_deg": 60, "centre": [4.0, 4.0, 0.0]},
            "F": {"kind": "linear", "axis": "x", "from": 1.0, "to": 1.4}}
    doc = GraphDocument(seed=11)
    st = UndoStack(doc)
    st.push(AddNode("PhasorFields", {"lo": [0.0, 0.0, 0.0], "hi": [8.0, 8.0, 2.0], "resolution": 16,
                                     "spec": json.dumps(spec), "strokes": []}, node_id="f"))
    st.push(AddNode("PhasorNoise", {}, node_id="n"))
    st.push(Connect("f", "fields", "n", "fields"))
    return doc, st


def _phasor_painted(doc, st, ev):
    ev.evaluate(doc)
    stroke = {"field": "D", "axis": "z", "position": 1.0, "points": [[5.0, 6.0], [7.0, 6.5]],
              "radius": 1.0, "strength": 0.7}
    st.push(SetParam("f", "strokes", [stroke]))      # the noise re-aligns locally: history in its phases


CASES = {"Grow": (_grow_doc, _regrown, "g", "tileset"),
         "RDGrow": (_rd_doc, _rd_edited, "g", "rdfields"),
         "PhasorNoise": (_phasor_doc, _phasor_painted, "n", "fields")}


def _evaluated(type_name):
    make, history, nid, in_port = CASES[type_name]
    doc, st = make()
    ev = Evaluator()
    history(doc, st, ev)
    report = ev.evaluate(doc)
    assert report.ok, report.errors
    src = doc.inputs_of(nid, in_port)[0]
    inputs = {in_port: report.outputs[src.src][src.src_port]}
    return doc, ev, report.outputs[nid], inputs


def _same_value(a, b):
    """The restored value equals the evaluated one in everything a project keeps."""
    assert type(a) is type(b)
    if isinstance(a, TilingValue):            # the tiles (the replay record is not kept)
        assert a.tiling.tiles.tobytes() == b.tiling.tiles.tobytes() and a.tileset is b.tileset
    elif isinstance(a, RDStructuresValue):
        assert a.s.tobytes() == b.s.tobytes()
        facts = ("directions", "steps", "stop_reasons", "edits")
        assert [getattr(a, n) for n in facts] == [getattr(b, n) for n in facts]
    else:                                     # PhasorInfill: the resampled kernels, the stored phases
        for name in ("phase_v", "phase_w", "direction_v", "direction_w"):
            assert np.array_equal(getattr(a.kernels, name), getattr(b.kernels, name)), name
        assert (a.iterations, a.filtered, a.filter_scale) == (b.iterations, b.filtered, b.filter_scale)


# the stored formats projects already hold (before the codecs the nodes wrote these by hand)
STORED_KEYS = {
    "Grow": {"tiling"},
    "PhasorNoise": {"n", "seed", "per_cell", "c", "iterations", "filtered", "filter_scale",
                    "fields_sha256", "phase_v", "phase_w"},
}


@pytest.mark.parametrize("type_name", STATEFUL)
def test_real_outputs_round_trip_through_the_codecs_in_the_stored_format(type_name):
    _, _, outputs, inputs = _evaluated(type_name)
    node = node_type(type_name)()
    assert "encode_state" not in type(node).__dict__ and "decode_state" not in type(node).__dict__
    blob = json.loads(json.dumps(node.encode_state(outputs)))      # as read back from a file
    if type_name in STORED_KEYS:
        assert set(blob) == STORED_KEYS[type_name]
    else:                                                           # RDGrow: rd_state's own format
        from engine.nodes import rd_state
        assert json.dumps(blob) == json.dumps(rd_state.encode_structures(outputs["structures"]))
    by_codec = node.decode_state(blob, inputs)
    assert set(by_codec) == {p.name for p in node.outputs}
    for port in by_codec:
        _same_value(by_codec[port], outputs[port])
    # a missing input is refused, naming what is not connected
    with pytest.raises(ValueError, match="connected"):
        node.decode_state(blob, {name: None for name in inputs})


@pytest.mark.parametrize("type_name", STATEFUL)
def test_projects_save_and_reopen_byte_identically_with_the_default(type_name, tmp_path):
    cls = node_type(type_name)
    assert cls.encode_state is NodeType.encode_state       # no per-node override: the codecs
    doc, ev, outputs, _ = _evaluated(type_name)
    nid = CASES[type_name][2]
    doc.node_state = ev.export_state()                 # encoded by the codecs
    default = tmp_path / "default.json"
    save_project(doc, default)
    # reopened: restored through the codecs (cached, no warning), re-saved unchanged
    opened = load_project(default)
    fresh = Evaluator()
    assert fresh.import_state(opened.node_state) == []
    report = fresh.evaluate(opened)
    assert report.ok and report.results[nid].status == "cached" and not report.warnings
    for port, value in report.outputs[nid].items():
        _same_value(value, outputs[port])
    # the restored value encodes to the stored JSON again (not only the held blob is re-saved)
    stored = json.loads(default.read_text())["node_state"][nid]["value"]
    assert json.dumps(NodeType.encode_state(cls(), report.outputs[nid])) == json.dumps(stored)
    opened.node_state = fresh.export_state()
    again = tmp_path / "again.json"
    save_project(opened, again)
    assert again.read_bytes() == default.read_bytes()


def test_shipped_examples_reopen_and_resave_unchanged(tmp_path):
    from pathlib import Path
    root = Path(__file__).resolve().parents[3] / "resources" / "examples"
    for path in sorted(root.glob("*.json")):
        doc = load_project(path)
        ev = Evaluator()
        assert ev.import_state(doc.node_state) == [], path.name
        doc.node_state = ev.export_state()
        out = tmp_path / path.name
        save_project(doc, out)
        first = out.read_bytes()
        save_project(load_project(out), out)
        assert out.read_bytes() == first, path.name
