"""What the viewport says when it has nothing to draw: why, and where to look instead."""

from __future__ import annotations

import pytest

from engine.graph import AddNode, Disconnect
from ui.main_window import EXAMPLES_DIR
from ui.view_content import EMPTY_GRAPH_HINT

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")  # NodeGraphQt uses distutils versions


def test_an_empty_graph_says_how_to_add_nodes_and_draws_no_empty_box(window):
    window.new_project()
    window.update_viewport()
    assert window.viewport.empty_hint == EMPTY_GRAPH_HINT
    assert "Tab" in EMPTY_GRAPH_HINT and "Example Gallery" in EMPTY_GRAPH_HINT
    assert "cell_box" not in window.viewport.scene.keys


def test_a_2d_graph_names_the_dock_that_shows_it(window, wait_eval):
    after = window.eval_count
    assert window.open_example(EXAMPLES_DIR / "phasor_slab.json", ask=False)
    window.evaluate_now()
    report = wait_eval(window, after, timeout=120000)
    assert report.ok, report.errors
    assert "Phasor Infill dock" in window.viewport.empty_hint


def test_a_failed_node_is_named_instead_of_nothing_to_show(window, wait_eval, strut_graph):
    ids = strut_graph(window.undo)
    after = window.eval_count
    window.evaluate_now()
    wait_eval(window, after)
    assert "cell_box" in window.viewport.scene.keys                 # a solid: the cell box is drawn
    after = window.eval_count
    window.undo.push(Disconnect(ids["v2"], "point", ids["e"], "vertices"))  # one vertex: the chain fails
    report = wait_eval(window, after)
    assert ids["e"] in report.errors
    window.editor.select(ids["v1"])
    hint = window.viewport.empty_hint
    assert repr(ids["e"]) in hint and "failed" in hint
    window.undo.push(AddNode("Vertex", {}, (0, 400)))               # still failing: still named
    assert repr(ids["e"]) in window.viewport.empty_hint
