"""``gtecat reg read|write -p POSITION ADDRESS ...``: an EtherCAT slave controller's registers.

Like IgH's ``ethercat reg_read`` / ``reg_write``: ``read ADDRESS [SIZE]`` prints SIZE bytes
(default 2) from the ESC register space in hex and as a little-endian number, with the
register's name where it has one (ETG.1000.4 table 31); ``write ADDRESS VALUE`` writes VALUE
(a number, sized by ``--size``, or hex bytes "01 02"). On the emulated bus each slave has a
virtual ESC whose registers follow the slave (AL status, station address, SII access, ...).
"""

from __future__ import annotations

import argparse

from gtecat.drives.esc.registers import Reg
from gtecat.eni.numbers import parse_int

from ..errors import ParameterError
from . import output
from .busview import add_bus_options, bus_view

EPILOG = """\
examples:
  gtecat reg read -p 0 0x0130           AL status of slave 0
  gtecat reg read 0x0000 8              type, revision, build, FMMU/SM counts of every slave
  gtecat reg write -p 0 0x0120 0x0002   AL control: request PREOP"""


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "reg",
        help="read or write ESC registers (reg read -p 0 0x0130)",
        description=output.describe(__doc__),
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("action", choices=("read", "write"))
    p.add_argument("address", help="register address, e.g. 0x0130")
    p.add_argument("value", nargs="?", help="read: SIZE in bytes (default 2); write: VALUE")
    p.add_argument("--size", type=int, help="write: bytes VALUE takes (default: 2)")
    add_bus_options(p)
    p.set_defaults(func=run)


NAMES = {int(r): r.name for r in Reg}


def _number(text: str, what: str, high: int) -> int:
    try:
        v = parse_int(text)
    except ValueError:
        raise ParameterError(f"reg: {what} {text!r} is not a number (e.g. 0x0130)") from None
    if not 0 <= v <= high:
        raise ParameterError(f"reg: {what} {text} out of range 0..0x{high:X}")
    return v


def _data(text: str, size: int | None) -> bytes:
    if " " in text.strip():
        try:
            return bytes.fromhex(text)
        except ValueError:
            raise ParameterError(f'reg write: {text!r} is not hex bytes (e.g. "01 02")') from None
    v = _number(text, "VALUE", (1 << 64) - 1)
    n = size or 2
    if v >= 1 << (8 * n):
        raise ParameterError(f"reg write: {text} does not fit {n} bytes (--size)")
    return v.to_bytes(n, "little")


def run(args: argparse.Namespace) -> int:
    address = _number(args.address, "ADDRESS", 0xFFFF)
    if args.action == "write":
        if args.value is None:
            raise ParameterError("reg write needs VALUE, e.g. gtecat reg write -p 0 0x0120 2")
        if args.position is None:
            raise ParameterError("reg write needs -p POSITION: one slave at a time")
        data = _data(args.value, args.size)
    else:
        size = _number(args.value, "SIZE", 0x1000) if args.value else 2
    rows = []
    with bus_view(args) as bus:
        for pos in bus.positions(args.position):
            if args.action == "write":
                bus.reg_write(pos, address, data)
                raw = bus.reg_read(pos, address, len(data))
            else:
                raw = bus.reg_read(pos, address, size)
            rows.append(
                {
                    "position": pos,
                    "address": address,
                    "register": NAMES.get(address, ""),
                    "bytes": raw.hex(),
                    "value": int.from_bytes(raw, "little") if len(raw) <= 8 else None,
                }
            )
    if args.json:
        output.print_json(rows)
        return 0
    for r in rows:
        raw = bytes.fromhex(r["bytes"])
        number = (
            f"  = {r['value']} (0x{r['value']:0{2 * len(raw)}X})" if r["value"] is not None else ""
        )
        name = f"  {r['register']}" if r["register"] else ""
        print(f"{r['position']:>3}  0x{address:04X}  {raw.hex(' ')}{number}{name}")
    return 0
