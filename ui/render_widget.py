"""The viewport's render widget: repaints that would redraw an unchanged scene only show the last frame.

The viewport is a native window VTK draws into (`ui.native_view`); Qt asks
it to paint when it is exposed or resized, and a timer renders five times a
second whatever happens (a net for code that forgets to render).  On the
software renderer a frame is 50-500 ms of GUI thread.  `StampedInteractor`
remembers a stamp of everything a frame depends on (widget size, and the
modification times of every renderer, camera, light and prop) at the end of
each render; a paint whose stamp is unchanged puts the last frame back on
screen (VTK keeps it in its own framebuffer) instead of rendering again, and
the timer renders only a scene that changed without being rendered.
"""

from __future__ import annotations

from .native_view import NativeInteractor


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


class StampedInteractor(NativeInteractor):
    """A `NativeInteractor` whose paints render only when the scene changed.

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

    def frame_is_current(self) -> bool:
        """The last frame shows the scene as it is now (nothing changed since it was rendered)."""
        return self._unchanged()

    def _auto_render(self) -> None:
        if self._unchanged():
            self.timer_skips += 1
            return
        super()._auto_render()

    def paintEvent(self, ev):  # noqa: N802 (Qt's name)
        if self._closed:
            return
        if not self._unchanged():
            self.paint_renders += 1
            super().paintEvent(ev)
            return
        self.paint_skips += 1          # the last frame, from VTK's framebuffer: no render
        self.render_window.MakeCurrent()
        self.render_window.Frame()
