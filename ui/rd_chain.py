"""The chain the RD dock follows and what it reads from it: TopOpt -> RDFields -> RDGrow -> RDCompile.

Which chain is `engine.graph.query.chain_around`'s answer (the dock's
``pick_rd_chain``); these helpers read the chain's latest outputs, its
brush data and its one-line caption.  No widgets.
"""

from __future__ import annotations

import numpy as np

from engine.geometry.values import Field
from engine.rd.values import RDFieldsValue, RDStructuresValue

CHAIN = ("TopOpt", "RDFields", "RDGrow", "RDCompile")
NO_CHAIN = "select an RD node (TopOpt, RDFields, RDGrow or RDCompile) or evaluate a graph with one"


def fields_of_design(design) -> RDFieldsValue:
    """A TopOpt design shown as RD fields (no infill map yet) while no RDFields follows it."""
    rho = np.asarray(design.rho)
    principal = getattr(design, "principal", None)
    return RDFieldsValue(rho, design.rotation, np.zeros_like(rho), design.lo, design.hi,
                         magnitude=None if principal is None else np.abs(principal))


def _value(outputs, node_id, kind):
    for value in (outputs.get(node_id) or {}).values() if node_id else ():
        if isinstance(value, kind):
            return value
    return None


def chain_outputs(outputs: dict, chain: dict) -> tuple:
    """(design, fields, structures, compiled) of ``chain`` in the evaluation ``outputs``
    (node id -> {port: value}); each None when missing (`fields_of_design` may stand in
    for missing fields)."""
    design = _value(outputs, chain["TopOpt"], object) if chain["TopOpt"] else None
    return (design, _value(outputs, chain["RDFields"], RDFieldsValue),
            _value(outputs, chain["RDGrow"], RDStructuresValue), _value(outputs, chain["RDCompile"], Field))


def painted(doc, chain: dict) -> tuple:
    """The brush data of ``chain`` in the document now: (RDGrow edits, RDFields gamma_c), as text."""
    nodes = doc.nodes if doc is not None else {}
    grow, fnode = nodes.get(chain["RDGrow"] or ""), nodes.get(chain["RDFields"] or "")
    return (repr(grow.params.get("edits")) if grow is not None else None,
            repr(fnode.params.get("gamma_c")) if fnode is not None else None)


def caption_text(nodes: dict, chain: dict, fields, structures, growth_grid) -> str:
    """The dock's caption: the chain's ids, its grids and how much is painted."""
    ids = [f"<b>{chain[k]}</b>" for k in CHAIN if chain[k]]
    if not ids:
        return NO_CHAIN
    parts = [" → ".join(ids)]
    if fields is not None:
        parts.append("fields " + " × ".join(str(n) for n in fields.grid_shape[::-1]))
    if growth_grid is not None:
        parts.append("growth " + " × ".join(str(n) for n in growth_grid[::-1]))
    if fields is None and structures is None:
        parts.append("not evaluated yet")
    grow, fnode = nodes.get(chain["RDGrow"] or ""), nodes.get(chain["RDFields"] or "")
    if grow is not None:
        parts.append(f"{len(grow.params.get('edits', []))} edit(s)")
    if fnode is not None:
        parts.append(f"{len(fnode.params.get('gamma_c', []))} solid stroke(s)")
    return ", ".join(parts)
