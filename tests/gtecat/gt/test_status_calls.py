"""Status word, safety and configuration through ``from gtecat import gt`` (lockstep clock).

Manual 4.3-4.6 (table 4-4), 6.3.1 (table 6-2), 9.2-9.4, 11.7 and chapter 13
entries 2, 3, 8, 15-18, 25, 60, 69-71, 81-83, 91, 98, 116, 121, 122.
"""

from __future__ import annotations

from ctypes import byref, c_double, c_long, c_short, c_ubyte, c_ulong, create_string_buffer
from pathlib import Path

import numpy as np
import pytest

from gtecat import gt

from .conftest import bring_up

ALARM, POS_ERR, POS_LIM, NEG_LIM = 1 << 1, 1 << 4, 1 << 5, 1 << 6
SMOOTH, ABRUPT, SERVO, MOVING, ARRIVED = 1 << 7, 1 << 8, 1 << 9, 1 << 10, 1 << 11


def machine(tmp_path: Path, body: str) -> str:
    p = tmp_path / "machine.toml"
    p.write_text(body)
    return str(p)


def up(tmp_path: Path | None = None, body: str = "", eni: str = "manual_fig5_2.eni") -> None:
    opts = {"machine": machine(tmp_path, body)} if tmp_path is not None and body else {}
    bring_up(eni, clock="lockstep", **opts)


def on(axis: int = 1) -> None:
    assert gt.GT_AxisOn(axis) == 0, gt.GTE_GetLastError()


def sts(axis: int = 1) -> int:
    s = c_long()
    assert gt.GT_GetSts(axis, byref(s)) == 0
    return s.value


def prf_pos(axis: int = 1) -> float:
    v = c_double()
    assert gt.GT_GetPrfPos(axis, byref(v)) == 0
    return v.value


def prf_vel(axis: int = 1) -> float:
    v = c_double()
    assert gt.GT_GetPrfVel(axis, byref(v)) == 0
    return v.value


def trap(axis: int, pos: int, vel: float, acc: float = 1.0, ts: int = 0) -> int:
    prm = gt.TTrapPrm()
    prm.acc, prm.dec, prm.velStart, prm.smoothTime = acc, acc, 0, ts
    assert gt.GT_PrfTrap(axis) == 0, gt.GTE_GetLastError()
    assert gt.GT_SetTrapPrm(axis, byref(prm)) == 0
    assert gt.GT_SetPos(axis, pos) == 0 and gt.GT_SetVel(axis, vel) == 0
    return gt.GT_Update(1 << (axis - 1))


def jog(axis: int, vel: float, acc: float = 1.0) -> int:
    prm = gt.TJogPrm()
    prm.acc, prm.dec = acc, acc
    assert gt.GT_PrfJog(axis) == 0, gt.GTE_GetLastError()
    assert gt.GT_SetJogPrm(axis, byref(prm)) == 0
    assert gt.GT_SetVel(axis, vel) == 0
    return gt.GT_Update(1 << (axis - 1))


def wait_still(axis: int = 1, limit: int = 100_000) -> int:
    for k in range(limit):
        if not sts(axis) & MOVING:
            return k
        gt.GTE_Wait(1)
    raise AssertionError("never stopped")


def channel(slave: int = 0, k: int = 0):
    return gt.GTE_Slave(slave).channel(k)


# --- bits 9, 10 ----------------------------------------------------------------------------------
def test_servo_and_moving_bits():
    up()
    assert sts() == 0
    on()
    assert sts() == SERVO
    assert trap(1, 2000, 10) == 0
    gt.GTE_Wait(1)
    assert sts() == SERVO | MOVING
    wait_still()
    assert sts() == SERVO
    many = (c_long * 2)()
    assert gt.GT_GetSts(1, many, 2) == 0 and list(many) == [SERVO, 0]
    assert gt.GT_GetSts(1, many, 3) == 7  # there is no axis 3


