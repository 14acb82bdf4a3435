"""`mesoforge grow` and `mesoforge study`: their registration on the command line.

The commands live in `app.grow_cmd` and `app.study_cmd`; both build graphs of
the growth nodes and evaluate them (see there). TILESET is a set name from
resources/tilesets (``TL+-``), a file stem (``tl_basic``) or a path to a
tile-set JSON file. Bad input exits with 2 and one line naming the argument;
an interrupted study exits with 130 and keeps the rows it wrote (run it
again to resume).

The study's subprocess protocol (``study_argv``, ``study_process``,
``parse_progress_line``) lives in ``engine.batch.study_process``, shared by
the command and the window.
"""

from __future__ import annotations

import sys

__all__ = ["COMMANDS", "add_parsers", "run"]

COMMANDS = ("grow", "study")


def add_parsers(sub) -> None:
    from app import grow_cmd, study_cmd

    grow_cmd.add_parser(sub)
    study_cmd.add_parser(sub)


def run(args) -> int:
    """Run ``grow`` or ``study``; a refused value exits 2 with one line."""
    from app import grow_cmd, study_cmd
    from app.flags import FlagError

    try:
        return grow_cmd.run(args) if args.command == "grow" else study_cmd.run(args)
    except (FlagError, ValueError) as exc:
        print(f"mesoforge {args.command}: {exc}", file=sys.stderr)
        return 2
