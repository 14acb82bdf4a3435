"""The start page: a gallery of the shipped examples (File › Example Gallery…).

Every example in ``resources/examples`` is listed with its thumbnail, title,
family and one-line summary; a family filter narrows the list, the selected
example's description is shown as rich text, and Open (or a double click)
opens it through the window's ``open_example``: an untitled copy, so the
shipped file is never written.

Thumbnails come from ``ui.example_thumbnails``: a shipped PNG whose digest
matches the example, else one rendered earlier into the cache directory. A
missing one is rendered on first show by the injected ``renderer(example,
png, should_stop)`` (the window's ``thumbnail_renderer``: a child process of
the headless renderer) through a `TaskRunner`, one at a time, so the GUI
thread only sets icons. The dialog is non-modal; "Show at startup" is kept in
the window's settings and read only by the plain ``mesoforge`` launch.
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable

from PySide6 import QtCore, QtGui, QtWidgets

from .example_thumbnails import EXAMPLES_DIR, ExampleInfo, cached_thumbnail_path, example_info, find_thumbnail
from .rich_text import doc_to_html
from .task_runner import TaskRunner

__all__ = ["ExampleGallery", "show_gallery", "show_at_startup", "SHOW_AT_STARTUP_KEY", "ALL_FAMILIES",
           "default_cache_dir"]

SHOW_AT_STARTUP_KEY = "gallery/show_at_startup"
ALL_FAMILIES = "All families"
ICON_SIZE = QtCore.QSize(128, 96)
FAMILY_ORDER = ("lattice", "shell & TPMS", "properties", "virtual growth", "phasor infill", "reaction diffusion")
STEM_ROLE = QtCore.Qt.ItemDataRole.UserRole

Renderer = Callable[[Path, Path, Callable[[], bool]], None]


def default_cache_dir() -> Path:
    """The user's cache directory for rendered thumbnails."""
    base = QtCore.QStandardPaths.writableLocation(QtCore.QStandardPaths.StandardLocation.CacheLocation)
    return Path(base or Path.home() / ".cache" / "mesoforge") / "thumbnails"


def show_at_startup(settings: QtCore.QSettings | None) -> bool:
    """Whether the plain launch shows the gallery (on unless turned off)."""
    if settings is None:
        return True
    value = settings.value(SHOW_AT_STARTUP_KEY, True)
    return value not in (False, "false", "0", 0)


def _placeholder(text: str) -> QtGui.QIcon:
    pix = QtGui.QPixmap(ICON_SIZE)
    pix.fill(QtGui.QColor("#3a3d42"))
    p = QtGui.QPainter(pix)
    p.setPen(QtGui.QColor("#9aa0a6"))
    p.drawText(pix.rect(), QtCore.Qt.AlignmentFlag.AlignCenter, text)
    p.end()
    return QtGui.QIcon(pix)


