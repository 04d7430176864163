"""The readers' C entries keep a value for its epoch (gtecat/controller/epoch.py): what they
answer after every kind of change - cycles, calls of the table path, a fault, a raw write,
the session - is the Python fast function's answer, asked afresh; a value they keep is
written again only while nothing that changes it has happened.  Figure 5-2's bus (manual
section 5, figure 5-2), lockstep clock."""

from __future__ import annotations

import ctypes
from collections.abc import Callable
from ctypes import byref
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from gtecat import faults, gt
from gtecat.controller.epoch import EPOCH, changed
from gtecat.gt import centry

from .conftest import bring_up

ENI = Path(__file__).resolve().parents[3] / "examples" / "manual_fig5_2.eni"
pytestmark = pytest.mark.skipif(bool(centry.REASON), reason=f"no C entry: {centry.REASON}")

#: (function, the arguments before the value's pointer, the value's type)
READS: list[tuple[str, tuple, type]] = [
    ("GT_GetSts", (1,), ctypes.c_long),
    ("GT_GetSts", (2,), ctypes.c_int32),
    ("GT_GetPrfPos", (1,), ctypes.c_double),
    ("GT_GetPrfVel", (1,), ctypes.c_double),
    ("GT_GetEncPos", (1,), ctypes.c_double),
    ("GT_GetAxisError", (1,), ctypes.c_double),
    ("GT_GetPrfMode", (1,), ctypes.c_long),
    ("GT_GetEcatEncPos", (1,), ctypes.c_long),
    ("GT_GetEcatErrorCode", (1,), ctypes.c_ushort),
    ("GT_GetEcatHomingStatus", (1,), ctypes.c_short),
    ("GT_GetDi", (0,), ctypes.c_long),  # MC_LIMIT_POSITIVE
    ("GT_GetDi", (3,), ctypes.c_long),  # MC_HOME
]


def _open(**options: str) -> Any:
    bring_up("manual_fig5_2.eni", clock="lockstep", **options)
    assert gt.GT_AxisOn(1) == 0
    assert gt.GT_AxisOn(2) == 0
    gt.GTE_Wait(10)
    return gt.GTE_Controller()


def _answers(kept: bool) -> list[Any]:
    """Every reader's (code, value) through its public function (the C entry, called twice:
    the second answer the kept one) or, ``kept`` False, its Python fast function."""
    out = []
    for name, before, tp in READS:
        fn = getattr(gt, name)
        for call in (fn, fn) if kept else (getattr(fn, "python", fn),):
            o = tp()
            rc = call(*before, byref(o))
            out.append((name, before, rc, o.value))
        if kept and out[-1] != out[-2]:
            raise AssertionError(f"{name}{before}: kept {out[-1]}, asked {out[-2]}")
        if kept:
            out.pop()
    arr, clk = (ctypes.c_long * 2)(), ctypes.c_ulong()
    for call in (gt.GT_GetSts, gt.GT_GetSts) if kept else (gt.GT_GetSts.python,):
        rc = call(1, arr, 2, byref(clk))
        got = ("span", rc, list(arr), clk.value)
    out.append(got)
    trap = gt.TTrapPrm()
    rc = (gt.GT_GetTrapPrm if kept else gt.GT_GetTrapPrm.python)(1, byref(trap))
    out.append(("trap", rc, bytes(trap)))
    clk = ctypes.c_ulong()
    rc = (gt.GT_GetClock if kept else gt.GT_GetClock.python)(byref(clk))
    out.append(("clock", rc, clk.value))
    return out


def _trap_move() -> None:
    prm = gt.TTrapPrm()
    prm.acc, prm.dec = 0.5, 0.5
    assert gt.GT_PrfTrap(1) == 0
    assert gt.GT_SetTrapPrm(1, byref(prm)) == 0
    assert gt.GT_SetVel(1, 10) == 0
    assert gt.GT_SetPos(1, 40_000) == 0
    assert gt.GT_Update(1) == 0


