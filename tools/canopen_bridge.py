"""An SDO-only CANopen bridge: a python-can bus in front of one virtual EtherCAT slave's CoE.

CoE carries CANopen's SDO protocol (ETG.1000.6 5.6.2): an expedited request or
response, or an initiate/abort frame, is the same 8 bytes on CAN (CiA 301 7.2.4.3)
as after the mailbox and CoE headers of a mailbox message.  So the bridge wraps each
8-byte CAN SDO request received on COB-ID 0x600 + node id into a whole mailbox
message (``gtecat.drives.coe.build_coe``), hands it to ``slave.mailbox()``, strips the
6-byte mailbox header and 2-byte CoE header from the answer and sends those 8 bytes
on 0x580 + node id.  That lets a CANopen client nobody here wrote (python-canopen's
``BaseNode402``) drive our CiA-402 drive over SDO only.

Where the two differ, the bridge translates:

* CoE answers an upload of more than 4 bytes with a *normal* response that carries
  the data (and segments as long as the mailbox); CAN segments carry 7 bytes.  The
  bridge answers the CAN initiate with the size and serves the CAN segments itself
  from the data it uploaded through CoE.
* A CAN segmented download is collected by the bridge and written in one CoE
  transfer after the last segment.  Block transfer is refused (0x05040001).
* A mailbox error reply becomes an SDO abort 0x08000000.

Time: the slave is stepped ``cycles_per_request`` cycles of ``cycle_ns`` before
each request is handled (and by :meth:`CanSdoBridge.run`), so the drive's state
follows the client's requests in virtual time, deterministically, and a statusword
read after a controlword write sees the drive's reaction.  There is no PDO, NMT,
SYNC or EMCY traffic: CANopen clients fall back to SDO for every object.
"""

from __future__ import annotations

import threading
from collections.abc import Iterable

import can
import canopen
from canopen import objectdictionary as cod

from gtecat.drives.abort import SdoAbort, SdoAbortCode
from gtecat.drives.coe import (
    COE_HEADER_SIZE,
    CoeService,
    MailboxType,
    SdoClient,
    SdoNormal,
    build_abort,
    build_coe,
    next_counter,
    parse_mailbox,
)
from gtecat.drives.od import Access, ObjectCode, ObjectDictionary, Variable
from gtecat.drives.slave import VirtualSlave

SDO_RX = 0x600  # client -> server (CiA 301 predefined connection set)
SDO_TX = 0x580  # server -> client

_ACCESS = {Access.RO: "ro", Access.WO: "wo", Access.RW: "rw", Access.CONST: "const"}


