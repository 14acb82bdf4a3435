"""Project loading: the bulk O(V + E) load against the per-edge reference.

Run: .venv/bin/python tests/bench/bench_project_load.py [--sizes 1000 4000 8000 16000] [--ref-max 4000]

Writes chain projects of N nodes (Vertex, Vertex -> EdgeChain -> Line ->
Group, the Groups chained, so the graph is as deep as it is long), times
`load_project` (best of --repeat) and, up to --ref-max nodes, the
straightforward reference: the same nodes and edges added one by one through
``_raw_connect``, whose cycle check walks the graph per edge.  Prints a table
with the ratio.  Asserts nothing about time.
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from engine.graph import Edge, GraphDocument, NodeInstance, load_project  # noqa: E402
from tests.engine.graph.test_project_files import chain_project  # noqa: E402


def reference_load(data: dict) -> GraphDocument:
    """Per-node, per-edge loading through the interactive checks."""
    doc = GraphDocument(seed=data["seed"])
    for n in data["nodes"]:
        doc._raw_add_node(NodeInstance(n["id"], n["type"], n["params"], tuple(n.get("position", (0, 0)))))
    for e in data["edges"]:
        doc._raw_connect(Edge(*e["from"], *e["to"]))
    return doc


def best(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", type=int, nargs="+", default=[1000, 4000, 8000, 16000])
    ap.add_argument("--ref-max", type=int, default=4000, help="largest size the slow reference runs on")
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    print(f"machine: {platform.machine()}, {platform.processor() or '?'}, python {platform.python_version()}")
    with tempfile.TemporaryDirectory() as d:
        warm = Path(d) / "warm.json"
        warm.write_text(json.dumps(chain_project(10)))
        load_project(warm)
        print(f"{'nodes':>7} {'edges':>7} {'load_project s':>15} {'reference s':>12} {'ratio':>7}")
        for n in a.sizes:
            data = chain_project(n)
            path = Path(d) / f"p{n}.json"
            path.write_text(json.dumps(data, indent=1))
            fast = best(lambda: load_project(path), a.repeat)
            if n <= a.ref_max:
                ref = best(lambda: reference_load(json.loads(path.read_text())), 1)
                tail = f"{ref:12.3f} {ref / fast:7.1f}"
            else:
                tail = f"{'-':>12} {'-':>7}"
            print(f"{len(data['nodes']):7d} {len(data['edges']):7d} {fast:15.3f} {tail}", flush=True)


if __name__ == "__main__":
    main()
