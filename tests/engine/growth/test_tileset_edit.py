"""Tile-set editing: adjacency against hand-derived tables, rules, renames,
refusals, saving outside resources/, and growth with an edited set."""

import copy
import json

import numpy as np
import pytest

from engine.growth import TILESET_DIR, grow_tiling, load_tileset, parse_tileset
from engine.growth.tileset_edit import (TileSetDraft, TileSetEditError, add_block, add_rule,
                                        block_adjacency, browse_tilesets, connectors_from_geometry,
                                        explain_adjacency, format_polylines, move_rule, parse_point,
                                        parse_polylines, read_document, remove_block,
                                        remove_rule, rename_block, save_path_for, save_tileset,
                                        set_name, set_weight, tileset_json, user_tileset_dir)

from .json_rules import violations

FACES = ("+x", "+y", "-x", "-y")

# One straight block "-" (arms -x, +x): "-@0" horizontal, "-@1" vertical.
WIRE = {"name": "wire", "dim": 2, "blocks": [{"name": "-", "arms": ["-x", "+x"]}]}
# A cap "C" (one orientation): a member to the +x edge midpoint, so +x is
# derived as "1"; the other faces carry "c", which nothing else carries.
CAP = dict(polylines=[[[0.5, 0.5], [1.0, 0.5]]], connectors={"+y": "c", "-x": "c", "-y": "c"},
           symmetry="none")

# Written out by hand from the labels:
#   -@0: +x 1, +y 0, -x 1, -y 0      -@1: +x 0, +y 1, -x 0, -y 1
#   C@0: +x 1, +y c, -x c, -y c
# b may sit across face f of a when a's label on f equals b's on the opposite face.
HAND = {
    "+x": {"-@0": {"-@0"}, "-@1": {"-@1"}, "C@0": {"-@0"}},
    "+y": {"-@0": {"-@0"}, "-@1": {"-@1"}, "C@0": {"C@0"}},
    "-x": {"-@0": {"-@0", "C@0"}, "-@1": {"-@1"}, "C@0": set()},
    "-y": {"-@0": {"-@0"}, "-@1": {"-@1"}, "C@0": {"C@0"}},
}


def _allowed_sets(ts):
    return {f: {a: {b for b in ts.tile_names if ts.allowed[d, ts.tile_index(a), ts.tile_index(b)]}
                for a in ts.tile_names}
            for d, f in enumerate(ts.faces)}


def _basic():
    return read_document(TILESET_DIR / "tl_basic.json")


@pytest.fixture
def user_dir(tmp_path, monkeypatch):
    folder = tmp_path / "user_sets"
    monkeypatch.setenv("MESOFORGE_TILESET_DIR", str(folder))
    return folder


def _shipped_snapshot():
    return {p.name: p.read_bytes() for p in sorted(TILESET_DIR.iterdir())}


# ------------------------------------------------------------------ blocks and adjacency

def test_added_block_adjacency_matches_hand_table():
    doc = add_block(WIRE, "C", **CAP)
    assert doc["blocks"][-1]["connectors"] == {"+x": "1", "+y": "c", "-x": "c", "-y": "c"}
    ts = parse_tileset(doc)
    assert ts.tile_names == ("-@0", "-@1", "C@0")
    assert _allowed_sets(ts) == HAND
    # across its +x face the cap takes the horizontal '-' and nothing else
    verdicts = explain_adjacency(ts, "C", "-", "+x")
    assert [(v.b, v.allowed, v.rule) for v in verdicts] == [("-@0", True, None), ("-@1", False, None)]
    assert "differ" in verdicts[1].reason and "'1'" in verdicts[1].reason


def test_block_adjacency_counts_by_hand():
    ts = load_tileset("TL+-")
    allowed, total = block_adjacency(ts, "+x")
    # T tiles' (+x, -x) labels: T@0 (1,1), T@1 (0,1), T@2 (1,1), T@3 (1,0):
    # 3 x 3 pairs of "1" plus 1 x 1 pair of "0"
    assert allowed[0, 0] == 10 and total[0, 0] == 16
    assert allowed[1, 1] == 0          # L next to L forbidden
    assert total[3, 3] == 1 and allowed[3, 3] == 1


