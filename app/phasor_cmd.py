"""`mesoforge phasor`: slices, singularity energies and G-code of a project's phasor infill.

    mesoforge phasor PROJECT.json --slice z=MM --png OUT.png [--px 0.1] [--node ID]
    mesoforge phasor PROJECT.json --slice z=MM --json
    mesoforge phasor PROJECT.json --gcode OUT.gcode [--layer 0.2] [--nozzle 0.4] [--perimeters 1]
                     [--settings PRINT.json] [--px 0.1]
    mesoforge phasor PROJECT.json --printability [--gcode OUT.gcode] [--json] [print options as above]

The project's PhasorNoise node is found automatically (``--node`` picks one
when there are several).  The command builds a small graph of the nodes
that feed it (``app.graph_run.build``: the same ids, parameters and seed as
the project) plus a PhasorSlice node for ``--slice``, and evaluates it with
the project's stored states, so a repainted infill is sliced as it was
saved.  Prints go through ``engine.nodes.phasor_session``, as the dock's
export does.  ``--px`` and ``--engine`` are the PhasorSlice node's
``pixel`` and ``engine`` (range, unit and default from its schema).

``--png`` writes the slice's black diamond cells inside the part as black
pixels on white.  ``--json`` prints the singularity energy F_S(2) of the
slice for the raw noise (phases 0), the aligned noise and the aligned,
filtered noise: three evaluations of the same kernels.  ``--gcode`` slices
every layer (in the middle of the layer) and writes the print; progress goes
to stderr, and Ctrl-C leaves no file behind (an existing one is untouched).
``--printability`` emulates the print (``engine.fab.printability``, paper
5.1): paths whose footprint is less than 40 % supported by the layer below
(overhangs) or that cover more than 10 % of the nozzle diameter of paths
already laid in their layer (overlaps), counted as violating segments by
length.  With ``--gcode`` the written file is measured, else the toolpaths of
every layer; ``--json`` gives the totals, bin edges and counts, otherwise a
table is printed.

Bad input exits with 2 and a one-line message naming the argument; a node
that fails to evaluate exits with 1; an interrupted print with 130.
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path
from types import SimpleNamespace

NOISE_TYPE = "PhasorNoise"
SLICE_NODE = "cli_slice"
# the PhasorSlice parameters set by flags; axis and position come from --slice
SLICE_FLAGS = {"pixel": "--px", "engine": "--engine"}


class _BadInput(ValueError):
    """A refused command-line value (exit code 2)."""


class _Failed(RuntimeError):
    """The project does not evaluate (exit code 1)."""


def add_parsers(sub) -> None:
    from app.schema_flags import add_param_flags
    from engine.fab import PrintSettings

    defaults = PrintSettings()
    p = sub.add_parser("phasor", help="slice a project's phasor infill: PNG, singularity energy, G-code")
    p.add_argument("project", help="project file (.json) with a PhasorNoise node")
    p.add_argument("--node", help="the PhasorNoise node to use (when the project has several)")
    p.add_argument("--slice", metavar="AXIS=MM", help="slice plane, e.g. z=2.5 (for --png / --json)")
    group = add_param_flags(p, "PhasorSlice", SLICE_FLAGS,
                            help_extra={"pixel": "of the slice and of every layer of a print"})
    p.set_defaults(phasor_slice_flags=group)
    p.add_argument("--png", help="write the slice's diamond cells (black) as a PNG")
    p.add_argument("--json", action="store_true",
                   help="print F_S(2) of the slice for the raw, aligned and aligned+filtered noise")
    p.add_argument("--gcode", help="write the print (every layer) as Marlin G-code")
    p.add_argument("--layer", type=float, help=f"layer height in mm (default {defaults.layer_height:g})")
    p.add_argument("--nozzle", type=float,
                   help=f"nozzle diameter = wall width in mm (default {defaults.nozzle_diameter:g})")
    p.add_argument("--perimeters", type=int,
                   help=f"perimeter loops around the part (default {defaults.perimeters})")
    p.add_argument("--settings", help="print settings JSON (engine.fab.PrintSettings fields)")
    p.add_argument("--printability", action="store_true",
                   help="emulate the print: overhang and overlap segments as histograms by length "
                        "(of the --gcode file, else of the toolpaths)")


# ------------------------------------------------------------------ helpers

def _fail(msg: str, code: int) -> int:
    print(f"mesoforge phasor: {msg}", file=sys.stderr)
    return code


def parse_slice(text: str) -> tuple:
    """``"z=2.5"`` -> ``("z", 2.5)``."""
    axis, sep, value = (text or "").partition("=")
    axis = axis.strip().lower()
    try:
        position = float(value)
    except ValueError:
        position = math.nan
    if not sep or axis not in ("x", "y", "z") or not math.isfinite(position):
        raise _BadInput(f"--slice {text!r}: expected AXIS=MM with AXIS x, y or z, e.g. z=2.5")
    return axis, position


def noise_node(doc, node_id: str | None) -> str:
    """The PhasorNoise node to use: ``node_id`` or the only one in ``doc``."""
    found = [nid for nid, n in doc.nodes.items() if n.type_name == NOISE_TYPE]
    if node_id is not None:
        if node_id not in doc.nodes:
            raise _BadInput(f"--node {node_id!r}: no such node (PhasorNoise nodes: "
                            f"{', '.join(found) or 'none'})")
        if doc.nodes[node_id].type_name != NOISE_TYPE:
            raise _BadInput(f"--node {node_id!r} is a {doc.nodes[node_id].type_name} node, not "
                            f"{NOISE_TYPE} (PhasorNoise nodes: {', '.join(found) or 'none'})")
        return node_id
    if not found:
        raise _BadInput("the project has no PhasorNoise node")
    if len(found) > 1:
        raise _BadInput(f"the project has {len(found)} PhasorNoise nodes ({', '.join(found)}); "
                        f"pick one with --node")
    return found[0]


def _settings(args):
    from engine.fab import PrintSettings

    data = {}
    if args.settings:
        try:
            data = json.loads(Path(args.settings).read_text(encoding="utf-8"))
        except (OSError, ValueError) as exc:
            raise _BadInput(f"--settings {args.settings}: {exc}") from None
        if not isinstance(data, dict):
            raise _BadInput(f"--settings {args.settings}: expected a JSON object of print settings")
    for name, value in (("layer_height", args.layer), ("nozzle_diameter", args.nozzle),
                        ("perimeters", args.perimeters)):
        if value is not None:
            data[name] = value
    try:
        return PrintSettings.from_dict(data)
    except (TypeError, ValueError) as exc:
        flags = {"layer_height": ("--layer", args.layer), "nozzle_diameter": ("--nozzle", args.nozzle),
                 "perimeters": ("--perimeters", args.perimeters)}
        text = str(exc)
        named, value = next(((f, v) for k, (f, v) in flags.items() if text.startswith(k) and v is not None),
                            ("--settings", args.settings))
        raise _BadInput(f"{named} {value}: {text}") from None


def _gcode_progress(stream):
    """``progress(done, total)`` printing ``layer done/total`` and the seconds so far."""
    t0 = time.perf_counter()

    def cb(done, total):
        if total:
            end = "" if stream.isatty() else "\n"
            lead = "\r" if stream.isatty() else ""
            print(f"{lead}  layer {done}/{total}  {time.perf_counter() - t0:6.1f} s", end=end,
                  file=stream, flush=True)
        return True
    return cb


# ------------------------------------------------------------------ the graph

def phasor_graph(doc, noise_id: str, slice_params: dict | None = None):
    """A small document of what feeds ``noise_id`` in ``doc`` (same ids, parameters,
    edges and seed, so stored states apply) and, with ``slice_params``, a
    PhasorSlice node `SLICE_NODE` on its infill."""
    from app.graph_run import build, part_of

    nodes, edges = part_of(doc, noise_id)
    if slice_params is not None:
        nodes[SLICE_NODE] = ("PhasorSlice", slice_params)
        edges.append((noise_id, "infill", SLICE_NODE, "infill"))
    return build(doc.seed, nodes, edges)


def _evaluate(evaluator, doc, targets):
    """Evaluate ``targets`` of ``doc`` quietly (stderr is for refusals and print progress);
    GraphRunFailed (exit 1) naming the first failed node's error and parameter."""
    from app.graph_run import evaluate

    return evaluate(doc, evaluator=evaluator, targets=targets, quiet=True)


