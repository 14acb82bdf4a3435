"""Printability in the Phasor Infill dock's print box: after an export, or on
"Printability…", the overhang and overlap histograms appear with the bar
heights of engine.fab.printability on the same layers (computed here)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from PySide6 import QtCore

import engine.nodes  # noqa: F401  (registers the node types)
from engine.fab import PrintSettings, layer_stack_toolpaths, printability, read_gcode_paths
from engine.graph import AddNode, Connect, Evaluator, GraphDocument, UndoStack
from engine.phasor.infill import print_layers

SPEC = {"D": {"kind": "spiral", "axis": "z", "angle_deg": 60}, "F": 1.0}


@pytest.fixture(scope="module")
def infill():
    doc = GraphDocument(seed=3)
    st = UndoStack(doc)
    st.push(AddNode("PhasorFields", {"lo": [0, 0, 0], "hi": [8, 8, 1], "resolution": 16,
                                     "spec": json.dumps(SPEC)}, node_id="f"))
    st.push(AddNode("PhasorNoise", {"iterations": 6}, node_id="n"))
    st.push(Connect("f", "fields", "n", "fields"))
    return Evaluator().evaluate(doc).output("n")


@pytest.fixture
def box(qtbot):
    from ui.phasor_print import PrintBox

    b = PrintBox()
    b.resize(520, 700)
    b.show()
    qtbot.waitExposed(b)
    yield b
    b.shutdown()
    b.close()
    b.deleteLater()
    qtbot.wait(10)


def _bar_heights(view, kind):
    return [int(round(bar.get_height())) for bar in view.bars[kind]]


def _check_view(view, report):
    assert view.isVisible() and view.report is report
    for kind in ("overhang", "overlap"):
        counts = getattr(report, f"{kind}_histogram").tolist()
        assert _bar_heights(view, kind) == counts
        lefts = [bar.get_x() for bar in view.bars[kind]]
        assert np.allclose(lefts, report.bin_edges[:-1])
    text = view.totals.text()
    assert f"{report.overhang_count} overhang segments" in text
    assert f"{report.overlap_count} overlap segments" in text


def test_printability_button_shows_the_histograms_of_the_infill_print(qtbot, box, infill):
    box.set_infill(infill, "part", engine="numpy")
    assert box.check_button.isEnabled()
    with qtbot.waitSignal(box.printability, timeout=60000) as sig:
        qtbot.mouseClick(box.check_button, QtCore.Qt.MouseButton.LeftButton)
    report = sig.args[0]
    assert not box.checking and box.check_button.isEnabled() and not box.check_row.isVisible()
    # the reference: the default print (0.2 mm layers, 0.4 mm nozzle) at the export's default pixel
    settings = PrintSettings()
    layers = list(layer_stack_toolpaths(print_layers(infill, layer_height=0.2, pixel=0.1, engine="numpy"),
                                        settings=settings))
    ref = printability(layers, nozzle_diameter=0.4)
    assert report.overhang_count == ref.overhang_count > 0 and report.overlap_count == ref.overlap_count > 0
    assert np.array_equal(report.overhang_histogram, ref.overhang_histogram)
    assert np.array_equal(report.overlap_histogram, ref.overlap_histogram)
    _check_view(box.printability_view, report)


def test_an_export_is_followed_by_the_printability_of_the_written_file(qtbot, box, infill, tmp_path):
    box.set_infill(infill, "part", engine="numpy")
    out = tmp_path / "part.gcode"
    messages = []
    box.message.connect(messages.append)
    with qtbot.waitSignal(box.printability, timeout=60000) as sig:
        box.export_gcode(str(out), settings=PrintSettings(layer_height=0.25), pixel=0.1)
    report = sig.args[0]
    ref = printability(read_gcode_paths(out, offset=(100.0, 100.0)), nozzle_diameter=0.4)
    assert len(report.overhang_per_layer) == 4
    assert np.array_equal(report.overhang_histogram, ref.overhang_histogram)
    assert np.array_equal(report.overlap_histogram, ref.overlap_histogram)
    _check_view(box.printability_view, report)
    assert any(m.startswith("wrote part.gcode") for m in messages)
    assert messages[-1].startswith("printability of part.gcode")


def test_a_printability_check_can_be_cancelled(qtbot, box, infill):
    box.set_infill(infill, "part", engine="numpy")
    messages = []
    box.message.connect(messages.append)
    box.check_printability()
    assert box.checking and not box.check_button.isEnabled()
    box.cancel_check()
    qtbot.waitUntil(lambda: not box.checking, timeout=30000)
    assert box.printability_view is None and box.check_button.isEnabled()
    assert messages[-1] == "printability check cancelled"
