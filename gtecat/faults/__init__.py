"""Break the machine on purpose: one fault vocabulary for the emulated bus and ``gtecat serve``.

Four ways in build the same objects (:mod:`.kinds`, :mod:`.triggers`):

* Python - :func:`inject` on the open controller (``GT_Open`` + ``GT_InitEcatComm`` first),
  :func:`clear`, :func:`listing`; the ``gtecat_faults`` pytest fixture is the same;
* the machine TOML - ``[[fault]]`` tables, armed each time the bus is brought up, before
  its InitCmds (:func:`specs_from_tables`);
* the command line on a running gtecat - ``gtecat fault inject|list|clear``;
* the panel, over the same inspection endpoint.

A fault is armed with a trigger (at once, ``at_ms``, ``after_ms``, ``after_cycles``,
``when_position = [axis, position]``, ``at_homing = [axis, stage]``, ``on_sdo = [slave,
index, n]``), may last ``duration_ms``, and may wait for another (``after = id``: a script's
step).  Starts and ends go to the master log.

Threads.  :func:`inject`, :func:`script`, :func:`clear` and :func:`listing` may be called
from any thread of the application (a watchdog, a test harness) while another one cycles
the controller (its GT calls, ``GTE_Wait``, the realtime clock's cycle thread): each holds
the controller's clock lock, as every GT call does (:func:`_between_cycles`), so what it
does falls whole between two cycles - every step of a script armed, every fault cleared -
and the next cycle is the first to act on it.  It is taken as a GT call of that thread
would be: after the call another thread has under way (a long ``GTE_Wait`` on the auto
clock included: its cycles are that call's), or the realtime cycle under way.  A fault armed
at once starts there; one with ``at_ms`` starts at that controller time whichever thread
armed it, provided it was armed before that time.  The cycles pay nothing for this: they
hold the lock already.
"""

from __future__ import annotations

import numbers
import operator
from collections.abc import Mapping
from contextlib import AbstractContextManager, nullcontext
from pathlib import Path
from typing import Any

from ..errors import CommandError, ParameterError
from .bus import EmulatedBus, FaultBus, WireBus
from .injector import Entry, Injector
from .kinds import KINDS, Fault, FaultSpecError, fault_from_dict, kind_rows
from .triggers import TRIGGER_KEYS, Trigger, _ms, describe_after, trigger_from_dict

_EXTRA_KEYS = ("duration_ms", "after", "name")


class FaultSpec:
    """One fault as the four ways in give it: the fault, its trigger, how long, after what."""

    __slots__ = ("after", "duration_ms", "fault", "name", "trigger", "where")

    def __init__(
        self,
        fault: Fault,
        trigger: Trigger,
        duration_ms: float | None = None,
        after: int | str | None = None,
        name: str = "",
        where: str = "",
    ) -> None:
        self.fault, self.trigger, self.duration_ms = fault, trigger, duration_ms
        self.after, self.name = after, name
        #: where it was written (a file and its table, a script's step): errors name it
        self.where = where

    def describe(self) -> str:
        if self.after is None:
            text = f"{self.fault.describe()}, {self.trigger.describe()}"
        else:
            text = (
                f"{self.fault.describe()}, {describe_after(self.trigger, _after_words(self.after))}"
            )
        if self.duration_ms is not None:
            text += f", for {self.duration_ms:g} ms"
        return text

    def as_dict(self) -> dict[str, Any]:
        d = {**self.fault.as_dict(), **self.trigger.as_dict()}
        if self.duration_ms is not None:
            d["duration_ms"] = self.duration_ms
        if self.after is not None:
            d["after"] = self.after
        if self.name:
            d["name"] = self.name
        return d


def _after_words(after: int | str) -> str:
    return f"fault {after}" if isinstance(after, int) else f"the fault named {after!r}"


def _tell(what: str, values: dict[str, Any]) -> None:
    from .injector import OBSERVERS

    for fn in list(OBSERVERS):
        fn(what, values)


