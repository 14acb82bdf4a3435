"""The Virtual Growth dock in a real window: tiling image, caption, block
probabilities, growth replay and the 2D stiffness of a Tiling Properties node.

Expected values are computed here from the evaluated tiling (numpy on
``tiling.tiles``), not by the panel's code.
"""

from __future__ import annotations

import numpy as np
import pytest

from engine.graph import AddNode, Connect
from engine.graph.node import node_seed

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")  # NodeGraphQt uses distutils versions

GRID = (6, 6)  # [nx, ny]


def build_growth_graph(undo, with_properties=False, availability=0.0):
    ids = {}
    ids["ts"] = undo.push(AddNode("TileSet", {}, (0, 0))).node_id
    ids["grow"] = undo.push(AddNode("Grow", {"size": list(GRID), "availability": availability},
                                    (240, 0))).node_id
    undo.push(Connect(ids["ts"], "tileset", ids["grow"], "tileset"))
    if with_properties:
        ids["props"] = undo.push(AddNode("TilingProperties", {"resolution": 10}, (480, 0))).node_id
        undo.push(Connect(ids["grow"], "tiling", ids["props"], "tiling"))
    return ids


def evaluated(window, wait_eval, with_properties=False, timeout=120000, availability=0.0):
    before = window.eval_count
    ids = build_growth_graph(window.undo, with_properties, availability)
    report = wait_eval(window, before, timeout)
    assert not report.errors, report.errors
    return ids, report


def test_panel_shows_the_selected_tiling(window, wait_eval):
    ids, report = evaluated(window, wait_eval)
    window.editor.select(ids["grow"])
    panel = window.growth_panel
    tv = report.outputs[ids["grow"]]["tiling"]
    tiles = np.asarray(tv.tiling.tiles)
    assert tiles.shape == GRID[::-1]
    assert panel.node_id == ids["grow"] and panel.value is tv

    # the image is 6 x 6 blocks of ppb pixels each
    ppb = panel.ppb
    assert panel.image_shape == (GRID[1] * ppb, GRID[0] * ppb)
    assert (panel.view.image.width(), panel.view.image.height()) == (GRID[0] * ppb, GRID[1] * ppb)
    assert panel.view.grid_shape == tiles.shape

    # caption: size, periodicity, defects and the node seed
    n_defects = int(np.count_nonzero(tiles == -1))
    text = panel.caption.text()
    assert "6 × 6" in text and "periodic: yes" in text
    assert f"defects: {n_defects}" in text
    assert f"seed: {node_seed(window.doc.seed, ids['grow'])}" in text
    assert len(panel.view.defects) == n_defects

    # pie data = block counts of the placed tiles
    ts = tv.tileset
    placed = tiles[tiles >= 0]
    counts = np.zeros(ts.n_blocks)
    for t in placed:
        counts[ts.tile_block[t]] += 1
    expected = counts / max(1, placed.size)
    assert panel.pie.names == list(ts.block_names)
    np.testing.assert_allclose(panel.pie.values, expected, rtol=0, atol=1e-12)
    assert panel.pie.requested is not None and abs(panel.pie.requested.sum() - 1) < 1e-12
    assert len(panel.pie.legend_lines()) == ts.n_blocks

    # without a Tiling Properties node there is no stiffness
    assert not panel.stiffness_box.isVisibleTo(panel)


def test_growth_replay_ends_in_the_evaluated_tiling(window, wait_eval, qtbot):
    ids, report = evaluated(window, wait_eval)
    window.editor.select(ids["grow"])
    panel = window.growth_panel
    tiles = np.asarray(report.outputs[ids["grow"]]["tiling"].tiling.tiles)
    n_cells = tiles.size

    # drive the timer by hand: 1 step per tick at 50 steps/s and 20 ms ticks
    panel.speed.setValue(50)
    qtbot.mouseClick(panel.play_button, qtbot_button())
    assert panel.playing and panel.play_button.text() == "Pause"
    panel.timer.stop()
    assert panel.assigned_count() == 0
    assert np.all(panel.shown_tiles == -2)  # every cell unassigned (grey) at the start
    shown = [0]
    for _ in range(10 * n_cells):
        if panel.anim_pos >= panel.n_steps:
            break
        panel._tick()
        shown.append(panel.assigned_count())
    assert all(b >= a for a, b in zip(shown, shown[1:])), shown
    assert shown[1] < n_cells and len(set(shown)) > 2
    assert shown[-1] == n_cells
    np.testing.assert_array_equal(panel.shown_tiles, tiles)
    assert not panel.playing and panel.play_button.text() == "Play"

    # the real timer at full speed replays it again from the start
    panel.speed.setValue(2000)
    panel.play()
    assert panel.anim_pos < panel.n_steps
    qtbot.waitUntil(lambda: not panel.playing, timeout=10000)
    np.testing.assert_array_equal(panel.shown_tiles, tiles)

    # pausing part-way keeps the partial grid
    panel.speed.setValue(1)
    panel.restart()
    counts = [panel.step(3), panel.step(3)]
    assert counts[0] <= counts[1] < n_cells
    panel.pause()
    assert not panel.playing


