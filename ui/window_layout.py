"""Where the main window's docks go by default, and keeping the user's layout.

The default, for a 1366 x 768 laptop up to a large screen: the node graph on
the left, the viewport in the centre, and on the right, over the window's
whole height, the inspector with the method docks tabbed behind it (tabs on
the right edge, so every title is written out in full however narrow the
column is); the log below the node graph and the viewport, a few lines high.

The layout (`QMainWindow.saveGeometry` / `saveState`) is written to a
QSettings on close and read back at start.  The settings are injected (a
`QSettings` or the path of an ini file; None keeps nothing), so tests never
write into the user's home.  A layout saved by a build with another set of
docks, or one Qt refuses, gives the default layout; View › Reset Layout
returns to the default at any time.
"""

from __future__ import annotations

from pathlib import Path

from PySide6 import QtCore, QtGui, QtWidgets

__all__ = ["WindowLayout", "open_settings", "dock_arrangement", "LAYOUT_VERSION"]

LAYOUT_VERSION = 1
"""Bumped whenever a saved state of this window must no longer be restored."""

KEY_GEOMETRY = "window/geometry"
KEY_STATE = "window/state"
KEY_DOCKS = "window/docks"

LEFT_DOCKS = ("editor_dock",)
RIGHT_TABS = ("inspector_dock", "surface_dock", "growth_dock", "tileset_dock", "study_dock",
              "phasor_dock", "rd_dock", "implicit_dock")
"""Tabbed on the right, in this order: the inspector, then the method docks in the order of
the methods (unit cell, virtual growth, phasor infill, reaction diffusion, implicit media)."""
BOTTOM_DOCKS = ("log_dock",)

EDITOR_SHARE = 0.26          # of the window's width, for the node graph
RIGHT_SHARE = (0.34, 0.39)   # the right column: wide enough for its widest content, within these
LOG_SHARE = 0.12             # of the window's height, for the log

Area = QtCore.Qt.DockWidgetArea


def open_settings(settings: QtCore.QSettings | str | Path | None) -> QtCore.QSettings | None:
    """`settings` itself, an ini file at the path `settings`, or None (nothing is kept)."""
    if settings is None or isinstance(settings, QtCore.QSettings):
        return settings
    return QtCore.QSettings(str(Path(settings)), QtCore.QSettings.Format.IniFormat)


def dock_arrangement(window: QtWidgets.QMainWindow) -> dict[str, tuple]:
    """Where each dock of `window` is, by title: (area name, floating, shown, titles of the
    docks tabbed with it, sorted).  Two windows with the same arrangement have the same layout
    up to sizes."""
    out = {}
    for dock in window.findChildren(QtWidgets.QDockWidget):
        tabbed = sorted(d.windowTitle() for d in window.tabifiedDockWidgets(dock))
        area = window.dockWidgetArea(dock)
        out[dock.windowTitle()] = (area.name, dock.isFloating(), not dock.isHidden(), tuple(tabbed))
    return out


