"""Levels of detail (`ui.scene_lod`) and the tiles sharing them (`ui.solid_actors`), without a window.

The choice of level is checked against the rules written out by hand; the
decimated levels against the full mesh they come from (bounds, closedness
of the surface as measured by its volume, unit normals); the tiles in view
against the camera's frustum computed independently for a camera looking
down the axis.
"""

from __future__ import annotations

import numpy as np
import pytest
import pyvista as pv

from ui.scene_lod import (MOVING_BUDGET, SINGLE_FRAME_BUDGET, STILL_BUDGET, STILL_ERROR_PIXELS,
                          TRIANGLES_PER_PIXEL, build_levels, decimated, level_targets, pick_level, pixels_per_mm,
                          surface_deviation)
from ui.scene_prep import prepare_cell

LEVELS = [123_248, 40_000, 10_500, 3_111, 1_481]       # the octet cell's ladder (build order)


def test_ladder_targets_what_each_view_can_afford():
    assert level_targets(123_248) == LEVELS
    assert level_targets(3_500) == [3_500, 1_481]              # 3 111 is not clearly coarser than 3 500
    assert level_targets(300) == [300]                         # too small to decimate
    assert level_targets(2_000_000) == [2_000_000, 40_000, 10_500, 3_111, 1_481]


def test_a_still_single_cell_draws_the_coarsest_level_no_pixel_can_tell_apart():
    for pixels in (50, 300, 2000):                             # deviations unknown: the full mesh
        assert pick_level(LEVELS, 1, pixels, moving=False) == (0, True)
    errors_mm = [0.0, 0.0004, 0.001, 0.004, 0.01]              # each level's deviation from the full mesh
    for ppm, want in ((100.0, 3), (1000.0, 1), (3000.0, 0), (30.0, 4)):
        i, fits = pick_level(LEVELS, 1, ppm, moving=False, error_pixels=[e * ppm for e in errors_mm])
        assert fits and i == want                              # the coarsest under half a pixel
        assert errors_mm[i] * ppm < STILL_ERROR_PIXELS
        assert all(errors_mm[j] * ppm >= STILL_ERROR_PIXELS for j in range(len(LEVELS)) if LEVELS[j] < LEVELS[i])
    # the deviations do not loosen the tiled or moving rules
    tiled = pick_level(LEVELS, 27, 170, moving=False, error_pixels=[e * 170 for e in errors_mm])
    assert tiled == pick_level(LEVELS, 27, 170, moving=False)


def _brute_deviation(a, b) -> float:
    """Largest distance from a vertex of either mesh to the other's triangles, by projecting each
    vertex on every triangle (plane, edges, corners) with numpy: slow and plain."""
    def point_triangle(p, tri):                     # (n, 3) points, (m, 3, 3) triangles -> (n,) min distance
        best = np.full(len(p), np.inf)
        a0, b0, c0 = tri[:, 0], tri[:, 1], tri[:, 2]
        n = np.cross(b0 - a0, c0 - a0)
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        for k in range(len(p)):
            q = p[k]
            d = np.einsum("ij,ij->i", q - a0, n)
            foot = q - d[:, None] * n
            inside = np.ones(len(tri), bool)        # the foot is inside if on the inner side of every edge
            for u, v in ((a0, b0), (b0, c0), (c0, a0)):
                inside &= np.einsum("ij,ij->i", np.cross(v - u, foot - u), n) >= 0
            cand = [np.where(inside, np.abs(d), np.inf)]
            for u, v in ((a0, b0), (b0, c0), (c0, a0)):
                t = np.clip(np.einsum("ij,ij->i", q - u, v - u) / np.einsum("ij,ij->i", v - u, v - u), 0, 1)
                cand.append(np.linalg.norm(q - (u + t[:, None] * (v - u)), axis=1))
            best[k] = np.min(cand)
        return best.max()
    va, vb = np.asarray(a.vertices, float), np.asarray(b.vertices, float)
    return max(point_triangle(va, vb[b.faces]), point_triangle(vb, va[a.faces]))


def test_the_measured_deviation_of_a_level_is_the_brute_force_one():
    sphere = pv.Sphere(radius=1.0, theta_resolution=24, phi_resolution=24).triangulate()
    full = prepare_cell(np.asarray(sphere.points), np.asarray(sphere.regular_faces))
    coarse = decimated(full, 700)
    for level in (coarse, decimated(coarse, 400, reference=full)):
        assert len(level.faces) < len(full.faces)
        assert level.error == pytest.approx(_brute_deviation(full, level), rel=1e-4, abs=1e-6)
        assert level.error > 0
    squashed = prepare_cell(full.vertices * np.array([1.0, 1.0, 0.9], np.float32), full.faces)
    assert surface_deviation(full, squashed) == pytest.approx(_brute_deviation(full, squashed), rel=1e-4)


def test_a_large_cell_is_first_published_with_its_still_level():
    sphere = pv.Sphere(radius=1.0, theta_resolution=200, phi_resolution=200).triangulate()
    faces = np.asarray(sphere.regular_faces)
    assert len(faces) > SINGLE_FRAME_BUDGET
    first = next(build_levels(np.asarray(sphere.points), faces))
    assert [len(c.faces) for c in first][0] == len(faces) and len(first) == 2
    assert len(first[1].faces) <= 1.1 * MOVING_BUDGET and first[1].error > 0


