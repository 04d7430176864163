"""The predictive wait's model of the master's cycle (gtecat.wire.pacing)."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.wire.pacing import (
    BASE_MARGIN_NS,
    GUARD_NS,
    LATE_SPAN_NS,
    MIN_MARGIN_NS,
    RELEARN,
    SAMPLES,
    STEADY_AFTER,
    Pacing,
)
from tests.conftest import examples


def steady(p: Pacing, t: int, n: int, period: int = 1_000_000) -> int:
    """``n`` arrivals one ``period`` apart from ``t``; the time of the next one."""
    for _ in range(n):
        p.arrived(t)
        t += period
    return t


def test_a_steady_1ms_master_gets_a_window_around_its_next_frame() -> None:
    p = Pacing()
    t = 5_000_000
    for _ in range(STEADY_AFTER + 2):  # the first two set the period, the rest confirm it
        assert p.window() is None
        p.arrived(t)
        t += 1_000_000
    opens, closes = p.window()  # type: ignore[misc]
    due = t  # one period after the last arrival
    assert opens == due - BASE_MARGIN_NS and closes == due + LATE_SPAN_NS


def test_no_window_before_the_rhythm_is_steady_or_after_a_miss() -> None:
    p = Pacing()
    for k in range(STEADY_AFTER + 1):
        p.arrived(k * 1_000_000)
    assert p.window() is None  # the first interval sets the period, then 7 confirmations
    p.arrived((STEADY_AFTER + 1) * 1_000_000)
    assert p.window() is not None
    p.missed()
    assert p.window() is None and p.misses == 1
    # the rhythm is kept: the late frame itself brings the window back for the next one
    p.arrived((STEADY_AFTER + 2) * 1_000_000 + 90_000)
    opens, closes = p.window()  # type: ignore[misc]
    assert opens < (STEADY_AFTER + 3) * 1_000_000 + 90_000 < closes


def test_the_margin_learns_the_hosts_late_wake_ups() -> None:
    """A host whose sleeps end 60 us late, and 2 in 100 of them 300 us late: the window
    opens early enough for the 99th percentile (300 us) plus the guard."""
    p = Pacing()
    t = steady(p, 0, STEADY_AFTER + 2)
    assert p.margin_ns == BASE_MARGIN_NS  # nothing learned yet
    for k in range(SAMPLES):
        p.woke(300_000 if k % 50 == 0 else 60_000)
        t = steady(p, t, 1)
    assert p.margin_ns == 300_000 + GUARD_NS
    opens, closes = p.window()  # type: ignore[misc]
    assert (opens, closes) == (t - 300_000 - GUARD_NS, t + 300_000 + GUARD_NS)  # > LATE_SPAN


def test_a_quiet_host_and_a_steady_master_spin_little() -> None:
    p = Pacing()
    t = steady(p, 0, STEADY_AFTER + 2)
    for _ in range(RELEARN * 2):
        p.woke(5_000)
        t = steady(p, t, 1)
    assert p.margin_ns == MIN_MARGIN_NS  # 5 us + the guard is less than the floor
    opens, closes = p.window()  # type: ignore[misc]
    # it opens 40 us before the frame; it stays open for a late frame, spinning only then
    assert (opens, closes) == (t - MIN_MARGIN_NS, t + LATE_SPAN_NS)


def test_the_margin_covers_the_masters_own_jitter() -> None:
    """A master whose frames come 60 us late, 20 us early or on time in turn: its frames
    wander up to 80 us from the due time, and the learned window holds the next one."""
    p = Pacing()
    jitter = (60_000, -20_000, 0)
    t = 0
    for k in range(SAMPLES):
        p.arrived(t + jitter[k % 3])
        t += 1_000_000
    assert 80_000 + GUARD_NS <= p.margin_ns < BASE_MARGIN_NS
    opens, closes = p.window()  # type: ignore[misc]
    assert opens < t + jitter[SAMPLES % 3] < closes


def test_a_margin_wider_than_half_the_period_is_a_window_as_wide_as_the_period() -> None:
    p = Pacing()
    t = steady(p, 0, STEADY_AFTER + 2, period=400_000)
    for _ in range(RELEARN):
        p.woke(900_000)  # a host far too busy: spin the whole time
        t = steady(p, t, 1, period=400_000)
    opens, closes = p.window()  # type: ignore[misc]
    assert closes - opens == 400_000


def test_a_change_of_period_restarts_the_estimate() -> None:
    p = Pacing()
    t = 0
    for _ in range(20):
        p.arrived(t)
        t += 1_000_000
    for _ in range(3):
        p.arrived(t)
        t += 4_000_000  # the master now runs at 250 Hz
    assert p.window() is None
    for _ in range(STEADY_AFTER + 1):
        p.arrived(t)
        t += 4_000_000
    opens, closes = p.window()  # type: ignore[misc]
    assert abs(opens + BASE_MARGIN_NS - t) < 1_000 and abs(closes - LATE_SPAN_NS - t) < 1_000


def test_periods_outside_the_predicted_range_are_left_to_poll() -> None:
    for period in (50_000, 50_000_000):
        p = Pacing()
        for k in range(30):
            p.arrived(k * period)
        assert p.window() is None


@settings(max_examples=examples(200, 25), deadline=None, derandomize=True)
@given(
    period=st.integers(100_000, 20_000_000),
    jitter=st.lists(st.integers(-20_000, 20_000), min_size=STEADY_AFTER + 2, max_size=60),
)
def test_the_window_holds_the_next_frame_of_a_jittery_master(period, jitter) -> None:
    """A master whose frames come within +-20 us of its period: the next frame (with the same
    jitter) falls inside the window, and the window is never wider than the period."""
    p = Pacing()
    t = 1_000_000_000
    for j in jitter:
        p.arrived(t + j)
        t += period
    window = p.window()
    if window is None:  # 20 us is more than a quarter of a short period: not steady
        assert period < 80_000 * 4 + 1
        return
    opens, closes = window
    assert closes - opens <= p.period_ns  # never wider than the period it estimates
    for j in (-20_000, 0, 20_000):
        assert opens <= t + j <= closes


def test_a_late_frame_and_the_burst_after_it_keep_the_learned_period() -> None:
    """A master held back once sends late, then the frames it owes back to back: two or
    three arrivals off the rhythm. The learned period stays (a busy host once had the loop
    report 344 us for a 1 ms master), the window comes back after two frames in rhythm."""
    p = Pacing()
    t = 0
    for _ in range(20):
        p.arrived(t)
        t += 1_000_000
    t += 700_000  # late by 0.7 ms
    p.arrived(t)
    p.arrived(t + 50_000)  # the owed frame, back to back
    t += 1_000_000
    assert p.window() is None  # off the rhythm: no window yet
    for _ in range(2):
        p.arrived(t)
        t += 1_000_000
    assert abs(p.period_ns - 1_000_000) < 10_000
    assert p.window() is not None
    for _ in range(4):  # a real change of period (three intervals agreeing) is still learned
        p.arrived(t)
        t += 3_000_000
    assert abs(p.period_ns - 3_000_000) < 1_000


def test_housekeeping_waits_for_the_gap_after_an_answer() -> None:
    """The serve loop's housekeeping (chain poll, inspection requests, a collection) does not
    start in the spin around the next frame's window, only in the gap after an answer - or
    when it is long overdue (a master whose frames leave no gap)."""
    from types import SimpleNamespace

    from gtecat.wire.serve import WireServer

    server = SimpleNamespace(
        HOUSEKEEPING_NS=WireServer.HOUSEKEEPING_NS,
        HOUSEKEEPING_OVERDUE_NS=WireServer.HOUSEKEEPING_OVERDUE_NS,
    )
    may_run = WireServer._housekeeping_may_run
    p = Pacing()
    period = 1_000_000
    for k in range(20):
        p.arrived(k * period)
    last = 19 * period
    opens, _closes = p.window()
    assert may_run(server, p, True, last + 100_000, last)  # just after the answer
    assert not may_run(server, p, True, opens - 100_000, last)  # about to spin
    assert not may_run(server, p, True, opens + 10_000, last)  # spinning
    assert may_run(server, p, True, opens + 10_000, opens - 60_000_000)  # long overdue
    assert may_run(server, p, False, opens + 10_000, last)  # not predicting: as before
    assert may_run(server, Pacing(), True, 5, 0)  # nothing learned yet