def test_stiffness_of_a_downstream_tiling_properties(window, wait_eval):
    from engine.physics.material_sphere import material_polar

    ids, report = evaluated(window, wait_eval, with_properties=True, timeout=600000)
    window.editor.select(ids["grow"])
    panel = window.growth_panel
    st = report.outputs[ids["props"]]["stiffness"]
    assert np.shape(st.C) == (3, 3)
    assert panel.stiffness is st and panel.stiffness_box.isVisibleTo(panel)
    text = panel.stiffness_label.text()
    assert f"{st.constants['E_avg'] / st.E:.4g}" in text
    assert f"{st.constants['nu_avg']:.4g}" in text
    theta, e = material_polar(st.C, n=180)
    np.testing.assert_allclose(panel.polar.values, e)

    # selecting the Tiling Properties node shows the tiling feeding it
    window.editor.select(ids["props"])
    assert panel.node_id == ids["grow"]


def test_defects_are_marked_and_replayed(window, wait_eval):
    """A finite supply of blocks (availability 1) leaves defects: they are counted in the
    caption, marked red at their cells, and the replay forms them where growth did."""
    ids, report = evaluated(window, wait_eval, availability=1.0)
    window.editor.select(ids["grow"])
    panel = window.growth_panel
    tiles = np.asarray(report.outputs[ids["grow"]]["tiling"].tiling.tiles)
    defect_cells = np.argwhere(tiles == -1)
    assert len(defect_cells) > 0, "availability 1 should leave defects on this grid"
    assert f"defects: {len(defect_cells)}" in panel.caption.text()
    assert sorted(map(tuple, panel.view.defects)) == sorted(map(tuple, defect_cells))
    panel.restart()
    previous = 0
    while panel.anim_pos < panel.n_steps:
        count = panel.step(5)
        assert count >= previous
        previous = count
    assert previous == tiles.size
    np.testing.assert_array_equal(panel.shown_tiles, tiles)
    assert sorted(map(tuple, panel.view.defects)) == sorted(map(tuple, defect_cells))


def qtbot_button():
    from PySide6 import QtCore
    return QtCore.Qt.MouseButton.LeftButton


def test_painting_in_the_window_regrows_locally_and_replays(window, wait_eval, qtbot):
    """A stroke on the dock's tiling is one undo step; the evaluation it triggers regrows
    only the painted cells and their margin, and the replay starts from the kept tiling."""
    from engine.growth.regions import parse_region_map
    from engine.growth.regrow import dilate

    ids, report = evaluated(window, wait_eval)
    window.editor.select(ids["grow"])
    panel = window.growth_panel
    if panel.undo is None:   # until the window hands the dock its undo stack
        panel.set_undo(window.undo)
    assert panel.view.painting
    old = np.array(report.outputs[ids["grow"]]["tiling"].tiling.tiles)
    panel.region_tools.label_buttons[3].click()
    panel.region_tools.radius.setValue(0.0)
    view = panel.view
    n = window.eval_count
    points = [view.widget_point(x, 1.5).toPoint() for x in (1.5, 2.5, 3.5)]
    qtbot.mousePress(view, qtbot_button(), pos=points[0])
    for p in points[1:]:
        qtbot.mouseMove(view, p)
    qtbot.mouseRelease(view, qtbot_button(), pos=points[-1])
    params = window.doc.nodes[ids["grow"]].params
    labels = parse_region_map(params["regions"], old.shape)
    expected = np.zeros(old.shape, int)
    expected[1, 1:4] = 3
    np.testing.assert_array_equal(labels, expected)
    assert window.undo.undo_text() == f"set {ids['grow']}.regions"

    report = wait_eval(window, n)
    assert not report.errors, report.errors
    tv = report.outputs[ids["grow"]]["tiling"]
    tiles = np.asarray(tv.tiling.tiles)
    kept = ~dilate(labels > 0, 1, periodic=True)
    np.testing.assert_array_equal(tiles[kept], old[kept])
    assert panel.value is tv
    panel.restart()
    np.testing.assert_array_equal(panel.shown_tiles[kept], old[kept])
    assert panel.assigned_count() == int(kept.sum())
    assert "local regrowth" in panel.anim_label.text()
    while panel.anim_pos < panel.n_steps:
        panel.step(2)
    np.testing.assert_array_equal(panel.shown_tiles, tiles)

    n = window.eval_count
    assert window.undo.undo()
    assert window.doc.nodes[ids["grow"]].params["regions"] == ""
    assert view.labels is None
    wait_eval(window, n)