def test_forbid_rule_removes_exactly_the_named_pairs():
    before = parse_tileset(add_block(WIRE, "C", **CAP))
    doc = add_rule(add_block(WIRE, "C", **CAP), "forbid", "C", "-@0", face="+x")
    after = parse_tileset(doc)
    diff = np.argwhere(before.allowed != after.allowed)
    c, h = after.tile_index("C@0"), after.tile_index("-@0")
    assert sorted(map(tuple, diff.tolist())) == [(0, c, h), (2, h, c)]
    v = explain_adjacency(after, "C@0", "-@0", "+x")[0]
    assert not v.allowed and v.rule == 0 and v.connectors_match
    assert "rule 1" in v.reason


def test_verdicts_agree_with_parsed_allowed_on_shipped_sets():
    for name in ("TL+-", "TL+-OV\\", "cubic-beams"):
        ts = load_tileset(name)
        for face in ts.faces:
            for a in ts.block_names:
                for v in explain_adjacency(ts, a, ts.block_names[-1], face):
                    rule = ts.rules[v.rule] if v.rule is not None else None
                    expected = v.connectors_match if rule is None else "allow" in rule
                    assert v.allowed == expected, v


def test_connectors_derived_from_arms_and_polylines():
    got = connectors_from_geometry(2, arms=["-x"], polylines=[[[0.5, 0.5], [0.5, 0.0]]])
    assert got == {"+x": "0", "+y": "0", "-x": "1", "-y": "1"}
    got3 = connectors_from_geometry(3, polylines=[[[0.5, 0.5, 0.5], [0.5, 0.5, 1.0]]])
    assert got3 == {"+x": "0", "+y": "0", "+z": "1", "-x": "0", "-y": "0", "-z": "0"}
    with pytest.raises(TileSetEditError, match=r"face \+y at \[0\.25, 1\.0\]"):
        connectors_from_geometry(2, polylines=[[[0.5, 0.5], [0.25, 1.0]]])
    # previews mark such a face instead of refusing
    assert connectors_from_geometry(2, polylines=[[[0.5, 0.5], [0.25, 1.0]]],
                                    off_centre="?")["+y"] == "?"
    # off-centre touch is fine once that face's label is given
    assert connectors_from_geometry(2, polylines=[[[0.5, 0.5], [0.25, 1.0]]],
                                    skip=["+y"]) == {"+x": "0", "-x": "0", "-y": "0"}


def test_arms_only_block_keeps_format_derivation():
    doc = add_block(_basic(), "Y", arms=["+x", "+y"], junction=[0.25, 0.25])
    spec = doc["blocks"][-1]
    assert "connectors" not in spec and spec["junction"] == [0.25, 0.25]
    assert parse_tileset(doc).n_orientations[-1] == 4


# ------------------------------------------------------------------ rename, remove, weights

def test_rename_updates_rules_and_tile_operands():
    doc = add_rule(_basic(), "allow", "L@1", "T", face="+y")
    new = rename_block(doc, "L", "Ell")
    assert [b["name"] for b in new["blocks"]] == ["T", "Ell", "-", "+"]
    assert new["rules"][0]["forbid"] == ["Ell", "Ell"]
    assert new["rules"][1]["allow"] == ["Ell@1", "T"]
    a, b = parse_tileset(doc), parse_tileset(new)
    assert np.array_equal(a.allowed, b.allowed)


def test_remove_block_with_rules_is_refused_unless_asked():
    doc = _basic()
    with pytest.raises(TileSetEditError, match=r"rule 1 \(forbid L next to L"):
        remove_block(doc, "L")
    new = remove_block(doc, "L", drop_rules=True)
    assert [b["name"] for b in new["blocks"]] == ["T", "-", "+"] and new["rules"] == []
    assert [b["name"] for b in remove_block(doc, "+")["blocks"]] == ["T", "L", "-"]


def test_weight_and_rule_order():
    doc = set_weight(_basic(), "T", 3.0)
    ts = parse_tileset(doc)
    assert np.allclose(ts.weights[ts.tiles_of("T")], 0.75)
    doc = add_rule(doc, "allow", "L", "L", face="+x")
    assert parse_tileset(doc).allowed[0, ts.tile_index("L@0"), ts.tile_index("L@2")]
    moved = move_rule(doc, 1, 0)       # the forbid now comes last and wins
    assert not parse_tileset(moved).allowed[0, ts.tile_index("L@0"), ts.tile_index("L@2")]
    assert remove_rule(moved, 1)["rules"] == [{"allow": ["L", "L"], "face": "+x"}]


