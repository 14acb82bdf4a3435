"""TopOpt: the topology-optimised design that reaction-diffusion growth fills
(Garnier, Schmidt & Rohmer 2022, section 3.2): density rho (the infill
space), element stress tensors per load case and the principal directions
that orient the growth.

    TopOpt --design--> RDFields --> RDGrow --> RDCompile
"""

from __future__ import annotations

import math
import time

import numpy as np

from engine.graph.errors import NodeInputError
from engine.graph.node import NodeType, register
from engine.graph.schema import Param, Port
from engine.topopt.values import DesignValue

# node preset -> (engine preset, dimension, default resolution [nx, ny(, nz)])
PRESETS = {
    "cantilever": ("cantilever_2d", 2, [64, 32]),
    "lbeam": ("lbeam_2d", 2, [40, 40]),
    "lbeam_stress": ("lbeam_stress_2d", 2, [40, 40]),
    "mbb3d": ("mbb_3d", 3, [32, 16, 4]),
    "bridge": ("bridge_2d_single", 2, [60, 40]),
    "bridge_multi": ("bridge_2d_multi", 2, [60, 40]),
}
MAX_ELEMENTS = {2: 250_000, 3: 120_000}
# Peak bytes per element of an optimisation (stiffness matrix, its factor,
# filter, stresses): measured ~7 kB in 2D (128x64) and ~45 kB in 3D (32x16x8).
BYTES_PER_ELEMENT = {2: 8_000, 3: 48_000}
OVERRIDE_KEYS = ("supports", "load_cases", "passive_runs")


def _check_overrides(data):
    if not isinstance(data, dict):
        raise ValueError(f"an object with some of {list(OVERRIDE_KEYS)}, got {type(data).__name__}")
    unknown = sorted(set(data) - set(OVERRIDE_KEYS))
    if unknown:
        raise ValueError(f"an object with some of {list(OVERRIDE_KEYS)} (unknown: {unknown})")
    return data


def preset_problem(name: str, resolution, *, volfrac=0.0, penal=3.0, rmin=0.0, overrides=None):
    """The engine Problem of node preset ``name`` on ``resolution`` ([nx, ny(, nz)],
    [] = the preset's default).  NodeInputError names the parameter at fault."""
    from engine.topopt.presets import preset
    from engine.topopt.problem import Problem

    engine_name, dim, default = PRESETS[name]
    res = list(resolution) or default
    if len(res) != dim:
        want = "[nx, ny]" if dim == 2 else "[nx, ny, nz]"
        raise NodeInputError(f"resolution {res} has {len(res)} entries but preset {name!r} is {dim}D: give "
                             f"{want}", where="resolution")
    if math.prod(res) > MAX_ELEMENTS[dim]:
        raise NodeInputError(f"resolution {res} has {math.prod(res)} elements; at most {MAX_ELEMENTS[dim]} "
                             f"are allowed in {dim}D", where="resolution")
    nx, ny = res[0], res[1]
    kwargs = {}
    if name.startswith("lbeam"):
        if nx != ny:
            raise NodeInputError(f"resolution {res}: the L-beam is square, give [n, n]", where="resolution")
    else:
        kwargs["aspect"] = nx / ny
    if dim == 3:
        kwargs["depth"] = res[2] / ny
    try:
        problem = preset(engine_name, ny, **kwargs)
    except ValueError as exc:
        raise NodeInputError(f"preset {name!r} at resolution {res}: {exc}", where="resolution") from None
    if tuple(problem.shape[::-1]) != tuple(res):
        raise NodeInputError(f"preset {name!r} cannot be built on {res} (it gives {list(problem.shape[::-1])})",
                             where="resolution")
    changes = {k: v for k, v in (("volfrac", volfrac), ("rmin", rmin)) if v}
    changes["penal"] = penal
    try:
        problem = problem.replace(**changes)
    except ValueError as exc:
        text = str(exc)
        where = next((k for k in changes if text.startswith(k)), "volfrac")
        raise NodeInputError(text, where=where) from None
    if overrides:
        try:
            problem = Problem.from_dict({**problem.to_dict(), **overrides})
        except (ValueError, TypeError, AttributeError) as exc:
            raise NodeInputError(f"problem: {exc}", where="problem") from None
    return problem


