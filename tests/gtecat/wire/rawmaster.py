"""A small EtherCAT master written for the tests, on a raw socket, independent of our code.

Frames, datagrams, mailbox and CoE messages are packed here with ``struct`` from
the standard's tables (ETG.1000.4 5.3/5.4 frames and datagrams, 5.5 mailbox,
ETG.1000.6 5.6 SDO and SDO Information), so a bug in ``gtecat.drives.esc`` or
``gtecat.drives.coe`` cannot hide on both sides.  It can do what real masters do that
matters to the slaves: resend a frame whose answer is late (SOEM's
``ecx_srconfirm``), count the mailbox counter 1..7, read every fragment of an
SDO Information answer, replay ENI InitCmds word for word.

Every wait is bounded by a timeout; nothing sleeps unbounded.
"""

from __future__ import annotations

import contextlib
import os
import secrets
import select
import shutil
import socket
import struct
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

ETHERTYPE = 0x88A4
SRC = b"\x04\x00\x00\x00\x00\x07"
PACKET_OUTGOING = 4  # sll_pkttype of a frame this host sent

APRD, APWR, APRW, FPRD, FPWR, FPRW, BRD, BWR, BRW, LRD, LWR, LRW, ARMW, FRMW = range(1, 15)


def why_not_root() -> str | None:
    if sys.platform != "linux":
        return "veth pairs and AF_PACKET sockets are Linux only"
    if os.geteuid() != 0:
        return "creating a veth pair and raw sockets need root (CAP_NET_ADMIN, CAP_NET_RAW)"
    if shutil.which("ip") is None:
        return "no `ip` command (iproute2) to create the veth pair"
    return None


#: how long a test's SOEM (pysoem) master waits for the answer to one frame: process data
#: (``receive_processdata``) and every other frame (pysoem's ``settings.timeouts.ret``, SOEM's
#: EC_TIMEOUTRET, 2 ms).  ``gtecat serve`` is Python beside the suite's workers; on a loaded
#: 2-CPU machine it answers tens of milliseconds late now and then, and a late answer is then
#: a lost cycle (working counter -1) or a mailbox frame SOEM sends again (whose exchange reads
#: a stale answer).  These tests are about what the slaves answer, not how fast: only a frame
#: that is really lost (a fault that drops answers) waits this long.
SOEM_FRAME_US = 500_000


#: SOEM's own EC_TIMEOUTRET (2 ms): for a test in which nothing answers by design
SOEM_DEFAULT_FRAME_US = 2_000


@contextlib.contextmanager
def patient_soem(frame_us: int = SOEM_FRAME_US) -> Iterator[None]:
    """pysoem's per-frame timeout at ``frame_us`` for the block (an older pysoem without
    ``settings`` keeps its own)."""
    import pysoem

    settings = getattr(pysoem, "settings", None)
    if settings is None:
        yield
        return
    old = settings.timeouts.ret
    settings.timeouts.ret = frame_us
    try:
        yield
    finally:
        settings.timeouts.ret = old


@contextlib.contextmanager
def veth_pair(prefix: str = "gr") -> Iterator[tuple[str, str]]:
    """A fresh veth pair (master end, slave end), deleted on the way out."""
    tag = secrets.token_hex(3)
    a, b = f"{prefix}m{tag}", f"{prefix}s{tag}"
    made = subprocess.run(
        ["ip", "link", "add", a, "type", "veth", "peer", "name", b],
        capture_output=True,
        text=True,
        timeout=10,
    )
    if made.returncode != 0:
        raise OSError(f"cannot create a veth pair: {made.stderr.strip()}")
    try:
        for name in (a, b):
            with contextlib.suppress(OSError):
                Path(f"/proc/sys/net/ipv6/conf/{name}/disable_ipv6").write_text("1")
            subprocess.run(["ip", "link", "set", name, "up"], check=True, timeout=10)
        _wait_carrier(a, b)
        yield a, b
    finally:
        subprocess.run(["ip", "link", "del", a], capture_output=True, timeout=10)


def _wait_carrier(*names: str, timeout_s: float = 5.0) -> None:
    """Both ends up (operstate): a frame sent before the peer's carrier is up is dropped by
    the kernel, which a loaded machine makes likely for the first frames of a test."""
    deadline = time.monotonic() + timeout_s
    for name in names:
        state = Path(f"/sys/class/net/{name}/operstate")
        while time.monotonic() < deadline:
            with contextlib.suppress(OSError):
                if state.read_text().strip() == "up":
                    break
            time.sleep(0.01)


