"""Late mailbox answers lose no SDO answer: SOEM's mailbox exchange against a lossy link.

A master drops an answer that comes later than its timeout (SOEM: 2 ms) although the slave
processed the frame: a read of SM1 answered late has emptied the slave's read mailbox, and
the master never saw the message.  ETG.1000.4 keeps it recoverable: the master toggles the
repeat request (SM1 activate bit 1), the slave puts the message the master read last back
into SM1 and acknowledges (PDI control bit 1), the master reads it again.  A resent SM0 write
(SOEM resends a frame whose answer is late) must not run the request twice.

The master here is SOEM 1.4's ``ecx_SDOread`` / ``ecx_mbxsend`` / ``ecx_mbxreceive`` written
out with raw datagrams (the same steps, registers and loops), on a link that loses a share
of the answers of frames the chain did process.  Every SDO upload must still get its own
answer, in order; emergencies the slave raises meanwhile are reported, never taken for an
answer.
"""

from __future__ import annotations

import random
import struct

from gtecat.drives.esc import Chain
from gtecat.drives.slave import AlState
from tests.drives.esc.mini import MiniSlave, mini_chain, sdo_upload_request
from tests.drives.esc.test_plan import SM

STATION = 0x1001
FPRD, FPWR = 4, 5  # ETG.1000.4 Table 9
SM0, SM1, SIZE = 0x1000, 0x1080, 128
SM0_STATUS, SM1_STATUS, SM1_PDI = 0x0805, 0x080D, 0x080F
#: object -> value of the mini drive's dictionary (tests/drives/esc/mini.py)
OBJECTS = {(0x1000, 0): 0x00020192, (0x2000, 0): 0x1234, (0x1C00, 0): 4, (0x1C00, 3): 3}


class LossyMaster:
    """SOEM's mailbox calls over a link that drops answers (the frame was processed)."""

    def __init__(self, chain: Chain, rng: random.Random, loss: float, skip: float) -> None:
        self.chain = chain
        self.rng = rng
        self.loss = loss
        #: how often the slave side does not run between two frames (a frame answered
        #: during the slaves' step: the next message reaches SM1 a frame later)
        self.skip = skip
        self.counter = 0
        self.repeats = 0
        self.lost = 0
        self.emergencies: list[int] = []
        self.frames = 0

    def _frame(
        self, cmd: int, ado: int, data: bytes, lossy: bool = True
    ) -> tuple[bytes, int] | None:
        """One datagram in one frame (ETG.1000.4 5.3/5.4, packed here); (data, WKC)."""
        self.frames += 1
        n = len(data)
        buf = bytearray(
            b"\xff" * 6
            + b"\x01" * 6
            + struct.pack(">H", 0x88A4)
            + struct.pack(
                "<HBBHHHH", 0x1000 | (12 + n), cmd, self.frames & 0xFF, STATION, ado, n, 0
            )
            + data
            + b"\0\0"
        )
        buf += bytes(max(0, 60 - len(buf)))
        assert self.chain.process(buf)
        self.chain.flush()
        if lossy and self.rng.random() < self.loss:
            self.lost += 1
            self.chain.service()  # the master waited its timeout: the slave side has run
            return None  # the answer came back after the master's timeout: dropped
        if self.rng.random() >= self.skip:
            self.chain.service()
        return bytes(buf[26 : 26 + n]), struct.unpack_from("<H", buf, 26 + n)[0]

    def fprd(self, ado: int, n: int) -> bytes | None:
        """FPRD with EC_TIMEOUTRET: one try; None = no answer or WKC 0 (SOEM: wkc <= 0)."""
        got = self._frame(FPRD, ado, bytes(n))
        return got[0] if got is not None and got[1] > 0 else None

    def fpwr(self, ado: int, data: bytes, tries: int = 1) -> int:
        """FPWR; ``tries`` > 1 resends the same frame while no answer came (EC_TIMEOUTRET3).
        The last try's answer is never lost: after three SOEM gives up the request itself
        (its own limit, which no slave can help), and that is not what is tested here."""
        for k in range(tries):
            lossy = tries == 1 or k < tries - 1
            got = self._frame(FPWR, ado, data, lossy)
            if got is not None:
                return got[1]
        return -1

    # --- ecx_mbxreceive ----------------------------------------------------------------------
    def mbxreceive(self, budget: int) -> bytes | None:
        smstat = None
        for _ in range(budget):  # wait for read mailbox available
            raw = self.fprd(SM1_STATUS, 2)
            if raw is not None and raw[0] & 0x08:
                smstat = struct.unpack("<H", raw)[0]
                break
        if smstat is None:
            return None
        for _ in range(budget):
            mbx = self.fprd(SM1, SIZE)
            if mbx is not None:
                if mbx[5] & 0x0F == 3 and struct.unpack_from("<H", mbx, 6)[0] >> 12 == 1:
                    self.emergencies.append(struct.unpack_from("<H", mbx, 8)[0])
                    continue  # wkc = 0: "prevent emergency to cascade up"; read again
                return mbx
            # read mailbox lost: toggle the repeat request, wait for the acknowledge, wait
            # for the mailbox to be full again
            self.repeats += 1
            smstat ^= 0x0200
            self.fpwr(SM1_STATUS, struct.pack("<H", smstat))
            for _ in range(budget):
                ctl = self.fprd(SM1_PDI, 1)
                if ctl is not None and ctl[0] & 0x02 == (smstat >> 8) & 0x02:
                    break
            for _ in range(budget):
                raw = self.fprd(SM1_STATUS, 2)
                if raw is not None and raw[0] & 0x08:
                    smstat = struct.unpack("<H", raw)[0]
                    break
        return None

    # --- ecx_mbxsend ---------------------------------------------------------------------------
    def mbxsend(self, msg: bytes, budget: int) -> int:
        for _ in range(budget):  # ecx_mbxempty: wait for SM0 to be empty
            raw = self.fprd(SM0_STATUS, 1)
            if raw is not None and not raw[0] & 0x08:
                break
        return self.fpwr(SM0, msg + bytes(SIZE - len(msg)), tries=3)

    # --- ecx_SDOread ---------------------------------------------------------------------------
    def sdo_upload(self, index: int, sub: int) -> int | None:
        """The value, or None where SOEM would report a failed SDO read."""
        self.mbxreceive(budget=1)  # "empty slave out mailbox if something is in", timeout 0
        self.counter = self.counter % 7 + 1
        if self.mbxsend(sdo_upload_request(index, sub, self.counter), budget=50) <= 0:
            return None
        answer = self.mbxreceive(budget=200)
        if answer is None:
            return None
        if answer[5] & 0x0F != 3 or struct.unpack_from("<HB", answer, 9) != (index, sub):
            return None  # "unexpected frame returned"
        assert answer[8] & 0xE0 == 0x40, answer[:16].hex()
        size = 4 - ((answer[8] >> 2) & 3)
        return int.from_bytes(answer[12 : 12 + size], "little")


