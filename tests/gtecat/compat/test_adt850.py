"""The ADT850 API (gtecat.compat.adt850) against seed 004's worked examples and closed forms.

Sections cited are seed 004's (/work/shared/seeds/004_2601a796f34a5868.txt): chapter 7
(3.x parameters, 5.x drives), chapter 9 (9.2 speeds), chapter 10 (the VB/VC examples).
Everything here goes through the compat API; time passes with gt.GTE_Wait (lockstep).
"""

from __future__ import annotations

import math
from ctypes import byref, c_int, c_long

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gtecat import gt
from gtecat.compat import adt850 as adt
from tests.conftest import examples

from .conftest import open_card


def pos(axis: int) -> int:
    p = c_long()
    assert adt.get_command_pos(0, axis, byref(p)) == 0
    return p.value


def actual(axis: int) -> int:
    p = c_long()
    assert adt.get_actual_pos(0, axis, byref(p)) == 0
    return p.value


def status(axis: int) -> int:
    v = c_int()
    assert adt.get_status(0, axis, byref(v)) == 0
    return v.value


def inp_running(no: int = 1) -> int:
    v = c_int()
    assert adt.get_inp_status(0, no, byref(v)) == 0
    return v.value


def wait_axes(*axes: int, limit: int = 200_000) -> int:
    for k in range(limit):
        if all(status(a) == 0 for a in axes):
            return k
        gt.GTE_Wait(1)
    raise AssertionError("the drive never ended")


