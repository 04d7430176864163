"""Bus inspection in the spirit of the IgH ``ethercat`` tool: ``slaves``, ``pdos``, ``sdo``.

Each verb opens the bus the way ``GT_Open`` would (``--eni`` or ``GTECAT_ENI``, else
``./Gecat.eni``; ``--backend``/``--iface`` for pysoem), brings it up, answers and
closes.  Human tables by default, ``--json`` for scripts.
"""

from __future__ import annotations

import argparse
import struct
from typing import Any

from gtecat.eni.numbers import parse_int

from ..errors import ParameterError
from . import output
from .busview import add_bus_options, bus_view, open_bus

__all__ = ["open_bus"]

TYPES = {  # --type name -> (struct code, size)
    "bool": ("?", 1),
    "int8": ("b", 1),
    "uint8": ("B", 1),
    "int16": ("h", 2),
    "uint16": ("H", 2),
    "int32": ("i", 4),
    "uint32": ("I", 4),
    "int64": ("q", 8),
    "uint64": ("Q", 8),
    "float": ("f", 4),
    "double": ("d", 8),
}
#: CiA 301 VISIBLE_STRING (0x0009): device name 1008h, versions 1009h/100Ah
STRING = "string"
#: CiA 301 data type name (the dictionary's) -> --type name
FROM_DICTIONARY = {
    "BOOL": "bool",
    "INT8": "int8",
    "UINT8": "uint8",
    "INT16": "int16",
    "UINT16": "uint16",
    "INT32": "int32",
    "UINT32": "uint32",
    "INT64": "int64",
    "UINT64": "uint64",
    "REAL32": "float",
    "VISIBLE_STRING": STRING,
}

SDO_EPILOG = """\
OBJECT is an index (0x6041), an index:subindex (0x6041:00) or an object's name
("Statusword"; looked up in the emulated slave's dictionary). Without --type the
type comes from that dictionary, else the value prints as raw bytes.

examples:
  gtecat sdo upload -p 0 0x1018:01                 vendor id of slave 0
  gtecat sdo upload 0 Statusword                   by name
  gtecat sdo download -p 0 0x6060 0 8              modes of operation := 8 (CSP)
  gtecat sdo upload 0 0x6502 0 --type uint32 --backend pysoem --iface eth0
  gtecat sdo upload 0 Statusword --controller unix:/tmp/ctl.sock

With a gtecat running (gtecat ps), the command reads and writes that one's bus: the
only one running, --attach ID, or --controller ADDRESS (GTECAT_CONTROLLER; gtecat ps
shows which bus each has).  With none running it starts a fresh bus of its own, and a
download lasts for that command only (use a script and `gtecat run` for sequences)."""


