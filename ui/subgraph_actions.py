"""The window's Edit-menu actions for frames and subgraphs.

Add Frame (around the selection), Remove Frame, Make Subgraph (Ctrl+G),
Ungroup (Ctrl+Shift+G), Collapse / Expand Subgraph, Save Subgraph to
Library… and Insert Subgraph ›; and, on the inspector's parameters, a context
menu that exposes one on the node's subgraph.
They call `NodeFrames` (``window.editor.frames``) and the window's
`SubgraphLibrary` (``window.subgraph_library``, a user folder; tests put
their own there).
"""

from __future__ import annotations

from PySide6 import QtCore, QtWidgets

from engine.graph import ExposeParam, GraphError, UnexposeParam
from engine.graph.subgraph_library import InsertSubgraph, SubgraphLibrary, default_library_dir


def build_annotation_actions(window) -> None:
    """Create the actions on `window` (a MainWindow being built)."""
    frames = window.editor.frames
    window.subgraph_library = SubgraphLibrary(default_library_dir())
    window.act_add_frame = window._action("Add &Frame", frames.add_frame_around_selection)
    window.act_remove_frame = window._action("Remove Frame", frames.remove_current_frame)
    window.act_make_subgraph = window._action("Make &Subgraph", frames.make_subgraph, "Ctrl+G")
    window.act_ungroup = window._action("&Ungroup", frames.ungroup, "Ctrl+Shift+G")
    window.act_save_subgraph = window._action("Save Subgraph to &Library…", lambda: save_subgraph(window))
    window.act_collapse_subgraph = window._action("Collapse / Expand Subgraph", frames.toggle_collapsed)
    box = window.inspector.params_box  # right click on a parameter: expose it on the node's subgraph
    box.setContextMenuPolicy(QtCore.Qt.ContextMenuPolicy.CustomContextMenu)
    box.customContextMenuRequested.connect(
        lambda pos: _exec(inspector_menu(window, box.childAt(pos)), box.mapToGlobal(pos)))


def fill_edit_menu(window, edit_menu: QtWidgets.QMenu) -> None:
    """Append the frame and subgraph items to the Edit menu."""
    edit_menu.addSeparator()
    edit_menu.addAction(window.act_add_frame)
    edit_menu.addAction(window.act_remove_frame)
    edit_menu.addAction(window.act_make_subgraph)
    edit_menu.addAction(window.act_ungroup)
    edit_menu.addAction(window.act_collapse_subgraph)
    edit_menu.addAction(window.act_save_subgraph)
    window.insert_subgraph_menu = edit_menu.addMenu("&Insert Subgraph")
    window.insert_subgraph_menu.aboutToShow.connect(lambda: fill_insert_menu(window))
    fill_insert_menu(window)


def fill_insert_menu(window) -> None:
    menu = window.insert_subgraph_menu
    menu.clear()
    entries, problems = window.subgraph_library.entries()
    for entry in entries:
        action = menu.addAction(entry.name)
        action.setToolTip(f"{len(entry.node_ids)} nodes from {entry.path}")
        action.triggered.connect(lambda _c=False, e=entry: insert_subgraph(window, e))
    for problem in problems:
        window.log("warning", problem)
    if not entries:
        none = menu.addAction("(no saved subgraphs)")
        none.setEnabled(False)


def inspector_param_at(window, widget) -> str | None:
    """The parameter whose label or editor `widget` is (or lies in), in the inspector."""
    inspector = window.inspector
    owners = {}
    for name, editor in inspector.editors.items():
        owners[editor.widget] = name
        label = inspector.form.labelForField(editor.widget)
        if label is not None:
            owners[label] = name
    while widget is not None and widget is not inspector.params_box:
        if widget in owners:
            return owners[widget]
        widget = widget.parentWidget()
    return None


def inspector_menu(window, widget) -> QtWidgets.QMenu | None:
    """The inspector's context menu for the parameter at `widget`: expose it on the subgraph."""
    name = inspector_param_at(window, widget)
    node_id = window.inspector.node_id
    if name is None or node_id is None:
        return None
    menu = QtWidgets.QMenu(window.inspector)
    sub = window.doc.annotations.subgraph_of(node_id)
    if sub is None:
        action = menu.addAction(f"Expose '{name}' (group the node first: Ctrl+G)")
        action.setEnabled(False)
    elif any((e.node_id, e.param) == (node_id, name) for e in sub.exposed):
        action = menu.addAction(f"Unexpose '{name}' from subgraph '{sub.name}'")
        action.triggered.connect(lambda _c=False: _push(window, UnexposeParam(sub.id, node_id, name)))
    else:
        action = menu.addAction(f"Expose '{name}' on subgraph '{sub.name}'")
        action.triggered.connect(lambda _c=False: _push(window, ExposeParam(sub.id, node_id, name)))
    return menu


def _exec(menu, pos) -> None:
    if menu is not None:
        menu.exec(pos)
        menu.deleteLater()


def _push(window, command) -> bool:
    try:
        window.undo.push(command)
    except GraphError as exc:
        window.log("error", f"refused: {exc}")
        return False
    return True


def save_subgraph(window) -> str | None:
    """Save the current subgraph (or the selected node's) under its name; returns the file."""
    sub_id = window.editor.frames.current_subgraph()
    if sub_id is None:
        window.log("error", "save subgraph: no subgraph selected; select a node of one first")
        return None
    try:
        path, replaced = window.subgraph_library.save(window.doc, sub_id)
    except (GraphError, OSError) as exc:
        window.log("error", f"save subgraph refused: {exc}")
        return None
    window.log("info", f"{'replaced' if replaced else 'saved'} subgraph in the library: {path}")
    return str(path)


def insert_subgraph(window, entry, offset=(40.0, 40.0)) -> str | None:
    """Insert a library subgraph (new node ids, one undo step); returns the new subgraph id."""
    cmd = InsertSubgraph(entry, offset=offset)
    try:
        window.undo.push(cmd)
    except GraphError as exc:
        window.log("error", f"insert subgraph refused: {exc}")
        return None
    window.editor.frames.select("subgraph", cmd.subgraph_id)
    return cmd.subgraph_id


__all__ = ["build_annotation_actions", "fill_edit_menu", "inspector_menu", "insert_subgraph", "save_subgraph"]
