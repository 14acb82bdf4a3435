"""Command-line values checked before any work: one refusal line per bad value.

Every subcommand refuses a bad value with exit code 2 and one line on stderr,
``mesoforge <cmd>: --flag VALUE: reason (allowed: range)``, before it starts
work or writes a file.  Ranges are not kept here: a value that becomes a node
parameter is checked by that parameter's schema (`schema_value`), a request's
size by the node type's memory estimate against the budget of
:mod:`engine.memory` (`memory_value`), an output path by its suffix and
directory (`output_path`).
"""

from __future__ import annotations

import argparse
import os
import re
from pathlib import Path

from engine.memory import MemoryLimitError, check_budget, format_bytes


class FlagError(ValueError):
    """A refused command-line value (exit code 2), naming the flag, the value
    and what is allowed."""

    def __init__(self, flag: str, value, reason: str, allowed: str = ""):
        self.flag, self.value, self.reason, self.allowed = flag, value, reason, allowed
        text = f"{flag} {shown(value)}: {reason}" if value is not None else f"{flag}: {reason}"
        super().__init__(text + (f" (allowed: {allowed})" if allowed else ""))


def shown(value) -> str:
    """A value as the user typed it: words bare, lists space-separated, empty or
    spaced text quoted."""
    if isinstance(value, (list, tuple)):
        return " ".join(shown(v) for v in value)
    if isinstance(value, str):
        return value if value and not re.search(r"\s", value) else repr(value)
    if isinstance(value, Path):
        return shown(str(value))
    return repr(value) if isinstance(value, float) else str(value)


def schema_value(flag: str, value, type_name: str, param: str, *, as_typed=None):
    """``value`` coerced by the parameter schema of node type ``type_name``
    (its range and kind, kept once there); FlagError when it refuses it.
    ``as_typed`` is the value to quote (default ``value``)."""
    from engine.graph import ParamError, node_type

    p = node_type(type_name).param(param)
    try:
        return p.coerce(value)
    except ParamError as exc:
        reason = "out of range" if exc.expected.startswith("a value in") else f"expected {exc.expected}"
        raise FlagError(flag, value if as_typed is None else as_typed, reason, p.allowed()) from None


def setting_value(flag: str, text, param):
    """The text typed for a setting that is not a node parameter (a preview or fit setting
    declared as a `Param` in the engine), read as its kind and coerced by it; FlagError naming
    the flag and the allowed range."""
    from engine.graph import ParamError

    value = text
    if param.kind in ("int", "float") and isinstance(text, str):
        s = text.strip()
        try:
            value = int(s) if param.kind == "int" and s.lstrip("+-").isdigit() else float(s)
        except ValueError:
            raise FlagError(flag, text, "not a number", param.allowed()) from None
    try:
        return param.coerce(value)
    except ParamError as exc:
        reason = "out of range" if exc.expected.startswith("a value in") else f"expected {exc.expected}"
        raise FlagError(flag, text, reason, param.allowed()) from None


def memory_value(flag: str, value, need: int, *, lower: str = "") -> int:
    """Refuse ``need`` bytes over the memory budget as a FlagError naming the flag."""
    try:
        return check_budget(need, what=flag)
    except MemoryLimitError as exc:
        raise memory_error(flag, value, exc, lower=lower) from None


def memory_error(flag: str, value, exc: MemoryLimitError, *, lower: str = "") -> FlagError:
    """A MemoryLimitError as the refusal of ``flag``; ``lower`` says what to
    change ("--tile", or a whole phrase starting with "raise" / "lower")."""
    env = os.environ.get("MESOFORGE_MEMORY_LIMIT", "").strip()
    where = "allowed by MESOFORGE_MEMORY_LIMIT" if env else "available"
    return FlagError(flag, value, f"needs about {format_bytes(exc.need)} of memory, more than the "
                                  f"{format_bytes(exc.budget)} {where}",
                     f"up to {format_bytes(exc.budget)}; {_hint(lower or flag)}")


def _hint(text: str) -> str:
    return text if text.split()[0] in ("raise", "lower") else f"lower {text}"


def output_path(flag: str, path, suffixes) -> Path | None:
    """Check a file to write before any work: not empty, one of ``suffixes``,
    not a directory, in an existing writable directory.  None stays None."""
    if path is None:
        return None
    want = "a file ending in " + ", ".join(suffixes)
    text = str(path)
    if not text.strip():
        raise FlagError(flag, text, "empty path", want)
    p = Path(text)
    if p.suffix.lower() not in suffixes:
        raise FlagError(flag, text, f"unsupported extension {p.suffix!r}" if p.suffix else "no extension", want)
    if p.is_dir():
        raise FlagError(flag, text, "is a directory", want)
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise FlagError(flag, text, f"directory {str(parent)!r} does not exist", want + " in an existing directory")
    if not os.access(parent, os.W_OK):
        raise FlagError(flag, text, f"directory {str(parent)!r} is not writable", want + " in a writable directory")
    return p


def distinct_outputs(*pairs) -> None:
    """Refuse two output flags naming the same file (``(flag, path)`` pairs; None skipped)."""
    seen = {}
    for flag, path in pairs:
        if path is None:
            continue
        key = os.path.abspath(str(path))
        if key in seen:
            raise FlagError(flag, str(path), f"the same file as {seen[key]}", "a different file")
        seen[key] = flag


class OneLineParser(argparse.ArgumentParser):
    """argparse whose refusals are one line, ``mesoforge <cmd>: --flag: reason``, exit 2."""

    def error(self, message):
        m = re.match(r"argument ([^:]+): (.*)", message, re.S)
        if m:
            message = f"{m.group(1).split('/')[0]}: {m.group(2)}"
        message = " ".join(message.split())
        self.exit(2, f"{self.prog}: {message} (see {self.prog} --help)\n")
