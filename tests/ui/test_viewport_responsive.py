"""The 3D viewport never blocks the GUI thread and frames what it shows.

Counts, never wall time: GUI-thread heartbeats (a 20 ms QTimer) while the
tiled mesh is prepared, actor replacements and full rebuilds on selection
changes, the camera's projection of the cell box, toolpaths after another
example opens.
"""

from __future__ import annotations

import threading

import numpy as np
import pytest
from PySide6 import QtCore

import ui.viewport as viewport_module
from ui.main_window import EXAMPLES_DIR

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")  # NodeGraphQt uses distutils versions

HEARTBEATS_WHILE_PREPARING = 5


class Heartbeat:
    """Ticks of a 20 ms timer on the GUI thread."""

    def __init__(self):
        self.ticks = 0
        self.timer = QtCore.QTimer()
        self.timer.setInterval(20)
        self.timer.timeout.connect(self._tick)
        self.timer.start()

    def _tick(self):
        self.ticks += 1

    def stop(self):
        self.timer.stop()


@pytest.fixture
def octet(make_window, wait_eval):
    """The plain launch: the octet example opened into a shown window, evaluated, its solid drawn."""
    window = make_window(open_example=True)
    report = wait_eval(window, 0, timeout=180000)
    assert report.ok, report.errors
    assert window.viewport.wait_ready()
    return window


def box_corners_on_screen(viewport, lo, hi) -> int:
    """How many of the 8 corners of the box (lo, hi) project inside the render area."""
    ren = viewport.plotter.renderer
    width, height = ren.GetSize()
    inside = 0
    for x in (lo[0], hi[0]):
        for y in (lo[1], hi[1]):
            for z in (lo[2], hi[2]):
                ren.SetWorldPoint(float(x), float(y), float(z), 1.0)
                ren.WorldToDisplay()
                px, py, _ = ren.GetDisplayPoint()
                inside += 0 <= px <= width and 0 <= py <= height
    return inside


def test_selection_changes_replace_no_solid_and_rebuild_nothing(octet, qtbot):
    vp = octet.viewport
    shown = octet.shown_solid_id
    swaps, prepared = vp.scene.replaced["solid"], vp.prepared
    sequence = [shown]                           # the solid node shown after each selection
    selected = [n for n in octet.doc.nodes if n != shown] + [shown]
    for nid in selected:
        octet.editor.select(nid)
        assert vp.wait_ready()
        sequence.append(octet.shown_solid_id)
    changes = sum(a != b for a, b in zip(sequence, sequence[1:]))
    assert vp.scene.full_rebuilds == 0
    assert vp.scene.replaced["solid"] - swaps <= changes     # a swap only where the shown solid changed
    assert vp.prepared - prepared <= len(set(sequence)) - 1  # each other solid prepared once at most
    same_solid = [nid for nid, solid_id in zip(selected, sequence[1:]) if solid_id == shown]
    assert len(same_solid) >= 3                  # skeleton nodes show the solid below them
    before = vp.scene.replaced["solid"]
    for nid in same_solid:                       # back and forth on nodes that show the same solid
        octet.editor.select(nid)
        octet.editor.select(shown)
    assert vp.scene.replaced["solid"] == before and vp.scene.full_rebuilds == 0


def test_tiling_is_prepared_while_the_gui_thread_keeps_ticking(octet, qtbot, monkeypatch):
    vp = octet.viewport
    single = vp.mesh_point_count()
    gate = threading.Event()
    real = viewport_module.tiled_polydata

    def held(*args, **kwargs):                   # the preparation waits until the GUI has ticked
        assert gate.wait(60), "the GUI thread never ticked while the tiled mesh was prepared"
        return real(*args, **kwargs)

    monkeypatch.setattr(viewport_module, "tiled_polydata", held)
    beat = Heartbeat()
    try:
        octet.act_tiling.setChecked(True)        # returns at once: the mesh is prepared elsewhere
        assert not vp.is_ready
        start = beat.ticks
        qtbot.waitUntil(lambda: beat.ticks - start >= HEARTBEATS_WHILE_PREPARING, timeout=30000)
        assert not vp.is_ready                   # still preparing, and the GUI ticked N times
        gate.set()
        assert vp.wait_ready()
    finally:
        gate.set()
        beat.stop()
    assert vp.mesh_point_count() == 27 * single
    assert 0 < vp.shown_mesh_point_count() <= 27 * single
    prepared, swaps = vp.prepared, vp.scene.replaced["solid"]
    for nid in list(octet.doc.nodes)[:4]:        # selections keep the tiled mesh
        octet.editor.select(nid)
        assert vp.wait_ready()
    octet.editor.select(octet.shown_solid_id)
    octet.act_tiling.setChecked(False)           # both tilings of this solid are kept: no new preparation
    octet.act_tiling.setChecked(True)
    assert vp.is_ready and vp.prepared == prepared
    assert vp.scene.full_rebuilds == 0
    assert vp.scene.replaced["solid"] >= swaps


def test_camera_frames_the_whole_cell_on_first_view_and_after_tiling(octet):
    vp = octet.viewport
    box = vp.cell_box()
    assert box_corners_on_screen(vp, np.zeros(3), box) == 8
    octet.act_tiling.setChecked(True)
    assert vp.wait_ready()
    lo, hi = viewport_module.block_bounds(3, box)
    assert box_corners_on_screen(vp, np.broadcast_to(lo, (3,)), np.broadcast_to(hi, (3,))) == 8


def test_toolpaths_go_when_another_example_opens(octet, wait_eval):
    points = np.array([[0, 0, 0.2], [50, 0, 0.2], [50, 50, 0.2]], float)
    segments = np.array([[0, 1], [1, 2]])
    colours = np.array([[255, 0, 0], [0, 0, 255]], np.uint8)
    octet.phasor_panel.preview_lines.emit(points, segments, colours)
    vp = octet.viewport
    assert vp.toolpath_segment_count() == 2
    assert vp.framing.homes >= 2                 # 50 mm of toolpaths around a 1 mm cell: re-framed
    octet.editor.select(next(iter(octet.doc.nodes)))
    assert vp.toolpath_segment_count() == 2      # a selection keeps it
    assert octet.open_example(EXAMPLES_DIR / "bcc.json", ask=False)
    assert vp.toolpath_segment_count() == 0 and "toolpaths" not in vp.plotter.actors
