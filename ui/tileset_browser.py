"""The tile-set browser of the Tile Sets dock: shipped and user sets in a tree.

Reading the folders (every set file is parsed) is lazy: :meth:`TileSetBrowser.refresh`
only notes what to list while the browser is hidden, and the list is read when it
is shown or a row is asked for (``fills`` counts the readings).
"""

from __future__ import annotations

from pathlib import Path

from PySide6 import QtCore, QtGui, QtWidgets

from engine.growth.tileset_edit import browse_tilesets

PATH_ROLE = QtCore.Qt.ItemDataRole.UserRole


class TileSetBrowser(QtWidgets.QTreeWidget):
    """Rows "Shipped" and "User (folder)", one child per set file (name, dim, blocks);
    a file that does not parse is shown red with its error as tooltip."""

    def __init__(self, parent=None):
        super().__init__(parent)
        self.setHeaderLabels(["Tile set", "dim", "blocks"])
        self.setRootIsDecorated(True)
        self.fills = 0
        self._wanted: tuple[Path, object] | None = None

    def refresh(self, folder: Path, current=None) -> None:
        """List the shipped sets and those in ``folder``; select the file ``current``
        (now if the browser is visible, else when it is shown or a row is asked for)."""
        self._wanted = (Path(folder), current)
        if self.isVisible():
            self.ensure_listed()

    def ensure_listed(self) -> None:
        """Read the folders now if a refresh waits."""
        if self._wanted is not None:
            folder, current = self._wanted
            self._wanted = None
            self._fill(folder, current)

    def showEvent(self, event: QtGui.QShowEvent) -> None:
        super().showEvent(event)
        self.ensure_listed()

    def _fill(self, folder: Path, current) -> None:
        self.fills += 1
        self.blockSignals(True)
        self.clear()
        groups = {True: QtWidgets.QTreeWidgetItem(["Shipped"]),
                  False: QtWidgets.QTreeWidgetItem([f"User ({folder})"])}
        self.addTopLevelItems(list(groups.values()))
        for entry in browse_tilesets(folder):
            item = QtWidgets.QTreeWidgetItem(
                [entry.name, str(entry.dim or "?"), str(entry.n_blocks or "?")])
            item.setData(0, PATH_ROLE, str(entry.path))
            item.setToolTip(0, entry.error or str(entry.path))
            if entry.error:
                item.setForeground(0, QtGui.QBrush(QtGui.QColor("#c03030")))
            groups[entry.shipped].addChild(item)
            if current is not None and Path(entry.path) == Path(current):
                self.setCurrentItem(item)
        self.expandAll()
        self.resizeColumnToContents(0)
        self.blockSignals(False)

    def item_named(self, name: str) -> QtWidgets.QTreeWidgetItem | None:
        """The row of the set called ``name`` (shipped first)."""
        self.ensure_listed()
        flags = QtCore.Qt.MatchFlag.MatchExactly | QtCore.Qt.MatchFlag.MatchRecursive
        rows = [i for i in self.findItems(name, flags, 0) if i.data(0, PATH_ROLE)]
        return rows[0] if rows else None