@dataclass
class Reply:
    data: bytes
    wkc: int
    adp: int = 0


class NoAnswer(Exception):
    """No answer to a frame within the timeout (after the resends)."""


class FrameTooLong(Exception):
    """Datagrams that no Ethernet frame carries."""


#: an Ethernet frame without FCS: 14 bytes of header and at most 1500 of payload
MAX_FRAME = 1514


#: how long :meth:`RawMaster.transact` waits for a frame's answer, resends included, and the
#: slave side for what it does after a frame (an EEPROM read, a state change, a mailbox
#: answer): the server is Python beside the suite's workers (in a thread of the test's own
#: process in some tests), and on a loaded 2-CPU machine an answer took more than the 0.5 s
#: this once was; only what never comes waits this long
ANSWER_S = 5.0


class RawMaster:
    """One datagram per frame, answers matched by the datagram index, like SOEM."""

    def __init__(self, iface: str, *, timeout: float = ANSWER_S, resend_after: float = 0.1) -> None:
        self.sock = socket.socket(socket.AF_PACKET, socket.SOCK_RAW, socket.htons(ETHERTYPE))
        self.sock.bind((iface, ETHERTYPE))
        self.timeout = timeout
        self.resend_after = resend_after
        self.index = 0
        self.mbx_counter: dict[int, int] = {}
        self.frames_sent = 0
        self.resends = 0

    def close(self) -> None:
        self.sock.close()

    def __enter__(self) -> RawMaster:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- frames -------------------------------------------------------------------------------
    @staticmethod
    def frame(cmd: int, index: int, adp: int, ado: int, data: bytes) -> bytes:
        """ETG.1000.4: Ethernet header, frame header (length | type 1), one datagram."""
        return RawMaster.frame_of([(cmd, adp, ado, data)], index)

    @staticmethod
    def frame_of(datagrams: list[tuple[int, int, int, bytes]], index: int) -> bytes:
        """Several datagrams (cmd, adp, ado, data) in one frame, chained by their M bit, the
        first carrying ``index`` (ETG.1000.4 5.3, 5.4)."""
        body = b""
        for k, (cmd, adp, ado, data) in enumerate(datagrams):
            more = 0x8000 if k + 1 < len(datagrams) else 0
            flags = len(data) | more
            body += struct.pack("<BBHHHH", cmd, index, adp & 0xFFFF, ado & 0xFFFF, flags, 0)
            body += bytes(data) + b"\0\0"
        raw = b"\xff" * 6 + SRC + struct.pack(">H", ETHERTYPE)
        raw += struct.pack("<H", 0x1000 | len(body)) + body
        return raw.ljust(60, b"\0")

    def send_raw(self, raw: bytes) -> None:
        self.sock.send(raw)
        self.frames_sent += 1

    @staticmethod
    def replies(raw: bytes) -> list[Reply]:
        """Every datagram of an answered frame: its data and working counter."""
        out = []
        pos = 16
        while pos + 12 <= len(raw):
            (length,) = struct.unpack_from("<H", raw, pos + 6)
            adp = struct.unpack_from("<H", raw, pos + 2)[0]
            data = raw[pos + 10 : pos + 10 + (length & 0x07FF)]
            wkc = struct.unpack_from("<H", raw, pos + 10 + (length & 0x07FF))[0]
            out.append(Reply(data, wkc, adp))
            if not length & 0x8000:
                break
            pos += 12 + (length & 0x07FF)
        return out

    def receive_all(self, index: int, deadline: float) -> list[Reply] | None:
        """The answer whose first datagram carries ``index`` (others are stale: dropped)."""
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                return None
            ready, _, _ = select.select([self.sock], [], [], left)
            if not ready:
                return None
            raw, addr = self.sock.recvfrom(2048)
            if addr[2] == PACKET_OUTGOING or len(raw) < 28 or raw[12:14] != b"\x88\xa4":
                continue  # our own frame seen on the way out, or not EtherCAT
            if raw[17] != index:
                continue
            return self.replies(raw)

    def receive(self, index: int, deadline: float) -> Reply | None:
        got = self.receive_all(index, deadline)
        return got[0] if got else None

    def transact(self, cmd: int, adp: int, ado: int, data: bytes) -> Reply:
        """Send; resend the same frame (same index) when the answer is late, like SOEM."""
        return self.transact_frame([(cmd, adp, ado, data)])[0]

    def transact_frame(self, datagrams: list[tuple[int, int, int, bytes]]) -> list[Reply]:
        """Several datagrams in one frame (an ENI's cyclic ``Frame``); a frame that an
        Ethernet link cannot carry (more than 1514 bytes without FCS) is refused."""
        self.index = (self.index + 1) & 0xFF
        raw = self.frame_of(datagrams, self.index)
        if len(raw) > MAX_FRAME:
            raise FrameTooLong(f"{len(raw)} bytes, an Ethernet frame carries {MAX_FRAME}")
        end = time.monotonic() + self.timeout
        while True:
            self.send_raw(raw)
            got = self.receive_all(self.index, min(end, time.monotonic() + self.resend_after))
            if got is not None:
                return got
            if time.monotonic() >= end:
                cmd, adp, ado, _ = datagrams[0]
                raise NoAnswer(f"cmd {cmd} adp 0x{adp:04X} ado 0x{ado:04X}: no answer")
            self.resends += 1

    def aprd(self, pos: int, ado: int, n: int) -> Reply:
        return self.transact(APRD, -pos, ado, bytes(n))

    def apwr(self, pos: int, ado: int, data: bytes) -> int:
        return self.transact(APWR, -pos, ado, data).wkc

    def fprd(self, station: int, ado: int, n: int) -> Reply:
        return self.transact(FPRD, station, ado, bytes(n))

    def fpwr(self, station: int, ado: int, data: bytes) -> int:
        return self.transact(FPWR, station, ado, data).wkc

    def brd(self, ado: int, n: int) -> Reply:
        return self.transact(BRD, 0, ado, bytes(n))

    def bwr(self, ado: int, data: bytes) -> int:
        return self.transact(BWR, 0, ado, data).wkc

    def lrw(self, address: int, data: bytes) -> Reply:
        return self.transact(LRW, address & 0xFFFF, address >> 16, data)

    # --- bring-up ----------------------------------------------------------------------------
    def scan(self, first_station: int = 0x1001) -> list[int]:
        """INIT everything, count the slaves, give them station addresses (SOEM's order)."""
        self.bwr(0x0120, struct.pack("<H", 0x11))  # INIT + ack
        n = self.brd(0x0000, 1).wkc
        stations = []
        for pos in range(n):
            station = first_station + pos
            assert self.apwr(pos, 0x0010, struct.pack("<H", station)) == 1
            stations.append(station)
        return stations

    def sii_word(self, station: int, word: int, timeout: float = ANSWER_S) -> int:
        return struct.unpack("<H", self.sii_read(station, word, timeout)[:2])[0]

    def sii_read(self, station: int, word: int, timeout: float = ANSWER_S) -> bytes:
        """Four (or eight) bytes of the EEPROM from ``word`` on (ETG.1000.4 Table 48)."""
        self.fpwr(station, 0x0502, struct.pack("<HI", 0x0100, word))
        end = time.monotonic() + timeout
        while struct.unpack("<H", self.fprd(station, 0x0502, 2).data)[0] & 0x8000:
            if time.monotonic() > end:
                raise NoAnswer("EEPROM stays busy")
        return self.fprd(station, 0x0508, 8).data

    def sii(self, station: int, words: int = 2048) -> bytes:
        """The EEPROM content up to the end category (or ``words`` words)."""
        raw = bytearray()
        while len(raw) < 2 * words:
            raw += self.sii_read(station, len(raw) // 2)
            if len(raw) >= 132:
                pos = 128
                while pos + 4 <= len(raw):
                    ctype, size = struct.unpack_from("<HH", raw, pos)
                    if ctype == 0xFFFF:
                        return bytes(raw[: pos + 2])
                    pos += 4 + 2 * size
        return bytes(raw)

    def state(self, station: int) -> tuple[int, int]:
        data = self.fprd(station, 0x0130, 6).data
        return data[0], struct.unpack_from("<H", data, 4)[0]

    def request_state(self, station: int, state: int, timeout: float = ANSWER_S) -> tuple[int, int]:
        self.fpwr(station, 0x0120, struct.pack("<H", state))
        end = time.monotonic() + timeout
        while True:
            st, code = self.state(station)
            if st & 0x0F == state or st & 0x10 or time.monotonic() > end:
                return st, code

    def setup_mailbox(self, station: int) -> tuple[int, int, int, int]:
        """SM0/SM1 from the SII words 18h..1Bh, as SOEM's config_init does."""
        out_start, out_len = self.sii_word(station, 0x18), self.sii_word(station, 0x19)
        in_start, in_len = self.sii_word(station, 0x1A), self.sii_word(station, 0x1B)
        sm0 = struct.pack("<HHBBBB", out_start, out_len, 0x26, 0, 1, 0)
        sm1 = struct.pack("<HHBBBB", in_start, in_len, 0x22, 0, 1, 0)
        assert self.fpwr(station, 0x0800, sm0 + sm1) == 1
        self.mbx_counter[station] = 0
        return out_start, out_len, in_start, in_len

    # --- mailbox -----------------------------------------------------------------------------
    def next_counter(self, station: int) -> int:
        cnt = self.mbx_counter.get(station, 0) % 7 + 1
        self.mbx_counter[station] = cnt
        return cnt

    def mailbox_message(self, station: int, mtype: int, body: bytes) -> bytes:
        cnt = self.next_counter(station)
        return struct.pack("<HHBB", len(body), 0, 0, mtype | cnt << 4) + body

    def mbx_write(self, station: int, sm: tuple[int, int, int, int], msg: bytes) -> int:
        start, length = sm[0], sm[1]
        return self.fpwr(station, start, msg.ljust(length, b"\0"))

    def mbx_read(
        self, station: int, sm: tuple[int, int, int, int], timeout: float = ANSWER_S
    ) -> bytes | None:
        """Poll SM1 until it is full, then read it whole (None when nothing came)."""
        start, length = sm[2], sm[3]
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            status = self.fprd(station, 0x080D, 1)
            if status.wkc and status.data[0] & 0x08:
                got = self.fprd(station, start, length)
                if got.wkc == 1:
                    size = struct.unpack_from("<H", got.data)[0]
                    return got.data[: 6 + size]
        return None

    def coe(self, station: int, sm: tuple[int, int, int, int], service: int, data: bytes) -> bytes:
        """One CoE request; the first answer that is not an emergency."""
        msg = self.mailbox_message(station, 3, struct.pack("<H", service << 12) + data)
        assert self.mbx_write(station, sm, msg) == 1, "SM0 refused the request"
        for _ in range(10):
            answer = self.mbx_read(station, sm)
            if answer is None:
                raise NoAnswer("no mailbox answer")
            if answer[5] & 0x0F == 3 and struct.unpack_from("<H", answer, 6)[0] >> 12 == 1:
                continue  # an emergency
            return answer
        raise NoAnswer("only emergencies")

    def sdo_upload(
        self, station: int, sm: tuple[int, int, int, int], index: int, sub: int
    ) -> bytes:
        """Expedited, normal or segmented upload (ETG.1000.6 5.6.2.4-5.6.2.6)."""
        answer = self.coe(station, sm, 2, struct.pack("<BHB4x", 0x40, index, sub))
        cmd = answer[8]
        if cmd == 0x80:
            raise SdoAbortSeen(struct.unpack_from("<I", answer, 12)[0])
        if cmd & 0x02:  # expedited
            n = 4 - ((cmd >> 2) & 3) if cmd & 0x01 else 4
            return answer[12 : 12 + n]
        total = struct.unpack_from("<I", answer, 12)[0]
        size = struct.unpack_from("<H", answer)[0]
        data = bytearray(answer[16 : 6 + size])
        toggle = 0
        while len(data) < total:
            seg = self.coe(station, sm, 2, bytes([0x60 | toggle]) + bytes(7))
            if seg[8] == 0x80:
                raise SdoAbortSeen(struct.unpack_from("<I", seg, 12)[0])
            seg_len = struct.unpack_from("<H", seg)[0] - 3
            chunk = seg[9 : 9 + seg_len]
            if seg[8] & 0x01 and seg_len == 7:
                chunk = chunk[: 7 - ((seg[8] >> 1) & 7)]
            data += chunk
            toggle ^= 0x10
            if seg[8] & 0x01:
                break
        return bytes(data[:total])

    def sdo_download(
        self,
        station: int,
        sm: tuple[int, int, int, int],
        index: int,
        sub: int,
        data: bytes,
        complete_access: bool = False,
    ) -> None:
        ca = 0x10 if complete_access else 0
        if 0 < len(data) <= 4:
            cmd = 0x23 | ca | ((4 - len(data)) << 2)
            body = struct.pack("<BHB", cmd, index, sub) + data.ljust(4, b"\0")
        else:
            room = sm[1] - 16
            if len(data) > room:
                raise ValueError("segmented downloads are not needed by the tests")
            body = struct.pack("<BHBI", 0x21 | ca, index, sub, len(data)) + data
        answer = self.coe(station, sm, 2, body)
        if answer[8] == 0x80:
            raise SdoAbortSeen(struct.unpack_from("<I", answer, 12)[0])
        assert answer[8] & 0xE0 == 0x60, answer.hex()  # download response (CA bit may echo)

    def sdo_info(
        self, station: int, sm: tuple[int, int, int, int], opcode: int, data: bytes
    ) -> list[bytes]:
        """One SDO Information request; every fragment's data, in order."""
        first = self.coe(station, sm, 8, struct.pack("<BBH", opcode, 0, 0) + data)
        frames = [first]
        while frames[-1][8] & 0x80:  # Incomplete: more fragments follow
            nxt = self.mbx_read(station, sm)
            if nxt is None:
                raise NoAnswer(f"fragment missing after {len(frames)}")
            frames.append(nxt)
        for k, f in enumerate(frames):
            assert struct.unpack_from("<H", f, 10)[0] == len(frames) - 1 - k
        return [f[12:] for f in frames]


class SdoAbortSeen(Exception):
    def __init__(self, code: int) -> None:
        super().__init__(f"SDO abort 0x{code:08X}")
        self.code = code


class ServeProcess:
    """``python -m gtecat serve`` in a subprocess, ready when it says so (bounded)."""

    def __init__(self, eni: Path, iface: str, stats: Path, *extra: str, cwd: Path) -> None:
        self.stats = stats
        self.proc = subprocess.Popen(
            [
                sys.executable,
                "-m",
                "gtecat",
                "serve",
                "--eni",
                str(eni),
                "--iface",
                iface,
                "--stats-json",
                str(stats),
                # a fraction of a CPU beside the suite's workers (``extra`` may say otherwise)
                "--wait",
                "predict",
                *extra,
            ],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            cwd=cwd,
        )
        assert self.proc.stdout is not None
        ready, _, _ = select.select([self.proc.stdout], [], [], 30)
        line = self.proc.stdout.readline() if ready else ""
        self.output = ""
        if "ready" not in line:
            self.stop()
            raise RuntimeError(f"gtecat serve did not start: {line!r} {self.output!r}")

    def stop(self) -> int:
        if self.proc.poll() is None:
            self.proc.terminate()
        try:
            out, _ = self.proc.communicate(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            out, _ = self.proc.communicate(timeout=10)
        self.output = out or ""
        return self.proc.returncode


class ChainMaster(RawMaster):
    """The same master with no socket: each frame goes to a line of ESCs in this process
    (anything with ``process(bytearray) -> bool`` and ``service()``, as
    :class:`gtecat.drives.esc.Chain` has), answered before ``send_raw`` returns; ``tick``
    is called after each frame (a virtual clock's 100 us on the wire)."""

    def __init__(self, chain: Any, tick: Callable[[], object] = lambda: None) -> None:
        # (no socket: RawMaster.__init__ is not run)
        self.chain = chain
        self.tick = tick
        self.timeout = ANSWER_S
        self.resend_after = 0.1
        self.index = 0
        self.mbx_counter: dict[int, int] = {}
        self.frames_sent = 0
        self.resends = 0
        self._answer: bytes | None = None

    def close(self) -> None:
        pass

    def send_raw(self, raw: bytes) -> None:
        self.frames_sent += 1
        buf = bytearray(raw)
        self._answer = bytes(buf) if self.chain.process(buf) else None
        self.chain.service()
        self.tick()

    def receive_all(self, index: int, deadline: float) -> list[Reply] | None:
        raw, self._answer = self._answer, None
        if raw is None or raw[17] != index:
            return None
        return self.replies(raw)
