"""The CiA 402 power state machine: every transition, the statusword, fault reset, properties."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.drives.cia402 import (
    COMMAND_OF,
    STATE_BITS,
    STATE_PATTERN,
    TRANSITION_TABLE,
    Command,
    PowerStateMachine,
    State,
    decode_state,
)
from gtecat.drives.drive import DriveSettings
from gtecat.drives.machine import AxisMachine
from tests.conftest import examples
from tests.drives.test_drive import Rig

S = State

# (transition, from-state, controlword, expected state) for the controlword-driven transitions
CW_TRANSITIONS = [
    (2, S.SWITCH_ON_DISABLED, 0x06, S.READY_TO_SWITCH_ON),
    (3, S.READY_TO_SWITCH_ON, 0x07, S.SWITCHED_ON),
    (4, S.SWITCHED_ON, 0x0F, S.OPERATION_ENABLED),
    (5, S.OPERATION_ENABLED, 0x07, S.SWITCHED_ON),
    (6, S.SWITCHED_ON, 0x06, S.READY_TO_SWITCH_ON),
    (7, S.READY_TO_SWITCH_ON, 0x00, S.SWITCH_ON_DISABLED),
    (7, S.READY_TO_SWITCH_ON, 0x02, S.SWITCH_ON_DISABLED),
    (8, S.OPERATION_ENABLED, 0x06, S.READY_TO_SWITCH_ON),
    (9, S.OPERATION_ENABLED, 0x00, S.SWITCH_ON_DISABLED),
    (10, S.SWITCHED_ON, 0x00, S.SWITCH_ON_DISABLED),
    (10, S.SWITCHED_ON, 0x02, S.SWITCH_ON_DISABLED),
    (11, S.OPERATION_ENABLED, 0x02, S.QUICK_STOP_ACTIVE),
    (12, S.QUICK_STOP_ACTIVE, 0x00, S.SWITCH_ON_DISABLED),
]

PATH = {
    S.SWITCH_ON_DISABLED: [],
    S.READY_TO_SWITCH_ON: [0x06],
    S.SWITCHED_ON: [0x06, 0x07],
    S.OPERATION_ENABLED: [0x06, 0x07, 0x0F],
    S.QUICK_STOP_ACTIVE: [0x06, 0x07, 0x0F, 0x02],
}


def walk(rig: Rig, cws: list[int]) -> None:
    for cw in cws:
        rig.set(0x6040, cw)
        rig.cycle()


@pytest.mark.parametrize(("number", "start", "cw", "end"), CW_TRANSITIONS)
def test_controlword_transition(number: int, start: State, cw: int, end: State) -> None:
    # 605Ah = 6 keeps QSA (no automatic transition 12) so transition 12 by command is visible
    rig = Rig(settings=DriveSettings(quick_stop_option=6))
    rig.enable(mode=8)
    walk(rig, [0x00])
    walk(rig, PATH[start])
    assert rig.ch.state is start
    walk(rig, [cw])
    assert rig.ch.state is end
    assert rig.ch.psm.last_transition == number
    mask, value = STATE_PATTERN[end]
    assert rig.sw() & mask == value


def test_transition_0_and_1_power_on() -> None:
    rig = Rig(op=False)
    assert rig.ch.state is S.NOT_READY_TO_SWITCH_ON
    assert rig.read(0x6041) & 0x4F == 0x00
    rig.drive.request_state(rig.drive.al_state.PREOP)
    assert rig.ch.state is S.SWITCH_ON_DISABLED and rig.ch.psm.last_transition == 1
    assert rig.read(0x6041) & 0x4F == 0x40


def test_transition_12_automatic_after_quick_stop_ramp() -> None:
    rig = Rig()  # 605Ah = 2: quick-stop ramp, then SWITCH ON DISABLED
    rig.enable(mode=9)
    rig.set(0x60FF, 50000)
    rig.cycle(100)
    assert rig.ch.mech.vel > 40000
    walk(rig, [0x02])
    assert rig.ch.state is S.QUICK_STOP_ACTIVE
    assert rig.sw() & 0x6F == 0x07
    for _ in range(200):
        rig.cycle()
        if rig.ch.state is not S.QUICK_STOP_ACTIVE:
            break
    assert rig.ch.state is S.SWITCH_ON_DISABLED and rig.ch.psm.last_transition == 12
    assert abs(rig.ch.mech.vel) < 100


@pytest.mark.parametrize("option", [5, 6, 7, 8])
def test_transition_16_back_to_operation_enabled(option: int) -> None:
    rig = Rig(settings=DriveSettings(quick_stop_option=option))
    rig.enable(mode=8)
    walk(rig, [0x02])
    rig.cycle(50)
    assert rig.ch.state is S.QUICK_STOP_ACTIVE  # 5..8 stay in QSA
    walk(rig, [0x0F])
    assert rig.ch.state is S.OPERATION_ENABLED and rig.ch.psm.last_transition == 16


@pytest.mark.parametrize("option", [1, 2, 3, 4])
def test_no_transition_16_for_options_1_to_4(option: int) -> None:
    sm = PowerStateMachine()
    sm.state = S.QUICK_STOP_ACTIVE
    assert sm.command(0x0F, option) == 0
    assert sm.state is S.QUICK_STOP_ACTIVE


def test_quick_stop_option_0_disables_at_once() -> None:
    rig = Rig(settings=DriveSettings(quick_stop_option=0))
    rig.enable()
    walk(rig, [0x02])
    assert rig.ch.state is S.SWITCH_ON_DISABLED and rig.ch.psm.last_transition == 12


def test_transitions_13_14_15_fault_and_reset_on_rising_edge_only() -> None:
    rig = Rig()
    rig.enable()
    rig.ch.inject_fault("alarm")
    rig.cycle()
    assert rig.ch.psm.last_transition in (13, 14)
    rig.cycle(20)
    assert rig.ch.state is S.FAULT and rig.ch.psm.last_transition == 14
    assert rig.inputs[0x603F] == 0xFF00
    assert rig.sw() & 0x4F == 0x08
    # a rising edge while the cause persists does nothing
    walk(rig, [0x80, 0x00, 0x80])
    assert rig.ch.state is S.FAULT
    rig.ch.clear_injected_fault()
    # bit 7 held high from before: no new edge, still FAULT
    walk(rig, [0x80, 0x80])
    assert rig.ch.state is S.FAULT
    walk(rig, [0x00, 0x80])
    assert rig.ch.state is S.SWITCH_ON_DISABLED and rig.ch.psm.last_transition == 15
    assert rig.inputs[0x603F] == 0
    # bit 7 still set: no command, stays SOD; clear it and enable again
    walk(rig, [0x86])
    assert rig.ch.state is S.SWITCH_ON_DISABLED
    rig.enable()


def test_fault_reset_within_one_cycle_is_missed() -> None:
    """Two writes between samples never make an edge (Technosoft, cia402-facts 7.1)."""
    rig = Rig(rx=(), tx=())
    rig.ch.inject_fault("alarm")
    rig.cycle(3)
    rig.ch.clear_injected_fault()
    rig.write(0x6040, 0x80)
    rig.write(0x6040, 0x00)
    rig.cycle()
    assert rig.ch.state is S.FAULT
    rig.write(0x6040, 0x80)
    rig.cycle()
    assert rig.ch.state is S.SWITCH_ON_DISABLED


def test_fault_from_switch_on_disabled_goes_straight_through() -> None:
    rig = Rig()
    rig.cycle()
    rig.ch.inject_fault(0x2310)
    rig.cycle(2)
    assert rig.ch.state is S.FAULT and rig.ch.error_code == 0x2310


def test_command_decoding_masks() -> None:
    assert COMMAND_OF[0x06] is Command.SHUTDOWN
    assert COMMAND_OF[0x0E] is Command.SHUTDOWN
    assert COMMAND_OF[0x07] is Command.SWITCH_ON
    assert COMMAND_OF[0x0F] is Command.ENABLE_OPERATION
    assert COMMAND_OF[0x1F] is Command.ENABLE_OPERATION
    assert COMMAND_OF[0x0D] is Command.DISABLE_VOLTAGE
    assert COMMAND_OF[0x0B] is Command.QUICK_STOP
    assert COMMAND_OF[0x8F] is Command.FAULT_RESET


def test_rtso_with_enable_operation_walks_through_switched_on() -> None:
    rig = Rig()
    walk(rig, [0x06, 0x0F])
    assert rig.ch.state is S.SWITCHED_ON
    walk(rig, [0x0F])
    assert rig.ch.state is S.OPERATION_ENABLED


def test_state_bits_match_python_canopen_masks() -> None:
    from canopen.profiles.p402 import State402

    names = {
        S.NOT_READY_TO_SWITCH_ON: "NOT READY TO SWITCH ON",
        S.SWITCH_ON_DISABLED: "SWITCH ON DISABLED",
        S.READY_TO_SWITCH_ON: "READY TO SWITCH ON",
        S.SWITCHED_ON: "SWITCHED ON",
        S.OPERATION_ENABLED: "OPERATION ENABLED",
        S.QUICK_STOP_ACTIVE: "QUICK STOP ACTIVE",
        S.FAULT_REACTION_ACTIVE: "FAULT REACTION ACTIVE",
        S.FAULT: "FAULT",
    }
    for state, bits in STATE_BITS.items():
        mask, value = State402.SW_MASK[names[state]]
        assert bits & mask == value
        matches = [n for n, (m, v) in State402.SW_MASK.items() if bits & m == v]
        assert matches == [names[state]]
        assert decode_state(bits | 0x0200) is state


def test_transition_table_lists_all_sixteen() -> None:
    assert set(TRANSITION_TABLE) == set(range(17))


@settings(max_examples=examples(60, 15), deadline=None)
@given(st.lists(st.integers(0, 0xFFFF), min_size=1, max_size=40))
def test_any_controlword_sequence_stays_legal(cws: list[int]) -> None:
    rig = Rig(machines=[AxisMachine()])
    allowed = {(a, b) for a, b in TRANSITION_TABLE.values()}
    for cw in cws:
        before = rig.ch.state
        rig.set(0x6040, cw)
        rig.set(0x6060, 8)
        rig.set(0x607A, rig.ch.position_actual)
        rig.cycle()
        after = rig.ch.state
        assert decode_state(rig.sw()) is after
        if after is not before:
            n = rig.ch.psm.last_transition
            frm, to = TRANSITION_TABLE[n]
            assert to is after and frm in (None, before)
            assert (frm, to) in allowed
        sw = rig.sw()
        assert sw & 0x0200  # remote
        if after is not S.OPERATION_ENABLED:
            assert not sw & 0x1000 or rig.ch.mode == 6
        assert after is not S.NOT_READY_TO_SWITCH_ON
