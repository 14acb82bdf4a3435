"""`mesoforge rd`: a stress-aligned lattice grown by reaction-diffusion, from the command line.

    mesoforge rd --preset cantilever|lbeam|lbeam_stress|bridge|bridge_multi|mbb3d
                 [--res WxH[xD]] [--grow-res WxH[xD]] --out OUT.png|OUT.stl
                 [--fields FILE.npz|FILE.vti] [--seed N] [--max-iter N] [--max-steps N]
                 [--gamma X] [--iso X] [--json]

Runs the graph TopOpt -> RDFields -> RDGrow -> RDCompile (the nodes the
window uses): a SIMP optimisation of the preset on ``--res`` elements (or
the fields imported from ``--fields`` instead), one Gray-Scott growth per
principal direction on ``--grow-res`` cells (default: ten times ``--res``
per axis in 2D, twice in 3D), then the compiled lattice: a PNG (2D; black
= solid, +y up) or a closed STL (3D; in TopOpt elements).  ``--json`` prints the
optimisation and growth times, steps, cell updates per second and, per
direction, where the stop criterion G^t < eps (eq. 14) fired.

The node-parameter flags are generated from the nodes' schemas
(`app.schema_flags`): ``--help`` shows each one's range, unit and default,
and a value is refused by the same check as in the inspector.  The graph is
built and evaluated by `app.graph_run`, as the window would evaluate it.

Progress goes to stderr.  Ctrl-C exits with 130 and writes nothing (the
output is written atomically once everything is done).  Bad input exits
with 2 and a one-line message naming what was wrong; a node that fails on
valid arguments exits with 1.
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

UPSAMPLE = {2: 10, 3: 2}      # the command's growth grid per TopOpt element and axis (without --grow-res)

# node parameters the command exposes, by node type: {parameter: flag}; help, ranges and
# defaults come from the parameters' schemas (app.schema_flags)
PARAM_FLAGS = {
    "TopOpt": {"resolution": "--res", "max_iter": "--max-iter"},
    "RDFields": {"path": "--fields"},
    "RDGrow": {"resolution": "--grow-res", "max_steps": "--max-steps", "gamma": "--gamma"},
    "RDCompile": {"iso": "--iso"},
}
HELP_EXTRA = {        # what a flag means on the command line, beyond its parameter's doc
    ("TopOpt", "resolution"): "typed WxH or WxHxD",
    ("RDFields", "path"): "given, the fields are read instead of optimising",
    ("RDGrow", "resolution"): "typed WxH[xD]; without it: 10 x --res per axis in 2D, 2 x in 3D",
    ("RDGrow", "gamma"): "the wavelength shrinks as 1/sqrt(gamma): raise it on small grids",
}


def add_parsers(sub) -> None:
    from engine.graph import node_type

    from app.schema_flags import add_param_flags, help_text

    p = sub.add_parser("rd", help="grow a stress-aligned lattice by reaction-diffusion in an optimised shape")
    preset = node_type("TopOpt").param("preset")
    p.add_argument("--preset", choices=preset.choices, default=preset.default,
                   help=help_text(preset))
    groups = {}
    for type_name, flags in PARAM_FLAGS.items():
        extra = {name: HELP_EXTRA.get((type_name, name), "") for name in flags}
        groups[type_name] = add_param_flags(p, type_name, flags, help_extra=extra)
    p.add_argument("--out", required=True, help="the lattice: .png (2D) or .stl (3D)")
    p.add_argument("--seed", type=int, default=0, help="document seed (default 0)")
    p.add_argument("--json", action="store_true", help="print times, steps and stop points as JSON")
    p.set_defaults(rd_param_flags=groups)


def _fail(msg: str, code: int) -> int:
    print(f"mesoforge rd: {msg}", file=sys.stderr)
    return code


def _grid_text(size) -> str:
    return "x".join(str(n) for n in size)


def _want(dim: int) -> str:
    return "WxH" if dim == 2 else "WxHxD"


def _check_grids(args, res, grow, dim) -> None:
    """--res and --grow-res against the TopOpt / RDGrow schemas, their cell
    limits and memory estimates; a growth grid derived from --res is refused
    as --res."""
    from app.flags import FlagError, memory_value
    from engine.graph import NodeInputError, node_type
    from engine.nodes.rd import MAX_FIELD_CELLS
    from engine.nodes.rd_topopt import preset_problem

    if res and not args.fields:
        try:   # the preset's own demands (an L-beam is square, element limit), as the TopOpt node checks them
            preset_problem(args.preset, res)
        except NodeInputError as exc:
            raise FlagError("--res", args.res or _grid_text(res), str(exc)) from None
        need = node_type("TopOpt").memory_estimate({"preset": args.preset, "resolution": res})
        memory_value("--res", args.res or _grid_text(res), need, lower="--res")
    derived = not args.grow_res
    flag, shown = ("--res", args.res or _grid_text(res)) if derived else ("--grow-res", args.grow_res)
    why = f"the growth grid {_grid_text(grow)} ({UPSAMPLE[dim]} x --res) " if derived else ""
    p = node_type("RDGrow").param("resolution")
    try:
        p.coerce(grow)
    except ValueError:
        raise FlagError(flag, shown, f"{why}is out of range" if why else "out of range",
                        p.allowed() + (" per axis; or give --grow-res" if derived else " per axis")) from None
    if math.prod(grow) > MAX_FIELD_CELLS:
        raise FlagError(flag, shown, f"{why}has {math.prod(grow)} cells",
                        f"at most {MAX_FIELD_CELLS} cells" + ("; or give --grow-res" if derived else ""))
    need = node_type("RDGrow").memory_estimate({"resolution": grow})
    memory_value(flag, shown, need, lower="--grow-res" if not derived else "--res or give --grow-res")


def _check_args(args) -> dict:
    """Every flag checked before any work: {node type: its parameters set by flags}, plus
    the output suffix.  FlagError names the first bad flag."""
    from app.flags import FlagError, memory_value, output_path
    from app.schema_flags import param_values
    from engine.graph import node_type
    from engine.nodes.rd_topopt import PRESETS as NODE_PRESETS

    output_path("--out", args.out, (".png", ".stl"))
    suffix = Path(args.out).suffix.lower()
    groups = args.rd_param_flags
    params = {t: param_values(args, g) for t, g in groups.items()}
    res = list(params["TopOpt"].get("resolution") or [])
    grow = list(params["RDGrow"].get("resolution") or [])
    path = params["RDFields"].get("path")
    if path:
        from engine.rd.field_io import load_fields

        if Path(path).suffix.lower() not in (".npz", ".vti"):
            raise FlagError("--fields", path, "expected an .npz or .vti file", ".npz, .vti")
        if res:
            raise FlagError("--res", args.res, "the fields come from --fields; set the growth grid with --grow-res")
        try:
            fields = load_fields(path)
        except ValueError as exc:
            raise FlagError("--fields", path, str(exc)) from None
        dim = fields.ndim
    else:
        dim = NODE_PRESETS[args.preset][1]
        res = res or list(NODE_PRESETS[args.preset][2])
        if len(res) != dim:
            raise FlagError("--res", args.res, f"preset {args.preset} is {dim}D; give {_want(dim)}")
        grow = grow or [n * UPSAMPLE[dim] for n in res]
    if grow and len(grow) != dim:
        raise FlagError("--grow-res", args.grow_res, f"the fields are {dim}D; give {_want(dim)}")
    if (suffix == ".png") != (dim == 2):
        raise FlagError("--out", args.out, f"a {dim}D lattice is written as {'.png' if dim == 2 else '.stl'}")
    if args.seed < 0:
        raise FlagError("--seed", args.seed, "expected an integer >= 0", "0, 1, 2, ...")
    if grow:
        _check_grids(args, res, grow, dim)
    elif path:
        shape = list(fields.rho.shape[::-1])      # growth on the fields' grid
        memory_value("--fields", path, node_type("RDGrow").memory_estimate({"resolution": shape}))
    params["TopOpt"]["resolution"] = res
    params["RDGrow"]["resolution"] = grow
    if path:
        params["RDFields"]["path"] = str(Path(path).resolve())
    return {"params": params, "suffix": suffix, "fields": bool(path)}


def build_document(args, checked):
    """The TopOpt (or file) -> RDFields -> RDGrow -> RDCompile graph of the checked arguments
    (`app.graph_run.build`: the window's undo commands, so every parameter meets its schema)."""
    from app.graph_run import build

    params = checked["params"]
    nodes, edges = {}, []
    if not checked["fields"]:
        nodes["topopt"] = ("TopOpt", {"preset": args.preset, **params["TopOpt"]})
        edges.append(("topopt", "design", "fields", "design"))
    nodes["fields"] = ("RDFields", params["RDFields"])
    nodes["grow"] = ("RDGrow", params["RDGrow"])
    nodes["compile"] = ("RDCompile", params["RDCompile"])
    edges += [("fields", "rdfields", "grow", "rdfields"), ("grow", "structures", "compile", "structures")]
    return build(args.seed, nodes, edges)


def flag_of() -> dict:
    """{node type: {parameter: flag}}: which flag set what a failing node names."""
    out = {t: dict(flags) for t, flags in PARAM_FLAGS.items()}
    out["TopOpt"]["preset"] = "--preset"
    return out


def _evaluate(doc):
    """The graph evaluated by the Evaluator, progress on stderr; GraphRunFailed (exit 1) names
    the flag behind what a node refused on checked arguments."""
    from app.graph_run import evaluate

    return evaluate(doc, flag_of=flag_of())


def summary(report, *, out_path) -> dict:
    """The JSON-able facts of one run."""
    results = report.results
    info = {"out": str(Path(out_path).resolve())}
    if "topopt" in report.outputs:
        design = report.outputs["topopt"]["design"]
        res = design.result
        info["optimisation"] = {"preset": design.problem.name, "elements": list(design.grid_shape[::-1]),
                                "seconds": design.seconds, "iterations": int(res.iterations),
                                "converged": bool(res.converged), "objective": float(res.objective),
                                "compliances": [float(c) for c in res.compliances]}
    else:
        info["optimisation"] = None
    st = report.outputs["grow"]["structures"]
    directions = []
    for k, i in enumerate(st.directions):
        state = st.states[k]
        hist = st.g_history[k]
        directions.append({"direction": int(i), "steps": int(st.steps[k]), "seconds": st.seconds[k],
                           "stop_reason": st.stop_reasons[k], "stop_step": int(st.stop_steps[k]),
                           "stop_time": float(st.stop_steps[k] * state.params.dt),
                           "stop_g": float(hist[-1, 1]) if len(hist) else None,
                           "dt": float(state.params.dt)})
    info["growth"] = {"grid": list(st.fields.grid_shape[::-1]), "seconds": float(sum(st.seconds)),
                      "cell_updates_per_second": st.cell_updates_per_second, "directions": directions}
    info["compile_seconds"] = results["compile"].seconds
    info["node_seconds"] = {nid: r.seconds for nid, r in results.items()}
    return info


def _write(report, path, suffix) -> None:
    from app.flags import FlagError
    from engine.geometry.mesh_io import export_mesh
    from engine.rd.compile import LEVEL, save_structure_png

    out = report.outputs["compile"]
    field = out["field"]
    if suffix == ".png":
        if field.ndim != 2:
            raise FlagError("--out", path, f"the lattice is {field.ndim}D; write it as .stl")
        save_structure_png(path, field.values, level=LEVEL)
    else:
        if field.ndim != 3:
            raise FlagError("--out", path, f"the lattice is {field.ndim}D; write it as .png")
        solid = out["solid"]
        export_mesh(solid.vertices, solid.faces, path)


def run(args) -> int:
    from app.flags import FlagError
    from app.graph_run import GraphRunFailed, end_progress_line

    t0 = time.perf_counter()
    try:
        checked = _check_args(args)
        doc = build_document(args, checked)
        report = _evaluate(doc)
        _write(report, args.out, checked["suffix"])
        info = summary(report, out_path=args.out)
    except FlagError as exc:
        return _fail(str(exc), 2)
    except GraphRunFailed as exc:
        return _fail(str(exc), 1)
    except OSError as exc:
        return _fail(f"--out {args.out}: cannot write: {exc}", 1)
    except KeyboardInterrupt:
        end_progress_line()
        return _fail(f"interrupted; {args.out} was not written", 130)
    info["total_seconds"] = time.perf_counter() - t0
    if args.json:
        print(json.dumps(info, indent=1))
    else:
        g = info["growth"]
        steps = ", ".join(f"{d['steps']} ({d['stop_reason']})" for d in g["directions"])
        print(f"wrote {info['out']}: grown on {'x'.join(map(str, g['grid']))} cells in {g['seconds']:.1f} s "
              f"({g['cell_updates_per_second'] / 1e6:.1f} M cell updates/s); steps per direction: {steps}")
    return 0
