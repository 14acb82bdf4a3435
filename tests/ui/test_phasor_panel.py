"""The Phasor Infill dock, driven by real mouse events over its canvas.

A tiny graph (PhasorFields 16^3 over a 20 mm box -> PhasorNoise) is
evaluated here with the engine's Evaluator; the dock gets the outputs the
way the window hands them over (``set_context``).  Expected values come from
independent computations: millimetres from the canvas rectangle and the box,
fields in closed form, the singularity measure from the engine's own
``singularity_slice`` on a plane built here.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from PySide6 import QtCore

import engine.nodes  # noqa: F401  (registers the node types)
from engine.graph import AddNode, Connect, Evaluator, GraphDocument, UndoStack
from engine.gpu.slice_plane import SlicePlane
from keyboard_entry import type_into

LO, HI = [0.0, 0.0, 0.0], [20.0, 20.0, 20.0]
# in-plane axes (u, v) per slice normal, as indices into (x, y, z)
IN_PLANE = {"x": (1, 2), "y": (0, 2), "z": (0, 1)}
STEPS = 200  # the dock's scrub steps through the box


class Graph:
    def __init__(self, spec, *, filtered=True, iterations=4, hi=HI, mesh_path=None):
        self.doc = GraphDocument(seed=7)
        self.undo = UndoStack(self.doc)
        self.fields_id = self.undo.push(AddNode("PhasorFields", {
            "lo": LO, "hi": list(hi), "resolution": 16, "spec": json.dumps(spec), "margin": 2.0})).node_id
        if mesh_path is not None:
            mesh_id = self.undo.push(AddNode("MeshImport", {"path": str(mesh_path)})).node_id
            self.undo.push(Connect(mesh_id, "mesh", self.fields_id, "domain"))
        self.noise_id = self.undo.push(AddNode("PhasorNoise", {
            "iterations": iterations, "filtered": filtered})).node_id
        self.undo.push(Connect(self.fields_id, "fields", self.noise_id, "fields"))
        self.undo.clear()   # the graph itself is not under test: only strokes go on the stack
        self.evaluator = Evaluator()
        self.outputs = {}
        self.evaluate()

    def evaluate(self):
        report = self.evaluator.evaluate(self.doc.snapshot())
        assert not report.errors, report.errors
        self.outputs = report.outputs
        return report.outputs

    @property
    def strokes(self):
        return self.doc.nodes[self.fields_id].params["strokes"]

    @property
    def fields(self):
        return self.outputs[self.fields_id]["fields"].fields

    @property
    def infill(self):
        return self.outputs[self.noise_id]["infill"]


@pytest.fixture
def make_panel(qtbot):
    from ui.phasor_panel import PhasorPanel

    panels = []

    def make(graph, display="field", field="F"):
        panel = PhasorPanel(graph.doc, graph.undo)
        panel.resize(520, 980)
        panel.show()
        qtbot.waitExposed(panel)
        panel.set_context(graph.doc, graph.outputs, graph.fields_id)
        panel.field_box.setCurrentIndex(["D", "F", "Gamma"].index(field))
        panel.set_display(display)
        panel.worker.wait_idle()
        panels.append(panel)
        return panel

    yield make
    for panel in panels:
        panel.shutdown()
        panel.close()
        panel.deleteLater()
    qtbot.wait(10)


def expected_mm(canvas, point, axis, lo=LO, hi=HI):
    """In-plane mm under a widget point, from the drawn rectangle and the box alone."""
    r = canvas.target_rect()
    u, v = IN_PLANE[axis]
    return (lo[u] + (point.x() - r.left()) / r.width() * (hi[u] - lo[u]),
            hi[v] - (point.y() - r.top()) / r.height() * (hi[v] - lo[v]))


def widget_pos(canvas, fx, fy):
    """Integer widget position at fractions (fx across, fy down) of the drawn rectangle."""
    r = canvas.target_rect()
    return QtCore.QPoint(int(r.left() + fx * r.width()), int(r.top() + fy * r.height()))


def drag(qtbot, canvas, points, *, release=True):
    qtbot.mousePress(canvas, QtCore.Qt.MouseButton.LeftButton, pos=points[0])
    for p in points[1:]:
        qtbot.mouseMove(canvas, p)
    if release:
        qtbot.mouseRelease(canvas, QtCore.Qt.MouseButton.LeftButton, pos=points[-1])


def pixel_centres(shape, axis, lo=LO, hi=HI):
    """(H, W) u and v mm of the pixel centres of a slice image covering the box."""
    h, w = shape
    u, v = IN_PLANE[axis]
    us = lo[u] + (np.arange(w) + 0.5) * (hi[u] - lo[u]) / w
    vs = lo[v] + (np.arange(h) + 0.5) * (hi[v] - lo[v]) / h
    return np.meshgrid(us, vs)


CONSTANT = {"D": [1.0, 0.0, 0.0], "F": 1.0, "Gamma": 0.0}


def test_a_drag_is_one_undo_item_with_points_in_slice_mm(qtbot, make_panel):
    g = Graph(CONSTANT)
    panel = make_panel(g)
    panel.value_spin.setValue(2.0)
    panel.radius_spin.setValue(2.5)
    canvas = panel.canvas
    path = [widget_pos(canvas, 0.2 + 0.1 * k, 0.3 + 0.05 * k) for k in range(6)]
    drag(qtbot, canvas, path)

    assert g.undo.can_undo and len(g.strokes) == 1
    s = g.strokes[0]
    assert (s["field"], s["axis"], s["value"], s["radius"]) == ("F", "z", 2.0, 2.5)
    z = LO[2] + (panel.position_slider.value() + 0.5) * (HI[2] - LO[2]) / STEPS
    assert s["position"] == pytest.approx(z)
    expected = [expected_mm(canvas, p, "z") for p in path]
    got = np.asarray(s["points"])
    assert np.allclose(got[0], expected[0]) and np.allclose(got[-1], expected[-1])
    for point in got:  # every recorded point is one of the mouse positions
        assert min(np.hypot(*(point - e)) for e in expected) < 1e-9
    # the dock shows the painted state at once and says how many strokes there are
    assert "1 stroke" in panel.caption.text()

    g.undo.undo()
    assert g.strokes == [] and not g.undo.can_undo
    g.undo.redo()
    assert len(g.strokes) == 1


def test_undo_then_new_outputs_refresh_the_view(qtbot, make_panel):
    g = Graph(CONSTANT)
    panel = make_panel(g)
    before = panel.shown_values.copy()
    panel.value_spin.setValue(1.5)     # F up to 1.5 keeps the view at 128 pixels (4 per period)
    drag(qtbot, panel.canvas, [widget_pos(panel.canvas, 0.3, 0.5), widget_pos(panel.canvas, 0.6, 0.5)])
    painted = panel.shown_values.copy()
    assert not np.array_equal(painted, before)
    panel.set_context(g.doc, g.evaluate(), g.fields_id)
    assert np.allclose(panel.shown_values, painted)   # the evaluated fields are what was previewed
    g.undo.undo()
    panel.set_context(g.doc, g.evaluate(), g.fields_id)
    assert np.array_equal(panel.shown_values, before)


@pytest.mark.parametrize("field, typed, words", [("F", "-1", "[0, inf] cells/mm"),
                                                 ("F", "0", "frequency F > 0"),
                                                 ("Gamma", "100", "[0, 90] °")])
def test_a_bad_brush_value_is_refused_at_its_field(qtbot, make_panel, field, typed, words):
    g = Graph(CONSTANT)
    panel = make_panel(g, field=field)
    kept = panel.value_spin.value()
    type_into(qtbot, panel.value_spin, typed)
    text = panel.value_spin.message.text()
    assert panel.value_spin.refused and words in text and f"{field} = {typed} refused" in text
    assert panel.value_spin.value() == kept                      # not clamped: the kept value
    drag(qtbot, panel.canvas, [widget_pos(panel.canvas, 0.3, 0.3), widget_pos(panel.canvas, 0.6, 0.6)])
    assert len(g.strokes) == 1                                    # painted with the kept value
    assert g.strokes[0]["value"] == pytest.approx(kept if field == "F" else math.radians(kept))
    # a good value clears the refusal and is painted
    type_into(qtbot, panel.value_spin, "1.5" if field == "F" else "45")
    assert not panel.value_spin.refused and panel.message.text() == ""
    drag(qtbot, panel.canvas, [widget_pos(panel.canvas, 0.3, 0.3), widget_pos(panel.canvas, 0.6, 0.6)])
    assert g.strokes[1]["value"] == pytest.approx(1.5 if field == "F" else math.radians(45.0))


@pytest.mark.parametrize("name, typed, words", [("radius_spin", "-2", "[0, inf] mm"),
                                                ("radius_spin", "0", "> 0 mm"),
                                                ("strength_spin", "1.5", "[0, 1]"),
                                                ("tilt_spin", "120", "[-90, 90] °"),
                                                ("heading_spin", "600", "[-360, 360] °"),
                                                ("depth_spin", "-1", "[0, inf] mm")])
def test_brush_fields_refuse_out_of_range_values_and_keep_theirs(qtbot, make_panel, name, typed, words):
    g = Graph(CONSTANT)
    panel = make_panel(g, field="D" if name in ("tilt_spin", "heading_spin") else "F")
    box = getattr(panel, name)
    kept = box.value()
    seen = []
    box.valueChanged.connect(seen.append)
    type_into(qtbot, box, typed)
    assert box.refused and words in box.message.text() and "kept" in box.message.text()
    assert box.value() == kept and seen == []
    tip = box.toolTip()
    assert "allowed:" in tip and "default:" in tip


def test_depth_zero_shows_as_the_radius_and_a_precise_value_is_kept_exactly(qtbot, make_panel):
    panel = make_panel(Graph(CONSTANT))
    assert panel.depth_spin.value() == 0.0 and panel.depth_spin.lineEdit().text() == "= radius"
    assert "= radius" in panel.depth_spin.toolTip()
    type_into(qtbot, panel.depth_spin, "2.123456789")             # more digits than a QDoubleSpinBox keeps
    assert panel.depth_spin.value() == 2.123456789
    type_into(qtbot, panel.radius_spin, "600")                    # no silent cap at some maximum
    assert panel.radius_spin.value() == 600.0 and not panel.radius_spin.refused
    type_into(qtbot, panel.depth_spin, "= radius")
    assert panel.depth_spin.value() == 0.0


def test_the_field_view_changes_during_the_drag_only_inside_the_brush_box(qtbot, make_panel):
    g = Graph(CONSTANT)
    panel = make_panel(g)
    panel.value_spin.setValue(2.0)
    radius = 2.0
    panel.radius_spin.setValue(radius)
    panel.falloff_box.setCurrentIndex(panel.falloff_box.findData("constant"))
    canvas = panel.canvas
    before_rgb = canvas.rgb.copy()
    path = [widget_pos(canvas, 0.25 + 0.04 * k, 0.6) for k in range(5)]
    drag(qtbot, canvas, path, release=False)
    assert canvas.in_stroke and not g.undo.can_undo   # nothing pushed yet
    changed = np.any(canvas.rgb != before_rgb, axis=-1)
    assert changed.any()
    mm = np.array([expected_mm(canvas, p, "z") for p in path])
    uu, vv = pixel_centres(canvas.rgb.shape[:2], "z")
    cell = (HI[0] - LO[0]) / 16     # a sample reads cells up to one spacing away
    reach = radius + cell
    inside_box = ((uu >= mm[:, 0].min() - reach) & (uu <= mm[:, 0].max() + reach)
                  & (vv >= mm[:, 1].min() - reach) & (vv <= mm[:, 1].max() + reach))
    assert not np.any(changed & ~inside_box)
    # the brush's own disc is repainted: F is 2 along the drag (every cell around it has weight 1)
    j = np.argmin(np.abs(uu[0] - mm[2, 0]))
    i = np.argmin(np.abs(vv[:, 0] - mm[2, 1]))
    assert panel.shown_values[i, j] == pytest.approx(2.0)
    qtbot.keyClick(canvas, QtCore.Qt.Key.Key_Escape)   # abandon: nothing pushed, view restored
    assert not canvas.in_stroke and not g.undo.can_undo and g.strokes == []
    assert np.array_equal(canvas.rgb, before_rgb)


def test_axis_change_and_scrubbing_show_the_right_slice(qtbot, make_panel):
    spec = {"D": [1.0, 0.0, 0.0], "F": {"kind": "linear", "axis": "z", "from": 0.5, "to": 1.5},
            "Gamma": 0.0}
    g = Graph(spec)
    panel = make_panel(g)
    cell = (HI[2] - LO[2]) / 16
    fields = g.fields
    zs = fields.lo[2] + (np.arange(16) + 0.5) * cell
    f_cells = fields.frequency[:, 0, 0]        # F of each z layer of cells

    def f_at(z):   # piecewise linear between cell centres, clamped beyond them
        return np.interp(z, zs, f_cells)

    shown = []
    for step in (30, 100, 170):
        panel.position_slider.setValue(step)
        z = LO[2] + (step + 0.5) * (HI[2] - LO[2]) / STEPS
        assert panel.shown_values == pytest.approx(np.full(panel.shown_values.shape, f_at(z)))
        shown.append(panel.canvas.rgb.copy())
    assert not np.array_equal(shown[0], shown[1]) and not np.array_equal(shown[1], shown[2])

    panel.set_slice("x", 10.0)          # rows now run along z: F varies down the picture
    values = panel.shown_values
    _, vv = pixel_centres(values.shape, "x")
    assert values == pytest.approx(f_at(vv))
    assert panel.canvas.axis_names == ("y", "z")


def test_scrubbing_the_pattern_supersedes_older_requests(qtbot, make_panel):
    from engine.phasor.preview import pattern_slice

    g = Graph(CONSTANT)
    panel = make_panel(g, display="diamonds")
    first = panel.shown_values.copy()
    for step in (20, 60, 140):          # three requests in a row: the last one wins
        panel.position_slider.setValue(step)
    assert panel.worker.wait_idle()
    z = LO[2] + (140 + 0.5) * (HI[2] - LO[2]) / STEPS
    h, w = panel.shown_values.shape
    plane = SlicePlane((LO[0], LO[1], z), (1, 0, 0), (0, 1, 0), (HI[0] - LO[0], HI[1] - LO[1]), (w, h))
    want, _ = pattern_slice(g.infill, plane, "diamonds", engine=panel.pattern_engine)
    assert np.mean(panel.shown_values != want) < 1e-3   # float32 shader vs itself: same pixels
    assert not np.array_equal(first, panel.shown_values)


def test_singularity_heat_map_matches_the_engine(qtbot, make_panel):
    from engine.phasor.singularity import singularity_slice

    spec = {"D": {"kind": "spiral", "axis": "z", "angle_deg": 90}, "F": 0.6, "Gamma": 0.3}
    g = Graph(spec)
    panel = make_panel(g, display="singularity")
    assert panel.worker.wait_idle()
    values = panel.shown_values
    h, w = values.shape
    z = LO[2] + (panel.position_slider.value() + 0.5) * (HI[2] - LO[2]) / STEPS
    plane = SlicePlane((LO[0], LO[1], z), (1, 0, 0), (0, 1, 0), (HI[0] - LO[0], HI[1] - LO[1]), (w, h))
    inf = g.infill
    s_v, s_w = singularity_slice(inf.kernels, plane, fields=inf.fields, filtered=inf.filtered,
                                 filter_scale=inf.filter_scale, attenuation=inf.attenuation)
    want = np.maximum(s_v, s_w)
    assert np.array_equal(np.isinf(values), np.isinf(want))
    finite = np.isfinite(want)
    assert np.allclose(values[finite], want[finite], rtol=1e-9, atol=1e-12)
    assert np.ptp(want[finite]) > 0.1            # a real heat map, not a flat picture
    assert panel.canvas.scale is not None and "S" in panel.canvas.scale[3]
    rgb = panel.canvas.rgb
    hottest, coldest = np.unravel_index(np.argmax(np.where(finite, want, -1)), want.shape), \
        np.unravel_index(np.argmin(np.where(finite, want, 1e9)), want.shape)
    assert not np.array_equal(rgb[hottest], rgb[coldest])


def test_the_pattern_follows_the_brush_locally_and_matches_the_evaluation(qtbot, make_panel):
    spec = {"D": [1.0, 0.0, 0.0], "F": 2.0, "Gamma": 0.0}
    g = Graph(spec, filtered=False, iterations=3)
    panel = make_panel(g, display="diamonds", field="D")
    before = panel.shown_values.copy()
    radius = 1.5
    panel.radius_spin.setValue(radius)
    canvas = panel.canvas
    path = [widget_pos(canvas, 0.1 + 0.05 * k, 0.85 - 0.05 * k) for k in range(4)]
    drag(qtbot, canvas, path, release=False)
    assert panel.worker.wait_idle()
    during = panel.shown_values.copy()
    changed = during != before
    assert changed.any()
    # where it may change: the stroke's cells, one cell for the samples, the re-aligned kernels
    # (one kernel radius of margin) and their reach (one more), two cells for A(x)
    mm = np.array([expected_mm(canvas, p, "z") for p in path])
    kernel_radius = g.infill.kernels.radius
    cell = (HI[0] - LO[0]) / 16
    reach = radius + cell + cell + 2 * kernel_radius + 2 * cell
    uu, vv = pixel_centres(during.shape, "z")
    near = ((uu >= mm[:, 0].min() - reach) & (uu <= mm[:, 0].max() + reach)
            & (vv >= mm[:, 1].min() - reach) & (vv <= mm[:, 1].max() + reach))
    assert near.mean() < 0.8 and not np.any(changed & ~near)
    qtbot.mouseRelease(canvas, QtCore.Qt.MouseButton.LeftButton, pos=path[-1])
    assert panel.worker.wait_idle()
    assert len(g.strokes) == 1 and g.strokes[0]["field"] == "D"
    previewed = panel.shown_values.copy()
    # the evaluation (stateful noise: local resample + re-alignment) gives what was previewed
    panel.set_context(g.doc, g.evaluate(), g.fields_id)
    assert panel.worker.wait_idle()
    assert np.mean(panel.shown_values != previewed) < 1e-3


def test_gcode_preview_emits_coloured_lines(qtbot, make_panel, tmp_path):
    g = Graph(CONSTANT)
    panel = make_panel(g)
    # two layers by hand: a perimeter square and one infill wall each; bed offset (100, 100)
    text = ["G90", "M82", "G92 E0"]
    e = 0.0
    for z in (0.2, 0.4):
        text.append(f"G0 X100 Y100 Z{z}")
        text.append(";TYPE:perimeter")
        for x, y in ((110, 100), (110, 110), (100, 110), (100, 100)):
            e += 0.5
            text.append(f"G1 X{x} Y{y} E{e:.3f}")
        text.append("G0 X102 Y105")
        text.append(";TYPE:infill")
        e += 0.3
        text.append(f"G1 X108 Y105 E{e:.3f}")
    path = tmp_path / "hand.gcode"
    path.write_text("\n".join(text) + "\n")
    with qtbot.waitSignal(panel.preview_lines, timeout=5000) as sig:
        assert panel.preview_gcode(str(path))
    points, segments, colours = sig.args
    assert segments.shape == (2 * (4 + 1), 2) and colours.shape == (10, 3)
    seg = points[segments]                          # (m, 2, 3) part coordinates
    assert seg[..., :2].min() == pytest.approx(0.0) and seg[..., :2].max() == pytest.approx(10.0)
    assert set(np.round(seg[..., 2].ravel(), 6)) == {0.2, 0.4}
    perimeter = np.all(colours == (230, 120, 30), axis=1)
    infill = np.all(colours == (40, 110, 200), axis=1)
    assert perimeter.sum() == 8 and infill.sum() == 2
    lengths = np.linalg.norm(seg[:, 1] - seg[:, 0], axis=1)
    assert lengths[infill] == pytest.approx([6.0, 6.0])
    assert len(panel.print_box.layers) == 2 and panel.print_box.layer_view.isVisible()


def test_export_writes_gcode_with_progress_and_previews_it(qtbot, make_panel, tmp_path):
    from engine.fab import PrintSettings

    g = Graph(CONSTANT, hi=[20.0, 20.0, 1.2])
    panel = make_panel(g, display="diamonds")
    out = tmp_path / "part.gcode"
    progress = []
    panel.print_box.progress.connect(lambda d, t: progress.append((d, t)))
    with qtbot.waitSignal(panel.preview_lines, timeout=120000) as sig:
        panel.export_gcode(str(out), settings=PrintSettings(layer_height=0.4), pixel=0.2)
    assert out.exists() and panel.print_box.last_gcode == str(out) and not panel.print_box.exporting
    assert len(panel.print_box.layers) == 3            # 1.2 mm / 0.4 mm
    assert progress and progress[-1][0] == progress[-1][1] == 3
    points, segments, _ = sig.args
    assert len(segments) > 0 and points[:, 2].max() == pytest.approx(1.2)
    assert "part.gcode" in panel.message.text()


def test_a_d_stroke_records_heading_and_tilt_and_draws_glyphs(qtbot, make_panel):
    g = Graph(CONSTANT)
    panel = make_panel(g, field="D")
    assert panel.canvas.glyphs is not None            # D shows as glyphs over its hue
    centres, vectors, _ = panel.canvas.glyphs
    assert np.allclose(vectors, [1.0, 0.0])            # D = +x lies along u on a z slice
    panel.set_slice("y", 10.0)                          # on a y slice (u, v) = (x, z): still +u
    assert np.allclose(panel.canvas.glyphs[1], [1.0, 0.0])
    panel.tilt_spin.setValue(30.0)
    panel.heading_check.setChecked(True)
    panel.heading_spin.setValue(90.0)
    panel.radius_spin.setValue(4.0)
    panel.falloff_box.setCurrentIndex(panel.falloff_box.findData("constant"))
    drag(qtbot, panel.canvas, [widget_pos(panel.canvas, 0.5, 0.5), widget_pos(panel.canvas, 0.55, 0.5)])
    s = g.strokes[0]
    assert (s["field"], s["axis"], s["value"]) == ("D", "y", None)
    assert s["tilt"] == pytest.approx(math.radians(30.0))
    assert np.allclose(s["heading"], [0.0, 1.0], atol=1e-12)
    # under the brush D is now the heading (+v = +z) tilted towards +y: (0, sin 30, cos 30)
    panel.set_context(g.doc, g.evaluate(), g.fields_id)
    d = g.fields.sample_direction(np.array([[10.0, 10.0, 10.0]]))[0]
    assert np.allclose(d, [0.0, 0.5, math.sqrt(3) / 2])
    _, vectors, _ = panel.canvas.glyphs
    # the glyphs show D's in-plane part there: cos 30 along v
    assert np.any(np.all(np.isclose(vectors, [0.0, math.sqrt(3) / 2]), axis=1))


def test_a_slow_slice_shows_progress_and_can_be_cancelled(qtbot, make_panel):
    import time

    from engine.progress import report

    from ui.phasor_worker import SliceJob

    g = Graph(CONSTANT)
    panel = make_panel(g, display="diamonds")
    calls = []

    def slow(progress):          # stands in for a long local update: polls its progress callback
        for k in range(500):
            calls.append(k)
            report(progress, k, 500)
            time.sleep(0.01)
        raise AssertionError("not cancelled")

    panel.worker.request(SliceJob("diamonds", panel.plane, g.infill, prepare=slow, view=panel.view_id))
    qtbot.waitUntil(lambda: panel.progress_row.isVisible(), timeout=3000)
    assert len(calls) >= 20        # shown only after ~0.3 s
    at_click = len(calls)
    qtbot.mouseClick(panel.cancel_button, QtCore.Qt.MouseButton.LeftButton)
    assert panel.worker.wait_idle(30000)          # a generous bound; the count below is the test
    assert len(calls) - at_click <= 2, len(calls) - at_click   # stopped at its next progress check
    qtbot.waitUntil(lambda: not panel.progress_row.isVisible(), timeout=1000)
    assert "cancelled" in panel.status.text()


def test_the_part_outline_lies_over_the_slice(qtbot, make_panel, tmp_path):
    import trimesh

    cube = trimesh.creation.box(extents=(16.0, 12.0, 16.0))
    cube.apply_translation((10.0, 10.0, 10.0))            # x 2..18, y 4..16, z 2..18
    path = tmp_path / "part.stl"
    cube.export(path)
    g = Graph(CONSTANT, mesh_path=path)
    assert np.allclose(g.fields.lo, [0, 2, 0]) and np.allclose(g.fields.hi, [20, 18, 20])  # box + 2 mm
    panel = make_panel(g, display="diamonds")
    seg = panel.canvas.outline
    assert seg is not None
    pixel = 20.0 / panel.plane.shape[1]
    assert seg[..., 0].min() == pytest.approx(2.0, abs=pixel)
    assert seg[..., 0].max() == pytest.approx(18.0, abs=pixel)
    assert seg[..., 1].min() == pytest.approx(4.0, abs=pixel)
    assert seg[..., 1].max() == pytest.approx(16.0, abs=pixel)
    length = np.linalg.norm(seg[:, 1] - seg[:, 0], axis=1).sum()
    assert length == pytest.approx(2 * (16 + 12), abs=4 * pixel)
    # outside the part the pattern is dimmed towards grey: no pure black or white pixel there
    uu, vv = pixel_centres(panel.shown_values.shape, "z", lo=[0, 2, 0], hi=[20, 18, 20])
    outside = (uu < 1.5) | (uu > 18.5)
    rgb = panel.canvas.rgb[outside].astype(int)
    assert rgb.min() > 60 and rgb.max() < 200
    panel.set_slice("z", 19.5)                              # above the part: no outline
    assert panel.canvas.outline is None
