"""The docstring markup of node and parameter docs, as Qt rich text (HTML).

Node docs are written as docstrings: ``double`` or `single` backticks for
code and names, ``*emphasis*`` and ``**strong**``, paragraphs separated by a
blank line, and bullet lists (lines starting with ``- `` or ``* ``, an item
continued on more-indented lines). `doc_to_html` turns that into the subset
of HTML a QLabel or a tooltip renders; everything else is escaped, so a
docstring can never inject markup.
"""

from __future__ import annotations

import html
import inspect
import re

__all__ = ["doc_to_html", "inline_to_html"]

_INLINE = re.compile(
    r"``(?P<code2>.+?)``"                                   # ``code``
    r"|`(?P<code1>[^`]+?)`"                                 # `name`
    r"|\*\*(?P<strong>\S(?:.*?\S)?)\*\*"                    # **strong**
    r"|(?<![\w*])\*(?P<emph>[^\s*](?:[^*]*?[^\s*])?)\*(?![\w*])")   # *emph*
_BULLET = re.compile(r"^(\s*)[-*•]\s+(.*)$")


def inline_to_html(text: str) -> str:
    """One run of text: code, emphasis and strong marked up, the rest escaped."""
    out, last = [], 0
    for m in _INLINE.finditer(text):
        out.append(html.escape(text[last:m.start()], quote=False))
        if m.group("code2") is not None or m.group("code1") is not None:
            code = m.group("code2") if m.group("code2") is not None else m.group("code1")
            out.append(f"<code>{html.escape(code, quote=False)}</code>")
        elif m.group("strong") is not None:
            out.append(f"<b>{inline_to_html(m.group('strong'))}</b>")
        else:
            out.append(f"<i>{inline_to_html(m.group('emph'))}</i>")
        last = m.end()
    out.append(html.escape(text[last:], quote=False))
    return "".join(out)


def doc_to_html(doc: str | None) -> str:
    """A docstring (indentation as written in the source) as Qt HTML: ``<p>``
    per paragraph, ``<ul><li>`` per bullet list; "" for an empty doc."""
    text = inspect.cleandoc(doc or "")
    if not text.strip():
        return ""
    parts: list[str] = []
    for block in re.split(r"\n\s*\n", text):
        parts.extend(_block_html(block.splitlines()))
    return "".join(parts)


def _block_html(lines: list[str]) -> list[str]:
    """One blank-line separated block: runs of paragraph lines and bullet items."""
    out: list[str] = []
    para: list[str] = []
    items: list[list[str]] = []
    item_indent = 0

    def flush_para():
        if para:
            out.append(f"<p>{inline_to_html(' '.join(para))}</p>")
            para.clear()

    def flush_items():
        if items:
            lis = "".join(f"<li>{inline_to_html(' '.join(item))}</li>" for item in items)
            out.append(f"<ul>{lis}</ul>")
            items.clear()

    for raw in lines:
        if not raw.strip():
            continue
        bullet = _BULLET.match(raw)
        indent = len(raw) - len(raw.lstrip())
        if bullet:
            flush_para()
            items.append([bullet.group(2).strip()])
            item_indent = len(bullet.group(1))
        elif items and indent > item_indent:
            items[-1].append(raw.strip())          # an item continued on an indented line
        else:
            flush_items()
            para.append(raw.strip())
    flush_para()
    flush_items()
    return out
