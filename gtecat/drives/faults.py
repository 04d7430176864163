"""Drive faults: the 603Fh error codes and what keeps a fault from being reset.

Error codes are the CiA 402 / CiA 301 emergency codes (IEC 61800-7-201 Annex,
"error code" table); 0xFFxx are this virtual drive's vendor codes.  A fault has
a *cause* that may persist: an injected alarm or encoder error stays until the
scenario clears it, while a following error or a limit-switch fault is over
once the drive has stopped.  A fault reset (rising edge of 6040h bit 7) is
honoured only when no cause persists (cia402-facts.md section 7.1).
"""

from __future__ import annotations

from enum import IntEnum

from gtecat.eni.errors import GtecatError


class ErrorCode(IntEnum):
    """Values of 603Fh."""

    NO_ERROR = 0x0000
    GENERIC = 0x1000
    CONTINUOUS_OVER_CURRENT = 0x2310
    SHORT_CIRCUIT = 0x2320
    DC_LINK_OVER_VOLTAGE = 0x3210
    DC_LINK_UNDER_VOLTAGE = 0x3220
    DRIVE_OVER_TEMPERATURE = 0x4310
    MOTOR_OVER_TEMPERATURE = 0x4410
    ENCODER = 0x7305  # incremental sensor 1 fault
    COMMUNICATION = 0x8100
    #: CiA 301 "life guard error or heartbeat error": the drive's process data stopped
    #: (its sync-manager watchdog ran out)
    LIFE_GUARD = 0x8130
    FOLLOWING_ERROR = 0x8611
    REFERENCE_LIMIT = 0x8612
    ALARM = 0xFF00  # vendor: external alarm / generic servo alarm
    POSITIVE_LIMIT = 0xFF01  # vendor: positive limit switch (limit reaction "fault")
    NEGATIVE_LIMIT = 0xFF02  # vendor: negative limit switch
    SAFE_TORQUE_OFF = 0xFF10  # vendor: the STO input removed the power stage's enable


#: names a scenario may pass to ``inject_fault`` (besides an ErrorCode or a raw code)
FAULT_KINDS: dict[str, ErrorCode] = {
    "alarm": ErrorCode.ALARM,
    "encoder": ErrorCode.ENCODER,
    "overcurrent": ErrorCode.CONTINUOUS_OVER_CURRENT,
    "short_circuit": ErrorCode.SHORT_CIRCUIT,
    "overvoltage": ErrorCode.DC_LINK_OVER_VOLTAGE,
    "undervoltage": ErrorCode.DC_LINK_UNDER_VOLTAGE,
    "overtemperature": ErrorCode.DRIVE_OVER_TEMPERATURE,
    "motor_overtemperature": ErrorCode.MOTOR_OVER_TEMPERATURE,
    "following_error": ErrorCode.FOLLOWING_ERROR,
    "communication": ErrorCode.COMMUNICATION,
    "life_guard": ErrorCode.LIFE_GUARD,
    "generic": ErrorCode.GENERIC,
    "sto": ErrorCode.SAFE_TORQUE_OFF,
}


#: faults whose cause is over once the drive has stopped: injecting one fires it once
TRANSIENT: frozenset[int] = frozenset(
    {
        ErrorCode.FOLLOWING_ERROR,
        ErrorCode.REFERENCE_LIMIT,
        ErrorCode.POSITIVE_LIMIT,
        ErrorCode.NEGATIVE_LIMIT,
        ErrorCode.COMMUNICATION,
        ErrorCode.LIFE_GUARD,
    }
)


def error_register(code: int) -> int:
    """1001h (and the error register byte of the emergency) for a 603Fh ``code``.

    CiA 301 (7.5.2.2, object 1001h): bit 0 generic error is set for every error; the
    class of the code (its high digits, CiA 301 table of emergency error codes) sets
    one more: bit 1 current (2xxxh), bit 2 voltage (3xxxh), bit 3 temperature (4xxxh),
    bit 4 communication (81xxh: 8100h, 8130h life guard), bit 7 manufacturer specific
    (FFxxh).  The other classes (1000h generic, 5xxxh device hardware, 7xxxh additional
    modules such as the encoder, 86xxh the CiA 402 positioning codes: following error,
    reference limit) set bit 0 alone.  0 for no error.
    """
    code &= 0xFFFF
    if not code:
        return 0
    reg = 0x01
    if 0x2000 <= code < 0x3000:
        reg |= 0x02
    elif 0x3000 <= code < 0x4000:
        reg |= 0x04
    elif 0x4000 <= code < 0x5000:
        reg |= 0x08
    elif 0x8100 <= code < 0x8200:
        reg |= 0x10
    elif code >= 0xFF00:
        reg |= 0x80
    return reg


