"""Faults injected, listed and cleared from another thread of the application (a watchdog, a
test harness) while the main thread moves the axes and polls them: each change falls whole
between two cycles, and the next cycle is the first to act on it.  No thread sleeps on the
wall clock; the interleaving is the scheduler's, so what is asserted holds in every one."""

from __future__ import annotations

import sys
import threading
from collections.abc import Iterator
from ctypes import byref, c_long
from pathlib import Path

import pytest

from gtecat import faults, gt
from gtecat.faults.record import Recorder, replay

from .conftest import fig5_2_up

ALARM = 1 << 1  # GT_GetSts bit 1 (table 6-2)


@pytest.fixture(autouse=True)
def _switching_often() -> Iterator[None]:
    """The interpreter hands the GIL from thread to thread every 100 microseconds instead of
    every 5 ms: a change that other thread's cycles could cut in two is cut far more often."""
    was = sys.getswitchinterval()
    sys.setswitchinterval(1e-4)
    try:
        yield
    finally:
        sys.setswitchinterval(was)


def _moving() -> None:
    """The figure 5-2 bus, both axes on and in a long Trap move."""
    fig5_2_up()
    for axis in (1, 2):
        assert gt.GT_AxisOn(axis) == 0
        gt.GT_PrfTrap(axis)
        gt.GT_SetPos(axis, 1_000_000)
        gt.GT_SetVel(axis, 5.0)
    assert gt.GT_Update(0b11) == 0


def _alarms() -> tuple[int, tuple[bool, bool]]:
    """(GT_GetClock, the alarm bit of axes 1 and 2) as the application polls them."""
    sts, clock = (c_long * 2)(), c_long()
    gt.GT_GetSts(1, sts, 2, None)
    gt.GT_GetClock(byref(clock))
    return clock.value, (bool(sts[0] & ALARM), bool(sts[1] & ALARM))


def _poll_while(other: threading.Thread, started: threading.Event, limit_ms: int = 60_000) -> list:
    """Poll both axes (the main thread's GT calls: they run the cycles) from before
    ``other`` starts until both alarms are on; every poll that saw an alarm.  (``limit_ms``
    of controller time: a loaded machine may not run the other thread for thousands of
    this thread's polls, each a cycle; what is checked is how the faults start, not when.)"""
    seen = []
    polls = 0
    other.start()
    try:
        while True:
            t, alarms = _alarms()
            if any(alarms):
                seen.append((t, alarms))
                if all(alarms):
                    return seen
            gt.GTE_Wait(1)  # (a cycle each time round: as many as can cut in)
            polls += 1
            if polls == 50:
                started.set()  # (the other thread goes on while this one polls)
            assert t < limit_ms, "the faults never started"
    finally:
        started.set()
        other.join(timeout=60)


def test_a_script_injected_from_another_thread_starts_whole() -> None:
    """Every step of a script starts between the same two cycles: the first poll that sees
    an alarm sees both drives' alarms, and each fault started once, all in one cycle."""
    steps = [
        {"kind": "drive_fault", "axis": 1},
        *({"kind": "switch_stuck", "axis": a, "switch": "home"} for a in (1, 2)),
        {"kind": "encoder_noise", "axis": 1},
        {"kind": "drive_fault", "axis": 2},
    ]
    for _ in range(6):  # (a change cut in two was seen in one round of five or so)
        _moving()
        started = threading.Event()

        def watchdog(started: threading.Event = started) -> None:
            started.wait()
            faults.script(steps)

        seen = _poll_while(threading.Thread(target=watchdog), started)
        assert seen[0][1] == (True, True), seen[:3]
        inj = faults.injector_for(gt.GTE_Controller())
        starts = [(t, fid) for t, what, fid, _ in inj.events if what == "start"]
        assert [fid for _, fid in starts] == [1, 2, 3, 4, 5]  # each once
        assert len({t for t, _ in starts}) == 1, starts  # in one cycle
        gt.GT_Close()


def test_clear_and_listing_from_another_thread_see_one_moment() -> None:
    """A clear of every fault from another thread ends them all in one cycle; a listing from
    there lists what one moment between two cycles holds."""
    _moving()
    ids = faults.script(
        [
            {"kind": "switch_stuck", "axis": 1, "switch": "home"},
            {"kind": "switch_stuck", "axis": 2, "switch": "home"},
        ]
    )
    started = threading.Event()
    listed: list[list[dict]] = []
    ended: list[int] = []

    def harness() -> None:
        started.wait()
        listed.append(faults.listing())
        ended.append(faults.clear())
        listed.append(faults.listing())

    th = threading.Thread(target=harness)
    th.start()
    for _ in range(200):
        _alarms()
        started.set()
        if ended:
            break
    th.join(timeout=60)
    assert ended == [2]
    assert [(f["id"], f["state"]) for f in listed[0]] == [(ids[0], "active"), (ids[1], "active")]
    assert listed[1] == []
    inj = faults.injector_for(gt.GTE_Controller())
    ends = [t for t, what, _, _ in inj.events if what == "end"]
    assert len(ends) == 2 and ends[0] == ends[1]


def _first_alarm_at(at_ms: int, elsewhere: bool) -> int:
    """The GT_GetClock of the first poll that sees axis 1's alarm, for a drive fault armed
    with ``at_ms`` before that time, from the main thread or (``elsewhere``) another one."""
    _moving()
    armed = threading.Event()
    if not elsewhere:
        faults.inject("drive_fault", axis=1, at_ms=at_ms)
        armed.set()
    th = threading.Thread(
        target=lambda: (faults.inject("drive_fault", axis=1, at_ms=at_ms), armed.set())
    )
    if elsewhere:
        th.start()
    try:
        while True:
            t, alarms = _alarms()
            if alarms[0]:
                return t
            if t >= at_ms - 100:
                assert armed.wait(timeout=60)  # (armed before its time, whatever the scheduler did)
    finally:
        if elsewhere:
            th.join(timeout=60)
        gt.GT_Close()


def test_a_fault_at_a_time_starts_then_from_any_thread() -> None:
    """``at_ms`` from another thread: the fault starts at that controller time, as armed
    from the main thread (virtual time decides, not the scheduler)."""
    here = _first_alarm_at(400, elsewhere=False)
    assert 400 <= here <= 402
    assert _first_alarm_at(400, elsewhere=True) == here


def test_a_fault_injected_from_another_thread_replays(tmp_path: Path) -> None:
    """A recording of the main thread's calls holds the fault the watchdog injected where it
    was armed: the replay arms it between the same two cycles and every poll reads again."""
    path = tmp_path / "watchdog.gtrec"
    rec = Recorder(path).start()
    try:
        _moving()
        started = threading.Event()

        def watchdog() -> None:
            started.wait()
            faults.inject("drive_fault", axis=2, code=0x3220)
            faults.inject("drive_fault", axis=1, after_ms=30)

        _poll_while(threading.Thread(target=watchdog), started)
    finally:
        rec.stop()
        gt.GT_Close()
    rec.write()
    n, div = replay(path)
    assert div is None, str(div)
    assert n > 50
