"""Independent adjacency checker: connectors and rules read straight from the
tile set JSON, orientations re-derived here (not taken from TileSet.allowed).

Each tile's transform is validated against its geometry (the file's
polylines moved by the transform must be the tile's polylines), then the
face permutation is recomputed from face normals.
"""

from __future__ import annotations

import json

import numpy as np

FACES = {2: ["+x", "+y", "-x", "-y"], 3: ["+x", "+y", "+z", "-x", "-y", "-z"]}


def _normal(face: str, ndim: int) -> np.ndarray:
    v = np.zeros(ndim, dtype=int)
    v["xyz".index(face[1])] = 1 if face[0] == "+" else -1
    return v


def _file_block(path, name):
    data = json.loads(open(path, encoding="utf-8").read())
    return data, next(b for b in data["blocks"] if b["name"] == name)


def file_connectors(path, block: str) -> dict:
    """Face -> label as the file states it (arms give "1"/"0")."""
    data, spec = _file_block(path, block)
    if "connectors" in spec:
        return {f: str(v) for f, v in spec["connectors"].items()}
    return {f: ("1" if f in spec["arms"] else "0") for f in FACES[data["dim"]]}


def file_polylines(path, block: str) -> list:
    data, spec = _file_block(path, block)
    ndim = data["dim"]
    j = np.array(spec.get("junction", [0.5] * ndim), dtype=float)
    polys = [np.array([j, 0.5 + 0.5 * _normal(f, ndim)]) for f in spec.get("arms", [])]
    return polys + [np.array(p, dtype=float) for p in spec.get("polylines", [])]


def tile_connectors(path, tile) -> dict:
    """Connectors of one orientation, re-derived from the file and checked geometry."""
    R = np.asarray(tile.transform, dtype=int)
    ndim = R.shape[0]
    moved = [(p - 0.5) @ R.T + 0.5 for p in file_polylines(path, tile.block)]
    assert len(moved) == len(tile.polylines)
    for a, b in zip(moved, tile.polylines):
        assert np.allclose(a, b, atol=1e-9), f"{tile.name}: geometry does not match transform"
    base = file_connectors(path, tile.block)
    out = {}
    for f, label in base.items():
        g = R @ _normal(f, ndim)
        gname = next(h for h in FACES[ndim] if np.array_equal(_normal(h, ndim), g))
        out[gname] = label
    return out


def pair_ok(path, tileset, a: int, b: int, face: str, _cache={}) -> bool:
    """May tile ``b`` sit across face ``face`` of tile ``a``? From the JSON only.

    Supports rules whose operands are block names or ``block@k`` names, with
    or without ``face``.
    """
    key = (path, id(tileset))
    if key not in _cache:
        data = json.loads(open(path, encoding="utf-8").read())
        conns = [tile_connectors(path, t) for t in tileset.tiles]
        _cache[key] = (data, conns)
    data, conns = _cache[key]
    ndim = data["dim"]
    opp = {f: ("-" if f[0] == "+" else "+") + f[1] for f in FACES[ndim]}
    ta, tb = tileset.tiles[a], tileset.tiles[b]
    ok = conns[a][face] == conns[b][opp[face]]

    def match(ref, tile):
        return ref == tile.block or ref == tile.name

    for rule in data.get("rules", []):
        kind = "allow" if "allow" in rule else "forbid"
        x, y = rule[kind]
        f = rule.get("face")
        hit = (match(x, ta) and match(y, tb) and (f is None or f == face)) or \
              (match(x, tb) and match(y, ta) and (f is None or f == opp[face]))
        if hit:
            ok = kind == "allow"
    return ok


def violations(path, tileset, tiles: np.ndarray, periodic: bool) -> list:
    """Every adjacent pair of non-defect cells that the JSON does not allow."""
    ndim = tiles.ndim
    bad = []
    for axis in range(ndim):
        face = "+" + "xyz"[ndim - 1 - axis]
        n = tiles.shape[axis]
        for idx in np.ndindex(*tiles.shape):
            if idx[axis] == n - 1 and not periodic:
                continue
            nb = list(idx)
            nb[axis] = (nb[axis] + 1) % n
            a, b = tiles[idx], tiles[tuple(nb)]
            if a >= 0 and b >= 0 and not pair_ok(path, tileset, int(a), int(b), face):
                bad.append((idx, tuple(nb), face))
    return bad
