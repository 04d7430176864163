"""Homing methods against hand-computed home points (CiA 402 method table, cia402-facts §3).

Every expected value below was written by hand from the standard's table, not from the
code: the switch layout is chosen so that a wrong edge, a wrong index pulse (e.g. the
first one after the reversal instead of after the edge, or one swept during braking)
or a wrong initial direction (the other cam) gives a different number.

Machine "cams" (methods 7–14, 23–30): limits at -10000 / +10000, two home cams
C1 = [-7550, -5300) and C2 = [2450, 4700), index pulses at 130 + 1000 k:

    ... -7870 | -7550 C1 -6870 -5870 -5300 | -4870 ... 2130 | 2450 C2 3130 4130 4700 | 5130

Starts: left of C1, inside C1, between the cams, inside C2, right of C2.
Speeds 20000 / 2000 counts/s, 100000 counts/s²: braking from search speed takes
2000 counts (two index periods), so a pulse swept while braking would show.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.drives.homing import (
    SUPPORTED_METHODS,
    Homing,
    HomingError,
    HomingParams,
    HomingPhase,
    UnsupportedHomingMethodError,
)
from gtecat.drives.machine import AxisMachine
from gtecat.eni.errors import GtecatError

CAMS = AxisMachine(
    counts_per_rev=1000,
    negative_limit=-10000,
    positive_limit=10000,
    home_switch=((-7550, -5300), (2450, 4700)),
    index_offset=130,
)
LIMITS = AxisMachine(
    counts_per_rev=1000, negative_limit=-10000, positive_limit=10000, index_offset=130
)
POS_HS = AxisMachine(  # "positive" home switch: active from 2450 up past the positive limit
    counts_per_rev=1000,
    negative_limit=-10000,
    positive_limit=10000,
    home_switch=((2450, 20000),),
    index_offset=130,
)
NEG_HS = AxisMachine(  # "negative" home switch: active from past the negative limit up to 4700
    counts_per_rev=1000,
    negative_limit=-10000,
    positive_limit=10000,
    home_switch=((-20000, 4700),),
    index_offset=130,
)

S_LEFT, S_IN1, S_MID, S_IN2, S_RIGHT = -9000, -6800, -1000, 3500, 7000
CAM_STARTS = (S_LEFT, S_IN1, S_MID, S_IN2, S_RIGHT)

# method: (home point for each start in CAM_STARTS, final approach direction)
CAM_EXPECTED: dict[int, tuple[tuple[int, ...], int]] = {
    # 7: start +, reverse on PL; cam low edge approached -; first index left of it
    7: ((-7870, -7870, 2130, 2130, 2130), -1),
    # 8: start +; low edge approached +; first index right of it
    8: ((-6870, -6870, 3130, 3130, 3130), +1),
    # 9: start +; high edge approached -; index left of it
    9: ((-5870, -5870, 4130, 4130, 4130), -1),
    # 10: start +; high edge approached +; index right of it
    10: ((-4870, -4870, 5130, 5130, 5130), +1),
    # 11: start -, reverse on NL; high edge approached +; index right of it
    11: ((-4870, -4870, -4870, 5130, 5130), +1),
    # 12: start -; high edge approached -; index left of it
    12: ((-5870, -5870, -5870, 4130, 4130), -1),
    # 13: start -; low edge approached +; index right of it
    13: ((-6870, -6870, -6870, 3130, 3130), +1),
    # 14: start -; low edge approached -; index left of it
    14: ((-7870, -7870, -7870, 2130, 2130), -1),
    # 23–30 = 7–14 without index: the edge itself
    23: ((-7550, -7550, 2450, 2450, 2450), -1),
    24: ((-7550, -7550, 2450, 2450, 2450), +1),
    25: ((-5300, -5300, 4700, 4700, 4700), -1),
    26: ((-5300, -5300, 4700, 4700, 4700), +1),
    27: ((-5300, -5300, -5300, 4700, 4700), +1),
    28: ((-5300, -5300, -5300, 4700, 4700), -1),
    29: ((-7550, -7550, -7550, 2450, 2450), +1),
    30: ((-7550, -7550, -7550, 2450, 2450), -1),
}

# method: (machine, starts, home point, final direction)
OTHER_EXPECTED: dict[int, tuple[AxisMachine, tuple[float, ...], float, int]] = {
    # 1: NL falling edge at -10000 moving +, first index right of it
    1: (LIMITS, (-5000, -10500), -9870, +1),
    2: (LIMITS, (5000, 10500), 9130, -1),
    # 3: positive HS edge 2450 crossed moving - (HS turns off), index left of it
    3: (POS_HS, (-3000, 6000), 2130, -1),
    4: (POS_HS, (-3000, 6000), 3130, +1),
    # 5: negative HS edge 4700 crossed moving + (HS turns off), index right of it
    5: (NEG_HS, (6000, -3000), 5130, +1),
    6: (NEG_HS, (6000, -3000), 4130, -1),
    17: (LIMITS, (-5000, -10500), -10000, +1),
    18: (LIMITS, (5000, 10500), 10000, -1),
    19: (POS_HS, (-3000, 6000), 2450, -1),
    20: (POS_HS, (-3000, 6000), 2450, +1),
    21: (NEG_HS, (6000, -3000), 4700, +1),
    22: (NEG_HS, (6000, -3000), 4700, -1),
    # 33/34: first index pulse moving - / +
    33: (LIMITS, (500,), 130, -1),
    34: (LIMITS, (500,), 1130, +1),
}


@dataclass
class Run:
    homing: Homing
    positions: list[float] = field(default_factory=list)  # actual position per cycle
    demands: list[float] = field(default_factory=list)
    statuses: list[tuple[bool, bool, bool]] = field(default_factory=list)
    attained_dir: int = 0  # direction of travel in the cycle the home point was found

    @property
    def final(self) -> float:
        return self.positions[-1]

    def distinct_statuses(self) -> list[str]:
        out: list[str] = []
        for s10, s12, s13 in self.statuses:
            code = f"{int(s13)}{int(s12)}{int(s10)}"  # SW13 SW12 SW10, as in the table
            if not out or out[-1] != code:
                out.append(code)
        return out


def params(method: int, **kw: float) -> HomingParams:
    base = dict(speed_switch=20000.0, speed_zero=2000.0, acceleration=100000.0, home_offset=0)
    base.update(kw)
    return HomingParams(method=method, **base)  # type: ignore[arg-type]


def run(
    p: HomingParams,
    machine: AxisMachine,
    start: float,
    *,
    dt: float = 0.001,
    lag: int = 1,
    first_order: float | None = None,
    max_s: float = 60.0,
    extra_cycles: int = 5,
    on_cycle=None,
) -> Run:
    """A kinematic axis: the actual position is the demand of ``lag`` cycles ago
    (``lag=1``: follows exactly), or a first-order lag ``pos += k (demand - pos)``."""
    h = Homing(p, machine, start)
    r = Run(h)
    hist = [float(start)] * lag
    pos = float(start)
    left = None
    before = pos
    for k in range(int(max_s / dt)):
        was = h.attained
        demand = h.step(dt, pos)
        r.positions.append(pos)
        r.demands.append(demand)
        r.statuses.append(h.status_bits())
        if h.attained and not was and k > 0:
            r.attained_dir = (pos > before) - (pos < before)
        before = pos
        if on_cycle is not None:
            on_cycle(k, h)
        if first_order is None:
            hist.append(demand)
            pos = hist[-lag]
        else:
            pos += first_order * (demand - pos)
        if h.done and left is None:
            left = extra_cycles
        if left is not None:
            left -= 1
            if left < 0:
                break
    return r


# --- one test per homing method ------------------------------------------------


@pytest.mark.parametrize("method", sorted(CAM_EXPECTED))
@pytest.mark.parametrize(
    "start_i", range(len(CAM_STARTS)), ids=["left", "in1", "mid", "in2", "right"]
)
@pytest.mark.sample(10)
def test_cam_methods(method: int, start_i: int) -> None:
    homes, final_dir = CAM_EXPECTED[method]
    r = run(params(method), CAMS, CAM_STARTS[start_i])
    h = r.homing
    assert h.done and h.attained and not h.error
    assert h.home_machine_position == homes[start_i]
    assert r.final == pytest.approx(homes[start_i], abs=1e-9)  # stands on the home point
    assert r.attained_dir == final_dir
    assert h.status_bits() == (True, True, False)
    assert r.distinct_statuses() == ["000", "010", "011"]


@pytest.mark.parametrize("method", sorted(OTHER_EXPECTED))
def test_limit_homeswitch_and_index_methods(method: int) -> None:
    machine, starts, home, final_dir = OTHER_EXPECTED[method]
    for start in starts:
        r = run(params(method), machine, start)
        h = r.homing
        assert h.done and h.attained and not h.error, (start, h.reason)
        assert h.home_machine_position == home, start
        assert r.final == pytest.approx(home, abs=1e-9)
        assert r.attained_dir == final_dir, start
        assert r.distinct_statuses() == ["000", "010", "011"]


@pytest.mark.parametrize("method", [35, 37])
def test_current_position_methods(method: int) -> None:
    h = Homing(params(method, home_offset=-250), LIMITS, 1234.25)
    # complete from the very first read, no motion
    assert h.status_bits() == (True, True, False)
    assert h.done and h.attained and not h.moving
    assert h.home_machine_position == 1234.25
    assert h.step(0.001, 1234.25) == 1234.25
    # 6064 = machine - encoder_offset reads 607C at the current position
    assert 1234.25 - h.encoder_offset() == -250


def test_every_supported_method_has_a_test() -> None:
    tested = set(CAM_EXPECTED) | set(OTHER_EXPECTED) | {35, 37}
    assert tested == set(SUPPORTED_METHODS)
    assert set(range(1, 15)) | set(range(17, 31)) | {33, 34, 35, 37} == set(SUPPORTED_METHODS)


# --- independence from cycle time, speed and position-loop lag -----------------


@pytest.mark.parametrize(
    ("dt", "lag", "first_order", "speed"),
    [
        (0.00025, 1, None, 20000.0),
        (0.004, 1, None, 20000.0),
        (0.001, 3, None, 20000.0),
        (0.001, 1, 0.4, 20000.0),
        (0.002, 2, None, 7777.7),
    ],
)
@pytest.mark.parametrize("method", [1, 4, 8, 11, 26, 33])
def test_result_does_not_depend_on_cycle_or_lag(
    method: int, dt: float, lag: int, first_order: float | None, speed: float
) -> None:
    expected = {1: -9870, 4: 3130, 8: 3130, 11: 5130, 26: 4700, 33: 130}[method]
    machine = {1: LIMITS, 4: POS_HS, 33: LIMITS}.get(method, CAMS)
    start = {1: -5000, 4: 6000, 33: 500}.get(method, S_IN2)
    r = run(
        params(method, speed_switch=speed), machine, start, dt=dt, lag=lag, first_order=first_order
    )
    assert r.homing.home_machine_position == expected
    assert r.homing.status_bits() == (True, True, False)
    assert r.final == pytest.approx(expected, abs=1.0)


def _first_index_right(e: float, offset: float, cpr: int) -> float:
    return offset + cpr * (math.floor((e - offset) / cpr) + 1)


def _first_index_left(e: float, offset: float, cpr: int) -> float:
    return offset + cpr * (math.ceil((e - offset) / cpr) - 1)


@settings(max_examples=40, deadline=None)
@given(
    method=st.sampled_from(list(range(7, 15)) + list(range(23, 31))),
    lo=st.integers(-3000, 2000),
    width=st.integers(50, 3000),
    cpr=st.integers(200, 2000),
    offset_frac=st.floats(0.01, 0.99),
    start_zone=st.sampled_from(["left", "in", "right"]),
    speed=st.floats(3000.0, 30000.0),
    zero_ratio=st.floats(0.05, 1.0),
    acc=st.floats(50000.0, 500000.0),
    dt=st.sampled_from([0.0005, 0.001, 0.004]),
)
@pytest.mark.long
def test_random_cam_matches_method_table(
    method, lo, width, cpr, offset_frac, start_zone, speed, zero_ratio, acc, dt
) -> None:
    hi = lo + width + 0.5
    offset = lo + 0.37 + offset_frac * cpr  # never exactly on an edge
    if min(abs(((e - offset) / cpr) - round((e - offset) / cpr)) for e in (lo, hi)) < 1e-6:
        return
    m = AxisMachine(
        counts_per_rev=cpr,
        negative_limit=-20000,
        positive_limit=20000,
        home_switch=((lo, hi),),
        index_offset=offset,
    )
    start = {"left": lo - 4000.0, "in": lo + width / 2, "right": hi + 4000.0}[start_zone]
    base = method - 16 if method > 16 else method
    edge = lo if base in (7, 8, 13, 14) else hi
    final = +1 if base in (8, 10, 11, 13) else -1
    if method > 16:
        expected = edge
    elif final > 0:
        expected = _first_index_right(edge, offset, cpr)
    else:
        expected = _first_index_left(edge, offset, cpr)
    p = params(method, speed_switch=speed, speed_zero=speed * zero_ratio, acceleration=acc)
    r = run(p, m, start, dt=dt, max_s=30.0)
    assert r.homing.attained, r.homing.reason
    assert r.homing.home_machine_position == pytest.approx(expected, abs=1e-9)
    assert r.final == pytest.approx(expected, abs=1e-6)


# --- starting on a limit switch ------------------------------------------------------


def test_start_on_the_reversal_limit_reverses_at_once() -> None:
    # method 7 starts +; on PL already: reverse, go - through C2, index left of 2450
    r = run(params(7), CAMS, 10500)
    assert r.homing.home_machine_position == 2130
    # method 11 starts -; on NL already: reverse, + through C1, index right of -5300
    r = run(params(11), CAMS, -10500)
    assert r.homing.home_machine_position == -4870


def test_start_on_the_other_limit_moving_away_is_fine() -> None:
    # method 7 on NL: initial direction + leads away from NL, C1's low edge -> -7870
    assert run(params(7), CAMS, -10500).homing.home_machine_position == -7870


def test_start_on_a_limit_the_method_cannot_reverse_on_is_an_error() -> None:
    h = Homing(params(34), LIMITS, 10500)  # 34 moves + but PL is active
    assert h.error and h.status_bits() == (True, False, True)
    assert "positive limit" in h.reason
    assert h.step(0.001, 10500) == 10500


# --- errors ----------------------------------------------------------------------


def test_no_home_switch_reverses_once_then_fails_on_the_other_limit() -> None:
    r = run(params(7), LIMITS, 0)
    h = r.homing
    assert h.error and not h.attained and h.home_machine_position is None
    assert "negative limit" in h.reason
    assert r.distinct_statuses() == ["000", "100", "101"]
    # it did go to PL first, then to NL
    assert max(r.positions) >= 10000 and min(r.positions) <= -10000
    assert r.homing.encoder_offset() is None


def test_limit_hit_where_the_method_does_not_reverse_is_an_error() -> None:
    finite = AxisMachine(
        counts_per_rev=1000,
        negative_limit=-10000,
        positive_limit=10000,
        home_switch=((2450, 4700),),
        index_offset=130,
    )
    # method 3 assumes a positive HS: starting right of a finite window, + finds only PL
    r = run(params(3), finite, 7000)
    assert r.homing.error and "positive limit" in r.homing.reason
    assert r.distinct_statuses() == ["000", "100", "101"]
    assert max(r.positions) < 10000 + 2000 + 50  # braked at 609A from PL
    # method 1 on a machine without NL: the search - is bounded by max_travel
    no_nl = AxisMachine(counts_per_rev=1000, positive_limit=10000, index_offset=130)
    r = run(params(1, max_travel=30000), no_nl, 0)
    assert r.homing.error and "travel" in r.homing.reason


def test_index_method_without_index_pulse_fails_within_a_revolution() -> None:
    m = AxisMachine(
        counts_per_rev=1000,
        negative_limit=-10000,
        positive_limit=10000,
        home_switch=((2450, 4700),),
    )
    r = run(params(8), m, 0)
    assert r.homing.error and "index" in r.homing.reason
    assert max(r.positions) < 2450 + 1000 + 2000 + 1  # one revolution + braking
    r = run(params(34), AxisMachine(), 0)
    assert r.homing.error


def test_search_without_any_switch_or_limit_ends_in_error() -> None:
    r = run(params(19), AxisMachine(counts_per_rev=1000), 0, max_s=600)
    assert r.homing.error and r.homing.done
    assert len(r.positions) < 200_000  # bounded by the default travel bound


def test_timeout_bounds_the_search() -> None:
    r = run(params(19, timeout_s=1.5), AxisMachine(counts_per_rev=1000), 0)
    assert r.homing.error and "longer than" in r.homing.reason
    assert 1500 < len(r.positions) < 1800


@pytest.mark.parametrize("method", [0, 15, 16, 31, 32, 36, 38, -1, -4, 127])
def test_unsupported_methods_are_refused(method: int) -> None:
    with pytest.raises(UnsupportedHomingMethodError) as e:
        Homing(params(method), CAMS, 0)
    assert isinstance(e.value, GtecatError)
    assert str(method) in str(e.value)


@pytest.mark.parametrize(
    "kw",
    [
        {"speed_switch": 0.0},
        {"speed_zero": -5.0},
        {"acceleration": 0.0},
        {"acceleration": float("nan")},
        {"timeout_s": 0.0},
    ],
)
def test_unusable_parameters_are_refused(kw) -> None:
    with pytest.raises(HomingError):
        Homing(params(8, **kw), CAMS, 0)
    # 35/37 need no speeds
    assert Homing(params(37, **kw), CAMS, 0).attained


# --- status word through every phase --------------------------------------------


def test_status_is_in_progress_before_the_first_step() -> None:
    h = Homing(params(8), CAMS, 0)
    assert h.status_bits() == (False, False, False)
    assert not h.done and not h.attained and not h.error


def test_status_never_reserved_and_sw10_only_at_rest() -> None:
    r = run(params(13), CAMS, S_RIGHT)
    for _s10, s12, s13 in r.statuses:
        assert not (s12 and s13)
    attained_at = next(k for k, s in enumerate(r.statuses) if s[1])
    completed_at = next(k for k, s in enumerate(r.statuses) if s[0] and s[1])
    assert attained_at < completed_at
    # after completion the demand no longer moves
    assert len(set(r.demands[completed_at:])) == 1


def test_halt_during_search_interrupts() -> None:
    seen = []

    def cb(k: int, h: Homing) -> None:
        if k == 100:
            h.halt(True)
        if k == 102:
            seen.append(h.status_bits())
        if k == 900:
            h.halt(False)  # releasing halt does not resume the search

    r = run(params(8), CAMS, S_LEFT, on_cycle=cb, max_s=2.0, extra_cycles=1000)
    h = r.homing
    assert seen == [(False, False, False)]  # decelerating: SW10 = 0
    assert h.phase is HomingPhase.INTERRUPTED and not h.attained and not h.error
    assert h.status_bits() == (True, False, False)
    assert r.distinct_statuses() == ["000", "001"]
    # halted at 10000 counts/s (0.1 s into the ramp): braking at 609A takes 500 counts,
    # short of C1 at -7550
    stop = r.final
    assert r.positions[100] < stop <= r.positions[100] + 10000**2 / 2 / 100000 + 20
    assert stop < -7550
    assert r.positions[-1] == r.positions[-3]


def test_halt_after_home_found_stops_and_reports_completed() -> None:
    def cb(k: int, h: Homing) -> None:
        if h.attained:
            h.halt(True)

    r = run(params(24), CAMS, S_MID, on_cycle=cb)
    h = r.homing
    assert h.attained and h.home_machine_position == 2450
    assert h.status_bits() == (True, True, False)
    assert r.distinct_statuses() == ["000", "010", "011"]
    assert r.final > 2450  # stopped past the edge, did not return


def test_error_while_moving_reports_sw10_zero_until_stopped() -> None:
    r = run(params(2), LIMITS, 5000)  # 2 moves + to PL: ok, sanity
    assert r.homing.attained
    no_nl = AxisMachine(counts_per_rev=1000, positive_limit=10000, index_offset=130)
    r = run(params(1, max_travel=30000), no_nl, 9000)
    # 1 searches - for NL, which does not exist; the travel bound trips at full speed
    assert r.homing.error
    first_err = next(k for k, s in enumerate(r.statuses) if s[2])
    assert r.statuses[first_err] == (False, False, True)
    assert r.statuses[-1] == (True, False, True)


# --- ramps and speeds ------------------------------------------------------------


@pytest.mark.parametrize("method", [7, 12, 18, 33])
def test_demand_respects_speeds_and_acceleration(method: int) -> None:
    machine = LIMITS if method in (18, 33) else CAMS
    p = params(method)
    r = run(p, machine, 7000 if method != 33 else 500, dt=0.001)
    d = r.demands
    v = [(b - a) / 0.001 for a, b in itertools.pairwise(d)]
    assert max(abs(x) for x in v) <= p.speed_switch + 1e-6
    acc = [(b - a) / 0.001 for a, b in itertools.pairwise(v)]
    # ramps at 609A; the landing on the home point may exceed it by a fraction of a*dt
    assert max(abs(x) for x in acc) <= p.acceleration * 1.15
    assert sorted(abs(x) for x in acc)[-3] <= p.acceleration * 1.0001
    if method == 33:  # index search at 6099:02 only
        assert max(abs(x) for x in v) <= p.speed_zero + 1e-6


def test_final_approach_after_reversal_is_at_search_zero_speed() -> None:
    # method 7 from the left: + fast into C1, reverse, cross -7550 at 6099:02
    r = run(params(7), CAMS, S_LEFT)
    pos = r.positions
    k = next(i for i in range(1, len(pos)) if pos[i - 1] > -7550 >= pos[i])
    assert abs(pos[k] - pos[k - 1]) <= 2000 * 0.001 + 1e-9


# --- home offset -----------------------------------------------------------------


def test_home_offset_sign_convention() -> None:
    r = run(params(24, home_offset=777), CAMS, S_MID)
    h = r.homing
    off = h.encoder_offset()
    assert off == 2450 - 777
    # 6064 = machine - offset: the home point reads 607C, 100 counts further reads 877
    assert r.final - off == pytest.approx(777)
    assert (2550 - off) == 877


@settings(max_examples=40, deadline=None)
@given(
    method=st.sampled_from([1, 2, 3, 4, 5, 6, 17, 18, 19, 20, 21, 22, 33, 34]),
    edge=st.integers(-5000, 5000),
    cpr=st.integers(200, 2000),
    offset_frac=st.floats(0.01, 0.99),
    start_frac=st.floats(0.0, 1.0),
    speed=st.floats(3000.0, 30000.0),
    zero_ratio=st.floats(0.05, 1.0),
    acc=st.floats(50000.0, 500000.0),
    dt=st.sampled_from([0.0005, 0.001, 0.004]),
    lag=st.integers(1, 3),
)
@pytest.mark.long
def test_random_switch_layout_matches_method_table(
    method, edge, cpr, offset_frac, start_frac, speed, zero_ratio, acc, dt, lag
) -> None:
    nl, pl = -12000.0, 12000.0
    e = edge + 0.5
    offset = 0.37 + offset_frac * cpr
    base = method - 16 if 17 <= method <= 22 else method
    hs: tuple[tuple[float, float], ...] = ()
    if base in (3, 4):
        hs = ((e, pl + 10000.0),)  # positive home switch
    elif base in (5, 6):
        hs = ((nl - 10000.0, e),)  # negative home switch
    ref = {1: nl, 2: pl}.get(base, e)
    m = AxisMachine(
        counts_per_rev=cpr,
        negative_limit=nl,
        positive_limit=pl,
        home_switch=hs,
        index_offset=offset,
    )
    if base in (33, 34):
        start = nl + 3000 + start_frac * (pl - nl - 6000)
        ref = start
    else:
        start = nl - 2000 + start_frac * (pl - nl + 4000)
    if abs((ref - offset) / cpr - round((ref - offset) / cpr)) < 1e-9:
        return  # an index exactly on the edge is ambiguous
    right = base in (1, 4, 5, 34)
    if method in (17, 18, 19, 20, 21, 22):
        expected = ref
    elif right:
        expected = _first_index_right(ref, offset, cpr)
    else:
        expected = _first_index_left(ref, offset, cpr)
    p = params(method, speed_switch=speed, speed_zero=speed * zero_ratio, acceleration=acc)
    r = run(p, m, start, dt=dt, lag=lag, max_s=40.0)
    assert r.homing.attained, (start, r.homing.reason)
    assert r.homing.home_machine_position == pytest.approx(expected, abs=1e-9)
    assert r.final == pytest.approx(expected, abs=1e-6)
    assert r.attained_dir == (1 if right else -1)


def test_touching_home_switch_windows_form_one_cam() -> None:
    split = AxisMachine(
        counts_per_rev=1000,
        negative_limit=-10000,
        positive_limit=10000,
        home_switch=((2450, 3000), (3000, 4700)),
        index_offset=130,
    )
    # method 10 from between: through the cam, index right of its high edge 4700
    assert run(params(10), split, S_MID).homing.home_machine_position == 5130
    # method 9 from the left: exit at 4700, back, first index left of 4700
    assert run(params(9), split, S_MID).homing.home_machine_position == 4130
