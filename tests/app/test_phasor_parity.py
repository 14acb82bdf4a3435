"""`mesoforge phasor` and the window give identical bytes.

A document is built as the window builds it (PhasorFields -> PhasorNoise ->
PhasorSlice through the undo stack, a brush stroke pushed as one SetParam
after a first evaluation, so the noise is updated locally) and saved with
the evaluator's stored states.  The command line's outputs on that project
must equal, byte for byte, what the Evaluator gives on the same document:
the slice's PNG (the PhasorSlice node's image), its energies (the node's
energy and the session's other noise states), the G-code and the
printability of the dock's export path (``PhasorInfillSession``).
"""

from __future__ import annotations

import json

import pytest

from app import cli
from engine.fab import PrintSettings, read_gcode_paths
from engine.graph import AddNode, Connect, Evaluator, GraphDocument, SetParam, UndoStack, save_project
from engine.nodes.phasor_session import PhasorInfillSession, diamonds_png

SPEC = {"D": {"kind": "spiral", "axis": "z", "angle_deg": 60}, "F": 1.0}
STROKE = {"field": "F", "axis": "z", "position": 0.5, "points": [[2.0, 2.0], [5.0, 3.0]], "radius": 1.5,
          "value": 1.2}
PIXEL, LAYER = 0.1, 0.25


@pytest.fixture(scope="module")
def window(tmp_path_factory):
    """(project path, outputs of the window's evaluation after the stroke)."""
    doc = GraphDocument(seed=5)
    st = UndoStack(doc)
    st.push(AddNode("PhasorFields", {"lo": [0, 0, 0], "hi": [8, 8, 1], "resolution": 16,
                                     "spec": json.dumps(SPEC)}, node_id="f"))
    st.push(AddNode("PhasorNoise", {"iterations": 4}, node_id="n"))
    st.push(Connect("f", "fields", "n", "fields"))
    st.push(AddNode("PhasorSlice", {"position": 0.5, "pixel": PIXEL, "engine": "numpy"}, node_id="s"))
    st.push(Connect("n", "infill", "s", "infill"))
    evaluator = Evaluator()
    assert evaluator.evaluate(doc).ok
    st.push(SetParam("f", "strokes", [STROKE]))          # one brush stroke: a local noise update
    report = evaluator.evaluate(doc)
    assert report.ok, report.errors
    doc.node_state = evaluator.export_state()            # what the window saves
    path = tmp_path_factory.mktemp("parity") / "infill.json"
    save_project(doc, path)
    return path, report.outputs


def _cli(capsys, *args):
    code = cli.main(["phasor", *map(str, args)])
    cap = capsys.readouterr()
    assert code == 0, cap.err
    return cap.out


def _session(outputs):
    return PhasorInfillSession.of_infill(outputs["n"]["infill"])


def test_png_is_the_slice_nodes_image(window, tmp_path, capsys):
    path, outputs = window
    png = tmp_path / "s.png"
    _cli(capsys, path, "--slice", "z=0.5", "--px", PIXEL, "--engine", "numpy", "--png", png)
    assert png.read_bytes() == diamonds_png(outputs["s"]["image"].values)


def test_json_energies_are_the_slice_nodes_and_the_sessions(window, capsys):
    path, outputs = window
    info = json.loads(_cli(capsys, path, "--slice", "z=0.5", "--px", PIXEL, "--engine", "numpy", "--json"))
    own = outputs["s"]["energy"]
    assert own.state == "aligned+filtered"
    assert info["energy"][own.state] == {"F_S": own.value, "F_S_v": own.v, "F_S_w": own.w, "pixels": own.pixels}
    session = _session(outputs)
    for state in ("raw", "aligned"):
        e = session.energy(session.slice_at("z", 0.5, PIXEL, state=state, engine="numpy"))
        assert info["energy"][state] == {"F_S": e.value, "F_S_v": e.v, "F_S_w": e.w, "pixels": e.pixels}
    image = outputs["s"]["image"]
    assert info["slice"]["shape"] == list(image.values.shape) and info["slice"]["lo"] == image.lo.tolist()


def test_gcode_is_the_docks_export(window, tmp_path, capsys):
    path, outputs = window
    gcode = tmp_path / "cli.gcode"
    _cli(capsys, path, "--gcode", gcode, "--layer", LAYER, "--px", PIXEL, "--engine", "numpy")
    ref = tmp_path / "dock.gcode"
    _session(outputs).write_print(ref, settings=PrintSettings(layer_height=LAYER), pixel=PIXEL, engine="numpy")
    assert gcode.read_bytes() == ref.read_bytes() and len(read_gcode_paths(ref)) == 4


def test_printability_is_the_docks_check(window, capsys):
    from app.phasor_cmd import printability_summary

    path, outputs = window
    info = json.loads(_cli(capsys, path, "--printability", "--layer", LAYER, "--px", PIXEL, "--engine", "numpy",
                           "--json"))
    settings = PrintSettings(layer_height=LAYER)
    report = _session(outputs).printability(settings, pixel=PIXEL, engine="numpy")
    assert info["printability"] == json.loads(json.dumps(printability_summary(report, settings.nozzle_diameter)))
    assert info["printability"]["overhang"]["segments"] + info["printability"]["overlap"]["segments"] > 0
