"""GUI entry point: builds the QApplication and the main window."""

from __future__ import annotations

import sys
from pathlib import Path

from PySide6 import QtGui, QtWidgets

from ui.dialogs import Prompter
from ui.main_window import DEFAULT_EXAMPLE, EXAMPLES_DIR, MainWindow


def create_main_window(project_path: str | Path | None = None, autosave_dir: str | Path | None = None, *,
                       prompter: Prompter | None = None, open_example: bool = False,
                       offer_recovery: bool = False, autosave_interval_ms: int | None = None) -> MainWindow:
    """A MainWindow (a QApplication must exist) with `project_path` opened.

    Without a project, ``open_example=True`` loads the default example
    (``resources/examples/octet.json``) when it is present.  A shipped file
    (the default example ``mesoforge`` launches with, or any file under
    ``resources/``) opens as an untitled copy, so Save asks for a path and the
    shipped file is never overwritten.  With ``offer_recovery=True`` a crashed
    session's autosave is offered first.
    """
    extra = {} if autosave_interval_ms is None else {"autosave_interval_ms": autosave_interval_ms}
    window = MainWindow(autosave_dir=autosave_dir, prompter=prompter, **extra)
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


def run_gui(project_path: str | None = None, argv=None) -> int:
    """Run the desktop application; returns the exit code."""
    argv = list(sys.argv if argv is None else argv)
    app = QtWidgets.QApplication.instance() or QtWidgets.QApplication(argv)
    app.setApplicationName("Mesoforge")
    app.setOrganizationName("Mesoforge")
    apply_dark_theme(app)
    window = create_main_window(project_path, open_example=project_path is None, offer_recovery=True)
    window.show()
    return int(app.exec())


if __name__ == "__main__":
    sys.exit(run_gui(sys.argv[1] if len(sys.argv) > 1 else None))
