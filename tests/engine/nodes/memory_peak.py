"""The traced peak of an evaluation: what memory-estimate tests compare an estimate with."""

from __future__ import annotations

import tracemalloc

from engine.graph import Evaluator


def evaluate_traced(doc, **kwargs):
    """(report, peak bytes traced by tracemalloc) of evaluating `doc`."""
    tracemalloc.start()
    try:
        report = Evaluator().evaluate(doc, **kwargs)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    return report, peak
