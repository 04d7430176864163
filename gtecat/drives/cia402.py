"""The CiA 402 power drive system state machine (IEC 61800-7-201 6.3, ETG.6010 5).

States, controlword commands and transitions are tables, not if-ladders:

- :data:`COMMAND_OF` decodes the low byte of 0x6040 into a :class:`Command`
  with the masks of cia402-facts.md 1.3 (bit 7 must be 0 for every command; a
  set bit 7 is a fault reset, which only acts on its rising edge in FAULT);
- :data:`TRANSITIONS` maps (state, command) to (next state, transition number);
- :data:`STATE_BITS` gives the statusword bits 0..6 of each state.

Automatic transitions (0/1 power-on, 12 quick stop done, 13 fault, 14 fault
reaction done, 15 fault reset) are taken by :class:`PowerStateMachine` when
the drive reports the event.  The drive around it decides *when* a ramp is
done and whether a fault cause is still present.
"""

from __future__ import annotations

from enum import IntEnum, IntFlag


class State(IntEnum):
    """PDS states (cia402-facts.md 1.2)."""

    NOT_READY_TO_SWITCH_ON = 0
    SWITCH_ON_DISABLED = 1
    READY_TO_SWITCH_ON = 2
    SWITCHED_ON = 3
    OPERATION_ENABLED = 4
    QUICK_STOP_ACTIVE = 5
    FAULT_REACTION_ACTIVE = 6
    FAULT = 7


class Command(IntEnum):
    """Device control commands decoded from the controlword (cia402-facts.md 1.3)."""

    NONE = 0  # no command pattern (e.g. bit 7 set outside FAULT)
    SHUTDOWN = 1
    SWITCH_ON = 2  # also "disable operation" in OPERATION_ENABLED
    ENABLE_OPERATION = 3  # switch on + enable operation
    DISABLE_VOLTAGE = 4
    QUICK_STOP = 5
    FAULT_RESET = 6  # bit 7 set; acts only on its rising edge in FAULT


class Sw(IntFlag):
    """Statusword 0x6041 bits (cia402-facts.md 1.1)."""

    READY_TO_SWITCH_ON = 1 << 0
    SWITCHED_ON = 1 << 1
    OPERATION_ENABLED = 1 << 2
    FAULT = 1 << 3
    VOLTAGE_ENABLED = 1 << 4
    QUICK_STOP = 1 << 5  # active low: 0 = quick stop active
    SWITCH_ON_DISABLED = 1 << 6
    WARNING = 1 << 7
    MANUFACTURER_8 = 1 << 8
    REMOTE = 1 << 9
    TARGET_REACHED = 1 << 10
    INTERNAL_LIMIT = 1 << 11
    OMS_12 = 1 << 12  # set-point acknowledge / speed / homing attained / drive follows
    OMS_13 = 1 << 13  # following error / max slippage / homing error


class Cw(IntFlag):
    """Controlword 0x6040 bits (cia402-facts.md 1.3)."""

    SWITCH_ON = 1 << 0
    ENABLE_VOLTAGE = 1 << 1
    QUICK_STOP = 1 << 2  # active low
    ENABLE_OPERATION = 1 << 3
    OMS_4 = 1 << 4  # PP new set-point / HM start
    OMS_5 = 1 << 5  # PP change set immediately
    OMS_6 = 1 << 6  # PP relative
    FAULT_RESET = 1 << 7
    HALT = 1 << 8
    OMS_9 = 1 << 9  # PP change on set-point


#: (mask, value) of each state in the statusword, as python-canopen and the TI stack decode it
STATE_PATTERN: dict[State, tuple[int, int]] = {
    State.NOT_READY_TO_SWITCH_ON: (0x004F, 0x0000),
    State.SWITCH_ON_DISABLED: (0x004F, 0x0040),
    State.READY_TO_SWITCH_ON: (0x006F, 0x0021),
    State.SWITCHED_ON: (0x006F, 0x0023),
    State.OPERATION_ENABLED: (0x006F, 0x0027),
    State.QUICK_STOP_ACTIVE: (0x006F, 0x0007),
    State.FAULT_REACTION_ACTIVE: (0x004F, 0x000F),
    State.FAULT: (0x004F, 0x0008),
}