class FaultError(GtecatError):
    """A fault kind a scenario asked for that the drive does not know."""


def fault_code(kind: str | int) -> int:
    """An injectable fault as its 603Fh code: a name of :data:`FAULT_KINDS` or a code."""
    if isinstance(kind, str):
        try:
            return FAULT_KINDS[kind.lower()]
        except KeyError:
            raise FaultError(
                f"unknown fault kind {kind!r}; use one of {', '.join(FAULT_KINDS)} or a code"
            ) from None
    code = int(kind)
    if not 0 < code <= 0xFFFF:
        raise FaultError(f"fault code 0x{code:X} is not a 16-bit 603Fh code")
    return code


class FaultMonitor:
    """The latched 603Fh code and the persisting causes of one channel."""

    __slots__ = ("code", "injected", "pending")

    def __init__(self) -> None:
        self.code = 0  # 603Fh: the fault being shown (kept until a reset succeeds)
        self.injected = 0  # code of a persisting injected cause (0 = none)
        self.pending = 0  # a fault detected since the last cycle, not yet acted on

    @property
    def cause_active(self) -> bool:
        return self.injected != 0

    def raise_fault(self, code: int) -> None:
        """Report a fault; the drive enters FAULT REACTION ACTIVE on its next step."""
        if not self.pending:
            self.pending = code

    def inject(self, code: int) -> None:
        """A scenario's fault: its cause persists until cleared, unless it is TRANSIENT."""
        if code not in TRANSIENT:
            self.injected = code
        self.raise_fault(code)

    def clear_injected(self) -> None:
        self.injected = 0

    def take_pending(self) -> int:
        code, self.pending = self.pending, 0
        if code:
            self.code = code
        return code

    def reset(self) -> None:
        """A successful fault reset (transition 15)."""
        self.code = 0
        self.pending = 0


def forced_level(din: int, on: int, off: int) -> int:
    """The inputs ``din`` as the drive reads them while the field forces the bits ``on``
    set and the bits ``off`` clear (a bit in both reads clear): the one rule for 60FDh,
    the drive's homing and everything that reads a switch through them."""
    return (din | on) & ~off


class FieldOverride:
    """What the field does to one channel against the machine description: the scenario's
    hands on the wiring and the mechanics (set by :mod:`gtecat.faults`, read every cycle).

    ``din_set`` / ``din_clear``: 60FDh bits forced on / off (a switch stuck, a chattering
    one toggled every few cycles, a probe input that never switches); ``enc_noise``: +/-
    that many counts of noise on the encoder's reading (from ``rng``, seeded: runs repeat;
    drawn once a cycle, :attr:`Channel.noise_now`: 6064h, 60F4h and the following-error
    supervision read the same noisy position; the motor does not follow the noise, which
    the drive's loop filters).  Counts lost are no override: the drive's encoder offset
    moves for good (:meth:`Channel.lose_counts`); ``quick_stop``: the drive's quick-stop
    input is active (as controlword bit 2 clear); ``brake``: the holding brake stays
    closed (the motor cannot turn); ``sto``: safe torque off (no torque at all);
    ``probe_off``: the touch-probe inputs never switch.
    """

    __slots__ = (
        "brake",
        "din_clear",
        "din_set",
        "enc_noise",
        "probe_off",
        "quick_stop",
        "rng",
        "sto",
    )

    def __init__(self) -> None:
        import random

        self.din_set = 0
        self.din_clear = 0
        self.enc_noise = 0
        self.quick_stop = False
        self.brake = False
        self.sto = False
        self.probe_off = False
        self.rng = random.Random(0x6064)

    @property
    def idle(self) -> bool:
        return not (
            self.din_set
            or self.din_clear
            or self.enc_noise
            or self.quick_stop
            or self.brake
            or self.sto
            or self.probe_off
        )

    def noise(self) -> int:
        n = self.enc_noise
        return self.rng.randint(-n, n) if n else 0
