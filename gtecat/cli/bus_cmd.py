"""Bus inspection in the spirit of the IgH ``ethercat`` tool: ``slaves``, ``pdos``, ``sdo``.

Each verb opens the bus the way ``GT_Open`` would (``--eni`` or ``GTECAT_ENI``, else
``./Gecat.eni``; ``--backend``/``--iface`` for pysoem), brings it up, answers and
closes.  Human tables by default, ``--json`` for scripts.
"""

from __future__ import annotations

import argparse
import json
import os
import struct

from drives.machine import MachineError
from drives.slave import AlState
from eni.model import Direction
from eni.numbers import parse_int

from ..controller.core import Controller, Options
from ..errors import BusError, ConfigMismatch, ParameterError

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


def _common(p: argparse.ArgumentParser) -> None:
    p.add_argument("--eni", help="configuration file (default: $GTECAT_ENI or ./Gecat.eni)")
    p.add_argument("--machine", help="machine description TOML ($GTECAT_MACHINE)")
    p.add_argument("--backend", choices=("emulated", "pysoem"), help="($GTECAT_BACKEND)")
    p.add_argument("--iface", help="network interface for pysoem ($GTECAT_IFACE)")
    p.add_argument("--json", action="store_true", help="machine-readable output")


def _file(p: argparse.ArgumentParser) -> None:
    # ``gtecat slaves x.eni`` reads like ``gtecat map x.eni``; --eni says the same
    p.add_argument("file", nargs="?", help="configuration file (same as --eni)")


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("slaves", help="list the slaves: position, state, identity, axes")
    _file(p)
    _common(p)
    p.set_defaults(func=run_slaves)
    p = sub.add_parser("pdos", help="show each slave's sync managers, PDOs and entries")
    _file(p)
    _common(p)
    p.set_defaults(func=run_pdos)
    p = sub.add_parser("sdo", help="SDO upload / download")
    p.add_argument("action", choices=("upload", "download"))
    p.add_argument("slave", type=int)
    p.add_argument("index", help="object index, e.g. 0x6041")
    p.add_argument("subindex", help="subindex, e.g. 0")
    p.add_argument("value", nargs="?", help="value to download")
    p.add_argument(
        "--type",
        default=None,
        choices=sorted([*TYPES, STRING]),
        help="data type (upload default: raw hex; download: required)",
    )
    p.epilog = (
        "On the emulated bus every command starts a fresh bus: a download lasts for that "
        "command only (use a script and `gtecat run` for sequences)."
    )
    _common(p)
    p.set_defaults(func=run_sdo)


def run(args: argparse.Namespace) -> int:  # the dispatcher's fallback
    return int(args.func(args))


def open_bus(args: argparse.Namespace) -> Controller:
    """Bring the bus up as GT_Open + GT_InitEcatComm would (lockstep; realtime on pysoem)."""
    backend = args.backend or os.environ.get("GTECAT_BACKEND") or "emulated"
    try:
        ctl = Controller(
            Options(
                eni=args.eni or getattr(args, "file", None),
                machine=args.machine,
                # a real bus must cycle on the wall clock (docs/hardware.md)
                clock="realtime" if backend == "pysoem" else "lockstep",
                backend=args.backend,
                iface=args.iface,
                log="",
            )
        )
    except MachineError as e:
        raise MachineError(f"{e} (--machine FILE or GTECAT_MACHINE; or leave it out)") from None
    try:
        ctl.init_ecat()
        if not ctl.clock.run_until(lambda: ctl.ready, 2000):
            err = ctl.master.error if ctl.master else ""
            raise BusError(f"the bus did not reach OP{': ' + err if err else ''}")
    except ConfigMismatch as e:
        ctl.close()
        if "export" in str(e):  # the master already says what to do
            raise
        raise ConfigMismatch(
            f"{e}; the ENI does not describe this bus: export it again from the "
            "configuration tool for this machine, or check the cabling order"
        ) from None
    except BaseException:
        ctl.close()
        raise
    return ctl


def _hex(v: int, w: int = 8) -> str:
    return f"0x{v:0{w}X}"


def run_slaves(args: argparse.Namespace) -> int:
    ctl = open_bus(args)
    try:
        m = ctl.master
        states = m.refresh_states()
        rows = []
        for sl, cfg, st in zip(m.layout.slaves, m.layout.config.slaves, states, strict=True):
            rows.append(
                {
                    "position": sl.position,
                    "state": AlState(st).name,
                    "name": cfg.name,
                    "vendor_id": cfg.identity.vendor_id,
                    "product_code": cfg.identity.product_code,
                    "revision": cfg.identity.revision_no,
                    "axes": list(sl.axes),
                    "gt_offset": sl.gt_offset,
                    "gt_size": sl.gt_size,
                }
            )
    finally:
        ctl.close()
    if args.json:
        print(json.dumps(rows, indent=2))
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
    ctl = open_bus(args)
    try:
        cfg = ctl.master.layout.config
        out = []
        for s in cfg.slaves:
            pdos = []
            for d, plist in ((Direction.OUT, s.rx_pdos), (Direction.IN, s.tx_pdos)):
                for p in plist:
                    pdos.append(
                        {
                            "dir": "out" if d == Direction.OUT else "in",
                            "sm": p.sm,
                            "index": p.index,
                            "name": p.name,
                            "entries": [
                                {
                                    "index": e.index,
                                    "subindex": e.subindex,
                                    "bits": e.bit_len,
                                    "name": e.name,
                                    "type": e.data_type,
                                }
                                for e in p.entries
                            ],
                        }
                    )
            out.append({"position": s.position, "name": s.name, "pdos": pdos})
    finally:
        ctl.close()
    if args.json:
        print(json.dumps(out, indent=2))
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


def run_sdo(args: argparse.Namespace) -> int:
    try:
        index, sub = parse_int(args.index), parse_int(args.subindex)
    except ValueError:
        raise ParameterError(
            f"sdo: INDEX and SUB must be numbers, e.g. 0x6041 0 (got {args.index} {args.subindex})"
        ) from None
    if args.action == "download":
        if args.value is None or args.type is None:
            raise ParameterError("sdo download needs VALUE and --type")
        data = _encode(args.value, args.type)
    ctl = open_bus(args)
    try:
        if args.action == "upload":
            raw = ctl.master.sdo_upload(args.slave, index, sub)
        else:
            ctl.master.sdo_download(args.slave, index, sub, data)
    finally:
        ctl.close()
    if args.action == "download":
        if args.json:
            print(json.dumps({"ok": True}))
        return 0
    value: object = raw.hex(" ")
    if args.type == STRING:
        value = raw.rstrip(b"\0").decode("utf-8", errors="backslashreplace")
    elif args.type:
        code, size = TYPES[args.type]
        if len(raw) < size:
            raise ParameterError(
                f"0x{index:04X}:{sub:02X} has {len(raw)} bytes, {args.type} needs {size}"
            )
        value = struct.unpack_from("<" + code, raw)[0]
    if args.json:
        print(
            json.dumps(
                {
                    "slave": args.slave,
                    "index": index,
                    "subindex": sub,
                    "bytes": raw.hex(),
                    "value": value,
                }
            )
        )
    else:
        print(value if args.type else f"{value}  ({len(raw)} bytes)")
    return 0
