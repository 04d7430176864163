"""Mailbox, CoE and SDO wire formats (ETG.1000.4 5.5, ETG.1000.6 5.6) and an SDO client.

The same bytes travel through the in-process backend (``VirtualSlave.mailbox``)
and, later, through sync managers 0/1 of the wire-level ESC: a whole mailbox
message is the 6-byte mailbox header followed by ``length`` bytes of service
data.  For CoE that is the 2-byte CoE header and the SDO frame.

Bit fields are declared most significant bit first (construct's ``BitStruct``
order) and read as "bits 7..0" of the byte the standard draws.
"""

from __future__ import annotations

import functools
import logging
from collections.abc import Callable
from dataclasses import dataclass
from enum import IntEnum, IntFlag
from typing import TypeVar

from construct import (
    BitsInteger,
    BitStruct,
    Bytes,
    ByteSwapped,
    Const,
    ConstructError,
    Container,
    Flag,
    GreedyBytes,
    Int8ul,
    Int16ul,
    Int32ul,
    Struct,
    this,
)

from gtecat.drives.abort import MailboxFailure, SdoAbort, SdoAbortCode, mailbox_failure

log = logging.getLogger(__name__)

MAILBOX_HEADER_SIZE = 6
COE_HEADER_SIZE = 2
#: default mailbox (SM0/SM1) size of the virtual slaves, bytes
DEFAULT_MAILBOX_SIZE = 128


class MailboxType(IntEnum):
    """Mailbox header ``Type`` (ETG.1000.4 Table 29)."""

    ERR = 0x0
    AOE = 0x1
    EOE = 0x2
    COE = 0x3
    FOE = 0x4
    SOE = 0x5
    VOE = 0xF


class MailboxError(IntEnum):
    """Detail of a mailbox error reply (ETG.1000.4 Table 30)."""

    SYNTAX = 0x01
    UNSUPPORTED_PROTOCOL = 0x02
    INVALID_CHANNEL = 0x03
    SERVICE_NOT_SUPPORTED = 0x04
    INVALID_HEADER = 0x05
    SIZE_TOO_SHORT = 0x06
    NO_MORE_MEMORY = 0x07
    INVALID_SIZE = 0x08


class CoeService(IntEnum):
    """CoE header ``Service`` (ETG.1000.6 Table 29)."""

    EMERGENCY = 1
    SDO_REQUEST = 2
    SDO_RESPONSE = 3
    TXPDO = 4
    RXPDO = 5
    TXPDO_REMOTE_REQUEST = 6
    RXPDO_REMOTE_REQUEST = 7
    SDO_INFORMATION = 8


class Ccs(IntEnum):
    """Client command specifier, bits 7..5 of an SDO request (ETG.1000.6 5.6.2)."""

    DOWNLOAD_SEGMENT = 0
    INITIATE_DOWNLOAD = 1
    INITIATE_UPLOAD = 2
    UPLOAD_SEGMENT = 3
    ABORT = 4


class Scs(IntEnum):
    """Server command specifier, bits 7..5 of an SDO response (ETG.1000.6 5.6.2)."""

    UPLOAD_SEGMENT = 0
    DOWNLOAD_SEGMENT = 1
    INITIATE_UPLOAD = 2
    INITIATE_DOWNLOAD = 3
    ABORT = 4


# --- ETG.1000.4 Table 29: mailbox header ------------------------------------
MailboxHeader = Struct(
    "length" / Int16ul,  # bytes of service data after this header
    "address" / Int16ul,  # station address of the source (master -> slave) or 0
    "bits"
    / BitStruct(
        "priority" / BitsInteger(2),  # byte 4 bits 7..6
        "channel" / BitsInteger(6),  # byte 4 bits 5..0
        "reserved" / BitsInteger(1),  # byte 5 bit 7
        "counter" / BitsInteger(3),  # byte 5 bits 6..4: 1..7, 0 = unused
        "type" / BitsInteger(4),  # byte 5 bits 3..0: MailboxType
    ),
)

MailboxMessage = Struct("header" / MailboxHeader, "data" / Bytes(this.header.length))

# --- ETG.1000.4 Table 30: mailbox error reply (Type = ERR) --------------------
MailboxErrorReply = Struct("type" / Const(1, Int16ul), "detail" / Int16ul)