def test_profile_status_word_is_bit_10_while_the_trap_move_runs():
    """GT_GetPrfSts (GTN-era header): the planner's own bit 10, nothing of the axis's."""
    up()
    on()
    word = (c_long * 5)()
    clock = c_ulong()
    # the field's call: 5 profiles from profile 1, whatever the bus holds (2 drives here)
    assert gt.GTN_GetPrfSts(1, 1, word, 5) == 0, gt.GTE_GetLastError()
    assert list(word) == [0] * 5  # servo on (bit 9) is the axis's, not the profile's
    assert trap(1, 2000, 10) == 0
    gt.GTE_Wait(1)
    assert gt.GT_GetPrfSts(1, word, 5, byref(clock)) == 0
    assert list(word) == [MOVING, 0, 0, 0, 0] and clock.value > 0
    assert sts() == SERVO | MOVING  # the axis's word has both
    wait_still()
    one = c_long(-1)
    assert gt.GT_GetPrfSts(1, byref(one)) == 0 and one.value == 0
    assert gt.GTN_GetPrfSts(1, 1, word, 5) == 0 and list(word) == [0] * 5
    assert gt.GT_GetPrfSts(12, word, 2) == 7  # past the controller's profiles
    assert gt.GT_GetPrfSts(0, byref(one)) == 7


# --- soft limits (example 9-1) -------------------------------------------------------------------
def test_soft_limit_stops_abruptly_latches_bit_5_and_refuses_only_that_direction():
    up()
    on()
    pos, neg = c_long(), c_long()
    assert gt.GT_GetSoftLimit(1, byref(pos), byref(neg)) == 0
    assert (pos.value, neg.value) == (0x7FFFFFFF, -0x80000000)  # disabled by default
    assert gt.GT_SetSoftLimit(1, -5, 5) == 7  # positive must be above negative
    assert gt.GT_SetSoftLimit(1, 20000, -20000) == 0
    assert trap(1, 1_000_000, 50, 0.125, ts=25) == 0
    crossed = None
    for k in range(100_000):
        gt.GTE_Wait(1)
        p = prf_pos()
        if crossed is None and p > 20000:
            crossed = (k, p, prf_vel())
        if not sts() & MOVING:
            break
    assert crossed is not None
    _, p_cross, v_cross = crossed
    final = prf_pos()
    # stopped with decAbruptStop (1000 pulse/ms²) from the first sample past the limit
    assert final == pytest.approx(p_cross + v_cross**2 / 2000)
    assert 20000 < final < 20000 + 50 + 2
    s = sts()
    assert s & POS_LIM and not s & NEG_LIM
    assert gt.GT_ClrSts(1) == 0 and sts() & POS_LIM  # still past the limit: stays
    assert trap(1, 30000, 10) == 1 and "positive" in gt.GTE_GetLastError()
    assert trap(1, 19000, 10) == 0  # away from the limit: allowed
    wait_still()
    assert sts() & POS_LIM  # latched until GT_ClrSts
    assert gt.GT_ClrSts(1) == 0 and not sts() & POS_LIM


def test_negative_soft_limit_and_jog():
    up()
    on()
    assert gt.GT_SetSoftLimit(1, 1000, -1000) == 0
    assert jog(1, -20) == 0
    wait_still()
    assert sts() & NEG_LIM and prf_pos() < -1000
    assert jog(1, -5) == 1
    assert jog(1, 5) == 0


# --- hardware limits -----------------------------------------------------------------------------
LIMITS = """
[axis.1]
negative_limit = -30000
positive_limit = 30000
"""


def test_hardware_limit_switch_stops_and_lmts_off_ignores_it(tmp_path):
    up(tmp_path, LIMITS)
    on()
    assert jog(1, 20) == 0
    stop_at = wait_still()
    assert 1400 < stop_at < 1600  # 30000 / 20 ms
    assert sts() & POS_LIM and not sts() & NEG_LIM
    din = c_long()
    assert gt.GT_GetEcatAxisDI(1, byref(din)) == 0 and din.value & 0b10  # 60FDh bit 1
    assert jog(1, 5) == 1  # further into the switch: refused
    assert gt.GT_ClrSts(1) == 0 and sts() & POS_LIM  # still on the switch
    assert gt.GT_LmtsOff(1, gt.MC_LIMIT_POSITIVE) == 0
    assert gt.GT_ClrSts(1) == 0 and not sts() & POS_LIM  # configuration takes effect (4.5.3)
    gt.GTE_Wait(5)
    assert not sts() & POS_LIM  # the switch is still active but ignored now
    assert gt.GT_LmtsOn(1, gt.MC_LIMIT_POSITIVE) == 0
    gt.GTE_Wait(1)
    assert sts() & POS_LIM
    assert gt.GT_LmtsOn(1, 2) == 7