#: statusword bits 0..6 the drive shows in each state.  Bit 4 (voltage enabled) is 1
#: whenever the power stage is fed and not faulted; bit 5 (quick stop, active low) is 1
#: only where the pattern demands it, as in the ZeroErr trace of cia402-facts.md 1.2.
STATE_BITS: dict[State, int] = {
    State.NOT_READY_TO_SWITCH_ON: 0x0000,
    State.SWITCH_ON_DISABLED: 0x0050,
    State.READY_TO_SWITCH_ON: 0x0031,
    State.SWITCHED_ON: 0x0033,
    State.OPERATION_ENABLED: 0x0037,
    State.QUICK_STOP_ACTIVE: 0x0017,
    State.FAULT_REACTION_ACTIVE: 0x000F,
    State.FAULT: 0x0008,
}


def decode_state(statusword: int) -> State | None:
    """The state a statusword shows (None if it matches no pattern)."""
    for state, (mask, value) in STATE_PATTERN.items():
        if statusword & mask == value:
            return state
    return None


def _command(cw: int) -> Command:
    if cw & 0x80:
        return Command.FAULT_RESET
    if cw & 0x02 == 0:
        return Command.DISABLE_VOLTAGE
    if cw & 0x06 == 0x02:
        return Command.QUICK_STOP
    if cw & 0x07 == 0x06:
        return Command.SHUTDOWN
    if cw & 0x0F == 0x07:
        return Command.SWITCH_ON
    return Command.ENABLE_OPERATION  # cw & 0x0F == 0x0F


#: the command of every controlword low byte (index = cw & 0xFF)
COMMAND_OF: tuple[Command, ...] = tuple(_command(b) for b in range(256))

_S = State
_C = Command

#: (state, command) -> (next state, CiA 402 transition number), cia402-facts.md 1.4.
#: Transition 16 (QSA -> OE) is added by the drive only when 605Ah is 5..8.
TRANSITIONS: dict[tuple[State, Command], tuple[State, int]] = {
    (_S.SWITCH_ON_DISABLED, _C.SHUTDOWN): (_S.READY_TO_SWITCH_ON, 2),
    (_S.READY_TO_SWITCH_ON, _C.SWITCH_ON): (_S.SWITCHED_ON, 3),
    (_S.READY_TO_SWITCH_ON, _C.ENABLE_OPERATION): (_S.SWITCHED_ON, 3),
    (_S.SWITCHED_ON, _C.ENABLE_OPERATION): (_S.OPERATION_ENABLED, 4),
    (_S.OPERATION_ENABLED, _C.SWITCH_ON): (_S.SWITCHED_ON, 5),
    (_S.SWITCHED_ON, _C.SHUTDOWN): (_S.READY_TO_SWITCH_ON, 6),
    (_S.READY_TO_SWITCH_ON, _C.DISABLE_VOLTAGE): (_S.SWITCH_ON_DISABLED, 7),
    (_S.READY_TO_SWITCH_ON, _C.QUICK_STOP): (_S.SWITCH_ON_DISABLED, 7),
    (_S.OPERATION_ENABLED, _C.SHUTDOWN): (_S.READY_TO_SWITCH_ON, 8),
    (_S.OPERATION_ENABLED, _C.DISABLE_VOLTAGE): (_S.SWITCH_ON_DISABLED, 9),
    (_S.SWITCHED_ON, _C.DISABLE_VOLTAGE): (_S.SWITCH_ON_DISABLED, 10),
    (_S.SWITCHED_ON, _C.QUICK_STOP): (_S.SWITCH_ON_DISABLED, 10),
    (_S.OPERATION_ENABLED, _C.QUICK_STOP): (_S.QUICK_STOP_ACTIVE, 11),
    (_S.QUICK_STOP_ACTIVE, _C.DISABLE_VOLTAGE): (_S.SWITCH_ON_DISABLED, 12),
}