# --- ETG.1000.6 Table 29 (CoE header): 16 bits little endian ------------------
CoeHeader = ByteSwapped(
    BitStruct(
        "service" / BitsInteger(4),  # bits 15..12: CoeService
        "reserved" / BitsInteger(3),  # bits 11..9
        "number" / BitsInteger(9),  # bits 8..0: PDO number (0 for SDO)
    )
)

# --- ETG.1000.6 5.6.2.1-5.6.2.2: initiate command byte -------------------------
SdoInitiateCommand = BitStruct(
    "command" / BitsInteger(3),  # Ccs / Scs
    "complete_access" / Flag,  # bit 4
    "size" / BitsInteger(2),  # bits 3..2: 4 - data bytes (expedited)
    "expedited" / Flag,  # bit 1
    "size_indicator" / Flag,  # bit 0
)

# --- ETG.1000.6 5.6.2.3/5.6.2.5: segment command byte ---------------------------
SdoSegmentCommand = BitStruct(
    "command" / BitsInteger(3),  # Ccs / Scs
    "toggle" / Flag,  # bit 4
    "seg_size" / BitsInteger(3),  # bits 3..1: 7 - data bytes when fewer than 7
    "last" / Flag,  # bit 0: 1 = no more segments follow
)

#: expedited download request/response, upload request, download response (10 bytes)
SdoExpedited = Struct(
    "cmd" / SdoInitiateCommand,
    "index" / Int16ul,
    "subindex" / Int8ul,
    "data" / Bytes(4),
)

#: normal (non-expedited) initiate download request / upload response
SdoNormal = Struct(
    "cmd" / SdoInitiateCommand,
    "index" / Int16ul,
    "subindex" / Int8ul,
    "complete_size" / Int32ul,
    "data" / GreedyBytes,
)

#: download/upload segment request and response
SdoSegment = Struct("cmd" / SdoSegmentCommand, "data" / GreedyBytes)

#: abort transfer (ETG.1000.6 5.6.2.7): command byte 0x80
SdoAbortFrame = Struct(
    "cmd" / Const(0x80, Int8ul),
    "index" / Int16ul,
    "subindex" / Int8ul,
    "code" / Int32ul,
)


class SdoInfoOpcode(IntEnum):
    """SDO Information service opcodes (ETG.1000.6 5.6.3, Table 43)."""

    GET_OD_LIST_REQUEST = 0x01
    GET_OD_LIST_RESPONSE = 0x02
    GET_OBJECT_DESCRIPTION_REQUEST = 0x03
    GET_OBJECT_DESCRIPTION_RESPONSE = 0x04
    GET_ENTRY_DESCRIPTION_REQUEST = 0x05
    GET_ENTRY_DESCRIPTION_RESPONSE = 0x06
    SDO_INFO_ERROR_REQUEST = 0x07


class OdListType(IntEnum):
    """Get OD List request ``ListType`` (ETG.1000.6 5.6.3.3.1)."""

    LENGTHS = 0x00  # the number of objects in each of the lists 1..5
    ALL = 0x01
    RXPDO_MAPPABLE = 0x02
    TXPDO_MAPPABLE = 0x03
    DEVICE_REPLACEMENT = 0x04  # stored for device replacement (backup)
    STARTUP = 0x05  # startup parameters (settings)


class ValueInfo(IntFlag):
    """Get Entry Description ``ValueInfo``: which optional parts follow (ETG.1000.6 5.6.3.5)."""

    UNIT_TYPE = 0x08
    DEFAULT_VALUE = 0x10
    MINIMUM_VALUE = 0x20
    MAXIMUM_VALUE = 0x40


# --- ETG.1000.6 5.6.3.2 (SDO Information header), after the CoE header ----------------
SdoInfoHeader = Struct(
    "op"
    / BitStruct(
        "incomplete" / Flag,  # bit 7: more fragments follow
        "opcode" / BitsInteger(7),  # SdoInfoOpcode
    ),
    "reserved" / Int8ul,
    "fragments_left" / Int16ul,
)
SDO_INFO_HEADER_SIZE = 4

#: Get Object Description response data (ETG.1000.6 5.6.3.5.2), the name fills the rest
ObjectDescription = Struct(
    "index" / Int16ul,
    "data_type" / Int16ul,
    "max_subindex" / Int8ul,
    "object_code" / Int8ul,
    "name" / GreedyBytes,
)

