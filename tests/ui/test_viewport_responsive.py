"""The 3D viewport never blocks the GUI thread and frames what it shows.

Counts, never wall time: GUI-thread heartbeats (a 20 ms QTimer) while the
levels of detail are prepared and while the tiling is toggled, actor
replacements, preparations and uploads (mappers) on selection and tiling
changes, triangles drawn while the camera moves and when it stops, the
camera's projection of the cell box, toolpaths after another example opens.
"""

from __future__ import annotations

import contextlib
import threading

import numpy as np
import pytest

import ui.scene_lod as scene_lod
import ui.viewport as viewport_module
import ui.viewport_solid as viewport_solid
from ui.main_window import EXAMPLES_DIR

from heartbeat import Heartbeat

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")  # NodeGraphQt uses distutils versions

HEARTBEATS_WHILE_PREPARING = 5


@contextlib.contextmanager
def frames_drawn(widget):
    """A list that gets one entry per frame the widget's render window draws inside the block."""
    frames = []
    tag = widget.render_window.AddObserver("EndEvent", lambda *_: frames.append(1))
    try:
        yield frames
    finally:
        widget.render_window.RemoveObserver(tag)


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


def test_levels_are_prepared_while_the_gui_thread_keeps_ticking(make_window, wait_eval, qtbot, monkeypatch):
    gate = threading.Event()
    real = viewport_solid.build_levels

    def held(*args, **kwargs):                   # the full cell comes at once, the coarser levels wait
        for k, levels in enumerate(real(*args, **kwargs)):
            if k == 1:
                assert gate.wait(60), "the GUI thread never ticked while the levels were made"
            yield levels

    monkeypatch.setattr(viewport_solid, "build_levels", held)
    window = make_window(open_example=True)
    beat = Heartbeat()
    try:
        assert wait_eval(window, 0, timeout=180000).ok
        vp = window.viewport
        qtbot.waitUntil(lambda: vp.shown_mesh_point_count() > 0, timeout=60000)   # the first set, drawn
        single = vp.shown_mesh_point_count()
        assert not vp.is_ready
        window.act_tiling.setChecked(True)       # returns at once; no level fits 27 copies yet
        view = vp.solid_view()
        assert view.partial and vp.shown_mesh_point_count() == single   # the middle tile only
        start = beat.ticks
        qtbot.waitUntil(lambda: beat.ticks - start >= HEARTBEATS_WHILE_PREPARING, timeout=30000)
        assert not vp.is_ready                   # still preparing, and the GUI ticked N times
        gate.set()
        assert vp.wait_ready()
    finally:
        gate.set()
        beat.stop()
    vp.plotter.render()
    full = len(vp.solid.vertices)
    assert vp.mesh_point_count() == 27 * full
    assert not view.partial and view.in_view == 27
    assert 27 * single > vp.shown_mesh_point_count() > 0            # every tile, at a coarser level
    assert view.drawn_triangles() <= scene_lod.STILL_BUDGET


def test_tiling_and_selections_reuse_the_uploaded_levels(octet, qtbot):
    vp = octet.viewport
    view = vp.solid_view()
    mappers = list(view.mappers)
    prepared = vp.prepared
    beat = Heartbeat()
    try:
        for _ in range(3):                       # toggling adds / removes tiles: nothing prepared or uploaded
            for on in (True, False):
                octet.act_tiling.setChecked(on)
                assert vp.wait_ready() and vp.prepared == prepared
                start = beat.ticks
                qtbot.waitUntil(lambda: beat.ticks - start >= 2, timeout=30000)   # the GUI thread ticks between
                assert len(view.actors) == (27 if on else 1)
                assert view.drawn_triangles() <= max(scene_lod.STILL_BUDGET, len(vp.solid.faces))
        octet.act_tiling.setChecked(True)
        for nid in list(octet.doc.nodes)[:4]:    # selections keep the tiles
            octet.editor.select(nid)
            assert vp.wait_ready()
    finally:
        beat.stop()
    octet.editor.select(octet.shown_solid_id)
    assert vp.wait_ready() and vp.solid_view() is view
    assert vp.prepared == prepared and view.mappers == mappers
    assert all(a.GetMapper() is view.mappers[view.level] for a in view.actors)
    assert vp.scene.full_rebuilds == 0