def preop_chain() -> tuple[Chain, MiniSlave]:
    chain = mini_chain(1)
    esc = chain.escs[0]
    assert esc.write(0x0010, struct.pack("<H", STATION))
    assert esc.write(0x0800, SM.pack(SM0, SIZE, 0x26, 0, 1, 0) + SM.pack(SM1, SIZE, 0x22, 0, 1, 0))
    assert esc.write(0x0120, struct.pack("<H", AlState.PREOP))
    assert esc.slave.al_state == AlState.PREOP
    slave = esc.slave
    assert isinstance(slave, MiniSlave)
    return chain, slave


def test_every_sdo_answer_survives_late_answers_through_the_repeat_request() -> None:
    keys = list(OBJECTS)
    repeats = lost = frames = 0
    for seed in range(12):
        rng = random.Random(seed)
        chain, slave = preop_chain()
        master = LossyMaster(chain, rng, loss=0.3, skip=0.2)
        raised = 0
        for n in range(25):
            if rng.random() < 0.2:  # the slave raises an emergency meanwhile
                slave.emit_emergency(0x8100 + n, 0x11)
                raised += 1
                chain.poll()
            key = keys[rng.randrange(len(keys))]
            got = master.sdo_upload(*key)
            assert got == OBJECTS[key], f"seed {seed}, upload {n} of {key}: {got}"
        # one request executed per upload: a resent SM0 write did not run twice
        uploads = [r for r in slave.requests if r[5] & 0x0F == 3]
        assert len(uploads) == 25, f"seed {seed}"
        assert set(master.emergencies) <= {0x8100 + n for n in range(25)}
        repeats += master.repeats
        lost += master.lost
        frames += master.frames
    assert repeats > 20 and lost > 200, (repeats, lost, frames)  # the repeat path, many times


def test_without_the_repeat_request_a_late_read_loses_the_answer() -> None:
    """What the repeat request is for: a read of SM1 whose answer came late has emptied the
    mailbox, and reading again finds nothing (an ESC frees the buffer when the last byte
    passes), so a master that does not ask for the repeat loses the answer."""
    chain, _slave = preop_chain()
    master = LossyMaster(chain, random.Random(0), loss=0.0, skip=0.0)
    master.counter = 1
    assert master.mbxsend(sdo_upload_request(0x2000, 0, 1), budget=5) == 1
    assert master.fprd(SM1_STATUS, 1)[0] & 0x08  # type: ignore[index]
    master.loss = 1.0
    assert master.fprd(SM1, SIZE) is None  # processed, answer late
    master.loss = 0.0
    assert master.fprd(SM1, SIZE) is None  # empty now: WKC 0
    smstat = struct.unpack("<H", master.fprd(SM1_STATUS, 2) or b"")[0]
    assert not smstat & 0x08
    master.fpwr(SM1_STATUS, struct.pack("<H", smstat ^ 0x0200))
    assert (master.fprd(SM1_PDI, 1) or b"\0")[0] & 0x02 == ((smstat ^ 0x0200) >> 8) & 0x02
    again = master.fprd(SM1, SIZE)
    assert again is not None and struct.unpack_from("<HB", again, 9) == (0x2000, 0)
    assert int.from_bytes(again[12:14], "little") == 0x1234
