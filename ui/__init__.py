"""Qt widgets of the Mesoforge window: node editor, inspector, viewport, log."""

from .dialogs import Prompter
from .main_window import MainWindow

__all__ = ["MainWindow", "Prompter"]