def _fields_box(evaluator, doc, fields_id):
    """(lo, hi) mm of the fields' grid from the PhasorFields parameters (and the part's
    mesh, loaded but nothing else evaluated), or None when it does not come out."""
    from engine.graph import node_type
    from engine.nodes.phasor_session import fields_box

    node = doc.nodes[fields_id]
    domain = None
    mesh = doc.inputs_of(fields_id, "domain")
    if mesh:
        report = _evaluate(evaluator, doc, [mesh[0].src])
        domain = report.outputs[mesh[0].src][mesh[0].src_port]
    try:
        return fields_box(domain, node_type(node.type_name).validate_params(node.params, fields_id))
    except ValueError:
        return None      # the evaluation names what is wrong


# ------------------------------------------------------------------ the command

def _check_args(args) -> dict:
    """Every argument checked before the project is read (FlagError / _BadInput);
    the PhasorSlice parameters the flags set."""
    from app.flags import distinct_outputs, output_path
    from app.schema_flags import param_values

    if not (args.png is not None or args.json or args.gcode is not None or args.printability):
        raise _BadInput("nothing to do: give --png, --json (with --slice), --gcode or --printability")
    output_path("--png", args.png, (".png",))
    output_path("--gcode", args.gcode, (".gcode",))
    distinct_outputs(("--png", args.png), ("--gcode", args.gcode))
    if (args.png or (args.json and not (args.gcode or args.printability))) and not args.slice:
        raise _BadInput(f"{'--png' if args.png else '--json'} needs --slice AXIS=MM (e.g. z=2.5)")
    if args.slice:
        parse_slice(args.slice)
    params = param_values(args, args.phasor_slice_flags, only_given=False)
    if args.gcode or args.printability:
        settings = _settings(args)
        if params["pixel"] > 0.5 * settings.nozzle_diameter:
            raise _BadInput(f"--px {params['pixel']}: the walls need a pixel below half the nozzle "
                            f"(allowed: below {0.5 * settings.nozzle_diameter:g} mm)")
    return params


