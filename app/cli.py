"""The `mesoforge` command.

    mesoforge                      open the window with an example (headless: render it)
    mesoforge PROJECT.json         open a project in the window
    mesoforge eval GRAPH.json [--out cell.stl] [--tile 3 3 3] [--node ID] [--resolution N] [--json]
    mesoforge render GRAPH.json --png out.png [--tile 3 3 3]
    mesoforge homogenize PROJECT.json|INPUT [--E 1 --nu 0.45] [--resolution N] [--res N] [--json]
    mesoforge grow TILESET --size 20x20 --out tiling.json [--png t.png] [--hints T=1,+=2] [--json]
    mesoforge study TILESET [--hints ...] [--n 100] [--out study.csv] [--scheduler ADDR] [--json]
    mesoforge phasor PROJECT.json [--slice z=MM --png out.png] [--json] [--gcode out.gcode] [--printability] [--node ID]
    mesoforge rd --preset cantilever|lbeam|bridge|mbb3d [--res WxH[xD]] [--grow-res WxH[xD]] --out OUT.png|OUT.stl
                 [--fields FILE.npz|.vti] [--seed N] [--json]
    mesoforge sdf GRAPH.json --render OUT.png [--size WxH] [--step fixed|bijection|adaptive] [--camera ...]
                 [--paths N] [--json]  |  --voxels N --out OUT.stl|OUT.npy [--node ID] [--json]
    mesoforge reconstruct GRAPH.json --node ID --exemplar FILE [--algorithm cmaes|powell|basinhopping|shgo]
                 [--budget SECONDS] [--fit NAME=LO:HI ...] [--out FITTED.json] [--json]

Exit codes: 0 done; 1 a node failed on valid input; 2 bad input, refused
before any work starts or any file is written, with one line on stderr
``mesoforge <cmd>: --flag VALUE: reason (allowed: range)`` (ranges from the
node schemas, sizes from the node types' memory estimates against the budget
of engine.memory: the available memory, or MESOFORGE_MEMORY_LIMIT such as
``2G``); 130 Ctrl-C, one line, no traceback.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

RESOURCES = Path(__file__).resolve().parent.parent / "resources"
DEFAULT_EXAMPLE = RESOURCES / "examples" / "octet.json"


def has_display() -> bool:
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


COMMANDS = ("eval", "render", "homogenize", "grow", "study", "phasor", "rd", "sdf", "reconstruct")


class _Refused(ValueError):
    """Bad input that is not one flag's value (an unreadable project): exit 2."""


def _fail(msg: str, code: int = 2, cmd: str | None = None) -> int:
    print(f"mesoforge{' ' + cmd if cmd else ''}: {msg}", file=sys.stderr)
    return code


def _load(path: str):
    from engine.graph import ProjectFileError, load_project
    try:
        return load_project(path), None
    except ProjectFileError as exc:
        return None, str(exc)


def _progress_printer(enabled: bool):
    if not enabled:
        return None
    last = {"node": None}

    def cb(node_id: str, fraction: float) -> None:
        if node_id != last["node"]:
            last["node"] = node_id
        print(f"\r  {node_id}: {100 * fraction:5.1f}%", end="", file=sys.stderr, flush=True)
    return cb


def _tiles(tiles, flag: str = "--tile") -> tuple:
    from engine.tiled_mesh import MAX_TILES, check_tiles
    from app.flags import FlagError

    try:
        return check_tiles(tiles)
    except ValueError:
        raise FlagError(flag, list(tiles), "out of range", f"integers in [1, {MAX_TILES}]") from None


def _checked_graph(graph: str, tiles, *, resolution=None, node=None, tile_flag="--tile", tile_value=None):
    """Load ``graph`` and refuse, before evaluating it, a --resolution, --node or
    --tile that the graph cannot take or whose memory estimate exceeds the budget."""
    from app.evaluation import GraphMemoryError, check_graph_memory, graph_tiling_estimate, override_resolution
    from app.flags import FlagError, memory_value, schema_value

    if resolution is not None:
        resolution = schema_value("--resolution", resolution, "Object", "resolution")
    doc, err = _load(graph)
    if doc is None:
        raise _Refused(err)
    if node is not None and node not in doc.nodes:
        raise FlagError("--node", node, "no such node", ", ".join(doc.nodes) or "none: the graph is empty")
    if resolution is not None:
        override_resolution(doc, resolution)
    try:
        check_graph_memory(doc)
    except GraphMemoryError as exc:
        if resolution is not None and exc.type_name == "Object":
            from app.flags import memory_error
            raise memory_error("--resolution", resolution, exc, lower="--resolution") from None
        raise _Refused(f"{graph}: {exc}") from None
    memory_value(tile_flag, list(tiles) if tile_value is None else tile_value, graph_tiling_estimate(doc, tiles),
                 lower=f"{tile_flag} or the Object resolution" if tile_value is None else "the Object resolution")
    return doc


