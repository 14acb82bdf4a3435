"""`mesoforge homogenize INPUT`: effective stiffness of a project's cell, a voxel /
pixel cell or a closed mesh.

A project (``.json``) is homogenized as the window does it: the nodes its
Voxel node needs plus a Material Matrix node on the Voxel node (the
project's own one if it has it), built with `app.graph_run.build` and
evaluated by the Evaluator, so the numbers are the node's Stiffness to the
bit.  The flags come from the node schemas (`app.schema_flags`): ``--E`` and
``--nu`` from the Voxel node, ``--resolution`` from the Material Matrix node.

A voxel grid (``.npy``, ``.vti``), a pixel image (``.png``) or a closed mesh
is read by a Voxel Import node with a Material Matrix node on it (resolution
0: the grid as it is), evaluated the same way; ``--E`` / ``--nu`` set the
Voxel Import node's material (the Voxel node's parameters), ``--res`` its mesh
voxelization.
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
IMPORT_ID = "import"              # id of the Voxel Import node reading a file INPUT
IMPORT_FLAGS = {"res": "--res", "E": "--E", "nu": "--nu", "path": "INPUT"}


def add_parser(sub) -> None:
    from app.schema_flags import add_param_flags

    h = sub.add_parser("homogenize", help="effective elastic stiffness of a periodic cell")
    h.add_argument("input", help=".json project (its Voxel node's solid), .npy / .vti voxel grid, "
                                 ".png pixel image (2D), or a closed mesh (.stl .obj .ply .3mf)")
    voxel = add_param_flags(h, "Voxel", VOXEL_FLAGS)
    matrix = add_param_flags(h, "MaterialMatrix", MATRIX_FLAGS,
                             help_extra={"resolution": "for a .json project INPUT"})
    mesh = add_param_flags(h, "VoxelImport", {"res": "--res"}, help_extra={"res": "for a mesh INPUT"},
                           typed=("res",))
    h.add_argument("--json", action="store_true", help="print a JSON summary")
    h.set_defaults(homogenize_flags=(voxel, matrix, mesh))


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

    voxel_flags, matrix_flags, _ = args.homogenize_flags
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


# -- a grid, an image or a mesh: Voxel Import -> Material Matrix ---------------------------------
def file_graph(path: str, params: dict):
    """A document of a Voxel Import node reading ``path`` (with ``params`` set
    on it: E, nu, res) and a Material Matrix node solving its grid as it is
    (resolution 0), as the window builds it."""
    from app.graph_run import build

    return build(0, {IMPORT_ID: ("VoxelImport", {"path": path, **params}),
                     MATRIX_ID: ("MaterialMatrix", {"resolution": 0})},
                 [(IMPORT_ID, "voxels", MATRIX_ID, "voxels")])


def _unprefixed(text: str, node_id: str, type_name: str) -> str:
    """A node's error without the ``node 'id' (Type): `` the evaluator puts before it."""
    prefix = f"node {node_id!r} ({type_name}): "
    return text.split(prefix, 1)[1] if prefix in text else text


def check_args(args):
    """The document of a file INPUT once every argument is checked against the
    node schemas and the file's header; FlagError before the file is read."""
    from app.evaluation import GraphMemoryError, check_graph_memory
    from app.flags import FlagError, memory_error
    from app.schema_flags import param_values
    from engine.geometry.voxel_inputs import INPUT_SUFFIXES, MESH_SUFFIXES

    voxel_flags, _, import_flags = args.homogenize_flags
    params = {**param_values(args, voxel_flags), **param_values(args, import_flags)}   # the material is the Voxel node's
    if args.resolution is not None:
        raise FlagError("--resolution", args.resolution, "only for a .json project INPUT",
                        "--res for a mesh INPUT")
    suffix = Path(args.input).suffix.lower()
    if suffix not in INPUT_SUFFIXES:
        raise FlagError("INPUT", args.input, f"unsupported extension {suffix!r}" if suffix else "no extension",
                        "a file ending in " + ", ".join((PROJECT_SUFFIX,) + tuple(INPUT_SUFFIXES)))
    if not Path(args.input).is_file():
        raise FlagError("INPUT", args.input, "no such file", "an existing file")
    if "res" in params and suffix not in MESH_SUFFIXES:
        raise FlagError("--res", args.res, "only for a mesh INPUT", "grids and images are read as they are")
    doc = file_graph(args.input, params)
    try:
        check_graph_memory(doc)           # the grid's shape from the file's header: nothing is read
    except GraphMemoryError as exc:
        if "res" in params:
            raise memory_error("--res", args.res, exc, lower="--res") from None
        raise FlagError("INPUT", args.input, _unprefixed(str(exc), exc.node, exc.type_name)) from None
    return doc


def run_file(args) -> tuple[int, dict | str]:
    """Homogenize a voxel grid, pixel image or mesh through the graph:
    ``(0, summary)`` or ``(code, message)``."""
    from app.flags import FlagError
    from app.graph_run import GraphRunFailed, evaluate

    try:
        doc = check_args(args)
    except FlagError as exc:
        return 2, str(exc)
    t0 = time.perf_counter()
    try:
        report = evaluate(doc, flag_of={"VoxelImport": IMPORT_FLAGS, "MaterialMatrix": {}})
    except GraphRunFailed as exc:
        if exc.node_id == IMPORT_ID and exc.where == "path":          # the file is refused
            return 2, f"INPUT {args.input}: {_unprefixed(str(exc), IMPORT_ID, 'VoxelImport')}"
        text = _unprefixed(str(exc), MATRIX_ID, "MaterialMatrix")
        if exc.node_id == MATRIX_ID and text.startswith("MemoryError: "):   # the solver's exact count
            return 2, f"INPUT {args.input}: {text[len('MemoryError: '):]}"
        return 1, text
    voxels, stiffness = report.outputs[IMPORT_ID]["voxels"], report.outputs[MATRIX_ID]["stiffness"]
    out = {"input": args.input, "kind": voxels.kind, **stiffness_json(stiffness)}
    convention = out.pop("convention")
    out.update({"seconds": round(time.perf_counter() - t0, 4), "convention": convention})
    if voxels.info:
        out["source"] = voxels.info
    if voxels.kind == "pixels" and stiffness.symmetry != "singular":
        from engine.physics.material_sphere import material_polar
        theta, e_theta = material_polar(np.asarray(stiffness.C), n=72)
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
