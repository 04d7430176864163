"""Small test doubles for the ESC tests: a slave with fixed PDOs and a minimal CoE server,
and a master that talks to a :class:`~gtecat.drives.esc.Chain` in-process, datagram by datagram.

The slave's CoE is hand-written on purpose (independent of gtecat.drives.coe): it
answers expedited uploads/downloads, the SM/PDO objects SOEM reads during
``config_map`` (1C00h, 1C12h/1C13h, 1600h/1A00h) and aborts unknown objects
with 06020000h, framed as ETG.1000.6 says (abort = CoE service 2).
"""

from __future__ import annotations

import struct

from gtecat.drives.esc import Chain, Command, Datagram, decode_frame, encode_frame
from gtecat.drives.slave import VirtualSlave
from gtecat.eni.model import Direction, Identity, Pdo, PdoEntry


def _pdos(direction: Direction, bits: int) -> tuple[Pdo, ...]:
    if bits <= 0:
        return ()
    parts = [16] + [32] * ((bits - 16) // 32) if bits >= 16 else [bits]
    rest = bits - sum(parts)
    if rest:
        parts.append(rest)
    obj = 0x7000 if direction == Direction.OUT else 0x6000
    index = 0x1600 if direction == Direction.OUT else 0x1A00
    entries = tuple(PdoEntry(obj, k, b, f"obj {k}", "") for k, b in enumerate(parts, 1))
    return (Pdo(index, direction, entries, "PDO"),)


class MiniSlave(VirtualSlave):
    """Fixed PDO sizes; ``step`` echoes the outputs into the inputs and counts."""

    def __init__(
        self,
        position: int,
        name: str,
        identity: Identity,
        rx_bits: int = 48,
        tx_bits: int = 80,
        mailbox: bool = True,
    ) -> None:
        self._sizes = (rx_bits, tx_bits)
        self.has_mailbox = mailbox
        self.rx_pdos = _pdos(Direction.OUT, rx_bits)
        self.tx_pdos = _pdos(Direction.IN, tx_bits)
        super().__init__(position, name, identity)
        self.steps = 0
        self.requests: list[bytes] = []
        od: dict[tuple[int, int], tuple[int, int]] = {
            (0x1000, 0): (4, 0x00020192),
            (0x2000, 0): (2, 0x1234),
            (0x1C00, 0): (1, 4),
        }
        for k, t in enumerate((1, 2, 3, 4), 1):
            od[(0x1C00, k)] = (1, t)
        for pdos, assign in ((self.rx_pdos, 0x1C12), (self.tx_pdos, 0x1C13)):
            od[(assign, 0)] = (1, len(pdos))
            for j, pdo in enumerate(pdos, 1):
                od[(assign, j)] = (2, pdo.index)
                od[(pdo.index, 0)] = (1, len(pdo.entries))
                for k, e in enumerate(pdo.entries, 1):
                    od[(pdo.index, k)] = (4, (e.index << 16) | (e.subindex << 8) | e.bit_len)
        self.od = od

    def pdo_sizes(self) -> tuple[int, int]:
        return self._sizes

    def mailbox(self, request: bytes) -> bytes | None:
        self.requests.append(bytes(request))
        if request[5] & 0x0F != 3:
            return None
        cmd = request[8]
        index, sub = struct.unpack_from("<HB", request, 9)

        def answer(command: int, data: bytes = bytes(4)) -> bytes:
            service = 2 if command == 0x80 else 3
            return (
                struct.pack("<HHBBH", 10, 0, 0, 3, service << 12)
                + bytes([command])
                + struct.pack("<HB", index, sub)
                + data
            )

        key = (index, sub)
        if key not in self.od:
            return answer(0x80, struct.pack("<I", 0x06020000))
        size, value = self.od[key]
        if cmd & 0xE0 == 0x40:  # initiate upload
            return answer(0x43 | ((4 - size) << 2), value.to_bytes(4, "little"))
        if cmd & 0xE0 == 0x20:  # initiate download, expedited
            if index == 0x1000:
                return answer(0x80, struct.pack("<I", 0x06010002))
            n = 4 - ((cmd >> 2) & 3)
            self.od[key] = (size, int.from_bytes(request[12 : 12 + n], "little"))
            return answer(0x60)
        return answer(0x80, struct.pack("<I", 0x05040001))

    def step(self, t_ns: int, dt_ns: int) -> None:
        self.steps += 1
        n = min(len(self.rx), len(self.tx))
        self.tx[:n] = self.rx[:n]
        if len(self.tx) > n:
            self.tx[n] = self.steps & 0xFF


def mini_chain(n: int = 2, **kw: object) -> Chain:
    slaves = [
        MiniSlave(0, "MiniDrive", Identity(0x1234, 0x5678, 2)),
        MiniSlave(1, "MiniIO", Identity(0x1234, 0x9999, 1), 16, 16, mailbox=False),
        MiniSlave(2, "MiniBits", Identity(0x1234, 0x4444, 1), 2, 3, mailbox=False),
    ][:n]
    return Chain(slaves, **kw)  # type: ignore[arg-type]


class MiniMaster:
    """One datagram per frame, like SOEM's blocking calls; returns (data, wkc)."""

    def __init__(self, chain: Chain) -> None:
        self.chain = chain
        self.index = 0

    def frame(self, datagrams: list[Datagram]) -> list[Datagram]:
        raw = self.chain.exchange(encode_frame(datagrams))
        assert raw is not None, "a well-formed frame must be answered"
        self.chain.service()
        return decode_frame(raw).datagrams

    def cmd(self, command: Command, adp: int, ado: int, data: bytes) -> tuple[bytes, int]:
        payload = bytes(data)
        self.index = (self.index + 1) & 0xFF
        d = self.frame([Datagram(command, adp & 0xFFFF, ado, payload, self.index)])[0]
        return d.data, d.wkc

    def aprd(self, pos: int, ado: int, n: int) -> tuple[bytes, int]:
        return self.cmd(Command.APRD, -pos, ado, bytes(n))

    def apwr(self, pos: int, ado: int, data: bytes) -> int:
        return self.cmd(Command.APWR, -pos, ado, data)[1]

    def fprd(self, station: int, ado: int, n: int) -> tuple[bytes, int]:
        return self.cmd(Command.FPRD, station, ado, bytes(n))

    def fpwr(self, station: int, ado: int, data: bytes) -> int:
        return self.cmd(Command.FPWR, station, ado, data)[1]

    def lrw(self, address: int, data: bytes) -> tuple[bytes, int]:
        d = self.frame([Datagram.logical(Command.LRW, address, data)])[0]
        return d.data, d.wkc

    # --- the things SOEM does, in miniature ----------------------------------------------------
    def eeprom_read(self, station: int, word: int) -> bytes:
        self.fpwr(station, 0x0502, struct.pack("<HIH", 0x0100, word, 0)[:6])
        for _ in range(100):
            status, _wkc = self.fprd(station, 0x0502, 2)
            if not struct.unpack("<H", status)[0] & 0x8000:
                break
        return self.fprd(station, 0x0508, 8)[0]

    def set_state(self, station: int, state: int) -> tuple[int, int]:
        self.fpwr(station, 0x0120, struct.pack("<H", state))
        data, _ = self.fprd(station, 0x0130, 6)
        return data[0], struct.unpack_from("<H", data, 4)[0]

    def mailbox_sdo(
        self, station: int, request: bytes, sm0: int = 0x1000, sm1: int = 0x1080, size: int = 128
    ) -> bytes:
        assert self.fpwr(station, sm0, request + bytes(size - len(request))) == 1
        status, _ = self.fprd(station, 0x080D, 1)
        assert status[0] & 0x08, "the answer is waiting in SM1"
        data, wkc = self.fprd(station, sm1, size)
        assert wkc == 1
        return data


def sdo_upload_request(index: int, sub: int, counter: int = 1) -> bytes:
    return struct.pack("<HHBBHBHB4x", 10, 0, 0, 3 | (counter << 4), 2 << 12, 0x40, index, sub)


def sdo_download_request(index: int, sub: int, value: bytes, counter: int = 1) -> bytes:
    cmd = 0x23 | ((4 - len(value)) << 2)
    return struct.pack("<HHBBHBHB", 10, 0, 0, 3 | (counter << 4), 2 << 12, cmd, index, sub) + (
        value + bytes(4 - len(value))
    )