def _tiled(solid, tiles, flag: str = "--tile"):
    from engine.tiled_mesh import tiled_mesh
    from app.flags import memory_error
    from engine.memory import MemoryLimitError

    try:
        return tiled_mesh(solid, tiles)
    except MemoryLimitError as exc:
        raise memory_error(flag, list(tiles), exc, lower=f"{flag} or the Object resolution") from None


def cmd_eval(args) -> int:
    from app.evaluation import evaluate_document, report_json, result_node, solid_of
    from app.flags import FlagError, output_path
    from engine.geometry.mesh_io import SUPPORTED_SUFFIXES, export_mesh

    try:
        output_path("--out", args.out, SUPPORTED_SUFFIXES)
        tiles = _tiles(args.tile)
        doc = _checked_graph(args.graph, tiles, resolution=args.resolution, node=args.node)
    except (FlagError, _Refused) as exc:
        return _fail(str(exc), cmd="eval")
    report = evaluate_document(doc, on_progress=_progress_printer(not args.json and sys.stderr.isatty()))
    out = report_json(doc, report)
    code = 0 if report.ok else 1
    nid = result_node(doc, report, args.node)
    solid = solid_of(report, nid) if nid else None
    if solid is not None:
        try:
            mesh = _tiled(solid, tiles)
        except FlagError as exc:
            return _fail(str(exc), cmd="eval")
        out["result_node"] = nid
        out["mesh"] = mesh.summary
        if args.out is not None:
            try:
                export_mesh(mesh.vertices, mesh.faces, args.out)
            except (ValueError, OSError) as exc:
                return _fail(f"--out {args.out}: cannot write: {exc}", 1, cmd="eval")
            out["mesh"]["path"] = str(Path(args.out).resolve())
    elif args.out is not None:
        out.setdefault("warnings", []).append(f"no solid result to export; {args.out} was not written")
        print(f"mesoforge eval: --out {args.out}: no solid result to export; nothing written", file=sys.stderr)
        code = 1
    if args.json:
        print(json.dumps(out, indent=1, default=float))
    else:
        for n in out["nodes"]:
            extra = f"  {n['error']}" if "error" in n else ""
            print(f"{n['id']:>10} {n['type']:<12} {n['status']:<10} {n['seconds'] * 1000:9.1f} ms{extra}")
        if "mesh" in out:
            m = out["mesh"]
            print(f"mesh: {m['vertex_count']} vertices, {m['face_count']} faces, "
                  f"watertight={m['watertight']}, volume fraction={m['volume_fraction']:.4f}"
                  + (f", written to {m['path']}" if "path" in m else ""))
    return code


def check_render_args(graph: str, png: str, mesh_out: str | None = None, tiles=(1, 1, 1), *,
                      tile_flag: str = "--tile"):
    """The loaded graph once every render argument is checked (FlagError or
    _Refused otherwise); nothing is evaluated or written."""
    from app.flags import distinct_outputs, output_path
    from engine.geometry.mesh_io import SUPPORTED_SUFFIXES

    output_path("--png", png, (".png",))
    output_path("--out", mesh_out, SUPPORTED_SUFFIXES)
    distinct_outputs(("--png", png), ("--out", mesh_out))
    tiles = _tiles(tiles, tile_flag)
    return _checked_graph(graph, tiles, tile_flag=tile_flag), tiles


def render_headless(graph: str, png: str, mesh_out: str | None = None, tiles=(1, 1, 1), *,
                    doc=None) -> dict:
    """Evaluate a project and render its result to a PNG without a display."""
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    from app.evaluation import evaluate_document, result_node, solid_of
    from app.render import render_mesh_png
    from engine.geometry.mesh_io import export_mesh

    if doc is None:
        doc, tiles = check_render_args(graph, png, mesh_out, tiles)
    report = evaluate_document(doc)
    nid = result_node(doc, report)
    solid = solid_of(report, nid) if nid else None
    if solid is None:
        raise ValueError(f"{graph}: evaluation produced no solid ({report.errors or 'no Object node'})")
    mesh = _tiled(solid, tiles)
    render_mesh_png(mesh.vertices, mesh.faces, png)
    if not Path(png).is_file():       # never report a picture that was not written
        raise OSError(f"--png {png}: the renderer wrote no file")
    if mesh_out:
        export_mesh(mesh.vertices, mesh.faces, mesh_out)
    return {"png": str(Path(png).resolve()), "mesh": str(Path(mesh_out).resolve()) if mesh_out else None,
            **mesh.summary}


def cmd_render(args) -> int:
    from app.flags import FlagError

    try:
        doc, tiles = check_render_args(args.graph, args.png, args.out, args.tile)
    except (FlagError, _Refused) as exc:
        return _fail(str(exc), cmd="render")
    try:
        info = render_headless(args.graph, args.png, args.out, tiles, doc=doc)
    except FlagError as exc:
        return _fail(str(exc), cmd="render")
    except (ValueError, OSError) as exc:
        return _fail(str(exc), 1, cmd="render")
    print(json.dumps(info, indent=1, default=float))
    return 0


