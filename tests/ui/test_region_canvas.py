"""Painting hint regions, replaying recorded growth and 3D layers in the Virtual Growth
panel, driven with real mouse and key events on a real GrowthPanel under Xvfb.

Expected label maps are computed here from the pointer positions (distance of each
cell centre to the stroke polyline), not by the panel's code.
"""

from __future__ import annotations

import numpy as np
import pytest
from PySide6 import QtCore

from engine.graph import (AddNode, Connect, Evaluator, GraphDocument, SetParam, UndoStack,
                          document_to_dict)
from engine.growth.values import TilingValue
from engine.growth import UNASSIGNED, grow_tiling, load_tileset, regrow_region
from engine.growth.regions import parse_region_map
from engine.growth.regrow import dilate
from keyboard_entry import type_into
from ui.growth_panel import GrowthPanel

LEFT = QtCore.Qt.MouseButton.LeftButton
RIGHT = QtCore.Qt.MouseButton.RightButton
NX, NY = 8, 6


class Scene:
    def __init__(self, qtbot, size=(NX, NY), tileset="TL+-", undo=True):
        self.doc = GraphDocument(seed=5)
        self.undo = UndoStack(self.doc)
        ts = self.undo.push(AddNode("TileSet", {"name": tileset}, (0, 0))).node_id
        self.grow = self.undo.push(AddNode("Grow", {"size": list(size)}, (200, 0))).node_id
        self.undo.push(Connect(ts, "tileset", self.grow, "tileset"))
        self.evaluator = Evaluator()
        self.panel = GrowthPanel(undo=self.undo if undo else None)
        qtbot.addWidget(self.panel)
        self.panel.resize(520, 1000)
        self.panel.show()
        qtbot.waitExposed(self.panel)
        self.evaluate()

    def evaluate(self):
        report = self.evaluator.evaluate(self.doc)
        assert not report.errors, report.errors
        self.outputs = report.outputs
        self.panel.set_context(self.doc, report.outputs, self.grow)
        return report

    @property
    def regions(self) -> str:
        return self.doc.nodes[self.grow].params["regions"]

    @property
    def tiling(self):
        return self.outputs[self.grow]["tiling"]


def point_of(view, x, y) -> QtCore.QPoint:
    return view.widget_point(x, y).toPoint()


def drag(qtbot, view, cells, button=LEFT, release=True):
    """Press at the first (x, y) cell position, move through the others, release at the last."""
    pts = [point_of(view, x, y) for x, y in cells]
    qtbot.mousePress(view, button, pos=pts[0])
    for p in pts[1:]:
        qtbot.mouseMove(view, p)
    if release:
        qtbot.mouseRelease(view, button, pos=pts[-1])
    return pts


def capsule_cells(shape, polyline, radius):
    """Cells whose centre lies within `radius` of the polyline (brute force)."""
    ny, nx = shape
    out = np.zeros(shape, bool)
    p = np.asarray(polyline, float)
    for i in range(ny):
        for j in range(nx):
            c = np.array([j + 0.5, i + 0.5])
            for a, b in zip(p[:-1], p[1:]):
                t = np.clip(np.dot(c - a, b - a) / max(np.dot(b - a, b - a), 1e-300), 0, 1)
                if np.linalg.norm(c - (a + t * (b - a))) <= radius:
                    out[i, j] = True
    return out


@pytest.fixture
def scene(qtbot):
    return Scene(qtbot)


