"""Touch probe (60B8/60B9/60BA–60BD/60D5–60D8) against known edges (cia402-facts §4).

The axis moves at speeds that are not a whole number of counts per cycle, so every
edge falls between two samples; the latched value must be the encoder position at the
exact crossing (within one count), not a sample.
"""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.drives.machine import AxisMachine
from gtecat.drives.signal_edges import level, merge_windows, window_edges
from gtecat.drives.touch_probe import TOGGLE_BITS, TouchProbe, TouchProbeError
from gtecat.eni.errors import GtecatError
from tests.conftest import examples

ENC0 = 4321.25  # encoder = machine - ENC0 (a homing offset, say)
M = AxisMachine(
    counts_per_rev=1000,
    index_offset=130,
    probe1=((1000.3, 1500.7), (3000.9, 3100.1)),
    probe2=((-400.2, -399.9),),  # 0.3 counts wide: crossed inside one cycle
)

# 60B8 bits
TP1_EN, TP1_CONT, TP1_IDX, TP1_POS, TP1_NEG = 0x01, 0x02, 0x04, 0x10, 0x20
TP2_EN, TP2_CONT, TP2_IDX, TP2_POS, TP2_NEG = 0x100, 0x200, 0x400, 0x1000, 0x2000


class Axis:
    """Moves the mechanics at a constant speed and steps the probe every 1 ms cycle."""

    def __init__(self, tp: TouchProbe, pos: float, enc0: float = ENC0) -> None:
        self.tp, self.pos, self.enc0, self.t_ns = tp, pos, enc0, 0

    def move(self, counts_per_cycle: float, cycles: int, after=None) -> None:
        for _ in range(cycles):
            p0, p1 = self.pos, self.pos + counts_per_cycle
            self.t_ns += 1_000_000
            self.tp.step(p0, p1, p0 - self.enc0, p1 - self.enc0, self.t_ns, 1_000_000)
            self.pos = p1
            if after is not None:
                after(self)

    def move_to(self, target: float, counts_per_cycle: float) -> None:
        step = abs(counts_per_cycle) if target > self.pos else -abs(counts_per_cycle)
        while (target - self.pos) * step > 0:
            s = step if abs(target - self.pos) > abs(step) else target - self.pos
            self.move(s, 1)


def enc(machine_pos: float) -> float:
    return machine_pos - ENC0


def within_one_count(value: int, true: float) -> bool:
    return abs(value - true) <= 1.0


def test_both_edges_moving_up_latch_between_samples() -> None:
    tp = TouchProbe(M)
    tp.write_function(TP1_EN | TP1_POS | TP1_NEG)
    assert tp.status == 0x0001
    ax = Axis(tp, 0.0)
    ax.move_to(2000, 37.3)
    assert tp.status == 0x0007
    assert within_one_count(tp.values[0], enc(1000.3))
    assert within_one_count(tp.values[1], enc(1500.7))
    assert tp.values[0] == round(enc(1000.3)) and tp.values[1] == round(enc(1500.7))
    assert tp.counters[:2] == [1, 1]


def test_moving_down_rising_is_the_upper_boundary() -> None:
    tp = TouchProbe(M)
    tp.write_function(TP1_EN | TP1_POS | TP1_NEG)
    ax = Axis(tp, 2000.0)
    ax.move_to(500, 41.7)
    # entering [1000.3, 1500.7) from above: the input rises at 1500.7, falls at 1000.3
    assert tp.values[0] == round(enc(1500.7))
    assert tp.values[1] == round(enc(1000.3))


def test_probe2_narrow_mark_crossed_inside_one_cycle_gives_both_edges() -> None:
    tp = TouchProbe(M)
    tp.write_function(TP2_EN | TP2_POS | TP2_NEG)
    assert tp.status == 0x0100
    ax = Axis(tp, -1000.0)
    ax.move_to(0, 123.4)  # the 0.3-count mark lies wholly inside one cycle's travel
    assert tp.status == 0x0700
    assert tp.values[2] == round(enc(-400.2))
    assert tp.values[3] == round(enc(-399.9))
    assert tp.values[:2] == [0, 0]
    assert tp.counters == [0, 0, 1, 1]


def test_timestamps_are_interpolated_inside_the_cycle() -> None:
    tp = TouchProbe(M)
    tp.write_function(TP1_EN | TP1_POS)
    tp.step(1000.0, 1001.0, 0.0, 1.0, 5_000_000, 1_000_000)  # edge at 30 % of the cycle
    assert tp.timestamps[0] == 4_000_000 + 300_000
    assert tp.values[0] == 0  # 0.3 rounds to 0


