"""GUI entry point: builds the QApplication and the main window."""

from __future__ import annotations

import sys
from pathlib import Path

from PySide6 import QtCore, QtGui, QtWidgets

from app.thumbnails import render_in_child
from engine.kernel_warmup import warm_up_kernels
from ui.dialogs import Prompter
from ui.example_gallery import show_at_startup, show_gallery
from ui.main_window import DEFAULT_EXAMPLE, EXAMPLES_DIR, MainWindow


def create_main_window(project_path: str | Path | None = None, autosave_dir: str | Path | None = None, *,
                       prompter: Prompter | None = None, open_example: bool = False,
                       offer_recovery: bool = False, autosave_interval_ms: int | None = None,
                       settings=None) -> MainWindow:
    """A MainWindow (a QApplication must exist) with `project_path` opened.

    Without a project, ``open_example=True`` loads the default example
    (``resources/examples/octet.json``) when it is present.  A shipped file
    (the default example ``mesoforge`` launches with, or any file under
    ``resources/``) opens as an untitled copy, so Save asks for a path and the
    shipped file is never overwritten.  With ``offer_recovery=True`` a crashed
    session's autosave is offered first.  `settings` (a QSettings or an ini file's
    path) keeps the window's layout between sessions; None keeps nothing.
    """
    warm_up_kernels()        # numba's tables now, not on a worker thread in the first evaluation (GIL)
    extra = {} if autosave_interval_ms is None else {"autosave_interval_ms": autosave_interval_ms}
    window = MainWindow(autosave_dir=autosave_dir, prompter=prompter, settings=settings, **extra)
    window.thumbnail_renderer = render_in_child    # the gallery's missing thumbnails, off the GUI thread
    if offer_recovery and window.offer_recovery():
        return window
    if project_path is not None:
        window.open_project(project_path, ask=False)
    elif open_example:
        example = EXAMPLES_DIR / DEFAULT_EXAMPLE
        if not example.is_file():
            found = MainWindow.example_files()
            example = found[0] if found else None
        if example is not None:
            window.open_example(example, ask=False)
    return window


def apply_dark_theme(app: QtWidgets.QApplication) -> None:
    """Fusion with a dark palette, matching the node editor and the viewport."""
    app.setStyle("Fusion")
    pal = QtGui.QPalette()
    role, colour = QtGui.QPalette.ColorRole, QtGui.QColor
    for r, c in ((role.Window, "#2b2d31"), (role.WindowText, "#e6e6e6"), (role.Base, "#1f2124"),
                 (role.AlternateBase, "#2b2d31"), (role.ToolTipBase, "#3a3d42"), (role.ToolTipText, "#f0f0f0"),
                 (role.Text, "#e6e6e6"), (role.Button, "#35383d"), (role.ButtonText, "#e6e6e6"),
                 (role.BrightText, "#ff6060"), (role.Highlight, "#3d7ecb"), (role.HighlightedText, "#ffffff"),
                 (role.Link, "#6aa8e0"), (role.PlaceholderText, "#8a8f96")):
        pal.setColor(r, colour(c))
    disabled = QtGui.QPalette.ColorGroup.Disabled
    for r in (role.WindowText, role.Text, role.ButtonText):
        pal.setColor(disabled, r, colour("#777a80"))
    app.setPalette(pal)


def wants_start_page(project_path, settings) -> bool:
    """A plain ``mesoforge`` launch (no project, or the default example app.cli passes)
    shows the example gallery, unless its "Show at startup" was turned off."""
    plain = project_path is None or Path(project_path).resolve() == (EXAMPLES_DIR / DEFAULT_EXAMPLE).resolve()
    return plain and show_at_startup(settings)


def run_gui(project_path: str | None = None, argv=None) -> int:
    """Run the desktop application; returns the exit code."""
    argv = list(sys.argv if argv is None else argv)
    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication(argv)
    app.setApplicationName("Mesoforge")
    app.setOrganizationName("Mesoforge")
    apply_dark_theme(app)
    window = create_main_window(project_path, open_example=project_path is None, offer_recovery=True,
                                settings=QtCore.QSettings())    # the user's layout, per user
    window.show()
    if wants_start_page(project_path, window.layout_settings):
        show_gallery(window)            # the start page (non-modal)
    return int(app.exec())


if __name__ == "__main__":
    sys.exit(run_gui(sys.argv[1] if len(sys.argv) > 1 else None))
