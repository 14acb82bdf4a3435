"""`mesoforge homogenize INPUT`: effective stiffness of a project's cell, a voxel /
pixel cell or a closed mesh.

A project (``.json``) is homogenized as the window does it: the nodes its
Voxel node needs plus a Material Matrix node on the Voxel node (the
project's own one if it has it), built with `app.graph_run.build` and
evaluated by the Evaluator, so the numbers are the node's Stiffness to the
bit.  The flags come from the node schemas (`app.schema_flags`): ``--E`` and
``--nu`` from the Voxel node, ``--resolution`` from the Material Matrix node.

Voxel grids (``.npy``, ``.vti``), pixel images (``.png``) and meshes are no
graph input: no node loads them, so they go to the homogenization kernels
directly, with the Voxel node's material ranges.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

VOXEL_FLAGS = {"E": "--E", "nu": "--nu"}
MATRIX_FLAGS = {"resolution": "--resolution"}
PROJECT_SUFFIX = ".json"
CONVENTION = "Voigt, engineering shear strains, order (xx, yy, zz, yz, xz, xy); 2D (xx, yy, xy)"
MATRIX_ID = "homogenize"          # id of the Material Matrix node added to a project without one


def add_parser(sub) -> None:
    from app.schema_flags import add_param_flags

    h = sub.add_parser("homogenize", help="effective elastic stiffness of a periodic cell")
    h.add_argument("input", help=".json project (its Voxel node's solid), .npy / .vti voxel grid, "
                                 ".png pixel image (2D), or a closed mesh (.stl .obj .ply .3mf)")
    voxel = add_param_flags(h, "Voxel", VOXEL_FLAGS)
    matrix = add_param_flags(h, "MaterialMatrix", MATRIX_FLAGS,
                             help_extra={"resolution": "for a .json project INPUT"})
    h.add_argument("--res", type=int, help="voxels per edge when voxelizing a mesh INPUT (default 100)")
    h.add_argument("--json", action="store_true", help="print a JSON summary")
    h.set_defaults(homogenize_flags=(voxel, matrix))


def _material(args) -> dict:
    """``{"E": ..., "nu": ...}``: the flags given, checked by the Voxel node's schema, its defaults else."""
    from app.schema_flags import param_values

    return param_values(args, args.homogenize_flags[0], only_given=False)


# -- a project: a small graph evaluated by the Evaluator ------------------------------------------
def project_graph(project, material: dict, matrix: dict):
    """``(doc, matrix node id)``: the nodes ``project``'s Voxel node needs, with
    ``material`` set on it, and a Material Matrix node on its voxels (the
    project's own one, if it has one, with ``matrix`` set on it).

    Node ids, the document seed and the order of connections are kept, so every
    node runs as in the project.  Raises ValueError when there is no Voxel node.
    """
    from app.graph_run import build, part_of
    from engine.graph.query import downstream_of_type

    voxel = next((nid for nid, node in project.nodes.items() if node.type_name == "Voxel"), None)
    if voxel is None:
        raise ValueError("no Voxel node: connect the solid to homogenize to a Voxel node")
    nodes, edges = part_of(project, voxel)
    nodes[voxel] = ("Voxel", {**nodes[voxel][1], **material})
    mm = downstream_of_type(project, voxel, "MaterialMatrix")
    own = dict(project.nodes[mm].params) if mm is not None else {}
    if mm is None:
        mm = MATRIX_ID
        while mm in project.nodes:
            mm += "_"
    nodes[mm] = ("MaterialMatrix", {**own, **matrix})
    edges.append((voxel, "voxels", mm, "voxels"))
    return build(project.seed, nodes, edges), mm