def _check_memory(args, box, px, settings) -> None:
    """Refuse --px / --layer whose slices would exceed the memory budget (the
    PhasorSlice node's estimate and the print's, over the fields' box) before any work."""
    from app.flags import memory_value
    from engine.graph import node_type
    from engine.nodes.phasor import print_memory_estimate

    if box is None:
        return
    lo, hi = box
    if args.slice and (args.png or args.json):
        axis, _ = parse_slice(args.slice)
        infill = SimpleNamespace(fields=SimpleNamespace(lo=lo, hi=hi))   # the estimate reads the box only
        need = node_type("PhasorSlice").memory_estimate({"axis": axis, "pixel": px}, {"infill": infill})
        memory_value("--px", px, need, lower="raise --px (coarser pixels)")
    if settings is not None:
        need = print_memory_estimate(lo, hi, px, settings.layer_height)
        flag, value = ("--layer", settings.layer_height) if args.layer is not None else ("--px", px)
        memory_value(flag, value, need, lower="raise --px or --layer")


def _check_fields(args, fields, px) -> None:
    """Refuse a slice outside the fields' box or a pixel too coarse for their highest F."""
    from engine.nodes.phasor_session import PhasorInfillSession

    session = PhasorInfillSession(fields)
    try:
        if args.slice and (args.png or args.json):
            session.check_slice(*parse_slice(args.slice), px)
        elif args.gcode or args.printability:
            session.check_pixel(px)
    except ValueError as exc:
        text = str(exc)
        raise _BadInput(f"--px {px}: {text}" if text.startswith("pixel") else f"--slice {args.slice}: {text}") \
            from None