def drag(vp, moves=4):
    """A left-button drag on the render window through the VTK interactor (what a mouse drag does);
    returns whether the frames during the drag were drawn as moving."""
    iren = vp.plotter.iren.interactor
    w, h = vp.plotter.render_window.GetSize()
    seen = []
    iren.SetEventInformation(w // 2, h // 2, 0, 0)
    iren.InvokeEvent("LeftButtonPressEvent")
    for k in range(1, moves + 1):
        iren.SetEventInformation(w // 2 + 15 * k, h // 2 + 5 * k, 0, 0)
        iren.InvokeEvent("MouseMoveEvent")
        seen.append(vp.solid_view().last_moving)
    iren.InvokeEvent("LeftButtonReleaseEvent")
    return seen


def screen_pixels_per_mm(vp) -> float:
    """Pixels a 1 mm step across the view spans at the focal point (projected by the renderer)."""
    ren = vp.plotter.renderer
    cam = ren.GetActiveCamera()
    focal, up = np.array(cam.GetFocalPoint()), np.array(cam.GetViewUp())

    def display(p):
        ren.SetWorldPoint(*(float(v) for v in p), 1.0)
        ren.WorldToDisplay()
        return np.array(ren.GetDisplayPoint()[:2])
    return float(np.linalg.norm(display(focal + up / np.linalg.norm(up)) - display(focal)))


def still_single_triangles(vp, view) -> int:
    """Triangles a still single cell should draw: the coarsest level whose measured deviation
    from the full mesh is under `STILL_ERROR_PIXELS` on screen."""
    ppm = screen_pixels_per_mm(vp)
    return min(m.n_cells for m, e in zip(view.meshes, view.errors) if e * ppm < scene_lod.STILL_ERROR_PIXELS)


def test_level_of_detail_is_coarse_while_the_camera_moves_and_sub_pixel_when_still(octet):
    vp = octet.viewport
    view = vp.solid_view()
    full = len(vp.solid.faces)
    vp.plotter.render()
    single = still_single_triangles(vp, view)
    assert single < full and full > scene_lod.SINGLE_FRAME_BUDGET      # framed whole: a decimated level
    assert view.drawn_triangles() == single and not view.last_moving
    assert all(drag(vp))                                                 # while dragging: the coarse level
    assert view.last_moving is False                                     # the release renders it still again
    assert view.drawn_triangles() == still_single_triangles(vp, view)
    frames = []
    tag = vp.plotter.render_window.AddObserver("EndEvent", lambda *_: frames.append(view.last_moving))
    vp.plotter.iren.interactor.InvokeEvent("MouseWheelForwardEvent")    # a wheel notch: coarse, then still
    vp.plotter.render_window.RemoveObserver(tag)
    assert frames and frames[-1] is False and view.drawn_triangles() == still_single_triangles(vp, view)
    finest_error = min(e for e in view.errors if e > 0)
    vp.plotter.camera.zoom(1.5 / (finest_error * screen_pixels_per_mm(vp)))   # close: every level would show
    vp.plotter.render()
    assert view.drawn_triangles() == full                                # full geometry
    assert vp.shown_mesh_point_count() == len(vp.solid.vertices)
    vp.reset_camera()
    octet.act_tiling.setChecked(True)
    assert vp.wait_ready()
    vp.plotter.render()
    still = view.drawn_triangles()
    assert view.in_view == 27 and still <= scene_lod.STILL_BUDGET
    moving = drag(vp)
    assert all(moving)
    vp.plotter.render_window.SetDesiredUpdateRate(vp.plotter.iren.interactor.GetDesiredUpdateRate())
    vp.plotter.render()
    assert view.drawn_triangles() <= scene_lod.MOVING_BUDGET < still
    vp.plotter.render_window.SetDesiredUpdateRate(vp.plotter.iren.interactor.GetStillUpdateRate())
    vp.plotter.render()
    assert view.drawn_triangles() == still
    cam = vp.plotter.camera                       # close to the middle tile: few tiles in view, finer tiles
    cam.focal_point = tuple(0.5 * vp.cell_box())
    cam.position = tuple(0.5 * vp.cell_box() + np.array([0.0, -0.6, 0.0]) * float(vp.cell_box().max()))
    vp.plotter.render()
    assert view.in_view < 27
    assert view.drawn_triangles() / view.in_view > still / 27
    octet.act_tiling.setChecked(False)
    assert vp.wait_ready()
    vp.reset_camera()
    assert view.drawn_triangles() == still_single_triangles(vp, view)


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


def test_an_unchanged_scene_is_not_rendered_again(octet, qtbot):
    vp = octet.viewport
    widget = vp.plotter
    with frames_drawn(widget) as frames:
        skips = widget.timer_skips
        qtbot.waitUntil(lambda: widget.timer_skips >= skips + 2, timeout=30000)   # the 5/s auto-update ticked
        for k in range(5):                      # repaints of the window (status text): the last frame is shown
            octet.statusBar().showMessage(f"message {k}")
            widget.repaint()
        assert frames == [] and widget.paint_skips > 0
        widget.camera.azimuth += 30.0           # a change nobody rendered: the auto-update draws it
        qtbot.waitUntil(lambda: len(frames) >= 1, timeout=30000)
        vp.plotter.render()                     # an explicit render is done once, not again by a repaint
        count = len(frames)
        skips = widget.paint_skips
        widget.repaint()
        assert widget.paint_skips == skips + 1 and len(frames) == count


def test_the_rest_of_the_window_repaints_without_the_viewport(octet, qtbot):
    """The viewport is a native window VTK draws into: the main window stays a raster
    surface (nothing composed through OpenGL), and repainting other widgets neither
    paints nor renders the viewport."""
    from PySide6 import QtGui
    assert octet.windowHandle().surfaceType() == QtGui.QSurface.SurfaceType.RasterSurface
    widget = octet.viewport.plotter
    assert widget.windowHandle() is not None and widget.internalWinId()   # a native child window
    qtbot.wait(300)
    with frames_drawn(widget) as frames:
        paints = widget.paint_renders + widget.paint_skips
        for k in range(5):
            octet.statusBar().showMessage(f"message {k}")
            octet.statusBar().repaint()
            qtbot.wait(20)
        assert widget.paint_renders + widget.paint_skips == paints and frames == []


def test_the_solid_shaders_are_built_once_before_the_first_solid(octet):
    """The warm-up speck drew once the viewport was sized and left nothing behind:
    no actor, the renderer's cullers back, the solid's opacity back."""
    vp = octet.viewport
    assert vp._shaders_warm
    ren = vp.plotter.renderer
    assert ren.GetCullers().GetNumberOfItems() == 1
    view = vp.solid_view()
    tiles = set(map(id, view.actors))
    solid_like = [a for a in ren.GetActors() if a.GetProperty() is vp.solid_prop and id(a) not in tiles]
    assert solid_like == [] and vp.solid_prop.GetOpacity() == 1.0
    assert vp._warm_up_shaders() is False              # once per viewport


def test_a_requested_frame_already_drawn_by_the_auto_update_is_not_drawn_again(octet, qtbot):
    vp = octet.viewport
    widget = vp.plotter
    with frames_drawn(widget) as frames:
        widget.camera.azimuth += 10.0
        vp.request_render()                 # queued for after the events being handled
        widget._auto_render()               # the 5/s timer got there first: it draws the change
        assert len(frames) == 1
        qtbot.waitUntil(lambda: not vp._render_pending, timeout=10000)
        assert len(frames) == 1             # the queued request found the frame current
        widget.camera.azimuth += 10.0
        vp.request_render()
        qtbot.waitUntil(lambda: len(frames) == 2, timeout=10000)   # a change nobody drew: drawn once
