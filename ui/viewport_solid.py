"""The viewport's solid: its levels of detail prepared off the GUI thread and its tiles.

A mixin of `ui.viewport.Viewport`.  A new solid's levels (`ui.scene_lod.build_levels`:
the full cell with normals, then decimated cells) are made in the viewport's
`TaskRunner` (a large cell's first set holds its full mesh and the level a
still single cell draws); each growing set is drawn as it arrives, and the solid counts as
shown (`is_ready`) once every level is in.  The levels and their uploaded
meshes (`ui.solid_actors.SolidActors`) are kept for the last `KEPT_SOLIDS`
solids, so re-selecting a solid or switching the tiling prepares and uploads
nothing.
"""

from __future__ import annotations

import threading

import numpy as np

from engine.geometry.values import Solid

from .scene_lod import build_levels
from .scene_prep import prepare_cell
from .solid_actors import SolidActors
from .view_content import tile_offsets

KEPT_SOLIDS = 3       # solids whose prepared levels (and uploaded meshes) are kept for re-selection
WARM_OPACITIES = (1.0, 0.35)   # the solid's shader variants: opaque, and faint behind its skeleton
_TET_VERTICES = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
_TET_FACES = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], dtype=np.int64)
FIRST_FRAME_WAIT = 1.0   # s the coarser levels wait for a new solid's first frame (then go on anyway)