def test_first_event_keeps_the_first_edge_until_rearmed() -> None:
    tp = TouchProbe(M)
    tp.write_function(TP1_EN | TP1_POS)
    ax = Axis(tp, 0.0)
    ax.move_to(4000, 55.5)
    assert tp.values[0] == round(enc(1000.3))  # not the second mark at 3000.9
    assert tp.counters[0] == 2  # both edges seen
    assert tp.status & (1 << TOGGLE_BITS[0]) == 0  # no toggling in first-event mode
    # re-arm by clearing and setting the edge-enable bit: the stored bit clears, value stays
    tp.write_function(TP1_EN)
    assert tp.status == 0x0001 and tp.values[0] == round(enc(1000.3))
    tp.write_function(TP1_EN | TP1_POS)
    ax.move_to(0, 55.5)  # moving down: rising edges at 3100.1 then 1500.7
    assert tp.values[0] == round(enc(3100.1))
    assert tp.status == 0x0003


def test_rearm_by_disable_enable_and_values_survive_disable() -> None:
    tp = TouchProbe(M)
    tp.write_function(TP1_EN | TP1_POS | TP1_NEG)
    ax = Axis(tp, 0.0)
    ax.move_to(2000, 20.2)
    assert tp.status == 0x0007
    tp.write_function(0)
    assert tp.status == 0 and tp.values[:2] == [round(enc(1000.3)), round(enc(1500.7))]
    ax.move_to(4000, 20.2)  # disabled: nothing latched, nothing counted
    assert tp.values[0] == round(enc(1000.3)) and tp.counters[0] == 1
    tp.write_function(TP1_EN | TP1_POS | TP1_NEG)
    assert tp.status == 0x0001
    ax.move_to(2000, 20.2)
    assert tp.values[0] == round(enc(3100.1)) and tp.values[1] == round(enc(3000.9))


def test_repeating_the_same_function_every_cycle_does_not_rearm() -> None:
    tp = TouchProbe(M)
    ax = Axis(tp, 0.0)

    def pdo(a: Axis) -> None:  # the master sends 60B8 in every frame
        a.tp.write_function(TP1_EN | TP1_POS)

    pdo(ax)
    ax.move(50.5, 90, after=pdo)
    assert tp.values[0] == round(enc(1000.3))
    assert tp.status == 0x0003


def test_continuous_overwrites_and_toggles_per_capture() -> None:
    tp = TouchProbe(M)
    tp.write_function(TP1_EN | TP1_CONT | TP1_POS | TP1_NEG)
    ax = Axis(tp, 0.0)
    ax.move_to(1200, 33.3)
    assert tp.values[0] == round(enc(1000.3))
    assert tp.status == 0x0001 | 0x0002 | 0x0040  # bit 6 toggled once
    ax.move_to(2000, 33.3)
    assert tp.status == 0x0001 | 0x0002 | 0x0004 | 0x0040 | 0x0080
    ax.move_to(4000, 33.3)  # second mark: both toggles flip back, values overwritten
    assert tp.values[0] == round(enc(3000.9)) and tp.values[1] == round(enc(3100.1))
    assert tp.status == 0x0007
    assert tp.counters[:2] == [2, 2]


def test_probe2_toggle_bits_14_and_15() -> None:
    tp = TouchProbe(M)
    tp.write_function(TP2_EN | TP2_CONT | TP2_POS | TP2_NEG)
    Axis(tp, -1000.0).move_to(0, 77.7)
    assert tp.status == 0x0100 | 0x0200 | 0x0400 | (1 << 14) | (1 << 15)


def test_encoder_index_source() -> None:
    tp = TouchProbe(M)
    tp.write_function(TP1_EN | TP1_IDX | TP1_POS | TP2_EN | TP2_CONT | TP2_IDX | TP2_POS)
    Axis(tp, 0.0).move_to(2500, 64.9)  # index pulses at 130, 1130, 2130
    assert tp.values[0] == round(enc(130))  # first event
    assert tp.values[2] == round(enc(2130))  # continuous: the last one
    assert tp.counters[0] == 3 and tp.counters[2] == 3
    # probe inputs are ignored with the index source
    assert tp.values[1] == 0


def test_source_from_60d0_and_reserved_source() -> None:
    tp = TouchProbe(M)
    tp.set_source(1, 2)  # TP1 follows the probe-2 input
    tp.write_function(TP1_EN | 0x08 | TP1_POS)  # bits 3:2 = 10b
    Axis(tp, -1000.0).move_to(0, 50.0)
    assert tp.values[0] == round(enc(-400.2))
    tp = TouchProbe(M)
    tp.set_source(2, 5)  # zero impulse
    tp.write_function(TP2_EN | 0x800 | TP2_POS)
    Axis(tp, 0.0).move_to(500, 50.0)
    assert tp.values[2] == round(enc(130))
    tp = TouchProbe(M)
    tp.write_function(TP1_EN | 0x0C | TP1_POS)  # 11b reserved: never triggers
    Axis(tp, 0.0).move_to(2000, 50.0)
    assert tp.status == 0x0001 and tp.counters[0] == 0
    with pytest.raises(TouchProbeError):
        tp.set_source(1, 9)


