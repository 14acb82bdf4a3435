"""Where "Arrange nodes" puts the nodes: columns by depth, wrapped into bands."""

from __future__ import annotations

from engine.graph import GraphError


def arrange_positions(doc, *, columns: int, column_width: float = 240.0,
                      row_height: float = 100.0) -> dict[str, tuple[float, float]] | None:
    """``{node id: (x, y)}`` scene positions: a node's column is its depth (longest
    path from a source), ``columns`` columns per band, bands stacked downwards;
    None when the graph has a cycle."""
    try:
        order = doc.topological_order()
    except GraphError:
        return None
    depth: dict[str, int] = {}
    for nid in order:
        depth[nid] = max((depth[e.src] + 1 for e in doc.inputs_of(nid) if e.src in depth), default=0)
    levels: dict[int, list[str]] = {}
    for nid in order:
        levels.setdefault(depth[nid], []).append(nid)
    positions, top = {}, 0.0
    n_levels = max(levels, default=-1) + 1
    for band_start in range(0, n_levels, columns):
        band = [levels.get(d, []) for d in range(band_start, min(band_start + columns, n_levels))]
        for k, ids in enumerate(band):
            for r, nid in enumerate(ids):
                positions[nid] = (k * column_width, top + r * row_height)
        top += max(len(ids) for ids in band) * row_height + 0.6 * row_height
    return positions