class ExampleGallery(QtWidgets.QDialog):
    """The example gallery of `window` (a MainWindow: ``open_example``, ``layout_settings``)."""

    thumbnail_ready = QtCore.Signal(str)          # stem
    opened = QtCore.Signal(str)                   # stem of the example opened

    def __init__(self, window, *, examples_dir: str | Path = EXAMPLES_DIR, cache_dir: str | Path | None = None,
                 renderer: Renderer | None = None, settings: QtCore.QSettings | None = None):
        super().__init__(window)
        self.setWindowTitle("Example Gallery")
        self.setModal(False)
        self.window_ = window
        self.examples_dir = Path(examples_dir)
        self.cache_dir = Path(cache_dir) if cache_dir is not None else default_cache_dir()
        self.renderer = renderer if renderer is not None else getattr(window, "thumbnail_renderer", None)
        self.settings = settings if settings is not None else getattr(window, "layout_settings", None)
        self.entries: list[ExampleInfo] = []
        self.items: dict[str, QtWidgets.QListWidgetItem] = {}
        self.thumbnails: dict[str, Path] = {}
        self.render_failures: dict[str, str] = {}
        self._queue: list[ExampleInfo] = []
        self.runner = TaskRunner(self)
        self.runner.finished.connect(self._on_rendered)
        self.runner.failed.connect(self._on_render_failed)
        self.runner.cancelled.connect(lambda _t: None)
        self._build()
        self.reload()
        window.installEventFilter(self)
        self.resize(760, 640)

    # -- widgets --------------------------------------------------------------------------------
    def _build(self) -> None:
        self.family_box = QtWidgets.QComboBox()
        self.family_box.currentTextChanged.connect(self._apply_filter)
        self.list = QtWidgets.QListWidget()
        self.list.setIconSize(ICON_SIZE)
        self.list.setWordWrap(True)
        self.list.setSpacing(4)
        self.list.setSelectionMode(QtWidgets.QAbstractItemView.SelectionMode.SingleSelection)
        self.list.currentItemChanged.connect(self._on_current)
        self.list.itemActivated.connect(lambda _item: self.open_selected())
        self.description = QtWidgets.QLabel()
        self.description.setWordWrap(True)
        self.description.setTextFormat(QtCore.Qt.TextFormat.RichText)
        self.description.setMinimumHeight(70)
        self.description.setAlignment(QtCore.Qt.AlignmentFlag.AlignTop)
        self.startup_box = QtWidgets.QCheckBox("Show at startup")
        self.startup_box.setChecked(show_at_startup(self.settings))
        self.startup_box.toggled.connect(self._on_startup_toggled)
        self.open_button = QtWidgets.QPushButton("Open")
        self.open_button.setDefault(True)
        self.open_button.setToolTip("Open the selected example as an untitled copy")
        self.open_button.clicked.connect(self.open_selected)
        close = QtWidgets.QPushButton("Close")
        close.clicked.connect(self.close)

        top = QtWidgets.QHBoxLayout()
        top.addWidget(QtWidgets.QLabel("Family:"))
        top.addWidget(self.family_box, 1)
        bottom = QtWidgets.QHBoxLayout()
        bottom.addWidget(self.startup_box)
        bottom.addStretch(1)
        bottom.addWidget(self.open_button)
        bottom.addWidget(close)
        lay = QtWidgets.QVBoxLayout(self)
        lay.addLayout(top)
        lay.addWidget(self.list, 1)
        lay.addWidget(self.description)
        lay.addLayout(bottom)

    # -- content --------------------------------------------------------------------------------
    def reload(self) -> None:
        """Read the examples folder again and list every example."""
        self.stop_rendering()
        files = sorted(self.examples_dir.glob("*.json")) if self.examples_dir.is_dir() else []
        entries = []
        for path in files:
            try:
                entries.append(example_info(path))
            except (OSError, ValueError):
                continue
        rank = {f: k for k, f in enumerate(FAMILY_ORDER)}
        self.entries = sorted(entries, key=lambda e: (rank.get(e.family, len(rank)), e.title.lower()))
        self.list.clear()
        self.items.clear()
        for info in self.entries:
            item = QtWidgets.QListWidgetItem(f"{info.title}\n{info.family} — {info.summary}")
            item.setData(STEM_ROLE, info.stem)
            item.setToolTip(doc_to_html(info.description))
            item.setSizeHint(QtCore.QSize(0, ICON_SIZE.height() + 12))
            self.list.addItem(item)
            self.items[info.stem] = item
        families = [f for f in FAMILY_ORDER if any(e.family == f for e in self.entries)]
        families += sorted({e.family for e in self.entries} - set(families))
        current = self.family_box.currentText()
        self.family_box.blockSignals(True)
        self.family_box.clear()
        self.family_box.addItems([ALL_FAMILIES] + families)
        self.family_box.setCurrentText(current if current in families else ALL_FAMILIES)
        self.family_box.blockSignals(False)
        self._apply_filter(self.family_box.currentText())
        self._load_thumbnails()

    def families(self) -> list[str]:
        return [self.family_box.itemText(k) for k in range(1, self.family_box.count())]

    def set_family(self, family: str) -> None:
        """Show only `family` (ALL_FAMILIES: every example)."""
        if self.family_box.findText(family) < 0:
            raise ValueError(f"family {family!r} is not one of {[ALL_FAMILIES] + self.families()}")
        self.family_box.setCurrentText(family)

    def visible_stems(self) -> list[str]:
        return [self.list.item(k).data(STEM_ROLE) for k in range(self.list.count())
                if not self.list.item(k).isHidden()]

    def _apply_filter(self, family: str) -> None:
        for info in self.entries:
            self.items[info.stem].setHidden(family not in (ALL_FAMILIES, "") and info.family != family)
        current = self.list.currentItem()
        if current is None or current.isHidden():
            visible = self.visible_stems()
            self.list.setCurrentItem(self.items[visible[0]] if visible else None)

    def _on_current(self, item, _previous=None) -> None:
        info = self._info(item.data(STEM_ROLE)) if item is not None else None
        self.open_button.setEnabled(info is not None)
        if info is None:
            self.description.setText("")
            return
        self.description.setText(f"<b>{info.title}</b> <span style='color:#9aa0a6'>({info.family})</span>"
                                 f"{doc_to_html(info.description)}")

    def _info(self, stem: str | None) -> ExampleInfo | None:
        return next((e for e in self.entries if e.stem == stem), None)

    def select(self, stem: str) -> None:
        self.list.setCurrentItem(self.items[stem])

    # -- opening --------------------------------------------------------------------------------
    def open_selected(self) -> bool:
        """Open the selected example as an untitled copy; the gallery closes when it opened."""
        item = self.list.currentItem()
        info = self._info(item.data(STEM_ROLE)) if item is not None else None
        if info is None:
            return False
        if not self.window_.open_example(info.path):
            return False
        self.opened.emit(info.stem)
        self.close()
        return True

    def _on_startup_toggled(self, on: bool) -> None:
        if self.settings is not None:
            self.settings.setValue(SHOW_AT_STARTUP_KEY, bool(on))
            self.settings.sync()

    # -- thumbnails -----------------------------------------------------------------------------
    def _load_thumbnails(self) -> None:
        missing = []
        for info in self.entries:
            png = find_thumbnail(info, self.cache_dir)
            if png is not None:
                self._set_thumbnail(info.stem, png)
            else:
                self.items[info.stem].setIcon(_placeholder("rendering…" if self.renderer else "no picture"))
                missing.append(info)
        self._queue = missing if self.renderer is not None else []
        if self.isVisible():
            self._render_next()

    def showEvent(self, event) -> None:
        super().showEvent(event)
        self._render_next()

    def _set_thumbnail(self, stem: str, png: Path) -> None:
        pix = QtGui.QPixmap(str(png))
        if pix.isNull():
            return
        self.thumbnails[stem] = png
        self.items[stem].setIcon(QtGui.QIcon(pix.scaled(ICON_SIZE, QtCore.Qt.AspectRatioMode.KeepAspectRatio,
                                                        QtCore.Qt.TransformationMode.SmoothTransformation)))

    def _render_next(self) -> None:
        if self.runner.is_busy or not self._queue or self.renderer is None:
            return
        info = self._queue.pop(0)
        png = cached_thumbnail_path(info, self.cache_dir)
        renderer = self.renderer

        def render(task):
            png.parent.mkdir(parents=True, exist_ok=True)
            renderer(info.path, png, lambda: task.stop_requested)
            return png

        self.runner.submit(render, data=info.stem, supersede=False)

    def _on_rendered(self, task, png) -> None:
        if task.data in self.items and Path(png).is_file():
            self._set_thumbnail(task.data, Path(png))
            self.thumbnail_ready.emit(task.data)
        QtCore.QTimer.singleShot(0, self._render_next)

    def _on_render_failed(self, task, message: str) -> None:
        self.render_failures[task.data] = message
        if task.data in self.items:
            self.items[task.data].setIcon(_placeholder("no picture"))
        QtCore.QTimer.singleShot(0, self._render_next)

    def pending_thumbnails(self) -> list[str]:
        return [e.stem for e in self._queue]

    def stop_rendering(self) -> None:
        """Drop the queue and stop (and join) a running render."""
        self._queue = []
        self.runner.shutdown()

    def eventFilter(self, obj, event) -> bool:
        if obj is self.window_ and event.type() == QtCore.QEvent.Type.Close:
            self.stop_rendering()      # the window goes: no render thread may outlive it
        return False


def show_gallery(window, **kwargs) -> ExampleGallery:
    """Show (or raise) `window`'s example gallery, non-modal."""
    gallery = getattr(window, "example_gallery", None)
    if gallery is None:
        gallery = window.example_gallery = ExampleGallery(window, **kwargs)
    gallery.show()
    gallery.raise_()
    gallery.activateWindow()
    return gallery
