"""Faults and the controller's many-cycles-at-once path.

The same session (two drives, lockstep clock) runs three ways: as it comes (cycles at once
up to the next trigger, the axis bank running the axes no trigger watches), one cycle at a
time (the clock's batch path off) and without the axis bank.  Every trigger kind must fire,
and every duration end, in the same cycle all three ways, and the axes must end where they
did.  A session whose faults were cleared runs its cycles as many at once as one that never
had any (counted by the bank, not timed).
"""

from __future__ import annotations

from ctypes import byref, c_double, c_long, c_short, c_ubyte, c_uint32

from gtecat import faults, gt
from tests.conftest import EXAMPLES

ALARM = 1 << 1


def _up(bank: str = "auto") -> object:
    assert (
        gt.GT_Open(eni=str(EXAMPLES / "manual_fig5_2.eni"), clock="lockstep", log="", bank=bank)
        == 0
    )
    assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
    st = c_short()
    for _ in range(300):
        if gt.GT_IsEcatReady(byref(st)) == 0 and st.value == 1:
            break
        gt.GTE_Wait(1)
    assert gt.GT_StartEcatComm() == 0
    assert gt.GT_Reset() == 0
    for a in (1, 2):
        assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(20)
    return gt.GTE_Controller()


def _trap(axis: int, pos: int, vel: float = 20) -> int:
    prm = gt.TTrapPrm()
    prm.acc = prm.dec = 0.5
    assert gt.GT_PrfTrap(axis) == 0
    assert gt.GT_SetTrapPrm(axis, byref(prm)) == 0
    assert gt.GT_SetPos(axis, pos) == 0
    assert gt.GT_SetVel(axis, vel) == 0
    return gt.GT_Update(1 << (axis - 1))


def _session(way: str) -> tuple[list, list]:
    """What happened (fault events with their cycle) and where the axes ended."""
    ctl = _up("off" if way == "no bank" else "auto")
    if way == "one at a time":
        ctl.clock.run_many = None
    t = c_long()
    gt.GT_GetClock(byref(t))
    t0 = t.value
    # time triggers a little off the cycle grid, a count, a duration, an SDO, a position
    faults.inject("encoder_noise", axis=2, counts=3, at_ms=t0 + 123.4, duration_ms=37.3)
    faults.inject("switch_stuck", axis=2, switch="negative", after_ms=55.5, duration_ms=10)
    faults.inject("encoder_lost", axis=2, counts=5, after_cycles=77)
    faults.inject("mailbox_abort", slave=0, index=0x6081, code=0x06090031, on_sdo=[0, 0x6081, 2])
    faults.inject("drive_fault", axis=1, code=0x2310, when_position=[1, 3000])
    gt.GTE_Wait(300)
    data, abort = (c_ubyte * 4)(1, 0, 0, 0), c_uint32()
    for _ in range(2):
        gt.GT_EcatSDODownload(0, 0x6081, 0, data, 4, byref(abort))
        gt.GTE_Wait(7)
    rcs = [_trap(1, 10_000), _trap(2, -5_000)]  # axis 2: its limit latched (bit 6) refuses
    gt.GTE_Wait(1500)
    inj = faults.injector_for(ctl)
    cycle = ctl.clock.cycle_ns / 1e6
    events = [(round(ms / cycle), what, ident) for ms, what, ident, _ in inj.events]
    ends = []
    for a in (1, 2):
        p, s = c_double(), c_long()
        gt.GT_GetEncPos(a, byref(p))
        gt.GT_GetSts(a, byref(s))
        ends.append((p.value, s.value))
    gt.GT_Close()
    return events, ends + rcs


def test_every_trigger_fires_in_the_same_cycle_batched_or_not() -> None:
    fast = _session("batched")
    assert {e[1:] for e in fast[0]} >= {("start", i) for i in range(1, 6)}
    assert fast[1][0][1] & ALARM  # the position trigger's drive fault
    assert fast == _session("one at a time")
    assert fast == _session("no bank")


