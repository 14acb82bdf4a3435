"""Painting a Scalar Field in the Implicit Media dock of a real window: a mouse drag on the slice
is ONE SetParam on the undo stack (undo removes it), the evaluated slice shows the painted
value where the brush reached (cells worked out here from the box and the drag), and the
SDF view steps aside while a field is shown."""

from __future__ import annotations

import math

import numpy as np
import pytest
from PySide6 import QtCore

from engine.graph import AddNode

LO, HI = [0.0, 0.0, 0.0], [10.0, 10.0, 10.0]
N = 10                                   # 1 mm cells


def _add_field(window, wait_eval, **params):
    after = window.eval_count
    nid = window.undo.push(AddNode("ScalarField", {"lo": LO, "hi": HI, "resolution": N, "base": 0.25,
                                                   **params}, (0, 0))).node_id
    window.evaluate_now()
    assert wait_eval(window, after).ok
    return nid


def _drag(qtbot, canvas, points):
    pts = [canvas.widget_point(u, v).toPoint() for u, v in points]
    qtbot.mousePress(canvas, QtCore.Qt.MouseButton.LeftButton, pos=pts[0])
    for p in pts[1:]:
        qtbot.mouseMove(canvas, p)
    qtbot.mouseRelease(canvas, QtCore.Qt.MouseButton.LeftButton, pos=pts[-1])


@pytest.fixture
def painting(window, qtbot, wait_eval):
    nid = _add_field(window, wait_eval)
    panel = window.implicit_panel
    window.implicit_dock.show()
    window.implicit_dock.raise_()
    window.editor.select(nid)
    box = panel.paint_box
    qtbot.waitUntil(lambda: box.field is not None and box.canvas.rgb is not None, timeout=30000)
    return window, panel, box, nid


def test_a_scalar_field_shows_its_paint_canvas_instead_of_the_trace_view(painting):
    window, panel, box, nid = painting
    assert panel.node_id == nid
    assert box.isVisible() and not panel.sdf_box.isVisible() and not panel.fit_box.isVisible()
    assert box.layer.shape == (N, N) and np.all(box.layer == 0.25)
    assert box.canvas.painting
    box.axis_box.setCurrentIndex(0)                     # an x slice: (u, v) = (y, z)
    assert box.canvas.axis_names == ("y", "z")


def test_a_drag_is_one_stroke_shown_where_painted_and_undo_removes_it(painting, qtbot, wait_eval):
    window, panel, box, nid = painting
    box.axis_box.setCurrentIndex(2)
    box.position_slider.setValue(box.position_slider.maximum() * 55 // 100)   # z = 5.5: layer 5
    assert box.layer_index == 5 and box.position == pytest.approx(5.5)
    box.value_spin.setValue(0.9)
    box.radius_spin.setValue(1.5)
    box.strength_spin.setValue(1.0)
    box.falloff_box.setCurrentIndex(box.falloff_box.findData("constant"))
    before = box.field
    after = window.eval_count
    _drag(qtbot, box.canvas, [(2.5, 5.0), (4.5, 5.0), (6.5, 5.0), (7.5, 5.0)])
    strokes = window.doc.nodes[nid].params["strokes"]
    assert len(strokes) == 1
    st = strokes[0]
    assert st["axis"] == "z" and st["position"] == pytest.approx(5.5) and st["value"] == 0.9
    assert st["falloff"] == "constant" and st["radius"] == 1.5
    assert window.undo.undo_text().endswith(".strokes")           # the one undo item of the drag
    assert wait_eval(window, after).ok
    qtbot.waitUntil(lambda: box.field is not None and box.field is not before, timeout=30000)
    assert box.field is window.last_report.outputs[nid]["field"]     # the worker's evaluation
    # cells of layer z = 5.5 whose centres lie within 1.5 mm of the dragged polyline get 0.9
    pts = np.array(st["points"])
    c = np.arange(N) + 0.5
    want = np.full((N, N), 0.25)
    for row, y in enumerate(c):
        for col, x in enumerate(c):
            d = min(_seg(x, y, a, b) for a, b in zip(pts[:-1], pts[1:]))
            if d < 1.5:
                want[row, col] = 0.9
    assert np.count_nonzero(want == 0.9) >= 10
    assert np.allclose(box.field.values[5], want)                  # layer z = 5.5 of the field
    assert np.allclose(box.layer, want)                            # ... is what the slice shows
    rgb = box.canvas.rgb
    vmin, vmax = box.vrange
    assert (vmin, vmax) == (0.25, 0.9)
    painted, bare = rgb[want == 0.9], rgb[want == 0.25]
    assert np.all(painted == 255) and np.all(bare == 0)        # grey scale: top white, bottom black

    painted_field = box.field
    after = window.eval_count
    window.undo.undo()
    assert window.doc.nodes[nid].params["strokes"] == []
    assert wait_eval(window, after).ok
    qtbot.waitUntil(lambda: box.field is not None and box.field is not painted_field, timeout=30000)
    assert np.all(box.layer == 0.25)


def test_the_drag_so_far_is_previewed_on_the_slice_and_escape_abandons_it(painting, qtbot):
    window, panel, box, nid = painting
    box.value_spin.setValue(0.75)
    box.radius_spin.setValue(1.0)
    box.falloff_box.setCurrentIndex(box.falloff_box.findData("constant"))
    assert not box.radius_spin.setValue(0.0)           # refused at the field (radius > 0): stays 1
    assert box.radius_spin.value() == 1.0
    canvas = box.canvas
    start, end = canvas.widget_point(2.5, 2.5).toPoint(), canvas.widget_point(7.5, 2.5).toPoint()
    qtbot.mousePress(canvas, QtCore.Qt.MouseButton.LeftButton, pos=start)
    qtbot.mouseMove(canvas, end)
    row = box.layer[2]                                  # y = 2.5: the drag's own row of cells
    assert np.all(row[2:8] == 0.75) and row[0] == 0.25 and row[9] == 0.25
    assert window.doc.nodes[nid].params["strokes"] == []          # nothing pushed while dragging
    qtbot.keyClick(canvas, QtCore.Qt.Key.Key_Escape)
    qtbot.mouseRelease(canvas, QtCore.Qt.MouseButton.LeftButton, pos=end)
    assert window.doc.nodes[nid].params["strokes"] == []
    assert np.all(box.layer == 0.25)


def _seg(x, y, a, b):
    ex, ey = b[0] - a[0], b[1] - a[1]
    t = min(max(((x - a[0]) * ex + (y - a[1]) * ey) / (ex * ex + ey * ey), 0.0), 1.0)
    return math.hypot(x - a[0] - t * ex, y - a[1] - t * ey)