def test_leaving_the_limit_then_clearing(tmp_path):
    up(tmp_path, LIMITS)
    on()
    assert jog(1, -20) == 0
    wait_still()
    assert sts() & NEG_LIM
    assert trap(1, 0, 20) == 0  # away from the negative switch
    wait_still()
    gt.GTE_Wait(20)
    assert sts() & NEG_LIM
    assert gt.GT_ClrSts(1) == 0 and sts() & (NEG_LIM | POS_LIM) == 0


def test_example_4_3_standing_on_a_limit_clears_after_lmts_off_and_clrsts(tmp_path):
    up(tmp_path, "[axis.1]\nposition = 50000\npositive_limit = 40000\n")
    gt.GTE_Wait(2)
    assert sts() & POS_LIM
    assert gt.GT_Reset() == 0
    gt.GTE_Wait(1)
    assert sts() & POS_LIM  # the cause is back at once
    assert gt.GT_AlarmOff(1) == 0 and gt.GT_LmtsOff(1, -1) == 0
    assert sts() & POS_LIM  # latched until ...
    assert gt.GT_ClrSts(1, 1) == 0 and sts() == 0  # ... GT_ClrSts
    on()
    assert sts() == SERVO


# --- alarm (9.3) ---------------------------------------------------------------------------------
def test_alarm_switches_the_servo_off_stops_and_clears_only_without_cause():
    up()
    on()
    assert jog(1, 30) == 0
    gt.GTE_Wait(100)
    channel().inject_fault("alarm")
    gt.GTE_Wait(2)
    s = sts()
    assert s & ALARM and not s & SERVO and not s & MOVING
    p = prf_pos()
    gt.GTE_Wait(50)
    enc = c_long()
    gt.GT_GetEcatEncPos(1, byref(enc))
    assert prf_pos() == enc.value != p  # the plan follows the coasting drive
    assert gt.GT_AxisOn(1) == 1  # the drive is in FAULT
    assert gt.GT_ClrSts(1) == 0 and sts() & ALARM  # the cause persists
    assert jog(1, 10) == 1 and "alarm" in gt.GTE_GetLastError()
    channel().clear_injected_fault()
    assert gt.GT_ClrSts(1) == 0 and not sts() & ALARM  # fault reset by GT_ClrSts
    assert channel().state.name == "SWITCH_ON_DISABLED"
    on()
    assert jog(1, 10) == 0


def test_alarm_off_ignores_the_fault_but_the_servo_still_drops():
    up()
    on()
    assert gt.GT_AlarmOff(1) == 0
    channel().inject_fault("alarm")
    gt.GTE_Wait(3)
    assert not sts() & ALARM and not sts() & SERVO
    assert gt.GT_AlarmOn(1) == 0
    gt.GTE_Wait(1)
    assert sts() & ALARM


def test_drive_following_error_fault_raises_the_alarm():
    """The drive's own following-error window (6065h) trips: an alarm, not bit 4."""
    up()
    on()
    assert gt.GT_SetPosErr(1, 2147483648) == 7  # long is 32 bits (entry 116)
    assert gt.GT_SetPosErr(1, 2147483647) == 0
    err = c_long()
    assert gt.GT_GetPosErr(1, byref(err)) == 0 and err.value == 2147483647
    window = (c_ubyte * 4)(*(30).to_bytes(4, "little"))  # 6065h = 30 counts
    assert gt.GT_EcatSDODownload(0, 0x6065, 0, window, 4) == 0
    assert trap(1, 100000, 60, 500) == 0  # far beyond what the motor can accelerate
    for _ in range(200):
        gt.GTE_Wait(1)
        if sts() & ALARM:
            break
    assert sts() & ALARM and not sts() & POS_ERR and not sts() & SERVO
    assert channel().error_code == 0x8611
    assert gt.GT_ClrSts(1) == 0 and not sts() & ALARM  # no lasting cause: the reset clears it