def _batched_cycles(ctl, ms: int) -> tuple[int, int]:
    """(cycles run, cycles the bank ran at once) over a wait of ``ms``."""
    c0, b0 = ctl.clock.cycles, ctl.bank.many_cycles
    gt.GTE_Wait(ms)
    return ctl.clock.cycles - c0, ctl.bank.many_cycles - b0


def test_a_cleared_fault_leaves_the_session_as_fast_as_none() -> None:
    ctl = _up()
    plain = _batched_cycles(ctl, 2000)
    assert plain[1] == plain[0]  # idle servo-on axes: every cycle in a batch
    faults.inject("drive_fault", axis=1, code=0x2310, at_ms=1e9)
    assert _batched_cycles(ctl, 2000) == plain  # armed far ahead: batches up to it
    faults.clear()
    assert _batched_cycles(ctl, 2000) == plain
    faults.inject("drive_fault", axis=1, code=0x2310)  # started at once, then cleared
    gt.GTE_Wait(5)
    faults.clear()
    assert gt.GT_ClrSts(1, 1) == 0 and gt.GT_AxisOn(1) == 0
    gt.GTE_Wait(50)
    assert _batched_cycles(ctl, 2000) == plain
    # a time trigger: cycles at once up to it; its drive fault takes axis 2 off the bank
    # while the drive reacts and the alarm latches, then the axis rests in the bank again
    # (servo off, its drive in FAULT, the alarm latched): cycles at once again
    t = c_long()
    gt.GT_GetClock(byref(t))
    faults.inject("drive_fault", axis=2, code=0x2310, at_ms=t.value + 700)
    run, many = _batched_cycles(ctl, 2000)
    assert run == 2000 and 1900 <= many < 2000
    assert faults.listing()[0]["state"] == "active"
    assert not ctl._run_axes and ctl.bank.n_frz == 1
    s = c_long()
    assert gt.GT_GetSts(2, byref(s)) == 0 and s.value & ALARM  # read through the bank


def test_a_position_trigger_keeps_every_axis_on_the_bank_while_it_waits() -> None:
    ctl = _up()
    gt.GTE_Wait(5)
    assert not ctl._run_axes
    faults.inject("drive_fault", axis=1, code=0x2310, when_position=[1, 3000])
    gt.GTE_Wait(5)
    assert not ctl._run_axes and ctl.bank.held == frozenset()  # the watched axis too
    assert _trap(1, 10_000) == 0
    b0 = ctl.bank.many_cycles
    for _ in range(1000):
        gt.GTE_Wait(1)
        if faults.listing()[0]["state"] == "active":
            break
    assert ctl.bank.many_cycles - b0 > 50  # the bank's compiled cycles, up to the one before
    gt.GTE_Wait(5)
    assert 2 not in [ax.number for ax in ctl._run_axes]
    assert ctl.bank.held == frozenset()
    # a position far off: the mechanics cannot get there in a run of cycles, so the runs
    # are as long as without it, and a link loss armed so keeps every axis on the bank too
    faults.clear()
    assert gt.GT_ClrSts(1, 2) == 0 and gt.GT_AxisOn(1) == 0
    gt.GTE_Wait(50)
    plain = _batched_cycles(ctl, 2000)
    assert plain[0] == plain[1]
    faults.inject("link_down", after_slave=0, when_position=[2, 1e9])
    assert _batched_cycles(ctl, 2000) == plain
    assert faults.listing()[0]["state"] == "armed"


