"""The viewport's solid: its levels of detail prepared off the GUI thread and its tiles.

A mixin of `ui.viewport.Viewport`.  A new solid's levels (`ui.scene_lod.build_levels`:
the full cell with normals, then decimated cells) are made in the viewport's
`TaskRunner`; each growing set is drawn as it arrives, and the solid counts as
shown (`is_ready`) once every level is in.  The levels and their uploaded
meshes (`ui.solid_actors.SolidActors`) are kept for the last `KEPT_SOLIDS`
solids, so re-selecting a solid or switching the tiling prepares and uploads
nothing.
"""

from __future__ import annotations

from engine.geometry.values import Solid

from .scene_lod import build_levels
from .solid_actors import SolidActors
from .view_content import tile_offsets

KEPT_SOLIDS = 3       # solids whose prepared levels (and uploaded meshes) are kept for re-selection


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
        self._prep.submit(lambda task: _prepare_levels(task, solid), data=key)
        return False

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


def _prepare_levels(task, solid: Solid):
    """Worker thread: the levels of detail of `solid`'s cell (`ui.scene_lod.build_levels`),
    each growing set published as it is made; returns the full set."""
    levels = ()
    for levels in build_levels(solid.vertices, solid.faces, check=task.check):
        task.publish(levels)
    return levels
