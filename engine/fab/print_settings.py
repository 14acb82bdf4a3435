"""Fused-filament print settings: one validated, immutable record.

Lengths are in millimetres, speeds in mm/s (the G-code writer converts to
the mm/min of ``F`` words), temperatures in degrees Celsius.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

# (low, high, low_inclusive, high_inclusive) per numeric setting. The ranges
# are deliberately wide: they refuse nonsense and typos, not unusual printers.
_RANGES = {
    "nozzle_diameter": (0.05, 3.0, True, True),
    "layer_height": (0.0, None, False, True),          # upper bound: nozzle
    "filament_diameter": (0.5, 5.0, True, True),
    "print_speed": (0.0, 1000.0, False, True),
    "travel_speed": (0.0, 1000.0, False, True),
    "first_layer_speed": (0.0, 1000.0, False, True),
    "nozzle_temperature": (0.0, 500.0, True, True),
    "bed_temperature": (0.0, 200.0, True, True),
    "extrusion_multiplier": (0.0, 5.0, False, True),
    "retraction_length": (0.0, 20.0, True, True),
    "retraction_speed": (0.0, 300.0, False, True),
    "retraction_min_travel": (0.0, 100.0, True, True),
    "perimeters": (0, 20, True, True),
}


def _describe(lo, hi, lo_in, hi_in):
    left = "[" if lo_in else "("
    right = "]" if hi_in else ")"
    return f"{left}{lo}, {hi}{right}"


@dataclass(frozen=True)
class PrintSettings:
    """Settings of one FFF print.

    Attributes
    ----------
    nozzle_diameter : float
        mm; also the extrusion (wall) width ``w``.
    layer_height : float
        mm, in (0, nozzle_diameter].
    filament_diameter : float
        mm (1.75 or 2.85 in practice).
    print_speed, travel_speed, first_layer_speed : float
        mm/s; the first layer's extrusion moves use ``first_layer_speed``.
    nozzle_temperature, bed_temperature : float
        degrees Celsius; 0 means "do not heat".
    extrusion_multiplier : float
        Flow factor applied to the volumetric extrusion.
    relative_extrusion : bool
        ``M83`` (relative E) when True, ``M82`` (absolute E) otherwise.
    retraction_length, retraction_speed : float
        mm of filament and mm/s; length 0 disables retraction.
    retraction_min_travel : float
        mm; shorter travel moves are made without retracting.
    perimeters : int
        Number of perimeter loops around each part outline (0 allowed).
    perimeters_first : bool
        Print the perimeters before the infill walls of a layer.
    offset : (2,) float
        mm; placement of the part origin on the bed (added to X and Y).
    """

    nozzle_diameter: float = 0.4
    layer_height: float = 0.2
    filament_diameter: float = 1.75
    print_speed: float = 40.0
    travel_speed: float = 120.0
    first_layer_speed: float = 20.0
    nozzle_temperature: float = 210.0
    bed_temperature: float = 60.0
    extrusion_multiplier: float = 1.0
    relative_extrusion: bool = False
    retraction_length: float = 1.0
    retraction_speed: float = 35.0
    retraction_min_travel: float = 1.0
    perimeters: int = 1
    perimeters_first: bool = True
    offset: tuple = field(default=(100.0, 100.0))

    def __post_init__(self):
        for name, (lo, hi, lo_in, hi_in) in _RANGES.items():
            value = getattr(self, name)
            if name == "perimeters":
                try:
                    whole = not isinstance(value, bool) and int(value) == value
                except (TypeError, ValueError):
                    whole = False
                if not whole:
                    raise ValueError(f"perimeters must be a whole number, got {value!r}")
                object.__setattr__(self, name, int(value))
            else:
                try:
                    value = float(value)
                except (TypeError, ValueError):
                    raise ValueError(f"{name} must be a number, got {value!r}") from None
                object.__setattr__(self, name, value)
            if name == "layer_height":
                hi = self.nozzle_diameter
            ok = math.isfinite(value)
            ok = ok and (value >= lo if lo_in else value > lo)
            ok = ok and (value <= hi if hi_in else value < hi)
            if not ok:
                where = _describe(lo, hi, lo_in, hi_in)
                extra = " (at most the nozzle diameter)" if name == "layer_height" else ""
                raise ValueError(f"{name} = {value!r} is outside the allowed range {where}{extra}")
        for name in ("relative_extrusion", "perimeters_first"):
            if not isinstance(getattr(self, name), (bool, int)):
                raise ValueError(f"{name} must be True or False, got {getattr(self, name)!r}")
            object.__setattr__(self, name, bool(getattr(self, name)))
        try:
            off = tuple(float(v) for v in self.offset)
        except (TypeError, ValueError):
            raise ValueError(f"offset must be two numbers (x, y) in mm, got {self.offset!r}") from None
        if len(off) != 2 or not all(math.isfinite(v) for v in off):
            raise ValueError(f"offset must be two finite numbers (x, y) in mm, got {self.offset!r}")
        object.__setattr__(self, "offset", off)

    @property
    def line_width(self) -> float:
        """Extrusion width ``w`` in mm (the nozzle diameter)."""
        return self.nozzle_diameter

    @property
    def filament_per_mm(self) -> float:
        """mm of filament pushed per mm of extruded path:
        ``w * h * multiplier / (pi * (d_f / 2)**2)``."""
        area = math.pi * (0.5 * self.filament_diameter) ** 2
        return self.line_width * self.layer_height * self.extrusion_multiplier / area

    def replace(self, **changes) -> "PrintSettings":
        """A copy with ``changes`` applied (validated again)."""
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict:
        """Plain JSON-able dict of every setting."""
        d = dataclasses.asdict(self)
        d["offset"] = list(self.offset)
        return d

    @classmethod
    def from_dict(cls, data: dict) -> "PrintSettings":
        """Inverse of :meth:`to_dict`; unknown keys are refused by name."""
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(data) - names)
        if unknown:
            raise ValueError(f"unknown print settings {unknown}; expected some of {sorted(names)}")
        return cls(**data)