def combined_tensor(sigma, compliances, theta=None, pnorm=8.0):
    """The tensor that orients the growth, its principal values and directions.

    One load case: its stress.  Several: ``sqrt(sum_i w_i sigma_i^2)``, the
    weights ``w_i = (c_i / c_max)^(P - 1)`` of the compliances' p-norm, which
    is blind to each case's sign; with an optimised material angle ``theta``
    (2D) the first direction is that angle and the values are
    ``sqrt(n . M n)`` along it and across it.

    Returns
    -------
    sigma_combined : grid + (d, d); values : grid + (d,); rotation : grid + (d, d)
    """
    from engine.rd.tensor_field import principal_decomposition, reconstruct_tensor

    s = np.asarray(sigma, dtype=np.float64)
    if s.shape[0] == 1 and theta is None:
        values, rotation = principal_decomposition(s[0])
        return s[0], values, rotation
    c = np.asarray(compliances, dtype=np.float64)
    w = (c / c.max()) ** (pnorm - 1.0) if c.max() > 0 else np.ones_like(c)
    m = np.einsum("c,c...ij,c...jk->...ik", w, s, s)
    if theta is None:
        lam, vec = np.linalg.eigh(m)
        root = np.einsum("...ik,...k,...jk->...ij", vec, np.sqrt(np.maximum(lam, 0.0)), vec)
        values, rotation = principal_decomposition(0.5 * (root + np.swapaxes(root, -1, -2)))
        return reconstruct_tensor(values, rotation), values, rotation
    t = np.asarray(theta, dtype=np.float64)
    n = np.stack([np.cos(t), np.sin(t)], axis=-1)
    q = np.stack([-np.sin(t), np.cos(t)], axis=-1)
    rotation = np.stack([n, q], axis=-1)
    values = np.sqrt(np.maximum(np.stack([np.einsum("...i,...ij,...j->...", a, m, a) for a in (n, q)], -1), 0.0))
    return reconstruct_tensor(values, rotation), values, rotation


@register
class TopOptNode(NodeType):
    """Density-based topology optimisation (SIMP with a density filter) of one
    of the paper's problems: 2D cantilever, L-beam (compliance or
    stress-aware), 3D MBB beam, five-load bridge as one load case or five
    (density and material orientation, eq. 19).  `problem` overrides the
    preset's supports, load cases or passive regions (the engine's Problem
    JSON, nodes [ix, iy(, iz)])."""

    type_name = "TopOpt"
    title = "Topology Optimisation"
    code = "to"
    family = "topology"
    outputs = (Port("design", "Design"),)
    params = (
        Param("preset", "enum", "cantilever", choices=tuple(PRESETS),
              doc="the paper's problems: cantilever, L-beam, stress-aware L-beam, 3D MBB, bridge single / "
                  "multi load case"),
        Param("resolution", "int_list", [], 2, 1024, unit="elements",
              doc="elements [nx, ny(, nz)]; [] = the preset's default"),
        Param("volfrac", "float", 0.0, 0.0, 0.95, doc="material volume fraction; 0 = the preset's"),
        Param("penal", "float", 3.0, 1.0, 8.0, doc="SIMP penalty p"),
        Param("rmin", "float", 0.0, 0.0, 50.0, unit="elements", doc="density filter radius; 0 = the preset's"),
        Param("max_iter", "int", 60, 1, 2000, doc="optimisation iterations at most"),
        Param("problem", "json", {}, check=_check_overrides,
              doc="overrides of the preset: supports, load_cases, passive_runs (Problem JSON)"),
    )

    memory_param = "resolution"

    @classmethod
    def memory_estimate(cls, params, inputs_shape_info=None) -> int:
        _, dim, default = PRESETS[params["preset"]]
        res = list(params["resolution"]) or list(default)
        return math.prod(res) * BYTES_PER_ELEMENT[dim]

    def evaluate(self, inputs, params, ctx):
        from engine.topopt import element_stress, optimise

        problem = preset_problem(params["preset"], params["resolution"], volfrac=params["volfrac"],
                                 penal=params["penal"], rmin=params["rmin"], overrides=params["problem"])
        t0 = time.perf_counter()
        try:
            result = optimise(problem, max_iter=params["max_iter"], progress=ctx.progress)
        except ValueError as exc:
            raise NodeInputError(f"the optimisation refused the problem: {exc}", where="problem") from None
        seconds = time.perf_counter() - t0
        ctx.check()
        sigma = element_stress(problem, result.rho, result.displacements)
        combined, values, rotation = combined_tensor(sigma, result.compliances, result.theta)
        hi = np.array(problem.shape[::-1], dtype=np.float64) * problem.h
        return {"design": DesignValue(result.rho, sigma, combined, rotation, values, problem, result,
                                      np.zeros(problem.dim), hi, seconds)}
