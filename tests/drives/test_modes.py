"""Modes of operation: 6060h/6061h, 6502h, CSP/CSV/CST, PP handshake, PV, PT, homing."""

from __future__ import annotations

import pytest

from gtecat.drives.abort import SdoAbort, SdoAbortCode
from gtecat.drives.cia402 import State
from gtecat.drives.drive import DriveSettings
from gtecat.drives.machine import AxisMachine
from gtecat.drives.modes import OpMode, profile_step, supported_bits
from tests.drives.test_drive import Rig

PP_RX = (0x6040, 0x6060, 0x607A)
PP_TX = (0x6041, 0x6061, 0x6064, 0x606C)


def test_6502_matches_python_canopen_bits() -> None:
    from canopen.profiles.p402 import OperationMode

    bits = supported_bits([1, 3, 4, 6, 8, 9, 10])
    sup = OperationMode.SUPPORTED
    expected = (
        sup["PROFILED POSITION"]
        | sup["PROFILED VELOCITY"]
        | sup["PROFILED TORQUE"]
        | sup["HOMING"]
        | sup["CYCLIC SYNCHRONOUS POSITION"]
        | sup["CYCLIC SYNCHRONOUS VELOCITY"]
        | sup["CYCLIC SYNCHRONOUS TORQUE"]
    )
    assert bits == expected == 0x03AD
    rig = Rig(settings=DriveSettings(supported_modes=(8, 9)))
    assert rig.read(0x6502, 0, "I") == 0x0180


@pytest.mark.parametrize("latency", [0, 1, 3])
def test_6061_follows_6060_after_the_configured_latency(latency: int) -> None:
    rig = Rig(settings=DriveSettings(mode_latency_cycles=latency))
    rig.set(0x6060, 9)
    seen = []
    for _ in range(5):
        seen.append(rig.cycle()[0x6061])
    assert seen == [0] * latency + [9] * (5 - latency)


def test_mode_display_while_switching_like_festo() -> None:
    rig = Rig(settings=DriveSettings(mode_latency_cycles=3, mode_display_while_switching=-1))
    rig.set(0x6060, 1)
    assert [rig.cycle()[0x6061] for _ in range(4)] == [-1, -1, -1, 1]


def test_unsupported_mode_by_sdo_is_aborted() -> None:
    rig = Rig(rx=(0x6040, 0x607A), tx=(0x6041,), settings=DriveSettings(supported_modes=(8,)))
    with pytest.raises(SdoAbort) as e:
        rig.write(0x6060, 7)
    assert e.value.code == SdoAbortCode.VALUE_RANGE_EXCEEDED == 0x06090030
    with pytest.raises(SdoAbort) as e:
        rig.write(0x6060, 1)
    assert e.value.code == 0x06090030
    rig.write(0x6060, 8)
    rig.cycle(2)
    assert rig.read(0x6061) == 8


def test_unsupported_mode_by_pdo_is_not_taken() -> None:
    rig = Rig()
    rig.set(0x6060, 8)
    rig.cycle(2)
    rig.set(0x6060, 7)  # interpolated position: not supported
    assert [rig.cycle()[0x6061] for _ in range(3)] == [8, 8, 8]
    rig.set(0x6060, 9)
    rig.cycle(2)
    assert rig.inputs[0x6061] == 9


def test_mode_change_refused_while_halt_when_configured() -> None:
    rig = Rig(settings=DriveSettings(refuse_mode_change_while_halt=True))
    rig.enable(mode=8)
    rig.set(0x6040, 0x010F)
    rig.set(0x6060, 9)
    rig.cycle(5)
    assert rig.inputs[0x6061] == 8
    rig.set(0x6040, 0x000F)
    rig.cycle()
    assert rig.inputs[0x6061] == 9


def test_mode_change_only_in_given_states() -> None:
    rig = Rig(settings=DriveSettings(mode_change_states=frozenset({State.SWITCH_ON_DISABLED})))
    rig.enable(mode=None)
    rig.set(0x6060, 8)
    rig.cycle(3)
    assert rig.inputs[0x6061] == 0
    rig.set(0x6040, 0)
    rig.cycle(2)
    assert rig.inputs[0x6061] == 8


def test_csp_tracks_with_a_small_lag_and_sw12() -> None:
    rig = Rig()
    rig.enable(mode=8)
    target = 0.0
    velocity = 0.0
    lags = []
    for i in range(600):  # accelerate to 200000 counts/s (20 rev/s) then cruise
        velocity = min(velocity + 2000.0, 200000.0)
        target += velocity / 1000.0
        rig.set(0x607A, round(target))
        inp = rig.cycle()
        if i > 200:
            lags.append(round(target) - inp[0x6064])
    assert rig.sw() & 0x1000  # drive follows the command value
    assert rig.ch.error_code == 0
    assert 0 < max(lags) <= 10  # "a few counts at speed"
    assert abs(inp[0x606C] - 200000) < 500
    assert rig.ch.following_error_actual == pytest.approx(max(lags), abs=3)