# --- following error (bit 4) ---------------------------------------------------------------------
def test_following_error_latches_bit_4_and_clears_when_back_in_range():
    up()
    on()
    err = c_long()
    assert gt.GT_GetPosErr(1, byref(err)) == 0 and err.value == 32767  # our default
    assert gt.GT_SetPosErr(1, 0) == 7
    assert gt.GT_SetPosErr(1, 50) == 0
    assert trap(1, 100000, 50, 50) == 0  # the motor lags up to ~90 pulses
    errors = []
    for _ in range(100):
        gt.GTE_Wait(1)
        e = c_double()
        gt.GT_GetAxisError(1, byref(e))
        errors.append(e.value)
        if sts() & POS_ERR:
            break
    assert sts() & POS_ERR and abs(errors[-1]) > 50
    assert all(abs(e) <= 50 for e in errors[:-1])  # set in the first cycle over the limit
    assert sts() & SERVO  # the servo stays on
    assert gt.GT_ClrSts(1) == 0 and sts() & POS_ERR  # still over the limit
    assert wait_still() <= 1  # stopped abruptly (decAbruptStop)
    assert trap(1, 0, 10) == 1 and "following error" in gt.GTE_GetLastError()
    gt.GTE_Wait(100)
    assert sts() & POS_ERR  # latched
    assert gt.GT_ClrSts(1) == 0 and not sts() & POS_ERR
    assert trap(1, 0, 10) == 0


def test_pushed_axis_gives_a_following_error_while_the_cause_lasts():
    up()
    on()
    assert gt.GT_SetPosErr(1, 100) == 0
    channel().machine_position = 1000.0  # something pushes the slide
    gt.GTE_Wait(1)
    assert sts() & POS_ERR
    assert gt.GT_ClrSts(1) == 0 and sts() & POS_ERR
    gt.GTE_Wait(200)  # the drive pulls it back to 607Ah
    assert gt.GT_ClrSts(1) == 0 and not sts() & POS_ERR


# --- in position (11.7) --------------------------------------------------------------------------
def test_axis_band_off_by_default_then_bit_11_after_the_hold_time():
    up()
    on()
    band, time = c_long(), c_long()
    assert gt.GT_GetAxisBand(1, byref(band), byref(time)) == 0 and (band.value, time.value) == (
        0,
        0,
    )
    assert trap(1, 5000, 20, 0.5) == 0
    wait_still()
    gt.GTE_Wait(50)
    assert not sts() & ARRIVED  # off by default
    assert gt.GT_SetAxisBand(1, 20, -1) == 7
    assert gt.GT_SetAxisBand(1, 20, 8) == 0  # 8 x 250 µs = 2 ms
    assert gt.GT_GetAxisBand(1, byref(band), byref(time)) == 0 and (band.value, time.value) == (
        20,
        8,
    )
    assert trap(1, 0, 20, 0.5) == 0
    rows = []
    for _ in range(2000):
        gt.GTE_Wait(1)
        e = c_double()
        gt.GT_GetAxisError(1, byref(e))
        rows.append((sts(), e.value))
        if rows[-1][0] & ARRIVED:
            break
    s = np.array([r[0] for r in rows])
    e = np.array([r[1] for r in rows])
    assert s[-1] & ARRIVED and not np.any(s[:-1] & ARRIVED)
    ok = ((s & MOVING) == 0) & (np.abs(e) <= 20)
    k = len(rows) - 1
    k0 = k
    while k0 > 0 and ok[k0 - 1]:
        k0 -= 1
    assert ok[k0 : k + 1].all() and k - k0 == 2  # first cycle >= 2 ms after entering the band
    assert trap(1, 100, 20, 0.5) == 0
    gt.GTE_Wait(1)
    assert not sts() & ARRIVED  # cleared as soon as the profile moves


def test_band_with_zero_hold_time_sets_at_once_and_leaving_the_band_clears():
    up()
    on()
    assert gt.GT_SetAxisBand(1, 5, 0) == 0
    gt.GTE_Wait(1)
    assert sts() & ARRIVED
    channel().machine_position = 100.0
    gt.GTE_Wait(1)
    assert not sts() & ARRIVED
    assert gt.GT_SetAxisBand(1, 0, 0) == 0  # off again
    gt.GTE_Wait(300)
    assert not sts() & ARRIVED


