"""Clock modes (DESIGN.md "Time"): lockstep, auto (host-call latency), run_until bounds."""

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
