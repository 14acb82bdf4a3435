"""`mesoforge phasor`: slices, singularity energies and G-code of a project's phasor infill.

    mesoforge phasor PROJECT.json --slice z=MM --png OUT.png [--px 0.1] [--node ID]
    mesoforge phasor PROJECT.json --slice z=MM --json
    mesoforge phasor PROJECT.json --gcode OUT.gcode [--layer 0.2] [--nozzle 0.4] [--perimeters 1]
                     [--settings PRINT.json] [--px 0.1]
    mesoforge phasor PROJECT.json --printability [--gcode OUT.gcode] [--json] [print options as above]

The project's PhasorNoise node is found automatically (``--node`` picks one
when there are several).  Its result comes from the states stored in the
project, so a repainted infill is sliced as it was saved.

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

import io
import json
import math
import sys
import time
from pathlib import Path

NOISE_TYPE = "PhasorNoise"


class _BadInput(ValueError):
    """A refused command-line value (exit code 2)."""


class _Failed(RuntimeError):
    """The project does not evaluate (exit code 1)."""


def add_parsers(sub) -> None:
    p = sub.add_parser("phasor", help="slice a project's phasor infill: PNG, singularity energy, G-code")
    p.add_argument("project", help="project file (.json) with a PhasorNoise node")
    p.add_argument("--node", help="the PhasorNoise node to use (when the project has several)")
    p.add_argument("--slice", metavar="AXIS=MM", help="slice plane, e.g. z=2.5 (for --png / --json)")
    p.add_argument("--px", type=float, default=0.1, help="pixel size in mm (default 0.1)")
    p.add_argument("--png", help="write the slice's diamond cells (black) as a PNG")
    p.add_argument("--json", action="store_true",
                   help="print F_S(2) of the slice for the raw, aligned and aligned+filtered noise")
    p.add_argument("--gcode", help="write the print (every layer) as Marlin G-code")
    p.add_argument("--layer", type=float, help="layer height in mm (default 0.2)")
    p.add_argument("--nozzle", type=float, help="nozzle diameter = wall width in mm (default 0.4)")
    p.add_argument("--perimeters", type=int, help="perimeter loops around the part (default 1)")
    p.add_argument("--settings", help="print settings JSON (engine.fab.PrintSettings fields)")
    p.add_argument("--engine", choices=("gpu", "numpy"), default="gpu",
                   help="slice evaluator (default gpu; numpy when no EGL context can be made)")
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


def _infill(args):
    from engine.graph import Evaluator, ProjectFileError, load_project

    try:
        doc = load_project(args.project)
    except ProjectFileError as exc:
        raise _BadInput(str(exc)) from None
    nid = noise_node(doc, args.node)
    evaluator = Evaluator()
    evaluator.import_state(doc.node_state)
    report = evaluator.evaluate(doc, targets=[nid])
    if not report.ok:
        failed = [r for r in report.results.values() if r.status not in ("evaluated", "cached")]
        first = next((r for r in failed if r.error and r.status == "failed"), failed[0])
        where = f" [{first.where}]" if first.where else ""
        raise _Failed(f"{first.error or first.status}{where}")
    return nid, report.outputs[nid]["infill"]


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


def _png_bytes(diamonds) -> bytes:
    import numpy as np
    from PIL import Image

    # rows run along +v (up): flip so the picture is seen from +axis with v upwards
    img = np.where(diamonds[::-1], 0, 255).astype(np.uint8)
    buf = io.BytesIO()
    Image.fromarray(img).save(buf, format="PNG")
    return buf.getvalue()


def _gcode_progress(stream):
    t0 = time.perf_counter()

    def cb(done, total):
        if total:
            end = "" if stream.isatty() else "\n"
            lead = "\r" if stream.isatty() else ""
            print(f"{lead}  layer {done}/{total}  {time.perf_counter() - t0:6.1f} s", end=end,
                  file=stream, flush=True)
        return True
    return cb


# ------------------------------------------------------------------ the command

def _slice_outputs(args, infill, out) -> None:
    from engine.fileio import write_atomic
    from engine.phasor.infill import STATES, infill_slice

    axis, position = parse_slice(args.slice)
    try:
        result = infill_slice(infill, axis, position, args.px, engine=args.engine)
    except ValueError as exc:
        text = str(exc)
        raise _BadInput(f"--px {args.px}: {text}" if text.startswith("pixel") else f"--slice {args.slice}: {text}") \
            from None
    out["slice"] = {"axis": axis, "position": position, "pixel": args.px,
                    "shape": list(result.plane.shape), "lo": result.lo.tolist(), "hi": result.hi.tolist(),
                    "engine": result.engine}
    if args.png:
        try:
            write_atomic(args.png, _png_bytes(result.diamonds))
        except OSError as exc:
            raise _Failed(f"--png {args.png}: cannot write: {exc}") from None
        out["png"] = str(Path(args.png).resolve())
        out["diamond_fraction"] = float(result.diamonds[result.inside].mean()) if result.inside.any() else 0.0
    if args.json:
        energy = {}
        for state in STATES:
            r = result if state == result.state else infill_slice(infill, axis, position, args.px,
                                                                  state=state, engine=args.engine)
            try:
                e = r.energy()
            except ValueError as exc:
                raise _BadInput(f"--slice {args.slice}: {exc}") from None
            energy[state] = {"F_S": e["either"], "F_S_v": e["v"], "F_S_w": e["w"], "pixels": e["pixels"]}
        out["energy"] = energy
        out["q"] = 2.0


def _print_settings(args, infill):
    """PrintSettings from the arguments, with --px checked for walls."""
    from engine.phasor.infill import check_pixel

    settings = _settings(args)
    try:
        check_pixel(infill.fields, args.px)
    except ValueError as exc:
        raise _BadInput(f"--px {args.px}: {exc}") from None
    return settings


def _gcode_output(args, infill, out, settings) -> None:
    from engine.geometry.cancel import Cancelled
    from engine.phasor.infill import layer_positions, write_print

    n = len(layer_positions(infill, settings.layer_height))
    print(f"slicing {n} layers of {settings.layer_height:g} mm into {args.gcode}", file=sys.stderr)
    try:
        summary = write_print(infill, args.gcode, settings=settings, pixel=args.px, engine=args.engine,
                              progress=_gcode_progress(sys.stderr))
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


def _printability_output(args, infill, out, settings) -> None:
    from engine.phasor.infill import infill_toolpaths
    from engine.fab import printability, read_gcode_paths
    from engine.geometry.cancel import Cancelled

    try:
        if args.gcode:
            layers = read_gcode_paths(args.gcode, offset=settings.offset)
        else:
            print("slicing the toolpaths of every layer", file=sys.stderr)
            layers = infill_toolpaths(infill, settings, pixel=args.px, engine=args.engine,
                                     progress=_gcode_progress(sys.stderr))
        print(f"emulating the print of {len(layers)} layers", file=sys.stderr)
        report = printability(layers, nozzle_diameter=settings.nozzle_diameter,
                              progress=_gcode_progress(sys.stderr))
    except Cancelled:
        raise KeyboardInterrupt from None
    except ValueError as exc:          # the emulation grid would be too large
        raise _Failed(f"--printability: {exc}") from None
    out["printability"] = printability_summary(report, settings.nozzle_diameter)


def _check_args(args) -> None:
    """Every argument checked before the project is read (FlagError / _BadInput)."""
    from app.flags import distinct_outputs, output_path, schema_value

    if not (args.png is not None or args.json or args.gcode is not None or args.printability):
        raise _BadInput("nothing to do: give --png, --json (with --slice), --gcode or --printability")
    output_path("--png", args.png, (".png",))
    output_path("--gcode", args.gcode, (".gcode",))
    distinct_outputs(("--png", args.png), ("--gcode", args.gcode))
    if (args.png or (args.json and not (args.gcode or args.printability))) and not args.slice:
        raise _BadInput(f"{'--png' if args.png else '--json'} needs --slice AXIS=MM (e.g. z=2.5)")
    if args.slice:
        parse_slice(args.slice)
    # the pixel's range is the Phasor Slice node's, which slices the infill in a graph
    args.px = schema_value("--px", args.px, "PhasorSlice", "pixel")
    if args.gcode or args.printability:
        settings = _settings(args)
        if args.px > 0.5 * settings.nozzle_diameter:
            raise _BadInput(f"--px {args.px}: the walls need a pixel below half the nozzle "
                            f"(allowed: below {0.5 * settings.nozzle_diameter:g} mm)")


def _check_memory(args, infill, settings) -> None:
    """Refuse --px / --layer whose slices would exceed the memory budget
    (the Phasor Slice node's estimate over the infill's box)."""
    from app.flags import memory_value
    from engine.graph import node_type
    from engine.nodes.phasor import print_memory_estimate

    if args.slice and (args.png or args.json):
        axis, _ = parse_slice(args.slice)
        need = node_type("PhasorSlice").memory_estimate({"axis": axis, "pixel": args.px}, {"infill": infill})
        memory_value("--px", args.px, need, lower="raise --px (coarser pixels)")
    if settings is not None:
        f = infill.fields
        need = print_memory_estimate(f.lo, f.hi, args.px, settings.layer_height)
        flag, value = ("--layer", settings.layer_height) if args.layer is not None else ("--px", args.px)
        memory_value(flag, value, need, lower="raise --px or --layer")


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


def run(args) -> int:
    from app.flags import FlagError

    out = {}
    try:
        _check_args(args)
        nid, infill = _infill(args)
        out.update(project=str(Path(args.project).resolve()), node=nid)
        settings = _print_settings(args, infill) if (args.gcode or args.printability) else None
        _check_memory(args, infill, settings)
        if args.slice and (args.png or args.json):
            _slice_outputs(args, infill, out)
        if args.gcode:
            _gcode_output(args, infill, out, settings)
        if args.printability:
            _printability_output(args, infill, out, settings)
    except (_BadInput, FlagError) as exc:
        return _fail(str(exc), 2)
    except _Failed as exc:
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
