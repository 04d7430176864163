"""The slave side of CoE SDO: one mailbox request in, one mailbox response out.

Follows ETG.1000.6 5.6.2: expedited, normal and segmented upload/download and
complete access, against an :class:`~gtecat.drives.od.ObjectDictionary`.  Every
:class:`~gtecat.drives.abort.SdoAbort` becomes an abort frame with its code; any other
exception becomes 0x08000000 (general error) and a log line, so a bug in a
hook never reaches the master as a traceback (python-canopen's
``SdoServer.on_request`` does the same).

CoE service 8, SDO Information (ETG.1000.6 5.6.3), lists and describes the
dictionary (:mod:`gtecat.drives.sdo_info`); an answer longer than one mailbox leaves
here as several messages: :meth:`SdoServer.handle` returns the first and
:meth:`SdoServer.next_message` the others, one per call, as the ESC frees its
send mailbox.  A new request drops fragments not yet fetched.

Mailbox problems that are not SDO problems (cut-short message, another
mailbox protocol, another CoE service) get a mailbox error reply
(ETG.1000.4 Table 30).  Requests are not de-duplicated by their counter: the
SM "repeat" handshake is the wire-level ESC's business, and de-duplication
would answer a fresh client with a stale response.
"""

from __future__ import annotations

import logging
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

from gtecat.drives.abort import SdoAbort, SdoAbortCode
from gtecat.drives.coe import (
    COE_HEADER_SIZE,
    DEFAULT_MAILBOX_SIZE,
    INITIATE_OVERHEAD,
    SEGMENT_OVERHEAD,
    Ccs,
    CoeService,
    MailboxError,
    MailboxType,
    Scs,
    SdoNormal,
    SdoSegment,
    advance_counter,
    build_abort,
    build_coe,
    build_initiate,
    build_sdo_info,
    initiate_cmd,
    mailbox_error,
    next_counter,
    pad_segment,
    parse_coe_header,
    parse_expedited,
    parse_initiate_command,
    parse_mailbox,
    segment_cmd,
)
from gtecat.drives.od import ObjectDictionary
from gtecat.drives.sdo_info import SdoInformation, fragments
from gtecat.drives.slave import AlState

log = logging.getLogger(__name__)
_T = TypeVar("_T")


def _answered_abort(err: Exception, index: int, subindex: int) -> SdoAbort:
    """What the client reads from the answer to a request served in process that raised
    ``err`` (called where it is caught): an abort's code and address, anything else a
    general error, logged (a bug in a hook)."""
    if isinstance(err, SdoAbort):
        return SdoAbort(err.code, err.index, err.subindex)
    log.exception("SDO request 0x%04X:%02X failed inside the slave", index, subindex)
    return SdoAbort(SdoAbortCode.GENERAL_ERROR, index, subindex)


@dataclass(slots=True)
class _Upload:
    index: int
    subindex: int
    remaining: bytes
    toggle: bool = False


@dataclass(slots=True)
class _Download:
    index: int
    subindex: int
    complete_access: bool
    size: int
    buffer: bytearray
    toggle: bool = False


