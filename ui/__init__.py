"""Qt widgets of the Mesoforge window: node editor, inspector, viewport, log."""

from .main_window import MainWindow, Prompter

__all__ = ["MainWindow", "Prompter"]
