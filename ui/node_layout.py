"""Where "Arrange nodes" puts the nodes: `engine.graph.layout.layered_positions`
over the document (columns by depth, rows ordered to cross fewer edges)."""

from __future__ import annotations

from engine.graph.layout import layered_positions


def arrange_positions(doc, *, column_width: float = 240.0,
                      row_height: float = 110.0) -> dict[str, tuple[float, float]]:
    """``{node id: (x, y)}`` scene positions for every node of ``doc``; the nodes
    keep their relative vertical order where crossings allow (input order is the
    order of their current y, then x)."""
    ids = sorted(doc.nodes, key=lambda n: (doc.nodes[n].position[1], doc.nodes[n].position[0], n))
    edges = [(e.src, e.dst) for e in doc.edges]
    return layered_positions(ids, edges, column_width=column_width, row_height=row_height)