def _resting_session(way: str) -> list:
    """A drive under safe torque off and one whose fault persists, reset by the application
    every 50 ms while the cause lasts (each reset runs its cycles and gives up), then moved
    again: what GT_ClrSts and GT_GetSts gave, where the axes ended, and how many of the cycles
    the bank ran at once while the drives rested (the way it came only)."""
    ctl = _up("off" if way == "no bank" else "auto")
    if way == "one at a time":
        ctl.clock.run_many = None
    faults.inject("sto", axis=1, duration_ms=260)
    faults.inject("drive_fault", axis=2, code=0x2310, duration_ms=180)
    seen = []
    s = c_long()
    c0 = ctl.clock.cycles
    b0 = ctl.bank.many_cycles if ctl.bank is not None else 0
    for _ in range(8):
        gt.GTE_Wait(50)
        for a in (1, 2):
            seen.append((gt.GT_ClrSts(a, 1), gt.GT_GetSts(a, byref(s)), s.value))
    batched = (ctl.bank.many_cycles - b0) / (ctl.clock.cycles - c0) if way == "batched" else 0
    seen += [gt.GT_AxisOn(1), gt.GT_AxisOn(2)]
    gt.GTE_Wait(20)
    seen += [_trap(1, 4000), _trap(2, -3000)]
    gt.GTE_Wait(400)
    for a in (1, 2):
        p = c_double()
        gt.GT_GetEncPos(a, byref(p))
        gt.GT_GetSts(a, byref(s))
        seen.append((p.value, s.value))
    gt.GT_Close()
    return [seen, batched]


def test_drives_resting_in_a_fault_run_at_once_and_reset_alike() -> None:
    """A drive at rest in FAULT under safe torque off rests in the bank (the field's hands
    change nothing of it), and the axes of a fault reset stay off it while the reset runs:
    the same codes, words and positions as one cycle at a time and without the bank."""
    fast = _resting_session("batched")
    assert fast[0][0][2] & ALARM and fast[0][1][2] & ALARM  # both drives faulted at first
    assert fast[1] > 0.85  # the resting cycles ran at once (0.48 with both drives scalar)
    slow = _resting_session("one at a time")
    assert fast[0] == slow[0]
    assert fast[0] == _resting_session("no bank")[0]


def _reset_session(way: str) -> list:
    """Time triggers counted down across runs of cycles at once, the clock's origin moved
    by GT_Reset between them (at_ms counts from it, a duration does not)."""
    ctl = _up()
    if way == "one at a time":
        ctl.clock.run_many = None
    t = c_long()
    gt.GT_GetClock(byref(t))
    faults.inject("drive_fault", axis=1, code=0x2310, at_ms=t.value + 150, duration_ms=40)
    faults.inject("encoder_lost", axis=2, counts=5, after_ms=260)
    gt.GTE_Wait(100)
    assert gt.GT_Reset() == 0  # the clock reads 0: at_ms is further off than it was
    gt.GTE_Wait(600)
    inj = faults.injector_for(ctl)
    cycle = ctl.clock.cycle_ns / 1e6
    events = [(round(ms / cycle), what, ident) for ms, what, ident, _ in inj.events]
    gt.GT_Close()
    return events


def test_time_triggers_fire_in_the_same_cycle_across_a_reset() -> None:
    fast = _reset_session("batched")
    assert sorted(e[1:] for e in fast) == [("end", 1), ("end", 2), ("start", 1), ("start", 2)]
    assert fast == _reset_session("one at a time")


def _pushed(way: str) -> list:
    """A position trigger waiting while the mechanics are moved from outside between two
    cycles (a scenario pushing the axis): the cycle its fault starts in."""
    ctl = _up("off" if way == "no bank" else "auto")
    if way == "one at a time":
        ctl.clock.run_many = None
    faults.inject("drive_fault", axis=2, code=0x2310, when_position=[1, 3000])
    gt.GTE_Wait(10)
    ctl.backend.slaves[0].channel(0).machine_position = 5000.0
    gt.GTE_Wait(10)
    cycle = ctl.clock.cycle_ns / 1e6
    events = [(round(ms / cycle), what) for ms, what, _, _ in faults.injector_for(ctl).events]
    gt.GT_Close()
    return events


def test_a_position_trigger_sees_the_mechanics_moved_between_cycles() -> None:
    batched = _pushed("batched")
    assert [what for _, what in batched] == ["start"]
    assert batched == _pushed("one at a time") == _pushed("no bank")