def spec_from_dict(values: dict[str, Any], where: str = "") -> FaultSpec:
    """A ``[[fault]]`` table (or ``key=value`` pairs) as a :class:`FaultSpec`."""
    prefix = f"{where}: " if where else ""
    if not isinstance(values, Mapping):
        raise FaultSpecError(
            f"{prefix}a fault is a table of its values, such as "
            f"{{'kind': 'drive_fault', 'axis': 1}}; got {values!r}"
        )
    vals = dict(values)
    extra = {k: vals.pop(k) for k in _EXTRA_KEYS if k in vals}
    trig = {k: vals.pop(k) for k in TRIGGER_KEYS if k in vals}
    try:
        trigger = trigger_from_dict(trig)
    except FaultSpecError as e:
        raise FaultSpecError(f"{prefix}{e}") from None
    fault = fault_from_dict(vals, where)
    duration = extra.get("duration_ms")
    if duration is not None:
        try:
            duration = _ms("duration_ms", duration)
        except FaultSpecError as e:
            raise FaultSpecError(f"{prefix}{e}") from None
    after = extra.get("after")
    if isinstance(after, str) and after.strip().lstrip("-").isdecimal():
        after = int(after)
    if isinstance(after, float) and after.is_integer():
        after = int(after)
    if isinstance(after, numbers.Integral) and not isinstance(after, bool):
        after = operator.index(after)  # (a NumPy integer, as _int takes one)
    if after is not None and (
        isinstance(after, bool)
        or not isinstance(after, int | str)
        or (isinstance(after, int) and after < 1)
        or (isinstance(after, str) and not after.strip())
    ):
        raise FaultSpecError(
            f"{prefix}after must be a fault's id (1 or more) or the name of a fault before it, "
            f"got {after!r}"
        )
    name = extra.get("name", "")
    if not isinstance(name, str) or ("name" in extra and not name.strip()):
        raise FaultSpecError(
            f"{prefix}name must be text that names the fault (for another's after=), got {name!r}"
        )
    return FaultSpec(fault, trigger, duration, after, name, where)


def specs_from_tables(tables: Any, source: str = "") -> list[FaultSpec]:
    if isinstance(tables, dict):
        tables = [tables]
    if not isinstance(tables, list):
        raise FaultSpecError(f"{source}: [[fault]] tables expected")
    return [
        spec_from_dict(t, f"{source} [[fault]] #{i}" if source else f"[[fault]] #{i}")
        for i, t in enumerate(tables, 1)
    ]


