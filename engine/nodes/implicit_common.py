"""What the implicit-media nodes share: the axis names, congruence rules as JSON, and turning a
kernel's refusal into a node error."""

from __future__ import annotations

from typing import Callable, TypeVar

from engine.graph.errors import NodeInputError
from engine.implicit import congruence

T = TypeVar("T")

AXES = ("x", "y", "z")


def polynomial(data):
    """JSON ``[[a, [ex, ey, ez]], ...]`` as the kernel's tuple of monomials."""
    return tuple((int(a), tuple(int(e) for e in ex)) for a, ex in data)


def rule_json(data):
    """A congruence rule as JSON: ``{"polynomials": [[[a, [ex, ey, ez]], ...], ...],
    "moduli": [m or null, ...], "classes": [[[value, sign], ...], ...], "inner": "or",
    "outer": "or"}``; checked by building it (ValueError names what is wrong)."""
    if data is None:
        return None
    if not isinstance(data, dict):
        raise ValueError("expected an object with polynomials, moduli and classes")
    try:
        rule = make_rule(data)
    except (TypeError, KeyError) as exc:
        raise ValueError(f"expected polynomials, moduli and classes lists ({exc})") from None
    return data if rule is not None else None


def make_rule(data):
    return congruence.CongruenceRule(
        tuple(polynomial(p) for p in data["polynomials"]),
        tuple(None if m is None else int(m) for m in data["moduli"]),
        tuple(tuple((int(v), int(s)) for v, s in c) for c in data["classes"]),
        inner=data.get("inner", "or"), outer=data.get("outer", "or"))


def built(make: Callable[[], T], params: dict, aliases: dict[str, str] | None = None) -> T:
    """``make()``, with a `ValueError` of the engine.implicit value it builds re-raised as a
    `NodeInputError` located at the parameter its message names (the kernel's message says
    what was wrong and the allowed range).

    aliases : words of a kernel message -> the node parameter they mean (e.g. "cell width"
        -> "cell"), tried before the parameter names themselves.
    """
    try:
        return make()
    except ValueError as exc:
        text = str(exc)
        where = next((p for word, p in (aliases or {}).items() if word in text), None)
        if where is None:
            names = sorted(params, key=len, reverse=True)
            where = next((n for n in names if n in text or n.replace("_", " ") in text), None)
        raise NodeInputError(text, where=where) from None