class ViewportSolid:
    """Solid methods of `Viewport` (``self`` is the Viewport)."""

    def _sync_solid(self, tiles: int) -> bool:
        solid = self.solid
        if not (self.show_solid and solid is not None and len(solid.faces)):
            self._wanted_solid = None
            self._prep.cancel()
            return self._drop_solid()
        key = (solid, tiles)
        self._wanted_solid = key
        if self.scene.same("solid", key):
            return self._set_solid_opacity()
        view = self._kept(solid)
        if view is not None and view.complete:
            self._prep.cancel()
            self._show_view(key, view)
            return True
        if same_key(key, self._failed):
            return False
        running = self._prep.running
        if running is not None and running.data[0] is solid and self._prep.pending is None:
            if view is not None:
                self._attach(key, view)          # levels so far; the rest arrive
                return True
            return False
        shown = threading.Event()
        self._first_frame = (solid, shown)
        self._prep.submit(lambda task: _prepare_levels(task, solid, shown), data=key)
        return False

    def _warm_up_shaders(self) -> bool:
        """Once, when the viewport is first shown and sized: draw a speck with the solid's
        actor kind and property, opaque and translucent, so that compiling those shaders
        (~60 ms on llvmpipe) is not added to the first solid's frame.  True if it drew."""
        if self._shaders_warm or self._closed:
            return False
        self._shaders_warm = True
        camera = self.plotter.renderer.GetActiveCamera()
        size = 1e-3 * max(camera.GetDistance(), 1e-9)
        speck = SolidActors(self.plotter.renderer, self.solid_prop, np.full(3, size))
        speck.set_levels([prepare_cell(_TET_VERTICES * size, _TET_FACES)], complete=True)
        speck.set_offsets(np.asarray(camera.GetFocalPoint(), dtype=float))   # in view, whatever the camera
        opacity = self.solid_prop.GetOpacity()
        cullers = self.plotter.renderer.GetCullers()
        kept = [cullers.GetItemAsObject(i) for i in range(cullers.GetNumberOfItems())]
        cullers.RemoveAllItems()            # a sub-pixel speck would be culled, its shaders never built
        try:
            for value in WARM_OPACITIES:
                self.solid_prop.SetOpacity(value)
                self.plotter.render()
        finally:
            for culler in kept:
                cullers.AddItem(culler)
            self.solid_prop.SetOpacity(opacity)
            speck.release(self.plotter.render_window)
        return True

    def _after_frame(self, *_args) -> None:
        """Render window EndEvent: a new solid's first frame is on screen, so the
        decimation of its other levels no longer competes with drawing it."""
        first = self._first_frame
        if first is not None and self._view is not None and self._kept(first[0]) is self._view:
            first[1].set()
            self._first_frame = None

    def _kept(self, solid: Solid) -> SolidActors | None:
        return next((v for s, v in self._views if s is solid), None)

    def _drop_solid(self) -> bool:
        if self._view is not None:
            self._view.remove()
            self._view = None
        return self.scene.drop("solid")

    def _set_solid_opacity(self) -> bool:
        translucent = self.show_skeleton and self.skeleton is not None and self.skeleton_emphasis
        opacity = 0.35 if translucent else 1.0
        if self.solid_prop.GetOpacity() == opacity:
            return False
        self.solid_prop.SetOpacity(opacity)
        return True

    def _attach(self, key: tuple, view: SolidActors) -> None:
        """Put `view`'s tiles for `key` (solid, tiles) in the renderer: no upload when it was drawn before."""
        solid, tiles = key
        if self._view is not view:
            if self._view is not None:
                self._view.remove()
            self._view = view
        view.set_offsets(tile_offsets(tiles, solid.box))
        self._set_solid_opacity()

    def _show_view(self, key: tuple, view: SolidActors) -> None:
        """Show a solid whose levels are all in (the scene counts it as a swap)."""
        self._attach(key, view)
        self.scene.put("solid", key, lambda: None)

    def _on_partial(self, task, cells) -> None:
        self._on_levels(task, cells, complete=False)

    def _on_done(self, task, cells) -> None:
        self._on_levels(task, cells, complete=True)

    def _on_levels(self, task, cells, complete: bool) -> None:
        """Levels of a solid arrived: a growing set while they are made, then the whole set."""
        if self._closed:
            return
        solid, _tiles = task.data
        view = self._kept(solid)
        if view is None:
            view = SolidActors(self.plotter.renderer, self.solid_prop, solid.box)
            dropped = self._views[:-KEPT_SOLIDS + 1] if len(self._views) >= KEPT_SOLIDS else []
            for _s, old in dropped:
                if old is self._view:
                    self._drop_solid()
                old.release(self.plotter.render_window)
            self._views = [*self._views[len(dropped):], (solid, view)]
        view.set_levels(cells, complete)
        if complete:
            self.prepared += 1
        wanted = self._wanted_solid
        if wanted is None or wanted[0] is not solid:
            return
        before = (self._view is view, view.drawn_state())
        if complete:
            self._show_view(wanted, view)
        else:
            self._attach(wanted, view)      # drawn now; `is_ready` once every level is in
        if self._frame() or before != (True, view.drawn_state()):
            self.request_render()           # a level that changes nothing on screen is not drawn again
        if complete:
            self.scene_ready.emit()

    def _on_prep_failed(self, task, message: str) -> None:
        self._failed = task.data
        self.caption = f"{self.caption}\nsolid not drawn: {message}".strip()
        self.redraw()


def same_key(a, b) -> bool:
    """Two (solid, tiles) keys name the same thing."""
    return a is not None and b is not None and a[0] is b[0] and a[1] == b[1]


def _prepare_levels(task, solid: Solid, shown: threading.Event | None = None):
    """Worker thread: the levels of detail of `solid`'s cell (`ui.scene_lod.build_levels`),
    each growing set published as it is made; returns the full set.  After the
    first set is published, the coarser levels wait for `shown` (its first
    frame: decimating shares the two cores and the GIL with that frame), at most
    `FIRST_FRAME_WAIT` seconds."""
    levels = ()
    for k, levels in enumerate(build_levels(solid.vertices, solid.faces, check=task.check)):
        task.publish(levels)
        if shown is not None and k == 0:
            _wait_for(shown, task)
    return levels


def _wait_for(event: threading.Event, task, timeout: float = FIRST_FRAME_WAIT, step: float = 0.02) -> bool:
    """Wait until `event` is set (True) or `timeout` s pass (False); `task.check()` between
    steps, so a cancelled task stops waiting."""
    waited = 0.0
    while not event.wait(step):
        task.check()
        waited += step
        if waited >= timeout:
            return False
    return True
