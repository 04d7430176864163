"""The MCX314 library (gtecat.compat.mcx314) against seed 003's chapter 4.

Sections cited are seed 003's (/work/shared/seeds/003_c64bf74c371d1d19.txt): 4.3 initial
settings, 4.4 the speed formulas and T/S drives, 4.5 interpolation, 4.7 homing, 4.8 the
position registers.  Everything goes through the compat API; time passes with GTE_Wait.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gtecat import gt
from gtecat.compat import CompatError
from gtecat.compat import mcx314 as m
from tests.conftest import examples

from .conftest import open_card

X, Y, Z, U = 1, 2, 4, 8


def lp(axis: int) -> int:
    v = m.ReadLPS(axis)
    return v - 2**32 if v >= 2**31 else v


def busy(axis: int) -> bool:
    return m.card().status_word({1: 1, 2: 2, 4: 3, 8: 4}[axis]) != 0


def crd_busy(no: int = 1) -> bool:
    from gtecat.controller.crd import bank

    return bank(m.card().ctl).get(no).running


def wait(pred, limit: int = 200_000) -> int:
    for k in range(limit):
        if not pred():
            return k
        gt.GTE_Wait(1)
    raise AssertionError("never ended")


def up(**machine) -> None:
    open_card(**machine)
    m.Open()
    m.SetRange(800_000)  # M = 10 on every axis


def test_speed_formulas_of_4_4():
    """4.4: M = 8000000/R; acceleration A·125·M; jerk 62500000/K·M; SV·M; V·M."""
    up()
    card = m.card()
    m.SetSV(X, 100)
    m.SetV(X, 2000)
    m.SetA(X, 80)
    m.SetAA(X, 625)
    card.regs[1].s_curve = True
    prm = card.regs[1].params()
    assert prm.vel_start * 1000 == pytest.approx(100 * 10)
    assert prm.vel * 1000 == pytest.approx(2000 * 10)
    assert prm.acc * 1e6 == pytest.approx(80 * 125 * 10)
    assert prm.jerk * 1e9 == pytest.approx(62_500_000 / 625 * 10)
    m.SetMultiple(Y | Z, 500)
    assert card.regs[2].m == card.regs[3].m == 500 and card.regs[4].m == 10
    m.SetMaxSpeed(4_000_000)
    assert card.regs[1].m == 500


@pytest.mark.long
def test_tcurve_f_and_scurve_f_end_exactly_in_closed_form_time():
    """4.4 TCurve_F / SCurve_F: fixed drives; the chip computes the ramps, the pulses end."""
    up()
    m.TCurve_F(X, 100, 2000, 100, 30_000)
    k = wait(lambda: busy(X))
    sv, v, a = 1.0, 20.0, 100 * 125 * 10 / 1e6
    t = 2 * (v - sv) / a + (30_000 - (sv + v) * (v - sv) / a) / v
    assert k == pytest.approx(math.ceil(t), abs=1) and lp(X) == 30_000
    m.SCurve_F(Y, 100, 2000, 100, 0, 200, -30_000)
    k2 = wait(lambda: busy(Y))
    jerk = 62_500_000 / 200 * 10 / 1e9
    t_ramp = (v - sv) / a + a / jerk
    t2 = 2 * t_ramp + (30_000 - (sv + v) * t_ramp) / v
    assert k2 == pytest.approx(math.ceil(t2), abs=1) and lp(Y) == -30_000


def test_continuous_drives_and_readings():
    up()
    m.TCurve_C(X | Y, 100, 1000, 50)
    gt.GTE_Wait(1000)
    assert m.ReadCV(X) == 1000 and m.ReadCV(Y) == 1000
    m.DecStop(X)
    gt.GTE_Wait(1)
    assert m.ReadCA(X) == 50
    m.SuddenStop(Y)
    wait(lambda: busy(X) or busy(Y))
    assert m.ReadCV(X) == 0


def test_line2d_c_on_the_line_long_axis_speed():
    """4.5.1: a 2-axis line at constant speed; the end points from SetP."""
    up()
    m.SetP(X, 4000)
    m.SetP(Y, 1000)
    ld = m.LINEDATA(SV=1000, V=1000)
    m.Line2D_C(ld, 0x3)
    pts = []
    while crd_busy():
        gt.GTE_Wait(1)
        pts.append((lp(X), lp(Y)))
    for x, y in pts:
        assert abs(x * 1000 - y * 4000) / math.hypot(4000, 1000) <= 0.75
    assert pts[-1] == (4000, 1000)
    assert len(pts) == pytest.approx(4000 / 10, abs=1)


def test_line3d_s_and_line2d_t():
    up()
    for axis, d in ((X, 3000), (Y, -3000), (Z, 6000)):
        m.SetP(axis, d)
    m.Line3D_S(m.LINEDATA(SV=100, V=2000, A=100, K=500), 0x7)
    wait(crd_busy)
    assert (lp(X), lp(Y), lp(Z)) == (3000, -3000, 6000)
    m.SetP(Z | U, 2000)
    m.Line2D_T(m.LINEDATA(SV=100, V=2000, A=100), 0xC)
    wait(lambda: crd_busy(2))
    assert (lp(Z), lp(U)) == (8000, 2000)
    with pytest.raises(CompatError):
        m.Line2D_C(m.LINEDATA(SV=1, V=1), 0x7)  # not a pair


@pytest.mark.long
def test_circles_cw_ccw_and_t_needs_manual_dec():
    """4.5.2: the centre (SetC) and end (SetP) relative to the start; CircleCW_T needs
    ManualDec (4.4 note on AutoDec)."""
    up()
    m.SetC(X, 2000)
    m.SetC(Y, 0)
    m.SetP(X | Y, 0)  # end on the start: a full circle
    m.CircleCCW_C(m.CIRCLEDATA(SV=500, V=500), 0x3)
    pts = []
    while crd_busy():
        gt.GTE_Wait(1)
        pts.append((lp(X), lp(Y)))
    assert all(abs(math.hypot(x - 2000, y) - 2000) <= 1.0 for x, y in pts)
    assert pts[len(pts) // 4][1] < 0  # counter-clockwise from (0,0) around (2000,0): y < 0 first
    assert pts[-1] == (0, 0)
    with pytest.raises(CompatError, match="ManualDec"):
        m.CircleCW_T(m.CIRCLEDATA(SV=100, V=1000, A=100), 0x3)
    m.ManualDec(X, 4000)
    m.CircleCW_T(m.CIRCLEDATA(SV=100, V=1000, A=100), 0x3)
    wait(crd_busy)
    assert (lp(X), lp(Y)) == (0, 0)


def test_bit_pattern_steps():
    up()
    m.BitPattern(X | Y, 1000, [[0x00FF], [0x0F0F]], [[0xFF00], [0x0000]])
    wait(crd_busy)
    assert (lp(X), lp(Y)) == (0, 8)


def test_registers_of_4_8_unsigned_and_any_time():
    up()
    m.LPS(X, -5)
    assert m.ReadLPS(X) == 2**32 - 5
    m.EPS(X, 0xFFFFFFFF)
    assert m.ReadEPS(X) == 0xFFFFFFFF
    m.TCurve_C(X, 1000, 1000, 1)
    gt.GTE_Wait(10)
    m.LPS(X, 0)  # while driving: nothing jumps, the counter restarts
    gt.GTE_Wait(10)
    assert 0 < lp(X) <= 101
    m.RESET()
    gt.GTE_Wait(1)
    assert not busy(X)


def test_soft_limits_slmtp_setcompp():
    up()
    m.SetCompP(X, 5000)
    m.SLMTP(1)
    m.TCurve_C(X, 100, 1000, 100)
    wait(lambda: busy(X))
    assert 5000 <= lp(X) <= 6000
    assert m.card().regs[1].stopdata & 0x40


@pytest.mark.long
def test_home_type_1_and_2_find_the_switch():
    """4.7: type 1 decelerates at ORG; type 2 backs off and approaches slowly."""
    up(a1=dict(position=20_000, home_switch=((5000, 8000),)))
    m.LPS(X, 20_000)
    m.HomeType1(0x2, 100, 1000, 100)  # IN0 (home switch), low-active: the chip's WR1
    assert 3000 < lp(X) < 8000
    m.HomeType2(0x2, 100, 1000, 100)
    assert lp(X) in range(7990, 8001)  # the switch's upper edge, approached slowly
    with pytest.raises(CompatError):
        m.HomeType1(0x100, 100, 1000, 100)  # no input enabled (bit 8: an interrupt enable)


@pytest.mark.long
def test_home_type_3_stops_on_the_index():
    up(a1=dict(position=20_000, home_switch=((5000, 8000),), index_offset=100,
               counts_per_rev=1000))  # fmt: skip
    m.LPS(X, 20_000)
    m.HomeType3(0x2, 100, 1000, 100)
    ep = m.ReadEPS(X)
    assert (ep - 100) % 1000 in range(0, 12) or (ep - 100) % 1000 > 988


_ANY = st.one_of(st.integers(-(2**40), 2**40), st.floats(allow_nan=True), st.none(),
                 st.text(max_size=2))  # fmt: skip


@settings(
    max_examples=examples(150, 15),
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(
    name=st.sampled_from(["SetSV", "SetV", "SetA", "SetD", "SetAA", "SetMultiple", "SetP",
                          "SetC", "LPS", "SetCompP", "ManualDec", "Pulse", "SetAO"]),
    axis=st.one_of(st.integers(-1, 16), _ANY),
    data=_ANY,
)  # fmt: skip
def test_property_bad_arguments_raise_compat_error_only(name, axis, data):
    if m.card() is None:
        up()
    try:
        getattr(m, name)(axis, data)
    except CompatError as e:
        assert str(e)
        assert m.last_error()
    else:
        assert isinstance(axis, int) and 1 <= axis <= 15


@pytest.mark.long
def test_scenario_drives_then_interpolation():
    """Four axes by TCurve_F, then an X-Y line by Line2D_T, read by ReadLPS/ReadEPS."""
    up()
    for axis, p in ((X, 12_000), (Y, -6000), (Z, 3000), (U, 9000)):
        m.TCurve_F(axis, 100, 2000, 100, p)
    gt.GTE_Wait(50)
    assert all(busy(a) for a in (X, Y, Z, U))
    wait(lambda: any(busy(a) for a in (X, Y, Z, U)))
    assert [lp(a) for a in (X, Y, Z, U)] == [12_000, -6000, 3000, 9000]
    gt.GTE_Wait(20)
    assert abs(m.ReadEPS(X) - 12_000) <= 1
    m.AutoDec()
    m.SetP(X, -12_000)
    m.SetP(Y, 6000)
    m.Line2D_T(m.LINEDATA(SV=100, V=2000, A=100), 0x3)
    wait(crd_busy)
    assert (lp(X), lp(Y)) == (0, 0)
    m.Close()


def test_a_thesis_program_runs_without_an_open_call():
    """Chapter 4 has no open call: the first library call finds the card. Here the card is
    the one GT_Open opened (a test's lockstep card), used as it is."""
    open_card()
    m.SetRange(800_000)  # the program's first call: no Open() before it
    m.TCurve_F(X, 100, 1000, 100, 5_000)
    wait(lambda: busy(X))
    assert lp(X) == 5_000


def test_structures_are_taken_by_their_fields_not_their_class():
    """4.5: LINEDATA holds the speeds; a program's own structure with the same fields (or
    the same layout) is what C would pass."""
    import ctypes

    class MyLine(ctypes.Structure):  # the program's own declaration
        _fields_ = [(n, ctypes.c_int) for n in ("SV", "V", "A", "D", "K")]

    class Raw(ctypes.Structure):  # same layout, other names
        _fields_ = [(f"f{i}", ctypes.c_int) for i in range(5)]

    up()
    m.SetP(X, 3_000)
    m.SetP(Y, 4_000)
    m.Line2D_C(ctypes.byref(MyLine(SV=1000, V=1000)), 0x3)
    wait(lambda: busy(X) or busy(Y))
    assert (lp(X), lp(Y)) == (3_000, 4_000)
    m.Line2D_C(Raw(1000, 1000, 0, 0, 0), 0x3)
    wait(lambda: busy(X) or busy(Y))
    assert (lp(X), lp(Y)) == (6_000, 8_000)
    with pytest.raises(m.CompatError, match="fields SV, V, A, D, K"):
        m.Line2D_C(object(), 0x3)


@pytest.mark.long
def test_scurve_f_unnamed_argument_changes_nothing():
    """4.4: SCurve_F(axis, SV, V, A, <unnamed>, K, Pulse): the text names no deceleration;
    the same drive whatever the fifth argument is."""
    up()
    m.SCurve_F(X, 100, 2000, 100, 0, 200, 30_000)
    k0 = wait(lambda: busy(X))
    m.SCurve_F(X, 100, 2000, 100, 7, 200, 30_000)
    assert wait(lambda: busy(X)) == k0 and lp(X) == 60_000


@pytest.mark.parametrize("level", [0, 1])
def test_slmtp_takes_the_active_level_and_sets_up_the_limit(level):
    """4.6: SLMTP(n)/SLMTM(n): n is the active level (0 Low, 1 Hi); either sets up the
    soft limit of all axes."""
    up()
    m.SetCompP(X, 2_000)
    m.SLMTP(level)
    m.TCurve_C(X, 100, 1000, 100)
    wait(lambda: busy(X))
    assert 2_000 <= lp(X) < 3_000


def test_read_ca_holds_its_value_at_constant_speed():
    up()
    m.TCurve_C(X, 100, 1000, 50)
    gt.GTE_Wait(1000)  # long at constant speed
    assert m.ReadCV(X) == 1000 and m.ReadCA(X) == 50


# --- levels, INPOS, encoder settings, homing without invented bits, axis numbers -------------
def ep(axis: int) -> int:
    v = m.ReadEPS(axis)
    return v - 2**32 if v >= 2**31 else v


def test_home_type_takes_the_chips_wr1_and_homes_every_axis_that_can():
    """4.7: HomeTypeN(WR1Reg, SV, V, A) names no axis: every axis whose machine has the
    origin signal ahead is homed, negatively; the others stand (named in last_error).
    WR1's upper byte (the chip's interrupt enables) changes nothing. Ours: axis=, then an
    axis without its signal is an error before anything moves."""
    up(a1=dict(position=2_000, home_switch=((500, 800),)), a3=dict(position=-100,
       home_switch=((-900, -700),)))  # fmt: skip
    m.LPS(X | Z, 0)
    m.HomeType1(0xFF02, 100, 100, 100)
    assert 1_200 <= -lp(X) <= 1_500 and 0 < -lp(Z) <= 900
    assert lp(Y) == 0 and lp(U) == 0
    assert "axis 2, 4 left standing" in m.last_error()
    with pytest.raises(CompatError, match="axis 2 has no IN0"):
        m.HomeType1(0x2, 100, 100, 100, axis=Y)
    m.HomeType1(0x2, 100, 100, 100, axis=X, direction=1)  # back up onto the switch
    assert m.card().active(1, 2)


def test_enable_in_pos_makes_homing_wait_for_the_amplifier():
    """4.6 EnableInPos / InPosSig: with the in-position input on, a homing step ends when
    the amplifier stands in position (EP = LP); with a level the amplifier never gives,
    the step never ends (here: an error after INPOS_WAIT_MS)."""
    lags = []
    for on in (0, 1):
        up(a1=dict(position=20_000, home_switch=((5000, 8000),)))
        m.SetRange(200_000)  # M = 40: 200 pulse/ms, the amplifier lags
        m.LPS(X, 20_000)
        m.EPS(X, 20_000)
        m.EnableInPos(on)
        m.HomeType1(0x2, 5000, 5000, 100, axis=X)  # constant speed: stops at once
        lags.append(ep(X) - lp(X))
        m.Close()
        gt.GT_Close()
    assert lags[0] >= 2 and lags[1] == 0


def test_in_pos_sig_against_the_amplifier_never_ends(monkeypatch):
    monkeypatch.setattr(m, "INPOS_WAIT_MS", 30.0)
    up(a1=dict(position=1_000, home_switch=((0, 500),)))
    m.EnableInPos(1)
    m.InPosSig(1, X)  # the amplifier's in-position output is low
    with pytest.raises(CompatError, match="INPOS never came"):
        m.HomeType1(0x2, 1000, 1000, 100, axis=X)


def test_hlmtp_level_against_a_normally_open_switch():
    """4.6 HLMTP(n, axis): n the active level. A normally-open + limit reads low when hit;
    set Hi-active, the card sees it active off the switch: a + drive does not move."""
    up(a1=dict(positive_limit=5000, switch_wiring="normally_open"))
    m.HLMTP(1, X)
    m.TCurve_C(X, 100, 100, 1)
    gt.GTE_Wait(20)
    assert lp(X) == 0 and m.ReadCV(X) == 0
    m.HLMTP(0, X)
    m.TCurve_F(X, 1000, 1000, 1, 200)
    gt.GTE_Wait(30)
    assert lp(X) == 200


def test_alm_sig_and_enable_alm():
    """4.6: EnableALM(1) and ALMSig(1, X) (Hi active) while the healthy amplifier's alarm
    output is high: the card sees an alarm and X does not drive; Low active, it does."""
    up()
    m.EnableALM(1)
    m.ALMSig(1, X)
    m.TCurve_F(X, 100, 100, 1, 100)
    gt.GTE_Wait(20)
    assert lp(X) == 0 and m.card().regs[1].stopdata == 0x20
    m.ALMSig(0, X)
    m.TCurve_F(X, 1000, 1000, 1, 100)
    gt.GTE_Wait(20)
    assert lp(X) == 100


def test_encoder_mode_and_direction():
    """4.6 EncoderCWCCW(1, axis): the real counter counts the other way; EncoderMode(1,
    axis): single up/down pulse input, fed A/B signals: it holds its reading."""
    up()
    m.EncoderCWCCW(1, X)
    m.EncoderMode(1, Y)
    m.TCurve_F(X | Y, 1000, 1000, 1, 500)
    gt.GTE_Wait(60)
    assert (lp(X), ep(X)) == (500, -500)
    assert (lp(Y), ep(Y)) == (500, 0)


def test_readers_take_one_axis_bit_not_a_number():
    """4.8: the readers read one axis (為各軸分別讀取); the axis is its bit, as everywhere in
    the library: 3 (Z as a number, or X and Y) is refused, naming the bits."""
    up()
    assert m.ReadLPS(4) == 0
    with pytest.raises(CompatError, match="X 1, Y 2, Z 4, U 8"):
        m.ReadLPS(3)
    with pytest.raises(CompatError):
        m.ReadCV(0)


def test_settings_with_nothing_to_act_on_say_so():
    up()
    m.SetPulseMode(X, 1)
    assert "kept" in m.last_error()
    m.SetAO(X, 100)
    assert "SetAO" in m.last_error()
