"""The controller keeps the cycles running while a mailbox transfer waits on a wire.

:meth:`Controller._mailbox_transfer` is where the pysoem backend's SDOs wait (the wire
itself: ``tests/gtecat/wire/test_sdo_wire.py``).  Here a transfer that sleeps stands for
one, on the emulated bus: in lockstep (and auto) the calling thread runs one cycle per bus
cycle of wall time while the transfer waits in a worker; in realtime a caller that holds
the cycle lock, as every GT call does, lets go of it, so the cycle thread runs on.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator

import pytest

from gtecat.drives.abort import SdoAbort, SdoAbortCode
from tests.conftest import EXAMPLES

ENI = str(EXAMPLES / "manual_fig5_2.eni")
WAIT_S = 0.06
#: cycles that must run during one transfer to show the cycle lock was let go (held, none
#: would run): a few, not a share of WAIT_S - a loaded machine (a CI neighbour, a test run
#: beside others) makes the cycle thread late, and how late is not what these tests check
MIN_CYCLES = 3


def _controller(clock: str) -> Iterator[object]:
    from gtecat import gt

    gt.GT_Close()
    assert gt.GT_Open(eni=ENI, clock=clock, log="") == 0
    try:
        yield gt.GTE_Controller()
    finally:
        gt.GT_Close()


@pytest.fixture
def lockstep() -> Iterator[object]:
    yield from _controller("lockstep")


@pytest.fixture
def realtime() -> Iterator[object]:
    yield from _controller("realtime")


def _waits(result: object = b"x", error: Exception | None = None):
    """A transfer that takes :data:`WAIT_S` of wall time, in the thread it runs in."""
    seen: list[threading.Thread] = []

    def transfer() -> object:
        seen.append(threading.current_thread())
        time.sleep(WAIT_S)
        if error is not None:
            raise error
        return result

    return transfer, seen


def test_lockstep_runs_a_cycle_per_bus_cycle_of_wall_time(lockstep) -> None:
    ctl = lockstep
    transfer, seen = _waits(b"\x07")
    c0, t0 = ctl.clock.cycles, time.perf_counter()
    assert ctl._mailbox_transfer(transfer) == b"\x07"
    wall_ms = (time.perf_counter() - t0) * 1000
    ran = ctl.clock.cycles - c0
    assert seen[0] is not threading.current_thread()  # the transfer waited in a worker
    # one cycle per millisecond of wall time (those a busy machine made late are skipped)
    assert MIN_CYCLES <= ran <= wall_ms + 1, (ran, wall_ms)
    assert ctl.clock.now_ns == ctl.clock.cycles * ctl.clock.cycle_ns


def test_lockstep_raises_what_the_transfer_raised_after_its_cycles(lockstep) -> None:
    ctl = lockstep
    abort = SdoAbort(SdoAbortCode.SDO_PROTOCOL_TIMED_OUT, 0x6067, 0, "no answer")
    transfer, _ = _waits(error=abort)
    c0 = ctl.clock.cycles
    with pytest.raises(SdoAbort) as e:
        ctl._mailbox_transfer(transfer)
    assert e.value is abort
    assert ctl.clock.cycles - c0 >= MIN_CYCLES


def test_lockstep_inside_a_cycle_runs_the_transfer_alone(lockstep) -> None:
    ctl = lockstep
    transfer, seen = _waits()
    c0 = ctl.clock.cycles
    ctl.cycling = True  # (an SDO a hook of the cycle makes)
    try:
        assert ctl._mailbox_transfer(transfer) == b"x"
    finally:
        ctl.cycling = False
    assert ctl.clock.cycles == c0 and seen[0] is threading.current_thread()


def test_realtime_lets_go_of_the_cycle_lock_while_the_transfer_waits(realtime) -> None:
    ctl = realtime
    transfer, seen = _waits()
    with ctl.clock.lock, ctl.clock.lock:  # (a GT call, perhaps one inside another)
        c0 = ctl.clock.cycles
        assert ctl._mailbox_transfer(transfer) == b"x"
        ran = ctl.clock.cycles - c0
        assert ctl.clock.lock._is_owned()  # held again, as before
        time.sleep(0.01)
        assert ctl.clock.cycles - c0 == ran  # (and no cycle runs while it is held)
    assert seen[0] is threading.current_thread()
    assert ran >= MIN_CYCLES, ran
