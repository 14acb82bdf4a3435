"""Tile sets: orientation counts, geometry, compatibility against the JSON, validation."""

import copy
import itertools
import json

import numpy as np
import pytest

from engine.growth import TILESET_DIR, block_image, load_tileset, parse_tileset
from engine.growth._symmetry import opposite

from .json_rules import FACES, file_polylines, pair_ok

BASIC = TILESET_DIR / "tl_basic.json"
EXTENDED = TILESET_DIR / "tl_extended.json"


def _counts(ts):
    return dict(zip(ts.block_names, ts.n_orientations.tolist()))


def test_basic_orientation_counts_match_paper():
    # fig. S1A: four T, four L, two -, one +
    assert _counts(load_tileset("TL+-")) == {"T": 4, "L": 4, "-": 2, "+": 1}
    for name in ("TL+-acute", "TL+-obtuse"):
        assert _counts(load_tileset(name)) == {"T": 4, "L": 4, "-": 2, "+": 1}
    assert _counts(load_tileset("TL+-OV\\")) == {"T": 4, "L": 4, "-": 2, "+": 1,
                                                 "O": 1, "V": 4, "\\": 4}


def _orbit_size(arms, ndim):
    """Number of distinct arm sets under all signed permutations (brute force)."""
    normals = {f: tuple(int(f[0] + "1") if "xyz".index(f[1]) == k else 0 for k in range(ndim))
               for f in FACES[ndim]}
    images = set()
    for perm in itertools.permutations(range(ndim)):
        for signs in itertools.product((1, -1), repeat=ndim):
            moved = []
            for f in arms:
                n = normals[f]
                moved.append(tuple(signs[r] * n[perm[r]] for r in range(ndim)))
            images.add(frozenset(moved))
    return len(images)


@pytest.mark.parametrize("name", ["cubic-beams", "cubic-beams-offset", "cubic-beams-mixed"])
def test_3d_orientation_counts_are_orbit_sizes(name):
    ts = load_tileset(name)
    data = json.loads(open(ts.source, encoding="utf-8").read())
    hand = {"+3": 1, "X": 3, "T3": 12, "Y3": 8, "L3": 12, "-3": 3}
    for spec in data["blocks"]:
        expected = _orbit_size(spec["arms"], 3)
        assert _counts(ts)[spec["name"]] == expected == hand[spec["name"].rstrip("o")]


@pytest.mark.parametrize("path", [BASIC, EXTENDED, TILESET_DIR / "tl_acute.json"])
def test_2d_orientations_are_the_dihedral_images(path):
    """Tile images = distinct rotations/flips of the base block image (numpy ops)."""
    ts = load_tileset(path)
    for block in ts.block_names:
        tiles = [ts.tiles[i] for i in ts.tiles_of(block)]
        base = block_image(tiles[0], resolution=24, line_width=4)
        expected = set()
        for k in range(4):
            for img in (np.rot90(base, k), np.rot90(base.T, k)):
                expected.add(img.tobytes())
        got = {block_image(t, resolution=24, line_width=4).tobytes() for t in tiles}
        assert got == expected and len(got) == len(tiles)


def test_base_orientation_is_the_file_geometry():
    ts = load_tileset(BASIC)
    for block in ts.block_names:
        t0 = ts.tiles[ts.tiles_of(block)[0]]
        assert t0.orientation == 0 and t0.name == f"{block}@0"
        for a, b in zip(file_polylines(BASIC, block), t0.polylines):
            np.testing.assert_allclose(a, b)


@pytest.mark.parametrize("path", [BASIC, EXTENDED, TILESET_DIR / "cubic_beams.json"])
def test_allowed_matches_brute_force_from_json(path):
    ts = load_tileset(path)
    for d, face in enumerate(ts.faces):
        for a in range(ts.n_tiles):
            for b in range(ts.n_tiles):
                assert ts.allowed[d, a, b] == pair_ok(path, ts, a, b, face), \
                    (face, ts.tile_names[a], ts.tile_names[b])
    # symmetric under swapping the pair and the face
    for d in range(len(ts.faces)):
        np.testing.assert_array_equal(ts.allowed[d], ts.allowed[opposite(d, ts.ndim)].T)


def test_l_next_to_l_is_forbidden_everywhere():
    ts = load_tileset("TL+-")
    L = ts.tiles_of("L")
    assert not ts.allowed[:, L][:, :, L].any()
    # and without the rule some L-L pairs fit by connectors
    data = json.loads(BASIC.read_text())
    data["rules"] = []
    free = parse_tileset(data)
    assert free.allowed[:, L][:, :, L].any()