@pytest.mark.parametrize("edit, message", [
    (lambda d: add_block(d, "T", arms=["+x"]), r"already a block named 'T'"),
    (lambda d: add_block(d, "Q", polylines=[[[0.5, 0.5], [1.5, 0.5]]], connectors=dict.fromkeys(FACES, 0)),
     r"block 'Q'.*polylines\[0\].*\[0\.0, 1\.0\]"),
    (lambda d: add_block(d, "Q@1", arms=["+x"]), r"without '@'"),
    (lambda d: add_block(d, "Q", connectors={"+z": "1"}), r"unknown faces \['\+z'\]"),
    (lambda d: add_rule(d, "forbid", "Q", "L"), r"unknown block or tile 'Q'"),
    (lambda d: add_rule(d, "forbid", "T", "L", face="+z"), r"'face' must be one of"),
    (lambda d: add_rule(d, "prefer", "T", "L"), r"kind must be one of"),
    (lambda d: set_weight(d, "T", -1.0), r"block 'T': 'weight'"),
    (lambda d: set_weight(d, "Z", 1.0), r"there is no block 'Z'"),
    (lambda d: remove_rule(d, 5), r"rule index must be in \[0, 0\]"),
    (lambda d: rename_block(d, "T", "L"), r"already a block named 'L'"),
    (lambda d: set_name(d, " "), r"non-empty"),
])
def test_invalid_edits_are_refused_and_change_nothing(edit, message):
    doc = _basic()
    before = copy.deepcopy(doc)
    with pytest.raises(TileSetEditError, match=message):
        edit(doc)
    assert doc == before


def test_edits_never_mutate_their_input():
    doc = _basic()
    before = copy.deepcopy(doc)
    add_block(doc, "E", polylines=[[[0.5, 0.5], [1.0, 0.5]]])
    rename_block(doc, "L", "Ell")
    add_rule(doc, "forbid", "T", "T")
    remove_block(doc, "L", drop_rules=True)
    set_weight(doc, "T", 2.0)
    assert doc == before


# ------------------------------------------------------------------ draft (editor undo)

def test_draft_undo_redo_and_dirty():
    draft = TileSetDraft(_basic(), source=TILESET_DIR / "tl_basic.json")
    assert draft.shipped and not draft.dirty and draft.error == ""
    original = draft.data
    draft.apply("add E", add_block, "E", polylines=[[[0.5, 0.5], [1.0, 0.5]]])
    draft.apply("forbid E E", add_rule, "forbid", "E", "E")
    edited = draft.data
    assert draft.dirty and draft.undo_text() == "forbid E E"
    with pytest.raises(TileSetEditError):
        draft.apply("bad", add_rule, "forbid", "E", "nope")
    assert draft.data == edited and draft.undo_text() == "forbid E E"
    assert draft.undo() and draft.undo() and not draft.undo()
    assert draft.data == original and not draft.dirty
    assert draft.redo() and draft.redo()
    assert draft.data == edited and draft.tileset.n_blocks == 5


def test_draft_of_invalid_file_reports_error(tmp_path):
    p = tmp_path / "bad.json"
    p.write_text(json.dumps({"name": "bad", "dim": 2, "blocks": [{"name": "X"}]}))
    draft = TileSetDraft.open(p)
    assert draft.tileset is None and "block 'X'" in draft.error


# ------------------------------------------------------------------ saving

def test_user_dir_env_and_default(monkeypatch, tmp_path):
    monkeypatch.setenv("MESOFORGE_TILESET_DIR", str(tmp_path))
    assert user_tileset_dir() == tmp_path
    monkeypatch.delenv("MESOFORGE_TILESET_DIR")
    monkeypatch.setenv("HOME", str(tmp_path))
    assert user_tileset_dir() == tmp_path / ".local/share/mesoforge/tilesets"


