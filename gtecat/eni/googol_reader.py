"""Googol's INI-style ``Gecat.eni`` (written by the vendor's EtherCAT configuration tool).

The format, as the tool writes it (``fixtures/README.md``)::

    [CommonInfo] [MasterInfo] [SlaveIndex] slavenum=N
    then N times:  [SlaveStart] position ... [slave_info] [slave_sync]
                   [slave_syncK_PDO] [slave_syncK_PDO_entry] [slave_dc]
                   [slave_iomap] [slave_startsdo] [SlaveEnd]

Every line is ``ParamN=name=<key>,Section=<TYPE>,Value=<v>[,Section=<TYPE>,Value=<v>]...``;
``ParamN`` numbers repeat inside a section (``slave_dc``), so lines are read in
order and keyed by ``name``, never by ``ParamN``.  Items:

* ``slave_info``: ``slavename``, ``vid``, ``pcode``, ``type`` (1 servo / 0 IO), ``nservo``;
* ``syncitem`` = (sync manager, direction 1 outputs / 2 inputs, PDO count);
* ``pdoitem`` = (PDO index, entry count, first entry in the entry list, enabled);
* ``entryitem`` = (index, subindex, bit length, enabled);
* ``mapitem`` = (index, subindex, bit length): each slave's outputs then inputs,
  the GT raw order (checked against the PDO lists);
* ``startitem`` = (index, subindex, size in bytes, value): an SDO written at
  PREOP -> SAFEOP, kept as an :class:`InitCmd` with transition ``"PS"``;
* ``slave_dc`` ``cycletime0`` (ns): the bus cycle.

The reader is tolerant of what hand edits do (case, spaces, CRLF, comments,
blank lines, unknown sections and keys) and strict about what changes the
image (counts and lists that disagree raise :class:`EniError` with the line).
Every number it uses is checked against its range in :mod:`gtecat.eni.limits`
(``cycletime0`` 0 means "not given", as the tool writes it with DC off; any
other value must lie in 31.25 us .. 1 s).
The logical image is ours to lay out: slaves in order, each slave's outputs
byte-aligned in the output image, its inputs likewise in the input image.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field

from .check import check_config
from .errors import EniError
from .limits import (
    CYCLE_NS,
    ENABLED,
    ENTRY_BITS,
    ENTRY_POS,
    IDENTITY,
    INDEX,
    NSERVO,
    PDO_COUNT,
    POSITION,
    SDO_SIZE,
    SERVO_TYPE,
    SLAVE_COUNT,
    SM,
    SUBINDEX,
    SYNC_DIR,
    Limit,
    sdo_value,
)
from .model import (
    Direction,
    EniConfig,
    Identity,
    InitCmd,
    Pdo,
    PdoEntry,
    ProcessDataArea,
    Slave,
)
from .numbers import TooLong, fmt_index, parse_int, shown

_SECTION = re.compile(r"^\[\s*([^\]]*?)\s*\]\s*$")
_LINE = re.compile(r"^(?:[^=]*=)?\s*name\s*=\s*(?P<name>[^,]*?)\s*(?P<rest>,.*)?$", re.I)
_PAIR = re.compile(
    r",\s*Section\s*=\s*(?P<t>[^,]*?)\s*,\s*Value\s*=\s*(?P<v>.*?)\s*(?=,\s*Section\s*=|$)",
    re.I,
)
_SYNC_PDO = re.compile(r"^slave_sync(\d+)_pdo$", re.I)
_SYNC_ENTRY = re.compile(r"^slave_sync(\d+)_pdo_entry$", re.I)

Value = int | float | str
#: a number with more digits than any field holds (:data:`gtecat.eni.numbers.MAX_DIGITS`):
#: every range refuses it, and the error shows the text as written
_BEYOND = 1 << 256
#: a value checked after the ones it depends on (a start SDO value, by its size)
_ANY = Limit(-_BEYOND, _BEYOND, "checked with its size")
_ON = ("enabled", ENABLED)
#: a slave_iomap gap (index 0) may carry any length an entry may
_MAP_BITS = Limit(0, ENTRY_BITS.hi, ENTRY_BITS.why)


@dataclass
class _Item:
    name: str
    values: list[Value]
    line: int
    #: the values as written, for error messages
    raw: list[str] = field(default_factory=list)


@dataclass
class _Block:
    line: int
    sections: dict[str, list[_Item]] = field(default_factory=dict)
    section_lines: dict[str, int] = field(default_factory=dict)


def _value(kind: str, raw: str) -> Value:
    k = kind.strip().upper()
    v = raw.strip()
    if k == "STRING":
        return v
    if k == "FLOAT":
        return float(v)
    sign, digits = (v[0], v[1:]) if v[:1] in ("-", "+") else ("", v)
    if k == "HEX" and not digits.lower().startswith(("0x", "#x")):
        digits = "0x" + digits
    # DWORD, WORD, BYTE, INT...: decimal, tolerating a hex spelling
    try:
        return parse_int(sign + digits)
    except TooLong:
        return -_BEYOND if sign == "-" else _BEYOND


def _decode(data: bytes | str) -> str:
    if isinstance(data, str):
        return data.lstrip("\ufeff")
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):  # Windows "Unicode" (UTF-16 with BOM)
        try:
            return data.decode("utf-16")
        except UnicodeDecodeError:
            pass  # not really UTF-16: fall through to the byte encodings
    for enc in ("utf-8-sig", "gb18030"):
        try:
            return data.decode(enc)
        except UnicodeDecodeError:
            continue
    return data.decode("latin-1")


def _tokenise(text: str, source: str) -> tuple[dict[str, list[_Item]], list[_Block]]:
    """Lines -> global sections and per-slave blocks, each a list of items in file order."""
    glob: dict[str, list[_Item]] = {}
    blocks: list[_Block] = []
    current: _Block | None = None
    section = ""
    for lineno, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        if not line or line.startswith(("//", ";", "#")):
            continue
        m = _SECTION.match(line)
        if m:
            section = m.group(1).lower()
            if section == "slavestart":
                current = _Block(lineno)
                blocks.append(current)
            elif section == "slaveend":
                current = None
            elif current is not None:
                current.sections.setdefault(section, [])
                current.section_lines.setdefault(section, lineno)
            continue
        m = _LINE.match(line)
        if m is None:
            if section.startswith("slave"):
                raise EniError(
                    f"cannot read line {shown(line)} (expected name=...,Section=...,Value=...)",
                    file=source,
                    line=lineno,
                    element=f"[{section}]",
                )
            continue  # unknown syntax in a section we do not use
        values: list[Value] = []
        raws: list[str] = []
        for pm in _PAIR.finditer(m.group("rest") or ""):
            try:
                values.append(_value(pm.group("t"), pm.group("v")))
                raws.append(pm.group("v").strip())
            except ValueError:
                raise EniError(
                    f"value {shown(pm.group('v'))} is not a valid {shown(pm.group('t'))}",
                    file=source,
                    line=lineno,
                    element=f"[{section}] {m.group('name')}",
                ) from None
        item = _Item(m.group("name").strip().lower(), values, lineno, raws)
        if current is not None and section != "slaveend":
            current.sections.setdefault(section, []).append(item)
        else:
            glob.setdefault(section, []).append(item)
    return glob, blocks


def _first(items: list[_Item], name: str) -> _Item | None:
    return next((i for i in items if i.name == name), None)


Fail = Callable[[str, int | None, str], EniError]


def _checked(item: _Item, k: int, limit: Limit, what: str, fail: Fail, element: str) -> int:
    """Value ``k`` of ``item``, an integer inside ``limit`` (:mod:`gtecat.eni.limits`)."""
    v = item.values[k]
    raw = item.raw[k] if k < len(item.raw) else str(v)
    if not isinstance(v, int):
        raise fail(f"{what} {shown(raw)} is not an integer: legal is {limit}", item.line, element)
    try:
        return limit.check(v, what, raw)
    except ValueError as exc:
        raise fail(str(exc), item.line, element) from None


def _int_item(items: list[_Item], name: str, limit: Limit, fail: Fail, section: str) -> int | None:
    """The first value of item ``name`` (None when absent or empty), checked."""
    it = _first(items, name)
    if it is None or not it.values:
        return None
    return _checked(it, 0, limit, name, fail, f"[{section}] {name}")


def _or_not_given(fail: Fail) -> Fail:
    def or_zero(msg: str, line: int | None, element: str) -> EniError:
        return fail(f"{msg}, or 0 for not given", line, element)

    return or_zero


def _global_fail(source: str) -> Fail:
    def fail(msg: str, line: int | None, element: str) -> EniError:
        return EniError(msg, file=source, line=line, element=element)

    return fail


def read_googol(data: bytes | str, source: str) -> EniConfig:
    """Build the model from a Googol INI ``Gecat.eni`` (see module doc)."""
    glob, blocks = _tokenise(_decode(data), source)
    gfail = _global_fail(source)
    declared = _int_item(glob.get("slaveindex", []), "slavenum", SLAVE_COUNT, gfail, "SlaveIndex")
    if declared is None and not blocks:
        # an explicit slavenum=0 is an empty bus; saying nothing at all is a broken file
        raise EniError(
            "no [SlaveStart] blocks and no [SlaveIndex] slavenum: the file describes no bus "
            "(truncated, or not written by the Googol configuration tool?)",
            file=source,
        )
    if declared is not None and declared != len(blocks):
        it = _first(glob["slaveindex"], "slavenum")
        raise EniError(
            f"slavenum says {declared} slaves but the file has {len(blocks)} [SlaveStart] blocks",
            file=source,
            line=it.line if it else None,
            element="[SlaveIndex] slavenum",
        )

    parsed: list[tuple[int, Slave]] = []
    cycle_ns: int | None = None
    for order, block in enumerate(blocks):
        pos = _int_item(
            block.sections.get("slavestart", []), "position", POSITION, gfail, "SlaveStart"
        )
        slave, cycle = _slave(block, order if pos is None else pos, order, source)
        parsed.append((order if pos is None else pos, slave))
        if cycle_ns is None and cycle:
            cycle_ns = cycle
    parsed.sort(key=lambda t: t[0])
    for k, (pos, s) in enumerate(parsed):
        if k and parsed[k - 1][0] == pos:
            raise EniError(
                f"two slaves say position {pos}",
                file=source,
                line=s.line,
                slave=pos,
                slave_name=s.name,
                element="[SlaveStart] position",
            )
    # our layout of the logical images: slaves in order, byte-aligned per direction
    slaves: list[Slave] = []
    cursor = {Direction.OUT: 0, Direction.IN: 0}
    for k, (_pos, s) in enumerate(parsed):
        areas: dict[Direction, ProcessDataArea | None] = {}
        pdo_sets: dict[Direction, tuple[Pdo, ...]] = {}
        for d, pdos in ((Direction.OUT, s.rx_pdos), (Direction.IN, s.tx_pdos)):
            bits = sum(p.bit_len for p in pdos)
            start = cursor[d] * 8
            areas[d] = ProcessDataArea(start, bits) if bits else None
            placed = []
            cum = start
            for p in pdos:
                entries = []
                for e in p.entries:
                    entries.append(
                        e
                        if e.is_padding
                        else PdoEntry(e.index, e.subindex, e.bit_len, e.name, e.data_type, cum)
                    )
                    cum += e.bit_len
                placed.append(Pdo(p.index, d, tuple(entries), p.name, p.sm, p.fixed))
            pdo_sets[d] = tuple(placed)
            cursor[d] += (bits + 7) // 8
        slaves.append(
            Slave(
                position=k,
                name=s.name,
                identity=s.identity,
                phys_addr=s.phys_addr,
                auto_inc_addr=s.auto_inc_addr,
                rx_pdos=pdo_sets[Direction.OUT],
                tx_pdos=pdo_sets[Direction.IN],
                outputs=areas[Direction.OUT],
                inputs=areas[Direction.IN],
                init_cmds=s.init_cmds,
                mailbox=s.mailbox,
                servo_hint=s.servo_hint,
                nservo_hint=s.nservo_hint,
                line=s.line,
            )
        )
    cfg = EniConfig(
        source=source,
        format="googol",
        slaves=tuple(slaves),
        cycle_time_ns=cycle_ns,
        outputs_bytes=cursor[Direction.OUT],
        inputs_bytes=cursor[Direction.IN],
    )
    check_config(cfg)
    return cfg


def _ints(
    item: _Item, fields: tuple[tuple[str, Limit], ...], fail: Fail, section: str, optional: int = 0
) -> list[int]:
    """The values of ``item`` named and checked by ``fields`` (the last ``optional`` may lack)."""
    element = f"[{section}] {item.name}"
    n = len(fields) - optional
    if len(item.values) < n:
        names = ", ".join(what for what, _ in fields[:n])
        found = ", ".join(shown(r) for r in item.raw[:8])
        raise fail(
            f"{item.name} needs {n} integer values ({names}), found [{found}]", item.line, element
        )
    return [
        _checked(item, k, limit, what, fail, element)
        for k, (what, limit) in enumerate(fields)
        if k < len(item.values)
    ]


def _slave(block: _Block, pos: int, order: int, source: str) -> tuple[Slave, int | None]:
    info = block.sections.get("slave_info", [])
    name_item = _first(info, "slavename")
    name = str(name_item.values[0]) if name_item and name_item.values else f"Slave {pos}"

    def err(msg: str, line: int | None, element: str) -> EniError:
        return EniError(msg, file=source, line=line, slave=pos, slave_name=name, element=element)

    vid = _int_item(info, "vid", IDENTITY, err, "slave_info")
    pcode = _int_item(info, "pcode", IDENTITY, err, "slave_info")
    if vid is None or pcode is None:
        raise err(
            "slave_info has no vid/pcode (vendor id and product code)",
            block.section_lines.get("slave_info", block.line),
            "[slave_info]",
        )
    stype = _int_item(info, "type", SERVO_TYPE, err, "slave_info")
    nservo = _int_item(info, "nservo", NSERVO, err, "slave_info")
    revision = (
        _int_item(info, "revision", IDENTITY, err, "slave_info")
        or _int_item(info, "revisionno", IDENTITY, err, "slave_info")
        or 0
    )

    # sync managers: sm -> direction (1 outputs, 2 inputs) and PDO count
    syncs: dict[int, tuple[Direction, int, int]] = {}
    for it in block.sections.get("slave_sync", []):
        if it.name != "syncitem":
            continue
        sm, dcode, npdo = _ints(
            it,
            (("sync manager", SM), ("direction", SYNC_DIR), ("PDO count", PDO_COUNT)),
            err,
            "slave_sync",
        )
        syncs[sm] = (Direction.OUT if dcode == 1 else Direction.IN, npdo, it.line)
    pdo_sections: dict[int, str] = {}
    for sec in block.sections:
        if m := _SYNC_PDO.match(sec):
            try:
                pdo_sections[SM.parse(m.group(1), "sync manager")] = sec
            except ValueError as exc:
                raise err(str(exc), block.section_lines.get(sec), "[slave_syncN_PDO]") from None
    for sm in pdo_sections:
        if sm not in syncs and sm in (2, 3):  # tolerate a missing slave_sync: SM2 out, SM3 in
            syncs[sm] = (Direction.OUT if sm == 2 else Direction.IN, -1, 0)

    rx: list[Pdo] = []
    tx: list[Pdo] = []
    for sm in sorted(syncs):
        direction, npdo, sline = syncs[sm]
        psec = f"slave_sync{sm}_pdo"
        esec = f"slave_sync{sm}_pdo_entry"
        pitems = [i for i in block.sections.get(psec, []) if i.name == "pdoitem"]
        eitems = [i for i in block.sections.get(esec, []) if i.name == "entryitem"]
        if npdo >= 0 and len(pitems) != npdo:
            raise err(
                f"slave_sync says sync manager {sm} has {npdo} PDOs but [{psec}] "
                f"lists {len(pitems)}",
                block.section_lines.get(psec, sline),
                f"[{psec}]",
            )
        entries: list[tuple[PdoEntry, bool]] = []
        for it in eitems:
            vals = _ints(
                it,
                (("index", INDEX), ("subindex", SUBINDEX), ("bit length", ENTRY_BITS), _ON),
                err,
                esec,
                optional=1,
            )
            index, sub, bits = vals[:3]
            enabled = len(vals) < 4 or vals[3] != 0
            entries.append((PdoEntry(index, sub, bits), enabled))
        cursor = 0
        for it in pitems:
            vals = _ints(
                it,
                (("PDO index", INDEX), ("entry count", PDO_COUNT), ("first entry", ENTRY_POS), _ON),
                err,
                psec,
                optional=2,
            )
            pindex, count = vals[0], vals[1]
            first = vals[2] if len(vals) > 2 else cursor
            enabled = len(vals) < 4 or vals[3] != 0
            if count < 0 or first < 0 or first + count > len(entries):
                raise err(
                    f"PDO 0x{pindex:04X} takes entries {first}..{first + count - 1} but "
                    f"[{esec}] has {len(entries)}",
                    it.line,
                    f"[{psec}] pdoitem",
                )
            cursor = first + count
            if not enabled:
                continue
            chosen = tuple(e for e, _on in entries[first : first + count])
            pdo = Pdo(pindex, direction, chosen, "", sm, False)
            (rx if direction == Direction.OUT else tx).append(pdo)

    _check_iomap(block, rx, tx, err)

    init_cmds = []
    for it in block.sections.get("slave_startsdo", []):
        if it.name != "startitem":
            continue
        index, sub, size = _ints(
            it,
            (("index", INDEX), ("subindex", SUBINDEX), ("size", SDO_SIZE), ("value", _ANY)),
            err,
            "slave_startsdo",
        )[:3]
        value = _checked(it, 3, sdo_value(size), "value", err, "[slave_startsdo] startitem")
        init_cmds.append(
            InitCmd(
                ("PS",),
                index,
                sub,
                (value & ((1 << (8 * size)) - 1)).to_bytes(size, "little"),
                comment=f"Googol start SDO {fmt_index(index, sub)}",
            )
        )

    cycle = None
    for it in block.sections.get("slave_dc", []):
        if it.name == "cycletime0" and it.values:
            # 0 is "not given" (the tool writes it with DC off); else 31.25 us .. 1 s
            if it.values[0] != 0:
                cycle = _checked(
                    it, 0, CYCLE_NS, "cycletime0", _or_not_given(err), "[slave_dc] cycletime0"
                )
            break

    slave = Slave(
        position=pos,
        name=name,
        identity=Identity(vid, pcode, revision),
        rx_pdos=tuple(rx),
        tx_pdos=tuple(tx),
        init_cmds=tuple(init_cmds),
        mailbox=bool(init_cmds) or stype == 1,
        servo_hint=None if stype is None else stype == 1,
        nservo_hint=nservo,
        line=block.line,
    )
    return slave, cycle


def _check_iomap(block: _Block, rx: list[Pdo], tx: list[Pdo], err: Fail) -> None:
    """``slave_iomap`` lists the outputs then the inputs (GT raw order): it must agree."""
    items = [i for i in block.sections.get("slave_iomap", []) if i.name == "mapitem"]
    if not items:
        return
    mapped = [
        (e.index, e.subindex, e.bit_len) for p in (*rx, *tx) for e in p.entries if not e.is_padding
    ]
    listed: list[tuple[tuple[int, int, int], int]] = []
    for it in items:
        vals = _ints(
            it,
            (("index", INDEX), ("subindex", SUBINDEX), ("bit length", _MAP_BITS)),
            err,
            "slave_iomap",
        )
        key = (vals[0], vals[1], vals[2])
        if key[0] != 0:
            listed.append((key, it.line))
    for k, (key, line) in enumerate(listed):
        if k >= len(mapped) or mapped[k] != key:
            want = (
                f"{fmt_index(*mapped[k][:2])} ({mapped[k][2]} bits)"
                if k < len(mapped)
                else "nothing"
            )
            raise err(
                f"slave_iomap item {k} is {fmt_index(key[0], key[1])} ({key[2]} bits) but "
                f"the sync manager PDO lists give {want}",
                line,
                "[slave_iomap] mapitem",
            )
    if len(listed) < len(mapped):
        missing = mapped[len(listed)]
        raise err(
            f"slave_iomap ends before {fmt_index(*missing[:2])}, which the PDO lists map",
            items[-1].line,
            "[slave_iomap]",
        )
