"""`mesoforge homogenize INPUT`: effective stiffness of a voxel / pixel cell or a closed mesh."""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np


def add_parser(sub) -> None:
    h = sub.add_parser("homogenize", help="effective elastic stiffness of a periodic cell")
    h.add_argument("input", help=".npy / .vti voxel grid, .png pixel image (2D), or a closed mesh (.stl .obj .ply .3mf)")
    h.add_argument("--E", type=float, default=1.0, help="Young's modulus of the base material (default 1)")
    h.add_argument("--nu", type=float, default=0.45, help="Poisson's ratio of the base material (default 0.45)")
    h.add_argument("--res", type=int, help="voxels per edge when voxelizing a mesh (default 100)")
    h.add_argument("--json", action="store_true", help="print a JSON summary")


def check_args(args) -> tuple:
    """``(shape, kind)`` of the input from its header once every argument is
    checked; raises FlagError before anything is read in full."""
    from app.flags import FlagError, memory_error, schema_value
    from engine.geometry.voxel_inputs import INPUT_SUFFIXES, MAX_RES, SOLVER_BYTES_PER_DOF, check_memory, grid_shape_of
    from engine.memory import MemoryLimitError

    # the base material's ranges are the Voxel node's, which carries them in a graph
    args.E = schema_value("--E", args.E, "Voxel", "E")
    args.nu = schema_value("--nu", args.nu, "Voxel", "nu")
    if args.res is not None and not 2 <= args.res <= MAX_RES:
        raise FlagError("--res", args.res, "out of range", f"an integer in [2, {MAX_RES}]")
    suffix = Path(args.input).suffix.lower()
    if suffix not in INPUT_SUFFIXES:
        raise FlagError("INPUT", args.input, f"unsupported extension {suffix!r}" if suffix else "no extension",
                        "a file ending in " + ", ".join(INPUT_SUFFIXES))
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


def run(args) -> int:
    from app.flags import FlagError
    from engine.geometry.voxel_inputs import load_voxel_grid, validate_density
    from engine.physics.elastic import engineering_constants, symmetry_class, zener_ratio
    from engine.physics.homogenize2d import homogenize_pixels
    from engine.physics.homogenize3d import homogenize_voxels

    def fail(msg: str, code: int = 2) -> int:
        print(f"mesoforge homogenize: {msg}", file=sys.stderr)
        return code

    try:
        check_args(args)
    except FlagError as exc:
        return fail(str(exc))
    try:
        grid, kind, info = load_voxel_grid(args.input, res=args.res)
        validate_density(grid, cubic=(kind == "voxels"))
    except (ValueError, OSError) as exc:
        return fail(f"INPUT {args.input}: {exc}")
    t0 = time.perf_counter()
    try:
        solve = homogenize_voxels if kind == "voxels" else homogenize_pixels
        result = solve(np.asarray(grid, dtype=np.float64), E=args.E, nu=args.nu)
    except MemoryError as exc:     # the solver's own check, on the exact solid count
        return fail(f"INPUT {args.input}: {exc}")
    except ValueError as exc:
        return fail(str(exc), 1)
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
        "convention": "Voigt, engineering shear strains, order (xx, yy, zz, yz, xz, xy); 2D (xx, yy, xy)",
        **({"source": info} if info else {}),
    }
    if kind == "pixels" and sym != "singular":
        from engine.physics.material_sphere import material_polar
        theta, e_theta = material_polar(C, n=72)
        out["polar"] = {"theta_deg": np.degrees(theta).round(6).tolist(), "E": e_theta.tolist()}
    if args.json:
        print(json.dumps(out, indent=1, default=float))
        return 0
    np.set_printoptions(precision=5, suppress=True, linewidth=120)
    print(f"{kind} {tuple(grid.shape)}, density {out['density']:.4f}, symmetry {sym}"
          + (f", Zener {out['zener']:.4f}" if out["zener"] is not None else ""))
    print("C =")
    print(C)
    for k, v in out["constants"].items():
        print(f"  {k:>8} = {v:.6g}")
    if out["dropped_fraction"] > 0:
        print(f"  dropped {out['dropped_fraction']:.4%} of the cell as disconnected islands")
    return 0
