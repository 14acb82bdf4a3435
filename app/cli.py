"""The `mesoforge` command.

    mesoforge                      open the window with an example (headless: render it)
    mesoforge PROJECT.json         open a project in the window
    mesoforge eval GRAPH.json [--out cell.stl] [--tile 3 3 3] [--node ID] [--resolution N] [--json]
    mesoforge render GRAPH.json --png out.png [--tile 3 3 3]
    mesoforge homogenize INPUT [--E 1 --nu 0.45] [--res N] [--json]
    mesoforge grow TILESET --size 20x20 --out tiling.json [--png t.png] [--hints T=1,+=2] [--json]
    mesoforge study TILESET [--hints ...] [--n 100] [--out study.csv] [--scheduler ADDR] [--json]
    mesoforge phasor PROJECT.json [--slice z=MM --png out.png] [--json] [--gcode out.gcode] [--printability] [--node ID]
    mesoforge rd --preset cantilever|lbeam|bridge|mbb3d [--res WxH[xD]] [--grow-res WxH[xD]] --out OUT.png|OUT.stl
                 [--fields FILE.npz|.vti] [--seed N] [--json]
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


def _fail(msg: str, code: int = 2) -> int:
    print(f"mesoforge: {msg}", file=sys.stderr)
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


def cmd_eval(args) -> int:
    from app.evaluation import evaluate_document, override_resolution, report_json, result_node, solid_of, tiled_mesh
    from engine.geometry.mesh_io import export_mesh

    doc, err = _load(args.graph)
    if doc is None:
        return _fail(err)
    if args.resolution is not None:
        try:
            override_resolution(doc, args.resolution)
        except ValueError as exc:
            return _fail(f"--resolution: {exc}")
    report = evaluate_document(doc, on_progress=_progress_printer(not args.json and sys.stderr.isatty()))
    out = report_json(doc, report)
    code = 0 if report.ok else 1
    try:
        nid = result_node(doc, report, args.node)
    except ValueError as exc:
        return _fail(str(exc))
    solid = solid_of(report, nid) if nid else None
    if solid is not None:
        mesh = tiled_mesh(solid, args.tile)
        out["result_node"] = nid
        out["mesh"] = mesh.summary
        if args.out:
            try:
                export_mesh(mesh.vertices, mesh.faces, args.out)
            except (ValueError, OSError) as exc:
                return _fail(f"--out {args.out}: {exc}")
            out["mesh"]["path"] = str(Path(args.out).resolve())
    elif args.out:
        out.setdefault("warnings", []).append("no solid result to export")
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


def render_headless(graph: str, png: str, mesh_out: str | None = None, tiles=(1, 1, 1)) -> dict:
    """Evaluate a project and render its result to a PNG without a display."""
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    from app.evaluation import evaluate_document, result_node, solid_of, tiled_mesh
    from app.render import render_mesh_png
    from engine.geometry.mesh_io import export_mesh

    doc, err = _load(graph)
    if doc is None:
        raise ValueError(err)
    report = evaluate_document(doc)
    nid = result_node(doc, report)
    solid = solid_of(report, nid) if nid else None
    if solid is None:
        raise ValueError(f"{graph}: evaluation produced no solid ({report.errors or 'no Object node'})")
    mesh = tiled_mesh(solid, tiles)
    render_mesh_png(mesh.vertices, mesh.faces, png)
    if mesh_out:
        export_mesh(mesh.vertices, mesh.faces, mesh_out)
    return {"png": str(Path(png).resolve()), "mesh": str(Path(mesh_out).resolve()) if mesh_out else None,
            **mesh.summary}


def cmd_render(args) -> int:
    try:
        info = render_headless(args.graph, args.png, args.out, args.tile)
    except (ValueError, OSError) as exc:
        return _fail(str(exc))
    print(json.dumps(info, indent=1, default=float))
    return 0


def cmd_open(project: str | None) -> int:
    path = project or (str(DEFAULT_EXAMPLE) if DEFAULT_EXAMPLE.exists() else None)
    if not has_display():
        if path is None:
            return _fail("no display and no example project to render")
        out_dir = Path.cwd() / "mesoforge-out"
        out_dir.mkdir(exist_ok=True)
        stem = Path(path).stem
        try:
            info = render_headless(path, str(out_dir / f"{stem}.png"), str(out_dir / f"{stem}.stl"), (3, 3, 3))
        except (ValueError, OSError) as exc:
            return _fail(str(exc))
        print("No display found: rendered the project headlessly.")
        print(f"  picture: {info['png']}")
        print(f"  mesh:    {info['mesh']}  ({info['face_count']} faces, watertight={info['watertight']})")
        return 0
    from app.gui import run_gui
    return run_gui(path)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="mesoforge", description="Design architected materials.")
    sub = p.add_subparsers(dest="command")
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
    return p


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if not argv or (len(argv) == 1 and argv[0].endswith(".json") and not argv[0].startswith("-")):
        return cmd_open(argv[0] if argv else None)
    args = build_parser().parse_args(argv)
    if args.command == "eval":
        if any(t < 1 or t > 20 for t in args.tile):
            return _fail(f"--tile {args.tile}: each count must be between 1 and 20")
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
    build_parser().print_help()
    return 2


if __name__ == "__main__":
    sys.exit(main())