def cmd_open(project: str | None) -> int:
    from app.flags import FlagError

    path = project or (str(DEFAULT_EXAMPLE) if DEFAULT_EXAMPLE.exists() else None)
    if not has_display():
        if path is None:
            return _fail("no display and no example project to render")
        out_dir = Path.cwd() / "mesoforge-out"
        stem = Path(path).stem
        png, stl = str(out_dir / f"{stem}.png"), str(out_dir / f"{stem}.stl")
        try:
            tiles = (3, 3, 3)        # the headless picture shows a 3x3x3 block
            doc = _checked_graph(path, tiles, tile_flag="PROJECT", tile_value=f"{path} (3x3x3 cells)")
        except (FlagError, _Refused) as exc:
            return _fail(str(exc))
        try:
            out_dir.mkdir(exist_ok=True)
            info = render_headless(path, png, stl, tiles, doc=doc)
        except FlagError as exc:
            return _fail(str(exc))
        except (ValueError, OSError) as exc:
            return _fail(str(exc), 1)
        print("No display found: rendered the project headlessly.")
        print(f"  picture: {info['png']}")
        print(f"  mesh:    {info['mesh']}  ({info['face_count']} faces, watertight={info['watertight']})")
        return 0
    from app.gui import run_gui
    return run_gui(path)


def build_parser() -> argparse.ArgumentParser:
    from app.flags import OneLineParser

    p = OneLineParser(prog="mesoforge", description="Design architected materials.")
    sub = p.add_subparsers(dest="command", parser_class=OneLineParser)
    e = sub.add_parser("eval", help="evaluate a graph headlessly and summarise it")
    e.add_argument("graph")
    e.add_argument("--out", help="write the result mesh (.stl .obj .ply .3mf)")
    e.add_argument("--tile", nargs=3, type=int, default=(1, 1, 1), metavar=("NX", "NY", "NZ"))
    e.add_argument("--node", help="node whose solid is the result (default: the Voxel node's input)")
    e.add_argument("--resolution", type=int, help="override every Object node's grid resolution")
    e.add_argument("--json", action="store_true", help="print a JSON summary")
    r = sub.add_parser("render", help="render a graph's result to a PNG without a window")
    r.add_argument("graph")
    r.add_argument("--png", required=True)
    r.add_argument("--out", help="also write the mesh")
    r.add_argument("--tile", nargs=3, type=int, default=(1, 1, 1), metavar=("NX", "NY", "NZ"))
    from app import homogenize_cmd
    homogenize_cmd.add_parser(sub)
    from app import growth_cmd
    growth_cmd.add_parsers(sub)
    from app import phasor_cmd
    phasor_cmd.add_parsers(sub)
    from app import rd_cmd
    rd_cmd.add_parsers(sub)
    from app import sdf_cmd
    sdf_cmd.add_parsers(sub)
    from app import reconstruct_cmd
    reconstruct_cmd.add_parsers(sub)
    return p


def _dispatch(argv: list[str]) -> int:
    if not argv or (len(argv) == 1 and argv[0].endswith(".json") and not argv[0].startswith("-")):
        return cmd_open(argv[0] if argv else None)
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exc:          # argparse: --help (0) or a one-line refusal (2)
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    if args.command == "eval":
        return cmd_eval(args)
    if args.command == "render":
        return cmd_render(args)
    if args.command == "homogenize":
        from app import homogenize_cmd
        return homogenize_cmd.run(args)
    if args.command in ("grow", "study"):
        from app import growth_cmd
        return growth_cmd.run(args)
    if args.command == "phasor":
        from app import phasor_cmd
        return phasor_cmd.run(args)
    if args.command == "rd":
        from app import rd_cmd
        return rd_cmd.run(args)
    if args.command == "sdf":
        from app import sdf_cmd
        return sdf_cmd.run(args)
    if args.command == "reconstruct":
        from app import reconstruct_cmd
        return reconstruct_cmd.run(args)
    build_parser().print_help()
    return 2


def main(argv: list[str] | None = None) -> int:
    """Run the command; bad input exits 2 with one line, Ctrl-C 130 with one
    line, never a traceback for either."""
    argv = sys.argv[1:] if argv is None else list(argv)
    cmd = argv[0] if argv and argv[0] in COMMANDS else None
    from engine.memory import memory_budget
    try:
        memory_budget()
    except ValueError as exc:          # a malformed MESOFORGE_MEMORY_LIMIT
        return _fail(str(exc), 2, cmd)
    try:
        return _dispatch(argv)
    except KeyboardInterrupt:
        return _fail("interrupted", 130, cmd)
    except MemoryError:                # an allocation the estimates did not foresee
        return _fail("out of memory; lower the resolution, size or tiles", 1, cmd)


if __name__ == "__main__":
    sys.exit(main())
