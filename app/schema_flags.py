"""Command-line flags generated from node parameter schemas.

A subcommand that runs a node declares which of the node's parameters it
exposes; `add_param_flags` makes one flag per parameter whose help shows the
parameter's doc, unit, range and default (all read from the `Param`, never
repeated here), and `param_values` turns the parsed text into node
parameters through the same `Param.coerce` the inspector uses, so an
out-of-range flag is refused with the schema's range before any work:

    group = add_param_flags(parser, "Grow", {"size": "--size", "periodic": "--periodic"})
    ...
    params = param_values(args, "Grow", group)     # FlagError on a bad value

Flags left out keep the node's default (argparse's default is None).  Text
forms: numbers as typed; ``int_list`` as ``8x8``, ``8,8`` or ``8 8``; ``vec3``
as ``x,y,z``; ``bool`` as ``--flag`` / ``--no-flag``; ``json`` as JSON text
or ``@file.json``.
"""

from __future__ import annotations

import argparse
import json
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping, Sequence

from .flags import FlagError, schema_value


@dataclass(frozen=True)
class ParamFlags:
    """Which flags stand for which parameters of one node type."""

    type_name: str
    flags: tuple[tuple[str, str, str], ...]     # (parameter, flag, argparse dest)

    def flag_of(self, param: str) -> str:
        return next(f for p, f, _ in self.flags if p == param)


def _param(type_name: str, name: str):
    from engine.graph import node_type

    return node_type(type_name).param(name)


def help_text(p, extra: str = "", *, required: bool = False) -> str:
    """A flag's help: the parameter's doc, unit, allowed values and default (none when required)."""
    parts = [p.doc or p.label or p.name]
    if extra:
        parts.append(extra)
    allowed = p.allowed()
    if p.kind not in ("str", "json"):
        parts.append(f"allowed: {allowed}")
    default = p.default
    if p.kind == "int_list":
        default = "x".join(str(v) for v in default) if default else "none"
    elif p.kind == "vec3":
        default = ",".join(f"{v:g}" for v in default)
    elif p.kind == "bool":
        default = "on" if default else "off"
    elif p.kind == "json":
        default = json.dumps(default)
    elif p.kind == "str" and default == "":
        default = '""'
    unit = f" {p.unit}" if p.unit and p.kind in ("float", "int", "int_list", "vec3") else ""
    if required:
        parts.append(f"required{f'; unit: {p.unit}' if unit else ''}")
    else:
        parts.append(f"default: {default}{unit if default != 'none' else ''}")
    return "; ".join(parts).replace("%", "%%")


def add_param_flags(parser, type_name: str, params: Mapping[str, str] | Sequence[str], *,
                    help_extra: Mapping[str, str] | None = None, dest_prefix: str = "",
                    required: Sequence[str] = (), typed: Sequence[str] = ()) -> ParamFlags:
    """Add one flag per parameter of node type ``type_name``.

    params : ``{parameter: flag}``, or parameter names (flag ``--name`` with ``_`` → ``-``)
    help_extra : text added to a flag's help (e.g. what the flag means on the command line)
    dest_prefix : prefix of the argparse dests (two nodes with a same-named parameter)
    required : parameters whose flag must be given (no node default fits, e.g. a size whose
        length depends on another input)
    typed : float / int parameters whose parsed value (``args.<dest>``) should already be a
        number rather than the text typed (the schema still checks it in `param_values`)
    """
    mapping = dict(params) if isinstance(params, Mapping) else {n: "--" + n.replace("_", "-") for n in params}
    extra = dict(help_extra or {})
    out = []
    for name, flag in mapping.items():
        p = _param(type_name, name)
        dest = dest_prefix + flag.lstrip("-").replace("-", "_")
        text = help_text(p, extra.get(name, ""), required=name in required)
        if p.kind == "bool":
            parser.add_argument(flag, dest=dest, action=argparse.BooleanOptionalAction, default=None, help=text)
        elif p.kind == "enum":
            parser.add_argument(flag, dest=dest, default=None, metavar="{" + ",".join(map(str, p.choices)) + "}",
                                help=text)
        else:
            metavar = {"float": "X", "int": "N", "int_list": "NxN", "vec3": "X,Y,Z", "json": "JSON|@FILE",
                       "str": "TEXT", "samples": "JSON"}[p.kind]
            number = {"float": float, "int": int}.get(p.kind) if name in typed else None
            parser.add_argument(flag, dest=dest, default=None, metavar=metavar, help=text,
                                required=name in required, **({"type": number} if number else {}))
        out.append((name, flag, dest))
    return ParamFlags(type_name, tuple(out))


def _parse(p, flag: str, text):
    """Text as typed → the value to hand to the schema (FlagError for unreadable text)."""
    kind = p.kind
    if kind in ("bool", "str") or not isinstance(text, str):
        return text
    if kind == "enum":
        for choice in p.choices:
            if str(choice) == text:
                return choice
        return text
    if kind in ("float", "int"):
        try:
            return int(text) if kind == "int" and re.fullmatch(r"[+-]?\d+", text.strip()) else float(text)
        except ValueError:
            raise FlagError(flag, text, "not a number", p.allowed()) from None
    if kind in ("int_list", "vec3"):
        pieces = [s for s in re.split(r"[x,\s]+", text.strip()) if s]
        try:
            values = [int(s) if kind == "int_list" and re.fullmatch(r"[+-]?\d+", s) else float(s) for s in pieces]
        except ValueError:
            want = "integers like 8x8" if kind == "int_list" else "three numbers like 1,0,0"
            raise FlagError(flag, text, "not " + want, p.allowed()) from None
        return values
    if kind in ("json", "samples"):
        source = text
        if text.startswith("@"):
            try:
                source = Path(text[1:]).read_text(encoding="utf-8")
            except OSError as exc:
                raise FlagError(flag, text, f"cannot read {text[1:]!r}: {exc.strerror or exc}") from None
        try:
            return json.loads(source)
        except ValueError as exc:
            raise FlagError(flag, text, f"not JSON ({exc.msg} at character {exc.pos})") from None
    return text


def param_values(args, group: ParamFlags, *, only_given: bool = True) -> dict:
    """``{parameter: value}`` for the flags of ``group`` given on the command line,
    each coerced by its `Param` (FlagError naming the flag and the schema's range).
    With ``only_given=False`` the node defaults fill the rest."""
    out = {}
    for name, flag, dest in group.flags:
        text = getattr(args, dest, None)
        p = _param(group.type_name, name)
        if text is None:
            if not only_given:
                out[name] = p.default
            continue
        out[name] = schema_value(flag, _parse(p, flag, text), group.type_name, name, as_typed=text)
    return out