def test_saving_never_touches_shipped_sets(user_dir):
    snapshot = _shipped_snapshot()
    doc = _basic()
    with pytest.raises(TileSetEditError, match="shipped folder"):
        save_tileset(set_name(doc, "mine"), TILESET_DIR / "mine.json")
    with pytest.raises(TileSetEditError, match="shipped folder"):
        save_tileset(doc, TILESET_DIR / "tl_basic.json", overwrite=True)
    with pytest.raises(TileSetEditError, match="belongs to a shipped set"):
        save_tileset(doc)
    draft = TileSetDraft.open(TILESET_DIR / "tl_basic.json")
    draft.apply("rename", set_name, "TL+- mine")
    path = draft.save()
    assert path == user_dir / "TL_-_mine.json" and not draft.shipped and not draft.dirty
    with pytest.raises(TileSetEditError, match="already exists"):
        save_tileset(draft.data)
    assert save_tileset(draft.data, overwrite=True) == path
    assert _shipped_snapshot() == snapshot
    assert [e.name for e in browse_tilesets() if not e.shipped] == ["TL+- mine"]


def test_save_path_avoids_other_sets_with_the_same_slug(user_dir):
    a = save_tileset(set_name(_basic(), "a+b"))
    b_path = save_path_for("a-b")
    assert a.name == "a_b.json" and b_path.name == "a-b.json"
    c_path = save_path_for("a b")
    assert c_path.name == "a_b_2.json"
    assert save_path_for("a+b") == a


def test_tileset_json_round_trips():
    for p in TILESET_DIR.glob("*.json"):
        doc = read_document(p)
        assert json.loads(tileset_json(doc)) == doc


def test_saved_edited_set_grows_tilings_that_obey_the_edits(user_dir):
    doc = add_block(_basic(), "E", polylines=[[[0.5, 0.5], [1.0, 0.5]]], weight=0.5)
    doc = add_rule(doc, "forbid", "E", "E")
    doc = add_rule(doc, "forbid", "E", "+", face="+x")
    doc = rename_block(set_name(doc, "TL+-E"), "L", "Ell")
    path = save_tileset(doc)
    ts = load_tileset(path)
    assert ts.source == str(path) and dict(zip(ts.block_names, ts.n_orientations)) == \
        {"T": 4, "Ell": 4, "-": 2, "+": 1, "E": 4}
    seen_e = False
    for seed in range(3):
        tiling = grow_tiling(ts, (12, 12), rng=seed, periodic=seed == 2)
        tiles = np.asarray(tiling.tiles)
        assert violations(str(path), ts, tiles, tiling.periodic) == []
        blocks = np.where(tiles >= 0, ts.tile_block[np.maximum(tiles, 0)], -1)
        e, ell, plus = (ts.block_index(n) for n in ("E", "Ell", "+"))
        seen_e |= bool((blocks == e).any())
        # checked by hand: no E beside E and no Ell beside Ell, along either axis
        for bad in (e, ell):
            assert not ((blocks[:, :-1] == bad) & (blocks[:, 1:] == bad)).any()
            assert not ((blocks[:-1, :] == bad) & (blocks[1:, :] == bad)).any()
        # "+" never sits across the stub face (+x) of E@0
        e0 = ts.tile_index("E@0")
        assert not ((tiles[:, :-1] == e0) & (blocks[:, 1:] == plus)).any()
    assert seen_e


def test_typed_polylines_parse_and_format_back():
    text = "0.5 0.5; 1 0.5\n\n0.5, 0.5; 0.5 0; 0 0"
    polys = parse_polylines(text, 2)
    assert polys == [[[0.5, 0.5], [1.0, 0.5]], [[0.5, 0.5], [0.5, 0.0], [0.0, 0.0]]]
    assert parse_polylines(format_polylines(polys), 2) == polys
    with pytest.raises(TileSetEditError, match=r"line 1 needs at least 2 points"):
        parse_polylines("0.5 0.5", 2)
    with pytest.raises(TileSetEditError, match=r"line 2: '0.5 x' is not 2 numbers"):
        parse_polylines("0 0; 1 1\n0.5 x; 1 1", 2)
    assert parse_point("0.1 0.2 0.3", 3, "junction") == [0.1, 0.2, 0.3]
