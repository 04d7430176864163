"""``gtecat sii read [-p POSITION]``: each slave's SII (its EEPROM), decoded or raw.

Like IgH's ``ethercat sii_read``: identity, name, mailbox, sync managers and the PDOs the SII
describes; ``--raw`` prints the bytes (hex dump), ``--output FILE`` saves them (one slave).
On the emulated bus the SII is the one the virtual slave's ESC holds.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ..errors import ParameterError
from . import output
from .busview import add_bus_options, bus_view

EPILOG = """\
examples:
  gtecat sii read -p 0 --eni manual_fig5_2.eni
  gtecat sii read -p 0 --raw
  gtecat sii read -p 0 --output slave0.sii"""


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "sii",
        help="read the slaves' SII (EEPROM): identity, mailbox, sync managers, PDOs",
        description=output.describe(__doc__),
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("action", choices=("read",))
    p.add_argument("--raw", action="store_true", help="hex dump instead of the decoded fields")
    p.add_argument("--output", metavar="FILE", help="write the SII bytes of slave -p to FILE")
    add_bus_options(p)
    p.set_defaults(func=run)


def decoded(raw: bytes) -> dict[str, object]:
    from gtecat.drives.esc.sii import parse_sii

    info = parse_sii(raw)
    i = info.identity
    return {
        "vendor_id": i.vendor_id,
        "product_code": i.product_code,
        "revision": i.revision_no,
        "serial": getattr(i, "serial_no", 0),
        "name": info.name,
        "group": info.group,
        "alias": info.alias,
        "mailbox_protocols": [
            f.name for f in type(info.mailbox_protocols) if f & info.mailbox_protocols
        ],
        "rx_mailbox": list(info.rx_mailbox),
        "tx_mailbox": list(info.tx_mailbox),
        "sync_managers": [
            {"start": sm.start, "length": sm.length, "control": sm.control, "type": sm.type.name}
            for sm in info.sync_managers
        ],
        "pdos": [
            {
                "dir": d,
                "index": p.index,
                "name": p.name,
                "sm": p.sm,
                "entries": [
                    {"index": e.index, "subindex": e.subindex, "bits": e.bit_len, "name": e.name}
                    for e in p.entries
                ],
            }
            for d, pdos in (("out", info.rx_pdos), ("in", info.tx_pdos))
            for p in pdos
        ],
        "bytes": len(raw),
    }


def run(args: argparse.Namespace) -> int:
    if args.output and args.position is None:
        raise ParameterError("sii read --output needs -p POSITION: one slave per file")
    result = []
    with bus_view(args) as bus:
        for pos in bus.positions(args.position):
            raw = bus.sii(pos)
            if args.output:
                Path(args.output).write_bytes(raw)
                print(f"wrote {args.output}: {len(raw)} bytes of slave {pos}'s SII")
                return 0
            result.append((pos, raw))
    if args.raw:
        if args.json:
            output.print_json([{"position": p, "bytes": r.hex()} for p, r in result])
            return 0
        for pos, raw in result:
            print(f"slave {pos}: {len(raw)} bytes")
            for i in range(0, len(raw), 16):
                print(f"  {i:04X}  {raw[i : i + 16].hex(' ')}")
        return 0
    rows = [{"position": pos, **decoded(raw)} for pos, raw in result]
    if args.json:
        output.print_json(rows)
        return 0
    for r in rows:
        print(f"slave {r['position']}: {r['name']}")
        print(
            f"  vendor 0x{r['vendor_id']:08X}  product 0x{r['product_code']:08X}  "
            f"revision 0x{r['revision']:08X}  serial {r['serial']}  alias {r['alias']}"
        )
        protocols = ", ".join(r["mailbox_protocols"]) or "none"
        print(f"  mailbox: {protocols}; out {r['rx_mailbox'][0]:#06x}+{r['rx_mailbox'][1]}, "
              f"in {r['tx_mailbox'][0]:#06x}+{r['tx_mailbox'][1]}")  # fmt: skip
        for n, sm in enumerate(r["sync_managers"]):
            print(f"  SM{n}: {sm['start']:#06x}+{sm['length']}, control {sm['control']:#04x}, "
                  f"{sm['type']}")  # fmt: skip
        for p in r["pdos"]:
            rx = "RxPDO" if p["dir"] == "out" else "TxPDO"
            print(f'  {rx} 0x{p["index"]:04X} "{p["name"]}" (SM{p["sm"]})')
            for e in p["entries"]:
                print(
                    f'    0x{e["index"]:04X}:{e["subindex"]:02X}, {e["bits"]:>2} bit, "{e["name"]}"'
                )
    return 0
