"""The readers' C entries beside another thread that lets controller time pass.

On the lockstep and auto clocks a cycle runs in whichever thread lets time pass (GTE_Wait, a
call's host latency), holding the controller's clock lock; the C entries of the readers
(:mod:`gtecat.gt.centry`) answer without it.  The GIL does not make their reads whole: the
interpreter hands it over between any two bytecodes of the other thread's cycle, and the
axis bank's compiled cycle runs without it.  So an entry that finds the lock held by another
thread (or the epoch grown, or the lock taken, while its value function ran) answers again
holding the lock.  Checked here on twelve axes jogging alike, whose values are all equal in
every whole state: a span of GT_GetPrfPos, GT_GetEncPos, and the raw image's 6064h of every
axis.  The cycle is stopped at a point where half the axes (half the slaves) have had it,
and a read made then must wait for its end; then reads hammered beside a thread's cycles.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from ctypes import byref, c_double, c_short, c_ubyte
from pathlib import Path

import pytest

from gtecat import gt
from gtecat.gt import centry

from .conftest import bring_up

ROOT = Path(__file__).resolve().parents[3]
ENI = ROOT / "examples" / "twelve_axes.eni"
AXES = 12

pytestmark = pytest.mark.skipif(
    bool(centry.REASON), reason=f"the readers' C entries are not built here: {centry.REASON}"
)


def _jogging(bank: str) -> None:
    """Twelve axes on a lockstep bus, jogging alike (the same profile from the same cycle)."""
    gt.GT_Close()
    bring_up(str(ENI), clock="lockstep", bank=bank)
    prm = gt.TJogPrm()
    prm.acc, prm.dec, prm.smooth = 0.5, 0.5, 0.0
    for a in range(1, AXES + 1):
        assert gt.GT_AxisOn(a) == 0 and gt.GT_PrfJog(a) == 0
        assert gt.GT_SetJogPrm(a, byref(prm)) == 0 and gt.GT_SetVel(a, 20.0) == 0
    assert gt.GT_Update((1 << AXES) - 1) == 0
    gt.GTE_Wait(3)


def _enc_at() -> list[int]:
    """The GT raw offsets of every axis's 6064h (position actual value)."""
    layout = gt.GTE_Controller().layout
    out = {}
    for sl in layout.slaves:
        for p in sl.entries:
            if p.direction.name == "IN" and p.index & 0x7FF == 0x064 and p.subindex == 0:
                out[(sl.position, p.index)] = p.gt_byte
    assert len(out) == AXES
    return [out[k] for k in sorted(out)]


def _prf() -> tuple[float, ...]:
    v = (c_double * AXES)()
    assert gt.GT_GetPrfPos(1, v, AXES) == 0
    return tuple(v)


def _enc() -> tuple[float, ...]:
    v = (c_double * 8)()
    assert gt.GT_GetEncPos(1, v, 8) == 0
    return tuple(v)


def _raw_enc(at: list[int], size: int) -> tuple[int, ...]:
    raw = (c_ubyte * size)()
    assert gt.GT_GetEcatRawData(0, size, raw) == 0
    b = bytes(raw)
    return tuple(int.from_bytes(b[k : k + 4], "little", signed=True) for k in at)


@contextmanager
def _stopped_cycle(stop_in: Callable[[Callable[[], None]], None]) -> Iterator[threading.Event]:
    """A thread lets one cycle pass (GTE_Wait(1)); ``stop_in(pause)`` puts ``pause`` where the
    cycle must stand still: there it waits until the event yielded is set (at most 5 s)."""
    mid, go = threading.Event(), threading.Event()

    def pause() -> None:
        mid.set()
        go.wait(5)

    stop_in(pause)
    rc: list[int] = []
    t = threading.Thread(target=lambda: rc.append(gt.GTE_Wait(1)), name="cycles")
    t.start()
    try:
        assert mid.wait(5), "the cycle never reached its stop"
        yield go
    finally:
        go.set()
        t.join(10)
    assert rc == [0]


@pytest.fixture
def jogging() -> Iterator[None]:
    _jogging("off")
    yield
    gt.GT_Close()


def _go_soon(go: threading.Event) -> None:
    # (the stopped cycle goes on a moment after the read began: a read that waits for its end
    # sees it whole, one that does not has answered before)
    threading.Timer(0.05, go.set).start()


def test_a_span_read_while_another_thread_is_inside_a_cycle_waits_for_its_end(jogging):
    ctl = gt.GTE_Controller()
    before = _prf()
    assert len(set(before)) == 1
    ax = ctl.axes[7]  # axes 1-6 have had the cycle's profile step, 7-12 not yet
    step = ax.pre

    def stop_in(pause: Callable[[], None]) -> None:
        def pre(t: int, dt: int) -> None:
            pause()
            step(t, dt)

        ax.pre = pre

    try:
        with _stopped_cycle(stop_in) as go:
            _go_soon(go)
            got = _prf()
    finally:
        del ax.pre
    assert len(set(got)) == 1, f"a read of half a cycle: {got}"
    assert got != before and got == _prf()  # (the cycle's end: what a read now gives)