def test_csv_and_cst() -> None:
    rig = Rig()
    rig.enable(mode=9)
    rig.set(0x60FF, -30000)
    inp = rig.cycle(100)
    assert inp[0x606C] == pytest.approx(-30000, abs=50)
    assert rig.sw() & 0x1000
    p = inp[0x6064]
    assert rig.cycle(10)[0x6064] == pytest.approx(p - 300, abs=20)
    rig.set(0x60FF, 0)
    rig.set(0x6060, 10)
    rig.set(0x6071, 500)  # half rated torque
    rig.cycle(3)
    v0 = rig.ch.mech.vel
    inp = rig.cycle(20)
    assert rig.ch.mech.vel > v0  # accelerating under torque
    assert inp[0x6077] == pytest.approx(500, abs=40)


def _pp_rig() -> Rig:
    rig = Rig(rx=PP_RX, tx=PP_TX)
    rig.enable(mode=1)
    rig.write(0x6081, 100000, fmt="I")
    rig.write(0x6083, 1000000, fmt="I")
    rig.write(0x6084, 1000000, fmt="I")
    return rig


def test_pp_absolute_move_handshake_and_target_reached() -> None:
    rig = _pp_rig()
    rig.set(0x607A, 20000)
    rig.set(0x6040, 0x1F)
    rig.cycle()
    assert rig.sw() & 0x1000  # set-point acknowledged
    assert not rig.sw() & 0x0400
    rig.set(0x6040, 0x0F)
    rig.cycle()
    assert not rig.sw() & 0x1000  # buffer free again once CW4 is 0
    for _ in range(500):
        rig.cycle()
        if rig.sw() & 0x0400:
            break
    assert rig.sw() & 0x0400
    assert abs(rig.inputs[0x6064] - 20000) <= 10


def test_pp_relative_moves_add_to_the_previous_target() -> None:
    rig = _pp_rig()
    for _ in range(2):
        rig.set(0x607A, 5000)
        rig.set(0x6040, 0x5F)
        rig.cycle()
        rig.set(0x6040, 0x4F)
        rig.cycle(300)
    assert abs(rig.inputs[0x6064] - 10000) <= 10
    assert rig.sw() & 0x0400


def test_pp_queued_set_point_keeps_sw12_until_taken() -> None:
    rig = _pp_rig()
    rig.set(0x607A, 10000)
    rig.set(0x6040, 0x1F)
    rig.cycle()
    rig.set(0x6040, 0x0F)
    rig.cycle(5)
    rig.set(0x607A, 0)
    rig.set(0x6040, 0x1F)  # CW5 = 0: queued behind the running move
    rig.cycle()
    rig.set(0x6040, 0x0F)
    rig.cycle(2)
    assert rig.sw() & 0x1000  # buffer full
    peak = 0
    for _ in range(600):
        peak = max(peak, rig.cycle()[0x6064])
    assert peak >= 9990  # the first move completed before the queued one
    assert abs(rig.inputs[0x6064]) <= 10
    assert not rig.sw() & 0x1000


def test_pp_immediate_set_point_replaces_the_running_move() -> None:
    rig = _pp_rig()
    rig.set(0x607A, 50000)
    rig.set(0x6040, 0x1F)
    rig.cycle()
    rig.set(0x6040, 0x0F)
    rig.cycle(20)
    rig.set(0x607A, 0)
    rig.set(0x6040, 0x3F)  # CW5 = 1: change set immediately
    rig.cycle()
    peak = 0
    rig.set(0x6040, 0x2F)
    for _ in range(400):
        peak = max(peak, rig.cycle()[0x6064])
    assert peak < 10000
    assert abs(rig.inputs[0x6064]) <= 10


def test_pp_halt_stops_and_resumes() -> None:
    rig = _pp_rig()
    rig.set(0x607A, 30000)
    rig.set(0x6040, 0x1F)
    rig.cycle()
    rig.set(0x6040, 0x010F)
    rig.cycle(200)
    assert abs(rig.inputs[0x606C]) < 100
    assert rig.inputs[0x6064] < 30000
    assert rig.sw() & 0x0400  # halted and at standstill
    rig.set(0x6040, 0x000F)
    rig.cycle(600)
    assert abs(rig.inputs[0x6064] - 30000) <= 10


