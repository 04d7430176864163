"""``gtecat sdos [-p POSITION]``: each slave's CoE object dictionary, with current values.

Like IgH's ``ethercat sdos``: one line per entry, with its index and subindex, CiA 301
data type, access right, whether it can be PDO-mapped (RxPDO/TxPDO), name and the value it
holds now (decimal and hex). On the emulated bus this is the virtual slave's own dictionary.
"""

from __future__ import annotations

import argparse
from typing import Any

from . import output
from .busview import add_bus_options, bus_view

EPILOG = """\
examples:
  gtecat sdos -p 0 --eni manual_fig5_2.eni         slave 0's dictionary
  gtecat sdos -p 0 --grep homing                   entries whose name says "homing"
  gtecat sdos --json > od.json"""


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "sdos",
        help="list the CoE object dictionary (index, sub, name, type, access, value)",
        description=output.describe(__doc__),
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("file", nargs="?", help="configuration file (same as --eni)")
    p.add_argument("--grep", metavar="TEXT", help="only entries whose name contains TEXT")
    p.add_argument("--no-values", action="store_true", help="do not read the values")
    add_bus_options(p)
    p.set_defaults(func=run)


def _shown(row: dict[str, Any]) -> str:
    v, raw = row["value"], row["hex"]
    if v is None:
        return "-"
    if isinstance(v, int) and raw is not None and row["type"] not in ("BOOL",):
        return f"{v} (0x{bytes.fromhex(raw)[::-1].hex().upper()})"
    if row["type"] == "VISIBLE_STRING":
        return repr(v)
    return str(v)


def run(args: argparse.Namespace) -> int:
    with bus_view(args) as bus:
        rows = bus.sdos(args.position, not args.no_values, args.grep)
    if args.json:
        output.print_json(rows)
        return 0
    columns: list[output.Column] = [
        ("position", "pos"),
        ("index", "index:sub"),
        ("type", "type"),
        ("access", "access"),
        ("pdo", "pdo"),
        ("name", "name"),
        ("value", "value"),
    ]
    shown = [
        dict(r, index=output.hex_addr(r["index"], r["subindex"]), value=_shown(r)) for r in rows
    ]
    output.print_table(shown, columns)
    return 0