#: each change a reader's kept value must not outlive (manual chapter 13's calls; a fault)
CHANGES: list[tuple[str, Callable[[], Any]]] = [
    ("a Trap move started", _trap_move),
    ("cycles", lambda: gt.GTE_Wait(7)),
    ("one more cycle", lambda: gt.GTE_Wait(1)),
    ("a stop", lambda: gt.GT_Stop(1, 0)),
    ("cycles after the stop", lambda: gt.GTE_Wait(40)),
    ("positions zeroed", lambda: gt.GT_ZeroPos(1)),
    ("a drive fault", lambda: faults.inject("drive_fault", axis=1, code=0x2310)),
    ("cycles with the fault", lambda: gt.GTE_Wait(5)),
    ("the fault cleared", lambda: faults.clear()),
    ("the status cleared", lambda: gt.GT_ClrSts(1)),
    ("a limit stuck", lambda: faults.inject("switch_stuck", axis=1, switch="positive", value=1)),
    ("cycles with the limit", lambda: gt.GTE_Wait(3)),
    ("a refused call", lambda: gt.GT_GetSts(99, byref(ctypes.c_long()))),
    ("servo off", lambda: gt.GT_AxisOff(2)),
    ("cycles", lambda: gt.GTE_Wait(4)),
]


def test_every_change_is_seen_as_the_python_path_sees_it() -> None:
    _open()
    try:
        assert _answers(True) == _answers(False)
        for what, change in CHANGES:
            change()
            assert _answers(True) == _answers(False), what
    finally:
        faults.clear()
        gt.GT_Close()


def test_the_epoch_grows_at_each_kind_of_change() -> None:
    ctl = _open()
    try:
        s = ctypes.c_long()
        steps: list[tuple[str, Callable[[], Any]]] = [
            ("a cycle", lambda: gt.GTE_Wait(1)),
            ("a table call", lambda: gt.GT_ClrSts(1)),
            ("a raw write", lambda: gt.GT_SetEcatRawData(0, 1, (ctypes.c_ubyte * 1)())),
            ("a fault", lambda: faults.inject("switch_stuck", axis=1, switch="home", value=1)),
            ("a fault cleared", lambda: faults.clear()),
            ("the controller's own cycle", ctl.clock.cycle),
        ]
        for what, step in steps:
            gt.GT_GetSts(1, byref(s))
            before = EPOCH.n
            step()
            assert EPOCH.n > before, what
        before = EPOCH.n
        for _ in range(3):  # (reads change nothing)
            assert gt.GT_GetSts(1, byref(s)) == 0
            gt.GT_GetPrfPos(1, byref(ctypes.c_double()))
        assert EPOCH.n == before
    finally:
        faults.clear()
        gt.GT_Close()


def test_a_kept_value_is_written_again_until_the_epoch_grows() -> None:
    """A change made by hand to the controller's objects (not a GT call, not a cycle) is not
    seen by the C entry until :func:`changed`; the Python function sees it at once (an axis
    the bank does not run: its latched flags are read where they are set here)."""
    ctl = _open(bank="off")
    try:
        res = ctl.resources[2]
        s = ctypes.c_long()
        assert gt.GT_GetSts(2, byref(s)) == 0
        word = s.value
        kept = res.latched
        res.latched = kept | 0x40  # (a made-up latched flag)
        try:
            assert gt.GT_GetSts(2, byref(s)) == 0 and s.value == word
            assert gt.GT_GetSts.python(2, byref(s)) == 0 and s.value == word | 0x40
            changed()
            assert gt.GT_GetSts(2, byref(s)) == 0 and s.value == word | 0x40
        finally:
            res.latched = kept
            changed()
    finally:
        gt.GT_Close()


def test_last_error_is_cleared_by_a_kept_read() -> None:
    """GTE_GetLastError speaks of the latest call: a refused call, then a read the C entry
    answers from what it kept, leaves no error."""
    _open()
    try:
        s = ctypes.c_long()
        assert gt.GT_GetSts(1, byref(s)) == 0
        assert gt.GT_GetSts(1, byref(s)) == 0
        assert gt.GT_SetPos(99, 5) != 0
        assert gt.GTE_GetLastError()
        assert gt.GT_GetSts(1, byref(s)) == 0
        assert gt.GTE_GetLastError() in ("", None)
    finally:
        gt.GT_Close()


