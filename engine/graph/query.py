"""Which nodes a dock works on: one rule for "the node(s) around the selection".

Every dock asks the same question — which node of the kinds I edit belongs
to what the user selected — and gets the same answer from here:

1. the selected node itself, if it is of a wanted kind;
2. else the nearest wanted node above the selection (breadth first, inputs
   in connection order), so selecting a Voxel node under a Grow node shows
   that growth;
3. else the previous choice, while it is still in the document and wanted;
4. else the last wanted node in topological order (the end of the graph).

`pick_node` answers it for one node (``accept`` decides what is wanted:
a type or what the node's last outputs hold); `chain_around` extends the
pick along a chain of node types joined by edges (TopOpt → RDFields →
RDGrow → RDCompile, PhasorFields → PhasorNoise → PhasorSlice).

Plain functions of a `GraphDocument`; no Qt, no family knowledge.
"""

from __future__ import annotations

from typing import Callable, Iterable, Sequence

Accept = Callable[[str], bool]


def type_of(doc, node_id: str | None) -> str | None:
    """The type name of ``node_id`` in ``doc``, None when absent."""
    if doc is None or not node_id:
        return None
    node = doc.nodes.get(node_id)
    return None if node is None else node.type_name


def of_types(doc, types: Iterable[str]) -> Accept:
    """An ``accept`` predicate: the node's type is one of ``types``."""
    wanted = frozenset(types)
    return lambda node_id: type_of(doc, node_id) in wanted


def nearest_upstream(doc, start: str, accept: Accept) -> str | None:
    """The nearest node above ``start`` (breadth first, inputs in connection order)
    that ``accept`` takes; ``start`` itself is not considered."""
    if doc is None or start not in doc.nodes:
        return None
    seen, frontier = {start}, [start]
    while frontier:
        nxt = []
        for nid in frontier:
            for e in doc.inputs_of(nid):
                if e.src in seen:
                    continue
                seen.add(e.src)
                if accept(e.src):
                    return e.src
                nxt.append(e.src)
        frontier = nxt
    return None


def downstream_of_type(doc, node_id: str | None, type_name: str) -> str | None:
    """The first node (in document order) of ``type_name`` fed directly by ``node_id``."""
    if doc is None or not node_id:
        return None
    below = {e.dst for e in doc.outputs_of(node_id)}
    return next((n for n, node in doc.nodes.items() if n in below and node.type_name == type_name), None)


def upstream_of_type(doc, node_id: str | None, type_name: str, port: str | None = None) -> str | None:
    """The first node of ``type_name`` (in connection order) feeding ``node_id``
    (through ``port`` if given)."""
    if doc is None or not node_id:
        return None
    return next((e.src for e in doc.inputs_of(node_id, port) if type_of(doc, e.src) == type_name), None)


def pick_node(doc, selected: str | None, accept: Accept, *, previous: str | None = None) -> str | None:
    """The wanted node for ``selected`` by the module's rule (see above), or None."""
    if doc is None:
        return None
    if selected in doc.nodes:
        if accept(selected):
            return selected
        above = nearest_upstream(doc, selected, accept)
        if above is not None:
            return above
    if previous in doc.nodes and accept(previous):
        return previous
    try:
        order = doc.topological_order()
    except Exception:          # a cycle mid-edit: document order will do
        order = list(doc.nodes)
    return next((n for n in reversed(order) if accept(n)), None)


def chain_around(doc, selected: str | None, chain: Sequence[str], *,
                 previous: str | None = None) -> dict[str, str | None]:
    """``{type name: node id or None}`` for the chain of ``chain`` types (upstream
    first) that holds the node `pick_node` finds for ``selected``: from it, edges
    are followed up (first matching input) and down (first matching consumer in
    document order)."""
    found: dict[str, str | None] = dict.fromkeys(chain)
    start = pick_node(doc, selected, of_types(doc, chain), previous=previous)
    if start is None:
        return found
    k = list(chain).index(type_of(doc, start))
    found[chain[k]] = start
    for i in range(k, 0, -1):
        found[chain[i - 1]] = upstream_of_type(doc, found[chain[i]], chain[i - 1])
    for i in range(k, len(chain) - 1):
        found[chain[i + 1]] = downstream_of_type(doc, found[chain[i]], chain[i + 1])
    return found


def upstream_closure(doc, node_id: str) -> set[str]:
    """``node_id`` and every node it depends on (what must evaluate for it)."""
    keep, stack = set(), [node_id]
    while stack:
        nid = stack.pop()
        if nid not in keep:
            keep.add(nid)
            stack.extend(e.src for e in doc.inputs_of(nid))
    return keep
