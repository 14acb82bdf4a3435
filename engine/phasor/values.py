"""Values of the phasor-infill family that travel on graph ports: painted control
fields and the singularity energy of a slice.  Immutable once produced; no
graph import here.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from engine.geometry.values import MeshValue

__all__ = ["PhasorFieldsValue", "SliceEnergy"]


@dataclass(frozen=True, eq=False)
class PhasorFieldsValue:
    """Painted control fields of phasor infill (port type "PhasorFields").

    fields : engine.phasor.PhasorFields, D, F, Gamma on an (nz, ny, nx) grid
        over the box ``fields.lo .. fields.hi`` (mm).
    domain : MeshValue or None, the part to fill (None: the whole box).
    changed : (slice, slice, slice) or None
        ``[z, y, x]`` cells that differ from this node's previous result
        (all three ``slice(0, 0)`` when none do); None when there is no
        previous result to compare with (everything is new).
    n_strokes : int, brush strokes painted over the initial fields.
    """

    fields: object
    domain: MeshValue | None = None
    changed: tuple | None = None
    n_strokes: int = 0


@dataclass(frozen=True)
class SliceEnergy:
    """Singularity energy of one slice (port type "Energy"; Tricard et al. eq. 10).

    value : float, F_S(q), the fraction of the slice's part pixels where the
        singularity measure S(x) of p_v or of p_w exceeds q (NaN when no
        pixel of the slice lies inside the part).
    v, w : float, F_S(q) of p_v alone and of p_w alone.
    q : float, the threshold.
    pixels : int, pixels counted (|Omega|: inside the part, off the slice border).
    state : str, which noise was measured ("raw", "aligned", "aligned+filtered").
    engine : str, the evaluator of the slice ("gpu" or "numpy").
    """

    value: float
    v: float
    w: float
    q: float
    pixels: int
    state: str
    engine: str = ""

    def summary(self) -> dict:
        return {"F_S": self.value, "F_S_v": self.v, "F_S_w": self.w, "q": self.q,
                "pixels": self.pixels, "state": self.state, "engine": self.engine}
