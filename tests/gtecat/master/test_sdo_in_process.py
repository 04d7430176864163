"""The in-process backend serves an expedited SDO download (the bring-up's InitCmds, 17 per
drive) by the slave's SDO server directly when nothing sees the frames: the same object
dictionary, counters and aborts as the same download framed through the mailbox; an
expedited upload (a controller reading an unmapped object every cycle) likewise."""

from __future__ import annotations

from typing import Any

import pytest

from gtecat.drives.abort import SdoAbort
from gtecat.drives.sdo_server import SdoServer
from gtecat.eni.layout import build_layout
from gtecat.eni.reader import read_eni
from gtecat.master.backends.emulated import EmulatedBackend
from gtecat.master.bus import Master
from tests.conftest import EXAMPLES


class _Frames:
    """A capture of the mailbox frames: its presence sends every download through them."""

    def __init__(self) -> None:
        self.frames = 0

    def mailbox(self, position: int, request: bytes, answer: bytes | None) -> None:
        self.frames += 1

    def __getattr__(self, name: str) -> Any:
        return lambda *args, **kw: None  # the cycles' frames, the scan: not looked at


#: (slave, index, subindex, data, complete access): writes that take and writes refused
DOWNLOADS = [
    (0, 0x6060, 0, b"\x08", False),
    (0, 0x6065, 0, (1234).to_bytes(4, "little"), False),
    (1, 0x607D, 1, (-5000).to_bytes(4, "little", signed=True), False),
    (0, 0x6041, 0, b"\x00\x00", False),  # read-only
    (0, 0x5FFE, 0, b"\x01", False),  # no such object
    (1, 0x6060, 7, b"\x01", False),  # no such subindex
    (0, 0x1600, 1, (0x60400010).to_bytes(4, "little"), False),  # mapping, not in SAFEOP
    (1, 0x6065, 0, b"\x01\x02\x03", False),  # a length the object does not have
]


def _bus(frames: bool, eni: str = "manual_fig5_2.eni") -> tuple[EmulatedBackend, Master, Any]:
    backend = EmulatedBackend()
    cap = _Frames() if frames else None
    backend.capture = cap
    master = Master(build_layout(read_eni(EXAMPLES / eni)), backend, op_delay_cycles=0)
    master.open()  # the InitCmds: through the frames, or not
    return backend, master, cap


def _outcome(backend: EmulatedBackend, args: tuple) -> Any:
    try:
        backend.sdo_download(*args)
    except SdoAbort as e:
        return ("abort", int(e.code), e.index, e.subindex, str(e))
    return "ok"


