"""A short TOML description of a bus, turned into an :class:`EniConfig` (then an ENI by the writer).

Format (every key optional unless marked)::

    cycle_time_us = 1000          # bus cycle, ENI Cyclic/CycleTime (default 1000)
    master = "gtecat"             # master name written to the ENI

    [[slave]]                     # one table per slave, in bus order (position 0, 1, ...)
    kind = "servo"                # required: "servo" | "io" | "coupler" | "generic"
    name = "Drive 0"              # default "<kind> <position>"
    vendor_id = 0x47544543        # identity; default 0x47544543 ("GTEC", the emulator's own)
    product_code = 0x00010001     # default per kind: servo 0x00010001, coupler 0x00030001;
    revision = 0                  #   without a mailbox (io, generic) 0x0002xxxx / 0x0004xxxx,
                                  #   xxxx a code of the PDO layout, so different devices
                                  #   never share an identity (SOEM caches SII per identity)
    mailbox = true                # CoE mailbox; default true for servo and coupler
    init_cmds = true              # write CoE InitCmds that assign (and, for configurable
                                  # PDOs, map) the PDOs at PREOP->SAFEOP; default true for servo

    # kind = "servo": a CiA-402 drive with `channels` axes
    channels = 1                  # multi-axis module: channel k repeats every object of the
                                  # profile area 0x6000-0x67FF at +0x800*k (IEC 61800-7-201)
    rx = ["0x6040:0:16", "0x607A:0:32"]                  # channel-0 outputs (RxPDO 0x1600+0x10k)
    tx = ["0x6041:0:16", "0x6064:0:32", "0x60FD:0:32"]   # channel-0 inputs  (TxPDO 0x1A00+0x10k)
                                  # default: the GTHD mapping of manual figure 5-2 (shown here)

    # kind = "io": digital IO terminal
    do = 16                       # output channels: 0x7000:01.. (RxPDO 0x1600)
    di = 16                       # input channels:  0x6000:01.. (TxPDO 0x1A00)
    packing = "bytes"             # "bytes": one 8-bit entry per 8 channels (Googol IO style);
                                  # "bits": one BOOL entry per channel (Beckhoff style)

    # kind = "coupler": ETG.5001 modular device (one slave, modules behind it)
    coupler_word = true           # a 16-bit coupler word first in each direction
                                  # (0xF700:01 outputs, 0xF600:01 inputs)
    modules = ["DI16", "DO16", "AI4", "AO4"]
                                  # module n maps inputs at 0x6000+0x10*n, outputs at 0x7000+0x10*n;
                                  # DIn/DOn: one n-bit entry :01 (n = 8, 16, 32);
                                  # AIn/AOn: n 16-bit INT channels :01..:n

    # kind = "generic" (or to override any kind's process data):
    rx = [...]; tx = [...]        # one PDO per direction (0x1600 / 0x1A00)
    rx_pdos = [{ index = 0x1600, name = "Outputs", entries = [...] }, ...]
    tx_pdos = [...]               # several PDOs per direction, in assignment order

An entry is ``"index:subindex:bits[:TYPE[:name]]"`` (``"0x6040:0:16"``,
``"0x7000:1:1:BOOL:Lamp"``) or a table ``{index=, subindex=, bits=, type=,
name=}``; index 0 is a padding gap (``"0:0:6"``).  Names and types default to
the CiA-402 object table, else ``0xIIII:SS`` and an unsigned type of the size.

The logical images are laid out zero-based (acontis/Elmo style): slaves in
bus order, each slave's outputs byte-aligned in the output image, its inputs
likewise; every non-padding entry gets a ``ProcessImage`` variable named
``<slave>.<pdo>.<entry>``.  Station addresses (``PhysAddr``) are 1001 + position, as
TwinCAT numbers them, and past FFFFh the addresses below 1001: a topology holds up to
65 535 slaves, as many as an EtherCAT bus.
"""

from __future__ import annotations

