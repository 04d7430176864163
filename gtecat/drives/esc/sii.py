"""The SII EEPROM of a virtual slave, generated from what the slave is.

A master learns a slave from its Slave Information Interface (ETG.1000.6
5.4, Table 16 "SII area"; ETG.2010 Table 2): the fixed words 0000h-003Fh
(PDI configuration, station alias, checksum, identity, mailbox offsets and
sizes, supported mailbox protocols, EEPROM size) and, from word 0040h on, a
list of categories (ETG.1000.6 Table 17): strings (10), general (30), FMMU
usage (40), sync managers (41), TxPDOs (50), RxPDOs (51), each introduced by a
type word and a size word (size in words), closed by type FFFFh.

SOEM reads the identity and mailbox words during ``config_init``, the slave's
name from string 1, CoE details from the general category, the SM layout from
category 41 and, when the CoE mapping cannot be read, the PDO sizes from the
PDO categories.  :func:`sii_info_for` derives all of it from a
:class:`~gtecat.drives.slave.VirtualSlave`; :func:`build_sii` encodes, and
:func:`parse_sii` decodes (for tests and tools) with the same construct
declarations.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum, IntFlag

from construct import (
    Array,
    Bytes,
    ConstructError,
    Int8ul,
    Int16sl,
    Int16ul,
    Int32ul,
    PascalString,
    Struct,
    this,
)

from gtecat.eni.errors import GtecatError
from gtecat.eni.model import Direction, Identity, Pdo, PdoEntry


class SiiError(GtecatError):
    """SII content that cannot be built or parsed."""


class Category(IntEnum):
    """SII category types (ETG.1000.6 Table 17)."""

    NOP = 0
    STRINGS = 10
    DATATYPES = 20
    GENERAL = 30
    FMMU = 40
    SYNCM = 41
    TXPDO = 50
    RXPDO = 51
    DC = 60
    END = 0xFFFF


class MailboxProtocol(IntFlag):
    """Supported mailbox protocols, SII word 001Ch (ETG.1000.6 Table 18)."""

    AOE = 0x01
    EOE = 0x02
    COE = 0x04
    FOE = 0x08
    SOE = 0x10
    VOE = 0x20


class CoeDetails(IntFlag):
    """General category CoE details byte (ETG.2010 Table 6)."""

    SDO = 0x01
    SDO_INFO = 0x02
    PDO_ASSIGN = 0x04
    PDO_CONFIG = 0x08
    UPLOAD_AT_STARTUP = 0x10
    SDO_COMPLETE_ACCESS = 0x20


class SmType(IntEnum):
    """Sync manager usage, last byte of an SII SM entry (ETG.2010 Table 8)."""

    UNUSED = 0
    MAILBOX_OUT = 1  # master -> slave (SM0)
    MAILBOX_IN = 2  # slave -> master (SM1)
    OUTPUTS = 3
    INPUTS = 4


class FmmuUsage(IntEnum):
    """FMMU category byte (ETG.2010 Table 7)."""

    UNUSED = 0
    OUTPUTS = 1
    INPUTS = 2
    MAILBOX_STATE = 3


NO_PROTOCOLS = MailboxProtocol(0)
NO_COE = CoeDetails(0)

# SM control bytes (ETG.1000.4 Table 59): mode bits 1:0 (00 buffered, 10 mailbox),
# direction bits 3:2 (00 ECAT reads, 01 ECAT writes), bit 5 PDI interrupt, bit 6 watchdog.
SM_CONTROL_MBX_OUT = 0x26
SM_CONTROL_MBX_IN = 0x22
SM_CONTROL_OUTPUTS = 0x64
SM_CONTROL_INPUTS = 0x20

# --- construct declarations -------------------------------------------------------------------

#: words 0000h-003Fh (ETG.1000.6 Table 16, ETG.2010 Table 2)
SiiHeader = Struct(
    "pdi_control" / Int16ul,
    "pdi_configuration" / Int16ul,
    "sync_impulse_len" / Int16ul,
    "pdi_configuration2" / Int16ul,
    "station_alias" / Int16ul,
    "reserved1" / Bytes(4),
    "checksum" / Int16ul,  # CRC-8 of words 0-6 in the low byte
    "vendor_id" / Int32ul,
    "product_code" / Int32ul,
    "revision_no" / Int32ul,
    "serial_no" / Int32ul,
    "execution_delay" / Int16ul,
    "port0_delay" / Int16ul,
    "port1_delay" / Int16ul,
    "reserved2" / Int16ul,
    "bootstrap_rx_offset" / Int16ul,
    "bootstrap_rx_size" / Int16ul,
    "bootstrap_tx_offset" / Int16ul,
    "bootstrap_tx_size" / Int16ul,
    "std_rx_offset" / Int16ul,  # SM0, master -> slave
    "std_rx_size" / Int16ul,
    "std_tx_offset" / Int16ul,  # SM1, slave -> master
    "std_tx_size" / Int16ul,
    "mailbox_protocol" / Int16ul,
    "reserved3" / Bytes(66),
    "size" / Int16ul,  # EEPROM size in KBit - 1
    "version" / Int16ul,
)
assert SiiHeader.sizeof() == 128

CategoryHeader = Struct("type" / Int16ul, "words" / Int16ul)

#: general category (ETG.2010 Table 6)
GeneralCategory = Struct(
    "group_idx" / Int8ul,
    "image_idx" / Int8ul,
    "order_idx" / Int8ul,
    "name_idx" / Int8ul,
    "reserved1" / Int8ul,
    "coe_details" / Int8ul,
    "foe_details" / Int8ul,
    "eoe_details" / Int8ul,
    "soe_channels" / Int8ul,
    "ds402_channels" / Int8ul,
    "sysman_class" / Int8ul,
    "flags" / Int8ul,
    "current_on_ebus" / Int16sl,
    "group_idx_dup" / Int8ul,
    "reserved2" / Int8ul,
    "physical_port" / Int16ul,
    "physical_memory_address" / Int16ul,
    "reserved3" / Bytes(12),
)
assert GeneralCategory.sizeof() == 32

#: one sync manager entry (ETG.2010 Table 8)
SmEntry = Struct(
    "start" / Int16ul,
    "length" / Int16ul,
    "control" / Int8ul,
    "status" / Int8ul,
    "enable" / Int8ul,
    "type" / Int8ul,
)

#: one PDO entry (ETG.2010 Table 9)
PdoEntryStruct = Struct(
    "index" / Int16ul,
    "subindex" / Int8ul,
    "name_idx" / Int8ul,
    "data_type" / Int8ul,
    "bit_len" / Int8ul,
    "flags" / Int16ul,
)

#: one PDO of a TxPDO/RxPDO category (ETG.2010 Table 9)
PdoStruct = Struct(
    "index" / Int16ul,
    "n_entries" / Int8ul,
    "sm" / Int8ul,
    "dc_sync" / Int8ul,
    "name_idx" / Int8ul,
    "flags" / Int16ul,
    "entries" / Array(this.n_entries, PdoEntryStruct),
)

StringsCategory = Struct(
    "count" / Int8ul,
    "strings" / Array(this.count, PascalString(Int8ul, "latin-1")),
)

# CoE basic data types (ETG.1000.6 Table 64) by the names ENI files use.
_DATA_TYPES = {
    "BOOL": 0x01,
    "BIT": 0x01,
    "SINT": 0x02,
    "INT": 0x03,
    "DINT": 0x04,
    "USINT": 0x05,
    "UINT": 0x06,
    "UDINT": 0x07,
    "REAL": 0x08,
    "LREAL": 0x11,
    "LINT": 0x15,
    "ULINT": 0x1B,
    "BYTE": 0x05,
    "WORD": 0x06,
    "DWORD": 0x07,
    "INT8": 0x02,
    "INT16": 0x03,
    "INT32": 0x04,
    "UINT8": 0x05,
    "UINT16": 0x06,
    "UINT32": 0x07,
    "INT64": 0x15,
    "UINT64": 0x1B,
}
_DATA_TYPE_NAMES = {
    0x01: "BOOL",
    0x02: "SINT",
    0x03: "INT",
    0x04: "DINT",
    0x05: "USINT",
    0x06: "UINT",
    0x07: "UDINT",
    0x08: "REAL",
    0x11: "LREAL",
    0x15: "LINT",
    0x1B: "ULINT",
}
_BY_BITS = {1: 0x01, 8: 0x05, 16: 0x06, 32: 0x07, 64: 0x1B}


def data_type_code(entry: PdoEntry) -> int:
    """The CoE data type code of an entry (from its ENI type name, else its size)."""
    name = entry.data_type.upper().strip()
    if name in _DATA_TYPES:
        return _DATA_TYPES[name]
    if name.startswith("BIT"):
        return 0x01 if entry.bit_len == 1 else 0x30 + min(entry.bit_len, 8) - 1
    if entry.is_padding:
        return 0
    return _BY_BITS.get(entry.bit_len, 0)


@dataclass(frozen=True, slots=True)
class SmConfig:
    """A sync manager as the SII describes it (and a master programs it)."""

    start: int
    length: int
    control: int
    enable: int
    type: SmType


@dataclass(frozen=True, slots=True)
class SiiInfo:
    """Everything the SII of one slave says."""

    identity: Identity
    name: str
    group: str = ""
    alias: int = 0
    mailbox_protocols: MailboxProtocol = NO_PROTOCOLS
    rx_mailbox: tuple[int, int] = (0, 0)  # (offset, size), master -> slave
    tx_mailbox: tuple[int, int] = (0, 0)  # slave -> master
    coe_details: CoeDetails = NO_COE
    sync_managers: tuple[SmConfig, ...] = ()
    fmmus: tuple[FmmuUsage, ...] = ()
    rx_pdos: tuple[Pdo, ...] = ()
    tx_pdos: tuple[Pdo, ...] = ()
    ebus_current: int = 0
    #: PDI control word (SII word 0): 05h = 16-bit asynchronous microcontroller interface
    pdi_control: int = 0x0005
    ds402_channels: int = 0
    extra: dict[str, int] = field(default_factory=dict, compare=False)

    @property
    def has_mailbox(self) -> bool:
        return self.rx_mailbox[1] > 0 and self.tx_mailbox[1] > 0


def sii_crc(data: bytes) -> int:
    """CRC-8 of the first 7 SII words (ETG.1000.6 / IEC 61158-6-12 5.4).

    Polynomial x^8 + x^2 + x + 1, preset FFh, not reflected, no final XOR - the
    checksum IgH verifies when it scans a slave.
    """
    crc = 0xFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = ((crc << 1) ^ 0x07) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
    return crc


def _align(value: int, to: int) -> int:
    return (value + to - 1) // to * to


def default_layout(
    has_mailbox: bool, rx_bytes: int, tx_bytes: int, mailbox_size: int = 128
) -> tuple[SmConfig, ...]:
    """The SM layout of a virtual slave.

    With a mailbox: SM0/SM1 mailbox at 1000h, SM2 outputs, SM3 inputs (ETG.1000.4
    Table 59 usage).  Without: SM0 outputs and SM1 inputs, as simple terminals do.
    Each process data area leaves room for three buffers (and for a remapping
    that grows the PDOs).
    """
    sms: list[SmConfig] = []
    base = 0x1000
    if has_mailbox:
        sms.append(SmConfig(base, mailbox_size, SM_CONTROL_MBX_OUT, 1, SmType.MAILBOX_OUT))
        sms.append(
            SmConfig(base + mailbox_size, mailbox_size, SM_CONTROL_MBX_IN, 1, SmType.MAILBOX_IN)
        )
        base = _align(base + 2 * mailbox_size, 0x100)
    out_start = base
    in_start = out_start + max(0x300, _align(3 * rx_bytes, 0x100))
    sms.append(SmConfig(out_start, rx_bytes, SM_CONTROL_OUTPUTS, int(rx_bytes > 0), SmType.OUTPUTS))
    sms.append(SmConfig(in_start, tx_bytes, SM_CONTROL_INPUTS, int(tx_bytes > 0), SmType.INPUTS))
    return tuple(sms)


def _synthetic_pdos(direction: Direction, bits: int) -> tuple[Pdo, ...]:
    """A stand-in mapping of the right size for a slave that does not list its PDOs."""
    if bits <= 0:
        return ()
    entries = []
    left, sub = bits, 1
    while left:
        n = 8 if left >= 8 else left
        entries.append(PdoEntry(0x7000 if direction == Direction.OUT else 0x6000, sub, n))
        left -= n
        sub += 1
        if sub > 254:
            break
    index = 0x1600 if direction == Direction.OUT else 0x1A00
    return (Pdo(index, direction, tuple(entries)),)


def _mapped_pdos(slave: object, direction: Direction) -> tuple[Pdo, ...] | None:
    """The PDOs the slave's CoE mapping assigns now (1C12h/1C13h and 16xx/1Axx), with the
    names and types its object dictionary gives; None for a slave without such a mapping."""
    mapping = getattr(slave, "mapping", None)
    od = getattr(slave, "od", None)
    if mapping is None or od is None or not hasattr(mapping, "assigned"):
        return None
    pdos = []
    for pdo_index in mapping.assigned(direction):
        obj = od.objects.get(pdo_index)
        entries = []
        count = int(obj.subs[0].get()) if obj is not None and 0 in obj.subs else 0
        for k in range(1, count + 1):
            value = int(obj.subs[k].get()) if obj is not None and k in obj.subs else 0
            index, sub, bits = value >> 16, (value >> 8) & 0xFF, value & 0xFF
            target = od.find(index, sub) if index else None
            name = "" if target is None or target.placeholder else target.name
            dtype = "" if target is None else _DATA_TYPE_NAMES.get(int(target.data_type), "")
            entries.append(PdoEntry(index, sub, bits, name, dtype))
        pdos.append(Pdo(pdo_index, direction, tuple(entries), obj.name if obj else ""))
    return tuple(pdos)


def sii_info_for(slave: object, *, mailbox_size: int = 128) -> SiiInfo:
    """The SII of a :class:`~gtecat.drives.slave.VirtualSlave`.

    Identity and name come from the slave; the PDO categories from the mapping
    its CoE objects assign (``slave.mapping``: a drive's 6040h/607Ah and
    6041h/6064h/60FDh with their names), else from its ``rx_pdos``/``tx_pdos``
    (the mapping the ENI assigned), else from a stand-in of ``pdo_sizes()``;
    CoE details from an optional ``coe_details`` attribute (default: SDO, SDO
    Information, PDO assign and PDO config); the
    mailbox size from the slave's SDO server (``slave.sdo.mailbox_size``) when
    it has one, since that is the size it segments its answers to.
    """
    rx_bits, tx_bits = slave.pdo_sizes()  # type: ignore[attr-defined]
    # the SDO server segments its answers to its own mailbox size: the SMs must match it
    mailbox_size = int(getattr(getattr(slave, "sdo", None), "mailbox_size", mailbox_size))
    rx_pdos = _mapped_pdos(slave, Direction.OUT)
    if rx_pdos is None:
        rx_pdos = tuple(getattr(slave, "rx_pdos", ()) or ()) or _synthetic_pdos(
            Direction.OUT, rx_bits
        )
    tx_pdos = _mapped_pdos(slave, Direction.IN)
    if tx_pdos is None:
        tx_pdos = tuple(getattr(slave, "tx_pdos", ()) or ()) or _synthetic_pdos(
            Direction.IN, tx_bits
        )
    has_mailbox = bool(getattr(slave, "has_mailbox", False))
    rx_bytes, tx_bytes = (rx_bits + 7) // 8, (tx_bits + 7) // 8
    sms = default_layout(has_mailbox, rx_bytes, tx_bytes, mailbox_size)
    if has_mailbox:
        fmmus = (FmmuUsage.OUTPUTS, FmmuUsage.INPUTS, FmmuUsage.MAILBOX_STATE)
        coe = CoeDetails(
            getattr(
                slave,
                "coe_details",
                CoeDetails.SDO
                | CoeDetails.SDO_INFO
                | CoeDetails.PDO_ASSIGN
                | CoeDetails.PDO_CONFIG,
            )
        )
        protocols = MailboxProtocol.COE | MailboxProtocol.FOE  # FoE: gtecat.drives.foe
    else:
        fmmus = (FmmuUsage.OUTPUTS, FmmuUsage.INPUTS)
        coe, protocols = CoeDetails(0), MailboxProtocol(0)
    # a slave with a mailbox has a microcontroller on a 16-bit asynchronous PDI (05h); one
    # without is a bare ESC: digital I/O PDI (04h) with device emulation (0141h bit 0)
    pdi_control = 0x0005 if has_mailbox else 0x0104
    channels = getattr(slave, "channels", 0)
    if not isinstance(channels, int):
        channels = len(channels)
    return SiiInfo(
        identity=slave.identity,  # type: ignore[attr-defined]
        name=str(slave.name),  # type: ignore[attr-defined]
        group="Drives" if has_mailbox and channels else "IO",
        alias=int(getattr(slave, "station_alias", 0)),
        mailbox_protocols=protocols,
        rx_mailbox=(sms[0].start, sms[0].length) if has_mailbox else (0, 0),
        tx_mailbox=(sms[1].start, sms[1].length) if has_mailbox else (0, 0),
        coe_details=coe,
        sync_managers=sms,
        fmmus=fmmus,
        rx_pdos=rx_pdos,
        tx_pdos=tx_pdos,
        pdi_control=pdi_control,
        ds402_channels=channels,
    )


# --- encoding ---------------------------------------------------------------------------------


class _Strings:
    """The string table: index 1 is the slave's name (SOEM takes string 1 as the name)."""

    def __init__(self, limit: int = 255) -> None:
        self.items: list[str] = []
        self.limit = limit

    def add(self, text: str) -> int:
        text = text.encode("latin-1", "replace")[:255].decode("latin-1")
        if not text:
            return 0
        if text in self.items:
            return self.items.index(text) + 1
        if len(self.items) >= self.limit:
            return 0
        self.items.append(text)
        return len(self.items)