@pytest.fixture
def served(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """One entry per mailbox request a slave's SDO server answers from now on."""
    seen: list[int] = []
    handle = SdoServer.handle

    def counting(self: SdoServer, message: bytes, al_state: Any = None) -> Any:
        seen.append(1)
        return handle(self, message, al_state) if al_state is not None else handle(self, message)

    monkeypatch.setattr(SdoServer, "handle", counting)
    return seen


def test_an_unframed_download_is_the_framed_one(served: list[int]) -> None:
    framed, fm, cap = _bus(frames=True)
    served.clear()  # (the framed bring-up's)
    direct, dm, _ = _bus(frames=False)
    assert not served  # the bring-up's InitCmds went to the servers directly
    assert cap is not None and cap.frames > 0
    for s in range(2):
        assert direct.slaves[s].od.upload(0x1600, 1) == framed.slaves[s].od.upload(0x1600, 1)
    got = []
    for slave, index, sub, data, ca in DOWNLOADS:
        a = _outcome(framed, (slave, index, sub, data, ca))
        b = _outcome(direct, (slave, index, sub, data, ca))
        assert a == b, (hex(index), sub)
        got.append(a)
    assert got.count("ok") == 3 and len(got) > 6
    for s in range(2):
        for index, sub in ((0x6060, 0), (0x6065, 0), (0x607D, 1)):
            assert dm.sdo_upload(s, index, sub) == fm.sdo_upload(s, index, sub)
        assert direct._clients[s].counter == framed._clients[s].counter
        assert direct.slaves[s].sdo.counter == framed.slaves[s].sdo.counter


def test_a_coe_io_slave_too() -> None:
    framed, fm, _ = _bus(True, "manual_fig5_4.eni")  # the coupler has a mailbox
    direct, dm, _ = _bus(False, "manual_fig5_4.eni")
    outcomes = []
    for index, sub, data in (
        (0x7010, 1, b"\x5a\x00"),
        (0x6000, 1, b"\x01\x00"),
        (0x8000, 1, b"\x01"),
    ):
        a = _outcome(framed, (0, index, sub, data, False))
        assert a == _outcome(direct, (0, index, sub, data, False))
        outcomes.append(a)
    assert outcomes[0] == "ok" and outcomes[2][0] == "abort"
    assert dm.sdo_upload(0, 0x7010, 1) == fm.sdo_upload(0, 0x7010, 1) == b"\x5a\x00"
    assert direct._clients[0].counter == framed._clients[0].counter


#: (slave, index, subindex): reads that answer (1, 2 and 4 bytes), and reads refused
UPLOADS = [
    (0, 0x6041, 0),
    (0, 0x6061, 0),
    (1, 0x6064, 0),
    (0, 0x60B9, 0),  # the touch probe's status, read every cycle by a homing on the index
    (0, 0x1008, 0),  # a string: segmented, framed either way
    (0, 0x1600, 0),
    (0, 0x5FFE, 0),  # no such object
    (1, 0x6060, 7),  # no such subindex
]


def _upload(backend: EmulatedBackend, args: tuple) -> Any:
    try:
        return backend.sdo_upload(*args)
    except SdoAbort as e:
        return ("abort", int(e.code), e.index, e.subindex, str(e))


def test_an_unframed_upload_is_the_framed_one(served: list[int]) -> None:
    framed, _, cap = _bus(frames=True)
    direct, _, _ = _bus(frames=False)
    got = []
    for slave, index, sub in UPLOADS:
        before = len(served)
        a = _upload(framed, (slave, index, sub))
        framed_count = len(served) - before
        before = len(served)
        b = _upload(direct, (slave, index, sub))
        direct_count = len(served) - before
        assert a == b, (hex(index), sub)
        assert framed_count >= 1
        # 1 to 4 bytes go to the server directly; the rest is framed on both buses
        assert direct_count == (0 if isinstance(b, bytes) and len(b) <= 4 else framed_count)
        got.append(b)
    assert [isinstance(g, bytes) for g in got] == [True] * 6 + [False] * 2
    assert len(got[4]) > 4  # the string really took the segmented path
    for s in range(2):
        assert direct._clients[s].counter == framed._clients[s].counter
        assert direct.slaves[s].sdo.counter == framed.slaves[s].sdo.counter
    assert cap is not None and cap.frames > 0


#: (index, subindex, value, size) written to slave 0 in one call of the master, in order:
#: a drive homing's five parameters, then runs that one refused download ends
VALUE_RUNS = [
    [
        (0x6098, 0, 35, 1),
        (0x6099, 1, 20000, 4),
        (0x6099, 2, 2000, 4),
        (0x609A, 0, 150000, 4),
        (0x607C, 0, -5, 4),
    ],
    # a reserved method in the middle: 609Ah stays as it was
    [(0x6099, 1, 7, 4), (0x6098, 0, 15, 1), (0x609A, 0, 9, 4)],
    # values the objects read otherwise (-1 as UINT32, 0xFFFFFFFF as INT32), then a size
    # 6065h does not have
    [(0x6099, 2, -1, 4), (0x607C, 0, 0xFFFFFFFF, 4), (0x6065, 0, 5, 2), (0x609A, 0, 1, 4)],
    [(0x6041, 0, 1, 2), (0x609A, 0, 2, 4)],  # read-only first
    [(0x609A, 0, 3, 4), (0x5FFE, 0, 1, 1), (0x609A, 0, 4, 4)],  # no such object
    [(0x609A, 0, 5, 4), (0x6099, 9, 1, 4)],  # no such subindex
    [(0x609A, 0, 6, 4), (0x1600, 1, 0x60400010, 4)],  # a mapping, not writable now
    [(0x6098, 0, -3, 1), (0x609A, 0, 7, 4)],  # a method no table has
    # not one expedited download each (a subindex out of its byte): the rest one by one
    [(0x609A, 0, 8, 4), (0x6099, 0x100, 1, 4), (0x6099, 1, 9, 4)],
]
_OBJECTS = [(0x6098, 0), (0x6099, 1), (0x6099, 2), (0x609A, 0), (0x607C, 0), (0x6065, 0)]


def _values_outcome(master: Master, items: list) -> Any:
    try:
        master.sdo_download_values(0, items)
    except SdoAbort as e:
        return ("abort", int(e.code), e.index, e.subindex, str(e))
    except Exception as e:  # (whatever the framed path raises: the same)
        return (type(e).__name__, str(e))
    return "ok"


def test_downloads_of_values_in_one_call_are_the_framed_downloads(served: list[int]) -> None:
    """Master.sdo_download_values: each value one download as the framed bus sends its bytes
    one by one - the same objects, both sides' counters, the steady() marker moved, and the
    first refusal's abort ending the run (the downloads after it not sent)."""
    framed, fm, _ = _bus(frames=True)
    direct, dm, _ = _bus(frames=False)
    got = []
    for items in VALUE_RUNS:
        marker = direct._mailbox_ops
        served.clear()
        a = _values_outcome(fm, items)
        framed_served = len(served)
        served.clear()
        b = _values_outcome(dm, items)
        assert a == b, items
        got.append(b)
        assert framed_served >= 1
        if all(sub <= 0xFF for _, sub, _, _ in items):  # (each to the server directly)
            assert not served, items
        assert direct._mailbox_ops != marker
        for index, sub in _OBJECTS:
            assert dm.sdo_upload(0, index, sub) == fm.sdo_upload(0, index, sub), hex(index)
        assert direct._clients[0].counter == framed._clients[0].counter
        assert direct.slaves[0].sdo.counter == framed.slaves[0].sdo.counter
        if items is VALUE_RUNS[1]:  # the one after the refused method not sent
            assert direct.slaves[0].channel(0).homing_speed_switch == 7
            assert direct.slaves[0].channel(0).homing_acceleration == 150000
    assert got[0] == "ok"
    assert [g[1:4] for g in got[1:8]] == [
        (0x06090030, 0x6098, 0),  # 15 is not one of the drive's methods
        (0x06070013, 0x6065, 0),  # 2 bytes for a UINT32
        (0x06010002, 0x6041, 0),
        (0x06020000, 0x5FFE, 0),
        (0x06090011, 0x6099, 9),
        (0x08000022, 0x1600, 1),
        (0x06090030, 0x6098, 0),
    ]
    assert got[-1][0] == "FormatFieldError"  # (what the framed download of subindex 256 raises)
    assert dm.sdo_upload(0, 0x609A, 0) == (8).to_bytes(4, "little")  # the one before it
    assert dm.sdo_upload(0, 0x6099, 2) == b"\xff\xff\xff\xff"
    assert dm.sdo_upload(0, 0x607C, 0) == b"\xff\xff\xff\xff"
