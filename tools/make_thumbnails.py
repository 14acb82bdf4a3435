"""Render the example gallery's thumbnails into ``resources/examples/thumbnails``.

Each example is evaluated at preview resolution and drawn by the headless
renderer (``app.thumbnails``: VTK through EGL, no display needed) into a
256 x 192 ``<name>.png``; ``index.json`` records the content digest each PNG
was rendered from (``ui.example_thumbnails.content_digest``: nodes,
parameters, edges, not node positions), so ``tests/resources/test_thumbnails.py``
fails on a stale thumbnail. Only missing or stale thumbnails are rendered
unless ``--force``; every example runs in its own child process.

Usage::

    python tools/make_thumbnails.py                 # render what is missing or stale
    python tools/make_thumbnails.py --only octet    # these examples
    python tools/make_thumbnails.py --force         # everything
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from app.thumbnails import render_in_child  # noqa: E402
from engine.fileio import write_atomic  # noqa: E402
from ui.example_thumbnails import (EXAMPLES_DIR, INDEX_NAME, THUMBNAILS_DIR, example_info,  # noqa: E402
                                   read_index, shipped_thumbnail)


def write_index(out_dir: Path, entries: dict[str, dict]) -> None:
    text = json.dumps({"format": "mesoforge-thumbnails", "version": 1,
                       "thumbnails": dict(sorted(entries.items()))}, indent=1) + "\n"
    write_atomic(out_dir / INDEX_NAME, text.encode("utf-8"))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--examples", default=str(EXAMPLES_DIR), help="folder of the example graphs")
    parser.add_argument("--out", default=str(THUMBNAILS_DIR), help="folder of the thumbnails and index")
    parser.add_argument("--only", nargs="+", help="example names (file stems)")
    parser.add_argument("--force", action="store_true", help="render even fresh thumbnails")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    files = sorted(Path(args.examples).glob("*.json"))
    if args.only:
        unknown = sorted(set(args.only) - {p.stem for p in files})
        if unknown:
            parser.error(f"--only: no example named {', '.join(unknown)}")
        files = [p for p in files if p.stem in args.only]
    index = read_index(out)
    known = {p.stem for p in Path(args.examples).glob("*.json")}
    index = {k: v for k, v in index.items() if k in known}     # drop thumbnails of removed examples
    failed = 0
    for path in files:
        info = example_info(path)
        if not args.force and shipped_thumbnail(info, out, index) is not None:
            continue
        png = out / f"{info.stem}.png"
        start = time.perf_counter()
        try:
            render_in_child(path, png)
        except RuntimeError as exc:
            print(f"FAILED {exc}", file=sys.stderr)
            failed += 1
            continue
        index[info.stem] = {"digest": info.digest, "file": png.name}
        write_index(out, index)              # after each one: an interrupted run keeps its work
        print(f"{png}  ({time.perf_counter() - start:.1f} s)")
    for stale in sorted({p.stem for p in out.glob("*.png")} - set(index)):
        (out / f"{stale}.png").unlink()
    write_index(out, index)
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