def _file(p: argparse.ArgumentParser) -> None:
    # ``gtecat slaves x.eni`` reads like ``gtecat map x.eni``; --eni says the same
    p.add_argument("file", nargs="?", help="configuration file (same as --eni)")


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "slaves",
        help="list the slaves: position, state, identity, axes",
        description="List the slaves of the bus: position, AL state, identity, axes, GT raw "
        "region.",
        epilog="examples:\n  gtecat slaves manual_fig5_2.eni\n  gtecat slaves -p 2 --json",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    _file(p)
    add_bus_options(p)
    p.set_defaults(func=run_slaves)
    p = sub.add_parser(
        "pdos",
        help="show each slave's sync managers, PDOs and entries",
        epilog="examples:\n  gtecat pdos manual_fig5_2.eni\n  gtecat pdos -p 0 --json",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    _file(p)
    add_bus_options(p)
    p.set_defaults(func=run_pdos)
    p = sub.add_parser(
        "sdo",
        help="SDO upload / download",
        usage="gtecat sdo {upload,download} [-p POSITION | SLAVE] OBJECT [SUB] [VALUE] [options]",
        epilog=SDO_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("action", choices=("upload", "download"))
    p.add_argument(
        "words", nargs="+", metavar="ARG", help="[SLAVE] OBJECT [SUB] [VALUE] (see below)"
    )
    p.add_argument(
        "--type",
        default=None,
        choices=sorted([*TYPES, STRING]),
        help="data type (default: the dictionary's on the emulated bus, else raw bytes)",
    )
    add_bus_options(p)
    p.set_defaults(func=run_sdo)


def run(args: argparse.Namespace) -> int:  # the dispatcher's fallback
    return int(args.func(args))


def _hex(v: int, w: int = 8) -> str:
    return f"0x{v:0{w}X}"


def run_slaves(args: argparse.Namespace) -> int:
    with bus_view(args) as bus:
        rows = bus.slaves(args.position)
    if args.json:
        output.print_json(rows)
        return 0
    print(
        f"{'pos':>3}  {'state':<6} {'vendor':<10} {'product':<10} {'rev':<10} "
        f"{'axes':<8} {'GT raw':<9} name"
    )
    for r in rows:
        axes = ",".join(str(a) for a in r["axes"]) or "-"
        raw = f"{r['gt_offset']}+{r['gt_size']}"
        print(
            f"{r['position']:>3}  {r['state']:<6} {_hex(r['vendor_id'])} "
            f"{_hex(r['product_code'])} {_hex(r['revision'])} {axes:<8} {raw:<9} {r['name']}"
        )
    return 0


def run_pdos(args: argparse.Namespace) -> int:
    with bus_view(args) as bus:
        out = bus.pdos(args.position)
    if args.json:
        output.print_json(out)
        return 0
    for s in out:
        print(f"=== slave {s['position']}: {s['name']}")
        for p in s["pdos"]:
            rx = "RxPDO" if p["dir"] == "out" else "TxPDO"
            print(
                f"  SM{p['sm'] if p['sm'] is not None else '?'}: {rx} 0x{p['index']:04X} "
                f'"{p["name"]}"'
            )
            for e in p["entries"]:
                print(
                    f"    0x{e['index']:04X}:{e['subindex']:02X}, {e['bits']:>2} bit, "
                    f'{e["type"] or "-":<6} "{e["name"]}"'
                )
    return 0


def _encode(text: str, type_name: str) -> bytes:
    """VALUE as the bytes of ``--type`` (little endian, CiA 301); a bad value is one line."""
    if type_name == STRING:
        return text.encode("utf-8")
    code, _size = TYPES[type_name]
    try:
        v: float | int = float(text) if code in "fd" else parse_int(text)
    except ValueError:
        kind = "a number" if code in "fd" else "an integer (e.g. 10, -3, 0x1F)"
        raise ParameterError(f"VALUE {text!r} is not {kind} for --type {type_name}") from None
    try:
        return struct.pack("<" + code, v)
    except struct.error as e:
        raise ParameterError(f"{text} does not fit {type_name}: {e}") from None


def _number(text: str, what: str, high: int) -> int:
    try:
        v = parse_int(text)
    except ValueError:
        raise ParameterError(
            f"sdo: {what} {text!r} is not a number: INDEX and SUB must be numbers, "
            "e.g. 0x6041 0 (or an object's name on the emulated bus)"
        ) from None
    if not 0 <= v <= high:
        raise ParameterError(f"sdo: {what} {text} out of range 0..0x{high:X}")
    return v


def _is_number(text: str) -> bool:
    try:
        parse_int(text)
    except ValueError:
        return False
    return True


def _split_words(args: argparse.Namespace) -> tuple[int, str, str | None, str | None]:
    """``[SLAVE] OBJECT [SUB] [VALUE]`` -> (slave, object, sub, value)."""
    words = list(args.words)
    if args.position is None:
        if not words or not _is_number(words[0]):
            raise ParameterError(
                "sdo: give the slave first (gtecat sdo upload 0 0x6041 0) or with -p POSITION"
            )
        slave = parse_int(words.pop(0))
    else:
        slave = args.position
    if not words:
        raise ParameterError("sdo: give the object, e.g. 0x6041 0, 0x6041:00 or Statusword")
    obj = words.pop(0)
    sub: str | None = None
    if ":" in obj and _is_number(obj.split(":", 1)[0]):
        obj, sub = obj.split(":", 1)
    want = 1 if args.action == "download" else 0
    if sub is None and (len(words) > want or (words and _is_number(obj))):
        sub = words.pop(0)  # a numeric INDEX is followed by its SUB (IgH's order)
    value = words.pop(0) if args.action == "download" and words else None
    if words:
        raise ParameterError(f"sdo {args.action}: unexpected {' '.join(words)}")
    return slave, obj, sub, value


def _lookup(bus: Any, slave: int, obj: str, sub: str | None) -> tuple[int, int, dict[str, Any]]:
    """(index, subindex, the dictionary's {name, type} or {}) of OBJECT [SUB]."""
    if _is_number(obj):
        index = _number(obj, "INDEX", 0xFFFF)
        subindex = 0 if sub is None else _number(sub, "SUB", 0xFF)
        return index, subindex, bus.sdo_entry(slave, index, subindex)
    found = bus.sdo_find(slave, obj, None if sub is None else _number(sub, "SUB", 0xFF))
    return found["index"], found["subindex"], {"name": found["name"], "type": found["type"]}


def run_sdo(args: argparse.Namespace) -> int:
    slave, obj, sub, value_text = _split_words(args)
    if _is_number(obj):  # bad numbers are refused before the bus starts
        _number(obj, "INDEX", 0xFFFF)
        if sub is not None:
            _number(sub, "SUB", 0xFF)
    if args.action == "download" and value_text is None:
        raise ParameterError("sdo download needs VALUE (and --type where the type is unknown)")
    data = _encode(value_text or "", args.type) if args.action == "download" and args.type else b""
    with bus_view(args) as bus:
        index, subindex, entry = _lookup(bus, slave, obj, sub)
        type_name = args.type or FROM_DICTIONARY.get(entry.get("type", ""))
        raw = b""
        if args.action == "download":
            if type_name is None:
                raise ParameterError(
                    f"sdo download: the type of {output.hex_addr(index, subindex)} is unknown "
                    f"here; give --type ({', '.join(sorted(TYPES))}, string)"
                )
            bus.sdo_download(slave, index, subindex, data or _encode(value_text or "", type_name))
        else:
            raw = bus.sdo_upload(slave, index, subindex)
    return _sdo_print(args, slave, index, subindex, entry, type_name, raw)


def _sdo_print(
    args: argparse.Namespace,
    slave: int,
    index: int,
    subindex: int,
    entry: dict[str, Any],
    type_name: str | None,
    raw: bytes,
) -> int:
    if args.action == "download":
        if args.json:
            output.print_json({"ok": True})
        return 0
    value: object = raw.hex(" ")
    if type_name == STRING:
        value = raw.rstrip(b"\0").decode("utf-8", errors="backslashreplace")
    elif type_name:
        code, size = TYPES[type_name]
        if len(raw) < size:
            raise ParameterError(
                f"{output.hex_addr(index, subindex)} has {len(raw)} bytes, {type_name} needs {size}"
            )
        value = struct.unpack_from("<" + code, raw)[0]
    if args.json:
        out = {"slave": slave, "index": index, "subindex": subindex, "bytes": raw.hex()}
        out["value"] = value
        if entry:
            out["name"] = entry["name"]
            out["type"] = entry["type"]
        output.print_json(out)
    elif isinstance(value, int) and not isinstance(value, bool) and type_name:
        print(f"{value}  (0x{raw[: TYPES[type_name][1]][::-1].hex().upper()}, {type_name})")
    elif type_name:
        print(value)
    else:
        print(f"{value}  ({len(raw)} bytes)")
    return 0
