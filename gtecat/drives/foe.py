"""File access over EtherCAT (FoE, ETG.1000.6 5.8): the slave side, small and honest.

Masters probe FoE on their firmware-update paths (SOEM's ``ecx_FOEread`` /
``ecx_FOEwrite``, TwinCAT's "Firmware update", KickCAT's FoE client).  A
virtual slave has no firmware to replace, so it answers as a real device that
refuses does, with a well-formed FoE dialogue rather than "unsupported
mailbox protocol":

* Read request (opcode 1) of a file the slave offers (:attr:`FoeServer.files`,
  e.g. a small log or parameter file): Data packets (opcode 3) numbered from 1,
  each as large as the mailbox allows; the master acknowledges each (opcode 4)
  and the next follows; a packet shorter than the maximum is the last (an empty
  one follows a file that fills its last packet exactly).
* Read request of another name: Error 8001h "not found".
* Write request (opcode 2): Error 8002h "access denied" (no firmware update).
* A wrong password: Error 800Ah "no rights"; an Ack out of sequence: Error 8004h
  "illegal".

Message layout (ETG.1000.6 Table 92-97): ``OpCode u8, reserved u8`` then
``Password u32, FileName`` (requests), ``PacketNo u32, Data`` (data),
``PacketNo u32`` (ack), ``ErrorCode u32, ErrorText`` (error).
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field
from enum import IntEnum

from gtecat.drives.coe import MAILBOX_HEADER_SIZE, MailboxType, build_mailbox, next_counter

FOE_HEADER_SIZE = 6  # opcode, reserved, u32


class FoeOpcode(IntEnum):
    READ = 1
    WRITE = 2
    DATA = 3
    ACK = 4
    ERROR = 5
    BUSY = 6


class FoeError(IntEnum):
    """FoE error codes (ETG.1000.6 Table 98)."""

    NOT_DEFINED = 0x8000
    NOT_FOUND = 0x8001
    ACCESS_DENIED = 0x8002
    DISK_FULL = 0x8003
    ILLEGAL = 0x8004
    PACKET_NUMBER_WRONG = 0x8005
    ALREADY_EXISTS = 0x8006
    NO_USER = 0x8007
    BOOTSTRAP_ONLY = 0x8008
    NOT_BOOTSTRAP = 0x8009
    NO_RIGHTS = 0x800A
    PROGRAM_ERROR = 0x800B


_REQ = struct.Struct("<BBI")


@dataclass
class _Read:
    data: bytes
    packet: int = 0  # the last packet sent
    offset: int = 0


@dataclass
class FoeServer:
    """The files one slave offers for reading, and the read in progress."""

    mailbox_size: int = 128
    files: dict[str, bytes] = field(default_factory=dict)
    password: int = 0
    counter: int = 0
    _read: _Read | None = None

    def handle(self, message: bytes) -> bytes | None:
        """One whole FoE mailbox message in; the answer, or None (a final Ack)."""
        body = message[MAILBOX_HEADER_SIZE:]
        if len(body) < FOE_HEADER_SIZE:
            return self._error(FoeError.ILLEGAL, "short FoE message")
        opcode, _reserved, value = _REQ.unpack_from(body)
        rest = bytes(body[FOE_HEADER_SIZE:])
        if opcode == FoeOpcode.READ:
            self._read = None
            name = rest.split(b"\0", 1)[0].decode("latin-1")
            if name not in self.files:
                return self._error(FoeError.NOT_FOUND, f"no file {name!r}")
            if self.password and value != self.password:
                return self._error(FoeError.NO_RIGHTS, "wrong password")
            self._read = _Read(self.files[name])
            return self._next_data()
        if opcode == FoeOpcode.ACK:
            read = self._read
            if read is None or value != read.packet:
                self._read = None
                return self._error(FoeError.ILLEGAL, f"ack of packet {value} out of sequence")
            if read.offset >= len(read.data) and read.packet and self._last_was_short:
                self._read = None
                return None  # the last packet is acknowledged: the read is done
            return self._next_data()
        if opcode == FoeOpcode.WRITE:
            self._read = None
            return self._error(FoeError.ACCESS_DENIED, "the virtual slave takes no firmware")
        if opcode == FoeOpcode.ERROR:
            self._read = None
            return None  # the master gave up: nothing to answer
        self._read = None
        return self._error(FoeError.ILLEGAL, f"opcode {opcode}")

    _last_was_short = False

    def _room(self) -> int:
        return self.mailbox_size - MAILBOX_HEADER_SIZE - FOE_HEADER_SIZE

    def _next_data(self) -> bytes:
        read = self._read
        assert read is not None
        room = self._room()
        chunk = read.data[read.offset : read.offset + room]
        read.offset += len(chunk)
        read.packet += 1
        self._last_was_short = len(chunk) < room
        return self._frame(_REQ.pack(FoeOpcode.DATA, 0, read.packet) + chunk)

    def _error(self, code: FoeError, text: str) -> bytes:
        # the text is cut to the mailbox (a long file name echoed in it overflowed SM1)
        data = text.encode("latin-1", "replace")[: self._room()]
        return self._frame(_REQ.pack(FoeOpcode.ERROR, 0, int(code)) + data)

    def _frame(self, body: bytes) -> bytes:
        self.counter = next_counter(self.counter)
        return build_mailbox(body, counter=self.counter, mbx_type=MailboxType.FOE)
