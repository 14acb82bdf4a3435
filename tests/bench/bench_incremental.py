"""Incremental re-evaluation after editing the last node vs full evaluation.

Run: .venv/bin/python tests/bench/bench_incremental.py [GRAPH.json] [--resolution 128]
Prints the full evaluation time, the time after editing Voxel E (everything
upstream reused), and their ratio.  Prints; asserts nothing.
"""

from __future__ import annotations

import argparse
import platform
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from engine.graph import Evaluator, SetParam, UndoStack, load_project  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("graph", nargs="?", default=str(ROOT / "resources/examples/octet.json"))
    ap.add_argument("--resolution", type=int, default=128)
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    doc = load_project(a.graph)
    stack = UndoStack(doc)
    for nid, n in doc.nodes.items():
        if n.type_name == "Object":
            stack.push(SetParam(nid, "resolution", a.resolution))
    voxel = next(nid for nid, n in doc.nodes.items() if n.type_name == "Voxel")

    Evaluator().evaluate(doc)  # JIT warm-up
    fulls, objects = [], []
    for _ in range(a.repeat):
        ev = Evaluator()
        t0 = time.perf_counter()
        r = ev.evaluate(doc)
        fulls.append(time.perf_counter() - t0)
        objects.append(sum(res.seconds for nid, res in r.results.items() if doc.nodes[nid].type_name == "Object"))
        assert r.ok, r.errors
    incs = []
    for k in range(a.repeat):
        stack.push(SetParam(voxel, "E", 1.0 + 0.1 * (k + 1)))
        t0 = time.perf_counter()
        r = ev.evaluate(doc)
        incs.append(time.perf_counter() - t0)
        assert r.ok and r.results[voxel].status == "evaluated"
    full, inc, obj = min(fulls), min(incs), min(objects)
    print(f"machine: {platform.processor() or platform.machine()}, python {platform.python_version()}")
    print(f"graph: {Path(a.graph).name}, {len(doc.nodes)} nodes, Object resolution {a.resolution}^3")
    print(f"{'what':<38}{'seconds':>10}")
    print(f"{'Object node (SDF + marching cubes)':<38}{obj:>10.4f}")
    print(f"{'full evaluation (fresh cache)':<38}{full:>10.4f}")
    print(f"{'after editing Voxel E (incremental)':<38}{inc:>10.4f}")
    print(f"ratio full / incremental: {full / inc:.0f}x")


if __name__ == "__main__":
    main()
