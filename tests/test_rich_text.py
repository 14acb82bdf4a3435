"""ui.rich_text: the node-doc markup as Qt HTML, against hand-written HTML."""

from __future__ import annotations

import pytest

from ui.rich_text import doc_to_html, inline_to_html


@pytest.mark.parametrize("text, expected", [
    ("plain words", "plain words"),
    ("cell box ``[0, Lx] x [0, Ly]`` here", "cell box <code>[0, Lx] x [0, Ly]</code> here"),
    ("when `path` is set", "when <code>path</code> is set"),
    ("an *emphasised* word", "an <i>emphasised</i> word"),
    ("a **strong** word", "a <b>strong</b> word"),
    ("**bold with *emph* inside**", "<b>bold with <i>emph</i> inside</b>"),
    ("``a * b * c`` stays code", "<code>a * b * c</code> stays code"),
    ("2 * 3 * 4 is not emphasis", "2 * 3 * 4 is not emphasis"),
    ("x < y & z > w", "x &lt; y &amp; z &gt; w"),
    ("``<b>``", "<code>&lt;b&gt;</code>"),
    ("it's \"quoted\"", "it's \"quoted\""),
])
def test_inline(text, expected):
    assert inline_to_html(text) == expected


def test_one_paragraph_docstring_is_joined_and_dedented():
    doc = """Thickens every skeleton element on a periodic grid over the cell box
    ``[0, Lx] x [0, Ly] x [0, Lz]`` (the unit cube by default)."""
    assert doc_to_html(doc) == ("<p>Thickens every skeleton element on a periodic grid over the cell box "
                                "<code>[0, Lx] x [0, Ly] x [0, Lz]</code> (the unit cube by default).</p>")


def test_paragraphs_split_on_blank_lines():
    doc = """An ordered path over the connected vertices.

    `order` lists indices into the vertices;
    repeating the first index closes the loop.
    """
    assert doc_to_html(doc) == ("<p>An ordered path over the connected vertices.</p>"
                                "<p><code>order</code> lists indices into the vertices; "
                                "repeating the first index closes the loop.</p>")


def test_bullet_list_with_continued_item_and_following_paragraph():
    doc = """Modes:

    - ``removed``: void carries nothing
    * ``soft``: E_v = 1e-3 E,
      as in the *paper*
    After the list.
    """
    assert doc_to_html(doc) == ("<p>Modes:</p>"
                                "<ul><li><code>removed</code>: void carries nothing</li>"
                                "<li><code>soft</code>: E_v = 1e-3 E, as in the <i>paper</i></li></ul>"
                                "<p>After the list.</p>")


def test_list_right_after_a_paragraph_line():
    doc = "Two kinds:\n- one\n- two"
    assert doc_to_html(doc) == "<p>Two kinds:</p><ul><li>one</li><li>two</li></ul>"


@pytest.mark.parametrize("doc", [None, "", "   \n  "])
def test_empty(doc):
    assert doc_to_html(doc) == ""


def test_every_node_doc_converts_without_raw_backticks():
    import engine.nodes  # noqa: F401  (registers the node types)
    from engine.graph.node import all_node_types

    for name, cls in all_node_types().items():
        out = doc_to_html(cls.__doc__)
        assert "``" not in out, name
        assert out.startswith("<p>") or not cls.__doc__, name