def test_a_stroke_is_one_undo_item(scene, qtbot):
    panel, view = scene.panel, scene.panel.view
    assert view.painting and panel.paint_block_reason() is None
    assert view.grid_shape == (NY, NX)
    before_text = scene.undo.undo_text()
    before_doc = document_to_dict(scene.doc)
    panel.region_tools.label_buttons[2].click()
    panel.region_tools.radius.setValue(0.0)

    # radius 0: exactly the cells the pointer passes through (hand-computed)
    drag(qtbot, view, [(1.5, 1.5), (2.5, 1.5), (3.5, 1.5), (4.5, 1.5), (4.5, 2.5), (4.5, 3.5)],
         release=False)
    assert view.in_stroke and scene.regions == ""            # live overlay, nothing pushed yet
    assert scene.undo.undo_text() == before_text
    live = view.shown_labels()
    assert live is not None and np.count_nonzero(live) == 6
    qtbot.mouseRelease(view, LEFT, pos=point_of(view, 4.5, 3.5))
    expected = np.zeros((NY, NX), int)
    expected[1, 1:5] = 2
    expected[1:4, 4] = 2
    assert not view.in_stroke
    np.testing.assert_array_equal(parse_region_map(scene.regions, (NY, NX)), expected)
    assert scene.undo.undo_text() == f"set {scene.grow}.regions"
    np.testing.assert_array_equal(view.labels, expected)

    # one undo restores the empty map, the entry before is the graph's last edit
    assert scene.undo.undo()
    assert scene.regions == "" and scene.undo.undo_text() == before_text
    assert view.labels is None
    assert document_to_dict(scene.doc) == before_doc
    assert scene.undo.redo()
    np.testing.assert_array_equal(parse_region_map(scene.regions, (NY, NX)), expected)
    assert scene.undo.undo() and document_to_dict(scene.doc) == before_doc


def test_a_wide_brush_paints_the_cells_near_the_stroke(scene, qtbot):
    panel, view = scene.panel, scene.panel.view
    panel.region_tools.label_buttons[3].click()
    panel.region_tools.radius.setValue(1.2)
    # moves of several cells along rows and columns through cell centres: cell-centre
    # distances to the stroke are 0, 1, 1.41, ..., far from the radius 1.2
    first = [(1.5, 1.5), (3.5, 1.5), (5.5, 1.5), (5.5, 3.5), (5.5, 4.5)]
    pts = drag(qtbot, view, first)
    cells = [view.cell_at(p) for p in pts]                   # where the pointer really was
    expected = np.where(capsule_cells((NY, NX), cells, 1.2), 3, 0)
    np.testing.assert_array_equal(parse_region_map(scene.regions, (NY, NX)), expected)

    # a second stroke erasing with the right button; undo goes back to the first map
    text_after_first = scene.regions
    panel.region_tools.radius.setValue(0.0)
    drag(qtbot, view, [(1.5, 1.5), (2.5, 1.5)], button=RIGHT)
    second = expected.copy()
    second[1, 1:3] = 0
    np.testing.assert_array_equal(parse_region_map(scene.regions, (NY, NX)), second)
    assert scene.undo.undo() and scene.regions == text_after_first
    np.testing.assert_array_equal(view.labels, expected)


def test_escape_abandons_a_stroke_and_clear_is_one_step(scene, qtbot):
    panel, view = scene.panel, scene.panel.view
    drag(qtbot, view, [(0.5, 0.5), (3.5, 0.5)])
    painted = scene.regions
    assert painted
    top = scene.undo.undo_text()
    drag(qtbot, view, [(0.5, 4.5), (5.5, 4.5)], release=False)
    qtbot.keyClick(view, QtCore.Qt.Key.Key_Escape)
    assert not view.in_stroke
    qtbot.mouseRelease(view, LEFT, pos=point_of(view, 5.5, 4.5))
    assert scene.regions == painted
    qtbot.mouseClick(panel.region_tools.clear_button, LEFT)
    assert scene.regions == "" and view.labels is None
    assert scene.undo.undo() and scene.regions == painted and scene.undo.undo_text() == top