def _category(ctype: int, payload: bytes) -> bytes:
    if len(payload) % 2:
        payload += b"\x00"
    return CategoryHeader.build({"type": ctype, "words": len(payload) // 2}) + payload


def _pdo_category(pdos: tuple[Pdo, ...], sm: int, strings: _Strings, names: bool) -> bytes:
    out = bytearray()
    for pdo in pdos:
        entries = [
            {
                "index": e.index,
                "subindex": e.subindex,
                "name_idx": strings.add(e.name) if names else 0,
                "data_type": data_type_code(e),
                "bit_len": e.bit_len,
                "flags": 0,
            }
            for e in pdo.entries
        ]
        if any(not 0 < e.bit_len <= 255 for e in pdo.entries):
            raise SiiError(f"PDO 0x{pdo.index:04X}: an SII entry holds 1..255 bits")
        out += PdoStruct.build(
            {
                "index": pdo.index,
                "n_entries": len(entries),
                "sm": sm,
                "dc_sync": 0,
                "name_idx": strings.add(pdo.name) if names else 0,
                "flags": 0x0010 if pdo.fixed else 0,  # PdoFixedContent
                "entries": entries,
            }
        )
    return bytes(out)


def _sm_for(info: SiiInfo, kind: SmType) -> int:
    for n, sm in enumerate(info.sync_managers):
        if sm.type == kind:
            return n
    return 0xFF


def _build(info: SiiInfo, names: bool) -> bytes:
    strings = _Strings()
    name_idx = strings.add(info.name)
    group_idx = strings.add(info.group)
    cats = bytearray()
    general = GeneralCategory.build(
        {
            "group_idx": group_idx,
            "image_idx": 0,
            "order_idx": name_idx,
            "name_idx": name_idx,
            "reserved1": 0,
            "coe_details": int(info.coe_details),
            "foe_details": 0,
            "eoe_details": 0,
            "soe_channels": 0,
            "ds402_channels": info.ds402_channels,
            "sysman_class": 0,
            "flags": 0,
            "current_on_ebus": info.ebus_current,
            "group_idx_dup": group_idx,
            "reserved2": 0,
            "physical_port": 0x0011,  # ports 0 and 1: MII
            "physical_memory_address": 0,
            "reserved3": bytes(12),
        }
    )
    fmmu = bytes(int(u) for u in info.fmmus)
    syncm = b"".join(
        SmEntry.build(
            {
                "start": s.start,
                "length": s.length,
                "control": s.control,
                "status": 0,
                "enable": s.enable,
                "type": int(s.type),
            }
        )
        for s in info.sync_managers
    )
    txpdo = _pdo_category(info.tx_pdos, _sm_for(info, SmType.INPUTS), strings, names)
    rxpdo = _pdo_category(info.rx_pdos, _sm_for(info, SmType.OUTPUTS), strings, names)
    strings_payload = StringsCategory.build({"count": len(strings.items), "strings": strings.items})
    # the categories masters need most come first: a master with a small SII cache
    # (SOEM reads at most 4 KiB) still finds them
    cats += _category(Category.GENERAL, general)
    cats += _category(Category.FMMU, fmmu)
    cats += _category(Category.SYNCM, syncm)
    if txpdo:
        cats += _category(Category.TXPDO, txpdo)
    if rxpdo:
        cats += _category(Category.RXPDO, rxpdo)
    cats += _category(Category.STRINGS, strings_payload)
    cats += CategoryHeader.build({"type": Category.END, "words": 0})
    total = 128 + len(cats)
    kbit = 1
    while kbit * 128 < total:
        kbit *= 2
    header = dict(
        pdi_control=info.pdi_control,
        pdi_configuration=0,
        sync_impulse_len=0,
        pdi_configuration2=0,
        station_alias=info.alias,
        reserved1=bytes(4),
        checksum=0,
        vendor_id=info.identity.vendor_id,
        product_code=info.identity.product_code,
        revision_no=info.identity.revision_no,
        serial_no=info.identity.serial_no,
        execution_delay=0,
        port0_delay=0,
        port1_delay=0,
        reserved2=0,
        bootstrap_rx_offset=0,
        bootstrap_rx_size=0,
        bootstrap_tx_offset=0,
        bootstrap_tx_size=0,
        std_rx_offset=info.rx_mailbox[0],
        std_rx_size=info.rx_mailbox[1],
        std_tx_offset=info.tx_mailbox[0],
        std_tx_size=info.tx_mailbox[1],
        mailbox_protocol=int(info.mailbox_protocols),
        reserved3=bytes(66),
        size=kbit - 1,
        version=1,
    )
    raw = bytearray(SiiHeader.build(header))
    raw[14] = sii_crc(bytes(raw[:14]))
    return bytes(raw + cats)


#: SOEM caches at most 4096 bytes of SII; keep the whole content inside
SII_SOFT_LIMIT = 4096


def build_sii(info: SiiInfo) -> bytes:
    """Encode the SII content (entry names dropped if they would not fit a master's cache)."""
    try:
        raw = _build(info, names=True)
        if len(raw) > SII_SOFT_LIMIT:
            raw = _build(info, names=False)
    except (ConstructError, ValueError, OverflowError) as exc:
        raise SiiError(f"cannot encode SII of {info.name!r}: {exc}") from exc
    return raw


# --- decoding ---------------------------------------------------------------------------------


def iter_categories(raw: bytes) -> list[tuple[int, bytes]]:
    """(type, payload) of every category, in EEPROM order."""
    out: list[tuple[int, bytes]] = []
    pos = 128
    while pos + 4 <= len(raw):
        hdr = CategoryHeader.parse(raw[pos : pos + 4])
        if hdr.type == Category.END:
            return out
        end = pos + 4 + 2 * hdr.words
        if end > len(raw):
            raise SiiError(f"category {hdr.type} at byte {pos} runs past the end")
        out.append((hdr.type, raw[pos + 4 : end]))
        pos = end
    raise SiiError("no end category")


def _pdos(payload: bytes, direction: Direction, strings: list[str]) -> tuple[Pdo, ...]:
    def name(i: int) -> str:
        return strings[i - 1] if 0 < i <= len(strings) else ""

    pdos = []
    pos = 0
    while pos + 8 <= len(payload):
        p = PdoStruct.parse(payload[pos:])
        pos += 8 + 8 * p.n_entries
        pdos.append(
            Pdo(
                p.index,
                direction,
                tuple(
                    PdoEntry(
                        e.index,
                        e.subindex,
                        e.bit_len,
                        name(e.name_idx),
                        _DATA_TYPE_NAMES.get(e.data_type, ""),
                    )
                    for e in p.entries
                ),
                name(p.name_idx),
                None if p.sm == 0xFF else p.sm,
                bool(p.flags & 0x0010),
            )
        )
    return tuple(pdos)


def parse_sii(raw: bytes) -> SiiInfo:
    """Decode SII content back into a :class:`SiiInfo` (PDO SM numbers as stored)."""
    try:
        hdr = SiiHeader.parse(raw)
        cats = iter_categories(raw)
        strings: list[str] = []
        for ctype, payload in cats:
            if ctype == Category.STRINGS:
                strings = list(StringsCategory.parse(payload).strings)
        general = None
        sms: list[SmConfig] = []
        fmmus: tuple[FmmuUsage, ...] = ()
        tx_pdos: tuple[Pdo, ...] = ()
        rx_pdos: tuple[Pdo, ...] = ()
        for ctype, payload in cats:
            if ctype == Category.GENERAL:
                general = GeneralCategory.parse(payload)
            elif ctype == Category.FMMU:
                fmmus = tuple(FmmuUsage(b) for b in payload if b in (1, 2, 3))
            elif ctype == Category.SYNCM:
                for k in range(len(payload) // 8):
                    s = SmEntry.parse(payload[8 * k : 8 * k + 8])
                    sms.append(SmConfig(s.start, s.length, s.control, s.enable, SmType(s.type)))
            elif ctype == Category.TXPDO:
                tx_pdos = _pdos(payload, Direction.IN, strings)
            elif ctype == Category.RXPDO:
                rx_pdos = _pdos(payload, Direction.OUT, strings)
    except (ConstructError, ValueError) as exc:
        raise SiiError(f"malformed SII: {exc}") from exc

    def s(i: int) -> str:
        return strings[i - 1] if 0 < i <= len(strings) else ""

    return SiiInfo(
        identity=Identity(hdr.vendor_id, hdr.product_code, hdr.revision_no, hdr.serial_no),
        name=s(general.name_idx) if general else (strings[0] if strings else ""),
        group=s(general.group_idx) if general else "",
        alias=hdr.station_alias,
        mailbox_protocols=MailboxProtocol(hdr.mailbox_protocol),
        rx_mailbox=(hdr.std_rx_offset, hdr.std_rx_size),
        tx_mailbox=(hdr.std_tx_offset, hdr.std_tx_size),
        coe_details=CoeDetails(general.coe_details) if general else CoeDetails(0),
        sync_managers=tuple(sms),
        fmmus=fmmus,
        rx_pdos=rx_pdos,
        tx_pdos=tx_pdos,
        ebus_current=general.current_on_ebus if general else 0,
        pdi_control=hdr.pdi_control,
        ds402_channels=general.ds402_channels if general else 0,
        extra={"checksum": hdr.checksum & 0xFF, "crc": sii_crc(raw[:14]), "size": hdr.size},
    )
