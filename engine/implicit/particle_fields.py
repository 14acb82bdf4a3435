"""What a particle cloud reads beyond its own hash: a density field, an offset field and a cell rule.

Paper 004, section 3.1 (eqs. 6-7 and the rejection control paragraph) and
supplementary 10.2 ("Particle Correlation").  `particles.Suspension` takes

* a density field D (a `field_sampling.GridField` with samples in [0, 1]):
  the spatially varying acceptance probability of rejection control; a cell
  keeps its particle only if ``u_0 < density(c) * D(centre of c)``;
* an offset field o (a GridField, mm): added to the scalar offset at x;
* a cell rule (a `congruence.CongruenceRule` or `CombinedRule`): a cell
  keeps its particle only if ``rule.keep(c)``.  Removing whole blocks of
  cells leaves the survivors grouped, a positive correlation (10.2: "the
  modular function can be used to generate a positive correlation");
  `clusters` is the modular rule of that paragraph, in our own form.

The checks here are the cloud's boundary: they refuse what would break the
field's lower-bound guarantee (see the `particles` module docstring).
"""

from __future__ import annotations

import numpy as np

from .congruence import MAX_MODULUS, CombinedRule, CongruenceRule
from .field_sampling import GridField, as_grid_field

__all__ = ["clusters", "check_density_field", "check_offset_field", "check_rule"]


def _is_int(v) -> bool:
    return isinstance(v, (int, np.integer)) and not isinstance(v, (bool, np.bool_))


def clusters(period: int, size: int) -> CongruenceRule:
    """Cubic clusters of cells: keep cell (i, j, k) iff ``i mod period``, ``j mod period`` and
    ``k mod period`` all lie in [0, size).  Blocks of size^3 cells, `period` cells apart,
    separated by gaps of ``period - size`` empty cells along each axis (the mathematical mod,
    so negative cells continue the pattern).

    Raises
    ------
    ValueError
        If period is not an int in [2, MAX_MODULUS] or size not an int in [1, period).
    """
    if not (_is_int(period) and 2 <= period <= MAX_MODULUS):
        raise ValueError(f"cluster period must be an int in [2, {MAX_MODULUS}] cells, got {period!r}")
    if not (_is_int(size) and 1 <= size < period):
        raise ValueError(f"cluster size must be an int in [1, {int(period) - 1}] cells (< the period "
                         f"{period!r}, else every cell is kept), got {size!r}")
    coords = tuple(((1, tuple(int(a == axis) for a in range(3))),) for axis in range(3))
    band = tuple((r, 1) for r in range(int(size)))
    return CongruenceRule(coords, (int(period),) * 3, (band,) * 3, inner="or", outer="and")


def check_density_field(obj) -> GridField | None:
    """`obj` (None, a GridField or a Field-like with values / lo / hi) as a GridField of
    acceptance factors.

    Raises
    ------
    ValueError
        Naming density_field, if `obj` is no grid field or a sample lies outside [0, 1].
    """
    if obj is None:
        return None
    g = as_grid_field(obj, "density_field")
    if g.minimum < 0.0 or g.maximum > 1.0:
        raise ValueError(f"density_field values must lie in [0, 1] (a probability factor), got "
                         f"samples from {g.minimum!r} to {g.maximum!r}")
    return g


def check_offset_field(obj, offset: float, cell: float) -> GridField | None:
    """`obj` (None, a GridField or a Field-like) as a GridField of offsets (mm), such that the
    total offset ``offset + o(x)`` stays below w / 2 everywhere (o never exceeds its largest
    sample).  There is no lower limit: where ``offset + o(x) <= -w / 2`` no particle reaches
    (each particle's inner radius is at most its bounding radius <= w / 2), the field is
    simply positive there.

    Raises
    ------
    ValueError
        Naming offset_field, if `obj` is no grid field or ``offset + max(o) >= w / 2``.
    """
    if obj is None:
        return None
    g = as_grid_field(obj, "offset_field")
    if not offset + g.maximum < 0.5 * cell:
        raise ValueError(f"offset + max(offset_field) = {offset!r} + {g.maximum!r} mm must be < w / 2 = "
                         f"{0.5 * cell!r} mm (cell width {cell!r} mm), so that no material appears away "
                         f"from the particles")
    return g


def check_rule(rule):
    """`rule` if it is None, a CongruenceRule or a CombinedRule.

    Raises
    ------
    ValueError
        Naming rule, otherwise.
    """
    if rule is not None and not isinstance(rule, (CongruenceRule, CombinedRule)):
        raise ValueError(f"rule must be a CongruenceRule, a CombinedRule or None, got {type(rule).__name__}")
    return rule