def _slice_outputs(args, session, report, out, params) -> None:
    from engine.fileio import write_atomic
    from engine.nodes.phasor_session import diamonds_png
    from engine.phasor.infill import STATES

    axis, position = parse_slice(args.slice)
    image, own = report.outputs[SLICE_NODE]["image"], report.outputs[SLICE_NODE]["energy"]
    out["slice"] = {"axis": axis, "position": position, "pixel": params["pixel"],
                    "shape": list(image.values.shape), "lo": image.lo.tolist(), "hi": image.hi.tolist(),
                    "engine": own.engine}
    if args.png:
        try:
            write_atomic(args.png, diamonds_png(image.values))
        except OSError as exc:
            raise _Failed(f"--png {args.png}: cannot write: {exc}") from None
        out["png"] = str(Path(args.png).resolve())
        inside = session.part_mask(axis, position, params["pixel"])
        out["diamond_fraction"] = float(image.values[inside].mean()) if inside.any() else 0.0
    if args.json:
        energy = {}
        for state in STATES:
            e = own if state == own.state else session.energy(
                session.slice_at(axis, position, params["pixel"], state=state, engine=params["engine"]))
            if e.pixels == 0:
                raise _BadInput(f"--slice {args.slice}: no pixel of the slice lies inside the part away from "
                                "its border, so it has no singularity energy")
            energy[state] = {"F_S": e.value, "F_S_v": e.v, "F_S_w": e.w, "pixels": e.pixels}
        out["energy"] = energy
        out["q"] = own.q


def _gcode_output(args, session, out, settings, params) -> None:
    from engine.progress import Cancelled

    n = session.layer_count(settings.layer_height)
    print(f"slicing {n} layers of {settings.layer_height:g} mm into {args.gcode}", file=sys.stderr)
    try:
        summary = session.write_print(args.gcode, settings=settings, pixel=params["pixel"],
                                      engine=params["engine"], progress=_gcode_progress(sys.stderr))
    except Cancelled:
        raise KeyboardInterrupt from None
    except OSError as exc:
        raise _Failed(f"--gcode {args.gcode}: cannot write: {exc}") from None
    out["gcode"] = {"path": str(Path(args.gcode).resolve()), "layers": summary.layers,
                    "extrusion_length": summary.extrusion_length, "travel_length": summary.travel_length,
                    "filament_length": summary.filament_length, "print_time": summary.print_time,
                    "settings": settings.to_dict()}

def printability_summary(report, nozzle_diameter: float) -> dict:
    """The JSON-able totals and histograms of an :class:`engine.fab.PrintabilityReport`."""
    from engine.fab.printability import MAX_OVERLAP, MIN_SUPPORT

    def kind(lengths, histogram, per_layer):
        return {"segments": int(len(lengths)), "length": float(lengths.sum()),
                "counts": histogram.tolist(), "per_layer": per_layer.tolist()}

    return {"layers": int(len(report.overhang_per_layer)), "pieces": int(len(report.segment_length)),
            "nozzle_diameter": float(nozzle_diameter), "min_support": MIN_SUPPORT, "max_overlap": MAX_OVERLAP,
            "bin_edges": report.bin_edges.tolist(),
            "overhang": kind(report.overhang_segments, report.overhang_histogram, report.overhang_per_layer),
            "overlap": kind(report.overlap_segments, report.overlap_histogram, report.overlap_per_layer)}


def _printability_output(args, session, out, settings, params) -> None:
    from engine.fab import printability, read_gcode_paths
    from engine.progress import Cancelled

    try:
        if args.gcode:
            layers = read_gcode_paths(args.gcode, offset=settings.offset)
        else:
            print("slicing the toolpaths of every layer", file=sys.stderr)
            layers = session.toolpaths(settings, pixel=params["pixel"], engine=params["engine"],
                                       progress=_gcode_progress(sys.stderr))
        print(f"emulating the print of {len(layers)} layers", file=sys.stderr)
        report = printability(layers, nozzle_diameter=settings.nozzle_diameter,
                              progress=_gcode_progress(sys.stderr))
    except Cancelled:
        raise KeyboardInterrupt from None
    except ValueError as exc:          # the emulation grid would be too large
        raise _Failed(f"--printability: {exc}") from None
    out["printability"] = printability_summary(report, settings.nozzle_diameter)


