"""Classic pcap files of EtherCAT frames (what Wireshark/tshark read, linktype Ethernet).

The format is the libpcap one (https://www.tcpdump.org/manpages/pcap-savefile.5.html):
a 24-byte global header - magic ``A1B23C4D`` (nanosecond timestamps), version
2.4, snap length, link type 1 (Ethernet) - then one 16-byte record header per
packet (seconds, nanoseconds, captured length, original length) followed by
the frame.  All fields in the writer's byte order, which the magic tells.

:class:`PcapWriter` is used by ``gtecat serve --pcap`` (every frame received
and every answer sent) and by the emulated backend (the frames a real master
would have exchanged).  Writes are buffered; :meth:`PcapWriter.close` flushes.
"""

from __future__ import annotations

import struct
import time
from collections.abc import Sequence
from pathlib import Path
from typing import BinaryIO

from gtecat.eni.cyclic import MAX_DATAGRAM_DATA

#: nanosecond-resolution pcap magic (the microsecond one is A1B2C3D4)
MAGIC_NS = 0xA1B23C4D
LINKTYPE_ETHERNET = 1
SNAPLEN = 65535

_GLOBAL = struct.Struct("<IHHiIII")
_RECORD = struct.Struct("<IIII")


class PcapWriter:
    """Append Ethernet frames with their wall-clock time to a pcap file."""

    def __init__(self, path: str | Path, *, buffering: int = 1 << 16, append: bool = False) -> None:
        """``append``: add to a capture this writer's format started (no second header)."""
        self.path = Path(path)
        resume = append and self.path.is_file() and self.path.stat().st_size >= _GLOBAL.size
        self._fh: BinaryIO | None = open(self.path, "ab" if resume else "wb", buffering=buffering)
        if not resume:
            self._fh.write(_GLOBAL.pack(MAGIC_NS, 2, 4, 0, 0, SNAPLEN, LINKTYPE_ETHERNET))
        self.frames = 0
        self._last_ns = 0

    def write(self, frame: bytes | bytearray | memoryview, t_ns: int | None = None) -> None:
        """One frame; ``t_ns`` is wall-clock (CLOCK_REALTIME) nanoseconds, default now."""
        fh = self._fh
        if fh is None:
            raise ValueError(f"pcap file {self.path} is closed")
        if t_ns is None:
            t_ns = time.time_ns()
        # records in the order written, with times that never go back: a request that
        # waited in the socket while the previous answer went out carries its kernel time,
        # which is before that answer's; it is stamped with the answer's time instead, as
        # readers (and tools that merge or slice captures) expect non-decreasing times
        t_ns = self._last_ns = max(t_ns, self._last_ns)
        n = len(frame)
        cap = min(n, SNAPLEN)
        fh.write(_RECORD.pack(t_ns // 1_000_000_000, t_ns % 1_000_000_000, cap, n))
        fh.write(frame[:cap])
        self.frames += 1

    def flush(self) -> None:
        if self._fh is not None:
            self._fh.flush()

    def close(self) -> None:
        if self._fh is not None:
            self._fh.close()
            self._fh = None

    def __enter__(self) -> PcapWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def read_pcap(path: str | Path) -> list[tuple[int, bytes]]:
    """(timestamp ns, frame) of every record (for tests and tools; both magics)."""
    data = Path(path).read_bytes()
    if len(data) < _GLOBAL.size:
        raise ValueError(f"{path}: too short for a pcap header")
    magic = struct.unpack_from("<I", data)[0]
    if magic in (MAGIC_NS, 0xA1B2C3D4):
        order = "<"
    elif struct.unpack_from(">I", data)[0] in (MAGIC_NS, 0xA1B2C3D4):
        order, magic = ">", struct.unpack_from(">I", data)[0]
    else:
        raise ValueError(f"{path}: not a pcap file (magic 0x{magic:08X})")
    scale = 1 if magic == MAGIC_NS else 1000
    record = struct.Struct(order + "IIII")
    out = []
    pos = _GLOBAL.size
    while pos + record.size <= len(data):
        sec, frac, cap, _orig = record.unpack_from(data, pos)
        pos += record.size
        out.append((sec * 1_000_000_000 + frac * scale, data[pos : pos + cap]))
        pos += cap
    return out


class BusCapture:
    """The frames a real master would exchange with the emulated bus, into a pcap.

    The in-process backend exchanges no frames; for a capture it describes each
    of its operations as the frames SOEM would send for it and the answers a
    chain of ESCs would return (ETG.1000.4 datagrams, built by
    :func:`gtecat.drives.esc.frames.encode_frame`):

    * a scan: ``BRD 0000h`` answered with the slave count as WKC;
    * a state request: ``FPWR 0120h`` (AL control) then ``FPRD 0130h`` (AL status,
      code);
    * a cycle: one ``LRW`` over the logical image (outputs, then inputs: SOEM's
      non-overlapped map at logical address 0), answered with the inputs and the WKC; an
      image larger than one frame carries (1,484 bytes) in several frames;
    * a mailbox exchange: ``FPWR`` of the request into SM0 (1000h), ``FPRD`` of the
      SM1 status (080Dh) and ``FPRD`` of the answer from SM1 (1080h).

    Stations are 1001h + position, as SOEM assigns them.  Timestamps follow the
    bus's clock (virtual in the ``auto``/``lockstep`` modes) from the wall-clock
    time the capture started; frames without a bus time of their own come 1 us
    after the previous one.
    """

    #: captures this process started: a bus opened again (GT_InitEcatComm after
    #: GT_TerminateEcatComm) continues its file instead of starting it over
    _started: set[Path] = set()  # noqa: RUF012 - process-wide on purpose

    def __init__(self, path: str | Path, *, mailbox_size: int = 128) -> None:
        from gtecat.drives.esc.frames import MASTER_MAC

        key = Path(path).resolve()
        self.writer = PcapWriter(path, append=key in BusCapture._started)
        BusCapture._started.add(key)
        self.mailbox_size = mailbox_size
        self._src = MASTER_MAC
        self._answer_src = bytes([MASTER_MAC[0] | 0x02]) + MASTER_MAC[1:]
        self._wall0 = time.time_ns()
        self._bus0: int | None = None
        self._last = self._wall0
        self._index = 0

    # --- time -----------------------------------------------------------------
    def _stamp(self, t_ns: int | None) -> int:
        if t_ns is not None:
            if self._bus0 is None:
                self._bus0 = t_ns
            t = self._wall0 + (t_ns - self._bus0)
            self._last = max(t, self._last + 1_000)
        else:
            self._last += 1_000
        return self._last

    # --- one request/answer pair ----------------------------------------------
    def _pair(
        self,
        command: int,
        adp: int,
        ado: int,
        request: bytes,
        answer: bytes,
        wkc: int,
        t_ns: int | None = None,
    ) -> None:
        from gtecat.drives.esc.frames import Datagram, encode_frame

        self._index = (self._index + 1) & 0xFF
        n = self._count_adp(command, adp)
        sent = Datagram(command, adp & 0xFFFF, ado & 0xFFFF, request, self._index)
        back = Datagram(command, n & 0xFFFF, ado & 0xFFFF, answer, self._index, wkc=wkc)
        self.writer.write(encode_frame([sent], src=self._src), self._stamp(t_ns))
        self.writer.write(encode_frame([back], src=self._answer_src), self._stamp(None))
        if self.writer.frames % 2048 == 0:
            self.writer.flush()  # a capture read while the bus runs is mostly complete

    _slaves = 0

    def _count_adp(self, command: int, adp: int) -> int:
        # auto-increment and broadcast commands come back with ADP + number of slaves
        return adp + self._slaves if command in (1, 2, 3, 7, 8, 9, 13) else adp

    # --- what the backend does ------------------------------------------------
    def scan(self, count: int) -> None:
        self._slaves = count
        self._pair(7, 0, 0x0000, bytes(1), b"\x11", count)

    def state(self, position: int, requested: int, state: int, code: int, error: bool) -> None:
        station = 0x1001 + position
        self._pair(
            5, station, 0x0120, struct.pack("<H", requested), struct.pack("<H", requested), 1
        )
        status = struct.pack("<HHH", state | (0x10 if error else 0), 0, code)
        self._pair(4, station, 0x0130, bytes(6), status, 1)

    def cycle(
        self,
        t_ns: int,
        image: bytes,
        outputs_bytes: int,
        wkc: int,
        shares: Sequence[tuple[int, int, int]] = (),
    ) -> None:
        """One cycle's LRW.  An image larger than one datagram carries
        (:data:`~gtecat.eni.cyclic.MAX_DATAGRAM_DATA`) goes out in several frames, an LRW
        of consecutive bytes each (as SOEM splits its IO map), whose working counters come
        from ``shares``: (first byte, end, counter) of each slave's area that answered."""
        request = bytes(image[:outputs_bytes]) + bytes(len(image) - outputs_bytes)
        if len(image) <= MAX_DATAGRAM_DATA:
            self._pair(12, 0, 0, request, bytes(image), wkc, t_ns)
            return
        for start in range(0, len(image), MAX_DATAGRAM_DATA):
            end = min(start + MAX_DATAGRAM_DATA, len(image))
            n = sum(add for a, b, add in shares if a < end and start < b)
            at = t_ns if start == 0 else None
            self._pair(12, start, start >> 16, request[start:end], bytes(image[start:end]), n, at)

    def mailbox(self, position: int, request: bytes, answer: bytes | None) -> None:
        station, size = 0x1001 + position, self.mailbox_size
        self._pair(
            5,
            station,
            0x1000,
            request[:size].ljust(size, b"\0"),
            request[:size].ljust(size, b"\0"),
            1,
        )
        if answer is None:
            self._pair(4, station, 0x080D, bytes(1), b"\x00", 1)
            return
        self._pair(4, station, 0x080D, bytes(1), b"\x08", 1)
        self._pair(4, station, 0x1080, bytes(size), answer[:size].ljust(size, b"\0"), 1)

    def flush(self) -> None:
        self.writer.flush()

    def close(self) -> None:
        self.writer.close()