#: transition 16, allowed when the quick stop option code is 5..8
TRANSITION_16 = ((_S.QUICK_STOP_ACTIVE, _C.ENABLE_OPERATION), (_S.OPERATION_ENABLED, 16))

#: states in which the power stage drives the motor
POWERED = frozenset({State.OPERATION_ENABLED, State.QUICK_STOP_ACTIVE})
#: all transitions by number: (from, to); from None = any state
TRANSITION_TABLE: dict[int, tuple[State | None, State]] = {
    0: (None, State.NOT_READY_TO_SWITCH_ON),
    1: (State.NOT_READY_TO_SWITCH_ON, State.SWITCH_ON_DISABLED),
    12: (State.QUICK_STOP_ACTIVE, State.SWITCH_ON_DISABLED),
    13: (None, State.FAULT_REACTION_ACTIVE),
    14: (State.FAULT_REACTION_ACTIVE, State.FAULT),
    15: (State.FAULT, State.SWITCH_ON_DISABLED),
    16: (State.QUICK_STOP_ACTIVE, State.OPERATION_ENABLED),
    **{n: (a[0], b) for a, (b, n) in TRANSITIONS.items()},
}


class PowerStateMachine:
    """State plus the controlword edge detector; the drive owns the timing.

    ``command(cw, quick_stop_option)`` applies one controlword sample and
    returns the transition number taken (0 = none).  A fault reset acts on the
    0 -> 1 edge of bit 7 between two samples, and only if ``cause_active`` is
    false then; holding the bit does nothing more (cia402-facts.md section 7.1).
    """

    __slots__ = ("last_cw", "last_transition", "state")

    def __init__(self) -> None:
        self.state = State.NOT_READY_TO_SWITCH_ON
        self.last_cw = 0
        self.last_transition = 0

    def power_on(self) -> int:
        """Transition 1: self test done, communication up."""
        if self.state is State.NOT_READY_TO_SWITCH_ON:
            return self._go(State.SWITCH_ON_DISABLED, 1)
        return 0

    def command(self, cw: int, quick_stop_option: int, cause_active: bool = False) -> int:
        rising_reset = bool(cw & 0x80) and not (self.last_cw & 0x80)
        self.last_cw = cw
        state = self.state
        if state is State.FAULT:
            if rising_reset and not cause_active:
                return self._go(State.SWITCH_ON_DISABLED, 15)
            return 0
        if state is State.NOT_READY_TO_SWITCH_ON or state is State.FAULT_REACTION_ACTIVE:
            return 0
        cmd = COMMAND_OF[cw & 0xFF]
        nxt = TRANSITIONS.get((state, cmd))
        if nxt is None:
            if (state, cmd) == TRANSITION_16[0] and 5 <= quick_stop_option <= 8:
                nxt = TRANSITION_16[1]
            else:
                return 0
        return self._go(*nxt)

    def fault(self) -> int:
        """Transition 13: a fault was detected (ignored while already faulted)."""
        if self.state in (State.FAULT_REACTION_ACTIVE, State.FAULT):
            return 0
        return self._go(State.FAULT_REACTION_ACTIVE, 13)

    def fault_reaction_done(self) -> int:
        if self.state is State.FAULT_REACTION_ACTIVE:
            return self._go(State.FAULT, 14)
        return 0

    def quick_stop_done(self) -> int:
        """Transition 12 (automatic) when the quick stop ramp ends with 605Ah in 0..4."""
        if self.state is State.QUICK_STOP_ACTIVE:
            return self._go(State.SWITCH_ON_DISABLED, 12)
        return 0

    def force(self, state: State, transition: int) -> int:
        """A transition the drive takes on its own (e.g. communication loss)."""
        return self._go(state, transition)

    def _go(self, state: State, transition: int) -> int:
        self.state = state
        self.last_transition = transition
        return transition
