"""GIL holds of the engine: how long a pure-Python thread waits while the
engine evaluates an example and exports its 3x3x3 mesh.

Run as ``python tests/bench/bench_gil.py [--examples octet tpms_schwarz_p tpms_gyroid]
[--tiles 3] [--top 8]``.

A heartbeat thread sleeps 5 ms at a time and records the gaps between its
wake-ups; a gap far over 5 ms means another thread held the GIL (the window's
GUI thread would have stalled as long). To say who held it, the heartbeat
arms ``faulthandler.dump_traceback_later`` before every sleep: the watchdog is
a C thread that needs no GIL, so when a beat is late by more than
``--dump-ms`` it writes every thread's Python stack, i.e. the line of the
engine that is inside the long C call. No Qt; prints figures, asserts nothing.
"""

from __future__ import annotations

import argparse
import faulthandler
import os
import re
import sys
import tempfile
import threading
import time
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from engine.geometry.mesh_io import export_mesh  # noqa: E402
from engine.geometry.values import Solid  # noqa: E402
from engine.graph.evaluator import Evaluator  # noqa: E402
from engine.graph.project import load_project  # noqa: E402
from engine.tiled_mesh import tiled_arrays  # noqa: E402

EXAMPLES = ROOT / "resources" / "examples"
BEAT_S = 0.005


class Heartbeat(threading.Thread):
    """Sleeps BEAT_S; records (gap seconds, phase) per beat; arms the watchdog."""

    def __init__(self, dump_file, dump_s: float):
        super().__init__(daemon=True)
        self.gaps: list[tuple[float, str]] = []
        self.phase = "idle"
        self.stop = threading.Event()
        self._dump_file, self._dump_s = dump_file, dump_s

    def run(self) -> None:
        last = time.perf_counter()
        while not self.stop.is_set():
            faulthandler.dump_traceback_later(self._dump_s, repeat=True, file=self._dump_file)
            time.sleep(BEAT_S)
            faulthandler.cancel_dump_traceback_later()
            now = time.perf_counter()
            self.gaps.append((now - last - BEAT_S, self.phase))
            last = now


_FRAME = re.compile(r'\s+File "(.*)", line (\d+) in (\S+)')


def parse_dumps(text: str, main_ident: int) -> list[list[str]]:
    """The main thread's stacks (innermost first) from faulthandler dumps."""
    stacks, current, in_main = [], None, False
    for line in text.splitlines():
        if line.startswith(("Thread 0x", "Current thread 0x")):
            ident = int(line.split()[1 if line.startswith("Thread") else 2], 16)
            in_main = ident == main_ident
            current = [] if in_main else None
            if in_main:
                stacks.append(current)
        elif line.startswith("Timeout"):
            in_main = False
        elif in_main and current is not None:
            m = _FRAME.match(line)
            if m:
                path = os.path.relpath(m.group(1), ROOT) if m.group(1).startswith(str(ROOT)) else m.group(1)
                current.append(f"{path}:{m.group(2)} {m.group(3)}")
    return stacks


def where(stack: list[str]) -> str:
    """Innermost frame of the project (engine/ or ui/), plus the innermost frame overall."""
    own = next((f for f in stack if f.startswith(("engine/", "ui/"))), "?")
    return own if not stack or stack[0] == own else f"{own}  <- {stack[0].split('/')[-1]}"


def run_example(name: str, tiles: int, dump_ms: float, top: int) -> None:
    doc = load_project(EXAMPLES / f"{name}.json")
    with tempfile.TemporaryDirectory() as tmp:
        dump_path = Path(tmp) / "dumps.txt"
        with open(dump_path, "w") as dump_file:
            hb = Heartbeat(dump_file, dump_ms / 1000.0)
            hb.start()
            time.sleep(0.05)
            t0 = time.perf_counter()
            hb.phase = "evaluate"
            report = Evaluator().evaluate(doc)
            t_eval = time.perf_counter() - t0
            solid = next((v for outs in report.outputs.values() for v in outs.values()
                          if isinstance(v, Solid) and len(v.faces)), None)
            t_export = 0.0
            if solid is not None:
                hb.phase = "export"
                t1 = time.perf_counter()
                v, f = tiled_arrays(solid, (tiles,) * 3)
                export_mesh(v, f, Path(tmp) / "block.stl")
                t_export = time.perf_counter() - t1
            hb.phase = "idle"
            time.sleep(0.05)
            hb.stop.set()
            hb.join()
            faulthandler.cancel_dump_traceback_later()
        stacks = parse_dumps(dump_path.read_text(), threading.main_thread().ident)

    print(f"\n== {name}: evaluate {t_eval:.2f} s, export {tiles}^3 {t_export:.2f} s"
          + ("" if solid is not None else " (no solid)"))
    for phase in ("evaluate", "export"):
        gaps = sorted((g for g, p in hb.gaps if p == phase), reverse=True)
        if gaps:
            print(f"  {phase}: longest GIL wait {1000 * gaps[0]:.0f} ms; "
                  f"waits > 50 ms: {sum(g > 0.05 for g in gaps)}; > 100 ms: {sum(g > 0.1 for g in gaps)}; "
                  f"top: {', '.join(f'{1000 * g:.0f}' for g in gaps[:top])}")
    counts = defaultdict(int)
    for s in stacks:
        counts[where(s)] += 1
    if counts:
        print(f"  holders of the GIL (watchdog dumps of the main thread, one per {dump_ms:.0f} ms held):")
        for w, c in sorted(counts.items(), key=lambda kv: -kv[1])[:top]:
            print(f"    {c:4d} x {w}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--examples", nargs="+", default=["octet", "tpms_schwarz_p", "tpms_gyroid"])
    ap.add_argument("--tiles", type=int, default=3)
    ap.add_argument("--dump-ms", type=float, default=40.0,
                    help="a beat later than this dumps the stacks (ms)")
    ap.add_argument("--top", type=int, default=8)
    args = ap.parse_args()
    print(f"python {sys.version.split()[0]}, load average {os.getloadavg()[0]:.2f}, "
          f"switch interval {1000 * sys.getswitchinterval():.0f} ms")
    for name in args.examples:
        run_example(name, args.tiles, args.dump_ms, args.top)


if __name__ == "__main__":
    main()
