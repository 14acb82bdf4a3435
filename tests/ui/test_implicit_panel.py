"""The Implicit Media dock in a real window: the traced view follows the selected SDF node,
orbits by drag, edits re-trace, path tracing lands frame by frame, the histogram counts the
cloud's own particles and the volume fraction is the view box's."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6 import QtCore

from engine.graph import AddNode, Connect, SetParam
from engine.implicit.particles import Suspension
from engine.implicit.volume_fraction import volume_fraction


def _add(window, wait_eval, *nodes, edges=()):
    after = window.eval_count
    ids = [window.undo.push(AddNode(t, p, (200 * k, 0))).node_id for k, (t, p) in enumerate(nodes)]
    for a, port_a, b, port_b in edges:
        window.undo.push(Connect(ids[a], port_a, ids[b], port_b))
    window.evaluate_now()
    assert wait_eval(window, after).ok
    return ids


def _traced(qtbot, panel, before):
    qtbot.waitUntil(lambda: panel.view.frames_shown > before and not panel.traces.is_busy, timeout=60000)


def test_the_selected_sdf_node_is_traced_with_its_readout(window, qtbot, wait_eval):
    (gid,) = _add(window, wait_eval, ("PeriodicFunction", {"kind": "schwarz_p", "cell": 0.5}))
    panel = window.implicit_panel
    window.implicit_dock.show()
    window.implicit_dock.raise_()
    window.editor.select(gid)
    assert panel.node_id == gid
    _traced(qtbot, panel, 0)
    assert "steps/ray" in panel.readout.text() and panel.last_trace["mean_steps"] >= 1
    assert 0.1 < panel.last_trace["hit"] < 1.0                 # the unit view box in the middle of the frame
    qtbot.waitUntil(lambda: bool(panel.measured), timeout=60000)
    want = volume_fraction(panel.sdf, ((0, 0, 0), (1, 1, 1)), 48)
    assert panel.measured["fraction"] == pytest.approx(want, abs=1e-12)
    assert panel.measured["sizes"] is None                      # a periodic function has no particles


def test_a_drag_orbits_and_an_edit_traces_the_new_sdf(window, qtbot, wait_eval):
    (gid,) = _add(window, wait_eval, ("PeriodicFunction", {"kind": "gyroid", "cell": 0.5}))
    panel = window.implicit_panel
    window.implicit_dock.raise_()
    window.editor.select(gid)
    _traced(qtbot, panel, 0)
    first = panel.view.frames_shown
    az = panel.view.azimuth
    view = panel.view
    qtbot.mousePress(view, QtCore.Qt.MouseButton.LeftButton, pos=QtCore.QPoint(50, 50))
    qtbot.mouseMove(view, QtCore.QPoint(90, 60))
    qtbot.mouseRelease(view, QtCore.Qt.MouseButton.LeftButton, pos=QtCore.QPoint(90, 60))
    _traced(qtbot, panel, first)
    assert panel.view.azimuth != az
    old = panel.sdf
    after = window.eval_count
    window.undo.push(SetParam(gid, "cell", 0.25))
    wait_eval(window, after)
    qtbot.waitUntil(lambda: panel.sdf is not old and panel.sdf is not None, timeout=60000)
    assert panel.sdf.cell[0] == pytest.approx(0.25)
    assert panel.param_form.editors["cell"] is not None


def test_particles_histogram_counts_the_clouds_own_particles_and_paths_land(window, qtbot, wait_eval):
    (pid,) = _add(window, wait_eval, ("Particles", {"cell": 0.2, "size_a": 0.03, "size_b": 0.09, "seed": 4}))
    panel = window.implicit_panel
    window.implicit_dock.raise_()
    window.editor.select(pid)
    qtbot.waitUntil(lambda: bool(panel.measured), timeout=60000)
    cloud = panel.sdf
    assert isinstance(cloud, Suspension)
    want = cloud.particles_in_box(np.zeros(3), np.ones(3)).sizes
    assert np.array_equal(np.sort(panel.measured["sizes"]), np.sort(want))
    assert np.array_equal(panel.histogram.sizes, panel.measured["sizes"])
    _traced(qtbot, panel, 0)
    shown = panel.view.frames_shown
    panel.paths_box.setValue(3)
    panel.depth_box.setValue(3)
    panel.start_path_trace()
    qtbot.waitUntil(lambda: not panel.traces.is_busy and "path traced: 3 frames" in panel.readout.text(),
                    timeout=120000)
    assert panel.view.frames_shown >= shown + 1


def test_a_graph_without_sdf_nodes_says_how_to_add_one(window):
    panel = window.implicit_panel
    assert panel.node_id is None and "Particles" in panel.title.text()


def test_a_fit_to_a_grid_exemplar_is_applied_as_one_undo_step(window, qtbot, wait_eval, tmp_path):
    import json

    from engine.implicit.periodic import Periodic
    from engine.implicit.voxelize import grid_nodes, sample_nodes

    truth = Periodic("gyroid", cell=0.31, level=0.0)
    origin, spacing, counts = grid_nodes((0, 0, 0), (1, 1, 1), 24, periodic=True)
    np.save(tmp_path / "ex.npy", sample_nodes(truth, origin, spacing, counts).astype(np.float64))
    (tmp_path / "ex.json").write_text(json.dumps({"spacing": list(spacing), "origin": [0, 0, 0]}))
    (gid,) = _add(window, wait_eval, ("PeriodicFunction", {"kind": "gyroid", "cell": 0.4, "level_by": "level",
                                                           "level": 0.0}))
    panel = window.implicit_panel
    window.editor.select(gid)
    box = panel.fit_box
    box.path_edit.setText(str(tmp_path / "ex.npy"))
    box.bounds_edit.setText("cell=0.2:0.6")
    box.algorithm_box.setCurrentIndex(box.algorithm_box.findData("powell"))
    box.budget_box.setValue(20.0)
    box.loss_box.setCurrentIndex(box.loss_box.findData("mse"))
    assert box.start()
    qtbot.waitUntil(lambda: box.result is not None and not box.runner.is_busy, timeout=60000)
    assert box.result.params[0] == pytest.approx(0.31, rel=0.01)
    assert window.doc.nodes[gid].params["cell"] == 0.4              # nothing changed until Apply
    assert box.apply()
    assert window.doc.nodes[gid].params["cell"] == pytest.approx(box.result.params[0])
    window.undo.undo()
    assert window.doc.nodes[gid].params["cell"] == 0.4


def test_a_bad_exemplar_is_refused_at_the_box(window, wait_eval, tmp_path):
    (gid,) = _add(window, wait_eval, ("PeriodicFunction", {}))
    panel = window.implicit_panel
    window.editor.select(gid)
    np.save(tmp_path / "flat.npy", np.zeros((8, 8)))
    panel.fit_box.path_edit.setText(str(tmp_path / "flat.npy"))
    assert not panel.fit_box.start()
    assert "flat.npy" in panel.fit_box.status.text()