def test_a_polling_loop_in_the_auto_clock_sees_the_move() -> None:
    """The default clock: each read costs its host latency and cycles run inside reads; a
    loop polling GT_GetPrfPos and GT_GetSts through the C entries sees the move go on and end
    (manual section 13: GT_GetSts' motion bit, GT_GetPrfPos)."""
    bring_up("manual_fig5_2.eni", clock="auto")
    try:
        assert gt.GT_AxisOn(1) == 0
        _trap_move()
        pos, sts = ctypes.c_double(), ctypes.c_long()
        seen = set()
        for _ in range(200_000):
            assert gt.GT_GetPrfPos(1, byref(pos)) == 0
            seen.add(pos.value)
            assert gt.GT_GetSts(1, byref(sts)) == 0
            if not sts.value & 0x400 and pos.value == 40_000:
                break
        assert pos.value == 40_000 and not sts.value & 0x400
        assert len(seen) > 10
    finally:
        gt.GT_Close()


def test_gt_is_ecat_ready_answers_as_the_table_through_a_bring_up() -> None:
    """Manual example 5-5's loop: GT_IsEcatReady polled from GT_InitEcatComm to OP, and
    through a link loss, answers as its table path does, call by call (the status and the
    code; 1 with its reason before GT_InitEcatComm)."""
    assert gt.GT_Open(eni=str(ENI), clock="lockstep", log="") == 0
    try:

        def both() -> tuple:
            out = []
            for call in (gt.GT_IsEcatReady, gt.GT_IsEcatReady.slow):
                s, a = ctypes.c_short(7), np.full(2, 7, np.int16)
                rc = call(byref(s))
                got = [rc, s.value, gt.GTE_GetLastError() if rc else ""]
                rc = call(a)  # (a numpy array: its first element)
                out.append((*got, rc, list(a), gt.GTE_GetLastError() if rc else ""))
            return tuple(out)

        a, b = both()
        assert a == b and a[0] != 0
        assert gt.GT_InitEcatComm() == 0
        seen = set()
        for _ in range(80):
            gt.GTE_Wait(1)
            a, b = both()
            assert a == b
            seen.add(a[1])
        assert seen == {0, 1}
        faults.inject("link_down", after_slave=0)
        gt.GTE_Wait(3)
        a, b = both()
        assert a == b and a[1] == 0
        extra = [
            gt.GT_IsEcatReady(byref(ctypes.c_short()), 0),
            gt.GT_IsEcatReady.slow(byref(ctypes.c_short()), 0),
        ]
        assert extra[0] == extra[1] != 0  # (an argument too many: the table's refusal)
    finally:
        faults.clear()
        gt.GT_Close()


def _buffers(b: bytes) -> list[Any]:
    """``b`` in each kind of buffer a raw write takes through its C entry."""
    return [
        bytes(b),
        (ctypes.c_ubyte * len(b))(*b),
        np.frombuffer(b, np.uint8).copy(),
        memoryview(bytearray(b)),
        memoryview(bytes(b)),  # (read only: a write takes it)
    ]


def test_a_raw_write_grows_the_epoch_only_where_it_changes_the_image() -> None:
    """A raw write of the bytes the image holds changes nothing a reader reads: the epoch
    stays (what the readers kept stands); a write that changes a byte makes it grow and
    reaches the slave in the next cycle (figure 5-2: slave 2's DO at raw offset 32, manual
    5.2.2.5)."""
    _open()
    try:
        io = gt.GTE_Slave(2)
        s = ctypes.c_long()
        for src in [bytes([0x5A, 0xA5]), bytes([0x5A, 0x01]), bytes([0, 0])]:
            for j, buf in enumerate(_buffers(src)):
                gt.GT_GetSts(1, byref(s))
                before = EPOCH.n
                assert gt.GT_SetEcatRawData(32, 2, buf) == 0
                assert (EPOCH.n > before) == (j == 0), (src, j)  # (new bytes the first time)
                got = (ctypes.c_ubyte * 2)()
                assert gt.GT_GetEcatRawData(32, 2, got) == 0 and bytes(got) == src
                gt.GT_GetSts(1, byref(s))
                before = EPOCH.n
                assert gt.GT_SetEcatRawData(32, 2, buf) == 0  # (the same bytes again)
                assert gt.GT_EcatIOWriteOutput(2, 0, 2, buf) == 0
                assert EPOCH.n == before
            assert gt.GTE_Wait(1) == 0
            assert bytes(io.field_outputs[:2]) == src
    finally:
        gt.GT_Close()