#: Get Entry Description request data (ETG.1000.6 5.6.3.6.1)
EntryDescriptionRequest = Struct("index" / Int16ul, "subindex" / Int8ul, "value_info" / Int8ul)

#: Get Entry Description response data (ETG.1000.6 5.6.3.6.2): unit/default/min/max as
#: ``value_info`` announces them, then the name, both in ``rest``
EntryDescription = Struct(
    "index" / Int16ul,
    "subindex" / Int8ul,
    "value_info" / Int8ul,
    "data_type" / Int16ul,
    "bit_length" / Int16ul,
    "object_access" / Int16ul,
    "rest" / GreedyBytes,
)

#: SDO Info error request data (ETG.1000.6 5.6.3.7): an SDO abort code
SdoInfoError = Struct("code" / Int32ul)


def build_sdo_info(
    opcode: SdoInfoOpcode, data: bytes, *, counter: int, fragments_left: int = 0
) -> bytes:
    """A whole mailbox message carrying one SDO Information fragment."""
    header = SdoInfoHeader.build(
        {
            "op": {"incomplete": fragments_left > 0, "opcode": int(opcode)},
            "reserved": 0,
            "fragments_left": fragments_left,
        }
    )
    return build_coe(CoeService.SDO_INFORMATION, header + data, counter=counter)


#: bytes of SDO data after the mailbox header, the CoE header and the 8-byte initiate frame
INITIATE_OVERHEAD = MAILBOX_HEADER_SIZE + COE_HEADER_SIZE + 8
#: ... after the headers and the segment command byte
SEGMENT_OVERHEAD = MAILBOX_HEADER_SIZE + COE_HEADER_SIZE + 1


# --- building and parsing helpers -------------------------------------------------
# The fixed headers below are pure functions of a few small numbers (or bytes), built and
# parsed by their construct definitions once per distinct value: a bus bring-up sends the
# same few hundred InitCmd SDOs every time, and construct costs ~100 us per build here.
# Parsed containers are shared: callers only read them.
@functools.lru_cache(maxsize=4096)
def _mailbox_header(length: int, address: int, counter: int, mbx_type: int) -> bytes:
    return MailboxHeader.build(
        {
            "length": length,
            "address": address,
            "bits": {
                "priority": 0,
                "channel": 0,
                "reserved": 0,
                "counter": counter,
                "type": mbx_type,
            },
        }
    )


@functools.lru_cache(maxsize=64)
def _coe_header(service: int) -> bytes:
    return CoeHeader.build({"service": service, "reserved": 0, "number": 0})


@functools.lru_cache(maxsize=4096)
def _parsed_mailbox_header(raw: bytes) -> tuple[int, int, int]:
    hdr = MailboxHeader.parse(raw)
    return hdr.length, hdr.bits.counter, hdr.bits.type


@functools.lru_cache(maxsize=256)
def parse_coe_header(raw: bytes) -> Container:
    """The CoE header (2 bytes) as parsed by CoeHeader; a shared, read-only container."""
    return CoeHeader.parse(raw)


@functools.lru_cache(maxsize=256)
def parse_initiate_command(raw: bytes) -> Container:
    """The SDO command byte as parsed by SdoInitiateCommand; shared, read-only."""
    return SdoInitiateCommand.parse(raw)


@functools.lru_cache(maxsize=4096)
def parse_expedited(raw: bytes) -> Container:
    """An 8..10-byte expedited SDO frame as parsed by SdoExpedited; shared, read-only."""
    return SdoExpedited.parse(raw)


def build_mailbox(
    data: bytes, *, counter: int, mbx_type: MailboxType = MailboxType.COE, address: int = 0
) -> bytes:
    return _mailbox_header(len(data), address, counter & 7, int(mbx_type)) + data


def mailbox_error(detail: MailboxError, *, counter: int = 0) -> bytes:
    """A whole mailbox error reply (type 0, service 0001h, detail; ETG.1000.6 5.4)."""
    data = MailboxErrorReply.build({"detail": int(detail)})
    return build_mailbox(data, counter=counter, mbx_type=MailboxType.ERR)


def build_coe(service: CoeService, sdo: bytes, *, counter: int) -> bytes:
    """A whole mailbox message carrying one CoE service."""
    return build_mailbox(_coe_header(int(service)) + sdo, counter=counter)


