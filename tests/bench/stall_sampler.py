"""Which GUI-thread code runs while the heartbeat is late: a watchdog thread for the benches.

`StallSampler(heartbeat)` starts a daemon thread that, every `period` seconds,
looks at the heartbeat's last tick; while the tick is more than `late` seconds
old it reads the GUI thread's Python stack (``sys._current_frames()``) and
counts it under the current gap.  `report()` lists the gaps longer than
`late`, longest first, each with its most frequent stacks (only the frames of
this repository's ``ui/``, ``engine/`` and ``app/`` packages, plus the innermost
frame, whatever library it is in), so a bench can print where the GUI thread
spent a stall.  Sampling needs the GIL: a stall inside C code that holds it is
attributed to the Python frame that called into it.
"""

from __future__ import annotations

import collections
import sys
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
_OURS = tuple(str(ROOT / p) for p in ("ui", "engine", "app"))


def _frame_name(code) -> str:
    path = Path(code.co_filename)
    try:
        rel = path.relative_to(ROOT)
        where = str(rel.with_suffix("")).replace("/", ".")
    except ValueError:
        parts = path.parts
        where = ".".join(parts[-2:]).removesuffix(".py")
    return f"{where}:{code.co_name}"


def stack_key(frame, depth: int = 8) -> tuple[str, ...]:
    """`frame`'s stack, outermost first: this repository's frames, and of each run of
    library frames between them only its outermost and innermost (at most `depth` entries,
    the innermost kept)."""
    names, run = [], []                 # innermost first
    f = frame
    while f is not None:
        code = f.f_code
        if code.co_filename.startswith(_OURS):
            if run:
                names.append("… " + run[0] if len(run) == 1 else f"… {run[-1]} … {run[0]}")
                run = []
            names.append(_frame_name(code))
        else:
            run.append(_frame_name(code))
        f = f.f_back
    if run:
        names.append("… " + run[0] if len(run) == 1 else f"… {run[-1]} … {run[0]}")
    names = names[:depth]
    names.reverse()
    return tuple(n.replace(".venv.lib.python3.11.site-packages.", "") for n in names)


class StallSampler:
    """Samples the GUI thread's stack while `heartbeat.last` is older than `late` s."""

    def __init__(self, heartbeat, *, late: float = 0.05, period: float = 0.005):
        self.heartbeat = heartbeat
        self.late, self.period = late, period
        self.gui_id = threading.get_ident()     # made on the GUI thread
        self.gaps: list[dict] = []              # {"start", "length", "stacks": Counter}
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="stall-sampler", daemon=True)

    def __enter__(self):
        self._thread.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join(1.0)

    def _run(self) -> None:
        current, current_last = None, None
        while not self._stop.wait(self.period):
            last = self.heartbeat.last
            if last is None:
                continue
            age = time.perf_counter() - last
            if age <= self.late:
                if current is not None:
                    current["length"] = last - current_last
                    current = None
                continue
            if current is None or last != current_last:
                if current is not None:
                    current["length"] = last - current_last
                current_last = last
                current = {"start": last, "length": age, "stacks": collections.Counter()}
                self.gaps.append(current)
            current["length"] = max(current["length"], age)
            frame = sys._current_frames().get(self.gui_id)
            if frame is not None:
                current["stacks"][stack_key(frame)] += 1

    def report(self, top_gaps: int = 4, top_stacks: int = 3) -> list[str]:
        """Lines: the `top_gaps` longest gaps, each with its `top_stacks` commonest stacks."""
        lines = []
        for gap in sorted(self.gaps, key=lambda g: -g["length"])[:top_gaps]:
            total = sum(gap["stacks"].values()) or 1
            lines.append(f"    gap {1000 * gap['length']:.0f} ms ({total} samples)")
            for stack, n in gap["stacks"].most_common(top_stacks):
                lines.append(f"      {100 * n / total:3.0f}%  " + " > ".join(stack[-5:]))
        return lines
