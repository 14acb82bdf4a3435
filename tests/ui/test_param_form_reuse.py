"""Selecting a node of the same type as the one shown keeps the inspector's rows (no widgets
rebuilt) and shows the new node's values; a refusal shown for the first node goes, and an
edit after the switch lands on the node now shown."""

from __future__ import annotations

from ui.main_window import EXAMPLES_DIR


def test_like_nodes_share_the_rows_and_each_shows_its_own_values(window):
    assert window.open_example(EXAMPLES_DIR / "octet.json", ask=False)
    inspector, doc = window.inspector, window.doc
    inspector.set_node("v_corner")
    editor = inspector.editors["position"]
    boxes = list(editor.boxes)
    assert [b.current() for b in boxes] == [0.0, 0.0, 0.0]
    assert not inspector.param_form.commit("position", [20.0, 0.0, 0.0])        # out of range: refused
    assert inspector.messages["position"].refused

    inspector.set_node("v_face_z")                                              # another Vertex
    assert inspector.editors["position"] is editor and editor.boxes == boxes     # the same widgets
    assert [b.current() for b in boxes] == [0.5, 0.5, 0.0]
    assert not inspector.messages["position"].refused                           # the refusal was v_corner's
    assert inspector.param_form.commit("position", [0.5, 0.5, 0.25])
    assert doc.nodes["v_face_z"].params["position"] == [0.5, 0.5, 0.25]
    assert doc.nodes["v_corner"].params["position"] == [0.0, 0.0, 0.0]

    inspector.set_node("e_strut")                                               # another type: new rows
    assert "position" not in inspector.editors and "smooth" in inspector.editors
    inspector.set_node("v_corner")
    assert [b.current() for b in inspector.editors["position"].boxes] == [0.0, 0.0, 0.0]
    window.undo.undo()
    assert doc.nodes["v_face_z"].params["position"] == [0.5, 0.5, 0.0]
