"""`mesoforge grow`: virtual growth from the command line, through the graph.

    mesoforge grow TILESET --size 20x20[x10] [--no-periodic] [--seed S] --out tiling.json
                   [--png tiling.png] [--hints T=1,L=1,+=2,-=1] [--availability N]
                   [--tiling-seed T] [--json]

The command builds the graph the window would hold, TileSet → Grow (→ Tiling
Image for ``--png``), with `app.graph_run.build` and evaluates it: the tiling
is the Grow node's. ``--seed`` is the DOCUMENT seed (as in ``mesoforge rd``
and ``eval``): the tiling seed is derived from it and the node id unless
``--tiling-seed`` gives one. The flags that set node parameters come from
the Grow node's schema (`app.schema_flags`): their defaults are the node's
(periodic on) and an out-of-range value is refused with the schema's range.
TILESET is a set name from resources/tilesets (``TL+-``), a file stem
(``tl_basic``) or a path to a tile-set JSON file.
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

from app.flags import FlagError

# the ids the window gives the first node of each type
TILESET_ID, GROW_ID, IMAGE_ID = "ts1", "grow1", "timg1"
GROW_FLAGS = {"size": "--size", "periodic": "--periodic", "hints": "--hints",
              "availability": "--availability", "seed": "--tiling-seed"}
_flags = None        # the ParamFlags of the Grow node's flags (set by add_parser)


def add_parser(sub) -> None:
    """Register ``grow`` on the subparsers ``sub``."""
    from app.schema_flags import add_param_flags

    global _flags
    g = sub.add_parser("grow", help="grow an irregular tiling by virtual growth")
    g.add_argument("tileset", help="tile set name (resources/tilesets) or JSON file")
    _flags = add_param_flags(g, "Grow", GROW_FLAGS, help_extra={
        "size": "NXxNY (2D set) or NXxNYxNZ (3D set)",
        "seed": "overrides the seed derived from --seed"}, required=("size",))
    g.add_argument("--seed", type=int, default=0,
                   help="document seed (default 0); the tiling seed is derived from it and the "
                        "Grow node's id, as in a document")
    g.add_argument("--out", required=True, help="tiling file to write (tiling.json)")
    g.add_argument("--png", help="also write the pixel image (2D; black = solid)")
    g.add_argument("--json", action="store_true", help="print a JSON summary")


def tileset_node(text: str):
    """(TileSet, TileSet node parameters) for the TILESET argument; FlagError-like
    refusal (ValueError naming TILESET) when it does not load."""
    from engine.growth import load_tileset
    from engine.nodes.growth import tileset_params

    try:
        ts = load_tileset(text)
        return ts, tileset_params(text)
    except ValueError as exc:
        raise ValueError(f"TILESET {text!r}: {exc}") from None


def check_size(flag: str, text: str, size, ts) -> None:
    """Refuse a size whose length is not the set's dimension or that exceeds
    the Grow node's cell limit (MAX_CELLS)."""
    from engine.nodes.growth import MAX_CELLS

    if len(size) != ts.ndim:
        want = "NXxNY" if ts.ndim == 2 else "NXxNYxNZ"
        raise FlagError(flag, text, f"the tile set is {ts.ndim}D, expected {want}")
    if math.prod(size) > MAX_CELLS:
        raise FlagError(flag, text, f"{math.prod(size)} cells is more than {MAX_CELLS}",
                        f"at most {MAX_CELLS} cells")


def check_hints(flag: str, text, ts) -> None:
    from engine.batch import parse_hints
    try:
        parse_hints(text or "", ts)
    except ValueError as exc:
        raise FlagError(flag, None, str(exc)) from None


