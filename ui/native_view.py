"""A pyvista plotter drawn by VTK straight into a native window inside the Qt window.

pyvistaqt's widget is a ``QOpenGLWidget``: VTK draws into a framebuffer
object and Qt composes it with the rest of the window.  With one such widget
in it, the whole window is composed through OpenGL, so on the software
renderer every repaint of anything (a progress bar, a status message) cost
17-20 ms of GUI thread and every VTK frame about twice its own drawing time
(measured in BENCHMARKS.md, "A native viewport window").  Here the viewport
is a native child window (VTK's own ``QVTKRenderWindowInteractor`` with a
``QWidget`` base): VTK draws into it through GLX, Qt never composes it, and
the rest of the window stays a raster surface.

`NativeInteractor` gives that widget pyvista's `BasePlotter` API (``add_mesh``,
``renderer``, ``screenshot`` ...), as ``pyvistaqt.QtInteractor`` does for
its widget.  It keeps VTK's render window pointed at the widget's window when
Qt re-creates it (``WinIdChange``), and releases the OpenGL context before Qt
destroys the window.
"""

from __future__ import annotations

import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (registers the OpenGL render window before the first one is made)
import pyvista as pv
from pyvista.plotting import BasePlotter
from pyvista.plotting.render_window_interactor import RenderWindowInteractor
from PySide6 import QtCore
from vtkmodules.qt.QVTKRenderWindowInteractor import QVTKRenderWindowInteractor


class _QtInitEnds:
    """Ends the Qt binding's cooperative ``__init__`` chain: `BasePlotter` is initialised explicitly, with arguments."""

    def __init__(self, *args, **kwargs):
        pass


class NativeInteractor(QVTKRenderWindowInteractor, _QtInitEnds, BasePlotter):
    """pyvista's plotting API on a native-window VTK widget.

    ``auto_update`` renders this many times a second from a timer (``_auto_render``),
    a net for code that changes the scene without rendering; 0 turns it off."""

    def __init__(self, parent=None, auto_update: float = 5.0):
        self._closed = True                        # until constructed: `close` has nothing to release
        QVTKRenderWindowInteractor.__init__(self, parent)
        BasePlotter.__init__(self)
        self.interactor = self
        self.ren_win = self.GetRenderWindow()
        for renderer in self.renderers:
            renderer.view_isometric()
            self.ren_win.AddRenderer(renderer)
        self.background_color = pv.global_theme.background
        self.iren = RenderWindowInteractor(self, interactor=self.ren_win.GetInteractor())
        self.iren.interactor.RemoveObservers("MouseMoveEvent")    # the widget forwards Qt's mouse events itself
        self.iren.initialize()
        self.enable_trackball_style()
        self._observers = {}
        self.iren.add_observer("KeyPressEvent", self.key_press_event)
        self.reset_key_events()
        self.render_timer = QtCore.QTimer(self)
        if auto_update > 0:
            self.render_timer.timeout.connect(self._auto_render)
            self.render_timer.start(int(1000.0 / auto_update))
        self._first_time = False                   # BasePlotter renders only once this is False
        self._closed = False

    # -- Qt events ---------------------------------------------------------------------
    def event(self, ev) -> bool:
        if ev.type() == QtCore.QEvent.Type.WinIdChange and getattr(self, "_RenderWindow", None) is not None:
            self._RenderWindow.SetWindowInfo(str(int(self.winId())))   # PySide gives the id as an int
        return super().event(ev)

    def closeEvent(self, ev) -> None:
        self.render_timer.stop()
        if self._RenderWindow is not None:
            super().closeEvent(ev)                 # finalizes the render window

    # -- plotting ----------------------------------------------------------------------
    def _auto_render(self) -> None:
        if not self._closed and self.isVisible():
            self.render()

    def render(self) -> None:
        """Render the scene now (nothing once closed: the OpenGL context is gone)."""
        if not self._closed:
            BasePlotter.render(self)

    def _check_has_ren_win(self) -> None:
        # another OpenGL context (a slice renderer) may be current: pyvista's
        # screenshot checks this window's context is
        if self.render_window is not None:
            self.render_window.MakeCurrent()
        BasePlotter._check_has_ren_win(self)

    def close(self) -> None:
        """Release the renderers and the OpenGL context, then close the widget (safe to call twice)."""
        if self._closed:
            return
        self._closed = True
        self.render_timer.stop()
        BasePlotter.close(self)                    # finalizes the render window
        self.setEnabled(False)                     # no input reaches the interactor from here on
        QVTKRenderWindowInteractor.close(self)
        # VTK's X render window closes the display connection it opened when it
        # is destroyed: let that happen now, not at interpreter exit when the X
        # server may be gone (Xlib then ends the process).
        self._Iren.SetRenderWindow(None)
        self._RenderWindow = None

    def resizeEvent(self, ev) -> None:
        if not self._closed:
            super().resizeEvent(ev)