def test_region_hints_editor_refuses_bad_text_and_keeps_it(scene, qtbot):
    panel, view = scene.panel, scene.panel.view
    tools = panel.region_tools
    tools.label_buttons[2].click()
    drag(qtbot, view, [(1.5, 1.5), (2.5, 2.5)])
    assert sorted(tools.fields) == [2]
    field = tools.fields[2]
    top = scene.undo.undo_text()
    qtbot.keyClicks(field, "T=3,Q=1")
    qtbot.mouseClick(tools.apply_button, LEFT)
    message = tools.message.text()
    assert "label 2" in message and "'Q'" in message and "not a block" in message
    assert field.text() == "T=3,Q=1"
    assert scene.doc.nodes[scene.grow].params["region_hints"] == ""
    assert scene.undo.undo_text() == top

    # the typed text survives a stroke that adds a label (the rows are rebuilt)
    tools.label_buttons[4].click()
    drag(qtbot, view, [(6.5, 4.5), (6.5, 5.5)])
    assert sorted(tools.fields) == [2, 4]
    assert tools.fields[2].text() == "T=3,Q=1"
    qtbot.keyClicks(tools.fields[4], "L=2")
    tools.fields[2].clear()
    qtbot.keyClicks(tools.fields[2], "T=3,+=1")
    top = scene.undo.undo_text()
    qtbot.keyClick(tools.fields[2], QtCore.Qt.Key.Key_Return)
    assert scene.doc.nodes[scene.grow].params["region_hints"] == "2: T=3,+=1 | 4: L=2"
    assert scene.undo.undo_text() == f"set {scene.grow}.region_hints"
    assert scene.undo.undo() and scene.undo.undo_text() == top
    assert scene.doc.nodes[scene.grow].params["region_hints"] == ""
    assert tools.fields[2].text() == "" and tools.fields[4].text() == ""   # the document's again
    assert scene.undo.redo()
    assert tools.fields[2].text() == "T=3,+=1" and tools.fields[4].text() == "L=2"

    # a '|' would split the entry: refused, naming the label
    tools.fields[4].clear()
    qtbot.keyClicks(tools.fields[4], "L=2 | 3: T=1")
    tools.apply()
    assert "label 4" in tools.message.text() and "'|'" in tools.message.text()
    assert tools.fields[4].text() == "L=2 | 3: T=1"


def test_painting_regrows_the_node_and_the_replay_follows_the_record(scene, qtbot):
    view = scene.panel.view
    old = np.array(scene.tiling.tiling.tiles)
    scene.panel.region_tools.radius.setValue(0.0)
    drag(qtbot, view, [(2.5, 2.5), (3.5, 2.5)])
    scene.evaluate()   # as the window does after an edit
    tv = scene.tiling
    tiles = np.array(tv.tiling.tiles)
    cleared = dilate(parse_region_map(scene.regions, (NY, NX)) > 0, 1, periodic=tv.tiling.periodic)
    np.testing.assert_array_equal(tiles[~cleared], old[~cleared])   # local regrowth
    panel = scene.panel
    panel.restart()
    if getattr(tv, "start_tiles", None) is not None:
        np.testing.assert_array_equal(panel.shown_tiles, tv.start_tiles)
    np.testing.assert_array_equal(panel.shown_tiles[~cleared], old[~cleared])
    assert np.all(panel.shown_tiles[cleared] == UNASSIGNED)
    while panel.anim_pos < panel.n_steps:
        panel.step(1)
    np.testing.assert_array_equal(panel.shown_tiles, tiles)


def with_history(tiling, tileset, steps, start):
    try:
        return TilingValue(tiling, tileset, steps, start)
    except TypeError:   # TilingValue without the growth record
        tv = TilingValue(tiling, tileset)
        object.__setattr__(tv, "steps", steps)
        object.__setattr__(tv, "start_tiles", start)
        return tv


def test_replay_from_start_tiles_and_steps(qtbot):
    scene = Scene(qtbot)
    ts = load_tileset("TL+-")
    before = grow_tiling(ts, (10, 12), periodic=True, availability=1.0, rng=3)
    region = np.zeros((10, 12), bool)
    region[3:7, 2:9] = True
    after = regrow_region(before, ts, region, margin=1, rng=8, record_steps=True)
    cleared = dilate(region, 1, periodic=True)
    start = np.where(cleared, UNASSIGNED, before.tiles).astype(np.int32)
    tv = with_history(after, ts, after.steps, start)
    panel = scene.panel
    panel.set_context(None, {"grow": {"tiling": tv}}, "grow")
    assert panel.value is tv and panel.paint_block_reason() is not None   # not a Grow node of the doc
    panel.restart()
    np.testing.assert_array_equal(panel.shown_tiles, start)
    assert panel.n_steps == len(after.steps) == int(cleared.sum())
    assert "local regrowth" in panel.anim_label.text()
    counts = [panel.assigned_count()]
    seen_defect = False
    while panel.anim_pos < panel.n_steps:
        cell, tile = after.steps[panel.anim_pos]
        counts.append(panel.step(1))
        if tile == -1:   # a defect forming is marked red at once
            r, c = np.unravel_index(cell, after.shape)
            assert [r, c] in panel.view.defects.tolist()
            seen_defect = True
    assert counts == sorted(counts) and counts[-1] == after.tiles.size
    np.testing.assert_array_equal(panel.shown_tiles, after.tiles)
    assert sorted(map(tuple, panel.view.defects)) == sorted(map(tuple, np.argwhere(after.tiles == -1)))
    if (after.steps[:, 1] == -1).any():
        assert seen_defect


