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
from pathlib import Path
from typing import BinaryIO

#: nanosecond-resolution pcap magic (the microsecond one is A1B2C3D4)
MAGIC_NS = 0xA1B23C4D
LINKTYPE_ETHERNET = 1
SNAPLEN = 65535

_GLOBAL = struct.Struct("<IHHiIII")
_RECORD = struct.Struct("<IIII")


class PcapWriter:
    """Append Ethernet frames with their wall-clock time to a pcap file."""

    def __init__(self, path: str | Path, *, buffering: int = 1 << 16) -> None:
        self.path = Path(path)
        self._fh: BinaryIO | None = open(self.path, "wb", buffering=buffering)
        self._fh.write(_GLOBAL.pack(MAGIC_NS, 2, 4, 0, 0, SNAPLEN, LINKTYPE_ETHERNET))
        self.frames = 0

    def write(self, frame: bytes | bytearray | memoryview, t_ns: int | None = None) -> None:
        """One frame; ``t_ns`` is wall-clock (CLOCK_REALTIME) nanoseconds, default now."""
        fh = self._fh
        if fh is None:
            raise ValueError(f"pcap file {self.path} is closed")
        if t_ns is None:
            t_ns = time.time_ns()
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