def test_rules_by_orientation_and_face_override_connectors():
    data = json.loads(BASIC.read_text())
    data["rules"] = [{"forbid": ["-@0", "+"], "face": "+x"},
                     {"allow": ["-@1", "-@0"], "face": "+x"}]
    ts = parse_tileset(data)
    h, v, p = ts.tile_index("-@0"), ts.tile_index("-@1"), ts.tile_index("+@0")
    x, mx = ts.faces.index("+x"), ts.faces.index("-x")
    assert not ts.allowed[x, h, p] and not ts.allowed[mx, p, h]
    assert ts.allowed[mx, h, p]           # other side untouched: + left of - is fine
    assert ts.allowed[x, v, h] and ts.allowed[mx, h, v]   # connectors 0 vs 1, allowed by rule


def test_masks_are_packed_allowed_for_more_than_64_tiles():
    ts = load_tileset("cubic-beams-mixed")
    assert ts.n_tiles == 71 and ts.n_words == 2
    bits = np.unpackbits(ts.masks.view(np.uint8), axis=-1, bitorder="little")[..., :ts.n_tiles]
    np.testing.assert_array_equal(bits.astype(bool), ts.allowed)
    bm = np.unpackbits(ts.block_masks.view(np.uint8), axis=-1, bitorder="little")[:, :71]
    np.testing.assert_array_equal(bm.argmax(axis=0), ts.tile_block)


def test_default_weights_share_block_weight_among_orientations():
    ts = load_tileset("TL+-")
    w = ts.weights
    for b, name in enumerate(ts.block_names):
        np.testing.assert_allclose(w[ts.tiles_of(name)].sum(), 1.0)


def test_tileset_is_immutable_and_cached():
    ts = load_tileset("TL+-")
    assert load_tileset("tl_basic") is ts and load_tileset(BASIC) is ts
    with pytest.raises(ValueError):
        ts.allowed[0, 0, 0] = True
    with pytest.raises(AttributeError):
        ts.name = "other"


def _bad(mutate):
    data = json.loads(BASIC.read_text())
    mutate(data)
    return data


@pytest.mark.parametrize("mutate, words", [
    (lambda d: d["rules"].append({"forbid": ["Q", "L"]}), "'Q'"),
    (lambda d: d["rules"].append({"forbid": ["L@9", "L"]}), "'L@9'"),
    (lambda d: d["rules"].append({"forbid": ["L", "L"], "face": "up"}), "'up'"),
    (lambda d: d["rules"].append({"forbid": ["L"]}), "two names"),
    (lambda d: d["blocks"].append({"name": "Z", "polylines": [[[0, 0.5], [1, 0.5]]],
                                   "connectors": {"+x": 1, "-x": 1}}), "connectors"),
    (lambda d: d["blocks"][0].update(arms=["+x", "+w"]), "'+w'"),
    (lambda d: d["blocks"][1].update(name="T"), "'T'"),
    (lambda d: d["blocks"][0].update(weight=-1), "weight"),
    (lambda d: d["blocks"][0].update(junction=[0.5, 1.5]), "junction"),
    (lambda d: d["blocks"][0].update(symmetry="some"), "'some'"),
    (lambda d: d["blocks"][0].update(colour="red"), "colour"),
    (lambda d: d.update(dim=4), "dim"),
    (lambda d: d.update(blocks=[]), "blocks"),
])
def test_validation_names_the_problem(mutate, words):
    with pytest.raises(ValueError) as e:
        parse_tileset(_bad(mutate))
    assert words in str(e.value)


def test_unknown_set_and_bad_json(tmp_path):
    with pytest.raises(ValueError, match="no-such-set"):
        load_tileset("no-such-set")
    p = tmp_path / "broken.json"
    p.write_text("{ not json")
    with pytest.raises(ValueError, match="broken.json"):
        load_tileset(p)


def test_symmetry_modes_limit_orientations():
    data = json.loads(BASIC.read_text())
    d2 = copy.deepcopy(data)
    d2["blocks"][0]["symmetry"] = "none"
    assert parse_tileset(d2).n_orientations[0] == 1
    d2["blocks"][0]["symmetry"] = "rotations"
    assert parse_tileset(d2).n_orientations[0] == 4
