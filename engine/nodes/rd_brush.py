"""The Reaction Diffusion dock's own settings as `Param` schemas: the brush and live growth.

A brush stroke is stored in a node parameter (RDGrow ``edits``: erase / draw in
growth cells; RDFields ``gamma_c``: solid marks in field cells), whose check
(`engine.nodes.rd`) decides what a stroke may hold.  These schemas give the
dock's fields that rule with a unit and a default; `brush_check` runs the
node's own check on a one-stamp stroke, so the field refuses exactly what the
node would.  ``every`` (steps between live frames) is capped by RDGrow's
``max_steps`` range: more steps per frame than a growth may take show nothing.
"""

from __future__ import annotations

from engine.graph import Param, ParamError, node_type

__all__ = ["BRUSH_RADIUS", "SOLID_VALUE", "LIVE_EVERY", "brush_check"]

# RDGrow's max_steps maximum (engine.nodes.rd; tests/engine/nodes/test_dock_settings.py keeps them equal)
_MAX_STEPS = 10_000_000

BRUSH_RADIUS = Param("radius", "float", 3.0, 0.0, None, unit="cells",
                     doc="brush radius: growth cells (erase / draw), field cells (mark solid)")
SOLID_VALUE = Param("value", "float", 1.0, 0.0, 1.0, doc="Gamma_c of the marked cells: 1 = solid")
LIVE_EVERY = Param("every", "int", 100, 1, _MAX_STEPS, unit="steps",
                   doc="growth steps per direction between two live frames")


def _stroke(setting: str, value, solid: bool) -> tuple:
    radius = value if setting == "radius" else 1.0
    if solid:
        level = value if setting == "value" else 1.0
        return "RDFields", "gamma_c", [[{"centre": [0.5, 0.5], "radius": radius, "value": level}]]
    return "RDGrow", "edits", [{"mode": "erase", "centre": [0.5, 0.5], "radius": radius}]


def brush_check(setting: str, *, solid: bool = False):
    """callable(value) raising ValueError with the node's message when a stroke with
    brush ``setting`` ("radius" or "value") at that value would be refused."""
    def check(value):
        kind, name, data = _stroke(setting, value, solid)
        try:
            node_type(kind).param(name).coerce(data)
        except ParamError as exc:
            raise ValueError(exc.expected.split(": ", 1)[-1]) from None     # "stroke 0 stamp 0: " off
    return check