# --- GT_ClrSts span, GT_Reset --------------------------------------------------------------------
def test_clrsts_span_beyond_the_bus_and_errors():
    up()
    assert gt.GT_ClrSts(1, 8) == 0  # the manual's examples clear 8 axes
    assert gt.GT_ClrSts(0, 1) == 7
    # the count rule (resources.axis_span): axes without a drive exist up to 12
    assert gt.GT_ClrSts(5, 2) == 0
    assert gt.GT_ClrSts(12, 1) == 0
    assert gt.GT_ClrSts(12, 2) == 7 and "1..12" in gt.GTE_GetLastError()
    assert gt.GT_ClrSts(1, 0) == 7


def test_reset_restores_table_4_4():
    up()
    on()
    assert gt.GT_SetStopDec(1, 3, 300) == 0
    assert gt.GT_SetSoftLimit(1, 10, -10) == 0
    assert gt.GT_SetAxisBand(1, 10, 4) == 0
    assert gt.GT_SetPosErr(1, 5) == 0
    assert gt.GT_ProfileScale(1, 3, 2) == 0
    assert gt.GT_PrfJog(1) == 0
    assert gt.GT_LmtsOff(1) == 0 and gt.GT_AlarmOff(1) == 0
    assert gt.GT_Reset() == 0
    d1, d2 = c_double(), c_double()
    assert gt.GT_GetStopDec(1, byref(d1), byref(d2)) == 0 and (d1.value, d2.value) == (1, 1000)
    p, n = c_long(), c_long()
    gt.GT_GetSoftLimit(1, byref(p), byref(n))
    assert (p.value, n.value) == (0x7FFFFFFF, -0x80000000)
    b, t = c_long(), c_long()
    gt.GT_GetAxisBand(1, byref(b), byref(t))
    assert (b.value, t.value) == (0, 0)
    mode = c_long()
    gt.GT_GetPrfMode(1, byref(mode))
    assert mode.value == 0
    assert sts() == 0  # servo off, nothing latched
    res = gt.GTE_Controller().axis(1).motion
    assert res.safety.alarm_on and res.safety.positive_on and res.prf_link.ratio == 1.0


# --- configuration: scaling validation, encoders, GT_LoadConfig ----------------------------------
def test_enc_sns_and_enc_on_off_arguments():
    up()
    assert gt.GT_EncSns(0x10000) == 7
    assert gt.GT_EncSns(0xFFF) == 0
    assert gt.GTE_Controller().axis(2).motion.encoder.sense == -1
    assert gt.GT_EncOff(3) == 7 and gt.GT_EncOn(2) == 0


CFG = """
# test.cfg of examples 7-1 / 7-2: alarms and limits off
[axis 1]
alarm = off
positive_limit = off
negative_limit = off
soft_limit = 5000 -5000
[axis 7]              ; an axis this bus does not have: ignored
alarm = off
[profile 1]
smooth_stop_dec = 2.5
abrupt_stop_dec = 500
[encoder 1]
reverse = 1
"""


def test_load_config_applies_and_reports_errors_with_file_and_line(tmp_path):
    up(tmp_path, LIMITS)
    on()
    cfg = tmp_path / "test.cfg"
    cfg.write_text(CFG)
    assert gt.GT_LoadConfig(str(cfg)) == 0, gt.GTE_GetLastError()
    res = gt.GTE_Controller().axis(1).motion
    assert not res.safety.alarm_on and not res.safety.positive_on
    d1, d2 = c_double(), c_double()
    gt.GT_GetStopDec(1, byref(d1), byref(d2))
    assert (d1.value, d2.value) == (2.5, 500)
    assert res.encoder.sense == -1
    p, n = c_long(), c_long()
    gt.GT_GetSoftLimit(1, byref(p), byref(n))
    assert (p.value, n.value) == (5000, -5000)
    assert gt.GT_LoadConfig(create_string_buffer(str(cfg).encode())) == 0
    bad = tmp_path / "bad.cfg"
    bad.write_text("[axis 1]\nalarm = maybe\n")
    assert gt.GT_LoadConfig(str(bad)) == 7
    assert "bad.cfg:2" in gt.GTE_GetLastError()
    assert gt.GT_LoadConfig(str(tmp_path / "missing.cfg")) == 7
    assert gt.GT_LoadConfig("x" * 126) == 7
    assert jog(1, 5) == 0
    gt.GTE_Wait(5)
    assert gt.GT_LoadConfig(str(cfg)) == 1 and "moving" in gt.GTE_GetLastError()


