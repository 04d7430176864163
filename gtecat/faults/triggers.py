"""When a fault happens: in virtual time, after healthy cycles, on a milestone of the machine.

A trigger is asked once per cycle (:meth:`Trigger.due`) with the bus it watches
(:class:`gtecat.faults.bus.FaultBus`), except :class:`OnSdo`, which counts the mailbox
requests as they pass (:meth:`Trigger.sdo`), so the fault it arms meets the very request
that fired it.  One that watches the machine (:class:`WhenPosition`, :class:`AtHomingStage`)
is asked between cycles instead (``look``): what it sees there is what the next cycle's
``due`` would see, and the injector needs to know it before that cycle starts.

Every trigger has ``describe()`` in words and the plain-dict keys the
``[[fault]]`` tables use (``at_ms``, ``after_cycles``, ``when_position``, ``at_homing``,
``on_sdo``); no key: at once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from .kinds import HOMING_STAGES, FaultSpecError


@dataclass(kw_only=True)
class Trigger:
    def due(self, bus: Any) -> bool:
        return True

    def sdo(self, slave: int, index: int) -> bool:
        return False

    def quiet_cycles(self, bus: Any, n: int) -> int:
        """How many of the next ``n`` cycles :meth:`due` is surely False in, so the
        controller may run them at once (0: it must be asked in the next cycle)."""
        return 0

    def cycles_passed(self, bus: Any, k: int) -> None:
        """``k`` quiet cycles ran at once: count them as :meth:`due` would have."""

    def soon(self, bus: Any) -> bool:
        """Whether :meth:`due` may hold in the next cycle (True when it cannot tell)."""
        return True

    def describe(self) -> str:
        return "at once"

    def as_dict(self) -> dict[str, Any]:
        return {}


@dataclass(kw_only=True)
class Now(Trigger):
    pass


@dataclass(kw_only=True)
class AtTime(Trigger):
    """At controller time ``ms`` (what GT_GetClock reads; on ``gtecat serve``: since it began)."""

    ms: float

    def due(self, bus: Any) -> bool:
        return bus.now_ms() >= self.ms

    def quiet_cycles(self, bus: Any, n: int) -> int:
        if n > 0 and bus.now_ms(n - 1) < self.ms:  # not due in the last of them: in none
            return n
        return first_cycle(lambda k: bus.now_ms(k) >= self.ms, bus, self.ms - bus.now_ms(), n)

    def soon(self, bus: Any) -> bool:
        return bus.now_ms(1) >= self.ms

    def describe(self) -> str:
        return f"at {self.ms:g} ms"

    def as_dict(self) -> dict[str, Any]:
        return {"at_ms": self.ms}


@dataclass(kw_only=True)
class AfterTime(Trigger):
    """``ms`` of controller time after the fault was armed (a script's step: after the
    step before it started)."""

    ms: float
    since: float = 0.0

    def due(self, bus: Any) -> bool:
        return bus.t_ms() - self.since >= self.ms

    def quiet_cycles(self, bus: Any, n: int) -> int:
        if n > 0 and bus.t_ms(n - 1) - self.since < self.ms:  # not due in the last: in none
            return n
        return first_cycle(
            lambda k: bus.t_ms(k) - self.since >= self.ms,
            bus,
            self.ms - (bus.t_ms() - self.since),
            n,
        )

    def soon(self, bus: Any) -> bool:
        return bus.t_ms(1) - self.since >= self.ms

    def describe(self) -> str:
        return f"{self.ms:g} ms later"

    def as_dict(self) -> dict[str, Any]:
        return {"after_ms": self.ms}


@dataclass(kw_only=True)
class AfterCycles(Trigger):
    """After ``cycles`` healthy cycles (working counter as expected) from when it was armed."""

    cycles: int
    seen: int = 0

    def due(self, bus: Any) -> bool:
        if bus.healthy():
            self.seen += 1
        return self.seen >= self.cycles

    def quiet_cycles(self, bus: Any, n: int) -> int:
        if not bus.healthy():
            return n  # the cycles run at once are steady ones: none counts
        return max(0, min(n, self.cycles - self.seen - 1))

    def cycles_passed(self, bus: Any, k: int) -> None:
        if bus.healthy():
            self.seen += k

    def soon(self, bus: Any) -> bool:
        return self.seen + 1 >= self.cycles

    def describe(self) -> str:
        return f"after {self.cycles} healthy cycles"

    def as_dict(self) -> dict[str, Any]:
        return {"after_cycles": self.cycles}


@dataclass(kw_only=True)
class WhenPosition(Trigger):
    """When the mechanics of ``axis`` reach or pass ``position`` (drive counts, either way)."""

    axis: int
    position: float
    _side: int | None = None
    #: the position :meth:`look` last saw
    _seen: float = math.nan

    def due(self, bus: Any) -> bool:
        return self._due(bus.position(self.axis))

    def look(self, bus: Any) -> bool:
        """:meth:`due` asked between two cycles, of the drive's state wherever it is kept
        (the axis bank's row: the axis stays on the bank), so the injector knows before
        the next cycle whether its tick may fire (:meth:`Injector.look`)."""
        self._seen = pos = bus.position_now(self.axis)
        return self._due(pos)

    def cycles_short(self, bus: Any, n: int) -> int:
        """How many of the next ``n`` cycles may run at once after a :meth:`look` that saw
        nothing (at least 1): the mechanics move at most their top speed per cycle
        (:meth:`FaultBus.max_step`), so every cycle of the run but its last ends short of
        the position (the position after the last one is looked at after the run)."""
        step = bus.max_step(self.axis)
        d = abs(self._seen - self.position)
        if not step > 0.0:
            return n if step == 0.0 and d > 0.0 else 1
        m = math.ceil(d / step) - 1  # cycle ends surely short of it: m * step < d
        return max(1, min(n, m + 1))

    def _due(self, pos: float) -> bool:
        side = (pos > self.position) - (pos < self.position)
        if side == 0:
            return True
        if self._side is None:
            self._side = side
            return False
        return side != self._side

    def describe(self) -> str:
        return f"when axis {self.axis} passes {self.position:g}"

    def as_dict(self) -> dict[str, Any]:
        return {"when_position": [self.axis, self.position]}


@dataclass(kw_only=True)
class AtHomingStage(Trigger):
    """When the homing of ``axis`` reaches ``stage`` (search, approach, index, return, ...)."""

    axis: int
    stage: str

    def due(self, bus: Any) -> bool:
        return bus.homing_stage(self.axis) == self.stage

    def look(self, bus: Any) -> bool:
        """:meth:`due` between two cycles, of the drive wherever it runs (a row of the axis
        bank keeps its homing's stage: it leaves the bank before anything could change it)."""
        return bus.homing_stage_now(self.axis) == self.stage

    def cycles_short(self, bus: Any, n: int) -> int:
        """How many of the next ``n`` cycles may run at once after a :meth:`look` that saw
        nothing: all of them while the axis bank runs the drive (a banked homing leaves the
        bank before any cycle that could change its stage, and that cycle is not one of a
        run at once; a drive in another mode starts no homing without a call), else 1."""
        return n if bus.banked(self.axis) else 1

    def describe(self) -> str:
        return f"when the homing of axis {self.axis} reaches its {self.stage} stage"

    def as_dict(self) -> dict[str, Any]:
        return {"at_homing": [self.axis, self.stage]}


@dataclass(kw_only=True)
class OnSdo(Trigger):
    """On the ``n``-th SDO request to object ``index`` of ``slave`` (counted from arming)."""

    slave: int
    index: int
    n: int = 1
    seen: int = 0

    def due(self, bus: Any) -> bool:
        return False

    def quiet_cycles(self, bus: Any, n: int) -> int:
        return n  # it counts mailbox requests, never cycles

    def soon(self, bus: Any) -> bool:
        return False  # it fires in a mailbox request, between cycles

    def sdo(self, slave: int, index: int) -> bool:
        if slave == self.slave and index == self.index:
            self.seen += 1
        return self.seen >= self.n

    def describe(self) -> str:
        nth = {1: "1st", 2: "2nd", 3: "3rd"}.get(self.n, f"{self.n}th")
        return f"on the {nth} SDO to 0x{self.index:04X} of slave {self.slave}"

    def as_dict(self) -> dict[str, Any]:
        return {"on_sdo": [self.slave, self.index, self.n]}


def first_cycle(due: Any, bus: Any, left_ms: float, n: int) -> int:
    """The first of the next ``n`` cycles (0: the coming one) in which ``due(k)`` holds,
    ``n`` when none: guessed from the time left, then settled with ``due`` itself, so the
    very comparison the per-cycle check makes decides (``due`` grows with ``k``)."""
    step = bus.cycle_ns / 1e6
    k = 0 if left_ms <= 0 else min(n, max(0, int(left_ms / step)))
    while k > 0 and due(k - 1):
        k -= 1
    while k < n and not due(k):
        k += 1
    return k


def describe_after(trigger: Trigger, after: str) -> str:
    """The trigger in words for a script's step that waits for ``after`` (e.g. "fault 1"):
    its time and cycles count from when that one started, so it says so first."""
    if isinstance(trigger, Now):
        return f"once {after} has started"
    return f"once {after} has started, {trigger.describe()}"


TRIGGER_KEYS = ("at_ms", "after_ms", "after_cycles", "when_position", "at_homing", "on_sdo")


def _num(name: str, v: Any) -> float:
    if isinstance(v, bool):
        raise FaultSpecError(f"{name} must be a number, got {v!r}")
    if isinstance(v, int | float):
        out = float(v)
    else:
        try:
            text = str(v).strip().replace("_", "")
            out = float(int(text, 0)) if text.lower().lstrip("-").startswith("0x") else float(text)
        except (TypeError, ValueError, OverflowError):
            raise FaultSpecError(f"{name} must be a number, got {v!r}") from None
    if not math.isfinite(out):
        raise FaultSpecError(f"{name} must be a finite number, got {v!r}")
    return out


def _whole(name: str, v: Any, lo: int, hi: int) -> int:
    """An integer value in ``lo..hi`` (hex text allowed) or a one-line error naming it."""
    x = _num(name, v)
    if not x.is_integer():
        raise FaultSpecError(f"{name} must be a whole number, got {v!r}")
    n = int(x)
    if not lo <= n <= hi:
        shown = (lambda k: f"0x{k:X}") if name.endswith("index") else str
        raise FaultSpecError(
            f"{name} {shown(n) if n >= 0 else n} is out of range {shown(lo)}..{shown(hi)}"
        )
    return n


def _list(name: str, v: Any, n: tuple[int, ...], what: str) -> list[Any]:
    if isinstance(v, str):
        v = [p.strip() for p in v.split(",")]
    if not isinstance(v, list | tuple) or len(v) not in n:
        want = " or ".join(str(k) for k in n)
        raise FaultSpecError(f"{name} needs {want} values [{what}], got {v!r}")
    return list(v)


#: the highest controller time (ms) a trigger may name: about 24 days, the GT clock's range
MAX_MS = float(0x7FFFFFFF)
_MAX_AXIS = 0xFFFF
_MAX_SLAVE = 0xFFFF
_MAX_COUNT = 0x7FFFFFFF


def _ms(name: str, v: Any) -> float:
    ms = _num(name, v)
    if not 0 <= ms <= MAX_MS:
        raise FaultSpecError(f"{name} {ms:g} is out of range 0..{MAX_MS:.0f}")
    return ms


def trigger_from_dict(values: dict[str, Any]) -> Trigger:
    """The trigger the keys of :data:`TRIGGER_KEYS` in ``values`` give (at most one).

    Every value is range-checked (times 0..MAX_MS ms, axes 1..65535, slaves 0..65535,
    indexes 0..0xFFFF, counts as below) and a wrong one raises :class:`FaultSpecError`
    with one line naming the key and its range."""
    given = [k for k in TRIGGER_KEYS if k in values]
    if len(given) > 1:
        raise FaultSpecError(f"one trigger per fault, got {', '.join(given)}")
    if not given:
        return Now()
    key = given[0]
    v = values[key]
    if key == "at_ms":
        return AtTime(ms=_ms(key, v))
    if key == "after_ms":
        return AfterTime(ms=_ms(key, v))
    if key == "after_cycles":
        return AfterCycles(cycles=_whole(key, v, 0, _MAX_COUNT))
    if key == "when_position":
        axis, pos = _list(key, v, (2,), "AXIS, POSITION")
        return WhenPosition(
            axis=_whole("when_position: axis", axis, 1, _MAX_AXIS),
            position=_num("when_position: position", pos),
        )
    if key == "at_homing":
        axis, stage = _list(key, v, (2,), "AXIS, STAGE")
        stage = str(stage).strip().lower()
        if stage not in HOMING_STAGES:
            raise FaultSpecError(f"at_homing: stage {stage!r}: one of {', '.join(HOMING_STAGES)}")
        return AtHomingStage(axis=_whole("at_homing: axis", axis, 1, _MAX_AXIS), stage=stage)
    slave, index, n = _list(key, v, (3,), "SLAVE, INDEX, N")
    return OnSdo(
        slave=_whole("on_sdo: slave", slave, 0, _MAX_SLAVE),
        index=_whole("on_sdo: index", index, 0, 0xFFFF),
        n=_whole("on_sdo: n", n, 1, _MAX_COUNT),
    )


__all__ = [
    "TRIGGER_KEYS",
    "AfterCycles",
    "AfterTime",
    "AtHomingStage",
    "AtTime",
    "Now",
    "OnSdo",
    "Trigger",
    "WhenPosition",
    "describe_after",
    "trigger_from_dict",
]
