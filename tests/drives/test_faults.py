"""Faults: following error, limit switches, injected alarm/encoder faults, recovery after reset."""

from __future__ import annotations

import pytest

from gtecat.drives.cia402 import State
from gtecat.drives.drive import DriveSettings
from gtecat.drives.faults import ErrorCode, FaultError, FaultMonitor, fault_code
from gtecat.drives.machine import AxisMachine
from tests.drives.test_drive import Rig


def reset(rig: Rig) -> None:
    for cw in (0x00, 0x80, 0x00):
        rig.set(0x6040, cw)
        rig.cycle()


def test_enabling_csp_far_from_the_actual_position_trips_following_error() -> None:
    """cia402-facts 7.4: 607A must equal 6064 before OE in CSP, or the drive trips."""
    rig = Rig(machines=[AxisMachine(position=50000.0)])
    rig.set(0x6060, 8)
    rig.set(0x607A, 0)  # stale target far from 6064 = 50000
    for cw in (0x06, 0x07, 0x0F):
        rig.set(0x6040, cw)
        rig.cycle()
    assert rig.ch.state is State.OPERATION_ENABLED
    rig.cycle(12)  # 6066h = 10 ms
    assert rig.ch.state in (State.FAULT_REACTION_ACTIVE, State.FAULT)
    assert rig.inputs[0x603F] == 0x8611
    rig.cycle(200)
    assert rig.ch.state is State.FAULT and rig.sw() & 0x4F == 0x08
    moved = 50000.0 - rig.ch.machine_position
    assert 0 < moved < 20000  # it started to move, then stopped on the fault
    # the cause is gone: reset on the rising edge, then enable properly
    reset(rig)
    assert rig.ch.state is State.SWITCH_ON_DISABLED and rig.inputs[0x603F] == 0
    rig.enable(mode=8)
    rig.cycle(50)
    assert rig.ch.state is State.OPERATION_ENABLED


def test_csp_step_beyond_the_window_trips_after_the_timeout() -> None:
    rig = Rig()
    rig.write(0x6065, 1000, fmt="I")
    rig.write(0x6066, 5, fmt="H")
    rig.enable(mode=8)
    rig.set(0x607A, 5000)
    n = 0
    while rig.ch.state is State.OPERATION_ENABLED and n < 50:
        rig.cycle()
        n += 1
    assert 5 <= n <= 7
    assert rig.ch.error_code == ErrorCode.FOLLOWING_ERROR


def test_following_error_monitoring_off() -> None:
    rig = Rig()
    rig.write(0x6065, 0xFFFFFFFF, fmt="I")
    rig.enable(mode=8)
    rig.set(0x607A, 300000)
    rig.cycle(800)
    assert rig.ch.state is State.OPERATION_ENABLED
    assert rig.inputs[0x6064] == pytest.approx(300000, abs=2)


def test_following_error_flag_only_when_fault_disabled() -> None:
    rig = Rig(settings=DriveSettings(following_error_fault=False))
    rig.enable(mode=8)
    rig.set(0x607A, 100000)
    rig.cycle(15)
    assert rig.ch.state is State.OPERATION_ENABLED
    assert rig.sw() & 0x2000  # SW13 following error


@pytest.mark.parametrize("kind", ["alarm", "encoder", "overcurrent", 0x4310])
def test_injected_fault_needs_the_cause_cleared_before_reset(kind: str | int) -> None:
    rig = Rig()
    rig.enable(mode=9)
    rig.set(0x60FF, 20000)
    rig.cycle(50)
    code = rig.ch.inject_fault(kind)
    rig.cycle(100)
    assert rig.ch.state is State.FAULT and rig.inputs[0x603F] == code
    reset(rig)
    assert rig.ch.state is State.FAULT  # cause still present
    rig.ch.clear_injected_fault()
    assert rig.ch.state is State.FAULT  # and clearing the cause alone does not reset
    reset(rig)
    assert rig.ch.state is State.SWITCH_ON_DISABLED and rig.inputs[0x603F] == 0
    rig.enable(mode=9)


def test_injected_following_error_is_transient() -> None:
    rig = Rig()
    rig.enable(mode=8)
    assert rig.ch.inject_fault("following_error") == 0x8611
    rig.cycle(30)
    assert rig.ch.state is State.FAULT and rig.inputs[0x603F] == 0x8611
    reset(rig)
    assert rig.ch.state is State.SWITCH_ON_DISABLED