def test_a_raw_read_while_another_thread_is_inside_the_exchange_waits_for_its_end(jogging):
    ctl = gt.GTE_Controller()
    at, size = _enc_at(), ctl.layout.gt_raw_bytes
    before = _raw_enc(at, size)
    assert len(set(before)) == 1
    slave = ctl.backend.slaves[3]  # slaves 0-2 have exchanged, 4-5 not yet
    step = slave.step

    def stop_in(pause: Callable[[], None]) -> None:
        def stepped(t: int, dt: int) -> None:
            pause()
            step(t, dt)

        slave.step = stepped

    try:
        with _stopped_cycle(stop_in) as go:
            _go_soon(go)
            got = _raw_enc(at, size)
    finally:
        del slave.step
    assert len(set(got)) == 1, f"a raw read of half an exchange: {got}"
    assert got != before and got == _raw_enc(at, size)


@pytest.mark.parametrize(
    "bank",
    [
        # (the default run: the bank's, the default; without the bank, a read made in the
        # middle of another thread's cycle waits for its end in the two tests above)
        pytest.param("off", marks=pytest.mark.long("the same reads without the bank")),
        "on",
    ],
)
def test_reads_hammered_beside_a_thread_that_runs_cycles_are_whole(bank):
    """Many reads while another thread runs cycles, the interpreter switching threads as often
    as it can: every span of GT_GetPrfPos, GT_GetEncPos and the raw 6064h is of one state."""
    _jogging(bank)
    try:
        ctl = gt.GTE_Controller()
        at, size = _enc_at(), ctl.layout.gt_raw_bytes
        reading, done = threading.Event(), threading.Event()

        def cycles() -> None:
            try:
                reading.wait(5)
                for k in range(150):
                    assert gt.GTE_Wait(1) == 0
                    if k % 5 == 4:  # (a moment between waits, as an application's loop has)
                        time.sleep(0.0002)
            finally:
                done.set()

        old = sys.getswitchinterval()
        sys.setswitchinterval(1e-6)
        t = threading.Thread(target=cycles, name="cycles")
        reads, torn = 0, []
        try:
            t.start()
            reading.set()
            while not done.is_set():
                for got in (_prf(), _enc(), _raw_enc(at, size)):
                    reads += 1
                    if len(set(got)) != 1:
                        torn.append(got)
        finally:
            sys.setswitchinterval(old)
            t.join(10)
        assert not torn, f"{len(torn)} of {reads} reads were of half a cycle: {torn[:3]}"
        assert reads > 30, reads
        assert len(set(_prf())) == 1 and _prf()[0] > 1000
    finally:
        gt.GT_Close()


@pytest.mark.parametrize("reader", ["GT_GetPrfPos", "GT_GetEncPos"])
def test_a_value_made_before_another_threads_cycles_is_not_kept_past_them(reader):
    """A reader's value function makes the bank's value of its row (the first read since
    a cycle: AxisBank.row_value); right after it is made, another thread runs cycles (forced
    here: the row's maker starts the thread and waits for it).  The read answers again
    holding the lock, and neither it nor the next read may answer from the value made before
    those cycles: both answer the value as those cycles left it (a lockstep clock: no time
    passes after them)."""
    fig = ROOT / "examples" / "manual_fig5_2.eni"
    gt.GT_Close()
    assert gt.GT_Open(eni=str(fig), clock="lockstep", log="", bank="on") == 0
    try:
        assert gt.GT_InitEcatComm() == 0
        ready = c_short()
        for _ in range(200):
            if gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1:
                break
            gt.GTE_Wait(1)
        assert gt.GT_StartEcatComm() == 0 and gt.GT_AxisOn(1) == 0
        prm = gt.TTrapPrm()
        prm.acc = prm.dec = 0.2
        assert gt.GT_PrfTrap(1) == 0 and gt.GT_SetTrapPrm(1, byref(prm)) == 0
        assert gt.GT_SetVel(1, 10.0) == 0 and gt.GT_SetPos(1, 200000) == 0
        assert gt.GT_Update(1) == 0 and gt.GTE_Wait(100) == 0
        res = gt.GTE_Controller().resources[1]
        bank = res.bank
        assert bank is not None
        read = getattr(gt, reader)

        def value() -> float:
            v = c_double()
            assert read(1, byref(v)) == 0
            return v.value

        made, row, other = bank._make_list, bank.row_value, []

        def cycles(name: str) -> None:
            # (the value as the cycles left it, from a list made here and kept nowhere)
            other.append((gt.GTE_Wait(50), float(made(name)[res.bank_row])))

        def make_then_cycles(name: str, r: int) -> float:
            out = row(name, r)
            if not other:
                t = threading.Thread(target=cycles, args=(name,), name="cycles")
                t.start()
                t.join(10)
            return out

        before = value()
        # (a cycle: the values are made again at the next read - by the value function: the
        # wait in Python, whose book the entries do not follow as they follow one in C)
        assert getattr(gt.GTE_Wait, "python", gt.GTE_Wait)(1) == 0
        bank.row_value = make_then_cycles
        try:
            hooked = value()
        finally:
            del bank.row_value
        assert len(other) == 1 and other[0][0] == 0, other
        after = other[0][1]
        assert after > before + 400
        assert (hooked, value()) == (after, after), (before, after)
    finally:
        gt.GT_Close()
