"""Bus inspection in the spirit of the IgH ``ethercat`` tool: ``slaves``, ``pdos``, ``sdo``.

Each verb opens the bus the way ``GT_Open`` would (``--eni`` or ``GTECAT_ENI``, else
``./Gecat.eni``; ``--backend``/``--iface`` for pysoem), brings it up, answers and
closes.  Human tables by default, ``--json`` for scripts.
"""

from __future__ import annotations

import argparse
import struct
from types import SimpleNamespace

from eni.numbers import parse_int

from ..errors import ParameterError
from ..native.field import pdo_rows, slave_rows
from . import output
from .busview import Bus, add_bus_options, open_bus

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
("Statusword"; emulated bus). Without --type the type comes from the slave's
object dictionary (emulated bus), else the value prints as raw bytes.

examples:
  gtecat sdo upload -p 0 0x1018:01                 vendor id of slave 0
  gtecat sdo upload 0 Statusword                   by name
  gtecat sdo download -p 0 0x6060 0 8              modes of operation := 8 (CSP)
  gtecat sdo upload 0 0x6502 0 --type uint32 --backend pysoem --iface eth0

On the emulated bus every command starts a fresh bus: a download lasts for that
command only (use a script and `gtecat run` for sequences), unless --controller
names a running controller (`gtecat controller`): then it reads and writes that
one's bus, by index (names need a bus of the command's own)."""


def _file(p: argparse.ArgumentParser) -> None:
    # ``gtecat slaves x.eni`` reads like ``gtecat map x.eni``; --eni says the same
    p.add_argument("file", nargs="?", help="configuration file (same as --eni)")


def _controller(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--controller",
        metavar="ADDR",
        help="read the bus of a running controller (unix:/path of `gtecat controller`, "
        "GTECAT_CONTROLLER of a program) instead of opening one",
    )


def _field(args: argparse.Namespace):
    from ..native.client import Field

    return Field.connect(args.controller)


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
    _controller(p)
    p.set_defaults(func=run_slaves)
    p = sub.add_parser(
        "pdos",
        help="show each slave's sync managers, PDOs and entries",
        epilog="examples:\n  gtecat pdos manual_fig5_2.eni\n  gtecat pdos -p 0 --json",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    _file(p)
    add_bus_options(p)
    _controller(p)
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
    _controller(p)
    p.set_defaults(func=run_sdo)


def run(args: argparse.Namespace) -> int:  # the dispatcher's fallback
    return int(args.func(args))


def _hex(v: int, w: int = 8) -> str:
    return f"0x{v:0{w}X}"


def run_slaves(args: argparse.Namespace) -> int:
    if args.controller:
        with _field(args) as f:
            rows = f.slaves(args.position)
    else:
        with Bus(args) as bus:
            rows = slave_rows(bus.master, bus.positions())
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
    if args.controller:
        with _field(args) as f:
            out = f.pdos(args.position)
    else:
        with Bus(args) as bus:
            out = pdo_rows(bus.layout.config, bus.positions())
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


def _lookup(bus: Bus, slave: int, obj: str, sub: str | None) -> tuple[int, int, object]:
    """(index, subindex, dictionary entry or None) for OBJECT [SUB]."""
    od = None
    if bus.emulated:
        try:
            od = bus.od(slave)
        except Exception:  # an IO slave without CoE: the SDO itself says so
            od = None
    if _is_number(obj):
        index = _number(obj, "INDEX", 0xFFFF)
        subindex = 0 if sub is None else _number(sub, "SUB", 0xFF)
        var = od.find(index, subindex) if od is not None else None
        return index, subindex, var
    if od is None:
        raise ParameterError(
            f"sdo: {obj!r} is not a number; names are looked up in the emulated slave's "
            "dictionary only: give the index, e.g. 0x6041 0"
        )
    wanted = obj.casefold()
    subindex = None if sub is None else _number(sub, "SUB", 0xFF)
    hits = []
    for o in od:
        subs = [o.subs[k] for k in sorted(o.subs)]
        if o.name.casefold() == wanted:
            if subindex is None and len(subs) > 1:
                raise ParameterError(
                    f"sdo: {obj!r} is 0x{o.index:04X} with subindexes "
                    f"{', '.join(str(v.subindex) for v in subs)}: give SUB"
                )
            hits += [v for v in subs if subindex is None or v.subindex == subindex]
        else:
            hits += [
                v
                for v in subs
                if v.name.casefold() == wanted and (subindex is None or v.subindex == subindex)
            ]
    if not hits:
        raise ParameterError(
            f"sdo: slave {slave} has no object called {obj!r} (`gtecat sdos -p {slave}` lists them)"
        )
    if len({(v.index, v.subindex) for v in hits}) > 1:
        where = ", ".join(output.hex_addr(v.index, v.subindex) for v in hits[:5])
        raise ParameterError(f"sdo: {obj!r} names {where}: give the index")
    v = hits[0]
    return v.index, v.subindex, v


def run_sdo(args: argparse.Namespace) -> int:
    slave, obj, sub, value_text = _split_words(args)
    if _is_number(obj):  # bad numbers are refused before the bus starts
        _number(obj, "INDEX", 0xFFFF)
        if sub is not None:
            _number(sub, "SUB", 0xFF)
    if args.action == "download" and value_text is None:
        raise ParameterError("sdo download needs VALUE (and --type where the type is unknown)")
    data = _encode(value_text or "", args.type) if args.action == "download" and args.type else b""
    if args.controller:
        index, subindex, var, type_name, raw = _sdo_remote(args, slave, obj, sub, value_text, data)
        return _sdo_print(args, slave, index, subindex, var, type_name, raw)
    with Bus(args) as bus:
        bus.check(slave)
        index, subindex, var = _lookup(bus, slave, obj, sub)
        type_name = args.type
        if type_name is None and var is not None:
            type_name = FROM_DICTIONARY.get(var.data_type.name)
        if args.action == "download":
            if type_name is None:
                raise ParameterError(
                    f"sdo download: the type of {output.hex_addr(index, subindex)} is unknown "
                    f"here; give --type ({', '.join(sorted(TYPES))}, string)"
                )
            if not args.type:
                data = _encode(value_text or "", type_name)
            bus.master.sdo_download(slave, index, subindex, data)
            raw = b""
        else:
            raw = bus.master.sdo_upload(slave, index, subindex)
    return _sdo_print(args, slave, index, subindex, var, type_name, raw)


def _sdo_remote(
    args: argparse.Namespace, slave: int, obj: str, sub: str | None, text: str | None, data: bytes
) -> tuple[int, int, object, str | None, bytes]:
    """``sdo --controller``: the running controller's bus does the transfer."""
    if not _is_number(obj):
        raise ParameterError(
            f"sdo --controller: give the index, e.g. 0x6041 0 ({obj!r} is looked up by name "
            "only in a bus of this command's own)"
        )
    index = _number(obj, "INDEX", 0xFFFF)
    subindex = 0 if sub is None else _number(sub, "SUB", 0xFF)
    with _field(args) as f:
        entry = f.sdo_entry(slave, index, subindex)
        var = (
            SimpleNamespace(name=entry["name"], data_type=SimpleNamespace(name=entry["type"]))
            if entry
            else None
        )
        type_name = args.type or (FROM_DICTIONARY.get(entry["type"]) if entry else None)
        if args.action == "download":
            if type_name is None:
                raise ParameterError(
                    f"sdo download: the type of {output.hex_addr(index, subindex)} is unknown "
                    f"here; give --type ({', '.join(sorted(TYPES))}, string)"
                )
            f.sdo_download(slave, index, subindex, data or _encode(text or "", type_name))
            return index, subindex, var, type_name, b""
        return index, subindex, var, type_name, f.sdo_upload(slave, index, subindex)


def _sdo_print(
    args: argparse.Namespace,
    slave: int,
    index: int,
    subindex: int,
    var: object,
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
        if var is not None:
            out["name"] = var.name
            out["type"] = var.data_type.name
        output.print_json(out)
    elif isinstance(value, int) and not isinstance(value, bool) and type_name:
        print(f"{value}  (0x{raw[: TYPES[type_name][1]][::-1].hex().upper()}, {type_name})")
    elif type_name:
        print(value)
    else:
        print(f"{value}  ({len(raw)} bytes)")
    return 0
