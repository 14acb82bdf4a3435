"""The inspector shows a node's description as rich text: ``code`` as <code>, never raw markup."""

from __future__ import annotations

from PySide6 import QtCore

from ui.main_window import EXAMPLES_DIR


def test_object_description_renders_code_markup(window):
    assert window.open_example(EXAMPLES_DIR / "octet.json", ask=False)
    window.inspector.set_node("object")
    label = window.inspector.description
    assert label.textFormat() == QtCore.Qt.TextFormat.RichText
    text = label.text()
    assert "<code>[0, Lx] x [0, Ly] x [0, Lz]</code>" in text
    assert "``" not in text
