"""``gtecat states [-p POSITION] [STATE]``: show the slaves' AL states, or request one.

Like IgH's ``ethercat states``: without STATE, each slave's AL state and status code; with
STATE (INIT, PREOP, SAFEOP, OP, BOOT) the master requests it of every slave (or of the one
``-p`` names) and shows where each one ended and why it refused, if it did. On the emulated
bus the change lasts for this command only, on a running controller (--controller) it stays.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from gtecat.drives.slave import AlState

from ..errors import ParameterError
from . import output
from .busview import add_bus_options, bus_view

EPILOG = """\
examples:
  gtecat states manual_fig5_2.eni                 every slave's state
  gtecat states -p 0 PREOP --eni manual_fig5_2.eni"""


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "states",
        help="show the slaves' AL states, or request one (INIT, PREOP, SAFEOP, OP, BOOT)",
        description=output.describe(__doc__),
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "words",
        nargs="*",
        metavar="[FILE] [STATE]",
        help="configuration file (same as --eni) and/or the state to request, in any order",
    )
    add_bus_options(p)
    p.set_defaults(func=run)


def _split(args: argparse.Namespace) -> AlState | None:
    """``states FILE``, ``states STATE``, ``states FILE STATE``: a word that names an AL
    state is the state, one that ends in .eni/.xml or names a file is the ENI."""
    target = None
    args.file = None
    for word in args.words:
        if word.upper() in AlState.__members__ and target is None:
            target = AlState[word.upper()]
        elif args.file is None and (word.lower().endswith((".eni", ".xml")) or Path(word).exists()):
            args.file = word
        else:
            raise ParameterError(
                f"no AL state {word!r}: give INIT, PREOP, SAFEOP, OP or BOOT (and the ENI "
                "file, if any, once)"
            )
    return target


def run(args: argparse.Namespace) -> int:
    target = _split(args)
    with bus_view(args) as bus:
        rows = bus.states(args.position, target.name if target is not None else None)
    if args.json:
        output.print_json(rows)
        return 0
    cols: list[output.Column] = [("position", "pos"), ("state", "state"), ("status", "AL status")]
    if target is not None:
        cols.insert(1, ("before", "was"))
    cols.append(("name", "name"))
    output.print_table(rows, cols)
    bad = [r for r in rows if r["refused"]]
    if bad:
        raise ParameterError(
            "; ".join(f"slave {r['position']} refused {target.name}: {r['refused']}" for r in bad)
        )
    return 0
