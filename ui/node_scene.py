"""The NodeGraphQt side of the node editor: node items, generated node classes
and a NodeGraph whose gestures go to the editor instead of NodeGraphQt's model.

Nothing here edits the document: `DocumentNodeGraph` hands every gesture
(connect, slice, move, search-create, rename, delete) to the `NodeEditor`,
which turns it into engine commands.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from NodeGraphQt import BaseNode, NodeGraph
from NodeGraphQt.qgraphics.node_base import NodeItem
from PySide6 import QtCore, QtGui

from engine.graph import all_node_types

from .colours import PORT_COLOURS, family_colour

if TYPE_CHECKING:
    from .node_editor import NodeEditor


STATUS_PENS = {
    "failed": ((230, 40, 40), 3.5),
    "blocked": ((230, 150, 40), 2.5),
    "cancelled": ((150, 150, 150), 2.5),
}


class StatusNodeItem(NodeItem):
    """A node item that outlines itself by evaluation status (red = failed)."""

    def __init__(self, name="node", parent=None):
        super().__init__(name, parent)
        self.status = ""
        self._proxy_mode_threshold = 36  # keep titles readable when zoomed out to fit a graph

    def paint(self, painter, option, widget):
        super().paint(painter, option, widget)
        pen_spec = STATUS_PENS.get(self.status)
        if pen_spec is None:
            return
        colour, width = pen_spec
        painter.save()
        pen = QtGui.QPen(QtGui.QColor(*colour), width)
        painter.setPen(pen)
        painter.setBrush(QtCore.Qt.BrushStyle.NoBrush)
        r = self.boundingRect().adjusted(1.0, 1.0, -1.0, -1.0)
        painter.drawRoundedRect(r, 5.0, 5.0)
        painter.restore()


class EngineNode(BaseNode):
    """Base of the generated NodeGraphQt classes; ENGINE_TYPE names the engine node type."""

    __identifier__ = "mesoforge"
    NODE_NAME = "Node"
    ENGINE_TYPE = ""

    def __init__(self):
        super().__init__(qgraphics_item=StatusNodeItem)
        cls = all_node_types()[self.ENGINE_TYPE]
        for port in cls.inputs:
            self.add_input(port.name, multi_input=port.multi, color=PORT_COLOURS.get(port.type))
        for port in cls.outputs:
            self.add_output(port.name, multi_output=True, color=PORT_COLOURS.get(port.type))
        r, g, b = family_colour(cls.family)
        self.set_color(r, g, b)


def make_node_classes() -> dict[str, type[EngineNode]]:
    """One NodeGraphQt class per engine node type, keyed by engine type name."""
    classes = {}
    for type_name, cls in sorted(all_node_types().items()):
        classes[type_name] = type(
            f"{type_name}Node", (EngineNode,),
            {"__identifier__": f"mesoforge.{cls.family}", "NODE_NAME": cls.title or type_name,
             "ENGINE_TYPE": type_name})
    return classes


class DocumentNodeGraph(NodeGraph):
    """NodeGraph whose gesture handlers hand over to the editor instead of
    editing NodeGraphQt's own model."""

    def __init__(self, editor: "NodeEditor", **kwargs):
        self._editor = editor
        super().__init__(**kwargs)

    def _on_connection_changed(self, disconnected, connected):
        self._editor.gesture_connections(disconnected, connected)

    def _on_connection_sliced(self, ports):
        self._editor.gesture_connections(ports, [])

    def _on_nodes_moved(self, node_data):
        self._editor.gesture_moved(node_data)

    def _on_search_triggered(self, node_type, pos):
        self._editor.gesture_create(node_type, pos)

    def _on_insert_node(self, pipe, node_id, prev_node_pos):
        # Dropping a node onto a pipe is only a move here.
        self._editor.gesture_moved(prev_node_pos)

    def _on_node_name_changed(self, node_id, name):
        self._editor.gesture_rename(node_id, name)

    def _on_node_data_dropped(self, mimedata, pos):
        pass  # NodeGraphQt would import its own session files

    def _on_context_menu_prompt(self, menu_name, node_id):
        self._editor.menu_scene_pos = self.cursor_pos()
        super()._on_context_menu_prompt(menu_name, node_id)

    def delete_nodes(self, nodes, push_undo=True):
        self._editor.gesture_delete([n.id for n in nodes])

    def delete_node(self, node, push_undo=True):
        self._editor.gesture_delete([node.id])