class WindowLayout:
    """Mixin of `MainWindow`: the default dock layout, View › Reset Layout, and the layout
    kept in ``self.layout_settings`` (``self`` is the QMainWindow)."""

    layout_settings: QtCore.QSettings | None = None
    layout_restored = False      # the layout at start came from the settings

    # -- the default --------------------------------------------------------------------------
    def _default_plan(self) -> list[tuple[QtWidgets.QDockWidget, Area]]:
        plan = [(name, Area.LeftDockWidgetArea) for name in LEFT_DOCKS]
        plan += [(name, Area.RightDockWidgetArea) for name in RIGHT_TABS]
        plan += [(name, Area.BottomDockWidgetArea) for name in BOTTOM_DOCKS]
        return [(getattr(self, name), area) for name, area in plan if getattr(self, name, None) is not None]

    def arrange_default_docks(self) -> None:
        """Put every dock of the plan in its default place, shown and docked, the inspector's tab
        in front.  Sizes are `size_default_docks` (they need the window's real geometry)."""
        C = QtCore.Qt.Corner
        self.setCorner(C.TopRightCorner, Area.RightDockWidgetArea)
        self.setCorner(C.BottomRightCorner, Area.RightDockWidgetArea)
        self.setCorner(C.TopLeftCorner, Area.LeftDockWidgetArea)
        self.setCorner(C.BottomLeftCorner, Area.BottomDockWidgetArea)
        self.setTabPosition(Area.RightDockWidgetArea, QtWidgets.QTabWidget.TabPosition.East)
        plan = self._default_plan()
        for dock, area in plan:
            dock.setFloating(False)
            self.addDockWidget(area, dock, QtCore.Qt.Orientation.Vertical)   # moves a docked one
            dock.show()
        right = [dock for dock, area in plan if area == Area.RightDockWidgetArea]
        for dock in right[1:]:
            self.tabifyDockWidget(right[0], dock)
        if right:
            right[0].raise_()

    def size_default_docks(self) -> None:
        """Column widths and the log's height for the window's present size."""
        w, h = self.width(), self.height()
        plan = self._default_plan()
        left = [d for d, a in plan if a == Area.LeftDockWidgetArea]
        right = [d for d, a in plan if a == Area.RightDockWidgetArea]
        bottom = [d for d, a in plan if a == Area.BottomDockWidgetArea]
        if left and right:
            want = max(self._content_width(d) for d in right) + self._tab_bar_thickness(right[0])
            right_w = min(max(want, RIGHT_SHARE[0] * w), RIGHT_SHARE[1] * w)
            self.resizeDocks([left[0], right[0]], [int(EDITOR_SHARE * w), int(right_w)],
                             QtCore.Qt.Orientation.Horizontal)
        if bottom:
            log_h = max(bottom[0].minimumSizeHint().height(), int(LOG_SHARE * h))
            self.resizeDocks([bottom[0]], [log_h], QtCore.Qt.Orientation.Vertical)

    def _content_width(self, dock: QtWidgets.QDockWidget) -> int:
        """Width `dock` needs to show its content without scrolling sideways."""
        widget = dock.widget()
        if isinstance(widget, QtWidgets.QScrollArea) and widget.widget() is not None:
            bar = self.style().pixelMetric(QtWidgets.QStyle.PixelMetric.PM_ScrollBarExtent)
            return widget.widget().minimumSizeHint().width() + bar + 2 * widget.frameWidth()
        return widget.minimumSizeHint().width()

    def _tab_bar_thickness(self, dock: QtWidgets.QDockWidget) -> int:
        """Width of the side tab bar of the tab group `dock` is in (0 if none)."""
        title = dock.windowTitle()
        for bar in self.findChildren(QtWidgets.QTabBar):
            if bar.parent() is self and title in (bar.tabText(i) for i in range(bar.count())):
                vertical = bar.shape() in (QtWidgets.QTabBar.Shape.RoundedEast, QtWidgets.QTabBar.Shape.RoundedWest)
                return bar.sizeHint().width() if vertical else 0
        return 0

    def reset_layout(self) -> None:
        """View › Reset Layout: every dock back in its default place and size."""
        self.arrange_default_docks()
        self.layout().activate()
        self.size_default_docks()
        self.log("info", "layout reset to the default")

    # -- kept between sessions ----------------------------------------------------------------
    def dock_names(self) -> str:
        """The object names of this window's docks, sorted: a saved state of another set of
        docks is not restored."""
        return ",".join(sorted(d.objectName() for d in self.findChildren(QtWidgets.QDockWidget)))

    def restore_layout(self) -> bool:
        """Read the saved geometry and dock layout; False (the default layout stays) when there
        is none, it was saved with other docks, or Qt refuses it."""
        self.layout_restored = False
        settings = self.layout_settings
        if settings is None:
            return False
        geometry = settings.value(KEY_GEOMETRY)
        if isinstance(geometry, QtCore.QByteArray) and not geometry.isEmpty():
            self.restoreGeometry(geometry)
        state = settings.value(KEY_STATE)
        if not isinstance(state, QtCore.QByteArray) or state.isEmpty():
            return False
        if settings.value(KEY_DOCKS) != self.dock_names():
            self.log("info", "the saved window layout has other docks than this version: default layout")
            return False
        if not self.restoreState(state, LAYOUT_VERSION):
            self.arrange_default_docks()     # whatever Qt read before it gave up is undone
            self.log("info", "the saved window layout could not be read: default layout")
            return False
        self.layout_restored = True
        return True

    def save_layout(self) -> bool:
        """Write the geometry and dock layout to the settings (nothing without settings)."""
        settings = self.layout_settings
        if settings is None:
            return False
        settings.setValue(KEY_GEOMETRY, self.saveGeometry())
        settings.setValue(KEY_STATE, self.saveState(LAYOUT_VERSION))
        settings.setValue(KEY_DOCKS, self.dock_names())
        settings.sync()
        return settings.status() == QtCore.QSettings.Status.NoError

    # -- first size ----------------------------------------------------------------------------
    def default_window_size(self, preferred=(1500, 900)) -> QtCore.QSize:
        """`preferred`, or less on a screen too small for it (leaving room for the frame)."""
        screen = self.screen() or QtGui.QGuiApplication.primaryScreen()
        if screen is None:
            return QtCore.QSize(*preferred)
        avail = screen.availableGeometry()
        return QtCore.QSize(min(preferred[0], avail.width() - 8), min(preferred[1], avail.height() - 40))