def grow_graph(seed: int, ts_params: dict, grow_params: dict, *, image: bool = False):
    """The document the window would hold: TileSet → Grow (→ Tiling Image)."""
    from app.graph_run import build

    nodes = {TILESET_ID: ("TileSet", ts_params), GROW_ID: ("Grow", grow_params)}
    edges = [(TILESET_ID, "tileset", GROW_ID, "tileset")]
    if image:
        nodes[IMAGE_ID] = ("TilingImage", {})
        edges.append((GROW_ID, "tiling", IMAGE_ID, "tiling"))
    return build(seed, nodes, edges)


def png_bytes(image) -> bytes:
    """PNG of a Tiling Image field's values: black = solid (so `mesoforge
    homogenize tiling.png` reads it back as material)."""
    import io

    import numpy as np
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(np.where(np.asarray(image) > 0, 0, 255).astype(np.uint8)).save(buf, format="PNG")
    return buf.getvalue()


def run(args) -> int:
    """``mesoforge grow``: exit 0, 1 (the graph failed), 2 (bad input)."""
    from app.flags import distinct_outputs, memory_value, output_path
    from app.graph_run import GraphRunFailed, evaluate
    from app.schema_flags import param_values
    from engine.graph import node_type
    from engine.growth import realised_probabilities, save_tiling

    output_path("--out", args.out, (".json",))
    output_path("--png", args.png, (".png",))
    distinct_outputs(("--out", args.out), ("--png", args.png))
    ts, ts_params = tileset_node(args.tileset)
    given = param_values(args, _flags)
    check_size("--size", args.size, given["size"], ts)
    check_hints("--hints", given.get("hints"), ts)
    if args.seed < 0:
        raise FlagError("--seed", args.seed, "expected an integer >= 0", "0, 1, 2, ...")
    if args.png and ts.ndim != 2:
        raise FlagError("--png", args.png, f"tile set {ts.name!r} is 3D; images are for 2D tilings",
                        "--png with a 2D tile set")
    grow = node_type("Grow")
    params = grow.validate_params(given)
    memory_value("--size", args.size, grow.memory_estimate(params, {"tileset": ts}), lower="--size")
    doc = grow_graph(args.seed, ts_params, given, image=bool(args.png))
    t0 = time.perf_counter()
    try:
        report = evaluate(doc, flag_of={"Grow": GROW_FLAGS}, quiet=not sys.stderr.isatty())
    except GraphRunFailed as exc:
        print(f"mesoforge grow: {exc}", file=sys.stderr)
        return 1
    seconds = time.perf_counter() - t0
    tv = report.outputs[GROW_ID]["tiling"]
    tiling = tv.tiling
    try:
        save_tiling(args.out, tiling, tv.tileset)
        if args.png:
            Path(args.png).write_bytes(png_bytes(report.outputs[IMAGE_ID]["image"].values))
    except OSError as exc:
        print(f"mesoforge grow: cannot write output: {exc}", file=sys.stderr)
        return 1
    _report(args, ts, params, tiling, realised_probabilities(tiling, ts), seconds)
    return 0


def _report(args, ts, params, tiling, probs, seconds) -> None:
    from engine.batch import parse_hints

    shape = list(tiling.shape)
    out = {"tileset": ts.name, "size": args.size, "shape": shape, "seed": args.seed,
           "tiling_seed": tiling.seed, "periodic": bool(params["periodic"]),
           "hints": parse_hints(params["hints"], ts), "availability": params["availability"] or None,
           "n_defects": tiling.n_defects, "complete": bool(tiling.stats.get("complete", True)),
           "realised_probabilities": dict(zip(ts.block_names, map(float, probs))),
           "seconds": round(seconds, 4), "out": str(Path(args.out).resolve()),
           "png": str(Path(args.png).resolve()) if args.png else None}
    if args.json:
        print(json.dumps(out, indent=1))
    else:
        pr = ", ".join(f"{b} {p:.3f}" for b, p in out["realised_probabilities"].items())
        print(f"grew {ts.name} {args.size} (seed {args.seed}, tiling seed {tiling.seed}) in "
              f"{seconds:.3f} s: {tiling.n_defects} defects; realised probabilities {pr}; "
              f"wrote {args.out}")