def initiate_cmd(
    command: int,
    *,
    complete_access: bool = False,
    expedited: bool = False,
    size: int = 0,
    size_indicator: bool = False,
) -> dict:
    return {
        "command": command,
        "complete_access": complete_access,
        "size": size,
        "expedited": expedited,
        "size_indicator": size_indicator,
    }


def build_initiate(
    command: int, index: int, subindex: int, data: bytes = b"", *, complete_access: bool = False
) -> bytes:
    """An 8-byte initiate frame (ETG.1000.6 5.6.2.1-4): expedited with ``data`` (1-4 bytes)
    and its size indicated, or without data (an upload request, a download answer)."""
    return _build_initiate(command, index, subindex, bytes(data), complete_access)


@functools.lru_cache(maxsize=4096)
def _build_initiate(
    command: int, index: int, subindex: int, data: bytes, complete_access: bool
) -> bytes:
    if data:
        cmd = initiate_cmd(
            command,
            complete_access=complete_access,
            expedited=True,
            size=4 - len(data),
            size_indicator=True,
        )
    else:
        cmd = initiate_cmd(command, complete_access=complete_access)
    return SdoExpedited.build(
        {"cmd": cmd, "index": index, "subindex": subindex, "data": bytes(data).ljust(4, b"\x00")}
    )


def segment_cmd(command: int, *, toggle: bool, seg_size: int = 0, last: bool = False) -> dict:
    return {"command": command, "toggle": toggle, "seg_size": seg_size, "last": last}


def build_abort(index: int, subindex: int, code: int) -> bytes:
    return SdoAbortFrame.build({"index": index, "subindex": subindex, "code": int(code)})


def pad_segment(data: bytes) -> tuple[bytes, int]:
    """Segments carry at least 7 data bytes; returns (padded data, unused byte count)."""
    if len(data) >= 7:
        return data, 0
    return data + bytes(7 - len(data)), 7 - len(data)


@dataclass(frozen=True, slots=True)
class ParsedMailbox:
    counter: int
    mbx_type: int
    data: bytes  # service data after the mailbox header


def parse_mailbox(message: bytes) -> ParsedMailbox:
    """Split a whole mailbox message; raises ValueError when it is cut short."""
    if len(message) < MAILBOX_HEADER_SIZE:
        raise ValueError(f"mailbox message of {len(message)} bytes is shorter than its header")
    length, counter, mbx_type = _parsed_mailbox_header(bytes(message[:MAILBOX_HEADER_SIZE]))
    end = MAILBOX_HEADER_SIZE + length
    if len(message) < end:
        raise ValueError(f"mailbox header says {length} bytes, message has {len(message) - 6}")
    return ParsedMailbox(counter, mbx_type, bytes(message[MAILBOX_HEADER_SIZE:end]))


def next_counter(counter: int) -> int:
    """Mailbox counters run 1..7 and skip 0 (ETG.1000.4 5.5)."""
    return 1 if counter >= 7 else counter + 1


def advance_counter(counter: int, steps: int) -> int:
    """``counter`` after ``steps`` calls of :func:`next_counter` (none: as it is); after the
    first the counter is in 1..7, where it comes round every 7."""
    if steps <= 0:
        return counter
    return (next_counter(counter) + steps - 2) % 7 + 1


# --- client -------------------------------------------------------------------------
#: largest object an upload accepts, bytes; a larger announced size ends in 0x05040005
DEFAULT_MAX_SDO_SIZE = 4 * 1024 * 1024
#: a segment frame carries at least 7 data bytes, padded (ETG.1000.6 5.6.2.3-5.6.2.6:
#: mailbox length >= 0x0A); the segment count cap of an upload is derived from it
MIN_SEGMENT_DATA = 7

_T = TypeVar("_T")


class _SlaveAborted(Exception):
    """The slave sent an abort frame: the transfer is over on both sides, nothing to send."""

    def __init__(self, abort: SdoAbort) -> None:
        super().__init__(str(abort))
        self.abort = abort


