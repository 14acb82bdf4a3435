"""The main window's files: new / open / example / save / export, autosave and
crash recovery.  A bad file leaves the open project untouched.

The window never writes into the shipped ``resources/`` folder: a shipped
file (an example) always opens as an untitled copy, so Save asks for a path,
and saving or exporting onto a path inside ``resources/`` is refused.
"""

from __future__ import annotations

from pathlib import Path

from PySide6 import QtCore

from engine.graph import GraphDocument, ProjectFileError, load_project, save_project

from .dialogs import MESH_FILTERS

SHIPPED_DIR = Path(__file__).resolve().parents[1] / "resources"
"""The folder of files shipped with Mesoforge (examples, tile sets...): never written."""


def is_shipped(path: str | Path) -> bool:
    """Whether `path` lies inside the shipped resources folder (symlinks resolved)."""
    try:
        Path(path).resolve().relative_to(SHIPPED_DIR.resolve())
    except ValueError:
        return False
    return True


class WindowFiles:
    """Mixin of `MainWindow`: the project file it shows, its autosave and the
    mesh export (``self`` is the QMainWindow)."""

    # -- files ---------------------------------------------------------------------------------
    def _replace_document(self, new_doc: GraphDocument, path: Path | None, name: str) -> None:
        self.worker.cancel()
        self._generation += 1
        self.last_report = None
        self.doc.replace_with(new_doc)
        # stateful nodes (a repainted Grow) resume from the results stored in the file;
        # this also drops the replaced document's, which its node ids must not inherit
        state_warnings = self.worker.evaluator.import_state(self.doc.node_state)
        for warning in [*new_doc.load_warnings, *state_warnings]:
            self.log("warning", warning)
        self.undo.clear()
        self.project_path = path
        self.display_name = name
        self._dirty_without_undo = False
        self.editor.set_results({})
        self.inspector.set_results({}, {})
        self.update_viewport()
        self._update_title()
        QtCore.QTimer.singleShot(0, self.editor.fit_view)

    def maybe_save(self) -> bool:
        """Ask about unsaved changes; False if the user cancelled (or saving failed)."""
        if not self.is_modified:
            return True
        answer = self.prompter.ask_unsaved(self.display_name)
        if answer == "save":
            return self.save()
        return answer == "discard"

    def _tileset_edits_may_go(self) -> bool:
        """Unsaved edits in the Tile Sets dock are only dropped when the user says so."""
        return not self.tileset_editor.unsaved or self.tileset_editor.confirm(
            "Unsaved tile set", "The Tile Sets dock has unsaved edits. Quit and discard them?")

    def new_project(self) -> bool:
        if not self.maybe_save():
            return False
        self._replace_document(GraphDocument(), None, "untitled")
        self.autosave.clear()
        self.log("info", "new project")
        return True

    def open_project(self, path: str | Path | None = None, *, ask: bool = True) -> bool:
        """Open a project file; on a bad file show why and keep the open project untouched."""
        if ask and not self.maybe_save():
            return False
        if path is None:
            start = str(self.project_path.parent) if self.project_path else str(Path.cwd())
            path = self.prompter.open_path("Open project", start)
            if not path:
                return False
        path = Path(path)
        if is_shipped(path):
            return self.open_example(path, ask=False)   # asked above; a shipped file is never the project
        try:
            new_doc = load_project(path)
        except ProjectFileError as exc:
            self.show_error("Cannot open project", str(exc))
            return False
        self._replace_document(new_doc, path, path.name)
        self.autosave.clear()
        self.log("info", f"opened {path}")
        return True

    def open_example(self, path: str | Path, *, ask: bool = True) -> bool:
        """Open an example as an untitled copy (saving never overwrites the shipped file)."""
        if ask and not self.maybe_save():
            return False
        path = Path(path)
        try:
            new_doc = load_project(path)
        except ProjectFileError as exc:
            self.show_error("Cannot open example", str(exc))
            return False
        self._replace_document(new_doc, None, f"{path.stem} (example)")
        self.log("info", f"opened example {path.name}")
        return True

    def save(self) -> bool:
        if self.project_path is None:
            return self.save_as()
        return self._write(self.project_path)

    def save_as(self, path: str | Path | None = None) -> bool:
        if path is None:
            start = str(self.project_path) if self.project_path else str(Path.cwd() / self._untitled_file_name())
            path = self.prompter.save_path("Save project as", start)
            if not path:
                return False
        return self._write(Path(path))

    def _untitled_file_name(self) -> str:
        name = self.display_name.removesuffix(" (example)").strip()
        return f"{name or 'untitled'}.json"

    def _refuse_shipped(self, title: str, path: Path) -> bool:
        """Show why `path` is not written and return True when it is inside resources/."""
        if not is_shipped(path):
            return False
        self.show_error(title, f"cannot write {str(path)!r}: it is inside Mesoforge's shipped resources folder "
                               f"({SHIPPED_DIR}), which is never overwritten; choose a path outside it")
        return True

    def _take_node_state(self) -> None:
        """Put the evaluator's stateful-node results into the document before writing it."""
        self.doc.node_state = self.worker.evaluator.export_state()

    def _write(self, path: Path) -> bool:
        if self._refuse_shipped("Cannot save project", path):
            return False
        try:
            self._take_node_state()
            save_project(self.doc, path)
        except (OSError, ValueError) as exc:
            self.show_error("Cannot save project", f"cannot save {str(path)!r}: {exc}")
            return False
        self.project_path = path
        self.display_name = path.name
        self._dirty_without_undo = False
        self.undo.set_clean()
        self.autosave.clear()
        self.log("info", f"saved {path}")
        self._update_title()
        return True

    def export_mesh(self, path: str | Path | None = None, *, wait: bool | None = None) -> bool:
        """Write the shown solid (with the current tiling) as STL / OBJ / PLY / 3MF, off the
        GUI thread with progress and cancel (`ui.export_task`).  Bad input is refused before
        anything is written.  `wait` (default: True when `path` is given, as scripts and
        tests do; False from the menu) processes events until the export ended and returns
        whether the file was written; otherwise True means the export started."""
        from .export_task import check_export

        solid = self.current_solid()
        if solid is None:
            self.show_error("Export mesh", "there is no solid to export yet: evaluate a graph with an Object node")
            return False
        if wait is None:
            wait = path is not None
        if path is None:
            stem = self.project_path.stem if self.project_path else "mesoforge"
            path = self.prompter.save_path("Export mesh", str(Path.cwd() / f"{stem}.stl"),
                                           ";;".join(MESH_FILTERS))
            if not path:
                return False
        path = Path(path)
        if path.suffix.lower() not in MESH_FILTERS.values():
            self.show_error("Export mesh", f"cannot export {str(path)!r}: expected a file ending in "
                                           f"{', '.join(MESH_FILTERS.values())}")
            return False
        if self._refuse_shipped("Export mesh", path):
            return False
        exporter = self.mesh_export()
        if exporter.busy:
            self.show_error("Export mesh", f"cannot export {str(path)!r}: another export is running; "
                                           "wait for it or press Cancel export in the status bar")
            return False
        tiles = self.viewport.tiles if solid.periodic else 1
        try:
            tiles3, path = check_export(solid, (tiles,) * 3, path)
        except ValueError as exc:       # a MemoryLimitError too: refused before meshing
            self.show_error("Export mesh", str(exc))
            return False
        exporter.start(solid, tiles3, path)
        return exporter.wait() if wait else True

    def mesh_export(self):
        """The window's `ui.export_task.MeshExport` (made on first use)."""
        exporter = getattr(self, "_mesh_export", None)
        if exporter is None:
            from .export_task import MeshExport

            exporter = MeshExport(self.statusBar(), self.log, self.show_error, parent=self)
            # stop a running export before the window releases its widgets
            self.viewport.closing.connect(exporter.shutdown)
            self._mesh_export = exporter
        return exporter

    def stop_export(self) -> None:
        """Cancel a running export and join its thread (window shutdown)."""
        exporter = getattr(self, "_mesh_export", None)
        if exporter is not None:
            exporter.shutdown()

    # -- autosave / recovery --------------------------------------------------------------
    def autosave_now(self) -> bool:
        if not self.is_modified:
            return False
        try:
            self._take_node_state()
            self.autosave.save(self.doc, self.project_path)
        except (OSError, ValueError) as exc:
            self.log("warning", f"autosave failed: {exc}")
            return False
        return True

    def offer_recovery(self) -> bool:
        """If a crashed session left autosaves, offer to recover the newest; True if recovered."""
        items = self.autosave.find_recoverable()
        if not items:
            return False
        recovered = False
        if self.prompter.ask_recover(items):
            item = items[0]
            try:
                new_doc = self.autosave.load(item)
            except ProjectFileError as exc:
                self.show_error("Cannot recover", str(exc))
            else:
                path = Path(item.original_path) if item.original_path else None
                if path is not None and is_shipped(path):
                    path = None                      # an example's copy: Save asks where
                self._replace_document(new_doc, path, path.name if path else "recovered")
                self._dirty_without_undo = True
                self._update_title()
                self.log("info", f"recovered autosave of {item.display_name}")
                recovered = True
        for item in items:
            self.autosave.discard(item)
        if recovered:
            self.autosave_now()
        return recovered