def test_moving_views_keep_to_the_moving_budget():
    i, fits = pick_level(LEVELS, 1, 500, moving=True)
    assert fits and LEVELS[i] == 40_000 <= MOVING_BUDGET
    i, fits = pick_level(LEVELS, 27, 170, moving=True)
    assert fits and 27 * LEVELS[i] <= MOVING_BUDGET and LEVELS[i] == 1_481


def test_a_still_tiled_view_gets_the_finest_level_the_budget_allows():
    i, fits = pick_level(LEVELS, 27, 170, moving=False)
    assert fits and LEVELS[i] == 3_111 and 27 * LEVELS[i] <= STILL_BUDGET
    i, _ = pick_level(LEVELS, 8, 600, moving=False)             # close: 8 tiles in view get finer tiles
    assert LEVELS[i] == 10_500
    i, _ = pick_level(LEVELS, 27, 10, moving=False)             # far away: enough detail is little
    assert LEVELS[i] == 1_481 >= TRIANGLES_PER_PIXEL * 10 ** 2


def test_a_translucent_solid_keeps_to_the_moving_budget_when_still():
    i, fits = pick_level(LEVELS, 1, 500, moving=False, translucent=True)
    assert fits and LEVELS[i] == 40_000 <= MOVING_BUDGET           # not the full 123,248
    i, fits = pick_level(LEVELS, 27, 170, moving=False, translucent=True)
    assert fits and LEVELS[i] == 1_481 and 27 * LEVELS[i] <= MOVING_BUDGET
    assert pick_level([123_248], 1, 500, moving=False, translucent=True) == (0, False)   # only the full mesh yet


def test_nothing_fits_until_a_coarse_level_exists():
    assert pick_level([123_248], 27, 170, moving=False) == (0, False)
    assert pick_level([123_248, 3_111], 27, 170, moving=False) == (1, True)


def test_pixels_per_mm_of_a_perspective_and_a_parallel_camera():
    # 90 degrees: the half height at distance d is d, so the screen shows 2 d mm
    assert pixels_per_mm(800, 10.0, 90.0) == pytest.approx(800 / 20.0)
    assert pixels_per_mm(800, 10.0, 30.0, parallel=True, parallel_scale=4.0) == pytest.approx(100.0)


def test_decimated_levels_keep_the_shape():
    sphere = pv.Sphere(radius=1.0, theta_resolution=120, phi_resolution=120).triangulate()
    v, f = np.asarray(sphere.points), np.asarray(sphere.regular_faces)
    levels = list(build_levels(v, f))
    assert len(levels[0]) == 1 and [len(x) for x in levels] == list(range(1, len(levels) + 1))
    cells = levels[-1]
    assert len(cells[0].faces) == len(f)
    for cell, target in zip(cells, level_targets(len(f))):
        assert len(cell.faces) <= 1.1 * target
        mesh = pv.PolyData.from_regular_faces(cell.vertices, cell.faces)
        np.testing.assert_allclose(mesh.bounds, sphere.bounds, atol=0.05)
        assert mesh.volume == pytest.approx(4.0 / 3.0 * np.pi, rel=0.05)        # still a closed ball
        np.testing.assert_allclose(np.linalg.norm(cell.normals, axis=1), 1.0, atol=1e-5)


def _unit_box_tiles(plotter, offsets):
    """A 1 mm box cell drawn at `offsets` in `plotter`'s renderer."""
    from ui.solid_actors import SolidActors

    box = pv.Box(bounds=(0, 1, 0, 1, 0, 1)).triangulate()
    view = SolidActors(plotter.renderer, pv.Property(), np.ones(3))
    view.set_levels([prepare_cell(np.asarray(box.points), np.asarray(box.regular_faces))], complete=True)
    view.set_offsets(offsets)
    return view


def test_tiles_in_view_follow_the_frustum():
    from ui.view_content import tile_offsets

    plotter = pv.Plotter(off_screen=True, window_size=(400, 400))
    try:
        view = _unit_box_tiles(plotter, tile_offsets(3, 1.0))
        cam = plotter.camera
        cam.focal_point, cam.position, cam.up = (0.5, 0.5, 0.5), (0.5, 0.5, 20.0), (0, 1, 0)
        plotter.render()
        assert view.copies_in_view() == 27
        # a narrow view (2 degrees) from z = 12 down the middle column: at the lowest tile (z = -1)
        # it is 2 * 13 * tan(1 degree) = 0.45 mm wide, inside the column x, y in [0, 1]
        cam.view_angle = 2.0
        cam.position, cam.focal_point = (0.5, 0.5, 12.0), (0.5, 0.5, 0.0)
        plotter.renderer.ResetCameraClippingRange()
        assert view.copies_in_view() == 3
        cam.position, cam.focal_point = (0.5, 0.5, 12.0), (0.5, 0.5, 24.0)      # looking away
        plotter.renderer.ResetCameraClippingRange()
        assert view.copies_in_view() == 0
    finally:
        plotter.close()