def test_config_input_none_makes_alarm_and_limit_switching_return_1(tmp_path):
    up()
    cfg = tmp_path / "none.cfg"
    cfg.write_text("[axis 1]\nalarm_input = none\npositive_limit_input = none\n")
    assert gt.GT_LoadConfig(str(cfg)) == 0
    assert gt.GT_AlarmOn(1) == 1 and "none" in gt.GTE_GetLastError()
    assert gt.GT_AlarmOff(1) == 1
    assert gt.GT_LmtsOff(1, gt.MC_LIMIT_POSITIVE) == 1
    assert gt.GT_LmtsOff(1, gt.MC_LIMIT_NEGATIVE) == 0
    channel().inject_fault("alarm")
    gt.GTE_Wait(2)
    assert not sts() & ALARM
    assert gt.GT_Reset() == 0 and gt.GT_AlarmOn(1) == 0  # reset: the inputs are back


def test_limit_input_taken_from_another_axis(tmp_path):
    """4.3.1: "将轴 2 的限位信号配给轴 1"."""
    up(tmp_path, "[axis.2]\nposition = 100\npositive_limit = 50\n")
    gt.GTE_Wait(1)
    assert not sts(1) & POS_LIM and sts(2) & POS_LIM
    cfg = tmp_path / "remap.cfg"
    cfg.write_text("[axis 1]\npositive_limit_input = 2\n")
    assert gt.GT_LoadConfig(str(cfg)) == 0
    gt.GTE_Wait(1)
    assert sts(1) & POS_LIM


def test_stop_inputs_from_the_configuration_file(tmp_path):
    """Extension: a 60FDh bit as smooth-stop input (bit 7) - here the home switch, bit 2."""
    up(tmp_path, "[axis.1]\nhome_switch = [[5000, 6000]]\n")
    cfg = tmp_path / "stop.cfg"
    cfg.write_text("[axis 1]\nsmooth_stop_input = 1:2\n")
    assert gt.GT_LoadConfig(str(cfg)) == 0
    on()
    assert jog(1, 10) == 0
    for _ in range(2000):
        gt.GTE_Wait(1)
        if sts() & SMOOTH:
            break
    assert sts() & SMOOTH and prf_vel() == 10
    gt.GTE_Wait(1)
    assert prf_vel() == 9  # smooth stop at decSmoothStop (1 pulse/ms²)
    assert wait_still() == 9
    assert jog(1, -10) == 1 and "smooth-stop" in gt.GTE_GetLastError()
    assert gt.GT_ClrSts(1) == 0 and sts() & SMOOTH  # still on the input
    assert gt.GT_LoadConfig(str(cfg)) == 0


def test_scale_arguments():
    up()
    assert gt.GT_ProfileScale(1, 32767, 1) == 7
    assert gt.GT_ProfileScale(1, -4, 3) == 0
    assert gt.GT_EncScale(1, 3, -3) == 0
    assert gt.GT_EncScale(1, 2, 3) == 7
    assert gt.GT_ProfileScale(1, 1.5, 1) == 7
    sh = c_short()
    assert gt.GT_GetPosScale(1, byref(sh)) == 0


def test_integer_memory_narrower_than_the_prototype_is_refused_with_the_type_to_pass():
    """A C compiler refuses a ``short *`` for a ``long *``; here such memory gets 7 and the
    ctypes type to pass, whatever the value (it used to depend on whether it fitted)."""
    from ctypes import c_int, c_int8, c_ushort

    bring_up(clock="lockstep")
    assert gt.GT_GetSts(1, byref(c_short())) == 7
    assert "pass byref(c_long())" in gt.GTE_GetLastError()
    assert gt.GT_GetSts(1, byref(c_int())) == 0 and gt.GT_GetSts(1, byref(c_long())) == 0
    assert gt.GT_GetEcatHomingStatus(1, byref(c_int8())) == 7
    assert "pass byref(c_ushort())" in gt.GTE_GetLastError()
    assert gt.GT_GetEcatHomingStatus(1, byref(c_ushort())) == 0