class SdoClient:
    """The master side of SDO: upload/download through whole mailbox messages.

    ``transfer`` sends one mailbox message and returns the slave's answer, or
    None when there is none (for a virtual slave it is exactly ``slave.mailbox``).
    Expedited transfer is used up to 4 bytes, normal transfer up to what one
    mailbox holds, segmented transfer beyond (ETG.1000.6 5.6.2).

    Every failure is an :class:`~gtecat.drives.abort.SdoAbort`, whatever the slave sends:

    - an abort frame from the slave raises its code, index and subindex;
    - no answer is 0x05040000 (SDO protocol timed out); a mailbox error reply,
      another mailbox type or CoE service, a cut-short frame or an answer for
      another object is 0x08000000 (general error); an answer with the wrong
      command specifier is 0x05040001; a segment with the wrong toggle bit is
      0x05030000; a finished upload whose length differs from the announced
      one is 0x06070010.

    An upload is bounded, so a slave cannot keep the master busy for ever:

    - the size the initiate response announces must not exceed ``max_size``
      (default :data:`DEFAULT_MAX_SDO_SIZE`, 4 MiB), else 0x05040005 (out of
      memory) before any segment is requested;
    - a transfer that makes no progress ends with 0x05040000: a non-last
      segment without data, a non-last segment that carries the data past the
      announced size, or more segments than ``ceil(remaining / 7) + 1`` (each
      non-last segment carries at least :data:`MIN_SEGMENT_DATA` bytes; one
      more allows an empty last segment).

    So an upload takes at most ``ceil(max_size / 7) + 3`` exchanges and a
    download ``ceil(len(data) / segment room) + 2``.  When the client itself
    ends a transfer it sends an abort request with the code it raises
    (ETG.1000.6 5.6.2.7, CiA 301 "abort SDO transfer"); that request is not
    answered and a failure to send it is only logged.
    """

    def __init__(
        self,
        transfer: Callable[[bytes], bytes | None],
        *,
        mailbox_size: int = DEFAULT_MAILBOX_SIZE,
        max_size: int = DEFAULT_MAX_SDO_SIZE,
    ) -> None:
        if mailbox_size < INITIATE_OVERHEAD + 4:
            raise ValueError(f"mailbox of {mailbox_size} bytes cannot carry an SDO")
        if max_size < 0:
            raise ValueError(f"max_size {max_size} is negative")
        self._transfer = transfer
        self.mailbox_size = mailbox_size
        self.max_size = max_size
        self.counter = 0
        #: requests that got no answer (each ends the transfer with 0x05040000): a real
        #: master waits its mailbox timeout for each (gtecat.master.bus.SDO_TIMEOUT_MS)
        self.unanswered = 0

    # --- services -----------------------------------------------------------
    def upload(self, index: int, subindex: int, complete_access: bool = False) -> bytes:
        """The object's bytes (the whole object with ``complete_access``)."""
        return self._run(self._upload, index, subindex, complete_access)

    def download(
        self, index: int, subindex: int, data: bytes, complete_access: bool = False
    ) -> None:
        """Write ``data`` to the object (the whole object with ``complete_access``)."""
        self._run(self._download, index, subindex, complete_access, bytes(data))

    def _run(self, service: Callable[..., _T], index: int, subindex: int, *args: object) -> _T:
        """Run one service; a client-detected failure also aborts the transfer at the slave."""
        try:
            return service(index, subindex, *args)
        except _SlaveAborted as e:
            raise e.abort from None
        except SdoAbort as e:
            self._send_abort(index, subindex, e.code)
            raise

    # --- plumbing -----------------------------------------------------------
    def _send_abort(self, index: int, subindex: int, code: int) -> None:
        self.counter = next_counter(self.counter)
        message = build_coe(
            CoeService.SDO_REQUEST, build_abort(index, subindex, code), counter=self.counter
        )
        try:
            self._transfer(message)  # not answered (ETG.1000.6 5.6.2.7)
        except Exception as e:  # the abort being raised matters more than this one
            log.warning("abort request for 0x%04X:%02X not sent: %s", index, subindex, e)

    def _exchange(self, sdo: bytes, index: int, subindex: int) -> bytes:
        """One request, the SDO frame of its answer (at least one byte)."""

        def fail(detail: str) -> SdoAbort:
            return mailbox_failure(MailboxFailure.UNEXPECTED, index, subindex, detail)

        self.counter = next_counter(self.counter)
        answer = self._transfer(build_coe(CoeService.SDO_REQUEST, sdo, counter=self.counter))
        if answer is None:
            self.unanswered += 1
            raise mailbox_failure(MailboxFailure.NO_ANSWER, index, subindex)
        try:
            mbx = parse_mailbox(bytes(answer))
        except ValueError as e:
            raise fail(str(e)) from None
        if mbx.mbx_type == MailboxType.ERR:
            raise mailbox_failure(
                MailboxFailure.ERROR_REPLY, index, subindex, _mailbox_error_text(mbx.data)
            )
        if mbx.mbx_type != MailboxType.COE:
            raise fail(f"answer has mailbox type {mbx.mbx_type}, not CoE")
        if len(mbx.data) < COE_HEADER_SIZE + 1:
            raise fail(f"CoE answer of {len(mbx.data)} bytes carries no SDO frame")
        coe = parse_coe_header(mbx.data[:COE_HEADER_SIZE])
        body = mbx.data[COE_HEADER_SIZE:]
        is_abort = body[0] == 0x80 and coe.service in (
            CoeService.SDO_REQUEST,  # what ETG.1000.6 / SOES / IgH send
            CoeService.SDO_RESPONSE,  # tolerated: some slaves label aborts so
        )
        if is_abort:
            if len(body) < SdoAbortFrame.sizeof():
                raise fail(f"abort frame of {len(body)} bytes, 8 expected")
            ab = SdoAbortFrame.parse(body[: SdoAbortFrame.sizeof()])
            raise _SlaveAborted(SdoAbort(ab.code, ab.index, ab.subindex))
        if coe.service != CoeService.SDO_RESPONSE:
            service = _enum_name(CoeService, coe.service)
            raise fail(f"answer has CoE service {service}, not SDO_RESPONSE")
        return body

    def _expect(self, body: bytes, scs: Scs, index: int, subindex: int) -> None:
        if body[0] >> 5 != scs:
            raise SdoAbort(
                SdoAbortCode.COMMAND_SPECIFIER_INVALID,
                index,
                subindex,
                f"answer 0x{body[0]:02X} is not {scs.name}",
            )

    def _initiate_answer(self, body: bytes, scs: Scs, index: int, subindex: int) -> None:
        """Check an initiate answer: command specifier, length and the object it is for."""
        self._expect(body, scs, index, subindex)
        if len(body) < 8:
            raise mailbox_failure(
                MailboxFailure.UNEXPECTED,
                index,
                subindex,
                f"{scs.name} answer of {len(body)} bytes, 8 expected",
            )
        echo = (int.from_bytes(body[1:3], "little"), body[3])
        if echo != (index, subindex):
            raise mailbox_failure(
                MailboxFailure.UNEXPECTED,
                index,
                subindex,
                f"{scs.name} answer is for 0x{echo[0]:04X}:{echo[1]:02X}",
            )

    def _upload(self, index: int, subindex: int, complete_access: bool) -> bytes:
        req = build_initiate(Ccs.INITIATE_UPLOAD, index, subindex, complete_access=complete_access)
        body = self._exchange(req, index, subindex)
        self._initiate_answer(body, Scs.INITIATE_UPLOAD, index, subindex)
        cmd = SdoInitiateCommand.parse(body[:1])
        if cmd.expedited:
            n = 4 - cmd.size if cmd.size_indicator else 4
            return bytes(body[4 : 4 + n])
        resp = SdoNormal.parse(body)
        total = resp.complete_size
        if total > self.max_size:
            raise mailbox_failure(
                MailboxFailure.TOO_BIG,
                index,
                subindex,
                f"{total} bytes announced, at most {self.max_size} accepted",
            )
        data = bytearray(resp.data[:total])
        if len(data) == total:
            return bytes(data)
        max_segments = -(-(total - len(data)) // MIN_SEGMENT_DATA) + 1
        toggle = False
        for n_seg in range(1, max_segments + 1):
            seg_req = SdoSegment.build(
                {"cmd": segment_cmd(Ccs.UPLOAD_SEGMENT, toggle=toggle), "data": bytes(7)}
            )
            body = self._exchange(seg_req, index, subindex)
            self._expect(body, Scs.UPLOAD_SEGMENT, index, subindex)
            seg = SdoSegment.parse(body)
            if seg.cmd.toggle != toggle:
                raise SdoAbort(
                    SdoAbortCode.TOGGLE_BIT_NOT_ALTERNATED,
                    index,
                    subindex,
                    f"segment {n_seg} has toggle {int(seg.cmd.toggle)}, {int(toggle)} expected",
                )
            chunk = seg.data
            if seg.cmd.last and len(chunk) == 7:
                chunk = chunk[: 7 - seg.cmd.seg_size]
            if seg.cmd.last:
                data += chunk
                if len(data) != total:
                    raise SdoAbort(
                        SdoAbortCode.LENGTH_MISMATCH,
                        index,
                        subindex,
                        f"{len(data)} bytes received, {total} announced",
                    )
                return bytes(data)
            if not chunk:
                raise SdoAbort(
                    SdoAbortCode.SDO_PROTOCOL_TIMED_OUT,
                    index,
                    subindex,
                    f"segment {n_seg} is empty and not the last: no progress",
                )
            if len(data) + len(chunk) > total:
                raise SdoAbort(
                    SdoAbortCode.SDO_PROTOCOL_TIMED_OUT,
                    index,
                    subindex,
                    f"segment {n_seg} brings {len(data) + len(chunk)} bytes"
                    f" and is not the last, {total} announced",
                )
            data += chunk
            toggle = not toggle
        raise SdoAbort(
            SdoAbortCode.SDO_PROTOCOL_TIMED_OUT,
            index,
            subindex,
            f"no last segment after {max_segments} segments ({len(data)} of {total} bytes)",
        )

    def _download(self, index: int, subindex: int, complete_access: bool, data: bytes) -> None:
        if 0 < len(data) <= 4:
            req = build_initiate(
                Ccs.INITIATE_DOWNLOAD, index, subindex, data, complete_access=complete_access
            )
            body = self._exchange(req, index, subindex)
            self._initiate_answer(body, Scs.INITIATE_DOWNLOAD, index, subindex)
            return
        first_max = self.mailbox_size - INITIATE_OVERHEAD
        first, rest = data[:first_max], data[first_max:]
        req = SdoNormal.build(
            {
                "cmd": initiate_cmd(
                    Ccs.INITIATE_DOWNLOAD, complete_access=complete_access, size_indicator=True
                ),
                "index": index,
                "subindex": subindex,
                "complete_size": len(data),
                "data": first,
            }
        )
        body = self._exchange(req, index, subindex)
        self._initiate_answer(body, Scs.INITIATE_DOWNLOAD, index, subindex)
        seg_max = self.mailbox_size - SEGMENT_OVERHEAD
        toggle = False
        n_seg = 0
        while rest:  # bounded by our own data: one segment per seg_max bytes
            n_seg += 1
            chunk, rest = rest[:seg_max], rest[seg_max:]
            padded, unused = pad_segment(chunk)
            seg = SdoSegment.build(
                {
                    "cmd": segment_cmd(
                        Ccs.DOWNLOAD_SEGMENT, toggle=toggle, seg_size=unused, last=not rest
                    ),
                    "data": padded,
                }
            )
            body = self._exchange(seg, index, subindex)
            self._expect(body, Scs.DOWNLOAD_SEGMENT, index, subindex)
            if bool(body[0] & 0x10) != toggle:
                raise SdoAbort(
                    SdoAbortCode.TOGGLE_BIT_NOT_ALTERNATED,
                    index,
                    subindex,
                    f"answer to segment {n_seg} has toggle {int(not toggle)}, {int(toggle)} sent",
                )
            toggle = not toggle


def _enum_name(enum: type[IntEnum], value: int, digits: int = 0) -> str:
    """The member's name, or the number (in hex with ``digits``) when there is none."""
    try:
        return enum(value).name
    except ValueError:
        return f"0x{value:0{digits}X}" if digits else str(value)


def _mailbox_error_text(data: bytes) -> str:
    """What a mailbox error reply (ETG.1000.4 Table 30) says, however malformed."""
    if len(data) < MailboxErrorReply.sizeof():
        return f"mailbox error reply of {len(data)} bytes"
    try:
        reply = MailboxErrorReply.parse(data[: MailboxErrorReply.sizeof()])
    except ConstructError:
        service = int.from_bytes(data[:2], "little")
        return f"mailbox error reply with service 0x{service:04X}, not 0x0001"
    return f"mailbox error {_enum_name(MailboxError, reply.detail, 4)}"