def test_encoder_fault_freezes_the_position() -> None:
    rig = Rig()
    rig.enable(mode=9)
    rig.set(0x60FF, 20000)
    rig.cycle(50)
    rig.ch.inject_fault("encoder")
    frozen = rig.cycle()[0x6064]
    rig.cycle(20)
    assert rig.inputs[0x6064] == frozen
    assert rig.ch.machine_position != frozen


@pytest.mark.parametrize(("option", "coasts"), [(0, True), (1, False), (2, False), (3, False)])
def test_fault_reaction_options(option: int, coasts: bool) -> None:
    rig = Rig()
    rig.write(0x605E, option, fmt="h")
    rig.enable(mode=9)
    rig.set(0x60FF, 100000)
    rig.cycle(100)
    rig.ch.inject_fault("alarm")
    rig.cycle()
    if coasts:
        assert rig.ch.state is State.FAULT
    else:
        assert rig.ch.state is State.FAULT_REACTION_ACTIVE
        assert rig.sw() & 0x4F == 0x0F
    rig.cycle(500)
    assert rig.ch.state is State.FAULT


def test_limit_switch_stops_motion_into_it_and_allows_leaving() -> None:
    m = AxisMachine(position=0.0, positive_limit=20000.0, negative_limit=-20000.0)
    rig = Rig(machines=[m])
    rig.enable(mode=9)
    rig.set(0x60FF, 100000)
    for _ in range(1000):
        rig.cycle()
        if rig.inputs[0x60FD] & 2:
            break
    assert rig.inputs[0x60FD] & 2
    rig.cycle(100)
    stop = rig.ch.machine_position
    assert 20000 <= stop < 21000  # overran the switch by the braking distance only
    assert abs(rig.inputs[0x606C]) < 50
    assert rig.sw() & 0x0800 and rig.sw() & 0x0080  # internal limit, warning
    assert not rig.sw() & 0x1000  # CSV no longer follows
    assert rig.ch.state is State.OPERATION_ENABLED and rig.ch.error_code == 0
    rig.cycle(100)
    assert rig.ch.machine_position == pytest.approx(stop, abs=1)
    rig.set(0x60FF, -50000)  # leaving is allowed
    rig.cycle(100)
    assert rig.ch.machine_position < 19000
    assert not rig.inputs[0x60FD] & 2


def test_limit_switch_in_csp_does_not_trip_following_error() -> None:
    m = AxisMachine(position=0.0, positive_limit=5000.0)
    rig = Rig(machines=[m])
    rig.enable(mode=8)
    target = 0
    for _ in range(300):
        target += 50
        rig.set(0x607A, target)
        rig.cycle()
    assert rig.ch.state is State.OPERATION_ENABLED
    assert 5000 <= rig.ch.machine_position < 5300  # braking distance at 6085h


def test_limit_switch_fault_reaction() -> None:
    m = AxisMachine(position=0.0, negative_limit=-3000.0)
    rig = Rig(machines=[m], settings=DriveSettings(limit_reaction="fault"))
    rig.enable(mode=9)
    rig.set(0x60FF, -50000)
    rig.cycle(200)
    assert rig.ch.state is State.FAULT and rig.ch.error_code == ErrorCode.NEGATIVE_LIMIT
    rig.set(0x60FF, 0)
    reset(rig)
    assert rig.ch.state is State.SWITCH_ON_DISABLED  # transient cause: reset works


def test_homing_mode_ignores_the_limit_reaction() -> None:
    m = AxisMachine(position=0.0, negative_limit=-20000.0, positive_limit=20000.0)
    rig = Rig(machines=[m])
    rig.write(0x6098, 17, fmt="b")  # negative limit switch as the reference
    rig.write(0x6099, 50000, sub=1, fmt="I")
    rig.write(0x609A, 1000000, fmt="I")
    rig.enable(mode=6)
    rig.set(0x6040, 0x1F)
    for _ in range(3000):
        if rig.cycle()[0x6041] & 0x3400 == 0x1400:
            break
    assert rig.sw() & 0x3400 == 0x1400 and rig.ch.error_code == 0
    assert rig.ch.machine_position == pytest.approx(-20000.0, abs=2)


def test_fault_kinds() -> None:
    assert fault_code("alarm") == 0xFF00 and fault_code("ENCODER") == 0x7305
    assert fault_code(0x8611) == 0x8611
    with pytest.raises(FaultError):
        fault_code("meltdown")
    with pytest.raises(FaultError):
        fault_code(0x10000)
    mon = FaultMonitor()
    mon.raise_fault(0x8611)
    mon.raise_fault(0x7305)  # the first pending one wins
    assert mon.take_pending() == 0x8611 and mon.code == 0x8611 and not mon.cause_active
