"""The fault vocabulary: one dataclass per kind of thing that goes wrong on a machine.

Three depths (DESIGN.md "Faults, recordings, checks"):

* the frame and its datagrams - :class:`DropResponses`, :class:`WkcOffset`,
  :class:`LinkDown`, :class:`FrameTruncate`, :class:`FrameWrongIndex`,
  :class:`FrameReplay`, :class:`FrameDelay`;
* the slave - :class:`PowerCycle`, :class:`RetreatSafeop`, :class:`AlError`, and its
  mailbox: :class:`MailboxAbort`, :class:`MailboxProtocol`, :class:`MailboxLost`;
* the drive and the machine - :class:`DriveFault` (603Fh), :class:`Sto`,
  :class:`QuickStopInput`, :class:`Brake`, :class:`SwitchStuck`, :class:`SwitchChatter`,
  :class:`EncoderLost`, :class:`EncoderNoise`, :class:`ProbeMissing`, :class:`IoStuck`.

A fault only says *what*; the bus it acts on (:mod:`gtecat.faults.bus`: the emulated bus
in-process, or the chain of ``gtecat serve``) says *how* on that bus, so one object means
the same on both.  *When* is a trigger (:mod:`gtecat.faults.triggers`).  Every kind has
``describe()`` in words and a plain-dict form (``as_dict`` / :func:`fault_from_dict`) that
the machine TOML's ``[[fault]]`` tables, the command line and recordings share.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import operator
from dataclasses import dataclass
from typing import Any, ClassVar

from gtecat.drives.abort import SdoAbortCode
from gtecat.drives.faults import FAULT_KINDS, ErrorCode
from gtecat.eni.errors import GtecatError


class FaultSpecError(GtecatError):
    """A fault description that cannot be used (unknown kind, missing or bad value)."""


#: kind name -> class
KINDS: dict[str, type[Fault]] = {}

#: what a mailbox fault may hit: any request, or one step of an SDO transfer (ETG.1000.6 5.6.2)
MAILBOX_STEPS = ("request", "download_init", "download_segment", "upload_init", "upload_segment")
#: the switches of an axis: 60FDh bit (CiA 402 6.2.1)
SWITCH_BITS = {"negative": 0, "positive": 1, "home": 2}
#: homing stages a trigger may wait for (the drive's homing phases)
HOMING_STAGES = ("search", "approach", "index", "return", "completed", "interrupted", "failed")


def _register(cls: type[Fault]) -> type[Fault]:
    KINDS[cls.kind] = cls
    return cls


@dataclass(kw_only=True)
class Fault:
    """Base of every kind: ``kind`` names it in TOML and on the command line."""

    kind: ClassVar[str] = ""
    #: frame | slave | mailbox | drive | field
    depth: ClassVar[str] = ""
    #: a fault that happens once (a power cycle); the others last until cleared or spent
    once: ClassVar[bool] = False
    summary: ClassVar[str] = ""

    def __post_init__(self) -> None:
        _check(self)  # every way in (a dict, the command line, the class itself) is checked

    def describe(self) -> str:
        return self.kind

    def as_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {"kind": self.kind}
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            if isinstance(v, int) and type(v) is not int:
                v = int(v)  # (an enum member, ErrorCode.X: a listing shows plain numbers)
            if v is not None:
                d[f.name] = list(v) if isinstance(v, tuple) else v
        return d


def _code_text(code: int) -> str:
    try:
        return f"0x{code:04X} ({ErrorCode(code).name.lower().replace('_', ' ')})"
    except ValueError:
        return f"0x{code:04X}"


def _abort_text(code: int) -> str:
    try:
        return f"0x{code:08X} ({SdoAbortCode(code).name.lower().replace('_', ' ')})"
    except ValueError:
        return f"0x{code:08X}"


def _times(count: int) -> str:
    if count == 0:
        return "until cleared"
    return "once" if count == 1 else f"{count} times"


# --- the frame ----------------------------------------
@_register
@dataclass(kw_only=True)
class DropResponses(Fault):
    kind: ClassVar[str] = "drop_responses"
    depth: ClassVar[str] = "frame"
    summary: ClassVar[str] = "the next COUNT answers never come back (the master times out)"
    count: int = 1

    def describe(self) -> str:
        n = self.count
        return f"the next {n} answer{'s' if n != 1 else ''} lost" if n else "every answer lost"


@_register
@dataclass(kw_only=True)
class WkcOffset(Fault):
    kind: ClassVar[str] = "wkc_offset"
    depth: ClassVar[str] = "frame"
    summary: ClassVar[str] = (
        "the working counter of COMMAND datagrams (or of those touching logical AREA "
        "[start, end) bytes) is off by OFFSET"
    )
    offset: int = -1
    command: str | None = None  # LRW, LRD, LWR, BRD, APRD, FPRD, ... (None: every command)
    area: tuple[int, int] | None = None  # logical bytes [start, end)
    count: int = 0  # answers affected (0: until cleared)

    def describe(self) -> str:
        what = f"{self.command} " if self.command else ""
        where = f" touching logical bytes {self.area[0]}..{self.area[1]}" if self.area else ""
        return f"working counter of {what}datagrams{where} off by {self.offset:+d}, " + _times(
            self.count
        )


@_register
@dataclass(kw_only=True)
class LinkDown(Fault):
    kind: ClassVar[str] = "link_down"
    depth: ClassVar[str] = "frame"
    summary: ClassVar[str] = (
        "the cable behind slave AFTER_SLAVE is pulled: the slaves after it vanish "
        "(-1: the cable at the master, the whole bus)"
    )
    after_slave: int

    def describe(self) -> str:
        if self.after_slave < 0:
            return "link down at the master (every slave vanishes)"
        return f"link down after slave {self.after_slave} (slaves {self.after_slave + 1}.. vanish)"


@_register
@dataclass(kw_only=True)
class FrameTruncate(Fault):
    kind: ClassVar[str] = "frame_truncate"
    depth: ClassVar[str] = "frame"
    summary: ClassVar[str] = "answers come back BYTES shorter (the master drops them as malformed)"
    bytes: int = 8
    count: int = 1

    def describe(self) -> str:
        return f"answers cut short by {self.bytes} bytes, {_times(self.count)}"


@_register
@dataclass(kw_only=True)
class FrameWrongIndex(Fault):
    kind: ClassVar[str] = "frame_wrong_index"
    depth: ClassVar[str] = "frame"
    summary: ClassVar[str] = "answers come back with another datagram index (not the master's)"
    count: int = 1

    def describe(self) -> str:
        return f"answers with a wrong datagram index, {_times(self.count)}"


@_register
@dataclass(kw_only=True)
class FrameReplay(Fault):
    kind: ClassVar[str] = "frame_replay"
    depth: ClassVar[str] = "frame"
    summary: ClassVar[str] = "the previous answer is sent again instead of this one"
    count: int = 1

    def describe(self) -> str:
        return f"the previous answer replayed, {_times(self.count)}"


@_register
@dataclass(kw_only=True)
class FrameDelay(Fault):
    kind: ClassVar[str] = "frame_delay"
    depth: ClassVar[str] = "frame"
    summary: ClassVar[str] = "answers leave US microseconds late (past the cycle: lost for it)"
    us: int = 1000
    count: int = 1

    def describe(self) -> str:
        return f"answers delayed by {self.us} us, {_times(self.count)}"


# --- the slave ----------------------------------------
@_register
@dataclass(kw_only=True)
class PowerCycle(Fault):
    kind: ClassVar[str] = "power_cycle"
    depth: ClassVar[str] = "slave"
    once: ClassVar[bool] = True
    summary: ClassVar[str] = "SLAVE loses power and comes back in INIT, its settings lost"
    slave: int

    def describe(self) -> str:
        return f"slave {self.slave} power-cycled (back to INIT, settings lost)"


@_register
@dataclass(kw_only=True)
class RetreatSafeop(Fault):
    kind: ClassVar[str] = "retreat_safeop"
    depth: ClassVar[str] = "slave"
    once: ClassVar[bool] = True
    summary: ClassVar[str] = "SLAVE leaves OP for SAFEOP by itself (with AL status CODE, 0: none)"
    slave: int
    code: int = 0

    def describe(self) -> str:
        extra = f" with AL status 0x{self.code:04X}" if self.code else ""
        return f"slave {self.slave} retreats to SAFEOP{extra}"


@_register
@dataclass(kw_only=True)
class AlError(Fault):
    kind: ClassVar[str] = "al_error"
    depth: ClassVar[str] = "slave"
    summary: ClassVar[str] = (
        "SLAVE latches AL status CODE and falls to STATE; it refuses to go higher until cleared"
    )
    slave: int
    code: int = 0x001A  # synchronization error
    state: str = "SAFEOP"

    def describe(self) -> str:
        return f"slave {self.slave} latches AL status 0x{self.code:04X} in {self.state.upper()}"


# --- the mailbox ----------------------------------------
@_register
@dataclass(kw_only=True)
class MailboxAbort(Fault):
    kind: ClassVar[str] = "mailbox_abort"
    depth: ClassVar[str] = "mailbox"
    summary: ClassVar[str] = (
        "SDOs to INDEX of SLAVE are aborted with CODE at STEP (request, download_init, "
        "download_segment, upload_init, upload_segment)"
    )
    slave: int
    index: int | None = None
    code: int = 0x08000000
    subindex: int | None = None
    step: str = "request"
    count: int = 1

    def describe(self) -> str:
        obj = f"0x{self.index:04X}" if self.index is not None else "any object"
        if self.subindex is not None and self.index is not None:
            obj += f":{self.subindex:02X}"
        at = "" if self.step == "request" else f" at {self.step.replace('_', ' ')}"
        return f"SDO to {obj} of slave {self.slave} aborted{at} with {_abort_text(self.code)}, " + (
            _times(self.count)
        )


@_register
@dataclass(kw_only=True)
class MailboxProtocol(Fault):
    kind: ClassVar[str] = "mailbox_protocol"
    depth: ClassVar[str] = "mailbox"
    summary: ClassVar[str] = (
        "SLAVE answers mailbox requests (to INDEX) with a protocol fault: VARIANT "
        "mailbox_error, wrong_service or short"
    )
    slave: int
    index: int | None = None
    variant: str = "mailbox_error"
    count: int = 1

    def describe(self) -> str:
        obj = f" to 0x{self.index:04X}" if self.index is not None else ""
        return f"mailbox requests{obj} of slave {self.slave} answered with a protocol fault " + (
            f"({self.variant.replace('_', ' ')}), {_times(self.count)}"
        )


@_register
@dataclass(kw_only=True)
class MailboxLost(Fault):
    kind: ClassVar[str] = "mailbox_lost"
    depth: ClassVar[str] = "mailbox"
    summary: ClassVar[str] = "SLAVE never answers mailbox requests (to INDEX): the master times out"
    slave: int
    index: int | None = None
    count: int = 1

    def describe(self) -> str:
        obj = f" to 0x{self.index:04X}" if self.index is not None else ""
        return f"the answer to mailbox requests{obj} of slave {self.slave} lost, " + _times(
            self.count
        )


# --- the drive ----------------------------------------
@_register
@dataclass(kw_only=True)
class DriveFault(Fault):
    kind: ClassVar[str] = "drive_fault"
    depth: ClassVar[str] = "drive"
    summary: ClassVar[str] = (
        "the drive of AXIS faults with 603Fh CODE (2310h overcurrent, 3210h overvoltage, "
        "3220h undervoltage, 4310h overtemperature, 7305h encoder, 8611h following error, "
        "or a name); the cause lasts until cleared"
    )
    axis: int
    code: int = int(ErrorCode.CONTINUOUS_OVER_CURRENT)

    def describe(self) -> str:
        return f"drive of axis {self.axis} faults with {_code_text(self.code)}"


@_register
@dataclass(kw_only=True)
class Sto(Fault):
    kind: ClassVar[str] = "sto"
    depth: ClassVar[str] = "drive"
    summary: ClassVar[str] = "safe torque off on AXIS: no torque at once, the drive faults (FF10h)"
    axis: int

    def describe(self) -> str:
        return f"safe torque off on axis {self.axis}"


@_register
@dataclass(kw_only=True)
class QuickStopInput(Fault):
    kind: ClassVar[str] = "quick_stop"
    depth: ClassVar[str] = "drive"
    summary: ClassVar[str] = "the quick-stop input of AXIS's drive is active"
    axis: int

    def describe(self) -> str:
        return f"quick-stop input of axis {self.axis} active"


@_register
@dataclass(kw_only=True)
class Brake(Fault):
    kind: ClassVar[str] = "brake"
    depth: ClassVar[str] = "drive"
    summary: ClassVar[str] = "the holding brake of AXIS stays closed: the motor cannot turn"
    axis: int

    def describe(self) -> str:
        return f"holding brake of axis {self.axis} stuck closed"


# --- the machine and the field ----------------------------------------
@_register
@dataclass(kw_only=True)
class SwitchStuck(Fault):
    kind: ClassVar[str] = "switch_stuck"
    depth: ClassVar[str] = "field"
    summary: ClassVar[str] = (
        "SWITCH (negative, positive, home) of AXIS reads VALUE whatever the position"
    )
    axis: int
    switch: str
    value: int = 1

    def describe(self) -> str:
        return f"{self.switch} switch of axis {self.axis} stuck {'on' if self.value else 'off'}"


@_register
@dataclass(kw_only=True)
class SwitchChatter(Fault):
    kind: ClassVar[str] = "switch_chatter"
    depth: ClassVar[str] = "field"
    summary: ClassVar[str] = (
        "SWITCH of AXIS toggles every PERIOD_CYCLES cycles (a bouncing contact)"
    )
    axis: int
    switch: str
    period_cycles: int = 2

    def describe(self) -> str:
        return (
            f"{self.switch} switch of axis {self.axis} chatters "
            f"(toggles every {self.period_cycles} cycles)"
        )


@_register
@dataclass(kw_only=True)
class EncoderLost(Fault):
    kind: ClassVar[str] = "encoder_lost"
    depth: ClassVar[str] = "field"
    once: ClassVar[bool] = True
    summary: ClassVar[str] = (
        "the encoder of AXIS loses COUNTS counts: 6064h jumps by -COUNTS and stays off until "
        "homed again; the drive's loop sees the error (60F4h) and closes it, or faults 8611h"
    )
    axis: int
    counts: int = 100

    def describe(self) -> str:
        return f"encoder of axis {self.axis} loses {self.counts} counts"


@_register
@dataclass(kw_only=True)
class EncoderNoise(Fault):
    kind: ClassVar[str] = "encoder_noise"
    depth: ClassVar[str] = "field"
    summary: ClassVar[str] = "the encoder of AXIS reads +/- COUNTS counts of noise"
    axis: int
    counts: int = 5

    def describe(self) -> str:
        return f"encoder of axis {self.axis} noisy by +/-{self.counts} counts"


@_register
@dataclass(kw_only=True)
class ProbeMissing(Fault):
    kind: ClassVar[str] = "probe_missing"
    depth: ClassVar[str] = "field"
    summary: ClassVar[str] = "the touch-probe inputs of AXIS never switch (a sensor unplugged)"
    axis: int

    def describe(self) -> str:
        return f"probe inputs of axis {self.axis} missing"


@_register
@dataclass(kw_only=True)
class IoStuck(Fault):
    kind: ClassVar[str] = "io_stuck"
    depth: ClassVar[str] = "field"
    summary: ClassVar[str] = "input BIT of IO slave SLAVE reads VALUE whatever the field does"
    slave: int
    bit: int
    value: int = 1

    def describe(self) -> str:
        return f"input bit {self.bit} of slave {self.slave} stuck {'on' if self.value else 'off'}"


# --- building one from plain values (TOML, the command line, recordings) -------------------
_ALIASES = {
    "drop": "drop_responses",
    "drop_answers": "drop_responses",
    "disconnect": "link_down",
    "link_loss": "link_down",
    "quick_stop_input": "quick_stop",
    "switch_chattering": "switch_chatter",
    "chatter": "switch_chatter",
    "mailbox_lost_answer": "mailbox_lost",
    "lost_answer": "mailbox_lost",
    "sdo_abort": "mailbox_abort",
    "latch_al_error": "al_error",
    "safeop": "retreat_safeop",
    "safe_torque_off": "sto",
    "brake_stuck": "brake",
    "encoder_counts_lost": "encoder_lost",
    "io_input_stuck": "io_stuck",
}
#: other names of the switches
_SWITCHES = {
    "neg": "negative",
    "negative_limit": "negative",
    "limit-": "negative",
    "pos": "positive",
    "positive_limit": "positive",
    "limit+": "positive",
    "home_switch": "home",
}


#: the integer values that are a yes or no (0 or 1): these alone take true/false, on/off
_FLAGS = frozenset({"value"})


def _int(name: str, v: Any) -> int:
    """The one check of an integer value from TOML, JSON, the command line or Python: an
    integer of any type (``numbers.Integral``: a NumPy one too), a float with no fraction, or
    text (decimal, 0x hex); true/false (on/off, yes/no) only for a yes-or-no value
    (:data:`_FLAGS`), never as an axis 1 or a slave 0.

    Floats and text are taken, unlike an integer argument of a GT function (a C ``short``
    or ``long`` of its prototype, :mod:`gtecat.gt.args`): a fault is a table of values that
    comes as TOML, JSON (a panel's or a recording's, where 1.0 is 1) or command-line text
    as often as from Python, and every source is checked alike."""
    flag = name in _FLAGS
    if isinstance(v, bool) or getattr(getattr(v, "dtype", None), "kind", "") == "b":
        if flag:
            return int(v)
    elif isinstance(v, numbers.Integral):
        return operator.index(v)
    elif isinstance(v, numbers.Real) and math.isfinite(v) and float(v).is_integer():
        return int(v)
    elif isinstance(v, str):
        try:
            return int(v.strip().replace("_", ""), 0)
        except ValueError:
            pass
        if flag and v.strip().lower() in ("on", "true", "yes"):
            return 1
        if flag and v.strip().lower() in ("off", "false", "no"):
            return 0
    raise FaultSpecError(f"{name} must be an integer, got {v!r}")


def _pair(name: str, v: Any) -> tuple[int, int]:
    if isinstance(v, str):
        v = [p for p in v.replace("..", ",").split(",") if p.strip()]
    if not isinstance(v, list | tuple) or len(v) != 2:
        raise FaultSpecError(f"{name} must be two integers [start, end], got {v!r}")
    a, b = _int(name, v[0]), _int(name, v[1])
    if not a < b:
        raise FaultSpecError(f"{name} [{a}, {b}]: start must be below end")
    return a, b


def _drive_code(v: Any) -> int:
    if isinstance(v, str) and v.strip().lower() in FAULT_KINDS:
        return int(FAULT_KINDS[v.strip().lower()])
    code = _int("code", v)
    lo, hi = _KIND_RANGES[("drive_fault", "code")]
    if not lo <= code <= hi:
        raise FaultSpecError(
            f"code {_shown('code', code)} is out of range 0x{lo:X}..0x{hi:X} "
            "(a 16-bit 603Fh error code, or a name: " + ", ".join(FAULT_KINDS) + ")"
        )
    return code


def _convert(cls: type[Fault], name: str, raw: Any) -> Any:
    f = {x.name: x for x in dataclasses.fields(cls)}[name]
    ann = str(f.type)
    if cls is DriveFault and name == "code":
        return _drive_code(raw)
    if "tuple" in ann:
        return None if raw is None else _pair(name, raw)
    if ann.startswith("int"):
        if raw is None and "None" in ann:
            return None
        return _int(name, raw)
    if ann.startswith("str"):
        if raw is None and "None" in ann:
            return None
        return str(raw)
    return raw


#: the range of every integer value, by field name: (lowest, highest, how it reads)
_I32 = 0x7FFFFFFF
RANGES: dict[str, tuple[int, int]] = {
    "slave": (0, 0xFFFF),
    "axis": (1, 0xFFFF),
    "after_slave": (-1, 0xFFFF),  # -1: before the first slave, the whole bus goes
    "count": (0, _I32),  # 0: until cleared
    "bytes": (1, 1500),  # at most a whole Ethernet payload
    "us": (0, 60_000_000),
    "period_cycles": (1, _I32),
    "bit": (0, 0xFFFF),
    "value": (0, 1),
    "offset": (-0xFFFF, 0xFFFF),  # the working counter is 16 bits
    "index": (0, 0xFFFF),
    "subindex": (0, 0xFF),
    "counts": (-_I32, _I32),
}
#: per-kind ranges where a field name means something else
_KIND_RANGES: dict[tuple[str, str], tuple[int, int]] = {
    ("mailbox_abort", "code"): (0, 0xFFFFFFFF),  # SDO abort code, 32 bits (ETG.1000.6)
    ("retreat_safeop", "code"): (0, 0xFFFF),  # AL status code, 16 bits
    ("al_error", "code"): (0, 0xFFFF),
    ("drive_fault", "code"): (1, 0xFFFF),  # 603Fh error code, 16 bits, 0: no error
    ("encoder_noise", "counts"): (0, _I32),
}
#: fields shown (and best read) in hex
HEX_FIELDS = frozenset({"code", "index"})


def field_range(kind: str, name: str) -> tuple[int, int] | None:
    """The accepted range of integer value ``name`` of ``kind`` (None: not an integer)."""
    return _KIND_RANGES.get((kind, name), RANGES.get(name))


def _shown(name: str, v: int, kind: str = "") -> str:
    if name in HEX_FIELDS:
        width = 8 if kind == "mailbox_abort" and name == "code" else 4
        return f"-0x{-v:X}" if v < 0 else f"0x{v:0{width}X}"
    return str(v)


def _in_range(kind: str, name: str, v: Any) -> None:
    rng = field_range(kind, name)
    if rng is None or v is None:
        return
    if isinstance(v, bool) or not isinstance(v, int):
        raise FaultSpecError(f"{kind}: {name} must be an integer, got {v!r}")
    lo, hi = rng
    if not lo <= v <= hi:
        raise FaultSpecError(
            f"{kind}: {name} {_shown(name, v, kind)} is out of range "
            f"{_shown(name, lo, kind)}..{_shown(name, hi, kind)}"
        )


def _check(fault: Fault) -> None:
    for f in dataclasses.fields(fault):
        v = getattr(fault, f.name)
        if f.name == "area" and v is not None:
            if not (isinstance(v, tuple) and len(v) == 2):
                raise FaultSpecError(f"{fault.kind}: area must be two integers [start, end]")
            for x in v:
                if isinstance(x, bool) or not isinstance(x, int) or not 0 <= x <= 0xFFFFFFFF:
                    raise FaultSpecError(
                        f"{fault.kind}: area {list(v)}: each end in range 0..4294967295"
                    )
            if not v[0] < v[1]:
                raise FaultSpecError(f"{fault.kind}: area {list(v)}: start must be below end")
            continue
        if f.name in ("switch", "step", "variant", "state", "command") and v is not None:
            if not isinstance(v, str):
                raise FaultSpecError(f"{fault.kind}: {f.name} must be text, got {v!r}")
            continue
        _in_range(fault.kind, f.name, v)
    if isinstance(fault, SwitchStuck | SwitchChatter) and fault.switch not in SWITCH_BITS:
        raise FaultSpecError(
            f"{fault.kind}: switch {fault.switch!r}: one of {', '.join(SWITCH_BITS)}"
        )
    if isinstance(fault, MailboxAbort) and fault.step not in MAILBOX_STEPS:
        raise FaultSpecError(
            f"mailbox_abort: step {fault.step!r}: one of {', '.join(MAILBOX_STEPS)}"
        )
    if isinstance(fault, MailboxProtocol) and fault.variant not in (
        "mailbox_error",
        "wrong_service",
        "short",
    ):
        raise FaultSpecError(
            f"mailbox_protocol: variant {fault.variant!r}: one of mailbox_error, wrong_service, "
            "short"
        )
    if isinstance(fault, AlError) and fault.state.upper() not in ("INIT", "PREOP", "SAFEOP"):
        raise FaultSpecError(f"al_error: state {fault.state!r}: one of INIT, PREOP, SAFEOP")
    if isinstance(fault, WkcOffset) and fault.command is not None:
        from gtecat.eni.ethercat import Command

        if fault.command.upper() not in Command.__members__:
            raise FaultSpecError(
                f"wkc_offset: command {fault.command!r}: one of " + ", ".join(Command.__members__)
            )


def fault_from_dict(values: dict[str, Any], where: str = "") -> Fault:
    """A fault from ``{"kind": ..., key: value}`` (extra keys raise); values may be text."""
    prefix = f"{where}: " if where else ""
    if values.get("kind") is None or not str(values.get("kind")).strip():
        raise FaultSpecError(
            f"{prefix}the fault kind is missing (kind=); the kinds are " + ", ".join(KINDS)
        )
    kind = str(values.get("kind", "")).strip().lower()
    kind = _ALIASES.get(kind, kind)
    cls = KINDS.get(kind)
    if cls is None:
        raise FaultSpecError(
            f"{prefix}unknown fault kind {values.get('kind')!r}; the kinds are " + ", ".join(KINDS)
        )
    names = {f.name: f for f in dataclasses.fields(cls)}
    kwargs: dict[str, Any] = {}
    for key, raw in values.items():
        if key == "kind":
            continue
        if key not in names:
            raise FaultSpecError(
                f"{prefix}{kind} has no {key!r}; it takes " + (", ".join(names) or "no values")
            )
        try:
            kwargs[key] = _convert(cls, key, raw)
        except FaultSpecError as e:
            raise FaultSpecError(f"{prefix}{kind}: {e}") from None
    missing = [
        n
        for n, f in names.items()
        if f.default is dataclasses.MISSING
        and f.default_factory is dataclasses.MISSING
        and n not in kwargs
    ]
    if missing:
        raise FaultSpecError(f"{prefix}{kind} needs {', '.join(missing)}")
    if isinstance(kwargs.get("switch"), str):
        sw = kwargs["switch"].strip().lower()
        kwargs["switch"] = _SWITCHES.get(sw, sw)
    try:
        return cls(**kwargs)
    except FaultSpecError as e:
        raise FaultSpecError(f"{prefix}{e}") from None


def kind_rows() -> list[dict[str, str]]:
    """One row per kind: name, depth, its values with defaults, what it does."""
    rows = []
    for name, cls in KINDS.items():
        params = []
        for f in dataclasses.fields(cls):
            if f.default is dataclasses.MISSING:
                params.append(f.name)
            else:
                d = f.default
                shown = "-" if d is None else _shown(f.name, d, name) if isinstance(d, int) else d
                params.append(f"{f.name}={shown}")
        rows.append(
            {"kind": name, "depth": cls.depth, "values": " ".join(params), "what": cls.summary}
        )
    return rows


__all__ = [
    "HEX_FIELDS",
    "HOMING_STAGES",
    "KINDS",
    "MAILBOX_STEPS",
    "RANGES",
    "SWITCH_BITS",
    "AlError",
    "Brake",
    "DriveFault",
    "DropResponses",
    "EncoderLost",
    "EncoderNoise",
    "Fault",
    "FaultSpecError",
    "FrameDelay",
    "FrameReplay",
    "FrameTruncate",
    "FrameWrongIndex",
    "IoStuck",
    "LinkDown",
    "MailboxAbort",
    "MailboxLost",
    "MailboxProtocol",
    "PowerCycle",
    "ProbeMissing",
    "QuickStopInput",
    "RetreatSafeop",
    "Sto",
    "SwitchChatter",
    "SwitchStuck",
    "WkcOffset",
    "fault_from_dict",
    "field_range",
    "kind_rows",
]