@pytest.mark.parametrize(("option", "cycles"), [(1, 100), (2, 10)])
def test_halt_option_chooses_the_deceleration(option: int, cycles: int) -> None:
    rig = Rig()
    rig.write(0x605D, option, fmt="h")
    rig.write(0x6084, 1_000_000, fmt="I")  # slow-down ramp: 100 ms from 100000 counts/s
    rig.write(0x6085, 10_000_000, fmt="I")  # quick-stop ramp: 10 ms
    rig.enable(mode=3)
    rig.set(0x60FF, 100000)
    rig.cycle(200)
    rig.set(0x6040, 0x010F)
    rig.cycle(cycles // 2)
    assert 30000 < abs(rig.ch.mech.vel) < 70000  # half way down the ramp
    rig.cycle(cycles // 2 + 20)
    assert abs(rig.ch.mech.vel) < 100 and rig.sw() & 0x0400
    assert rig.ch.state is State.OPERATION_ENABLED


def test_pv_ramps_to_target_velocity_and_reports() -> None:
    rig = Rig()
    rig.enable(mode=3)
    rig.write(0x6083, 500000, fmt="I")
    rig.set(0x60FF, 50000)
    rig.cycle(50)
    assert 0 < rig.ch.mech.vel < 50000  # still ramping at 500000 counts/s²
    rig.cycle(100)
    assert rig.sw() & 0x0400
    assert not rig.sw() & 0x1000
    rig.set(0x60FF, 0)
    rig.cycle(300)
    assert rig.sw() & 0x1000  # speed is zero


def test_pt_ramps_torque_with_the_slope() -> None:
    rig = Rig()
    rig.enable(mode=4)
    rig.write(0x6087, 1000, fmt="I")  # 1000 per mille per second
    rig.set(0x6071, 300)
    rig.cycle(100)
    assert rig.ch.dtorque == pytest.approx(100, abs=2)
    assert not rig.sw() & 0x0400
    rig.cycle(250)
    assert rig.ch.dtorque == 300 and rig.sw() & 0x0400


def test_homing_method_37_sets_position_to_home_offset() -> None:
    rig = Rig(machines=[AxisMachine(position=1234.0)])
    rig.write(0x6098, 37, fmt="b")
    rig.write(0x607C, 500)
    rig.enable(mode=6)
    assert rig.sw() & 0x3400 == 0x0400  # not started
    rig.set(0x6040, 0x1F)
    rig.cycle()
    for _ in range(100):
        if rig.cycle()[0x6041] & 0x3400 == 0x1400:
            break
    assert rig.sw() & 0x3400 == 0x1400
    assert rig.inputs[0x6064] == 500
    assert rig.ch.machine_position == pytest.approx(1234.0, abs=1)


def test_homing_on_home_switch_moves_and_redefines_the_encoder() -> None:
    m = AxisMachine(
        position=0.0,
        home_switch=((20000.0, 40000.0),),
        negative_limit=-100000.0,
        positive_limit=100000.0,
    )
    rig = Rig(machines=[m])
    rig.write(0x6098, 19, fmt="b")
    rig.write(0x6099, 50000, sub=1, fmt="I")
    rig.write(0x6099, 5000, sub=2, fmt="I")
    rig.write(0x609A, 1000000, fmt="I")
    rig.enable(mode=6)
    rig.set(0x6040, 0x1F)
    rig.cycle()
    assert rig.sw() & 0x3400 == 0  # in progress from the first cycle after CW4 rises
    for _ in range(5000):
        if rig.cycle()[0x6041] & 0x3400 == 0x1400:
            break
    assert rig.sw() & 0x3400 == 0x1400
    assert rig.ch.machine_position == pytest.approx(20000.0, abs=2)
    assert abs(rig.inputs[0x6064]) <= 2
    # switching back to CSP with 607A = 6064 does not jump
    rig.set(0x607A, rig.inputs[0x6064])
    rig.set(0x6060, 8)
    rig.set(0x6040, 0x0F)
    rig.cycle(20)
    assert rig.ch.state is State.OPERATION_ENABLED and rig.ch.error_code == 0
    # python-canopen's is_homed(): back in HM the bits still say completed
    rig.set(0x6060, 6)
    rig.cycle(3)
    assert rig.sw() & 0x3400 == 0x1400


def test_homing_halt_interrupts() -> None:
    m = AxisMachine(position=0.0, home_switch=((200000.0, 400000.0),))
    rig = Rig(machines=[m])
    rig.write(0x6098, 19, fmt="b")
    rig.enable(mode=6)
    rig.set(0x6040, 0x1F)
    rig.cycle(50)
    rig.set(0x6040, 0x11F)
    for _ in range(500):
        if rig.cycle()[0x6041] & 0x3400 == 0x0400:
            break
    assert rig.sw() & 0x3400 == 0x0400  # interrupted, standing still


def test_homing_with_unsupported_parameters_reports_error() -> None:
    rig = Rig()
    rig.enable(mode=6)  # 6098h = 0: no method chosen
    rig.set(0x6040, 0x1F)
    rig.cycle(2)
    assert rig.sw() & 0x3400 == 0x2400  # homing error, velocity 0
    with pytest.raises(SdoAbort) as e:
        rig.write(0x6098, 15, fmt="b")
    assert e.value.code == SdoAbortCode.VALUE_RANGE_EXCEEDED


def test_mode_0_holds_position() -> None:
    rig = Rig()
    rig.enable(mode=0)
    rig.cycle(10)
    assert rig.ch.mode == OpMode.NO_MODE
    assert rig.ch.mech.vel == 0.0


def test_profile_step_reaches_target_exactly() -> None:
    s, v = 0.0, 0.0
    for _ in range(10000):
        s, v, done = profile_step(s, v, 12345.0, 50000.0, 400000.0, 300000.0, 0.001)
        assert s <= 12345.0 + 1e-6
        if done:
            break
    assert done and s == 12345.0 and v == 0.0