@pytest.mark.parametrize("bad", [0x10000, -0x8001, 1.5, "3", True])
def test_bad_function_values_are_refused(bad) -> None:
    tp = TouchProbe(M)
    with pytest.raises(TouchProbeError) as e:
        tp.write_function(bad)
    assert isinstance(e.value, GtecatError)
    assert tp.function == 0


def test_negative_short_is_its_bit_pattern() -> None:
    tp = TouchProbe(M)
    tp.function = -0x7FEF  # 0x8011 as a C short: TP1 on, rising, bit 15 user-defined
    assert tp.function == 0x8011 and tp.status == 0x0001


def test_manual_example_5_3_continuous_refresh_logic() -> None:
    """Example 5-3: 16#0013, detect each new rising capture by bit 6 changing."""
    m = AxisMachine(probe1=tuple((1000.0 * k + 0.37, 1000.0 * k + 500.0) for k in range(1, 8)))
    tp = TouchProbe(m)
    tp.write_function(0x0013)
    seen: list[int] = []
    x_pre = False

    def plc(a: Axis) -> None:
        nonlocal x_pre
        sts = a.tp.status
        if sts & 0x01 and sts & 0x02 and bool(sts & 0x40) != x_pre:
            seen.append(a.tp.values[0])
            x_pre = bool(sts & 0x40)

    Axis(tp, 0.0, enc0=0.0).move(29.9, 300, after=plc)
    assert seen == [1000 * k for k in range(1, 8)]  # round(1000k + 0.37)
    # stop (16#00): status clears, the last value stays readable
    tp.write_function(0)
    assert tp.status & 0x7 == 0 and tp.values[0] == 7000


@settings(max_examples=examples(200, 25), deadline=None)
@given(
    lo=st.floats(-1e6, 1e6),
    width=st.floats(0.01, 5000.0),
    speed=st.floats(0.05, 4000.0),
    up=st.booleans(),
    enc0=st.floats(-1e5, 1e5),
    phase=st.floats(0.0, 1.0),
)
def test_random_mark_is_captured_within_one_count(lo, width, speed, up, enc0, phase) -> None:
    hi = lo + width
    speed = max(speed, width / 1000.0)  # keep the run short
    m = AxisMachine(probe1=((lo, hi),))
    tp = TouchProbe(m)
    tp.write_function(TP1_EN | TP1_POS | TP1_NEG)
    step = speed if up else -speed
    start = (lo - (1.0 + phase) * speed) if up else (hi + (1.0 + phase) * speed)
    end = hi + 2 * speed if up else lo - 2 * speed
    ax = Axis(tp, start, enc0=enc0)
    n = int(abs(end - start) / speed) + 2
    ax.move(step, n)
    rise, fall = (lo, hi) if up else (hi, lo)
    assert tp.status == 0x0007
    assert within_one_count(tp.values[0], rise - enc0)
    assert within_one_count(tp.values[1], fall - enc0)


# --- the shared edge helper (drives/signal_edges.py) ---------------------------------

windows_st = st.lists(
    st.tuples(st.integers(-50, 50), st.integers(1, 30)).map(lambda t: (t[0], t[0] + t[1])),
    max_size=5,
)


@settings(max_examples=examples(300, 38), deadline=None)
@given(windows=windows_st, p0=st.floats(-100, 100), p1=st.floats(-100, 100))
def test_window_edges_replay_the_sampled_levels(windows, p0, p1) -> None:
    merged = merge_windows(windows)
    assert level(merged, p0) == any(lo <= p0 < hi for lo, hi in windows)
    edges = window_edges(merged, p0, p1)
    lvl = level(merged, p0)
    lo, hi = min(p0, p1), max(p0, p1)
    dists = []
    for x, rising in edges:
        assert rising != lvl  # every edge changes the level
        lvl = rising
        assert lo <= x <= hi
        dists.append(abs(x - p0))
    assert lvl == level(merged, p1)
    assert dists == sorted(dists)


def test_touching_windows_are_one_signal() -> None:
    merged = merge_windows([(3.0, 5.0), (0.0, 3.0), (10.0, 12.0), (11.0, 11.5)])
    assert merged == ((0.0, 5.0), (10.0, 12.0))
    assert window_edges(merged, -1.0, 20.0) == [
        (0.0, True),
        (5.0, False),
        (10.0, True),
        (12.0, False),
    ]
    assert window_edges(merged, 20.0, -1.0) == [
        (12.0, True),
        (10.0, False),
        (5.0, True),
        (0.0, False),
    ]
