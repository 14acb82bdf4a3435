"""What the implicit-media nodes share: turning a kernel's refusal into a node error."""

from __future__ import annotations

from typing import Callable, TypeVar

from engine.graph.errors import NodeInputError

T = TypeVar("T")


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