import os
import re
import zlib
from collections.abc import Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

from .check import check_config
from .datatypes import (
    CHANNEL_STRIDE,
    MAX_CHANNELS,
    channel_of,
    cia402_name,
    cia402_type,
    default_type,
    type_bits,
)
from .errors import EniError
from .limits import SLAVE_COUNT, cycle_ns_from_us
from .model import (
    Direction,
    EniConfig,
    Identity,
    InitCmd,
    Pdo,
    PdoEntry,
    ProcessDataArea,
    Slave,
    Variable,
)
from .numbers import fmt_index, parse_int

GTEC_VENDOR_ID = 0x47544543  # "GTEC": the emulator's own vendor id, not a real ETG one
#: the station address (ENI ``PhysAddr``) of the slave at position 0, as TwinCAT numbers them
FIRST_STATION = 1001
#: the most slaves one bus holds: station and auto-increment addresses are 16 bits (ETG.1000.4,
#: ETG.2100 ``PhysAddr``), and 0 is the station address of a slave not given one
MAX_SLAVES = SLAVE_COUNT.hi
_PRODUCT = {"servo": 0x00010001, "io": 0x00020001, "coupler": 0x00030001, "generic": 0x00040001}
_MODULE = re.compile(r"^(DI|DO|AI|AO)(\d+)$")
#: manual figure 5-2, GTHD default mapping
DEFAULT_SERVO_RX = ("0x6040:0:16", "0x607A:0:32")
DEFAULT_SERVO_TX = ("0x6041:0:16", "0x6064:0:32", "0x60FD:0:32")
COUPLER_OUT_WORD = (0xF700, 1)
COUPLER_IN_WORD = (0xF600, 1)


class _Where:
    def __init__(self, source: str, pos: int | None = None, name: str | None = None) -> None:
        self.source, self.pos, self.name = source, pos, name

    def error(self, message: str, element: str | None = None) -> EniError:
        return EniError(
            message, file=self.source, slave=self.pos, slave_name=self.name, element=element
        )


