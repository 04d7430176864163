"""The predictive wait's model of the master's cycle (gtecat.wire.pacing)."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.wire.pacing import BASE_MARGIN_NS, STEADY_AFTER, Pacing


def test_a_steady_1ms_master_gets_a_window_around_its_next_frame() -> None:
    p = Pacing()
    t = 5_000_000
    for _ in range(STEADY_AFTER + 2):  # the first two set the period, the rest confirm it
        assert p.window() is None
        p.arrived(t)
        t += 1_000_000
    opens, closes = p.window()  # type: ignore[misc]
    due = t  # one period after the last arrival
    assert opens == due - BASE_MARGIN_NS and closes == due + BASE_MARGIN_NS


def test_no_window_before_the_rhythm_is_steady_or_after_a_miss() -> None:
    p = Pacing()
    for k in range(STEADY_AFTER + 1):
        p.arrived(k * 1_000_000)
    assert p.window() is None  # the first interval sets the period, then 7 confirmations
    p.arrived((STEADY_AFTER + 1) * 1_000_000)
    assert p.window() is not None
    p.missed()
    assert p.window() is None and p.misses == 1


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
    assert abs((opens + closes) / 2 - (t - 4_000_000 + 4_000_000)) < 1_000


def test_periods_outside_the_predicted_range_are_left_to_poll() -> None:
    for period in (50_000, 50_000_000):
        p = Pacing()
        for k in range(30):
            p.arrived(k * period)
        assert p.window() is None


@settings(max_examples=200, deadline=None, derandomize=True)
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