def _check_project(args):
    """``(project, doc, matrix id)`` once every argument is checked against the
    project; FlagError before anything is evaluated."""
    from app.evaluation import GraphMemoryError, check_graph_memory
    from app.flags import FlagError, memory_error
    from app.schema_flags import param_values
    from engine.graph import GraphError, ProjectFileError, load_project

    voxel_flags, matrix_flags = args.homogenize_flags
    material = param_values(args, voxel_flags)      # only the flags given: the project's values stay
    matrix = param_values(args, matrix_flags)
    if args.res is not None:
        raise FlagError("--res", args.res, "only for a mesh INPUT", "--resolution for a .json project")
    try:
        project = load_project(args.input)
    except ProjectFileError as exc:
        raise FlagError("INPUT", args.input, str(exc)) from None
    try:
        doc, mm = project_graph(project, material, matrix)
        check_graph_memory(doc)
    except GraphMemoryError as exc:
        if exc.type_name == "MaterialMatrix" and "resolution" in matrix:
            raise memory_error("--resolution", args.resolution, exc, lower="--resolution") from None
        raise FlagError("INPUT", args.input, str(exc)) from None
    except (ValueError, GraphError) as exc:
        raise FlagError("INPUT", args.input, str(exc)) from None
    return project, doc, mm


def stiffness_json(stiffness, **extra) -> dict:
    """The JSON summary of a Material Matrix node's `Stiffness` (C, S, constants...)."""
    C = np.asarray(stiffness.C)
    constants = dict(stiffness.constants)
    shape = stiffness.grid_shape or (stiffness.resolution,) * 3
    return {**extra, "shape": list(shape), "E": stiffness.E, "nu": stiffness.nu,
            "density": float(stiffness.density), "dropped_fraction": float(stiffness.dropped_fraction),
            "C": C.tolist(), "S": np.linalg.inv(C).tolist() if constants else None, "constants": constants,
            "symmetry": stiffness.symmetry, "zener": stiffness.zener, "iterations": int(stiffness.iterations),
            "convention": CONVENTION}


def run_project(args) -> tuple[int, dict | str]:
    """Homogenize a project through the graph: ``(0, summary)`` or ``(code, message)``."""
    from app.flags import FlagError
    from app.graph_run import GraphRunFailed, evaluate
    from engine.graph import Evaluator

    try:
        project, doc, mm = _check_project(args)
    except FlagError as exc:
        return 2, str(exc)
    evaluator = Evaluator()
    evaluator.import_state(project.node_state)      # a grown / repainted node as it was saved
    t0 = time.perf_counter()
    try:
        report = evaluate(doc, flag_of={"Voxel": VOXEL_FLAGS, "MaterialMatrix": MATRIX_FLAGS},
                          evaluator=evaluator)
    except GraphRunFailed as exc:
        return 1, str(exc)
    stiffness = report.outputs[mm]["stiffness"]
    return 0, {"input": args.input, "kind": "project", "node": mm,
               **stiffness_json(stiffness), "seconds": round(time.perf_counter() - t0, 4)}


# -- a grid, an image or a mesh: the kernels (no node loads them) -------------------------------
def check_args(args) -> tuple | None:
    """The grid shape of a file INPUT from its header (None when unknown)
    once every argument is checked; raises FlagError before anything is read
    in full."""
    from app.flags import FlagError, memory_error
    from engine.geometry.voxel_inputs import INPUT_SUFFIXES, MAX_RES, SOLVER_BYTES_PER_DOF, check_memory, grid_shape_of
    from engine.memory import MemoryLimitError

    # the base material's ranges are the Voxel node's, which carries them in a graph
    material = _material(args)
    args.E, args.nu = material["E"], material["nu"]
    if args.resolution is not None:
        raise FlagError("--resolution", args.resolution, "only for a .json project INPUT",
                        "--res for a mesh INPUT")
    if args.res is not None and not 2 <= args.res <= MAX_RES:
        raise FlagError("--res", args.res, "out of range", f"an integer in [2, {MAX_RES}]")
    suffix = Path(args.input).suffix.lower()
    if suffix not in INPUT_SUFFIXES:
        raise FlagError("INPUT", args.input, f"unsupported extension {suffix!r}" if suffix else "no extension",
                        "a file ending in " + ", ".join((PROJECT_SUFFIX,) + tuple(INPUT_SUFFIXES)))
    if not Path(args.input).is_file():
        raise FlagError("INPUT", args.input, "no such file", "an existing file")
    shape = grid_shape_of(args.input, res=args.res)
    if shape is not None:
        try:
            check_memory(shape, per_dof_bytes=SOLVER_BYTES_PER_DOF)
        except MemoryLimitError as exc:
            if args.res is not None:
                raise memory_error("--res", args.res, exc, lower="--res") from None
            raise FlagError("INPUT", args.input, str(exc)) from None
    return shape