def test_tiles_are_drawn_front_to_back():
    from ui.view_content import tile_offsets

    plotter = pv.Plotter(off_screen=True, window_size=(300, 300))
    try:
        offsets = tile_offsets(3, 1.0)
        view = _unit_box_tiles(plotter, offsets)
        cam = plotter.camera
        for eye in ((0.5, 0.5, 30.0), (0.5, 0.5, -30.0), (25.0, -20.0, 9.0)):
            cam.focal_point, cam.position = (0.5, 0.5, 0.5), eye
            view.choose(moving=False)               # what the viewport runs as every frame starts
            drawn = [view.renderer.GetActors().GetItemAsObject(i) for i in range(len(view.actors))]
            centres = np.array([a.GetPosition() for a in drawn]) + 0.5
            look = np.array([0.5, 0.5, 0.5]) - eye
            depth = (centres - np.asarray(eye)) @ (look / np.linalg.norm(look))
            assert np.all(np.diff(depth) >= -1e-9)  # nearer tiles first
            got = sorted(map(tuple, np.array([a.GetPosition() for a in drawn])))
            assert got == sorted(map(tuple, np.asarray(offsets, float)))      # the same 27 places
        assert view.tile_reorders >= 2
    finally:
        plotter.close()


def test_tiles_follow_the_shared_property_into_translucency():
    from ui.scene_prep import prepare_cell
    from ui.solid_actors import SolidActors

    plotter = pv.Plotter(off_screen=True, window_size=(400, 400))
    try:
        sphere = pv.Sphere(radius=0.5, center=(0.5, 0.5, 0.5), theta_resolution=200, phi_resolution=200)
        cells = list(build_levels(np.asarray(sphere.points), np.asarray(sphere.regular_faces)))[-1]
        prop = pv.Property()
        view = SolidActors(plotter.renderer, prop, np.ones(3))
        view.set_levels(cells, complete=True)
        view.set_offsets(np.zeros((1, 3)))
        finest = min(c.error for c in cells[1:])
        for distance in (1.0, 0.2 * finest * 400 / (2 * np.tan(np.radians(15.0)))):   # framed, then close
            plotter.camera.focal_point = (0.5, 0.5, 0.5)
            plotter.camera.position = (0.5, 0.5, 0.5 + distance)
            plotter.camera.view_angle = 30.0
            plotter.render()
            ppm = 400 / (2 * distance * np.tan(np.radians(15.0)))   # pixels per mm at the focal point
            opaque = min(len(c.faces) for c in cells if c.error * ppm < STILL_ERROR_PIXELS)
            prop.SetOpacity(1.0)
            view.choose(moving=False)
            assert view.drawn_triangles() == opaque
            prop.SetOpacity(0.35)
            view.choose(moving=False)
            assert view.drawn_triangles() == max(len(c.faces) for c in cells
                                                 if len(c.faces) <= min(MOVING_BUDGET, opaque))
            prop.SetOpacity(1.0)
            view.choose(moving=False)
            assert view.drawn_triangles() == opaque
        assert opaque == len(cells[0].faces) > MOVING_BUDGET       # close: the full mesh, unless translucent
    finally:
        plotter.close()


class _Task:
    """Stands in for a TaskRunner task: records publishes; `check` raises once cancelled."""

    def __init__(self):
        self.published = []
        self.cancelled = False

    def publish(self, levels):
        self.published.append(len(levels))

    def check(self):
        if self.cancelled:
            raise RuntimeError("cancelled")


def _sphere_cell():
    mesh = pv.Sphere(theta_resolution=60, phi_resolution=60).triangulate()
    return np.asarray(mesh.points), np.asarray(mesh.regular_faces)


def test_decimated_levels_wait_for_the_full_cells_first_frame():
    import threading

    from ui import viewport_solid

    vertices, faces = _sphere_cell()
    solid = type("SolidArrays", (), {"vertices": vertices, "faces": faces})()   # what the worker reads
    task, shown, out = _Task(), threading.Event(), []
    worker = threading.Thread(target=lambda: out.append(viewport_solid._prepare_levels(task, solid, shown)))
    worker.start()
    try:
        worker.join(0.5)
        assert worker.is_alive() and task.published == [1]     # the full cell only, then waiting
    finally:
        shown.set()                                             # the frame is on screen
    worker.join(120)
    assert not worker.is_alive()
    assert task.published == list(range(1, len(level_targets(len(faces))) + 1))
    assert len(out[0]) == len(task.published)


def test_the_wait_for_a_first_frame_ends_on_cancel_and_on_timeout():
    import threading

    from ui.viewport_solid import _wait_for

    task = _Task()
    assert _wait_for(threading.Event(), task, timeout=0.06, step=0.02) is False   # never drawn: go on
    ready = threading.Event()
    ready.set()
    assert _wait_for(ready, task) is True
    task.cancelled = True
    with pytest.raises(RuntimeError, match="cancelled"):
        _wait_for(threading.Event(), task)
