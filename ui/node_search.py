"""Search-to-add (Tab in the node editor): every node type with its family and the
first sentence of its description, filtered as you type (words of the name, the
family or the description, in any order); Enter adds the chosen type where the
cursor was when the search opened."""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import TYPE_CHECKING

from PySide6 import QtCore, QtGui, QtWidgets

from engine.graph import all_node_types

if TYPE_CHECKING:
    from .node_editor import NodeEditor


@dataclass(frozen=True)
class SearchEntry:
    type_name: str
    title: str
    family: str
    summary: str  # first sentence of the description

    @property
    def haystack(self) -> str:
        return f"{self.title} {self.type_name} {self.family} {self.summary}".lower()


_SENTENCE_END = re.compile(r"(?<!\beq)(?<!\beqs)(?<!\be\.g)(?<!\bi\.e)(?<!\bcf)(?<!\bFig)(?<!\bvs)[.!?](?=\s|$)")
SUMMARY_MAX = 140  # characters of a description shown in the list


def first_sentence(text: str) -> str:
    """The description's first sentence, on one line, cut at SUMMARY_MAX ("" for none)."""
    flat = " ".join((text or "").split())
    m = _SENTENCE_END.search(flat)
    sentence = flat[:m.end()] if m else flat
    if len(sentence) > SUMMARY_MAX:
        sentence = sentence[:SUMMARY_MAX].rsplit(" ", 1)[0] + "…"
    return sentence


def search_entries() -> list[SearchEntry]:
    """One entry per registered node type, by family then title."""
    out = []
    for name, cls in all_node_types().items():
        if name.startswith("_"):
            continue  # test-only types
        out.append(SearchEntry(name, cls.title or name, cls.family, first_sentence(cls.__doc__ or "")))
    return sorted(out, key=lambda e: (e.family, e.title.lower()))


def matching(entries: list[SearchEntry], query: str) -> list[SearchEntry]:
    """Entries holding every word of ``query`` (case-insensitive); names that start
    with the query first."""
    words = query.lower().split()
    hits = [e for e in entries if all(w in e.haystack for w in words)]
    q = query.strip().lower()
    if q:
        hits.sort(key=lambda e: (not e.title.lower().startswith(q), q not in e.title.lower()))
    return hits


class NodeSearch(QtWidgets.QFrame):
    """The search popup: a line edit over a list; a child of the editor, shown over
    its graph view."""

    def __init__(self, editor: "NodeEditor"):
        super().__init__(editor)
        self.editor = editor
        self.setObjectName("nodeSearch")
        self.setFrameShape(QtWidgets.QFrame.Shape.StyledPanel)
        self.setAutoFillBackground(True)
        self.entries = search_entries()
        self.scene_pos: tuple[float, float] = (0.0, 0.0)
        self.line = QtWidgets.QLineEdit(self)
        self.line.setPlaceholderText("Search node types: name, family or description words")
        self.list = QtWidgets.QListWidget(self)
        self.list.setWordWrap(True)
        self.list.setUniformItemSizes(False)
        self.list.setSpacing(2)
        layout = QtWidgets.QVBoxLayout(self)
        layout.setContentsMargins(4, 4, 4, 4)
        layout.setSpacing(3)
        layout.addWidget(self.line)
        layout.addWidget(self.list)
        self.line.textChanged.connect(self._refill)
        self.line.installEventFilter(self)
        self.list.itemActivated.connect(lambda _item: self.accept())
        self.list.itemClicked.connect(lambda _item: self.accept())
        self._viewport = editor.graph.viewer().viewport()
        self._viewport.installEventFilter(self)  # a click in the graph closes the search
        self.hide()

    # -- showing ---------------------------------------------------------------
    def open_at(self, scene_pos: tuple[float, float], view_pos: QtCore.QPoint | None = None) -> None:
        """Show the search; a chosen type is added at ``scene_pos``."""
        self.scene_pos = (float(scene_pos[0]), float(scene_pos[1]))
        self.line.clear()
        self._refill("")
        w, h = 420, 320
        area = self.parentWidget().rect()
        p = view_pos if view_pos is not None else area.center() - QtCore.QPoint(w // 2, h // 2)
        x = max(0, min(p.x(), area.width() - w))
        y = max(0, min(p.y(), area.height() - h))
        self.setGeometry(x, y, min(w, area.width()), min(h, area.height()))
        self.show()
        self.raise_()
        self.line.setFocus()

    def toggle_at_cursor(self) -> None:
        """Tab: open at the mouse (in the middle of the view when it is elsewhere), or close."""
        if not self.isHidden():
            self.close_search()
            return
        viewer = self.editor.graph.viewer()
        local = viewer.viewport().mapFromGlobal(QtGui.QCursor.pos())
        if viewer.viewport().rect().contains(local):
            p = viewer.mapToScene(local)
            self.open_at((p.x(), p.y()), viewer.viewport().mapTo(self.editor, local))
        else:
            p = viewer.mapToScene(viewer.viewport().rect().center())
            self.open_at((p.x(), p.y()))

    def detach(self) -> None:
        if self._viewport is not None:
            self._viewport.removeEventFilter(self)
            self._viewport = None

    def close_search(self) -> None:
        self.hide()
        self.editor.graph.viewer().setFocus()

    # -- list ------------------------------------------------------------------
    def visible_types(self) -> list[str]:
        return [self.list.item(i).data(QtCore.Qt.ItemDataRole.UserRole) for i in range(self.list.count())]

    def _refill(self, text: str) -> None:
        self.list.clear()
        for e in matching(self.entries, text):
            item = QtWidgets.QListWidgetItem(f"{e.title}   ·  {e.family}\n{e.summary}")
            item.setData(QtCore.Qt.ItemDataRole.UserRole, e.type_name)
            item.setToolTip(f"<b>{e.title}</b> ({e.type_name}, {e.family})<br/>{_escape(e.summary)}")
            self.list.addItem(item)
        if self.list.count():
            self.list.setCurrentRow(0)

    def accept(self) -> str | None:
        """Add the current type at the remembered position; its id (or None)."""
        item = self.list.currentItem()
        if item is None or self.isHidden():
            return None
        type_name = item.data(QtCore.Qt.ItemDataRole.UserRole)
        self.close_search()
        return self.editor.create_node(type_name, self.scene_pos)

    def eventFilter(self, watched, event) -> bool:
        if watched is self._viewport:
            if event.type() == QtCore.QEvent.Type.MouseButtonPress and not self.isHidden():
                self.hide()
            return False
        if watched is self.line and event.type() == QtCore.QEvent.Type.KeyPress:
            key = event.key()
            if key in (QtCore.Qt.Key.Key_Return, QtCore.Qt.Key.Key_Enter):
                self.accept()
                return True
            if key in (QtCore.Qt.Key.Key_Escape, QtCore.Qt.Key.Key_Tab):
                self.close_search()
                return True
            if key in (QtCore.Qt.Key.Key_Down, QtCore.Qt.Key.Key_Up):
                step = 1 if key == QtCore.Qt.Key.Key_Down else -1
                row = min(max(self.list.currentRow() + step, 0), self.list.count() - 1)
                self.list.setCurrentRow(row)
                return True
        return super().eventFilter(watched, event)



def _escape(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
