"""`mesoforge rd`: a stress-aligned lattice grown by reaction-diffusion, from the command line.

    mesoforge rd --preset cantilever|lbeam|lbeam_stress|bridge|bridge_multi|mbb3d
                 [--res WxH[xD]] [--grow-res WxH[xD]] --out OUT.png|OUT.stl
                 [--fields FILE.npz|FILE.vti] [--seed N] [--max-iter N] [--max-steps N]
                 [--gamma 1] [--iso 0.7] [--json]

Runs the graph TopOpt -> RDFields -> RDGrow -> RDCompile (the nodes the
window uses): a SIMP optimisation of the preset on ``--res`` elements (or
the fields imported from ``--fields`` instead), one Gray-Scott growth per
principal direction on ``--grow-res`` cells (default: ten times ``--res``
per axis in 2D, twice in 3D), then the compiled lattice: a PNG (2D; black
= solid, +y up) or a closed STL (3D; in TopOpt elements).  ``--json`` prints the
optimisation and growth times, steps, cell updates per second and, per
direction, where the stop criterion G^t < eps (eq. 14) fired.

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

PRESETS = ("cantilever", "lbeam", "lbeam_stress", "bridge", "bridge_multi", "mbb3d")
UPSAMPLE = {2: 10, 3: 2}      # default growth grid per TopOpt element and axis


class _BadInput(ValueError):
    """A refused command-line value (exit code 2)."""


class _Failed(RuntimeError):
    """The graph does not evaluate (exit code 1)."""


def add_parsers(sub) -> None:
    p = sub.add_parser("rd", help="grow a stress-aligned lattice by reaction-diffusion in an optimised shape")
    p.add_argument("--preset", choices=PRESETS, default="cantilever",
                   help="topology-optimisation problem (default cantilever)")
    p.add_argument("--res", help="optimisation elements WxH (2D) or WxHxD (3D); default: the preset's")
    p.add_argument("--grow-res", help="growth grid WxH[xD] (default: 10x --res in 2D, 2x in 3D)")
    p.add_argument("--out", required=True, help="the lattice: .png (2D) or .stl (3D)")
    p.add_argument("--fields", help="grow in fields read from an .npz / .vti file instead of optimising")
    p.add_argument("--seed", type=int, default=0, help="document seed (default 0)")
    p.add_argument("--max-iter", type=int, help="optimisation iterations at most (default 60)")
    p.add_argument("--max-steps", type=int, help="growth steps per direction at most (default 20000)")
    p.add_argument("--gamma", type=float, help="reaction speed (default 1): the pattern's wavelength "
                                               "shrinks as 1/sqrt(gamma); raise it on small grids")
    p.add_argument("--iso", type=float, help="compile: member where s_i > iso (default 0.7)")
    p.add_argument("--json", action="store_true", help="print times, steps and stop points as JSON")


def _fail(msg: str, code: int) -> int:
    print(f"mesoforge rd: {msg}", file=sys.stderr)
    return code


def parse_size(text: str, flag: str) -> list:
    """``"64x32"`` -> ``[64, 32]``; 2 or 3 integers (their range is the node's)."""
    parts = (text or "").lower().split("x")
    try:
        size = [int(p) for p in parts]
    except ValueError:
        size = []
    if len(size) not in (2, 3):
        raise _BadInput(f"{flag} {text!r}: expected WxH or WxHxD with integers, e.g. 64x32")
    return size


def _grid_text(size) -> str:
    return "x".join(str(n) for n in size)


def _check_grids(args, res, grow, dim) -> None:
    """--res and --grow-res against the TopOpt / RDGrow schemas, their cell
    limits and memory estimates; a growth grid derived from --res is refused
    as --res."""
    from app.flags import FlagError, memory_value, schema_value
    from engine.graph import node_type
    from engine.nodes.rd import MAX_FIELD_CELLS
    from engine.nodes.rd_topopt import MAX_ELEMENTS

    if res and not args.fields:
        from engine.graph import NodeInputError
        from engine.nodes.rd_topopt import preset_problem

        schema_value("--res", res, "TopOpt", "resolution", as_typed=args.res or _grid_text(res))
        try:   # the preset's own demands (an L-beam is square), as the TopOpt node checks them
            preset_problem(args.preset, res)
        except NodeInputError as exc:
            raise FlagError("--res", _grid_text(res), str(exc)) from None
        if math.prod(res) > MAX_ELEMENTS[dim]:
            raise FlagError("--res", _grid_text(res), f"{math.prod(res)} elements",
                            f"at most {MAX_ELEMENTS[dim]} in {dim}D")
        need = node_type("TopOpt").memory_estimate({"preset": args.preset, "resolution": res})
        memory_value("--res", _grid_text(res), need, lower="--res")
    derived = not args.grow_res
    flag, shown = ("--res", args.res) if derived else ("--grow-res", args.grow_res)
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
    from app.flags import output_path, schema_value
    from engine.nodes.rd_topopt import PRESETS as NODE_PRESETS

    output_path("--out", args.out, (".png", ".stl"))
    suffix = Path(args.out).suffix.lower()
    res = parse_size(args.res, "--res") if args.res else []
    grow = parse_size(args.grow_res, "--grow-res") if args.grow_res else []
    if args.fields:
        from engine.rd.field_io import load_fields

        if Path(args.fields).suffix.lower() not in (".npz", ".vti"):
            raise _BadInput(f"--fields {args.fields}: expected an .npz or .vti file (allowed: .npz, .vti)")
        if res:
            raise _BadInput(f"--res {args.res}: the fields come from --fields; set the growth grid with --grow-res")
        try:
            fields = load_fields(args.fields)
        except ValueError as exc:
            raise _BadInput(f"--fields {args.fields}: {exc}") from None
        dim = fields.ndim
    else:
        dim = NODE_PRESETS[args.preset][1]
        res = res or list(NODE_PRESETS[args.preset][2])
        if len(res) != dim:
            raise _BadInput(f"--res {args.res}: preset {args.preset} is {dim}D; give "
                            f"{'WxH' if dim == 2 else 'WxHxD'}")
        grow = grow or [n * UPSAMPLE[dim] for n in res]
    if grow and len(grow) != dim:
        raise _BadInput(f"--grow-res {args.grow_res}: the fields are {dim}D; give {'WxH' if dim == 2 else 'WxHxD'}")
    if (suffix == ".png") != (dim == 2):
        raise _BadInput(f"--out {args.out}: a {dim}D lattice is written as {'.png' if dim == 2 else '.stl'}")
    # every range is the schema of the node the flag sets
    if args.max_iter is not None:
        schema_value("--max-iter", args.max_iter, "TopOpt", "max_iter")
    if args.max_steps is not None:
        schema_value("--max-steps", args.max_steps, "RDGrow", "max_steps")
    if args.gamma is not None:
        args.gamma = schema_value("--gamma", args.gamma, "RDGrow", "gamma")
    if args.iso is not None:
        args.iso = schema_value("--iso", args.iso, "RDCompile", "iso")
    if args.seed < 0:
        raise _BadInput(f"--seed {args.seed}: expected an integer >= 0 (allowed: 0, 1, 2, ...)")
    if grow:
        _check_grids(args, res, grow, dim)
    elif args.fields:
        from engine.graph import node_type

        from app.flags import memory_value
        shape = list(fields.rho.shape[::-1])      # growth on the fields' grid
        memory_value("--fields", args.fields, node_type("RDGrow").memory_estimate({"resolution": shape}))
    return {"res": res, "grow": grow, "suffix": suffix}


def build_document(args, checked):
    """The TopOpt (or file) -> RDFields -> RDGrow -> RDCompile graph of the arguments."""
    from engine.graph import AddNode, Connect, GraphDocument, UndoStack

    doc = GraphDocument(seed=args.seed)
    st = UndoStack(doc)
    fields = {"path": str(Path(args.fields).resolve())} if args.fields else {}
    if not args.fields:
        topopt = {"preset": args.preset, "resolution": checked["res"]}
        if args.max_iter is not None:
            topopt["max_iter"] = args.max_iter
        st.push(AddNode("TopOpt", topopt, node_id="topopt"))
    st.push(AddNode("RDFields", fields, node_id="fields"))
    grow = {"resolution": checked["grow"]}
    if args.max_steps is not None:
        grow["max_steps"] = args.max_steps
    if args.gamma is not None:
        grow["gamma"] = args.gamma
    st.push(AddNode("RDGrow", grow, node_id="grow"))
    st.push(AddNode("RDCompile", {} if args.iso is None else {"iso": args.iso}, node_id="compile"))
    if not args.fields:
        st.push(Connect("topopt", "design", "fields", "design"))
    st.push(Connect("fields", "rdfields", "grow", "rdfields"))
    st.push(Connect("grow", "structures", "compile", "structures"))
    return doc


def _progress(stream):
    tty = stream.isatty()
    state = {"node": None, "t": 0.0}

    def cb(node_id, fraction):
        now = time.perf_counter()
        if node_id == state["node"] and now - state["t"] < (0.1 if tty else 2.0) and fraction < 1.0:
            return
        state["node"], state["t"] = node_id, now
        print(f"{chr(13) if tty else ''}  {node_id}: {100 * fraction:5.1f}%", end="" if tty else "\n",
              file=stream, flush=True)
    return cb


def _evaluate(doc):
    from engine.graph import Evaluator

    report = Evaluator().evaluate(doc, on_progress=_progress(sys.stderr))
    if sys.stderr.isatty():
        print(file=sys.stderr)
    if not report.ok:
        failed = [r for r in report.results.values() if r.status == "failed"]
        if not failed:
            raise _Failed("evaluation did not finish")
        first = failed[0]
        node = doc.nodes[first.node_id]
        # every argument was checked up front: a node failing now failed on valid
        # arguments (exit 1); the message names the flag that set what it refused
        flag = _ARG_OF.get(node.type_name, {}).get(first.where, "--fields" if first.where == "path" else "")
        raise _Failed(f"{flag + ': ' if flag else ''}{first.error}")
    return report


# node parameters the command sets, by the flag that sets them
_ARG_OF = {"TopOpt": {"resolution": "--res", "preset": "--preset", "max_iter": "--max-iter"},
           "RDGrow": {"resolution": "--grow-res", "max_steps": "--max-steps", "gamma": "--gamma"},
           "RDCompile": {"iso": "--iso"},
           "RDFields": {"path": "--fields"}}


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
    from engine.geometry.mesh_io import export_mesh
    from engine.rd.compile import LEVEL, save_structure_png

    out = report.outputs["compile"]
    field = out["field"]
    if suffix == ".png":
        if field.ndim != 2:
            raise _BadInput(f"--out {path}: the lattice is {field.ndim}D; write it as .stl")
        save_structure_png(path, field.values, level=LEVEL)
    else:
        if field.ndim != 3:
            raise _BadInput(f"--out {path}: the lattice is {field.ndim}D; write it as .png")
        solid = out["solid"]
        export_mesh(solid.vertices, solid.faces, path)


def run(args) -> int:
    from app.flags import FlagError

    t0 = time.perf_counter()
    try:
        checked = _check_args(args)
        doc = build_document(args, checked)
        report = _evaluate(doc)
        _write(report, args.out, checked["suffix"])
        info = summary(report, out_path=args.out)
    except (_BadInput, FlagError) as exc:
        return _fail(str(exc), 2)
    except _Failed as exc:
        return _fail(str(exc), 1)
    except OSError as exc:
        return _fail(f"--out {args.out}: cannot write: {exc}", 1)
    except KeyboardInterrupt:
        if sys.stderr.isatty():      # end the \r progress line
            print(file=sys.stderr)
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
