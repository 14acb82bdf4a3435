"""The example gallery (start page) on the real window: every example with its
thumbnail, title, family and summary; the family filter; opening an untitled
copy; missing thumbnails rendered off the GUI thread into the cache; the
"show at startup" setting."""

from __future__ import annotations

import json
import shutil
import threading
from pathlib import Path

import pytest
from PySide6 import QtCore, QtGui

from ui.example_gallery import ALL_FAMILIES, SHOW_AT_STARTUP_KEY, ExampleGallery, show_at_startup
from ui.example_thumbnails import cached_thumbnail_path, example_info
from ui.main_window import EXAMPLES_DIR

EXAMPLE_FILES = sorted(EXAMPLES_DIR.glob("*.json"))


class FakeRenderer:
    """Writes a small PNG in the worker thread and records where it ran."""

    def __init__(self):
        self.calls: list[str] = []
        self.threads: set[int] = set()

    def __call__(self, example, png, should_stop):
        self.calls.append(Path(example).stem)
        self.threads.add(threading.get_ident())
        image = QtGui.QImage(64, 48, QtGui.QImage.Format.Format_RGB32)
        image.fill(QtGui.QColor("#336699"))
        assert image.save(str(png))


@pytest.fixture
def renderer():
    return FakeRenderer()


@pytest.fixture
def gallery(window, tmp_path, renderer, qtbot):
    g = ExampleGallery(window, cache_dir=tmp_path / "cache", renderer=renderer)
    g.show()
    qtbot.waitExposed(g)
    yield g
    g.stop_rendering()
    g.close()


def test_lists_every_example_with_family_summary_and_thumbnail(gallery, renderer, qtbot):
    assert sorted(gallery.items) == sorted(p.stem for p in EXAMPLE_FILES)
    for path in EXAMPLE_FILES:
        meta = json.loads(path.read_text())["meta"]
        text = gallery.items[path.stem].text()
        assert meta["title"] in text and meta["family"] in text and meta["summary"] in text, path.stem
    # the shipped thumbnails are fresh (tests/resources/test_thumbnails.py), so none is rendered
    qtbot.waitUntil(lambda: not gallery.runner.is_busy and not gallery.pending_thumbnails(), timeout=10000)
    assert renderer.calls == []
    assert sorted(gallery.thumbnails) == sorted(gallery.items)
    for stem in gallery.items:
        assert not gallery.items[stem].icon().isNull()


def test_family_filter(gallery):
    families = gallery.families()
    assert {"lattice", "shell & TPMS", "properties", "virtual growth"} <= set(families)
    for family in families:
        gallery.set_family(family)
        shown = gallery.visible_stems()
        expected = sorted(p.stem for p in EXAMPLE_FILES if json.loads(p.read_text())["meta"]["family"] == family)
        assert sorted(shown) == expected, family
        assert gallery.list.currentItem() is not None and not gallery.list.currentItem().isHidden()
    gallery.set_family(ALL_FAMILIES)
    assert len(gallery.visible_stems()) == len(EXAMPLE_FILES)
    with pytest.raises(ValueError, match="family 'nonsense'"):
        gallery.set_family("nonsense")


def test_opening_an_example_opens_an_untitled_copy(window, gallery, qtbot):
    shipped = (EXAMPLES_DIR / "growth_tl_2d.json").read_bytes()
    gallery.select("growth_tl_2d")
    assert "Virtual growth" in gallery.description.text()
    with qtbot.waitSignal(gallery.opened, timeout=5000) as opened:
        assert gallery.open_selected()
    assert opened.args == ["growth_tl_2d"]
    assert window.project_path is None                     # untitled: Save asks for a path
    assert window.doc.meta["example"] == "growth_tl_2d"
    assert "grow" in window.doc.nodes
    assert not gallery.isVisible()
    assert (EXAMPLES_DIR / "growth_tl_2d.json").read_bytes() == shipped


def test_missing_thumbnail_is_rendered_off_the_gui_thread_into_the_cache(window, tmp_path, renderer, qtbot):
    examples = tmp_path / "examples"
    examples.mkdir()
    shutil.copy(EXAMPLES_DIR / "bcc.json", examples / "bcc.json")
    data = json.loads((EXAMPLES_DIR / "octet.json").read_text())
    data["nodes"][0]["params"]["position"] = [0.1, 0.0, 0.0]       # changed content: the shipped PNG is stale
    (examples / "octet.json").write_text(json.dumps(data))
    cache = tmp_path / "cache"
    g = ExampleGallery(window, examples_dir=examples, cache_dir=cache, renderer=renderer)
    try:
        assert g.pending_thumbnails() == ["octet"]          # bcc's shipped thumbnail still fits
        with qtbot.waitSignal(g.thumbnail_ready, timeout=10000) as ready:
            g.show()
        assert ready.args == ["octet"]
        assert renderer.calls == ["octet"]
        assert threading.get_ident() not in renderer.threads
        png = cached_thumbnail_path(example_info(examples / "octet.json"), cache)
        assert png.is_file() and g.thumbnails["octet"] == png
    finally:
        g.stop_rendering()
        g.close()
    # a second gallery finds it in the cache and renders nothing
    again = FakeRenderer()
    g2 = ExampleGallery(window, examples_dir=examples, cache_dir=cache, renderer=again)
    try:
        assert g2.pending_thumbnails() == [] and again.calls == []
        assert g2.thumbnails["octet"] == png
    finally:
        g2.close()


def test_show_at_startup_setting(window, tmp_path, renderer):
    from app.gui import wants_start_page

    settings = QtCore.QSettings(str(tmp_path / "settings.ini"), QtCore.QSettings.Format.IniFormat)
    assert show_at_startup(settings) and show_at_startup(None)
    g = ExampleGallery(window, cache_dir=tmp_path / "cache", renderer=renderer, settings=settings)
    assert g.startup_box.isChecked()
    g.startup_box.setChecked(False)
    reread = QtCore.QSettings(str(tmp_path / "settings.ini"), QtCore.QSettings.Format.IniFormat)
    assert reread.value(SHOW_AT_STARTUP_KEY) in (False, "false")
    assert not show_at_startup(reread)
    assert not wants_start_page(None, reread)
    g.startup_box.setChecked(True)
    assert wants_start_page(None, settings)
    assert wants_start_page(str(EXAMPLES_DIR / "octet.json"), settings)    # what app.cli passes
    assert not wants_start_page(str(EXAMPLES_DIR / "bcc.json"), settings)  # a project was asked for
    g.close()


def test_file_menu_opens_the_gallery_non_modal(window, qtbot):
    assert window.act_gallery.shortcut().toString()
    window.act_gallery.trigger()
    g = window.example_gallery
    qtbot.waitExposed(g)
    assert g.isVisible() and not g.isModal()
    assert window.isEnabled()
    g.stop_rendering()
    g.close()