def load(path: str | Path) -> list[FaultSpec]:
    """The ``[[fault]]`` tables of a TOML file (a machine description or a faults file)."""
    import tomllib  # (read here: a replay or a recording without such a file never needs it)

    p = Path(path)
    try:
        data = tomllib.loads(p.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise FaultSpecError(f"{p}: no such file") from None
    except (OSError, UnicodeDecodeError) as e:
        raise FaultSpecError(f"{p}: cannot be read: {e}") from None
    except tomllib.TOMLDecodeError as e:
        raise FaultSpecError(f"{p}: not valid TOML: {e}") from None
    if "fault" not in data:
        raise FaultSpecError(f"{p}: no [[fault]] table")
    from ..drives.machine import TABLES, MachineError, refuse_unknown

    try:  # (a machine description's other tables may be there: a file for both)
        refuse_unknown(data, TABLES, str(p), "table(s)", "it takes [[fault]] tables")
    except MachineError as e:
        raise FaultSpecError(str(e)) from None
    return specs_from_tables(data["fault"], str(p))


def arm(injector: Injector, specs: list[FaultSpec], origin: str = "") -> list[Entry]:
    """Add the specs to an injector, a script's ``after`` names resolved to ids.

    A name names one fault: two specs of one call (the tables of one file) with the same
    name are refused, and so is an injected fault named as one armed already.  A machine
    description's tables (``origin="machine"``, armed anew by every bring-up) are checked
    among themselves only, and their names stay theirs for the session: an injected fault
    named as one of them is refused even once that one has ended, as the next
    ``GT_InitEcatComm`` arms it again (two live faults of one name would follow, and an
    ``after`` naming it would bind to one of them)."""
    names: dict[str, int] = {e.name: e.id for e in injector.entries if e.name}
    machine = origin == "machine"
    taken: set[str] = set() if machine else set(names)
    for s in specs:
        prefix = f"{s.where}: " if s.where else ""
        if s.name and s.name in taken:
            raise FaultSpecError(
                f"{prefix}name {s.name!r} names another fault already; give each its own"
            )
        if s.name and not machine and s.name in injector.machine_names:
            raise FaultSpecError(
                f"{prefix}name {s.name!r} belongs to a [[fault]] table of the machine "
                "description (armed again by every GT_InitEcatComm); give this fault another"
            )
        if s.name:
            taken.add(s.name)
    out = []
    for s in specs:
        after = s.after
        if isinstance(after, str):
            if after not in names:
                prefix = f"{s.where}: " if s.where else ""
                raise FaultSpecError(f"{prefix}after={after!r}: no fault named so before it")
            after = names[after]
        try:
            e = injector.add(s.fault, s.trigger, s.duration_ms, after=after, name=s.name)
        except ParameterError as err:  # a slave, an axis, a fault the bus does not have
            if not s.where:
                raise
            raise ParameterError(f"{s.where}: {err}") from None
        e.origin = origin
        if s.name:
            names[s.name] = e.id
            if machine:
                injector.machine_names.add(s.name)
        out.append(e)
    return out


# --- the controller's injector ----------------------------------------------------------------
def injector_for(ctl: Any, create: bool = True) -> Injector | None:
    """The injector of ``ctl``'s bus (made on first use; one per GT_InitEcatComm); a
    ``gtecat serve`` (:class:`gtecat.inspect.serve.ServeHost`) keeps its own."""
    own = getattr(ctl, "fault_injector", None)
    if own is not None:
        return own(create)
    backend = ctl.backend
    if backend is None or ctl.master is None or not ctl.master.opened:
        if not create:
            return None
        raise ParameterError("the bus is not up: GT_InitEcatComm first, then inject faults")
    inj = getattr(backend, "injector", None)
    if inj is None and create:
        inj = Injector(EmulatedBus(ctl))
        prev = getattr(ctl, "_fault_injector", None)
        if prev is not None:
            inj._next = prev._next  # (ids are never used twice in one session)
        backend.injector = inj
        ctl._fault_injector = inj
        ctl.pre_cycle.append(inj.tick)
    return inj


def _carry_over(ctl: Any, holding: bool = False) -> None:
    """The bus is brought up again: the faults injected on the bus before stay
    (:meth:`Injector.carry`); the machine description's tables are armed anew."""
    old = getattr(ctl, "_fault_injector", None)
    if old is None or getattr(old.bus, "backend", None) is ctl.backend:
        return
    if not any(e.state in ("armed", "active") and e.origin != "machine" for e in old.entries):
        return
    inj = injector_for(ctl)
    assert inj is not None
    inj.holding = holding
    inj.carry(old)


def _bus_opening(ctl: Any) -> None:
    """Arm the machine description's ``[[fault]]`` tables on every bus before it is brought
    up (its slaves found, the state walk with the ENI's InitCmds to come): the machine is
    faulty from the start, so the bring-up meets them as the application's own calls do (an
    ``on_sdo`` trigger counts the InitCmds' SDOs, a mailbox fault can fail the bring-up).
    Any other fault that starts at once waits until the bus is up (:func:`_bus_up`), where
    it started before: the bring-up has no cycles for it.  The faults of a bus brought up
    before go with it.  Errors: :func:`_arm_machine`."""
    _carry_over(ctl, holding=True)
    _arm_machine(ctl, holding=True)
    ctl._faults_armed = ctl.backend


def _bus_up(ctl: Any) -> None:
    """The bus is up: the axis bank, made after the bring-up, learns which axes the armed
    faults watch; a bus that came up without :func:`_bus_opening` (a card's amplifiers) has
    its faults armed now."""
    if getattr(ctl, "_faults_armed", None) is not ctl.backend:
        _carry_over(ctl)
        _arm_machine(ctl)
        return
    inj = injector_for(ctl, create=False)
    if inj is not None:
        inj.bus_ready()


def _arm_machine(ctl: Any, holding: bool = False) -> None:
    """Arm the machine description's ``[[fault]]`` tables on ``ctl``'s bus (``holding``:
    before it is brought up, :attr:`Injector.holding`).

    Every error in them - a value out of range, an unknown kind, a slave or an axis the bus
    does not have (``link_down after_slave=5`` on a bus of three slaves), an ``after`` that
    names nothing - is one :class:`~gtecat.errors.CommandError`, so ``GT_InitEcatComm``
    returns 1 for each alike.  Decided from the manual's return codes (table 3-1): 7 is
    "a parameter of this call is wrong", and the call's own parameters are right; 1 is "the
    command could not be carried out", which is what a bus that cannot be brought up as its
    description says is.  GTE_GetLastError gives the one line naming the file and table."""
    for hooks in (ctl.pre_cycle, ctl.before_bank):  # (the tick, the look: Injector)
        hooks[:] = [
            f
            for f in hooks
            if not (
                isinstance(getattr(f, "__self__", None), Injector)
                and getattr(f.__self__.bus, "backend", None) is not ctl.backend
            )
        ]
    tables = getattr(ctl.machine, "faults", ())
    if tables and ctl.options.backend == "emulated":
        source = ctl.machine.source or "machine description"
        try:
            specs = specs_from_tables(list(tables), source)
            inj = injector_for(ctl)
            assert inj is not None
            inj.holding = holding
            arm(inj, specs, origin="machine")
        except (FaultSpecError, ParameterError) as e:
            raise CommandError(str(e)) from None


def _between_cycles(ctl: Any) -> AbstractContextManager[Any]:
    """``ctl``'s clock lock (module docstring "Threads"): held, no cycle runs and no other
    thread's GT call is under way, so a fault added or ended is seen whole by the next cycle.
    A ``gtecat serve`` has none: its faults change between two frames, in its own loop."""
    lock = getattr(getattr(ctl, "clock", None), "lock", None)
    return nullcontext() if lock is None else lock


def _controller(core: int = 1) -> Any:
    from ..gt._core import SESSION

    return SESSION.controller(core)


def inject(
    kind: str | Fault | FaultSpec,
    *,
    core: int = 1,
    ctl: Any = None,
    **values: Any,
) -> int:
    """Inject a fault on the open controller's emulated bus; its id.

    ``inject("drive_fault", axis=1, code=0x2310)``, ``inject("link_down", after_slave=1,
    at_ms=500, duration_ms=200)``, ``inject(DriveFault(axis=2), after_cycles=100)``.
    Trigger keys (``at_ms``, ``after_ms``, ``after_cycles``, ``when_position``,
    ``at_homing``, ``on_sdo``), ``duration_ms`` and ``after`` (an id) mix with the kind's
    own values.  ``name`` names one fault (:func:`arm`: not one armed already, nor a
    machine description's table's).  Raises :class:`FaultSpecError` / ParameterError for
    what cannot be."""
    ctl = ctl or _controller(core)
    if isinstance(kind, FaultSpec):
        spec = kind
    elif isinstance(kind, Fault):
        spec = spec_from_dict({**kind.as_dict(), **values})
    else:
        spec = spec_from_dict({"kind": kind, **values})
    with _between_cycles(ctl):
        inj = injector_for(ctl)
        assert inj is not None
        fid = arm(inj, [spec])[0].id
        _tell("inject", spec.as_dict())
    return fid


def script(steps: list[dict[str, Any]], *, core: int = 1, ctl: Any = None) -> list[int]:
    """Steps run in order: each is armed once the one before it has started (its trigger
    then counts from there: ``after_ms``, ``after_cycles``); the ids."""
    if not isinstance(steps, list | tuple):
        raise FaultSpecError(
            "a script is a list of steps, each a table of a fault's values, such as "
            f"[{{'kind': 'link_down', 'after_slave': 0}}, {{'kind': 'sto', 'axis': 1}}]; "
            f"got {steps!r}"
        )
    specs = [spec_from_dict(step, f"step {i}") for i, step in enumerate(steps, 1)]
    ctl = ctl or _controller(core)
    ids: list[int] = []
    with _between_cycles(ctl):  # (every step armed before the next cycle: one change)
        inj = injector_for(ctl)
        assert inj is not None
        for spec in specs:
            if ids and spec.after is None:
                spec.after = ids[-1]
            ids.append(arm(inj, [spec])[0].id)
            _tell("inject", spec.as_dict())
    return ids


def clear(ident: int | None = None, *, core: int = 1, ctl: Any = None) -> int:
    """End one fault (its id) or every fault; how many."""
    ctl = ctl or _controller(core)
    with _between_cycles(ctl):
        inj = injector_for(ctl, create=False)
        if inj is None:
            if ident is not None:
                raise ParameterError(f"no fault {ident}: none was injected")
            return 0
        n = inj.clear(ident)
        _tell("clear", {"id": ident})
    return n


def listing(*, core: int = 1, ctl: Any = None) -> list[dict[str, Any]]:
    """The armed and active faults: id, kind, values, trigger, state and ``describe``."""
    ctl = ctl or _controller(core)
    with _between_cycles(ctl):  # (as one moment of the faults: no cycle halfway through)
        inj = injector_for(ctl, create=False)
        return [] if inj is None else inj.listing()


def describe(values: dict[str, Any]) -> str:
    """A ``[[fault]]`` table in words."""
    return spec_from_dict(values).describe()


def _install() -> None:
    from ..controller.core import Controller

    if _bus_up not in Controller.bus_up_hooks:
        Controller.bus_up_hooks.append(_bus_up)
    if _bus_opening not in Controller.bus_opening_hooks:
        Controller.bus_opening_hooks.append(_bus_opening)


_install()

__all__ = [
    "KINDS",
    "EmulatedBus",
    "Entry",
    "Fault",
    "FaultBus",
    "FaultSpec",
    "FaultSpecError",
    "Injector",
    "WireBus",
    "arm",
    "clear",
    "describe",
    "inject",
    "injector_for",
    "kind_rows",
    "listing",
    "load",
    "script",
    "spec_from_dict",
    "specs_from_tables",
]


def _record_from_environment() -> None:
    """``GTECAT_RECORD=FILE`` (set by ``gtecat record`` for a program it starts): record this
    process's GT calls into FILE, written when the process ends (SIGTERM and SIGHUP included)."""
    import atexit
    import os

    path = os.environ.get("GTECAT_RECORD")
    if not path:
        return
    from .record import Recorder, end_on_signals

    program = os.environ.get("GTECAT_RECORD_PROGRAM", "")
    rec = Recorder(path, {"program": program}, any_thread=True).start()
    atexit.register(rec.write)
    end_on_signals()  # SIGTERM from a time-out: the recording is still written


_record_from_environment()
