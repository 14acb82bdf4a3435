"""Small graphs built by commands, shared by app and UI tests."""

from __future__ import annotations

from engine.graph import AddNode, Connect, GraphDocument, UndoStack


def straight_beam_graph(*, diameter: float = 0.2, resolution: int = 32, seed: int = 0) -> GraphDocument:
    """A beam along x through the whole cell: tiled, an infinite cylinder of
    volume fraction pi * (diameter / 2)**2."""
    doc = GraphDocument(seed=seed)
    st = UndoStack(doc)
    st.push(AddNode("Vertex", {"position": [0.0, 0.5, 0.5]}, node_id="v1", position=(0, 0)))
    st.push(AddNode("Vertex", {"position": [1.0, 0.5, 0.5]}, node_id="v2", position=(0, 100)))
    st.push(AddNode("EdgeChain", node_id="e1", position=(220, 50)))
    st.push(AddNode("Line", {"thickness": [[0.0, diameter], [1.0, diameter]]}, node_id="l1", position=(440, 50)))
    st.push(AddNode("Object", {"resolution": resolution}, node_id="obj1", position=(660, 50)))
    st.push(AddNode("Voxel", node_id="vox1", position=(880, 50)))
    st.push(Connect("v1", "point", "e1", "vertices"))
    st.push(Connect("v2", "point", "e1", "vertices"))
    st.push(Connect("e1", "chain", "l1", "chains"))
    st.push(Connect("l1", "skeleton", "obj1", "skeleton"))
    st.push(Connect("obj1", "solid", "vox1", "solid"))
    return doc
