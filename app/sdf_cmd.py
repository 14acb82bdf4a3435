"""`mesoforge sdf`: an implicit medium of a project, traced to a picture or voxelised.

    mesoforge sdf GRAPH.json --render OUT.png [--size 512x512] [--step fixed|bijection|adaptive]
                  [--adaptive-every N] [--camera EX,EY,EZ,TX,TY,TZ,FOV_DEG] [--paths N]
                  [--max-depth N] [--view-box X0,Y0,Z0,X1,Y1,Z1] [--node ID] [--json]
    mesoforge sdf GRAPH.json --voxels N --out OUT.stl|.obj|.ply|.3mf|.npy [--node ID]
                  [--box-from X,Y,Z --box-to X,Y,Z] [--periodic] [--backend auto|gpu|numpy] [--json]

The SDF is the output of ``--node`` (default: the last node in the project with an SDF
output).  ``--render`` traces it through `engine.nodes.sdf_preview.SDFPreview`, the object
the Implicit Media dock shows (sphere tracing, or ``--paths N`` frames of path tracing);
``--json`` prints the frame time, mean / max steps per ray and the camera used.
``--voxels`` adds an SDF Solid node below it (the node the window uses) with resolution N:
a mesh file gets its marching-cubes mesh; ``.npy`` gets the node samples of its grid, the
signed distance in mm at ``box_from + i * (box_to - box_from) / N`` for i = 0 .. N - 1 along
the longest edge (fewer along shorter ones), the box in ``--json``, and beside it
``<stem>.json`` with the spacing and origin (read by `mesoforge reconstruct --exemplar`).

Flags are checked before any work (ranges from the SDF Solid node's schema and the
preview's `PREVIEW_PARAMS`); bad input exits 2 with one line, a node that fails on valid
input exits 1; the output is written atomically at the end.
"""

from __future__ import annotations

import io
import json
import sys
from pathlib import Path

SOLID_FLAGS = {"box_from": "--box-from", "box_to": "--box-to", "periodic": "--periodic", "backend": "--backend"}
MESH_SUFFIXES = (".stl", ".obj", ".ply", ".3mf")
_flags = {}


def add_parsers(sub) -> None:
    from app.schema_flags import add_param_flags, help_text
    from engine.gpu.sphere_trace import STEP_MODES
    from engine.nodes.sdf_preview import preview_param

    p = sub.add_parser("sdf", help="trace an implicit medium to a PNG, or voxelise it to a mesh / .npy")
    p.add_argument("graph", help="project JSON holding SDF nodes")
    p.add_argument("--node", help="the node whose SDF is used (default: the last SDF node)")
    p.add_argument("--render", metavar="OUT.png", help="sphere-trace (or path-trace) the SDF into a PNG")
    p.add_argument("--size", metavar="WxH", help="image size; " + help_text(preview_param("width")))
    p.add_argument("--step", metavar="{" + ",".join(STEP_MODES) + "}", help=help_text(preview_param("step")))
    p.add_argument("--adaptive-every", metavar="N", help=help_text(preview_param("adaptive_every")))
    p.add_argument("--max-steps", metavar="N", help=help_text(preview_param("max_steps")))
    p.add_argument("--paths", metavar="N", help=help_text(preview_param("paths")))
    p.add_argument("--max-depth", metavar="N", help=help_text(preview_param("max_depth")))
    p.add_argument("--camera", metavar="EX,EY,EZ,TX,TY,TZ,FOV_DEG",
                   help="eye, target (mm) and vertical field of view (deg); default: framing the view box")
    p.add_argument("--view-box", metavar="X0,Y0,Z0,X1,Y1,Z1",
                   help="box the rays are clipped to (mm); default the SDF's own box, else (a medium that "
                        "fills space) the box of the SDF Solid node below it, else [0, 1]^3")
    p.add_argument("--voxels", metavar="N", help="voxelise at N along the longest box edge (SDF Solid resolution)")
    p.add_argument("--out", metavar="OUT", help="mesh (" + " ".join(MESH_SUFFIXES) + ") or .npy to write")
    _flags["SDFSolid"] = add_param_flags(p, "SDFSolid", SOLID_FLAGS)
    p.add_argument("--json", action="store_true", help="print a JSON summary")


def _number(flag, text, name):
    from app.flags import setting_value
    from engine.nodes.sdf_preview import preview_param

    return setting_value(flag, text, preview_param(name))


def _size(text):
    from app.flags import FlagError
    from engine.nodes.sdf_preview import preview_param

    parts = str(text).lower().split("x")
    if len(parts) != 2 or not all(s.strip().isdigit() for s in parts):
        raise FlagError("--size", text, "expected WxH, like 512x512", preview_param("width").allowed())
    return _number("--size", parts[0], "width"), _number("--size", parts[1], "height")