def _print_text(out) -> None:
    if "png" in out:
        s = out["slice"]
        print(f"slice {s['axis']} = {s['position']:g} mm, {s['shape'][1]} x {s['shape'][0]} px of "
              f"{s['pixel']:g} mm ({s['engine']}): {100 * out['diamond_fraction']:.1f} % diamonds; "
              f"wrote {out['png']}")
    if "gcode" in out:
        g = out["gcode"]
        print(f"wrote {g['path']}: {g['layers']} layers, {g['extrusion_length'] / 1000:.2f} m extruded, "
              f"{g['filament_length'] / 1000:.3f} m filament, >= {g['print_time'] / 60:.1f} min")
    if "printability" in out:
        print(printability_table(out["printability"]))


def printability_table(p: dict) -> str:
    """The printability summary as a text table: totals, then segments per length bin."""
    oh, ov = p["overhang"], p["overlap"]
    lines = [f"printability of {p['layers']} layers ({p['pieces']} pieces of ~{p['nozzle_diameter']:g} mm):",
             f"  overhang: {oh['segments']} segments, {oh['length']:.2f} mm "
             f"(< {100 * p['min_support']:g} % of the bead supported)",
             f"  overlap:  {ov['segments']} segments, {ov['length']:.2f} mm "
             f"(> {100 * p['max_overlap']:g} % of the nozzle covered)"]
    if oh["segments"] or ov["segments"]:
        edges = p["bin_edges"]
        lines.append(f"  {'segment length (mm)':>21}  {'overhang':>8}  {'overlap':>8}")
        for a, b, n_oh, n_ov in zip(edges[:-1], edges[1:], oh["counts"], ov["counts"]):
            lines.append(f"  {a:9.2f} .. {b:<8.2f}  {n_oh:>8}  {n_ov:>8}")
    return "\n".join(lines)


def _run(args, out) -> None:
    from engine.graph import Evaluator, ProjectFileError, load_project
    from engine.graph.query import upstream_of_type
    from engine.nodes.phasor_session import PhasorInfillSession

    params = _check_args(args)
    try:
        project = load_project(args.project)
    except ProjectFileError as exc:
        raise _BadInput(str(exc)) from None
    nid = noise_node(project, args.node)
    slicing = bool(args.slice and (args.png or args.json))
    axis, position = parse_slice(args.slice) if slicing else (None, None)
    doc = phasor_graph(project, nid, {**params, "axis": axis, "position": position, "show": "diamonds"}
                       if slicing else None)
    settings = _settings(args) if (args.gcode or args.printability) else None
    evaluator = Evaluator()
    evaluator.import_state(project.node_state)
    fields_id = upstream_of_type(doc, nid, "PhasorFields", "fields")
    if fields_id is not None:
        _check_memory(args, _fields_box(evaluator, doc, fields_id), params["pixel"], settings)
        fields = _evaluate(evaluator, doc, [fields_id]).outputs[fields_id]["fields"].fields
        _check_fields(args, fields, params["pixel"])
    report = _evaluate(evaluator, doc, [SLICE_NODE] if slicing else [nid])
    out.update(project=str(Path(args.project).resolve()), node=nid)
    session = PhasorInfillSession.of_infill(report.outputs[nid]["infill"])
    if fields_id is None:          # no fields node to check before the noise: check on the infill
        _check_fields(args, session.fields, params["pixel"])
    if slicing:
        _slice_outputs(args, session, report, out, params)
    if args.gcode:
        _gcode_output(args, session, out, settings, params)
    if args.printability:
        _printability_output(args, session, out, settings, params)


def run(args) -> int:
    from app.flags import FlagError
    from app.graph_run import GraphRunFailed

    out = {}
    try:
        _run(args, out)
    except (_BadInput, FlagError) as exc:
        return _fail(str(exc), 2)
    except (_Failed, GraphRunFailed) as exc:
        return _fail(str(exc), 1)
    except KeyboardInterrupt:
        where = f"; {args.gcode} was not written" if args.gcode and "gcode" not in out else ""
        if sys.stderr.isatty():      # end the \r progress line
            print(file=sys.stderr)
        return _fail(f"interrupted{where}", 130)
    if args.json:
        print(json.dumps(out, indent=1))
    else:
        _print_text(out)
    return 0
