"""The viewport's Qt render widget: repaints that would redraw an unchanged scene only show the last frame.

pyvistaqt's widget renders the VTK scene in every ``paintGL``, it asks Qt
for a repaint after every VTK render (to show the frame), and a timer renders
the scene five times a second whatever happens.  So each render was done
twice, any repaint of the window (a progress bar moving, a status message)
redrew the whole scene, and an idle view kept rendering: on the software
renderer that is 50-500 ms of GUI thread each time.  `StampedInteractor` remembers a stamp
of everything a frame depends on (widget size, and the modification times of
every renderer, camera, light and prop) at the end of each render; a
``paintGL`` whose stamp is unchanged shows the frame already rendered
(the widget's own in-paint guard skips the render) instead of rendering again,
and the timer renders only a scene that changed without being rendered (a
safety net for code that forgets to render).
"""

from __future__ import annotations

from pyvistaqt import QtInteractor


def scene_stamp(render_window, size: tuple) -> tuple:
    """What a frame depends on: the widget size and the largest modification time
    of each renderer, its camera, lights and props (a prop's redraw time covers its
    mapper and input)."""
    parts = [size, render_window.GetMTime()]
    renderers = render_window.GetRenderers()
    renderers.InitTraversal()
    for _ in range(renderers.GetNumberOfItems()):
        ren = renderers.GetNextItem()
        props = ren.GetViewProps()
        props.InitTraversal()
        newest = 0
        count = props.GetNumberOfItems()
        for _ in range(count):
            newest = max(newest, props.GetNextProp().GetRedrawMTime())
        lights = ren.GetLights()
        lights.InitTraversal()
        for _ in range(lights.GetNumberOfItems()):
            newest = max(newest, lights.GetNextItem().GetMTime())
        parts.append((ren.GetMTime(), ren.GetActiveCamera().GetMTime(), count, newest))
    return tuple(parts)


class StampedInteractor(QtInteractor):
    """A `pyvistaqt.QtInteractor` whose repaints render only when the scene changed.

    Counters (tests): ``paint_renders`` (paints that rendered), ``paint_skips``,
    ``timer_skips`` (auto-update ticks that found nothing new)."""

    def __init__(self, *args, **kwargs):
        self._frame_stamp = None
        self.paint_renders = 0
        self.paint_skips = 0
        self.timer_skips = 0
        super().__init__(*args, **kwargs)
        self.render_window.AddObserver("EndEvent", self._on_frame_end)

    def _size(self) -> tuple:
        return (self.width(), self.height(), self.devicePixelRatioF())

    def _on_frame_end(self, *_args) -> None:
        self._frame_stamp = scene_stamp(self.render_window, self._size())

    def _unchanged(self) -> bool:
        rw = getattr(self, "render_window", None)
        return rw is not None and self._frame_stamp is not None and \
            scene_stamp(rw, self._size()) == self._frame_stamp

    def _auto_render(self) -> None:
        if self._unchanged():
            self.timer_skips += 1
            return
        super()._auto_render()

    def paintGL(self):  # noqa: N802 (Qt's name)
        if not (hasattr(self, "_in_paint") and not self._in_paint and self._unchanged()):
            self.paint_renders += 1
            super().paintGL()
            return
        self.paint_skips += 1
        self._in_paint = True          # the widget's guard: blit the last frame, do not render
        try:
            super().paintGL()
        finally:
            self._in_paint = False
