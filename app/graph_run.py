"""How a subcommand runs its method: build a small graph, evaluate it, report.

Every method subcommand (grow, study, homogenize, phasor, rd, ...) builds a
`GraphDocument` of the nodes the window would use, with the parameters the
flags set (`app.schema_flags`), and evaluates it here through the one
`Evaluator`.  Progress goes to stderr (a ``\\r`` line on a terminal, a line
every 2 s otherwise); a node that fails on checked arguments becomes
`GraphRunFailed` (exit code 1) whose message names the flag that set the
parameter the node refused.
"""

from __future__ import annotations

import sys
import time
from typing import Mapping

from engine.graph import AddNode, Connect, Evaluator, GraphDocument, UndoStack


class GraphRunFailed(RuntimeError):
    """The graph did not evaluate on checked arguments (exit code 1).

    node_id, where : the failed node and the parameter or port it refused ("" when unknown)
    """

    def __init__(self, message: str, node_id: str = "", where: str = ""):
        super().__init__(message)
        self.node_id, self.where = node_id, where


def build(seed: int, nodes: Mapping[str, tuple[str, dict]], edges=()) -> GraphDocument:
    """A document of ``{node id: (type name, params)}`` joined by
    ``(src, src port, dst, dst port)`` edges, through the same undo commands
    as the window (so parameters are checked by their schemas)."""
    doc = GraphDocument(seed=seed)
    stack = UndoStack(doc)
    for node_id, (type_name, params) in nodes.items():
        stack.push(AddNode(type_name, dict(params), node_id=node_id))
    for src, src_port, dst, dst_port in edges:
        stack.push(Connect(src, src_port, dst, dst_port))
    return doc


def part_of(doc: GraphDocument, node_id: str) -> tuple[dict, list]:
    """``(nodes, edges)`` in `build`'s form for ``node_id`` and everything it depends
    on in ``doc`` (same ids and parameters, topological order), so that a
    subcommand can add its own nodes below a project's and the project's stored
    states still apply."""
    from engine.graph.query import upstream_closure

    keep = upstream_closure(doc, node_id)
    nodes = {nid: (doc.nodes[nid].type_name, dict(doc.nodes[nid].params))
             for nid in doc.topological_order() if nid in keep}
    edges = [(e.src, e.src_port, e.dst, e.dst_port) for e in doc.edges if e.dst in keep]
    return nodes, edges


def stderr_progress(stream=None):
    """An ``on_progress(node_id, fraction)`` printing to ``stream`` (stderr)."""
    stream = sys.stderr if stream is None else stream
    tty = stream.isatty()
    state = {"node": None, "t": 0.0}

    def cb(node_id, fraction):
        now = time.perf_counter()
        if node_id == state["node"] and now - state["t"] < (0.1 if tty else 2.0) and fraction < 1.0:
            return
        state["node"], state["t"] = node_id, now
        print(f"{chr(13) if tty else ''}  {node_id}: {100 * fraction:5.1f}%", end="" if tty else "\n",
              file=stream, flush=True)
    return cb


def end_progress_line(stream=None) -> None:
    """End a ``\\r`` progress line (after the run or on Ctrl-C)."""
    stream = sys.stderr if stream is None else stream
    if stream.isatty():
        print(file=stream)


def evaluate(doc: GraphDocument, *, flag_of: Mapping[str, Mapping[str, str]] | None = None,
             evaluator: Evaluator | None = None, quiet: bool = False, cancel=None, targets=None):
    """Evaluate ``doc`` (only what ``targets`` need, if given); the EvalReport, or
    GraphRunFailed naming the first failed node's error and (via
    ``flag_of[type name][parameter]``) the flag that set it, else the parameter
    (``error [parameter]``); ``quiet`` prints no progress (stderr kept for refusals)."""
    ev = evaluator or Evaluator()
    report = ev.evaluate(doc, targets=targets, on_progress=None if quiet else stderr_progress(), cancel=cancel)
    if not quiet:
        end_progress_line()
    if not report.ok:
        failed = [r for r in report.results.values() if r.status == "failed" and r.error]
        if not failed:
            raise GraphRunFailed("evaluation did not finish" if not report.cancelled else "cancelled")
        first = failed[0]
        node = doc.nodes[first.node_id]
        where = first.where or ""
        flag = (flag_of or {}).get(node.type_name, {}).get(where, "")
        text = f"{flag}: {first.error}" if flag else f"{first.error}{f' [{where}]' if where else ''}"
        raise GraphRunFailed(text, first.node_id, where)
    return report