def _box(text):
    from app.flags import FlagError

    try:
        v = [float(s) for s in str(text).split(",")]
    except ValueError:
        v = []
    if len(v) != 6:
        raise FlagError("--view-box", text, "expected six numbers X0,Y0,Z0,X1,Y1,Z1", "a box in mm")
    from engine.implicit.voxelize import check_box
    try:
        check_box(v[:3], v[3:])
    except ValueError as exc:
        raise FlagError("--view-box", text, str(exc), "hi > lo on every axis") from None
    return (tuple(v[:3]), tuple(v[3:]))


def _sdf_node(doc, wanted):
    from app.flags import FlagError

    sdf_nodes = [nid for nid in doc.topological_order()
                 if any(p.type == "SDF" for p in _node_outputs(doc, nid))]
    if wanted is not None:
        if wanted not in doc.nodes:
            raise FlagError("--node", wanted, "no such node", "a node id of the project")
        if wanted not in sdf_nodes:
            raise FlagError("--node", wanted, f"a {doc.nodes[wanted].type_name} node has no SDF output",
                            "one of " + ", ".join(sdf_nodes) if sdf_nodes else "an SDF node")
        return wanted
    if not sdf_nodes:
        raise FlagError("GRAPH", "", "the project has no node with an SDF output", "a project with SDF nodes")
    return sdf_nodes[-1]


def _node_outputs(doc, nid):
    from engine.graph import node_type
    return node_type(doc.nodes[nid].type_name).outputs


def _check(args):
    """Everything about the flags, before any work: (doc, node id, plan dict)."""
    from app.flags import FlagError, output_path
    from app.schema_flags import param_values
    from engine.graph import ProjectFileError, load_project

    if (args.render is None) == (args.voxels is None):
        raise FlagError("--render", args.render, "give exactly one of --render OUT.png or --voxels N",
                        "one of them")
    try:
        doc = load_project(args.graph)
    except ProjectFileError as exc:
        raise FlagError("GRAPH", args.graph, str(exc), "a readable project file") from None
    node = _sdf_node(doc, args.node)
    plan = {}
    if args.render is not None:
        plan["png"] = output_path("--render", args.render, (".png",))
        from engine.nodes.sdf_preview import preview_param
        plan["size"] = _size(args.size) if args.size else (preview_param("width").default,
                                                           preview_param("height").default)
        for flag, name in (("--step", "step"), ("--adaptive-every", "adaptive_every"), ("--max-steps", "max_steps"),
                           ("--paths", "paths"), ("--max-depth", "max_depth")):
            text = getattr(args, name)
            plan[name] = _number(flag, text, name) if text is not None else preview_param(name).default
        plan["view_box"] = _box(args.view_box) if args.view_box else None
        if args.camera:
            from engine.gpu.camera import parse_camera
            try:
                plan["camera"] = parse_camera(args.camera)
            except ValueError as exc:
                raise FlagError("--camera", args.camera, str(exc), "EX,EY,EZ,TX,TY,TZ,FOV_DEG") from None
        if args.out:
            raise FlagError("--out", args.out, "--out goes with --voxels; --render names the PNG", "no --out")
    else:
        from engine.graph import node_type
        from app.flags import schema_value
        plan["resolution"] = schema_value("--voxels", _int_text(args.voxels), "SDFSolid", "resolution",
                                          as_typed=args.voxels)
        if args.out is None:
            raise FlagError("--out", None, "missing", "a mesh (" + " ".join(MESH_SUFFIXES) + ") or .npy file")
        plan["out"] = output_path("--out", args.out, MESH_SUFFIXES + (".npy",))
        if plan["out"].suffix.lower() == ".npy":
            plan["sidecar"] = _sidecar(plan["out"])
        plan["solid"] = param_values(args, _flags["SDFSolid"])
        if "box_from" in plan["solid"] or "box_to" in plan["solid"]:
            plan["solid"]["fit_box"] = False
        lo = plan["solid"].get("box_from", node_type("SDFSolid").param("box_from").default)
        hi = plan["solid"].get("box_to", node_type("SDFSolid").param("box_to").default)
        if any(b <= a for a, b in zip(lo, hi)):
            raise FlagError("--box-to", ",".join(map(str, hi)), "not above --box-from on every axis",
                            "box_to > box_from")
        from app.flags import memory_error
        from engine.memory import MemoryLimitError
        params = {p.name: p.default for p in node_type("SDFSolid").params}
        params.update(plan["solid"], resolution=plan["resolution"])
        try:
            node_type("SDFSolid").check_memory(params)
        except MemoryLimitError as exc:
            raise memory_error("--voxels", args.voxels, exc) from None
    return doc, node, plan


def _sidecar(out: Path) -> Path:
    """``<stem>.json`` beside a .npy: its spacing and origin (what `mesoforge reconstruct` reads).
    A file of that name that this command did not write is never replaced."""
    from app.flags import FlagError

    side = out.with_suffix(".json")
    if side.exists():
        try:
            ours = json.loads(side.read_text(encoding="utf-8")).get("written_by") == "mesoforge sdf"
        except (OSError, ValueError, AttributeError):
            ours = False
        if not ours:
            raise FlagError("--out", str(out), f"{side.name} beside it is not a sidecar this command wrote",
                            "another name (the spacing and origin go in <stem>.json)")
    return side


