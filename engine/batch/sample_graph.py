"""A study sample as a graph: TileSet → Grow → TilingProperties.

Each sample of a study is the same small graph the window would hold, its
Grow node's ``seed`` parameter set to the sample's seed (so the document
seed plays no part), evaluated by the one `engine.graph.Evaluator`. Growth
and homogenization run in the nodes (`engine.nodes.growth`), never here.

`study_document` builds that graph; `evaluate_study_graph` evaluates it on
one BLAS and one numba thread and returns the tiling and stiffness values.
"""

from __future__ import annotations

import re
from contextlib import contextmanager

from engine.progress import Cancelled

from .blas_threads import blas_threads
from .hints_text import format_hints

__all__ = ["TILESET_ID", "GROW_ID", "PROPS_ID", "study_document", "evaluate_study_graph",
           "GraphSampleError", "check_tileset"]

# the ids the window gives the first node of each type (``code`` + 1)
TILESET_ID, GROW_ID, PROPS_ID = "ts1", "grow1", "tprop1"


class GraphSampleError(RuntimeError):
    """The sample's graph did not evaluate; the message is the failed node's
    error without the node prefix, ``"<ExceptionType>: <message>"``.
    ``value`` is the grown TilingValue when only the homogenization failed."""

    def __init__(self, message: str, value=None):
        super().__init__(message)
        self.value = value


def check_tileset(tileset) -> dict:
    """TileSet node parameters for ``tileset`` (ValueError when it has no file)."""
    from engine.nodes.growth import tileset_params

    return tileset_params(tileset)


def grow_params(config, hints, seed: int) -> dict:
    """The Grow node parameters of a sample (hints as text, ``seed`` explicit)."""
    return {"size": [int(s) for s in config.shape[::-1]], "periodic": bool(config.periodic),
            "hints": format_hints(hints), "availability": float(config.availability or 0.0),
            "seed": int(seed)}


def properties_params(config) -> dict:
    """The TilingProperties node parameters of a study configuration."""
    return {"E": float(config.E), "nu": float(config.nu), "resolution": int(config.resolution),
            "line_width": float(config.line_width or 0.0), "radius": float(config.radius),
            "void": config.void}


def study_document(config, hints, seed: int, *, document_seed: int = 0):
    """The GraphDocument of one sample (nodes TILESET_ID → GROW_ID → PROPS_ID),
    built through the undo commands as the window builds it (parameters
    checked by their schemas: ParamError on a value the node refuses)."""
    from engine.graph import AddNode, Connect, GraphDocument, UndoStack
    import engine.nodes  # noqa: F401  (registers the node types)

    doc = GraphDocument(seed=document_seed)
    stack = UndoStack(doc)
    stack.push(AddNode("TileSet", check_tileset(config.tileset), node_id=TILESET_ID))
    stack.push(AddNode("Grow", grow_params(config, hints, seed), node_id=GROW_ID))
    stack.push(AddNode("TilingProperties", properties_params(config), node_id=PROPS_ID))
    stack.push(Connect(TILESET_ID, "tileset", GROW_ID, "tileset"))
    stack.push(Connect(GROW_ID, "tiling", PROPS_ID, "tiling"))
    return doc


@contextmanager
def _one_thread():
    """One BLAS and one numba thread: a row is the same bits on every scheduler."""
    import numba

    old = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        with blas_threads(1):
            yield
    finally:
        numba.set_num_threads(old)


_PREFIX = re.compile(r"^node '[^']*' \([^)]*\): ")
_TYPED = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*(Error|Exception|Warning): ")


def _sample_error(message: str) -> str:
    text = _PREFIX.sub("", message or "evaluation failed")
    return text if _TYPED.match(text) else f"ValueError: {text}"


def evaluate_study_graph(doc, *, progress=None):
    """Evaluate a `study_document`: ``(TilingValue, Stiffness)``.

    progress : ``(done, total) -> bool``, polled while the nodes run; False
        cancels (raises engine.progress.Cancelled).
    Raises GraphSampleError when a node fails (its message, as the row keeps it).
    """
    from engine.graph import CancelToken, Evaluator

    token = CancelToken()

    def on_progress(_node, fraction):
        if progress is not None:
            answer = progress(fraction, 1.0)
            if answer is not None and not answer:
                token.cancel()

    with _one_thread():
        report = Evaluator().evaluate(doc, cancel=token, on_progress=on_progress)
    if report.cancelled:
        raise Cancelled("study sample cancelled")
    if not report.ok:
        failed = [r for r in report.results.values() if r.status == "failed"]
        grown = report.outputs.get(GROW_ID, {}).get("tiling")
        raise GraphSampleError(_sample_error(failed[0].error if failed else ""), grown)
    return report.outputs[GROW_ID]["tiling"], report.outputs[PROPS_ID]["stiffness"]
