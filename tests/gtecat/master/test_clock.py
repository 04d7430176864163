"""Clock modes (DESIGN.md "Time"): lockstep, auto (host-call latency), run_until bounds."""

import pytest

from gtecat.master.clock import Clock, ClockMode


def test_lockstep_runs_only_when_advanced():
    ran = []
    c = Clock(lambda: ran.append(1), cycle_ns=1_000_000, mode="lockstep")
    c.on_call()
    assert ran == []
    assert c.advance(2.5) == 2
    assert c.now_ns == 2_000_000
    assert c.advance(0.5) == 1  # the half millisecond left over is not lost
    assert c.now_ms == 3


def test_auto_charges_every_call():
    ran = []
    c = Clock(
        lambda: ran.append(1), cycle_ns=1_000_000, mode=ClockMode.AUTO, call_latency_ns=50_000
    )
    for _ in range(19):
        c.on_call()
    assert ran == []
    c.on_call()
    assert len(ran) == 1


def test_run_until_is_bounded():
    c = Clock(lambda: None, cycle_ns=1_000_000, mode="lockstep")
    assert c.run_until(lambda: c.cycles >= 3, timeout_ms=10)
    assert c.cycles == 3
    assert not c.run_until(lambda: False, timeout_ms=5)
    assert c.cycles == 8


def test_a_group_of_clocks_shares_one_time():
    """The cards of one PC: the time one lets pass passes for the others (cycles of their
    own length), once; a clock that leaves runs alone again."""
    from gtecat.master.clock import ClockGroup

    runs: list[str] = []
    a = Clock(lambda: runs.append("a"), cycle_ns=1_000_000, mode="lockstep")
    b = Clock(lambda: runs.append("b"), cycle_ns=2_000_000, mode="lockstep")
    group = ClockGroup()
    group.join(a)
    assert a.group is None  # alone: nothing to share
    group.join(b)
    a.advance(4)
    assert (a.cycles, b.cycles, b.now_ns) == (4, 2, 4_000_000)
    assert b.run_until(lambda: b.cycles == 3, 10)
    assert (a.now_ns, b.now_ns) == (6_000_000, 6_000_000)
    group.leave(b)
    a.advance(2)
    assert (a.cycles, b.cycles, a.group, b.group) == (8, 3, None, None)
    group.join(Clock(lambda: None, mode="realtime"))  # the wall clock is shared already
    assert group.clocks == [a]


@pytest.mark.parametrize("ns", [0, 0.5, -1])
def test_a_cycle_time_below_one_nanosecond_is_refused(ns):
    """The cycle time is whole nanoseconds: 0.5 is 0, no cycle time (never stored)."""
    clock = Clock(lambda: None, cycle_ns=1_000_000, mode=ClockMode.AUTO)
    with pytest.raises(ValueError, match="positive"):
        clock.cycle_ns = ns
    assert clock.cycle_ns == 1_000_000
    with pytest.raises(ValueError, match="positive"):
        Clock(lambda: None, cycle_ns=ns, mode=ClockMode.AUTO)
