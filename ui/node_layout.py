"""Where "Arrange nodes" puts the nodes: `engine.graph.layout.layered_positions`
over the document (columns by depth, rows ordered to cross fewer edges), the
columns wrapped into bands so the graph reads largest in the editor's view
(`engine.graph.layout.fit_columns`)."""

from __future__ import annotations

from engine.graph.layout import fit_columns, layered_positions


def arrange_positions(doc, *, column_width: float = 240.0, row_height: float = 110.0,
                      view: tuple[float, float] | None = None,
                      node_size: tuple[float, float] = (180.0, 80.0)) -> dict[str, tuple[float, float]]:
    """``{node id: (x, y)}`` scene positions for every node of ``doc``; the nodes
    keep their relative vertical order where crossings allow (input order is the
    order of their current y, then x). With ``view`` (the editor's width, height in
    pixels) long chains of columns wrap into bands that fit it best."""
    ids = sorted(doc.nodes, key=lambda n: (doc.nodes[n].position[1], doc.nodes[n].position[0], n))
    edges = [(e.src, e.dst) for e in doc.edges]
    bands = None
    if view is not None and ids:
        bands = fit_columns(ids, edges, view, column_width=column_width, row_height=row_height,
                            node_size=node_size)
    return layered_positions(ids, edges, column_width=column_width, row_height=row_height, max_columns=bands)
