"""``gtecat data [-p POSITION]``: the process image, as the master holds it after a cycle.

Like IgH's ``ethercat data``: the bytes of the image, here in the GT raw view (each slave's
outputs then inputs, the offsets GT_GetEcatRawData takes) as a hex dump per slave, with
``--entries`` one line per PDO entry and its value. ``--json`` for scripts; ``--cycles N``
lets N cycles pass after the bus reached OP before the image is read.
"""

from __future__ import annotations

import argparse

from eni.model import Direction

from . import output
from .busview import Bus, add_bus_options

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
    p.add_argument("--cycles", type=int, default=1, help="cycles to run first (default 1)")
    add_bus_options(p)
    p.set_defaults(func=run)


def _dump(data: bytes, start: int) -> list[str]:
    lines = []
    for i in range(0, len(data), 16):
        chunk = data[i : i + 16]
        lines.append(f"  {start + i:5d}  {chunk.hex(' ')}")
    return lines


def run(args: argparse.Namespace) -> int:
    with Bus(args) as bus:
        bus.ctl.wait_ms(max(0, args.cycles) * bus.ctl.clock.cycle_ns / 1e6)
        image = bus.master.image
        slaves = []
        for pos in bus.positions():
            s = bus.layout.slaves[pos]
            region = _region(bus, pos)
            entries = []
            for p in s.entries:
                if p.is_padding:
                    continue
                value = image.access(p).get()
                entries.append(
                    {
                        "dir": "out" if p.direction == Direction.OUT else "in",
                        "index": p.index,
                        "subindex": p.subindex,
                        "name": p.name,
                        "bits": p.bits,
                        "gt_bit": p.gt_bit,
                        "value": value,
                    }
                )
            slaves.append(
                {
                    "position": pos,
                    "name": s.name,
                    "gt_offset": s.gt_offset,
                    "gt_size": s.gt_size,
                    "bytes": region.hex(),
                    "entries": entries,
                }
            )
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


def _region(bus: Bus, pos: int) -> bytes:
    """Slave ``pos``'s GT raw region: its outputs then its inputs, read entry by entry."""
    s = bus.layout.slaves[pos]
    out = bytearray(s.gt_size)
    image = bus.master.image
    for p in s.entries:
        if p.is_padding:
            continue
        value = image.access(p).get()
        if isinstance(value, float):
            import struct

            raw = struct.pack("<f" if p.bits == 32 else "<d", value)
            start = p.gt_bit // 8 - s.gt_offset
            out[start : start + len(raw)] = raw
            continue
        v = int(value) & ((1 << p.bits) - 1)
        rel = p.gt_bit - s.gt_offset * 8
        for b in range(p.bits):
            if v >> b & 1:
                out[(rel + b) // 8] |= 1 << ((rel + b) % 8)
    return bytes(out)