def run_file(args) -> tuple[int, dict | str]:
    """Homogenize a voxel grid, pixel image or mesh: ``(0, summary)`` or ``(code, message)``."""
    from app.flags import FlagError
    from engine.geometry.voxel_inputs import load_voxel_grid, validate_density
    from engine.physics.elastic import engineering_constants, symmetry_class, zener_ratio
    from engine.physics.homogenize2d import homogenize_pixels
    from engine.physics.homogenize3d import homogenize_voxels

    try:
        check_args(args)
    except FlagError as exc:
        return 2, str(exc)
    try:
        grid, kind, info = load_voxel_grid(args.input, res=args.res)
        validate_density(grid, cubic=(kind == "voxels"))
    except (ValueError, OSError) as exc:
        return 2, f"INPUT {args.input}: {exc}"
    t0 = time.perf_counter()
    try:
        solve = homogenize_voxels if kind == "voxels" else homogenize_pixels
        result = solve(np.asarray(grid, dtype=np.float64), E=args.E, nu=args.nu)
    except MemoryError as exc:     # the solver's own check, on the exact solid count
        return 2, f"INPUT {args.input}: {exc}"
    except ValueError as exc:
        return 1, str(exc)
    C = np.asarray(result.C)
    try:
        sym = symmetry_class(C, tol=1e-3)
        constants = engineering_constants(C)
    except ValueError:  # a mechanism: C is singular, no compliance
        sym, constants = "singular", {}
    out = {
        "input": args.input, "kind": kind, "shape": list(grid.shape), "E": args.E, "nu": args.nu,
        "density": float(result.density), "dropped_fraction": float(result.dropped_fraction),
        "C": C.tolist(), "S": np.linalg.inv(C).tolist() if constants else None, "constants": constants,
        "symmetry": sym, "zener": float(zener_ratio(C)) if sym == "cubic" else None,
        "iterations": int(result.iterations), "seconds": round(time.perf_counter() - t0, 4),
        "convention": CONVENTION,
        **({"source": info} if info else {}),
    }
    if kind == "pixels" and sym != "singular":
        from engine.physics.material_sphere import material_polar
        theta, e_theta = material_polar(C, n=72)
        out["polar"] = {"theta_deg": np.degrees(theta).round(6).tolist(), "E": e_theta.tolist()}
    return 0, out


def run(args) -> int:
    is_project = Path(args.input).suffix.lower() == PROJECT_SUFFIX
    code, out = (run_project if is_project else run_file)(args)
    if code != 0:
        print(f"mesoforge homogenize: {out}", file=sys.stderr)
        return code
    if args.json:
        print(json.dumps(out, indent=1, default=float))
        return 0
    np.set_printoptions(precision=5, suppress=True, linewidth=120)
    C = np.asarray(out["C"])
    print(f"{out['kind']} {tuple(out['shape'])}, density {out['density']:.4f}, symmetry {out['symmetry']}"
          + (f", Zener {out['zener']:.4f}" if out["zener"] is not None else ""))
    print("C =")
    print(C)
    for k, v in out["constants"].items():
        print(f"  {k:>8} = {v:.6g}")
    if out["dropped_fraction"] > 0:
        print(f"  dropped {out['dropped_fraction']:.4%} of the cell as disconnected islands")
    return 0
