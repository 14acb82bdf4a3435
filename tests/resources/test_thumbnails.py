"""The gallery's shipped thumbnails: one per example, rendered from the example's
current content (digest in resources/examples/thumbnails/index.json), small."""

from __future__ import annotations

import json

import pytest

from ui.example_thumbnails import (INDEX_NAME, THUMBNAILS_DIR, content_digest, example_info, read_index,
                                   shipped_thumbnail)

from .example_files import EXAMPLES_DIR

FILES = sorted(EXAMPLES_DIR.glob("*.json"))
SIZE = (256, 192)
MAX_BYTES = 80_000


def test_index_lists_exactly_the_examples():
    index = read_index()
    assert sorted(index) == sorted(p.stem for p in FILES), \
        "run tools/make_thumbnails.py to render the missing thumbnails / drop removed ones"
    assert sorted(p.name for p in THUMBNAILS_DIR.glob("*.png")) == sorted(e["file"] for e in index.values())
    assert json.loads((THUMBNAILS_DIR / INDEX_NAME).read_text())["format"] == "mesoforge-thumbnails"


@pytest.mark.parametrize("path", FILES, ids=[p.stem for p in FILES])
def test_thumbnail_is_not_stale(path):
    png = shipped_thumbnail(example_info(path))
    assert png is not None, f"{path.stem}: thumbnail missing or stale; run tools/make_thumbnails.py"
    from PIL import Image
    with Image.open(png) as img:
        assert img.size == SIZE
        colours = img.convert("L").getextrema()
    assert colours[1] - colours[0] > 50, f"{path.stem}: the thumbnail is blank"
    assert png.stat().st_size < MAX_BYTES


def test_digest_ignores_positions_and_meta_but_not_parameters_or_edges():
    project = json.loads((EXAMPLES_DIR / "octet.json").read_text())
    base = content_digest(project)
    moved = json.loads(json.dumps(project))
    moved["nodes"][0]["position"] = [999.0, -5.0]
    moved["meta"]["summary"] = "another summary"
    assert content_digest(moved) == base
    changed = json.loads(json.dumps(project))
    changed["nodes"][0]["params"]["position"] = [0.1, 0.0, 0.0]
    assert content_digest(changed) != base
    rewired = json.loads(json.dumps(project))
    rewired["edges"] = rewired["edges"][::-1]
    assert content_digest(rewired) != base
    reseeded = dict(project, seed=1)
    assert content_digest(reseeded) != base
