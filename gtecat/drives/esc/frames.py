"""EtherCAT frames on Ethernet: the wire format of ETG.1000.4 clause 5.

An EtherCAT frame is an Ethernet II frame with EtherType 88A4h whose payload
starts with a 2-byte frame header (length 11 bits, reserved 1 bit, type 4 bits;
type 1 = EtherCAT DLPDUs) followed by one or more datagrams chained by their
``M`` (more) bit.  Each datagram (ETG.1000.4 5.4, Table 14 for APRD and its
sibling tables for the other commands) is::

    Cmd u8 | Idx u8 | ADP u16 | ADO u16 | Len:11 R:3 C:1 M:1 | IRQ u16 | Data[Len] | WKC u16

For logical commands ADP/ADO together are the 32-bit logical address (ADP is
the low word).  All fields are little endian.

The construct declarations below are the reference codec (build / parse, used
by tests, tools and anyone composing frames).  :func:`encode_frame` packs the
same bytes with :mod:`struct` and :func:`walk` is the lean per-frame path the
chain uses on every received frame; the property tests check that they agree
with the reference decoder on every frame.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field

from construct import (
    Bit,
    BitsInteger,
    BitStruct,
    Bytes,
    ByteSwapped,
    ConstructError,
    Flag,
    Int8ul,
    Int16ub,
    Int16ul,
    RepeatUntil,
    Struct,
    this,
)

from gtecat.eni.errors import GtecatError
from gtecat.eni.ethercat import (
    DATAGRAM_HEADER_LEN,
    ECAT_HEADER_LEN,
    ETH_HEADER_LEN,
    MAX_ECAT_LEN,
    WKC_LEN,
)

ETHERTYPE_ECAT = 0x88A4
#: frame header type of EtherCAT DLPDUs (ETG.1000.4 5.3); 4 = network variables, 5 = mailbox
FRAME_TYPE_DLPDU = 1
#: smallest Ethernet frame without FCS; shorter frames are padded with zeros
MIN_ETH_FRAME = 60
BROADCAST_MAC = b"\xff" * 6
#: the source address SOEM uses for its primary port
MASTER_MAC = b"\x01\x01\x01\x01\x01\x01"


_U16 = struct.Struct("<H")
_ETYPE = struct.Struct(">H")


class FrameError(GtecatError):
    """A frame that is not a well-formed EtherCAT frame (dropped, never half-processed)."""


# --- construct declarations -------------------------------------------------------------------

#: Ethernet II header (IEEE 802.3 clause 3); no VLAN tag (EtherCAT masters send none)
EthernetHeader = Struct(
    "dst" / Bytes(6),
    "src" / Bytes(6),
    "ethertype" / Int16ub,
)

#: EtherCAT frame header, a little-endian 16-bit word (ETG.1000.4 5.3)
EcatHeader = ByteSwapped(
    BitStruct(
        "type" / BitsInteger(4),
        "reserved" / Bit,
        "length" / BitsInteger(11),
    )
)

#: the word after ADP/ADO: Len:11, R:3, C (circulating):1, M (more follows):1
DatagramFlags = ByteSwapped(
    BitStruct(
        "more" / Flag,
        "circulating" / Flag,
        "reserved" / BitsInteger(3),
        "length" / BitsInteger(11),
    )
)

#: one EtherCAT datagram (ETG.1000.4 5.4)
DatagramStruct = Struct(
    "command" / Int8ul,
    "index" / Int8ul,
    "adp" / Int16ul,
    "ado" / Int16ul,
    "flags" / DatagramFlags,
    "irq" / Int16ul,
    "data" / Bytes(this.flags.length),
    "wkc" / Int16ul,
)

#: a whole frame: Ethernet header, EtherCAT header, datagrams until one has M = 0
FrameStruct = Struct(
    "eth" / EthernetHeader,
    "header" / EcatHeader,
    "datagrams" / RepeatUntil(lambda obj, lst, ctx: not obj["flags"]["more"], DatagramStruct),
)


@dataclass(slots=True)
class Datagram:
    """One datagram as a value; ``adp``/``ado`` hold the logical address for L commands."""

    command: int
    adp: int = 0
    ado: int = 0
    data: bytes = b""
    index: int = 0
    wkc: int = 0
    irq: int = 0
    circulating: bool = False

    @property
    def logical_address(self) -> int:
        return self.adp | (self.ado << 16)

    @classmethod
    def logical(cls, command: int, address: int, data: bytes, **kw: int) -> Datagram:
        return cls(command, address & 0xFFFF, (address >> 16) & 0xFFFF, data, **kw)

    @property
    def size(self) -> int:
        return DATAGRAM_HEADER_LEN + len(self.data) + WKC_LEN


@dataclass(slots=True)
class DecodedFrame:
    dst: bytes
    src: bytes
    datagrams: list[Datagram] = field(default_factory=list)


#: a datagram's header: Cmd, Idx, ADP, ADO, the Len/C/M word, IRQ (ETG.1000.4 5.4)
_DATAGRAM_HEADER = struct.Struct("<BBHHHH")
_ETHERTYPE_BYTES = ETHERTYPE_ECAT.to_bytes(2, "big")


def encode_frame(
    datagrams: list[Datagram],
    *,
    src: bytes = MASTER_MAC,
    dst: bytes = BROADCAST_MAC,
    pad: bool = True,
) -> bytes:
    """Build an Ethernet frame carrying ``datagrams`` (padded to 60 bytes unless ``pad=False``).

    Packed field by field with :mod:`struct`, the bytes :data:`FrameStruct` builds (its
    decoder reads them back in the tests): a capture or a test's master encodes frames by
    the thousand, and construct takes twenty times as long for each."""
    if not datagrams:
        raise FrameError("a frame needs at least one datagram")
    length = sum(d.size for d in datagrams)
    if length > MAX_ECAT_LEN:
        raise FrameError(f"datagrams need {length} bytes, a frame holds {MAX_ECAT_LEN}")
    if len(dst) != 6 or len(src) != 6:
        raise FrameError(f"cannot encode frame: MAC addresses of {len(dst)} and {len(src)} bytes")
    parts = [bytes(dst), bytes(src), _ETHERTYPE_BYTES, _U16.pack(FRAME_TYPE_DLPDU << 12 | length)]
    last = len(datagrams) - 1
    try:
        for i, d in enumerate(datagrams):
            data = bytes(d.data)
            flags = len(data) | (0x4000 if d.circulating else 0) | (0x8000 if i != last else 0)
            parts += (
                _DATAGRAM_HEADER.pack(d.command, d.index, d.adp, d.ado, flags, d.irq),
                data,
                _U16.pack(d.wkc),
            )
    except struct.error as exc:  # a field out of range
        raise FrameError(f"cannot encode frame: {exc}") from exc
    raw = b"".join(parts)
    if pad and len(raw) < MIN_ETH_FRAME:
        raw += bytes(MIN_ETH_FRAME - len(raw))
    return raw


def decode_frame(buf: bytes | bytearray | memoryview) -> DecodedFrame:
    """Parse a whole Ethernet frame; :class:`FrameError` for anything malformed."""
    buf = bytes(buf)
    if len(buf) < ETH_HEADER_LEN + ECAT_HEADER_LEN:
        raise FrameError(f"frame of {len(buf)} bytes is too short")
    try:
        parsed = FrameStruct.parse(buf)
    except ConstructError as exc:
        raise FrameError(f"malformed EtherCAT frame: {exc}") from None
    if parsed.eth.ethertype != ETHERTYPE_ECAT:
        raise FrameError(f"EtherType 0x{parsed.eth.ethertype:04X} is not EtherCAT")
    if parsed.header.type != FRAME_TYPE_DLPDU:
        raise FrameError(f"frame type {parsed.header.type} is not EtherCAT DLPDUs (1)")
    used = sum(DATAGRAM_HEADER_LEN + len(d.data) + WKC_LEN for d in parsed.datagrams)
    if used != parsed.header.length:
        raise FrameError(f"frame header says {parsed.header.length} bytes, datagrams take {used}")
    return DecodedFrame(
        parsed.eth.dst,
        parsed.eth.src,
        [
            Datagram(
                d.command,
                d.adp,
                d.ado,
                bytes(d.data),
                d.index,
                d.wkc,
                d.irq,
                bool(d.flags.circulating),
            )
            for d in parsed.datagrams
        ],
    )


# --- the lean path --------------------------------------------------------------------------


def walk(buf: bytes | bytearray | memoryview, n: int | None = None) -> list[int] | None:
    """Offsets of every datagram header in an Ethernet frame, or ``None`` if malformed.

    ``n`` is the number of valid bytes in ``buf`` (a receive buffer is larger
    than the frame).  Checks exactly what :func:`decode_frame` checks: the
    EtherType, the frame type, each datagram fitting inside the header length,
    the chain ending with ``M = 0`` at exactly that length.
    """
    if n is None:
        n = len(buf)
    if n < ETH_HEADER_LEN + ECAT_HEADER_LEN:
        return None
    if _ETYPE.unpack_from(buf, 12)[0] != ETHERTYPE_ECAT:
        return None
    hdr = _U16.unpack_from(buf, ETH_HEADER_LEN)[0]
    if hdr >> 12 != FRAME_TYPE_DLPDU:
        return None
    end = ETH_HEADER_LEN + ECAT_HEADER_LEN + (hdr & 0x07FF)
    if end > n:
        return None
    pos = ETH_HEADER_LEN + ECAT_HEADER_LEN
    offsets: list[int] = []
    while True:
        if pos + DATAGRAM_HEADER_LEN + WKC_LEN > end:
            return None
        flags = _U16.unpack_from(buf, pos + 6)[0]
        nxt = pos + DATAGRAM_HEADER_LEN + (flags & 0x07FF) + WKC_LEN
        if nxt > end:
            return None
        offsets.append(pos)
        pos = nxt
        if not flags & 0x8000:
            break
    if pos != end:
        return None
    return offsets
