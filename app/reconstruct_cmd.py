"""`mesoforge reconstruct`: fit an SDF node's parameters to an exemplar (paper 004, section 6).

    mesoforge reconstruct GRAPH.json --node ID --exemplar FILE.npy|.vti|.tif|.png
                          [--algorithm cmaes|powell|basinhopping|shgo] [--budget SECONDS]
                          [--fit NAME=LO:HI ...] [--max-evaluations N] [--seed N]
                          [--loss fourier|mse] [--camera EX,EY,EZ,TX,TY,TZ,FOV] [--view-box ...]
                          [--out FITTED.json] [--json]

The exemplar is a signed-distance (or occupancy) grid: ``.npy`` (spacing and origin in mm from
a ``<stem>.json`` sidecar ``{"spacing": [...], "origin": [...]}``, else 1 and 0), ``.vti`` or
a ``.tif`` stack (`engine.implicit.exemplar.load_exemplar`).  An image (``.png``, ``.jpg``,
``.bmp``, a one-page ``.tif``) is fitted by analysis by synthesis (section 6.2): every candidate
is sphere-traced at ``--camera`` (default: the view `mesoforge sdf --render` frames for the
node as it is now, in ``--view-box`` or its box) and compared by the 2D DFT amplitudes (eq. 39).  ``--fit`` names the node's float
parameters to fit and their bounds (repeatable); without it every non-zero float parameter is
fitted within half its value either way.  The fit (`engine.nodes.sdf_fit.NodeFit`, the object
the Implicit Media dock runs) starts from the node's current values and stops at the budget,
at ``--max-evaluations`` or when converged; ``--out`` writes a copy of the project with the
fitted values (never the input file).  ``--json`` prints the parameters found, the loss, the
evaluations, the seconds and why it stopped.  Bad input exits 2 before any work; Ctrl-C 130.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path


def add_parsers(sub) -> None:
    from app.schema_flags import help_text
    from engine.implicit.reconstruct import ALGORITHMS
    from engine.nodes.sdf_fit import fit_param

    p = sub.add_parser("reconstruct", help="fit an SDF node's parameters to an exemplar grid")
    p.add_argument("graph", help="project JSON")
    p.add_argument("--node", required=True, help="the SDF node whose parameters are fitted")
    p.add_argument("--exemplar", required=True, metavar="FILE", help="signed distances or occupancy: .npy .vti .tif")
    p.add_argument("--algorithm", metavar="{" + ",".join(ALGORITHMS) + "}", help=help_text(fit_param("algorithm")))
    p.add_argument("--budget", metavar="SECONDS", help=help_text(fit_param("budget")))
    p.add_argument("--max-evaluations", metavar="N", help=help_text(fit_param("max_evaluations")))
    p.add_argument("--seed", metavar="N", help=help_text(fit_param("seed")))
    p.add_argument("--loss", metavar="{fourier,mse}", help=help_text(fit_param("loss")))
    p.add_argument("--fit", action="append", metavar="NAME=LO:HI", help="a parameter to fit and its bounds")
    p.add_argument("--camera", metavar="EX,EY,EZ,TX,TY,TZ,FOV_DEG",
                   help="the camera an image exemplar was taken with (default: the sdf command's framing)")
    p.add_argument("--view-box", metavar="X0,Y0,Z0,X1,Y1,Z1", help="box the rays are clipped to (image exemplars)")
    p.add_argument("--out", metavar="FITTED.json", help="write the project with the fitted values")
    p.add_argument("--json", action="store_true", help="print a JSON summary")


def _setting(flag, text, name):
    from app.flags import setting_value
    from engine.nodes.sdf_fit import fit_param

    return setting_value(flag, text, fit_param(name))


def _check(args):
    from app.flags import FlagError, output_path
    from engine.graph import ProjectFileError, load_project, node_type
    from engine.nodes.sdf_fit import fit_param, parse_bounds

    try:
        doc = load_project(args.graph)
    except ProjectFileError as exc:
        raise FlagError("GRAPH", args.graph, str(exc), "a readable project file") from None
    if args.node not in doc.nodes:
        raise FlagError("--node", args.node, "no such node", "a node id of the project")
    cls = node_type(doc.nodes[args.node].type_name)
    if not any(p.type == "SDF" for p in cls.outputs):
        raise FlagError("--node", args.node, f"a {cls.type_name} node has no SDF output", "an SDF node")
    plan = {name: (_setting(flag, getattr(args, dest), name) if getattr(args, dest) is not None
                   else fit_param(name).default)
            for flag, dest, name in (("--algorithm", "algorithm", "algorithm"), ("--budget", "budget", "budget"),
                                     ("--max-evaluations", "max_evaluations", "max_evaluations"),
                                     ("--seed", "seed", "seed"), ("--loss", "loss", "loss"))}
    bounds = None
    if args.fit:
        bounds = {}
        for text in args.fit:
            try:
                name, lo, hi = parse_bounds(text)
            except ValueError as exc:
                raise FlagError("--fit", text, str(exc), "NAME=LO:HI") from None
            bounds[name] = (lo, hi)
    plan["bounds"] = bounds
    plan["exemplar"], plan["image"] = _exemplar(args.exemplar)
    if args.camera:
        from engine.gpu.camera import parse_camera
        try:
            plan["camera"] = parse_camera(args.camera)
        except ValueError as exc:
            raise FlagError("--camera", args.camera, str(exc), "EX,EY,EZ,TX,TY,TZ,FOV_DEG") from None
    if args.view_box:
        from app.sdf_cmd import _box
        plan["view_box"] = _box(args.view_box)
    plan["out"] = output_path("--out", args.out, (".json",))
    if plan["out"] is not None and plan["out"].resolve() == Path(args.graph).resolve():
        raise FlagError("--out", args.out, "is the input project", "another file (the input is never written)")
    return doc, plan


def _exemplar(path):
    from app.flags import FlagError
    from engine.nodes.sdf_fit import load_any_exemplar

    try:
        return load_any_exemplar(path)
    except ValueError as exc:
        raise FlagError("--exemplar", path, str(exc),
                        "a 3D grid (.npy .vti .tif) or an image (.png .jpg .bmp .tif)") from None


def run(args) -> int:
    from app.cli import _fail
    from app.flags import FlagError
    from app.graph_run import GraphRunFailed, build, evaluate, part_of
    from engine.nodes.sdf_fit import NodeFit

    try:
        doc, plan = _check(args)
        node = doc.nodes[args.node]
        nodes, edges = part_of(doc, args.node)
        graph = build(doc.seed, nodes, edges)
        report = evaluate(graph, targets=[args.node], quiet=args.json)
        inputs = {e.dst_port: report.output(e.src, e.src_port) for e in graph.edges if e.dst == args.node}
        try:
            fitting = NodeFit(node.type_name, node.params, inputs, plan["bounds"])
        except ValueError as exc:
            raise FlagError("--fit", " ".join(args.fit or []) or "(default)", str(exc), "float parameters of the node") \
                from None
    except FlagError as exc:
        return _fail(str(exc), cmd="reconstruct")
    except GraphRunFailed as exc:
        return _fail(str(exc), 1, cmd="reconstruct")

    def progress(done, best, x):
        if not args.json:
            print(f"\r  fit: {100 * done:5.1f}%  loss {best:.4g}", end="", file=sys.stderr, flush=True)

    settings = dict(algorithm=plan["algorithm"], budget=plan["budget"], max_evaluations=plan["max_evaluations"],
                    seed=plan["seed"], progress=progress)
    view = {}
    if plan["image"]:
        from engine.gpu.camera import format_camera
        from engine.nodes.sdf_preview import SDFPreview, fallback_box_for

        preview = SDFPreview(fitting.sdf(fitting.start()), plan.get("view_box"), fallback_box_for(doc, args.node))
        camera = plan.get("camera") or preview.camera()
        bounds = (tuple(preview.box[0]), tuple(preview.box[1]))
        result = fitting.fit_image(plan["exemplar"], camera, bounds=bounds, **settings)
        view = {"camera": format_camera(camera), "view_box": [list(map(float, b)) for b in bounds]}
    else:
        result = fitting.fit(plan["exemplar"], loss=plan["loss"], **settings)
    if not args.json:
        print(file=sys.stderr)
    found = {n: float(v) for n, v in zip(result.names or fitting.names, result.params)}
    info = {"node": args.node, "type": node.type_name, "algorithm": result.algorithm, "params": found,
            "start": {n: float(v) for n, v in zip(fitting.names, fitting.start())},
            "bounds": {n: list(b) for n, b in fitting.bounds.items()}, "loss": float(result.loss),
            "evaluations": int(result.evaluations), "seconds": float(result.seconds),
            "stopped_by": result.stopped_by, "exemplar": "image" if plan["image"] else "grid", **view}
    if plan["out"] is not None:
        _write_fitted(doc, args.node, found, plan["out"])
        info["out"] = str(plan["out"].resolve())
    print(json.dumps(info, indent=1) if args.json else
          "fitted " + ", ".join(f"{n} = {v:.6g}" for n, v in found.items()) + f"  (loss {result.loss:.4g})")
    return 0


def _write_fitted(doc, node_id, values, path) -> None:
    from engine.graph import SetParam, UndoStack, save_project

    stack = UndoStack(doc)
    for name, value in values.items():
        stack.push(SetParam(node_id, name, value))
    save_project(doc, path)