def _int_text(text):
    s = str(text).strip()
    return int(s) if s.lstrip("+-").isdigit() else s


def run(args) -> int:
    from app.cli import _fail
    from app.flags import FlagError
    from app.graph_run import GraphRunFailed, build, evaluate, part_of

    try:
        doc, node, plan = _check(args)
    except FlagError as exc:
        return _fail(str(exc), cmd="sdf")
    nodes, edges = part_of(doc, node)
    if "resolution" in plan:
        nodes["__sdf_solid"] = ("SDFSolid", {"resolution": plan["resolution"], **plan["solid"]})
        edges = list(edges) + [(node, "sdf", "__sdf_solid", "sdf")]
        target = "__sdf_solid"
    else:
        target = node
    try:
        graph = build(doc.seed, nodes, edges)
        report = evaluate(graph, flag_of={"SDFSolid": {"resolution": "--voxels", **SOLID_FLAGS}},
                          targets=[target], quiet=args.json)
    except GraphRunFailed as exc:
        return _fail(str(exc), 1, cmd="sdf")
    except (ValueError, FlagError) as exc:
        return _fail(str(exc), 2, cmd="sdf")
    if "resolution" in plan:
        info = _write_voxels(report.output(target), report.output(node, "sdf"), plan, graph)
    else:
        try:
            from engine.nodes.sdf_preview import fallback_box_for
            info = _write_render(report.output(node, "sdf"), plan, fallback_box_for(doc, node))
        except ValueError as exc:
            return _fail(str(exc), 1, cmd="sdf")
    info["node"] = node
    print(json.dumps(info, indent=1, default=float) if args.json else
          f"wrote {info.get('png') or info.get('out')}", file=sys.stdout)
    return 0


def _write_voxels(solid, sdf, plan, graph) -> dict:
    import numpy as np

    from engine.fileio import write_atomic
    from engine.geometry.mesh_io import export_mesh, mesh_summary
    from engine.nodes.implicit_solid import sdf_box
    from engine.tiled_mesh import tiled_arrays

    out = plan["out"]
    params = graph.nodes["__sdf_solid"].params
    lo, hi = sdf_box(sdf, params)
    info = {"out": str(out.resolve()), "box": [list(map(float, lo)), list(map(float, hi))],
            "grid": list(solid.grid_shape), "periodic": bool(solid.periodic),
            "volume_fraction": solid.volume_fraction}
    if out.suffix.lower() == ".npy":
        buf = io.BytesIO()
        np.save(buf, np.asarray(solid.sdf, dtype=np.float32) * np.float32(solid.cell_size))
        write_atomic(out, buf.getvalue())
        side = {"spacing": [float(v) for v in solid.spacing], "origin": [float(v) for v in lo],
                "written_by": "mesoforge sdf"}
        write_atomic(plan["sidecar"], (json.dumps(side, indent=1) + "\n").encode())
        info["sidecar"] = str(plan["sidecar"].resolve())
    else:
        vertices, faces = tiled_arrays(solid)                      # at the box's place
        export_mesh(vertices, faces, str(out))
        info.update(mesh_summary(vertices, faces))
    return info


def _write_render(sdf, plan, fallback_box=None) -> dict:
    from engine.fileio import write_atomic
    from engine.gpu.camera import format_camera
    from engine.nodes.sdf_preview import SDFPreview

    preview = SDFPreview(sdf, plan["view_box"], fallback_box)
    camera = plan.get("camera") or preview.camera()
    w, h = plan["size"]
    if plan["paths"] > 0:
        result = preview.path_trace(camera, width=w, height=h, paths=plan["paths"], max_depth=plan["max_depth"])
        rgba = result.rgba
        info = {"frames": int(plan["paths"]), "frame_ms": [float(t) for t in result.frame_ms],
                "mean_depth": float(result.mean_depth)}
    else:
        result = preview.trace(camera, width=w, height=h, step=plan["step"],
                               adaptive_every=plan["adaptive_every"], max_steps=plan["max_steps"])
        rgba = result.rgba
        info = {"frame_ms": float(result.frame_ms), "mean_steps": float(result.mean_steps),
                "max_steps": int(result.max_steps), "hit_fraction": float(result.hit.mean()),
                "retraced": int(result.retraced.sum()), "step": plan["step"]}
    write_atomic(plan["png"], _png(rgba))
    info.update({"png": str(Path(plan["png"]).resolve()), "size": [w, h], "camera": format_camera(camera),
                 "view_box": [list(map(float, preview.box[0])), list(map(float, preview.box[1]))],
                 "lipschitz": float(sdf.lipschitz)})
    return info


def _png(rgba) -> bytes:
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(rgba, mode="RGBA").save(buf, format="PNG")
    return buf.getvalue()