def test_a_changing_raw_write_grows_the_epoch_by_one_in_c() -> None:
    """A raw write that changes the image makes the epoch grow by exactly one, as
    :func:`changed` would, without calling Python (the entry grows it itself); a write of
    the bytes the image holds leaves it.  Every writer of figure 5-2's DO (slave 2, raw
    offset 32; manual 5.2.2.5), the bytes read back after each write."""
    import sys

    _open()
    calls: list[str] = []

    def watch(frame: Any, event: str, arg: Any) -> None:
        if event == "call" and frame.f_code is changed.__code__:
            calls.append(event)

    def raw(k: int) -> int:
        return gt.GT_SetEcatRawData(32, 2, (ctypes.c_ubyte * 2)(k, 0))

    def word(k: int) -> int:
        return gt.GT_EcatIOWriteOutput(2, 0, 2, byref(ctypes.c_ushort(k)))

    def bit(k: int) -> int:
        return gt.GT_EcatIOBitWriteOutput(2, 0, 0, k & 1)

    got = (ctypes.c_ubyte * 2)()
    try:
        for write in (raw, word, bit):
            for k in (0, 1, 1, 2, 3, 3, 0, 0):
                assert gt.GT_GetEcatRawData(32, 2, got) == 0
                was = bytes(got)
                before = EPOCH.n
                sys.setprofile(watch)
                try:
                    rc = write(k)
                finally:
                    sys.setprofile(None)
                assert rc == 0, gt.GTE_GetLastError()
                assert gt.GT_GetEcatRawData(32, 2, got) == 0
                want = bytes([k & 1 if write is bit else k, 0])
                assert bytes(got) == want, (write.__name__, k)
                assert EPOCH.n == before + (want != was), (write.__name__, k, was, want)
                assert calls == [], f"{write.__name__}: the epoch's changed() was called"
    finally:
        gt.GT_Close()


def test_raw_writes_in_the_auto_clock_reach_the_slave_in_the_next_cycle() -> None:
    """The default clock, cycles run inside the calls (the armed quick cycle among them): a
    loop writing the IO slave's outputs, the same bytes several times and then new ones, and
    polling GT_GetSts between, finds at every cycle the slave driving the bytes written
    before it (figure 5-2: slave 2's DO at raw offset 32)."""
    bring_up("manual_fig5_2.eni", clock="auto")
    try:
        assert gt.GT_AxisOn(1) == 0
        gt.GTE_Wait(5)
        ctl = gt.GTE_Controller()
        io = gt.GTE_Slave(2)
        s = ctypes.c_long()
        seen = 0
        written = bytes(2)
        cycles = ctl.clock.cycles
        for k in range(3_000):
            if k % 37 == 0:
                written = bytes([k % 251, (k // 37) % 7])
            buf = _buffers(written)[k % 5]
            for j in range(1 + k % 3):  # (the write, then 0 to 2 polls)
                rc = gt.GT_SetEcatRawData(32, 2, buf) if j == 0 else gt.GT_GetSts(1, byref(s))
                assert rc == 0
                if ctl.clock.cycles != cycles:  # (its latency ran a cycle)
                    cycles = ctl.clock.cycles
                    seen += 1
                    assert bytes(io.field_outputs[:2]) == written, (k, seen)
        assert seen > 200
    finally:
        gt.GT_Close()
