"""Painting hint regions in the Virtual Growth dock: strokes become undo steps.

Each stroke on the picture becomes one ``SetParam(node, "regions", text)``,
clear all one more, and the hints per label one ``SetParam(node,
"region_hints", text)``; the binding follows the document's events, so undo /
redo show at once. Painting is for the 2D tiling of a Grow node of the
document whose undo history the binding holds.
"""

from __future__ import annotations

import numpy as np
from PySide6 import QtCore

from engine.graph import SetParam
from engine.growth.regions import format_region_map, parse_region_map


class RegionBinding(QtCore.QObject):
    """Binds the canvas (`RegionCanvas`) and the tools (`RegionTools`) to a Grow node's
    ``regions`` / ``region_hints`` parameters through an undo stack.

    ``shown()`` returns ``(doc, node_id, value)``: the document shown, the node and
    its TilingValue (None when nothing is shown).
    """

    def __init__(self, view, tools, shown, parent=None):
        super().__init__(parent)
        self.view, self.tools, self._shown = view, tools, shown
        self.undo = None
        self._watched = None
        view.strokeFinished.connect(self._on_stroke)
        tools.labelChosen.connect(lambda label: setattr(view, "paint_label", int(label)))
        tools.radiusChanged.connect(lambda radius: setattr(view, "brush_radius", float(radius)))
        tools.overlayToggled.connect(view.set_overlay_visible)
        tools.clearRequested.connect(self.clear_regions)
        tools.hintsApplied.connect(self._on_hints_applied)
        view.paint_label = tools.paint_label
        view.brush_radius = tools.radius.value()

    # -- document and undo ------------------------------------------------------------------
    def set_undo(self, undo) -> None:
        """Where strokes go (an UndoStack over the shown document); None turns painting off."""
        self.undo = undo
        if undo is not None:
            self.watch(undo.doc)
        self.refresh()

    def watch(self, doc) -> None:
        """Follow ``doc``'s events (parameter edits, undo) to keep the painted map current."""
        if doc is self._watched:
            return
        if self._watched is not None:
            self._watched.unsubscribe(self._on_doc_event)
        self._watched = doc
        if doc is not None:
            doc.subscribe(self._on_doc_event)

    @property
    def watched(self):
        return self._watched

    def _on_doc_event(self, event: str, payload) -> None:
        try:
            _, node_id, _ = self._shown()
            if event == "param_changed":
                nid, name = payload
                if nid == node_id and name in ("regions", "region_hints", "hints", "size"):
                    self.refresh()
            elif event in ("node_removed", "reset"):
                self.refresh()
        except RuntimeError:   # the widgets are gone; the document lives on
            pass

    def grow_node(self):
        """The shown node when it is a Grow node of the document, else None."""
        doc, node_id, _ = self._shown()
        doc = doc if doc is not None else self._watched
        node = doc.nodes.get(node_id) if doc is not None and node_id else None
        return node if node is not None and node.type_name == "Grow" else None

    def block_reason(self) -> str | None:
        """Why painting is off now, or None when it is on."""
        doc, _, value = self._shown()
        node = self.grow_node()
        if value is None:
            return "painting needs a tiling: evaluate a graph with a Grow node"
        if node is None:
            return "hint regions are painted on the tiling of a Grow node"
        if value.ndim != 2:
            return "painted regions are for 2D grids; this tiling is 3D"
        if self.undo is None:
            return "painting is off: the panel has no undo history to record strokes"
        if doc is not None and self.undo.doc is not doc:
            return "painting is off: the undo history belongs to another document"
        size = tuple(int(s) for s in node.params.get("size", ()))[::-1]
        if size != tuple(value.tiling.shape):
            return "the grid size changed since the last evaluation: evaluate to paint"
        return None

    def refresh(self) -> None:
        """Show the node's painted map and hints; enable painting when it may."""
        _, _, value = self._shown()
        reason = self.block_reason()
        node = self.grow_node()
        labels, problem = None, ""
        painted = node is not None and value is not None and value.ndim == 2
        if painted:
            try:
                labels = parse_region_map(node.params.get("regions", ""), value.tiling.shape)
            except ValueError as exc:
                problem = f"the regions text does not fit this grid ({exc}); a stroke replaces it"
        self.view.set_labels(labels)
        self.view.set_painting(reason is None)
        self.view.setToolTip(reason or "")
        self.tools.set_available(reason)
        if painted:
            self.tools.set_state(labels, node.params.get("region_hints", ""),
                                 node.params.get("hints", ""), value.tileset)
        else:
            self.tools.set_state(None, "", "", None)
        if problem:
            self.tools.show_message(problem, error=True)

    # -- edits --------------------------------------------------------------------------------
    def _push(self, name: str, value: str) -> bool:
        _, node_id, _ = self._shown()
        try:
            self.undo.push(SetParam(node_id, name, value))
        except Exception as exc:   # refused by the document: nothing changed
            self.tools.show_message(f"not applied: {exc}", error=True)
            self.refresh()
            return False
        return True

    def _on_stroke(self, labels: np.ndarray) -> None:
        if self.block_reason() is not None:
            self.refresh()
            return
        self._push("regions", format_region_map(labels) if np.any(labels) else "")

    def clear_regions(self) -> None:
        """Remove every painted region: one undo step (nothing if nothing is painted)."""
        node = self.grow_node()
        if node is None or self.block_reason() is not None:
            return
        if not node.params.get("regions", "").strip():
            self.tools.show_message("nothing is painted")
            return
        self._push("regions", "")

    def _on_hints_applied(self, text: str) -> None:
        if self.grow_node() is not None and self.block_reason() is None:
            if self._push("region_hints", text):
                self.tools.show_message("hints applied")