class CanSdoBridge(can.Listener):
    """Serve ``slave``'s object dictionary as CANopen node ``node_id`` on ``bus`` (SDO only).

    Without a bus, :meth:`handle` still answers single frames (scripted tests).
    """

    def __init__(
        self,
        slave: VirtualSlave,
        bus: can.BusABC | None,
        node_id: int,
        *,
        cycle_ns: int = 1_000_000,
        cycles_per_request: int = 5,
    ) -> None:
        if not 1 <= node_id <= 127:
            raise ValueError(f"CANopen node id {node_id} is not 1..127")
        self.slave = slave
        self.bus = bus
        self.node_id = node_id
        self.cycle_ns = int(cycle_ns)
        self.cycles_per_request = int(cycles_per_request)
        self.t_ns = 0
        self.requests = 0
        self._counter = 0
        self._lock = threading.Lock()
        self._coe = SdoClient(self._transfer)
        self._upload: tuple[int, int, bytes, bool] | None = None  # index, sub, rest, toggle
        self._download: tuple[int, int, int, bytearray, bool] | None = None
        self._notifier: can.Notifier | None = None

    # --- lifecycle ----------------------------------------------------------------------
    def start(self) -> CanSdoBridge:
        """Listen on the bus (python-can's notifier thread answers the requests)."""
        if self.bus is None:
            raise ValueError("the bridge has no CAN bus to listen on")
        if self._notifier is None:
            self._notifier = can.Notifier(self.bus, [self], timeout=0.05)
        return self

    def close(self) -> None:
        """Stop listening (``can.Listener.stop`` is the notifier's hook, left as it is)."""
        notifier, self._notifier = self._notifier, None
        if notifier is not None:
            notifier.stop()

    def __enter__(self) -> CanSdoBridge:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()

    def run(self, cycles: int) -> None:
        """Step the slave ``cycles`` cycles of virtual time."""
        with self._lock:
            self._step(cycles)

    def _step(self, cycles: int) -> None:
        for _ in range(cycles):
            self.t_ns += self.cycle_ns
            self.slave.step(self.t_ns, self.cycle_ns)

    # --- CAN side -------------------------------------------------------------------------
    def on_message_received(self, msg: can.Message) -> None:
        if msg.is_extended_id or msg.is_remote_frame or msg.arbitration_id != SDO_RX + self.node_id:
            return
        answer = self.handle(bytes(msg.data))
        if answer is not None and self.bus is not None:
            self.bus.send(
                can.Message(arbitration_id=SDO_TX + self.node_id, data=answer, is_extended_id=False)
            )

    def handle(self, frame: bytes) -> bytes | None:
        """One 8-byte CAN SDO request in, the 8-byte response out (None: no answer)."""
        with self._lock:
            self.requests += 1
            self._step(self.cycles_per_request)
            frame = bytes(frame).ljust(8, b"\x00")[:8]
            index = int.from_bytes(frame[1:3], "little")
            subindex = frame[3]
            try:
                return self._sdo(frame, index, subindex)
            except SdoAbort as e:
                self._upload = self._download = None
                return build_abort(e.index or index, e.subindex or subindex, int(e.code))

    def _sdo(self, frame: bytes, index: int, subindex: int) -> bytes | None:
        ccs = frame[0] >> 5
        if ccs == 4:  # abort from the client: forget the transfer, no answer
            self._upload = self._download = None
            return None
        if ccs == 2:  # initiate upload
            self._upload = self._download = None
            body = self._request(frame, index, subindex)
            if body[0] & 0x02 or len(body) <= 8:  # expedited: the same 8 bytes on CAN
                return body[:8].ljust(8, b"\x00")
            resp = SdoNormal.parse(body)
            data = bytes(resp.data[: resp.complete_size])
            if len(data) < resp.complete_size:  # CoE segmented too: let our client fetch it
                data = self._coe.upload(index, subindex)
            self._upload = (index, subindex, data, False)
            return bytes([0x41]) + frame[1:4] + len(data).to_bytes(4, "little")
        if ccs == 3:  # upload segment
            if self._upload is None:
                raise SdoAbort(SdoAbortCode.COMMAND_SPECIFIER_INVALID, index, subindex)
            u_index, u_sub, rest, toggle = self._upload
            if bool(frame[0] & 0x10) != toggle:
                raise SdoAbort(SdoAbortCode.TOGGLE_BIT_NOT_ALTERNATED, u_index, u_sub)
            chunk, rest = rest[:7], rest[7:]
            last = not rest
            self._upload = None if last else (u_index, u_sub, rest, not toggle)
            cmd = (0x10 if toggle else 0) | ((7 - len(chunk)) << 1) | (1 if last else 0)
            return bytes([cmd]) + chunk.ljust(7, b"\x00")
        if ccs == 1:  # initiate download
            self._upload = self._download = None
            if frame[0] & 0x02:  # expedited: the same 8 bytes through CoE
                return self._request(frame, index, subindex)[:8].ljust(8, b"\x00")
            size = int.from_bytes(frame[4:8], "little") if frame[0] & 0x01 else -1
            self._download = (index, subindex, size, bytearray(), False)
            return bytes([0x60]) + frame[1:4] + bytes(4)
        if ccs == 0:  # download segment
            if self._download is None:
                raise SdoAbort(SdoAbortCode.COMMAND_SPECIFIER_INVALID, index, subindex)
            d_index, d_sub, size, data, toggle = self._download
            if bool(frame[0] & 0x10) != toggle:
                raise SdoAbort(SdoAbortCode.TOGGLE_BIT_NOT_ALTERNATED, d_index, d_sub)
            data += frame[1 : 8 - ((frame[0] >> 1) & 0x07)]
            ack = bytes([0x20 | (0x10 if toggle else 0)]) + bytes(7)
            if not frame[0] & 0x01:
                self._download = (d_index, d_sub, size, data, not toggle)
                return ack
            self._download = None
            if size >= 0 and len(data) != size:
                raise SdoAbort(SdoAbortCode.LENGTH_MISMATCH, d_index, d_sub)
            self._coe.download(d_index, d_sub, bytes(data))
            return ack
        raise SdoAbort(SdoAbortCode.COMMAND_SPECIFIER_INVALID, index, subindex, f"ccs {ccs}")

    # --- CoE side -------------------------------------------------------------------------
    def _request(self, frame: bytes, index: int, subindex: int) -> bytes:
        """The 8-byte frame as one CoE SDO request; the SDO part of the answer."""
        self._counter = next_counter(self._counter)
        answer = self.slave.mailbox(build_coe(CoeService.SDO_REQUEST, frame, counter=self._counter))
        if answer is None:
            raise SdoAbort(SdoAbortCode.SDO_PROTOCOL_TIMED_OUT, index, subindex, "no answer")
        mbx = parse_mailbox(answer)
        if mbx.mbx_type != MailboxType.COE or len(mbx.data) < COE_HEADER_SIZE + 8:
            raise SdoAbort(SdoAbortCode.GENERAL_ERROR, index, subindex, "mailbox error reply")
        return bytes(mbx.data[COE_HEADER_SIZE:])

    def _transfer(self, message: bytes) -> bytes | None:
        return self.slave.mailbox(message)


def canopen_dictionary(
    od: ObjectDictionary, indices: Iterable[int] | None = None
) -> canopen.ObjectDictionary:
    """python-canopen's description of our object dictionary (CiA 301 data type codes agree)."""
    out = canopen.ObjectDictionary()
    wanted = None if indices is None else set(indices)
    for obj in od:
        if wanted is not None and obj.index not in wanted:
            continue
        if obj.code is ObjectCode.VAR:
            out.add_object(_variable(obj.name, obj.index, obj.subs[0]))
            continue
        rec = cod.ODRecord(obj.name, obj.index)
        for sub in sorted(obj.subs):
            rec.add_member(_variable(obj.subs[sub].name, obj.index, obj.subs[sub]))
        out.add_object(rec)
    return out


def _variable(name: str, index: int, var: Variable) -> cod.ODVariable:
    v = cod.ODVariable(name, index, var.subindex)
    v.data_type = int(var.data_type)
    v.access_type = _ACCESS[var.access]
    return v
