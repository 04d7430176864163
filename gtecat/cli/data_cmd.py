"""``gtecat data [-p POSITION]``: the process image, as the master holds it after a cycle.

Like IgH's ``ethercat data``: the bytes of the image, here in the GT raw view (each slave's
outputs then inputs, the offsets GT_GetEcatRawData takes) as a hex dump per slave, with
``--entries`` one line per PDO entry and its value. ``--json`` for scripts; ``--cycles N``
lets N cycles pass after the bus reached OP before the image is read (on a running
controller none by default: the image as it holds it now).
"""

from __future__ import annotations

import argparse

from . import output
from .busview import add_bus_options, bus_view, controller_address

EPILOG = """\
examples:
  gtecat data manual_fig5_2.eni               hex dump of the GT raw image, slave by slave
  gtecat data -p 0 --entries                  slave 0's entries with their values"""


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "data",
        help="show the process image (GT raw view) after a cycle",
        description=output.describe(__doc__),
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("file", nargs="?", help="configuration file (same as --eni)")
    p.add_argument("--entries", action="store_true", help="one line per PDO entry, decoded")
    p.add_argument(
        "--cycles",
        type=int,
        help="cycles to run first (default 1; 0 on a running controller: its image as it is)",
    )
    add_bus_options(p)
    p.set_defaults(func=run)


def _dump(data: bytes, start: int) -> list[str]:
    lines = []
    for i in range(0, len(data), 16):
        chunk = data[i : i + 16]
        lines.append(f"  {start + i:5d}  {chunk.hex(' ')}")
    return lines


def run(args: argparse.Namespace) -> int:
    cycles = args.cycles
    if cycles is None:  # a bus of its own has not cycled yet; a running one has
        cycles = 0 if controller_address(args) else 1
    with bus_view(args) as bus:
        slaves = bus.data(args.position, max(0, cycles))
    if args.json:
        output.print_json(slaves)
        return 0
    for s in slaves:
        print(f"slave {s['position']}  {s['name']}  GT raw {s['gt_offset']}+{s['gt_size']}")
        if args.entries:
            rows = [
                {
                    "dir": e["dir"],
                    "index": output.hex_addr(e["index"], e["subindex"]),
                    "raw": f"{e['gt_bit'] >> 3}.{e['gt_bit'] & 7}",
                    "value": e["value"],
                    "hex": output.hex_word(int(e["value"]), e["bits"])
                    if isinstance(e["value"], int)
                    else "-",
                    "name": e["name"],
                }
                for e in s["entries"]
            ]
            cols: list[output.Column] = [
                ("dir", "dir"),
                ("index", "index:sub"),
                ("raw", "GT raw"),
                ("value", "value"),
                ("hex", "hex"),
                ("name", "name"),
            ]
            print("\n".join("  " + line for line in output.table(rows, cols).splitlines()))
        else:
            print("\n".join(_dump(bytes.fromhex(s["bytes"]), s["gt_offset"])) or "  (empty)")
    return 0