class SdoServer:
    """Serve SDO requests of one slave from its object dictionary."""

    def __init__(self, od: ObjectDictionary, *, mailbox_size: int = DEFAULT_MAILBOX_SIZE) -> None:
        self.od = od
        self.mailbox_size = mailbox_size
        self.counter = 0
        self._upload: _Upload | None = None
        self._download: _Download | None = None
        self.info = SdoInformation(od)
        self._pending: deque[bytes] = deque()

    # --- entry point ------------------------------------------------------------
    def handle(self, message: bytes, al_state: AlState = AlState.PREOP) -> bytes | None:
        """Answer one whole mailbox message (None: nothing to answer)."""
        try:
            mbx = parse_mailbox(message)
        except ValueError:
            return self._mailbox_error(MailboxError.SIZE_TOO_SHORT)
        if mbx.mbx_type != MailboxType.COE:
            return self._mailbox_error(MailboxError.UNSUPPORTED_PROTOCOL)
        if len(mbx.data) < COE_HEADER_SIZE + 1:
            return self._mailbox_error(MailboxError.SIZE_TOO_SHORT)
        coe = parse_coe_header(bytes(mbx.data[:COE_HEADER_SIZE]))
        self._pending.clear()
        if coe.service == CoeService.SDO_INFORMATION:
            return self._information(mbx.data[COE_HEADER_SIZE:])
        if coe.service != CoeService.SDO_REQUEST:
            return self._mailbox_error(MailboxError.SERVICE_NOT_SUPPORTED)
        body = mbx.data[COE_HEADER_SIZE:]
        index, subindex = _address(body)
        try:
            answer = self._sdo(body, al_state)
        except SdoAbort as err:
            self._upload = self._download = None
            answer = build_abort(err.index, err.subindex, err.code)
        except Exception:
            log.exception("SDO request 0x%04X:%02X failed inside the slave", index, subindex)
            self._upload = self._download = None
            answer = build_abort(index, subindex, SdoAbortCode.GENERAL_ERROR)
        if answer is None:
            return None
        return self._respond(answer)

    def download_in_process(
        self, index: int, subindex: int, data: bytes, complete_access: bool, al_state: AlState
    ) -> None:
        """An expedited download (1 to 4 bytes) exactly as :meth:`handle` serves its frame,
        for a client in the same process with nothing between the two (no capture of the
        frames, no fault in front of the mailbox): the same object dictionary write, the
        same counter, and the abort the client reads from the answer (its code, index and
        subindex) raised.  A bus brought up runs 17 of these per drive."""
        self._in_process(
            index, subindex, self.od.download, index, subindex, data, complete_access, al_state
        )

    def download_values_in_process(
        self, items: Sequence[tuple[int, int, int, int]], al_state: AlState
    ) -> tuple[int, SdoAbort | None]:
        """Expedited downloads ``(index, subindex, value, size)`` in order, each as
        :meth:`download_in_process` serves the value's ``size`` little-endian bytes (two's
        complement when negative), the value given to the dictionary as it is where the entry
        takes it so (:meth:`ObjectDictionary.download_value`): the same writes, counter and
        aborts.  How many it served, the one refused among them, and that one's abort (not
        raised: the client counts its side first); it stops before the first request that
        is not one expedited download (an index or subindex out of its field, not 1 to 4
        bytes), which the caller sends otherwise.  A drive homing's set-up is five of these."""
        write = self.od.download_value
        served = 0
        abort: SdoAbort | None = None
        for index, subindex, value, size in items:
            if index >> 16 or subindex >> 8 or not 0 < size <= 4:
                break  # (a negative number shifts to -1)
            if not served:
                self._pending.clear()
                self._upload = self._download = None
            served += 1
            try:
                write(index, subindex, value, size, al_state)
            except Exception as err:
                abort = _answered_abort(err, index, subindex)
                break
        if served:
            self.counter = advance_counter(self.counter, served)
        return served, abort

    def upload_in_process(self, index: int, subindex: int) -> bytes:
        """An expedited upload (an object of 1 to 4 bytes) as :meth:`download_in_process`
        serves a download: the same object dictionary read, counter and abort as the framed
        request.  A controller that reads an unmapped object every cycle (a touch probe's
        60B9h, a mode's 6061h) pays an object read, not two mailbox frames built and parsed.
        The caller checks the size (:meth:`ObjectDictionary.size_of`) first: a longer
        object is a segmented transfer, with more counters, and takes the framed path."""
        return self._in_process(index, subindex, self.od.upload, index, subindex)

    def _in_process(self, index: int, subindex: int, serve: Callable[..., _T], *args: Any) -> _T:
        """``serve(*args)`` as one expedited request served and answered: its result, or the
        abort the answer would carry (raised after the answer's counter).  (The arguments
        passed on, not a function made per request: a drive homing's set-up downloads five.)"""
        self._pending.clear()
        self._upload = self._download = None
        try:
            result = serve(*args)
        except Exception as err:
            abort = _answered_abort(err, index, subindex)
        else:
            self.counter = next_counter(self.counter)
            return result
        self.counter = next_counter(self.counter)
        raise abort

    def next_message(self) -> bytes | None:
        """The next fragment of a multi-message answer, or None when there is none."""
        return self._pending.popleft() if self._pending else None

    # --- SDO Information ---------------------------------------------------------
    def _information(self, body: bytes) -> bytes:
        opcode, payloads = self.info.handle(body)
        parts = [frag for payload in payloads for frag in fragments(payload, self.mailbox_size)]
        messages = []
        for k, part in enumerate(parts):
            self.counter = next_counter(self.counter)
            left = len(parts) - 1 - k
            messages.append(build_sdo_info(opcode, part, counter=self.counter, fragments_left=left))
        self._pending.extend(messages[1:])
        return messages[0]

    # --- framing ---------------------------------------------------------------
    def _respond(self, sdo: bytes) -> bytes:
        """Frame an SDO answer.  An abort travels as CoE service 2 "SDO request"
        (ETG.1000.6 Table 40; SOEM and IgH recognise an abort only that way)."""
        self.counter = next_counter(self.counter)
        service = CoeService.SDO_REQUEST if sdo[:1] == b"\x80" else CoeService.SDO_RESPONSE
        return build_coe(service, sdo, counter=self.counter)

    def _mailbox_error(self, detail: MailboxError) -> bytes:
        self.counter = next_counter(self.counter)
        return mailbox_error(detail, counter=self.counter)

    # --- SDO ---------------------------------------------------------------------
    def _sdo(self, body: bytes, al_state: AlState) -> bytes | None:
        ccs = body[0] >> 5
        if ccs == Ccs.ABORT:
            self._upload = self._download = None
            return None  # an abort from the client is not answered
        if ccs == Ccs.INITIATE_UPLOAD:
            return self._initiate_upload(body)
        if ccs == Ccs.UPLOAD_SEGMENT:
            return self._upload_segment(body)
        if ccs == Ccs.INITIATE_DOWNLOAD:
            return self._initiate_download(body, al_state)
        if ccs == Ccs.DOWNLOAD_SEGMENT:
            return self._download_segment(body, al_state)
        index, subindex = _address(body)
        raise SdoAbort(
            SdoAbortCode.COMMAND_SPECIFIER_INVALID, index, subindex, f"command specifier {ccs}"
        )

    def _initiate_upload(self, body: bytes) -> bytes:
        self._upload = self._download = None
        if len(body) < 4:
            raise SdoAbort(SdoAbortCode.GENERAL_ERROR, 0, 0, "short upload request")
        req = parse_expedited(bytes(body.ljust(10, b"\x00")))
        index, subindex, ca = req.index, req.subindex, req.cmd.complete_access
        data = self.od.upload(index, subindex, complete_access=ca)
        if len(data) <= 4 and data:
            return build_initiate(Scs.INITIATE_UPLOAD, index, subindex, data, complete_access=ca)
        first_max = self.mailbox_size - INITIATE_OVERHEAD
        first, rest = data[:first_max], data[first_max:]
        if rest:
            self._upload = _Upload(index, subindex, rest)
        return SdoNormal.build(
            {
                "cmd": initiate_cmd(Scs.INITIATE_UPLOAD, complete_access=ca, size_indicator=True),
                "index": index,
                "subindex": subindex,
                "complete_size": len(data),
                "data": first,
            }
        )

    def _upload_segment(self, body: bytes) -> bytes:
        state = self._upload
        if state is None:
            raise SdoAbort(
                SdoAbortCode.COMMAND_SPECIFIER_INVALID,
                0,
                0,
                "upload segment without an upload in progress",
            )
        toggle = bool(body[0] & 0x10)
        if toggle != state.toggle:
            raise SdoAbort(SdoAbortCode.TOGGLE_BIT_NOT_ALTERNATED, state.index, state.subindex)
        seg_max = self.mailbox_size - SEGMENT_OVERHEAD
        chunk, state.remaining = state.remaining[:seg_max], state.remaining[seg_max:]
        last = not state.remaining
        padded, unused = pad_segment(chunk) if last else (chunk, 0)
        if last:
            self._upload = None
        else:
            state.toggle = not state.toggle
        return SdoSegment.build(
            {
                "cmd": segment_cmd(Scs.UPLOAD_SEGMENT, toggle=toggle, seg_size=unused, last=last),
                "data": padded,
            }
        )

    def _initiate_download(self, body: bytes, al_state: AlState) -> bytes:
        self._upload = self._download = None
        if len(body) < 4:
            raise SdoAbort(SdoAbortCode.GENERAL_ERROR, 0, 0, "short download request")
        cmd = parse_initiate_command(bytes(body[:1]))
        index, subindex = _address(body)
        ca = cmd.complete_access
        if cmd.expedited:
            raw = bytes(body[4:8]).ljust(4, b"\x00")
            if cmd.size_indicator:
                data = raw[: 4 - cmd.size]
            else:  # size not indicated: the object's own size (CiA 301 7.2.4.3.3)
                size = self.od.size_of(index, subindex)
                data = raw if size is None else raw[:size]
            self.od.download(index, subindex, data, complete_access=ca, al_state=al_state)
        else:
            if len(body) < 8:
                raise SdoAbort(SdoAbortCode.GENERAL_ERROR, index, subindex, "short request")
            req = SdoNormal.parse(body)
            total = req.complete_size
            if total > len(req.data):
                self._download = _Download(index, subindex, ca, total, bytearray(req.data))
            else:
                self.od.download(
                    index, subindex, req.data[:total], complete_access=ca, al_state=al_state
                )
        return build_initiate(Scs.INITIATE_DOWNLOAD, index, subindex, complete_access=ca)

    def _download_segment(self, body: bytes, al_state: AlState) -> bytes:
        state = self._download
        if state is None:
            raise SdoAbort(
                SdoAbortCode.COMMAND_SPECIFIER_INVALID,
                0,
                0,
                "download segment without a download in progress",
            )
        seg = SdoSegment.parse(body)
        if seg.cmd.toggle != state.toggle:
            raise SdoAbort(SdoAbortCode.TOGGLE_BIT_NOT_ALTERNATED, state.index, state.subindex)
        chunk = seg.data
        if seg.cmd.last and len(chunk) == 7:
            chunk = chunk[: 7 - seg.cmd.seg_size]
        state.buffer += chunk
        if len(state.buffer) > state.size:
            raise SdoAbort(
                SdoAbortCode.LENGTH_TOO_HIGH,
                state.index,
                state.subindex,
                f"{len(state.buffer)} bytes sent, {state.size} announced",
            )
        if seg.cmd.last:
            self._download = None
            if len(state.buffer) != state.size:
                raise SdoAbort(
                    SdoAbortCode.LENGTH_TOO_LOW,
                    state.index,
                    state.subindex,
                    f"{len(state.buffer)} bytes sent, {state.size} announced",
                )
            self.od.download(
                state.index,
                state.subindex,
                bytes(state.buffer),
                complete_access=state.complete_access,
                al_state=al_state,
            )
        else:
            state.toggle = not state.toggle
        return SdoSegment.build(
            {"cmd": segment_cmd(Scs.DOWNLOAD_SEGMENT, toggle=seg.cmd.toggle), "data": bytes(7)}
        )


def _address(body: bytes) -> tuple[int, int]:
    """Index and subindex of an initiate frame (0, 0 when too short to hold them)."""
    if len(body) < 4:
        return 0, 0
    return int.from_bytes(body[1:3], "little"), body[3]