def load_topology(path: str | os.PathLike[str]) -> EniConfig:
    """Read a topology TOML file and build the configuration it describes."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except OSError as exc:
        raise EniError(f"cannot read the topology: {exc.strerror or exc}", file=str(p)) from None
    except UnicodeDecodeError as exc:
        raise EniError(f"the topology is not UTF-8: {exc}", file=str(p)) from None
    return parse_topology(text, str(p))


def parse_topology(text: str, source: str = "<topology>") -> EniConfig:
    import tomllib  # (read here: a bus from an ENI file never needs it)

    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        m = re.search(r"line (\d+)", str(exc))
        raise EniError(
            f"invalid TOML: {exc}", file=source, line=int(m.group(1)) if m else None
        ) from None
    return build_config(data, source)


def build_config(data: Mapping[str, Any], source: str = "<topology>") -> EniConfig:
    """Build the configuration from an already parsed topology mapping."""

    where = _Where(source)
    _known(where, data, {"cycle_time_us", "master", "slave"}, "topology")
    cycle_us = data.get("cycle_time_us", 1000)
    if isinstance(cycle_us, bool) or not isinstance(cycle_us, int | float) or cycle_us <= 0:
        raise where.error(
            f"cycle_time_us must be a positive number, not {cycle_us!r}", "cycle_time_us"
        )
    try:
        cycle_ns = cycle_ns_from_us(cycle_us, "cycle_time_us")
    except ValueError as exc:
        raise where.error(str(exc), "cycle_time_us") from None
    tables = data.get("slave", [])
    if not isinstance(tables, list) or not all(isinstance(t, Mapping) for t in tables):
        raise where.error("'slave' must be an array of tables ([[slave]])", "slave")
    if not tables:
        raise where.error(
            "the topology has no slaves: describe each one in a [[slave]] table, in bus order "
            "(gtecat example manual_fig5_2 writes one to start from)",
            "slave",
        )
    if len(tables) > MAX_SLAVES:
        raise where.error(
            f"the topology has {len(tables)} slaves: an EtherCAT bus holds at most "
            f"{MAX_SLAVES} (16-bit station addresses, 0 being that of a slave not given one)",
            "slave",
        )

    slaves = []
    shared: dict[object, Any] = {}
    for pos, table in enumerate(tables):
        slaves.append(_slave(_Where(source, pos), pos, table, shared))
    cfg = lay_out(
        EniConfig(
            source=source,
            format="xml",
            slaves=tuple(slaves),
            cycle_time_ns=cycle_ns,
            master_name=_text(where, data.get("master", "gtecat"), "master") or "gtecat",
        )
    )
    check_config(cfg)
    return cfg


def lay_out(cfg: EniConfig) -> EniConfig:
    """Zero-based logical images, slaves in order, byte-aligned; a variable per entry."""
    cursor = {Direction.OUT: 0, Direction.IN: 0}
    variables: dict[Direction, list[Variable]] = {Direction.OUT: [], Direction.IN: []}
    slaves = []
    for s in cfg.slaves:
        areas: dict[Direction, ProcessDataArea | None] = {}
        placed: dict[Direction, tuple[Pdo, ...]] = {}
        for d, pdos in ((Direction.OUT, s.rx_pdos), (Direction.IN, s.tx_pdos)):
            bits = sum(p.bit_len for p in pdos)
            start = cursor[d] * 8
            areas[d] = ProcessDataArea(start, bits) if bits else None
            bit = start
            new_pdos = []
            for p in pdos:
                entries = []
                for e in p.entries:
                    if e.is_padding:
                        entries.append(e.at(None))
                    else:
                        entries.append(e.at(bit))
                        variables[d].append(
                            Variable(f"{s.name}.{p.name}.{e.name}", d, bit, e.bit_len, e.data_type)
                        )
                    bit += e.bit_len
                new_pdos.append(replace(p, entries=tuple(entries)))
            placed[d] = tuple(new_pdos)
            cursor[d] += (bits + 7) // 8
        slaves.append(
            replace(
                s,
                rx_pdos=placed[Direction.OUT],
                tx_pdos=placed[Direction.IN],
                outputs=areas[Direction.OUT],
                inputs=areas[Direction.IN],
            )
        )
    return replace(
        cfg,
        slaves=tuple(slaves),
        outputs_bytes=cursor[Direction.OUT],
        inputs_bytes=cursor[Direction.IN],
        variables=tuple(variables[Direction.IN] + variables[Direction.OUT]),
    )


_COMMON = {
    "kind",
    "name",
    "vendor_id",
    "product_code",
    "revision",
    "serial",
    "mailbox",
    "init_cmds",
    "rx",
    "tx",
    "rx_pdos",
    "tx_pdos",
}
_KIND_KEYS = {
    "servo": {"channels"},
    "io": {"do", "di", "packing"},
    "coupler": {"coupler_word", "modules"},
    "generic": set(),
}


def _text(where: _Where, value: Any, element: str) -> str:
    """A name for the ENI: stripped, no control characters (XML 1.0 cannot carry them)."""
    text = str(value).strip()
    if any(ord(c) < 0x20 or 0x7F <= ord(c) < 0xA0 for c in text):
        raise where.error(f"{element} {text!r} contains control characters", element)
    return text


def _known(where: _Where, table: Mapping[str, Any], allowed: set[str], element: str) -> None:
    unknown = sorted(set(table) - allowed)
    if unknown:
        raise where.error(f"unknown key(s) {', '.join(unknown)}", element)


def _layout_code(rx: Sequence[Pdo], tx: Sequence[Pdo]) -> int:
    """A 16-bit code of a process-data layout (CRC-32 of its entries, folded), never 0."""
    text = ";".join(
        f"{p.direction}:{p.index:04X}:"
        + ",".join(f"{e.index:04X}.{e.subindex:02X}.{e.bit_len}" for e in p.entries)
        for p in (*rx, *tx)
    )
    crc = zlib.crc32(text.encode("ascii"))
    return ((crc >> 16) ^ crc) & 0xFFFF or 1


def _int(where: _Where, table: Mapping[str, Any], key: str, default: int) -> int:
    value = table.get(key, default)
    try:
        return parse_int(value)
    except (ValueError, TypeError):
        raise where.error(f"{key} must be an integer, not {value!r}", key) from None


def _bool(where: _Where, table: Mapping[str, Any], key: str, default: bool) -> bool:
    value = table.get(key, default)
    if not isinstance(value, bool):
        raise where.error(f"{key} must be true or false, not {value!r}", key)
    return value


def _slave(where: _Where, pos: int, t: Mapping[str, Any], shared: dict[object, Any]) -> Slave:
    """Slave ``pos``; ``shared`` holds the identities and init commands of the slaves before it,
    so equal ones are one object (the model is immutable; a bus of 65 535 like drives would
    otherwise hold 65 535 copies of them, as the XML reader never does)."""
    kind = t.get("kind")
    if kind not in _KIND_KEYS:
        raise where.error(f"kind must be one of servo, io, coupler, generic (got {kind!r})", "kind")
    name = _text(where, t.get("name", ""), "name") or f"{kind} {pos}"
    where.name = name
    _known(where, t, _COMMON | _KIND_KEYS[kind], f"[[slave]] {kind}")
    if kind == "servo":
        rx, tx = _servo(where, t)
    elif kind == "io":
        rx, tx = _io(where, t)
    elif kind == "coupler":
        rx, tx = _coupler(where, t)
    else:
        rx, tx = (), ()
    if kind != "servo":
        if "rx" in t or "rx_pdos" in t:
            rx = _pdos(where, t, Direction.OUT)
        if "tx" in t or "tx_pdos" in t:
            tx = _pdos(where, t, Direction.IN)
    mailbox = _bool(where, t, "mailbox", kind in ("servo", "coupler"))
    default_product = _PRODUCT[kind]
    if not mailbox:
        # a master without CoE learns the process data from the SII, and SOEM reuses the SII of
        # an earlier slave with the same identity: devices whose process data differ must
        # not share a product code (as real catalogue devices don't)
        default_product = (default_product & 0xFFFF0000) | _layout_code(rx, tx)
    identity = Identity(
        vendor_id=_int(where, t, "vendor_id", GTEC_VENDOR_ID),
        product_code=_int(where, t, "product_code", default_product),
        revision_no=_int(where, t, "revision", 0),
        serial_no=_int(where, t, "serial", 0),
    )
    identity = shared.setdefault(identity, identity)
    want_cmds = _bool(where, t, "init_cmds", kind == "servo")
    if want_cmds and not mailbox:
        raise where.error("init_cmds need a mailbox (mailbox = true)", "init_cmds")
    cmds: tuple[InitCmd, ...] = ()
    if want_cmds:
        cmds = shared.get((rx, tx), ())
        if not cmds:
            cmds = shared[rx, tx] = assignment_cmds(rx, tx)
    return Slave(
        position=pos,
        name=name,
        identity=identity,
        phys_addr=station_address(pos),
        auto_inc_addr=(-pos) & 0xFFFF,
        rx_pdos=rx,
        tx_pdos=tx,
        init_cmds=cmds,
        mailbox=mailbox,
    )


def station_address(pos: int) -> int:
    """The station address of bus position ``pos``: 1001, 1002, ... up to FFFFh, then the
    ones left below 1001 (1, 2, ...), so each of :data:`MAX_SLAVES` slaves has its own."""
    station = FIRST_STATION + pos
    return station if station <= 0xFFFF else station - 0xFFFF


def parse_entry(where: _Where, spec: Any, element: str) -> PdoEntry:
    """``"0x6040:0:16[:TYPE[:name]]"`` or ``{index=, subindex=, bits=, type=, name=}``."""
    if isinstance(spec, str):
        parts = spec.split(":", 4)
        if len(parts) < 3:
            raise where.error(f"entry {spec!r} is not 'index:subindex:bits[:type[:name]]'", element)
        raw = {"index": parts[0], "subindex": parts[1], "bits": parts[2]}
        if len(parts) > 3 and parts[3].strip():
            raw["type"] = parts[3].strip()
        if len(parts) > 4:
            raw["name"] = parts[4].strip()
        spec = raw
    if not isinstance(spec, Mapping):
        raise where.error(f"entry {spec!r} is neither a string nor a table", element)
    _known(where, spec, {"index", "subindex", "bits", "type", "name"}, element)
    try:
        index = parse_int(spec["index"])
        sub = parse_int(spec.get("subindex", 0))
        dtype = str(spec.get("type", "")).strip().upper()
        bits = parse_int(spec["bits"]) if "bits" in spec else type_bits(dtype)
    except KeyError as exc:
        raise where.error(f"entry {dict(spec)!r} has no {exc.args[0]}", element) from None
    except (ValueError, TypeError) as exc:
        raise where.error(f"entry {dict(spec)!r}: {exc}", element) from None
    if bits is None or bits <= 0:
        raise where.error(f"entry {dict(spec)!r} needs a positive bit size", element)
    if not 0 <= index <= 0xFFFF or not 0 <= sub <= 0xFF:
        raise where.error(f"entry {dict(spec)!r}: object address out of range", element)
    if index == 0:
        return PdoEntry(0, 0, bits)
    if dtype and type_bits(dtype) not in (None, bits):
        raise where.error(
            f"entry {fmt_index(index, sub)}: type {dtype} is not {bits} bits", element
        )
    dtype = dtype or cia402_type(index, sub, bits) or default_type(bits)
    name = (
        _text(where, spec.get("name", ""), element)
        or cia402_name(index, sub, bits)
        or fmt_index(index, sub)
    )
    return PdoEntry(index, sub, bits, name, dtype)


def _entries(where: _Where, specs: Any, element: str) -> tuple[PdoEntry, ...]:
    if not isinstance(specs, Sequence) or isinstance(specs, str):
        raise where.error(f"{element} must be a list of entries", element)
    return tuple(parse_entry(where, s, element) for s in specs)


def _pdos(where: _Where, t: Mapping[str, Any], d: Direction) -> tuple[Pdo, ...]:
    key = "rx" if d == Direction.OUT else "tx"
    base = 0x1600 if d == Direction.OUT else 0x1A00
    if f"{key}_pdos" in t:
        if key in t:
            raise where.error(f"give {key} or {key}_pdos, not both", key)
        tables = t[f"{key}_pdos"]
        if not isinstance(tables, list):
            raise where.error(f"{key}_pdos must be a list of tables", f"{key}_pdos")
        pdos = []
        for k, pt in enumerate(tables):
            if not isinstance(pt, Mapping):
                raise where.error(f"{key}_pdos[{k}] must be a table", f"{key}_pdos")
            _known(where, pt, {"index", "name", "entries", "fixed"}, f"{key}_pdos[{k}]")
            index = _int(where, pt, "index", base + k)
            pdos.append(
                Pdo(
                    index,
                    d,
                    _entries(where, pt.get("entries", []), f"{key}_pdos[{k}]"),
                    _text(where, pt.get("name", ""), f"{key}_pdos[{k}]")
                    or f"{'RxPDO' if d == Direction.OUT else 'TxPDO'} 0x{index:04X}",
                    2 if d == Direction.OUT else 3,
                    _bool(where, pt, "fixed", False),
                )
            )
        return tuple(pdos)
    entries = _entries(where, t.get(key, []), key)
    if not entries:
        return ()
    return (
        Pdo(
            base,
            d,
            entries,
            "Outputs" if d == Direction.OUT else "Inputs",
            2 if d == Direction.OUT else 3,
            False,
        ),
    )


def _servo(where: _Where, t: Mapping[str, Any]) -> tuple[tuple[Pdo, ...], tuple[Pdo, ...]]:
    channels = _int(where, t, "channels", 1)
    if not 1 <= channels <= MAX_CHANNELS:
        raise where.error(f"channels must be 1..{MAX_CHANNELS}, not {channels}", "channels")
    if "rx_pdos" in t or "tx_pdos" in t:
        raise where.error(
            'a servo takes rx/tx (channel 0 objects); use kind = "generic" for explicit PDO lists',
            "rx_pdos",
        )
    result = []
    for d, key, default in (
        (Direction.OUT, "rx", DEFAULT_SERVO_RX),
        (Direction.IN, "tx", DEFAULT_SERVO_TX),
    ):
        proto = _entries(where, t.get(key, list(default)), key)
        base = 0x1600 if d == Direction.OUT else 0x1A00
        pdos = []
        for k in range(channels):
            entries = []
            for e in proto:
                if e.is_padding or k == 0:
                    entries.append(e)
                    continue
                ch = channel_of(e.index)
                if ch is None or ch[0] != 0:
                    raise where.error(
                        f"{fmt_index(e.index, e.subindex)} is not a channel-0 profile object "
                        "(0x6000-0x67FF); a multi-channel servo repeats only those",
                        key,
                    )
                index = e.index + CHANNEL_STRIDE * k
                entries.append(PdoEntry(index, e.subindex, e.bit_len, e.name, e.data_type))
            label = "RxPDO" if d == Direction.OUT else "TxPDO"
            pdos.append(
                Pdo(
                    base + 0x10 * k,
                    d,
                    tuple(entries),
                    label if channels == 1 else f"{label} axis {k + 1}",
                    2 if d == Direction.OUT else 3,
                    False,
                )
            )
        result.append(tuple(p for p in pdos if p.entries))
    return result[0], result[1]


def _io(where: _Where, t: Mapping[str, Any]) -> tuple[tuple[Pdo, ...], tuple[Pdo, ...]]:
    packing = t.get("packing", "bytes")
    if packing not in ("bytes", "bits"):
        raise where.error(f'packing must be "bytes" or "bits", not {packing!r}', "packing")
    result = []
    for d, key, index, label in (
        (Direction.OUT, "do", 0x7000, "DO"),
        (Direction.IN, "di", 0x6000, "DI"),
    ):
        n = _int(where, t, key, 0)
        if not 0 <= n <= 2040:
            raise where.error(f"{key} must be 0..2040 channels, not {n}", key)
        entries: list[PdoEntry] = []
        if packing == "bits":
            entries = [PdoEntry(index, c + 1, 1, f"{label} {c}", "BOOL") for c in range(n)]
        else:
            for b in range((n + 7) // 8):
                entries.append(PdoEntry(index, b + 1, 8, f"{label} byte {b}", "USINT"))
        pdo_name = "Digital outputs" if d == Direction.OUT else "Digital inputs"
        result.append(
            (
                Pdo(
                    0x1600 if d == Direction.OUT else 0x1A00,
                    d,
                    tuple(entries),
                    pdo_name,
                    2 if d == Direction.OUT else 3,
                    True,
                ),
            )
            if entries
            else ()
        )
    return result[0], result[1]


def _coupler(where: _Where, t: Mapping[str, Any]) -> tuple[tuple[Pdo, ...], tuple[Pdo, ...]]:
    word = _bool(where, t, "coupler_word", True)
    modules = t.get("modules", [])
    if not isinstance(modules, list):
        raise where.error('modules must be a list such as ["DI16", "AO4"]', "modules")
    rx: list[Pdo] = []
    tx: list[Pdo] = []
    if word:
        rx.append(
            Pdo(
                0x1600,
                Direction.OUT,
                (PdoEntry(*COUPLER_OUT_WORD, 16, "Coupler control", "UINT"),),
                "Coupler",
                2,
                True,
            )
        )
        tx.append(
            Pdo(
                0x1A00,
                Direction.IN,
                (PdoEntry(*COUPLER_IN_WORD, 16, "Coupler status", "UINT"),),
                "Coupler",
                3,
                True,
            )
        )
    for n, mod in enumerate(modules):
        m = _MODULE.match(str(mod).strip().upper())
        if m is None:
            raise where.error(f"module {n} {mod!r} is not DIn, DOn, AIn or AOn", "modules")
        kind, count = m.group(1), int(m.group(2))
        if n >= 0x100:
            raise where.error("at most 256 modules", "modules")
        if kind in ("DI", "DO"):
            if count not in (8, 16, 32):
                raise where.error(
                    f"module {n} {mod}: digital modules have 8, 16 or 32 channels", "modules"
                )
            entries = (
                PdoEntry(
                    (0x6000 if kind == "DI" else 0x7000) + 0x10 * n,
                    1,
                    count,
                    f"{kind}{count}",
                    default_type(count),
                ),
            )
        else:
            if not 1 <= count <= 32:
                raise where.error(
                    f"module {n} {mod}: analog modules have 1..32 channels", "modules"
                )
            entries = tuple(
                PdoEntry(
                    (0x6000 if kind == "AI" else 0x7000) + 0x10 * n,
                    c + 1,
                    16,
                    f"Channel {c + 1}",
                    "INT",
                )
                for c in range(count)
            )
        label = f"Module {n} {kind}{count}"
        if kind in ("DO", "AO"):
            rx.append(Pdo(0x1601 + n, Direction.OUT, entries, label, 2, True))
        else:
            tx.append(Pdo(0x1A01 + n, Direction.IN, entries, label, 3, True))
    return tuple(rx), tuple(tx)


def _u8(v: int) -> bytes:
    return v.to_bytes(1, "little")


def assignment_cmds(rx: Sequence[Pdo], tx: Sequence[Pdo]) -> tuple[InitCmd, ...]:
    """CoE InitCmds (PREOP->SAFEOP) that map configurable PDOs and assign all of them.

    The order real tools use (ETG.2100 InitCmds, CiA 301 PDO mapping 0x16xx/0x1Axx,
    ETG.1000.6 sync-manager assignment 0x1C12/0x1C13): clear both assignments,
    for each configurable PDO clear, write and count its mapping, then write
    and count each assignment.
    """
    cmds: list[InitCmd] = []
    ps = ("PS",)
    for sm_obj in (0x1C12, 0x1C13):
        cmds.append(InitCmd(ps, sm_obj, 0, _u8(0), comment=f"clear sm pdos (0x{sm_obj:04X})"))
    for p in (*rx, *tx):
        if p.fixed:
            continue
        cmds.append(InitCmd(ps, p.index, 0, _u8(0), comment=f"clear pdo 0x{p.index:04X}"))
        for k, e in enumerate(p.entries, 1):
            value = (e.index << 16) | (e.subindex << 8) | e.bit_len
            cmds.append(
                InitCmd(
                    ps,
                    p.index,
                    k,
                    value.to_bytes(4, "little"),
                    comment=f"map {fmt_index(e.index, e.subindex)} ({e.bit_len} bits)",
                )
            )
        cmds.append(
            InitCmd(ps, p.index, 0, _u8(len(p.entries)), comment=f"pdo 0x{p.index:04X} entry count")
        )
    for sm_obj, pdos in ((0x1C12, rx), (0x1C13, tx)):
        for k, p in enumerate(pdos, 1):
            cmds.append(
                InitCmd(
                    ps,
                    sm_obj,
                    k,
                    p.index.to_bytes(2, "little"),
                    comment=f"assign pdo 0x{p.index:04X}",
                )
            )
        cmds.append(
            InitCmd(ps, sm_obj, 0, _u8(len(pdos)), comment=f"download pdo 0x{sm_obj:04X} count")
        )
    return tuple(cmds)