def init(multiple: int = 10, **machine) -> None:
    """The VB example's Init_Card (chapter 10, 1.2): range 8000000/MULTIPLE, counters 0,
    SV = V = 1000/MULTIPLE."""
    open_card(**machine)
    assert adt.adt850_initial() == 1
    for i in range(1, 5):
        assert adt.set_range(0, i, 8_000_000 // multiple) == 0
        assert adt.set_command_pos(0, i, 0) == 0
        assert adt.set_actual_pos(0, i, 0) == 0
        assert adt.set_startv(0, i, 1000 // multiple) == 0
        assert adt.set_speed(0, i, 1000 // multiple) == 0


def setup_speed(axis: int, startv: int, speed: int, add: int, multiple: int = 10) -> None:
    """The VB example's Setup_Speed (chapter 10, 1.2), in PPS and PPS/s."""
    if startv - speed >= 0:
        assert adt.set_startv(0, axis, startv // multiple) == 0
        assert adt.set_speed(0, axis, startv // multiple) == 0
    else:
        assert adt.set_startv(0, axis, startv // multiple) == 0
        assert adt.set_speed(0, axis, speed // multiple) == 0
        assert adt.set_acc(0, axis, add // 125 // multiple) == 0


# --- 3.x parameter examples -------------------------------------------------------------
def test_range_acac_acc_examples_of_3_1_to_3_3():
    """3.1: set_range(0,1,800000) is M = 10, set_range(0,3,16000) M = 500; 3.2: K = 100 with
    R = 800000 is 6250000 PPS/s²; 3.3: R = 80000, A = 100 is 1250000 PPS/s."""
    init()
    card = adt.card()
    assert adt.set_range(0, 1, 800_000) == 0 and card.regs[1].m == 10
    assert adt.set_range(0, 3, 16_000) == 0 and card.regs[3].m == 500
    assert adt.set_acac(0, 1, 100) == 0
    adt.set_ad_mode(0, 1, 1)
    assert card.regs[1].params().jerk * 1e9 == pytest.approx(6_250_000)
    assert adt.set_range(0, 2, 80_000) == 0 and adt.set_acc(0, 2, 100) == 0
    assert card.regs[2].params().acc * 1e6 == pytest.approx(1_250_000)


def test_speed_example_of_9_2_100_khz_and_10_khz():
    """9.2 (速度的设定): R = 640000 (M = 12.5); V 8000 is 100 kHz, V 800 is 10 kHz."""
    init()
    for v, khz in ((8000, 100), (800, 10)):
        assert adt.set_range(0, 1, 640_000) == 0
        assert adt.set_startv(0, 1, v) == 0 and adt.set_speed(0, 1, v) == 0  # constant (2.1)
        p0 = pos(1)
        assert adt.continue_move(0, 1, 0) == 0
        gt.GTE_Wait(10)
        p1 = pos(1)
        gt.GTE_Wait(100)
        assert pos(1) - p1 == pytest.approx(khz * 100, abs=1)  # kHz = pulses per ms
        spd = c_long()
        assert adt.get_speed(0, 1, byref(spd)) == 0 and spd.value == v
        assert adt.sudden_stop(0, 1) == 0
        gt.GTE_Wait(1)
        assert status(1) == 0 and pos(1) > p0


# --- 5.1 fixed drives ----------------------------------------------------------------------
@pytest.mark.long
def test_pmove_t_curve_closed_form_time_and_exact_end():
    """5.1 with 2.2's symmetric T curve: SV 100, V 2000, A 100 (x125x10 PPS/s)."""
    init()
    setup_speed(1, 1000, 20_000, 125_000)
    assert adt.pmove(0, 1, 50_000) == 0
    k = wait_axes(1)
    sv, v, a = 1.0, 20.0, 0.125  # pulse/ms, pulse/ms²
    t_ramp = (v - sv) / a
    t = 2 * t_ramp + (50_000 - (sv + v) * t_ramp) / v
    assert k == pytest.approx(math.ceil(t), abs=1)
    assert pos(1) == 50_000
    gt.GTE_Wait(20)
    assert abs(actual(1) - 50_000) <= 1  # the encoder follows the amplifier


@pytest.mark.long
def test_s_curve_status_bits_follow_the_sections():
    """2.1: D5/D6/D7 while the acceleration grows / holds / falls; D2 D3 D4 accel/const/dec."""
    init()
    setup_speed(1, 1000, 40_000, 125_000)
    assert adt.set_ad_mode(0, 1, 1) == 0 and adt.set_acac(0, 1, 200) == 0
    assert adt.pmove(0, 1, 60_000) == 0
    seen = set()
    for _ in range(20_000):
        gt.GTE_Wait(1)
        s = status(1)
        if s == 0:
            break
        seen.add(s & 0xFC)
    assert {0x04 | 0x20, 0x04 | 0x40, 0x04 | 0x80, 0x08, 0x10 | 0x20, 0x10 | 0x40} <= seen
    assert pos(1) == 60_000


@pytest.mark.long
def test_manual_deceleration_point_of_the_vb_example():
    """Chapter 10 Set_DecPos: DecPulse = (StartV + Speed)·addtime/2, addtime = (Speed -
    StartV)/Add; set_dec_pos(value - DecPulse): the drive reaches SV as the pulses end."""
    init()
    startv, speed, add, value = 1000, 20_000, 125_000, 40_000
    setup_speed(1, startv, speed, add)
    assert adt.set_dec2_mode(0, 1, 1) == 0
    addtime = (speed - startv) / add
    dec_pulse = (startv + speed) * addtime / 2
    assert adt.set_dec_pos(0, 1, round(value - dec_pulse)) == 0
    assert adt.pmove(0, 1, value) == 0
    speeds = []
    for _ in range(10_000):
        gt.GTE_Wait(1)
        s = c_long()
        adt.get_speed(0, 1, byref(s))
        speeds.append(s.value)
        if status(1) == 0:
            break
    assert pos(1) == value
    assert speeds[-3] <= 2 * startv // 10  # near SV at the end, no long SV tail
    assert max(speeds) == speed // 10


def test_continuous_drive_and_dec_stop():
    init()
    setup_speed(2, 1000, 20_000, 125_000)
    assert adt.continue_move(0, 2, 1) == 0  # negative
    gt.GTE_Wait(500)
    assert status(2) & 0x08  # cruising
    assert adt.dec_stop(0, 2) == 0
    gt.GTE_Wait(1)
    assert status(2) & 0x10
    wait_axes(2)
    assert pos(2) < 0


# --- 5.5-5.9 interpolation ------------------------------------------------------------------
def test_line_xy_long_axis_speed_points_within_half_lsb():
    """5.1 of chapter 5: the line within ±0.5 LSB; 9.2.6: the speed is the long axis's."""
    init()
    setup_speed(1, 10_000, 10_000, 0)  # constant 10 kPPS = 10 pulse/ms on the long axis
    x1, y1 = 3000, -1000
    assert adt.inp_move2(0, 1, x1, y1) == 0
    xs = []
    for _ in range(10_000):
        gt.GTE_Wait(1)
        xs.append((pos(1), pos(2)))
        if not inp_running():
            break
    for x, y in xs:
        assert abs(x * y1 - y * x1) / math.hypot(x1, y1) <= 0.5 * math.sqrt(2) + 1e-9
    assert xs[-1] == (x1, y1)
    assert len(xs) == pytest.approx(3000 / 10, abs=1)  # 3000 base pulses at 10 per ms


@pytest.mark.long
def test_xy_dec_disabled_by_default_then_enabled_auto_deceleration():
    """9.2.6: "默认情况是插补减速禁止": a lone node accelerates and stops at once; with
    inp_dec_enable it decelerates to SV at its end."""
    init()
    setup_speed(1, 1000, 20_000, 125_000)
    assert adt.inp_move2(0, 1, 20_000, 5000) == 0
    last = []
    while inp_running():
        gt.GTE_Wait(1)
        s = c_long()
        adt.get_speed(0, 1, byref(s))
        last.append(s.value)
    assert max(last[-5:-1]) == 2000  # full speed until the end
    assert adt.inp_dec_enable(0, 1) == 0
    assert adt.inp_move2(0, 1, -20_000, -5000) == 0
    last = []
    while inp_running():
        gt.GTE_Wait(1)
        s = c_long()
        adt.get_speed(0, 1, byref(s))
        last.append(s.value)
    assert max(last[-5:-1]) <= 200
    assert (pos(1), pos(2)) == (0, 0)


@pytest.mark.long
def test_continuous_interpolation_of_chapter_10_1_3_5():
    """Four X-Y nodes (the VB CmdContinueInp): decel disabled, manual deceleration on the
    last node, each next node written when get_inp_status2 allows; the speed never falls
    between nodes and the path ends on 4 x (Pos)."""
    init()
    startv, speed, add, px, py = 1000, 20_000, 125_000, 10_000, 4000
    setup_speed(1, startv, speed, add)
    assert adt.set_dec1_mode(0, 1, 0) == 0 and adt.set_dec2_mode(0, 1, 1) == 0
    dec_pulse = (startv + speed) * ((speed - startv) / add) / 2
    assert adt.set_dec_pos(0, 1, round(px - dec_pulse)) == 0
    assert adt.inp_dec_disable(0, 1) == 0
    speeds = []
    for node in range(4):
        if node == 3:
            assert adt.inp_dec_enable(0, 1) == 0
        assert adt.inp_move2(0, 1, px, py) == 0, adt.last_error()
        ok, err = c_int(), c_int()
        while True:
            gt.GTE_Wait(1)
            s = c_long()
            adt.get_speed(0, 1, byref(s))
            speeds.append(s.value)
            adt.get_stopdata(0, 1, byref(err))
            assert err.value == 0
            if node < 3:
                adt.get_inp_status2(0, 1, byref(ok))
                if ok.value:
                    break
            else:
                adt.get_inp_status(0, 1, byref(ok))
                if ok.value == 0:
                    break
    assert (pos(1), pos(2)) == (4 * px, 4 * py)
    cruise = speeds.index(speed // 10)
    assert min(speeds[cruise:-200]) == speed // 10  # no stop between nodes


def test_half_circle_of_chapter_10_1_3_6_on_the_circle():
    """The VB CmdInpArc: Interp_Arc(1, 2·Pos, 2·Pos, Pos, Pos, cw) with a manual
    deceleration at (r/1.414)·8 base pulses: a half circle through (0,0) and (2p, 2p)."""
    init()
    p = 3000
    setup_speed(1, 1000, 10_000, 62_500)
    assert adt.set_dec2_mode(0, 1, 1) == 0
    value = (math.sqrt(p * p + p * p) / 1.414) * 8
    startv, speed, add = 1000, 10_000, 62_500
    dec_pulse = (startv + speed) * ((speed - startv) / add) / 2
    assert adt.set_dec_pos(0, 1, round(value / 2 - dec_pulse)) == 0
    assert adt.inp_dec_enable(0, 1) == 0
    assert adt.inp_cw_arc(0, 1, 2 * p, 2 * p, p, p) == 0, adt.last_error()
    r = math.hypot(p, p)
    pts = []
    while inp_running():
        gt.GTE_Wait(1)
        pts.append((pos(1), pos(2)))
    for x, y in pts:
        assert abs(math.hypot(x - p, y - p) - r) <= 1.0
        # clockwise from (0,0) around (p,p) to (2p,2p): through the side y > x
        assert (x - p) * 0 + (y - x) >= -1
    assert pts[-1] == (2 * p, 2 * p)


def z_like_x(speed: int) -> None:
    """5.8/5.9: Z's multiplier and speed as X's, Z's start speed = X's speed."""
    setup_speed(3, speed, speed, 0)


def test_three_and_four_axis_lines_end_exactly():
    init()
    setup_speed(1, 20_000, 20_000, 0)
    z_like_x(20_000)
    assert adt.inp_move3(0, 1000, -2000, 3000) == 0
    while inp_running():
        gt.GTE_Wait(1)
    assert [pos(a) for a in (1, 2, 3)] == [1000, -2000, 3000]
    assert adt.inp_move4(0, 1, 2, 3, -4000) == 0
    k = 0
    while inp_running():
        gt.GTE_Wait(1)
        k += 1
    assert [pos(a) for a in (1, 2, 3, 4)] == [1001, -1998, 3003, -4000]
    assert k == pytest.approx(4000 / 20, abs=1)  # long axis W at 20 pulse/ms
    assert adt.inp_clear(0) == 0


def test_zw_pair_uses_z_speed():
    init()
    setup_speed(3, 5000, 5000, 0)
    assert adt.inp_move2(0, 2, 1000, 500) == 0
    k = 0
    while inp_running(2):
        gt.GTE_Wait(1)
        k += 1
    assert (pos(3), pos(4)) == (1000, 500)
    assert k == pytest.approx(1000 / 5, abs=1)


def test_refusals_of_5_4():
    """5.4: no S-curve arcs; an accelerating arc decelerates only manually."""
    init()
    setup_speed(1, 1000, 10_000, 62_500)
    assert adt.inp_dec_enable(0, 1) == 0
    assert adt.inp_cw_arc(0, 1, 0, 0, 1000, 0) == 1  # automatic deceleration
    assert "manual" in adt.last_error()
    assert adt.set_ad_mode(0, 1, 1) == 0
    assert adt.inp_ccw_arc(0, 1, 0, 0, 1000, 0) == 1
    assert "S-curve" in adt.last_error()


# --- signals ------------------------------------------------------------------------------
def test_stop0_home_switch_stops_and_reports_stopdata_d0():
    """1.3 and 2.2: STOP0 valid: the drive decelerates at the home switch; D0 set."""
    init(a1=dict(home_switch=((5000, 6000),)))
    setup_speed(1, 1000, 10_000, 125_000)
    assert adt.set_stop0_mode(0, 1, 1, 0) == 0
    assert adt.continue_move(0, 1, 0) == 0
    wait_axes(1)
    data = c_int()
    assert adt.get_stopdata(0, 1, byref(data)) == 0 and data.value & 0x01
    assert 5000 <= pos(1) <= 6500
    assert adt.read_bit(0, 2) == 0  # X STOP0 = the home switch, active: low (6.3)


def test_limit_switch_stops_and_reports_d3():
    init(a1=dict(positive_limit=3000))
    setup_speed(1, 5000, 5000, 0)
    assert adt.pmove(0, 1, 10_000) == 0
    wait_axes(1)
    data = c_int()
    adt.get_stopdata(0, 1, byref(data))
    assert data.value & 0x08
    assert 3000 <= pos(1) <= 3010
    di = c_long()
    assert adt.read_di(0, byref(di)) == 0 and not di.value & 0x1  # LMT+ active: low (6.1)
    assert adt.pmove(0, 1, -1000) == 0  # away from the limit is allowed
    wait_axes(1)


@pytest.mark.long
def test_soft_limit_comp_plus_decelerates():
    """1.9 / 3.9: COMP+ as a soft limit: a decelerating stop, D6; then only - moves."""
    init()
    setup_speed(1, 1000, 10_000, 125_000)
    assert adt.set_comp1(0, 1, 20_000) == 0 and adt.set_softlimit_mode1(0, 1, 1) == 0
    assert adt.continue_move(0, 1, 0) == 0
    wait_axes(1)
    data = c_int()
    adt.get_stopdata(0, 1, byref(data))
    assert data.value & 0x40
    assert 20_000 <= pos(1) < 21_000
    # further + is taken and ends at once with D6 (chapter 8: 1 is for a wrong card or axis)
    at = pos(1)
    assert adt.pmove(0, 1, 100) == 0
    assert status(1) == 0 and pos(1) == at
    adt.get_stopdata(0, 1, byref(data))
    assert data.value == 0x40
    assert adt.pmove(0, 1, -100) == 0


def test_outputs():
    init()
    assert adt.write_do(0, 0x12345678) == 0
    assert adt.write_bit(0, 0, 1) == 0 and adt.write_bit(0, 4, 0) == 0
    assert adt.read_outputs() == 0x12345669


# --- return codes and arguments --------------------------------------------------------------
def test_return_codes_of_chapter_8_4():
    """8.4: 1 for a wrong card or axis number; read_bit -1; adt850_initial the card count."""
    init()
    v = c_int()
    assert adt.get_status(1, 1, byref(v)) == 1
    assert adt.get_status(0, 5, byref(v)) == 1
    assert adt.get_status(0, 0, byref(v)) == 1
    assert adt.read_bit(0, 32) == -1 and adt.read_bit(1, 0) == -1
    assert adt.set_range(0, 1, 15_999) == 1 and adt.set_speed(0, 1, 8001) == 1
    assert adt.pmove(0, 1, 268_435_456) == 1
    assert adt.inp_move2(0, 3, 1, 1) == 1


def test_initial_without_a_card_is_0():
    from tests.conftest import EXAMPLES

    assert gt.GT_Open(eni=str(EXAMPLES / "manual_fig5_2.eni"), clock="lockstep", log="") == 0
    assert adt.adt850_initial() == 0


_VALUES = st.one_of(
    st.integers(-(2**40), 2**40), st.floats(allow_nan=True), st.none(), st.text(max_size=3)
)


@settings(
    max_examples=examples(150, 15),
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(
    name=st.sampled_from(
        ["set_range", "set_acac", "set_acc", "set_dec", "set_startv", "set_speed", "pmove",
         "continue_move", "set_ad_mode", "set_dec_pos", "set_command_pos", "set_comp1"]
    ),
    cardno=st.one_of(st.just(0), _VALUES),
    axis=st.one_of(st.integers(0, 5), _VALUES),
    value=_VALUES,
)  # fmt: skip
def test_property_bad_arguments_return_1_never_raise(name, cardno, axis, value):
    if adt.card() is None:
        init()
    rc = getattr(adt, name)(cardno, axis, value)
    assert rc in (0, 1)
    if cardno != 0 or axis not in (1, 2, 3, 4):
        assert rc == 1
    adt.sudden_stop(0, 1)
    adt.sudden_stop(0, 2)


# --- a scenario through the compat API only -------------------------------------------------
@pytest.mark.long
def test_scenario_four_axes_move_status_and_positions():
    """The VB CmdPmove with all four axes, then an X-Y interpolation, read back as the
    monitor timer (1.4) does: positions, speeds, get_status until all are 0."""
    init()
    for i in range(1, 5):
        setup_speed(i, 1000, 20_000, 125_000)
    targets = [10_000, -5000, 2500, 7777]
    for i, p in enumerate(targets, 1):
        assert adt.pmove(0, i, p) == 0
    gt.GTE_Wait(100)
    assert all(status(i) != 0 for i in range(1, 5))
    wait_axes(1, 2, 3, 4)
    assert [pos(i) for i in range(1, 5)] == targets
    gt.GTE_Wait(20)
    assert [abs(actual(i) - t) <= 1 for i, t in enumerate(targets, 1)] == [True] * 4
    assert adt.inp_dec_enable(0, 1) == 0
    assert adt.inp_move2(0, 1, -10_000, 5000) == 0
    while inp_running():
        gt.GTE_Wait(1)
    assert (pos(1), pos(2)) == (0, 0)
    assert adt.adt850_end() == 0


# --- what a user of the card hits: the documents' own rules ---------------------------------
def test_a_stop2_stop_clears_the_real_position_counter():
    """1.5 note and 9.4: with STOP2 valid, the real position counter clears at the STOP2
    signal; what it reads after the stop is the way run after the signal, not the distance
    from the start (and the manual tells users not to clear it in software)."""
    init(a1=dict(probe1=((8000, 9000),)))
    setup_speed(1, 1000, 10_000, 125_000)
    assert adt.set_actual_pos(0, 1, 4321) == 0
    assert adt.set_stop2_mode(0, 1, 1, 0) == 0
    assert adt.continue_move(0, 1, 0) == 0
    wait_axes(1)
    data = c_int()
    assert adt.get_stopdata(0, 1, byref(data)) == 0 and data.value & 0x04
    assert pos(1) > 8000  # the logic counter keeps counting
    assert 0 <= actual(1) <= pos(1) - 8000 + 1  # the real one counted from the signal


def test_the_variable_ring_counts_from_0_to_comp_plus():
    """1.17 / 4.3: with the ring on, 9990 + 20 with COMP+ 9999 reads 10, not 10010; the
    real counter wraps at COMP-; the COMP registers are no soft limits then."""
    init()
    setup_speed(1, 1000, 1000, 0)
    assert adt.set_comp1(0, 1, 9999) == 0 and adt.set_comp2(0, 1, 9999) == 0
    assert adt.set_softlimit_mode1(0, 1, 1) == 0
    assert adt.set_circle_mode(0, 1, 1) == 0
    assert adt.set_command_pos(0, 1, 9990) == 0 and adt.set_actual_pos(0, 1, 9990) == 0
    assert adt.pmove(0, 1, 20) == 0
    wait_axes(1)
    assert pos(1) == 10 and actual(1) == 10
    assert adt.set_command_pos(0, 1, 5) == 0
    assert adt.pmove(0, 1, -10) == 0  # the soft limit COMP+ does not stop the ring
    wait_axes(1)
    assert pos(1) == 9995  # 5 - 10 wraps below 0 to the top
    assert adt.set_circle_mode(0, 1, 0) == 0
    assert pos(1) == -5  # ring off: the plain 32-bit counter again


@pytest.mark.parametrize(("logic", "level"), [(0, 0), (1, 1)])
def test_inputs_read_their_electrical_level(logic, level):
    """6.1/6.3: 0 is a low input level. A limit is low-active by default (1.1), so an
    active LMT+ reads 0; set high-active it reads 1. An inactive one reads the other."""
    init(a1=dict(positive_limit=0))
    assert adt.set_limit_mode(0, 1, 0, logic) == 0
    assert adt.read_bit(0, 0) == level  # X LMT+ active
    assert adt.read_bit(0, 1) == 1 - level  # X LMT- inactive
    di = c_long()
    assert adt.read_di(0, byref(di)) == 0 and di.value & 1 == level


def test_status_right_after_pmove_reads_accelerating():
    """2.1: a T drive that just started is accelerating (D2), before any cycle ran."""
    init()
    setup_speed(1, 1000, 10_000, 125_000)
    assert adt.pmove(0, 1, 50_000) == 0
    assert status(1) & 0x04
    assert not status(1) & 0x08


def test_a_drive_into_an_active_limit_is_taken_and_ends_at_once():
    """A drive toward a limit that is on: 0, no motion, get_stopdata D3 (chapter 8 keeps 1
    for a wrong card or axis)."""
    init(a1=dict(positive_limit=0))
    setup_speed(1, 1000, 1000, 0)
    assert adt.pmove(0, 1, 500) == 0
    assert status(1) == 0 and pos(1) == 0
    data = c_int()
    assert adt.get_stopdata(0, 1, byref(data)) == 0 and data.value == 0x08


def test_appendix_b_home1_finds_the_switch_and_zeroes_the_counters():
    """B.2: home1 searches STOP0 in the tool's direction; 1 and both counters 0 there."""
    open_card(a1=dict(position=20_000, home_switch=((5_000, 6_000),)))
    assert adt.adt850_init_board({n: adt.AppParams(home_speed=20.0) for n in range(1, 5)}) == 1
    assert adt.home1(1) == 1
    assert pos(1) == 0 and actual(1) == 0


def test_appendix_b_home1_without_a_signal_or_limit_returns_minus_2():
    """B.2 return -2, "未检测到原点信号": no home switch and no limit ahead - refused at once
    with the reason, instead of a search that never ends."""
    open_card(a1=dict(position=20_000))
    assert adt.adt850_init_board({n: adt.AppParams() for n in range(1, 5)}) == 1
    before = pos(1)
    assert adt.home1(1) == -2
    assert "no home switch (STOP0) and no limit switch" in adt.last_error()
    assert pos(1) == before  # nothing moved
    assert adt.home4() == -2


def test_appendix_b_home1_stopped_by_a_limit_returns_minus_2_with_the_reason():
    """B.2 -2 after a search that met a limit switch instead of the home signal: the stop
    data says why and last_error() names it."""
    open_card(a1=dict(position=0, negative_limit=-1_000))
    assert adt.adt850_init_board({n: adt.AppParams() for n in range(1, 5)}) == 1
    assert adt.home1(1) == -2
    assert "axis 1 stopped before its home signal" in adt.last_error()


def test_actualcount_mode_sets_the_real_counters_direction_and_multiplication():
    """1.6: dir 1 counts the other way; freq 1 (2x) counts half the 4x pulses."""
    init()
    setup_speed(1, 1000, 1000, 0)
    assert adt.set_actualcount_mode(0, 1, 0, 1, 1) == 0
    assert actual(1) == 0
    assert adt.pmove(0, 1, 1000) == 0
    wait_axes(1)
    assert pos(1) == 1000 and actual(1) == -500


def test_three_axis_interpolation_needs_z_set_as_x():
    """5.8 note: Z's multiplier and drive speed as X's, Z's start speed = X's drive speed;
    other Z settings are refused with the rule."""
    init()
    setup_speed(1, 1000, 20_000, 125_000)
    assert adt.inp_move3(0, 1000, 1000, 1000) == 1
    assert "Z needs X's range and speed" in adt.last_error()
    z_like_x(20_000)
    assert adt.inp_move3(0, 1000, 1000, 1000) == 0


def test_an_unfinished_three_axis_interpolation_needs_inp_clear():
    """9.3 / 5.12: stopped before its distance, a 3/4-axis interpolation leaves Z and W
    moving wrongly until inp_clear; after it they move again."""
    init()
    setup_speed(1, 20_000, 20_000, 0)
    z_like_x(20_000)
    assert adt.inp_move3(0, 100_000, 0, 100_000) == 0
    gt.GTE_Wait(50)
    assert adt.sudden_stop(0, 1) == 0
    while inp_running():
        gt.GTE_Wait(1)
    assert adt.pmove(0, 3, 100) == 1 and "until inp_clear" in adt.last_error()
    assert status(3) == status(4) == 0x100  # 5.12: Z and W stay in the drive state
    assert adt.inp_move3(0, 10, 10, 10) == 1
    assert adt.pmove(0, 1, 100) == 0  # X is not concerned
    assert adt.inp_clear(0) == 0
    assert status(3) == status(4) == 0
    assert adt.pmove(0, 3, 100) == 0


# --- what a user of the card still hit: cards, INPOS, levels, settings -----------------------
def stopdata(axis: int, cardno: int = 0) -> int:
    v = c_int()
    assert adt.get_stopdata(cardno, axis, byref(v)) == 0
    return v.value


def test_up_to_16_cards_each_its_own_and_one_time():
    """1.1 and chapter 1: adt850_initial returns the number of cards (a PC holds up to 16),
    numbered 0, 1, 2 ...; each is a card of its own: its axes, registers and switches. A
    card number it did not find is an error (8.4: 1)."""
    from gtecat.drives.machine import AxisMachine, MachineDescription

    open_card()
    limit_on_x = MachineDescription({1: AxisMachine(positive_limit=0)})
    assert adt.adt850_initial(cards=3, machines={2: limit_on_x}) == 3
    for cardno in (0, 1, 2):
        assert adt.set_range(cardno, 1, 800_000) == 0
        assert adt.set_startv(cardno, 1, 100) == 0 and adt.set_speed(cardno, 1, 100) == 0
    assert adt.pmove(1, 1, 500) == 0
    assert adt.pmove(2, 1, 500) == 0  # card 2's X stands on its limit: taken, ended (D3)
    gt.GTE_Wait(20)  # time passes for every card at once
    p = [c_long() for _ in range(3)]
    for cardno in (0, 1, 2):
        assert adt.get_command_pos(cardno, 1, byref(p[cardno])) == 0
    assert [x.value for x in p] == [0, 20, 0]  # 1 pulse/ms on card 1 only
    assert stopdata(1, 2) == 0x08 and stopdata(1, 1) == 0
    assert adt.read_bit(2, 0) == 0 and adt.read_bit(1, 0) == 1  # only card 2's LMT+ is low
    assert adt.get_command_pos(3, 1, byref(p[0])) == 1
    assert "found 3 card(s), 0..2" in adt.last_error()
    assert adt.adt850_end() == 0


def test_card_count_from_the_environment(monkeypatch):
    monkeypatch.setenv("GTECAT_ADT850_CARDS", "2")
    open_card()
    assert adt.adt850_initial() == 2
    assert adt.adt850_initial(cards=17) == -1 and "out of" in adt.last_error()
    monkeypatch.setenv("GTECAT_ADT850_CARDS", "two")
    assert adt.adt850_initial() == -1 and "the number of cards, 1..16" in adt.last_error()


def test_inpos_valid_the_drive_ends_when_the_amplifier_is_in_position():
    """1.12 and chapter 5 (伺服马达对应的信号): with INPOS valid, a drive whose pulses are out
    ends only when INPOS is active; get_status reads D8 (0x100) while it waits. Without
    it the drive ends with the last pulse, the amplifier still a few pulses behind."""
    init()
    assert adt.set_range(0, 1, 200_000) == 0  # M = 40: 200 pulse/ms, a lagging amplifier
    assert adt.set_startv(0, 1, 5000) == 0 and adt.set_speed(0, 1, 5000) == 0
    lags, waits = [], []
    for valid in (0, 1):
        gt.GTE_Wait(10)  # the motor catches up with the last drive
        assert adt.set_inpos_mode(0, 1, valid, 0) == 0
        assert adt.set_command_pos(0, 1, 0) == 0 and adt.set_actual_pos(0, 1, 0) == 0
        assert adt.pmove(0, 1, 30_000) == 0
        seen = []
        while (s := status(1)) != 0:
            seen.append(s)
            gt.GTE_Wait(1)
        assert pos(1) == 30_000
        lags.append(30_000 - actual(1))
        waits.append(seen.count(0x100))
    assert lags[0] >= 2 and waits[0] == 0  # ended with the pulses, the motor behind
    assert lags[1] == 0 and waits[1] >= 1  # ended in position


def test_inpos_valid_but_never_active_the_drive_never_ends():
    """9.5: INPOS valid while the card cannot see it active (here: set high-active, the
    amplifier's in-position output being low): the drive status never ends; an
    interpolation (2.3) does not end either."""
    init()
    setup_speed(1, 10_000, 10_000, 0)
    assert adt.set_inpos_mode(0, 1, 1, 1) == 0
    assert adt.read_bit(0, 5) == 0  # X INPOS: low, the amplifier in position
    assert adt.pmove(0, 1, 100) == 0
    gt.GTE_Wait(200)
    assert pos(1) == 100 and status(1) == 0x100
    assert adt.set_inpos_mode(0, 1, 0, 0) == 0
    assert status(1) == 0
    assert adt.set_inpos_mode(0, 2, 1, 1) == 0
    assert adt.inp_move2(0, 1, 100, 50) == 0
    gt.GTE_Wait(100)
    assert (pos(1), pos(2)) == (200, 50) and inp_running() == 1  # Y never in position


def test_limit_level_against_the_wiring():
    """1.8 logic, 6.1: a normally-open limit switch reads low while hit. Set high-active,
    the card sees the limit active everywhere but on the switch: a + drive is taken and
    ends at once (D3), as on the card; the power-up low-active setting drives."""
    init(a1=dict(positive_limit=5000, switch_wiring="normally_open"))
    setup_speed(1, 1000, 1000, 0)
    assert adt.read_bit(0, 0) == 1  # not hit: high
    assert adt.set_limit_mode(0, 1, 0, 1) == 0
    assert adt.pmove(0, 1, 100) == 0
    assert status(1) == 0 and stopdata(1) == 0x08 and pos(1) == 0
    assert adt.set_limit_mode(0, 1, 0, 0) == 0
    assert adt.pmove(0, 1, 100) == 0
    wait_axes(1)
    assert pos(1) == 100 and stopdata(1) == 0


def test_normally_closed_limit_needs_high_active_logic():
    """A normally-closed switch opens (reads high) when hit; set high-active (1.8) the
    limit stops the drive there, at once (immediate mode, D3)."""
    init(a1=dict(positive_limit=300, switch_wiring="normally_closed"))
    setup_speed(1, 5000, 5000, 0)
    assert adt.read_bit(0, 0) == 0  # closed: low
    assert adt.set_limit_mode(0, 1, 0, 1) == 0
    assert adt.continue_move(0, 1, 0) == 0
    wait_axes(1)
    assert stopdata(1) == 0x08 and 300 <= pos(1) <= 305
    assert adt.read_bit(0, 0) == 1  # hit: open, high


def test_alarm_valid_with_a_level_the_amplifier_never_gives_stops_every_drive():
    """1.13: ALARM valid and high-active, while the healthy amplifier's alarm output is
    high (its alarm pulls it low): the card sees an alarm; a drive ends at once with D5.
    Valid and low-active, the drive runs; the amplifier in fault stops it at once (D5)."""
    init()
    setup_speed(1, 1000, 1000, 0)
    assert adt.read_bit(0, 6) == 1
    assert adt.set_alarm_mode(0, 1, 1, 1) == 0
    assert adt.pmove(0, 1, 100) == 0
    assert status(1) == 0 and stopdata(1) == 0x20
    assert adt.set_alarm_mode(0, 1, 1, 0) == 0
    assert adt.continue_move(0, 1, 0) == 0
    gt.GTE_Wait(10)
    gt.GTE_Slave(0).channel(0).inject_fault("alarm")
    gt.GTE_Wait(3)
    assert status(1) == 0 and stopdata(1) == 0x20
    assert adt.read_bit(0, 6) == 0  # the alarm output pulls the input low


def test_stop1_level_against_the_encoder_z():
    """1.4: STOP1 valid, low level (the encoder's Z pulls the input low as it passes):
    the drive stops at the index (D1). Set to stop at the high level, the card sees STOP1
    active off the index: the drive ends at once."""
    init(a1=dict(index_offset=700, counts_per_rev=10_000))
    setup_speed(1, 2000, 2000, 0)
    assert adt.set_stop1_mode(0, 1, 1, 0) == 0
    assert adt.continue_move(0, 1, 0) == 0
    wait_axes(1)
    assert stopdata(1) == 0x02 and 700 <= actual(1) <= 720
    assert adt.set_stop1_mode(0, 1, 1, 1) == 0
    at = pos(1)
    assert adt.continue_move(0, 1, 0) == 0
    wait_axes(1, limit=5)
    assert stopdata(1) == 0x02 and pos(1) - at <= 2 * 20


def test_settings_with_nothing_to_act_on_say_so():
    """1.7, 1.18, 1.19: taken (0) and said in last_error: the emulated amplifier takes any
    pulse mode, the emulated inputs have no noise to filter."""
    init()
    assert adt.set_pulse_mode(0, 1, 0, 1, 1) == 0 and "kept" in adt.last_error()
    assert adt.set_input_filter(0, 1, 1, 1) == 0 and "filter" in adt.last_error()
    assert adt.set_filter_time(0, 1, 8) == 0
    assert adt.set_filter_time(0, 1, 9) == 1
    setup_speed(1, 1000, 1000, 0)
    assert adt.pmove(0, 1, -50) == 0
    wait_axes(1)
    gt.GTE_Wait(5)
    assert pos(1) == -50 and actual(1) == -50  # the motor follows in every mode


def test_up_down_counter_input_holds_with_an_ab_encoder():
    """1.6 value 1: up/down pulse input, fed the emulated amplifier's A/B signals, counts
    up and down in turn: the real counter holds its reading."""
    init()
    setup_speed(1, 1000, 1000, 0)
    assert adt.set_actual_pos(0, 1, 77) == 0
    assert adt.set_actualcount_mode(0, 1, 1, 0, 0) == 0
    assert adt.pmove(0, 1, 300) == 0
    wait_axes(1)
    assert pos(1) == 300 and actual(1) == 77


def test_a_limit_of_any_axis_stops_an_interpolation():
    """Chapter 5 (插补时的越限错误): any axis's limit stops the interpolation, here Y's
    LMT+ at 200 on an X-Y line; get_stopdata of Y says D3."""
    init(a2=dict(positive_limit=200))
    setup_speed(1, 10_000, 10_000, 0)
    assert adt.inp_move2(0, 1, 1000, 500) == 0
    while inp_running():
        gt.GTE_Wait(1)
    assert stopdata(2) == 0x08
    assert 200 <= pos(2) <= 206 and 400 <= pos(1) <= 412
