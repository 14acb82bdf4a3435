"""The one check of a node's grid-size parameter (``[nx, ny]`` / ``[nx, ny, nz]``)."""

from __future__ import annotations

import math

from engine.graph.errors import NodeInputError


def grid_shape_of(values, ndim: int, limit: int, *, where: str, owner: str, hint: str = "") -> tuple:
    """``[nx, ny(, nz)]`` -> array shape ``(ny, nx)`` / ``(nz, ny, nx)``.

    values : the parameter's integers (already range-checked by its Param)
    ndim : what the input (tile set, fields) needs; ``owner`` says who, e.g.
        ``"tile set 'TL+-' is"`` or ``"the fields are"``
    limit : most cells allowed
    where : the parameter's name, reported with the error; ``hint`` ends the
        message about the entry count (e.g. ``" (or [] for the fields' grid)"``)

    Raises NodeInputError (``where``) on a wrong entry count or too many cells.
    """
    if len(values) != ndim:
        want = "[nx, ny]" if ndim == 2 else "[nx, ny, nz]"
        raise NodeInputError(f"{where} {list(values)} has {len(values)} entries but {owner} {ndim}D: "
                             f"give {want}{hint}", where=where)
    if math.prod(values) > limit:
        raise NodeInputError(f"{where} {list(values)} has {math.prod(values)} cells; at most "
                             f"{limit} are allowed", where=where)
    return tuple(int(n) for n in values[::-1])