def test_3d_tiling_layers_and_replay(qtbot):
    scene = Scene(qtbot, size=(5, 4, 3), tileset="cubic-beams")
    panel, view, tools = scene.panel, scene.panel.view, scene.panel.region_tools
    tv = scene.tiling
    assert tv.ndim == 3 and panel.layer_row.isVisibleTo(panel)
    # painting is off, and says why
    assert not view.painting and not tools.isEnabled()
    assert "painted regions are for 2D grids" in tools.toolTip()
    assert "2D grids" in view.toolTip()
    before = document_to_dict(scene.doc)
    drag(qtbot, view, [(0.5, 0.5), (2.5, 2.5)])
    assert document_to_dict(scene.doc) == before

    def image_bytes():
        img = view.image
        return bytes(img.constBits())[: img.sizeInBytes()]

    tiles = np.asarray(tv.tiling.tiles)
    pictures = {}
    for z in range(3):
        panel.set_layer("z", z)
        assert view.grid_shape == (4, 5)
        pictures[z] = image_bytes()
        assert sorted(map(tuple, view.defects)) == sorted(map(tuple, np.argwhere(tiles[z] == -1)))
    distinct_layers = len({tiles[z].tobytes() for z in range(3)})
    assert len(set(pictures.values())) == distinct_layers == 3
    panel.set_layer("x", 4)
    assert view.grid_shape == (3, 4) and panel.layer_slider.maximum() == 4
    panel.set_layer("z", 1)
    assert image_bytes() == pictures[1]

    # the replay runs on the shown layer: grey cells at the start, the layer at the end
    panel.restart()
    assert np.all(panel.shown_tiles == UNASSIGNED)
    assert image_bytes() != pictures[1]
    while panel.anim_pos < panel.n_steps:
        panel.step(7)
    np.testing.assert_array_equal(panel.shown_tiles, tiles)
    assert image_bytes() == pictures[1]


def test_without_an_undo_stack_painting_is_off(qtbot):
    scene = Scene(qtbot, undo=False)
    view = scene.panel.view
    assert not view.painting and "undo" in scene.panel.region_tools.toolTip()
    drag(qtbot, view, [(0.5, 0.5), (3.5, 3.5)])
    assert scene.regions == ""
    scene.panel.set_undo(scene.undo)
    assert view.painting
    drag(qtbot, view, [(0.5, 0.5), (3.5, 3.5)])
    assert scene.regions != ""


def test_painting_waits_for_a_resized_grid(scene, qtbot):
    view = scene.panel.view
    scene.undo.push(SetParam(scene.grow, "size", [NX + 2, NY]))
    assert not view.painting and "evaluate" in view.toolTip()
    drag(qtbot, view, [(0.5, 0.5), (2.5, 0.5)])
    assert scene.regions == ""
    scene.evaluate()
    assert view.painting and view.grid_shape == (NY, NX + 2)
    drag(qtbot, view, [(0.5, 0.5), (2.5, 0.5)])
    assert parse_region_map(scene.regions, (NY, NX + 2)).sum() > 0


@pytest.mark.parametrize("typed, words", [("-1", "[0, inf] cells"), ("inf", "a finite number"),
                                          ("big", "a finite number")])
def test_a_typed_bad_brush_radius_is_refused_at_the_field(scene, qtbot, typed, words):
    tools, view = scene.panel.region_tools, scene.panel.view
    kept = tools.radius.value()
    type_into(qtbot, tools.radius, typed)
    text = tools.radius.message.text()
    assert tools.radius.refused and words in text and "radius" in text and "kept" in text
    assert tools.radius.value() == kept and view.brush_radius == kept
    assert "allowed:" in tools.radius.toolTip() and "cells" in tools.radius.toolTip()
    type_into(qtbot, tools.radius, "250.25")                # beyond the old cap of 100, one more decimal
    assert tools.radius.value() == 250.25 and view.brush_radius == 250.25 and not tools.radius.refused
