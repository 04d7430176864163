"""The injector: the faults of one bus, armed, active and spent, run once per cycle.

:class:`Injector` holds entries (a fault, its trigger, how long it lasts); :meth:`tick`
runs once per cycle before the exchange (the controller's ``pre_cycle``; after each step
on ``gtecat serve``): triggers that are due start their fault, faults whose time is up
end, chattering switches toggle, stuck IO inputs are held.  Mailbox requests pass
:meth:`mailbox` (a stand-in in front of every slave's mailbox), cyclic answers
:meth:`answer` (emulated) or :meth:`frame` (wire).  Every start and end is written to the
master log (``fault 3 started: ...``) and kept in :attr:`events` (recordings read them).

A stuck IO input (``io_stuck``) holds the input bit at its value over what the field puts
there (``IoSlave.hold_input_bit``: laid over the field inputs on their way to the process
data, after the wires); when the fault ends (its ``duration_ms`` over, or cleared) the input
is let go: it reads what the field puts there *now* - the value it had before the fault,
unless something set it meanwhile (the slave's ``set_input_bit`` / ``set_input``, the
``gtecat`` field verbs, a wire from an output, a write of its ``field_inputs``), which the
field inputs underneath kept.  Of several faults on one bit the one added last holds it; the
bit is let go when the last of them ends.
"""

from __future__ import annotations

import struct
import time
from dataclasses import dataclass, field
from typing import Any

from gtecat.drives.coe import (
    CoeService,
    MailboxError,
    build_coe,
    mailbox_error,
    parse_mailbox,
)
from gtecat.drives.faults import ErrorCode
from gtecat.drives.io_slaves import IoSlave
from gtecat.drives.slave import AlState

from ..controller.epoch import changed as readers_changed
from ..errors import ParameterError
from ..master.backends.emulated import ANSWERED, LOST, PREVIOUS
from . import kinds as k
from .bus import FaultBus
from .triggers import (
    AfterTime,
    AtHomingStage,
    AtTime,
    Now,
    OnSdo,
    Trigger,
    WhenPosition,
    describe_after,
    first_cycle,
)

_LOGICAL = frozenset({"LRW", "LRD", "LWR"})
_STATES = {"INIT": AlState.INIT, "PREOP": AlState.PREOP, "SAFEOP": AlState.SAFEOP}
#: active faults that act in every cycle (no cycles at once while one is on); a stuck IO
#: input is not one: the slave holds it (IoSlave.hold_input_bit) from its start to its end
_EVERY_CYCLE = (k.SwitchChatter,)
#: a count of quiet cycles far beyond any run of cycles at once
_FAR = 1 << 40


def _by_time(e: Entry) -> bool:
    """An entry whose next change depends on the time alone: armed on a time (or on an SDO,
    which is no cycle's), or active with no cycle of its own to act in."""
    if e.after is not None:
        return False
    if e.state == "armed":
        return isinstance(e.trigger, AtTime | AfterTime | OnSdo)
    return e.state == "active" and not isinstance(e.fault, _EVERY_CYCLE)


#: called with ("inject", values) / ("clear", {"id": N}) for every fault a program or an
#: operator adds or ends (recordings keep them in the stream)
OBSERVERS: list[Any] = []


@dataclass(eq=False)
class Entry:
    id: int
    fault: k.Fault
    trigger: Trigger
    duration_ms: float | None = None
    state: str = "armed"  # armed | active | ended
    started_ms: float | None = None
    left: int = 0  # answers / requests still to hit (count kinds), 0 = no limit
    data: dict[str, Any] = field(default_factory=dict)
    #: a step of a script: armed only once the fault with this id has started
    after: int | None = None
    name: str = ""
    #: "machine" for a ``[[fault]]`` table of the machine description (armed again by every
    #: bring-up), "" for one injected (Python, the command line, the panel, a fixture)
    origin: str = ""

    def describe(self) -> str:
        if self.after is None:
            text = f"{self.fault.describe()}, {self.trigger.describe()}"
        else:
            text = f"{self.fault.describe()}, {describe_after(self.trigger, f'fault {self.after}')}"
        if self.duration_ms is not None:
            text += f", for {self.duration_ms:g} ms"
        return text

    def as_dict(self) -> dict[str, Any]:
        d = {"id": self.id, **self.fault.as_dict(), **self.trigger.as_dict()}
        if self.duration_ms is not None:
            d["duration_ms"] = self.duration_ms
        d["state"] = self.state
        d["describe"] = self.describe()
        return d


class Injector:
    """The faults of one bus (module docstring)."""

    #: the controller's pre_cycle protocol: the axis bank may run while faults are armed
    #: (the axes a fault is about to meet are kept off it: :meth:`_refresh`)
    bank_safe = True

    def __init__(self, bus: FaultBus) -> None:
        self.bus = bus
        self.entries: list[Entry] = []
        #: the names of the machine description's ``[[fault]]`` tables: theirs for good, as
        #: every bring-up arms the tables again (:func:`gtecat.faults.arm`)
        self.machine_names: set[str] = set()
        self._next = 1
        #: (time ms, "start" | "end", entry id, description): what happened, in order
        self.events: list[tuple[float, str, int, str]] = []
        self._frame_on = False
        self._mailboxes: dict[int, Any] = {}
        self._al_guards: dict[int, Any] = {}
        self._chatter_cycle = 0
        self._last_answer: bytes | None = None
        self._lbase: int | None = None
        self._started: set[int] = set()
        self._watched: frozenset[int] = frozenset()
        #: :meth:`look` runs before every cycle (an armed trigger watches the machine)
        self._looking = False
        #: the bus is being brought up (a machine description's faults, armed before it):
        #: a fault that starts at once waits for the bus unless the bring-up can meet it (a
        #: mailbox fault: the InitCmds are SDOs); :meth:`bus_ready` starts it then
        self.holding = False
        #: counts every change of the entries; with the first cycle in which anything may
        #: happen, as :meth:`quiet_cycles` last found it: (version, the bus's cycle mark,
        #: that cycle's count)
        self._version = 0
        self._memo: tuple[int, ...] | None = None
        self._wrap_mailboxes()

    # --- adding and clearing ----------------------------------------
    def add(
        self,
        fault: k.Fault,
        trigger: Trigger | None = None,
        duration_ms: float | None = None,
        *,
        after: int | None = None,
        name: str = "",
    ) -> Entry:
        self.bus.settle()  # (what it counted so far; the quick cycles armed: disarmed)
        self._check_target(fault)
        if trigger is not None:
            self._check_trigger(trigger)
        if (
            after is not None
            and after not in self._started
            and not any(e.id == after for e in self.entries)
        ):
            raise ParameterError(f"after={after}: no such fault")
        e = Entry(self._next, fault, trigger or Now(), duration_ms, after=after, name=name)
        self._next += 1
        trig = e.trigger
        if hasattr(trig, "since"):
            trig.since = self.bus.t_ms()  # type: ignore[attr-defined]
        self.entries.append(e)
        self.bus.log(f"Fault {e.id} armed: {e.describe()}.")
        self.look()  # (before the refresh: it keeps the fault's axes on the bank)
        self._refresh()
        if isinstance(trig, Now) and self._gate_open(e) and not self._held(e):
            self._start(e)
        return e

    def _held(self, e: Entry) -> bool:
        return self.holding and e.fault.depth != "mailbox"

    def carry(self, old: Injector) -> None:
        """The bus was brought up again (``GT_InitEcatComm`` once more): the injected faults
        of the bus before it stay, as they were - a re-initialisation repairs nothing.  An
        active one acts on the new bus too (its duration and the answers it still has to hit
        go on from where they were), an armed one keeps its trigger (a time, a count of
        cycles, of SDOs: all counted on); what started once and is over (a power cycle) is
        gone, and a machine description's tables are armed anew by the bring-up, not kept.
        Ids go on from the bus before, so an id names one fault for the whole session.  A
        fault on a slave or axis the new bus does not have (another ENI) is dropped, with a
        line in the master log.  Called before the bring-up (:attr:`holding`): a fault that
        was active starts as one armed at once would (:meth:`bus_ready`)."""
        old.bus.settle()
        self._next = max(self._next, old._next)
        kept_ids = set()
        for e in old.entries:
            if e.state not in ("armed", "active") or e.origin == "machine":
                continue
            why = ""
            try:
                self._check_target(e.fault)
                self._check_trigger(e.trigger)
            except ParameterError as err:
                why = str(err)
            if not why and e.after is not None and e.after not in old._started:
                if e.after not in kept_ids:
                    why = f"fault {e.after}, which it waits for, is gone"
            if why:
                self.bus.log(f"Fault {e.id} dropped with the bus brought up again: {why}.")
                continue
            n = Entry(e.id, e.fault, e.trigger, e.duration_ms, after=e.after, name=e.name)
            n.data = dict(e.data)
            if e.state == "active":
                n.data["resume"] = (e.started_ms, e.left)
            kept_ids.add(e.id)
            self.entries.append(n)
            self.bus.log(f"Fault {n.id} kept with the bus brought up again: {n.describe()}.")
        self._started |= old._started
        for n in self.entries:
            if "resume" in n.data and not self._held(n):
                self._resume(n)
        self._refresh()
        self.look()

    def _resume(self, e: Entry) -> None:
        """A fault active on the bus before a re-initialisation starts on the new one."""
        started, left = e.data.pop("resume")
        self._start(e)
        if e.state == "active":
            e.started_ms = started
            if left:
                e.left = left

    def clear(self, ident: int | None = None) -> int:
        """End one fault (by id) or all; the number ended."""
        self.bus.settle()
        n = 0
        for e in list(self.entries):
            if ident is not None and e.id != ident:
                continue
            if e.state == "active":
                self._end(e, "cleared")
            elif e.state == "armed":
                e.state = "ended"
                self.bus.log(f"Fault {e.id} disarmed: {e.describe()}.")
            n += 1
        if ident is not None and n == 0:
            raise ParameterError(f"no fault {ident} (gtecat fault list shows them)")
        self.entries = [e for e in self.entries if e.state != "ended"]
        self._refresh()
        return n

    def listing(self) -> list[dict[str, Any]]:
        return [e.as_dict() for e in self.entries]

    def _check_target(self, f: k.Fault) -> None:
        """Refuse a fault naming a slave or axis the bus does not have, when it is given."""
        if getattr(f, "axis", None) is not None:
            self.bus.channel(int(f.axis))  # type: ignore[attr-defined]
        if getattr(f, "slave", None) is not None:
            s = self.bus.slave(int(f.slave))  # type: ignore[attr-defined]
            if f.depth == "mailbox" and not s.has_mailbox:
                raise ParameterError(f"slave {s.position} ({s.name}) has no mailbox")
            if isinstance(f, k.IoStuck):
                if not isinstance(s, IoSlave):
                    raise ParameterError(f"slave {s.position} ({s.name}) is no IO slave")
                if not 0 <= f.bit < len(s.field_inputs) * 8:
                    raise ParameterError(f"slave {s.position}: no input bit {f.bit}")
        if isinstance(f, k.WkcOffset):
            size = self.bus.image_bytes() if f.area is not None else None
            if size is not None and f.area is not None and f.area[0] >= size:
                raise ParameterError(
                    f"wkc_offset: area [{f.area[0]}, {f.area[1]}) lies past the process "
                    f"image (logical bytes 0..{size - 1}), so it would never act"
                )
        if isinstance(f, k.LinkDown) and f.after_slave >= len(self.bus.slaves) - 1:
            raise ParameterError(
                f"link_down after slave {f.after_slave}: nothing follows it (the bus has "
                f"slaves 0..{len(self.bus.slaves) - 1})"
            )

    def _check_trigger(self, trig: Trigger) -> None:
        """Refuse a trigger watching a slave or axis the bus does not have (it would never
        fire), as :meth:`_check_target` does for the fault's own."""
        from .triggers import AtHomingStage, WhenPosition

        try:
            if isinstance(trig, WhenPosition | AtHomingStage):
                self.bus.channel(int(trig.axis))
            elif isinstance(trig, OnSdo):
                s = self.bus.slave(int(trig.slave))
                if not s.has_mailbox:
                    raise ParameterError(f"slave {s.position} ({s.name}) has no mailbox")
        except ParameterError as e:
            key = {WhenPosition: "when_position", AtHomingStage: "at_homing", OnSdo: "on_sdo"}
            raise ParameterError(f"{key[type(trig)]}: {e}") from None

    # --- the cycle ----------------------------------------
    def tick(self, _t_ns: int = 0, _dt_ns: int = 0, *, cycle: bool = True) -> None:
        """Once per cycle; ``cycle=False``: time alone passed (``gtecat serve`` between
        frames), so only time triggers and durations are looked at."""
        if not self.entries:
            return
        now = self.bus.t_ms()
        for e in self.entries:
            if e.state == "armed" and self._gate_open(e):
                if not cycle and not isinstance(e.trigger, AtTime | AfterTime):
                    continue
                if self._looks(e) and not e.data.get("hit", True):
                    continue  # (it saw nothing before this cycle: look)
                if e.trigger.due(self.bus):
                    self._start(e)
            elif e.state == "active" and e.duration_ms is not None:
                if now - (e.started_ms or 0.0) >= e.duration_ms:
                    self._end(e, "over")
        if not cycle:
            if any(e.state == "ended" for e in self.entries):
                self.entries = [e for e in self.entries if e.state != "ended"]
                self._refresh()
            return
        self._chatter_cycle += 1
        for e in self.entries:
            if e.state != "active":
                continue
            f = e.fault
            if isinstance(f, k.SwitchChatter):
                ff = self.bus.channel(f.axis).field
                if ff is not None:
                    bit = 1 << k.SWITCH_BITS[f.switch]
                    on = (self._chatter_cycle // f.period_cycles) % 2 == 0
                    ff.din_set = (ff.din_set | bit) if on else (ff.din_set & ~bit)
                    ff.din_clear = (ff.din_clear & ~bit) if on else (ff.din_clear | bit)
        if any(e.state == "ended" for e in self.entries):
            self.entries = [e for e in self.entries if e.state != "ended"]
        self._refresh()  # what the next cycle's triggers may change

    def quiet_cycles(self, n: int) -> int:
        """How many of the next ``n`` cycles :meth:`tick` surely does nothing in but count
        (the controller runs them at once, :meth:`Controller.run_cycles`): all of them
        without faults; up to the first trigger due or duration over; none while a
        chattering switch or a stuck IO input needs every cycle, or a trigger watches one.

        Asked before every run of cycles at once, so where every entry waits for a time
        alone (:func:`_by_time`) the first cycle anything may happen in is kept, by the bus's
        cycle count (:meth:`FaultBus.cycle_mark`), and the next asks count down to it: the
        same answer, as long as no entry changed (:attr:`_version`), no cycle ran outside
        the count and neither the cycle time nor the time GT_Reset counts from moved."""
        mark = self.bus.cycle_mark()
        memo = self._memo
        if mark is not None and memo is not None and memo[0] == self._version:
            _, ns0, c0, cyc0, reset0, until = memo
            ns, c, cyc, reset = mark
            if cyc == cyc0 and reset == reset0 and ns - ns0 == (c - c0) * cyc:
                return max(0, min(n, until - c))
        self._memo = None
        if mark is None or not all(map(_by_time, self.entries)):
            return self._quiet_cycles(n)
        far = self._quiet_cycles(_FAR)
        self._memo = (self._version, *mark, mark[1] + far)
        return max(0, min(n, far))

    def _quiet_cycles(self, n: int) -> int:
        if self._looking:
            self.look()
        for e in self.entries:
            if n <= 0:
                return 0
            if e.state == "armed":
                if self._looks(e):
                    # what it sees is known only after a cycle: none once it saw its fault
                    # due, else as many as surely change nothing it looks at (cycles_short)
                    if e.data.get("hit", True):
                        return 0
                    n = e.trigger.cycles_short(self.bus, n)  # type: ignore[attr-defined]
                    continue
                if e.after is not None:
                    if e.after not in self._started:
                        continue  # its gate opens only in a tick that starts another
                    if "armed_ms" not in e.data:
                        return 0  # the gate's first tick notes the time
                # the cycle before the trigger's runs on its own: its tick keeps the
                # fault's axes off the bank (_refresh)
                n = min(n, e.trigger.quiet_cycles(self.bus, n + 1) - 1)
            elif e.state == "active":
                f = e.fault
                if isinstance(f, _EVERY_CYCLE):
                    return 0
                if e.duration_ms is not None:
                    t0, d = e.started_ms or 0.0, e.duration_ms
                    if self.bus.t_ms(n - 1) - t0 < d:  # not over in the last of them: in none
                        continue
                    left = d - (self.bus.t_ms() - t0)
                    over = lambda j, t0=t0, d=d: self.bus.t_ms(j) - t0 >= d  # noqa: E731
                    n = min(n, first_cycle(over, self.bus, left, n))
            else:
                return 0  # an ended entry the next tick drops
        return max(0, n)

    def cycles_passed(self, n: int) -> None:
        """``n`` quiet cycles (:meth:`quiet_cycles`) ran at once: count them as :meth:`tick`
        would have."""
        if not self.entries:
            return
        self._chatter_cycle += n
        for e in self.entries:
            if e.state == "armed" and (e.after is None or e.after in self._started):
                e.trigger.cycles_passed(self.bus, n)

    def _looks(self, e: Entry) -> bool:
        """An armed entry whose trigger watches the machine and is asked between cycles
        (:meth:`look`), on a bus that has a hook before every cycle; a script's step waits
        for another and is asked in its tick."""
        return (
            e.state == "armed"
            and e.after is None
            and self.bus.between
            and isinstance(e.trigger, WhenPosition | AtHomingStage)
        )

    def look(self) -> None:
        """Between two cycles (before each: the emulated bus's ``before_bank`` hook, and
        :meth:`quiet_cycles` before every run at once; at arming): the triggers that watch
        the machine look at it (``look``: the axis bank's rows are read where they are), and
        what they see is what the next tick's ``due`` would see.  One that sees its fault
        due takes the watched axis and the fault's axes off the bank before that cycle
        (:meth:`_refresh`): its tick asks ``due`` as ever, and the fault meets them as on
        the scalar path.  Until then the watched axis stays on the bank, and so do the
        others."""
        changed = False
        for e in self.entries:
            if self._looks(e):
                hit = bool(e.trigger.look(self.bus))  # type: ignore[attr-defined]
                if hit != e.data.get("hit"):
                    e.data["hit"] = hit
                    changed = True
        if changed:
            self._refresh()

    def _gate_open(self, e: Entry) -> bool:
        if e.after is None:
            return True
        if e.after in self._started:
            if "armed_ms" not in e.data:
                e.data["armed_ms"] = self.bus.t_ms()
                if hasattr(e.trigger, "since"):
                    e.trigger.since = e.data["armed_ms"]  # type: ignore[attr-defined]
            return True
        return False

    def bus_ready(self) -> None:
        """The bus came up after these faults were armed (and the axis bank with it): the
        faults held while it was brought up start, as they would have been armed now, and
        the bank learns again which axes they watch and whether it may run at all."""
        self.bus.settle()
        if self.holding:
            self.holding = False
            for e in list(self.entries):
                if e.state != "armed":
                    continue
                if "resume" in e.data:
                    self._resume(e)  # active before a re-initialisation (carry)
                elif isinstance(e.trigger, Now) and self._gate_open(e):
                    self._start(e)
        self._watched = frozenset()
        if not self.bank_safe:
            self.bus.before_change()
        self._refresh()
        self.look()

    def _refresh(self) -> None:
        """Frame faults routed while one is active; the axes a fault may meet in the next
        cycle (all for a fault on the bus) kept off the axis bank, and the triggers that
        watch the machine looked at before every cycle (:meth:`look`)."""
        self._version += 1  # (called after every change of the entries)
        frame = any(
            e.state == "active" and e.fault.depth == "frame" and not isinstance(e.fault, k.LinkDown)
            for e in self.entries
        )
        if frame != self._frame_on:
            self._frame_on = frame
            self.bus.set_frame_faults(self if frame else None)
        # The axis bank runs its axes' whole cycle before this tick: an axis a fault is
        # about to change (its trigger may fire in the next cycle, or is watched every
        # cycle) is kept off the bank from now on, so the fault meets it in the very cycle
        # the trigger fires, as on the scalar path; a fault on the bus or a slave: all axes.
        # A trigger that watches the machine says whether it fires in the next cycle only
        # just before it (look): it keeps its fault's axes on the bank until then.
        held: set[int] = set()
        safe = True
        looking = False
        for e in self.entries:
            if e.state != "armed":
                continue
            trig = e.trigger
            if self._looks(e):
                looking = True
                if not e.data.get("hit", True):
                    continue
                held.add(trig.axis)  # (its tick asks due() of the scalar drive, as before)
            elif isinstance(trig, WhenPosition | AtHomingStage):
                held.add(trig.axis)
            elif e.after is None and not trig.soon(self.bus):
                continue
            axis = getattr(e.fault, "axis", None)
            if axis is not None:
                held.add(int(axis))
            elif e.fault.depth != "mailbox":
                safe = False
        if safe != self.bank_safe:
            self.bank_safe = safe
            if not safe:
                self.bus.before_change()
        watched = frozenset(held)
        if watched != self._watched:
            self._watched = watched
            self.bus.watch_axes(watched)  # the others stay on the bank
        if looking != self._looking:
            self._looking = looking
            self.bus.boundary(self.look if looking else None)

    # --- start and end ----------------------------------------
    def _start(self, e: Entry) -> None:
        self._version += 1
        e.state = "active"
        e.started_ms = self.bus.t_ms()
        self._started.add(e.id)
        f = e.fault
        e.left = int(getattr(f, "count", 0) or 0)
        self.events.append((e.started_ms, "start", e.id, e.describe()))
        self.bus.log(f"Fault {e.id} started: {f.describe()}.")
        bus = self.bus
        if isinstance(f, k.LinkDown):
            bus.cut_after(f.after_slave)
        elif isinstance(f, k.PowerCycle):
            bus.power_cycle(f.slave)
        elif isinstance(f, k.RetreatSafeop):
            bus.fall(f.slave, AlState.SAFEOP, f.code)
        elif isinstance(f, k.AlError):
            self._latch(f)
        elif isinstance(f, k.DriveFault):
            bus.before_change()
            bus.channel(f.axis).inject_fault(f.code)
        elif isinstance(f, k.Sto):
            bus.override(f.axis).sto = True
            bus.channel(f.axis).inject_fault(ErrorCode.SAFE_TORQUE_OFF)
        elif isinstance(f, k.QuickStopInput):
            bus.override(f.axis).quick_stop = True
        elif isinstance(f, k.Brake):
            bus.override(f.axis).brake = True
        elif isinstance(f, k.SwitchStuck):
            ff = bus.override(f.axis)
            bit = 1 << k.SWITCH_BITS[f.switch]
            if f.value:
                ff.din_set |= bit
            else:
                ff.din_clear |= bit
        elif isinstance(f, k.SwitchChatter):
            bus.override(f.axis)
        elif isinstance(f, k.EncoderLost):
            bus.before_change()
            bus.channel(f.axis).lose_counts(f.counts)
        elif isinstance(f, k.EncoderNoise):
            bus.override(f.axis).enc_noise = f.counts
        elif isinstance(f, k.ProbeMissing):
            ff = bus.override(f.axis)
            ff.probe_off = True
            ff.din_clear |= 3 << 16
        elif isinstance(f, k.IoStuck):
            self._hold(f.slave, f.bit)
        # the cyclic answers pass the injector from now on (a frame fault); a trigger that
        # watched an axis no longer does
        self._refresh()
        readers_changed()  # (what the GT readers answer may change now: controller/epoch.py)
        if f.once:
            self._end(e, "done")

    def _end(self, e: Entry, why: str) -> None:
        if e.state == "ended":
            return
        self._version += 1
        e.state = "ended"
        f = e.fault
        bus = self.bus
        now = bus.t_ms()
        self.events.append((now, "end", e.id, why))
        if not f.once:
            bus.log(f"Fault {e.id} ended ({why}): {f.describe()}.")
        if isinstance(f, k.LinkDown):
            bus.mend(f.after_slave)
        elif isinstance(f, k.AlError):
            self._unlatch(f)
        elif isinstance(f, k.DriveFault):
            bus.before_change()
            bus.channel(f.axis).clear_injected_fault()
        elif isinstance(f, k.Sto):
            bus.override(f.axis).sto = False
            bus.channel(f.axis).clear_injected_fault()
        elif isinstance(f, k.QuickStopInput):
            bus.override(f.axis).quick_stop = False
        elif isinstance(f, k.Brake):
            bus.override(f.axis).brake = False
        elif isinstance(f, k.SwitchStuck | k.SwitchChatter):
            ff = bus.override(f.axis)
            bit = 1 << k.SWITCH_BITS[f.switch]
            ff.din_set &= ~bit
            ff.din_clear &= ~bit
        elif isinstance(f, k.EncoderNoise):
            bus.override(f.axis).enc_noise = 0
        elif isinstance(f, k.ProbeMissing):
            ff = bus.override(f.axis)
            ff.probe_off = False
            ff.din_clear &= ~(3 << 16)
        elif isinstance(f, k.IoStuck):
            self._hold(f.slave, f.bit)
        axis = getattr(f, "axis", None)
        if axis is not None and f.depth in ("drive", "field"):
            bus.forget_override(axis)
        readers_changed()  # (what the GT readers answer may change now: controller/epoch.py)

    def _spend(self, e: Entry) -> None:
        """One hit of a counted fault; the last one ends it."""
        if e.left:
            e.left -= 1
            if e.left == 0:
                self._end(e, "spent")

    # --- stuck IO inputs -------------------------------------------------------------------------
    def _hold(self, slave: int, bit: int) -> None:
        """Input ``bit`` of ``slave`` held at the value of the active stuck fault on it added
        last, or let go when none is left (module docstring)."""
        value = None
        for e in self.entries:
            f = e.fault
            if (
                e.state == "active"
                and isinstance(f, k.IoStuck)
                and (f.slave, f.bit)
                == (
                    slave,
                    bit,
                )
            ):
                value = int(bool(f.value))
        s = self.bus.slave(slave)
        if isinstance(s, IoSlave):
            s.hold_input_bit(bit, value)

    # --- AL errors ------------------------------------------------------------------------------
    def _latch(self, f: k.AlError) -> None:
        s = self.bus.slave(f.slave)
        state = _STATES[f.state.upper()]
        self.bus.fall(f.slave, state, f.code)
        if f.slave in self._al_guards:
            return
        inner = s.on_state_change  # the class's (or a guard already there)

        def refuse(old: AlState, new: AlState, _code: int = f.code, _top: AlState = state) -> Any:
            if new > _top and new != AlState.BOOT:
                return _code  # the error is latched: the slave will not go higher
            return inner(old, new)

        s.on_state_change = refuse  # type: ignore[method-assign]
        self._al_guards[f.slave] = refuse

    def _unlatch(self, f: k.AlError) -> None:
        s = self.bus.slave(f.slave)
        if self._al_guards.pop(f.slave, None) is not None:
            try:
                del s.on_state_change  # back to the class's method
            except AttributeError:
                pass

    # --- the mailbox ----------------------------------------
    def _wrap_mailboxes(self) -> None:
        for s in self.bus.slaves:
            if not s.has_mailbox or s.position in self._mailboxes:
                continue
            inner = s.mailbox
            self._mailboxes[s.position] = inner
            s.mailbox = _StandIn(self, s.position, inner)  # type: ignore[method-assign]

    def detach(self) -> None:
        """Take every stand-in away (the bus goes on without faults)."""
        for e in list(self.entries):
            if e.state == "active":
                self._end(e, "cleared")
        self.entries = []
        self._refresh()
        for s in self.bus.slaves:
            if s.position in self._mailboxes:
                try:
                    del s.mailbox
                except AttributeError:
                    pass
        self._mailboxes.clear()

    def mailbox(self, position: int, request: bytes, inner: Any) -> bytes | None:
        info = _sdo_request(request)
        if info is not None and info[1] is not None:
            for e in self.entries:
                if e.state == "armed" and e.trigger.sdo(position, info[1]):
                    self._start(e)
        if info is not None:
            step, index, subindex = info
            if index is not None:
                self._mbx_index = (position, index)
            elif getattr(self, "_mbx_index", (None, None))[0] == position:
                index = self._mbx_index[1]  # a segment: the object of the transfer
            for e in self.entries:
                f = e.fault
                if e.state != "active" or f.depth != "mailbox" or f.slave != position:  # type: ignore[attr-defined]
                    continue
                if f.index is not None and f.index != index:  # type: ignore[attr-defined]
                    continue
                if isinstance(f, k.MailboxAbort):
                    if f.step != "request" and f.step != step:
                        continue
                    if f.subindex is not None and subindex is not None and f.subindex != subindex:
                        continue
                    self._spend(e)
                    return _abort(request, index or 0, subindex or 0, f.code)
                if isinstance(f, k.MailboxLost):
                    inner(request)  # the slave did it; only the answer is lost
                    self._spend(e)
                    return None
                if isinstance(f, k.MailboxProtocol):
                    self._spend(e)
                    return _protocol_fault(request, f.variant)
        return inner(request)

    # --- cyclic answers ----------------------------------------
    def answer(self, wkc: int) -> tuple[int, int]:
        """The emulated bus's cyclic LRW answer: (ANSWERED | LOST | PREVIOUS, working counter)."""
        action = ANSWERED
        size = 0
        for e in self.entries:
            if e.state != "active" or e.fault.depth != "frame":
                continue
            f = e.fault
            if isinstance(f, k.WkcOffset):
                if f.command is not None and f.command.upper() not in ("LRW",):
                    continue
                if f.area is not None:
                    if not size:
                        img = self.bus.ctl.master.image  # type: ignore[attr-defined]
                        size = img.outputs_bytes + img.inputs_bytes
                    if not (f.area[0] < size and 0 < f.area[1]):
                        continue
                wkc = max(0, wkc + f.offset)
                self._spend(e)
            elif action == ANSWERED:
                if isinstance(f, k.DropResponses | k.FrameTruncate | k.FrameWrongIndex):
                    action = LOST
                elif isinstance(f, k.FrameDelay):
                    if f.us * 1000 >= self.bus.cycle_ns:
                        action = LOST  # later than the master waits: lost for this cycle
                elif isinstance(f, k.FrameReplay):
                    action = PREVIOUS
                else:
                    continue
                self._spend(e)
        return action, wkc

    def frame(self, buf: bytearray, n: int, _t_ns: int) -> int:
        """An answered frame on the wire, changed in place; the length to send (0: lost)."""
        from gtecat.drives.esc.frames import walk

        chain = self.bus.chain  # type: ignore[attr-defined]
        if not chain.process_data:
            return n
        offsets = walk(buf, n) or []
        for e in self.entries:
            if e.state != "active" or e.fault.depth != "frame":
                continue
            f = e.fault
            if isinstance(f, k.WkcOffset):
                hit = False
                for off in offsets:
                    if not self._datagram_hit(buf, off, f):
                        continue
                    dlen = struct.unpack_from("<H", buf, off + 6)[0] & 0x07FF
                    at = off + 10 + dlen
                    w = struct.unpack_from("<H", buf, at)[0]
                    struct.pack_into("<H", buf, at, max(0, w + f.offset) & 0xFFFF)
                    hit = True
                if hit:
                    self._spend(e)
                continue
            if isinstance(f, k.DropResponses):
                self._spend(e)
                return 0
            if isinstance(f, k.FrameTruncate):
                self._spend(e)
                return max(1, n - f.bytes)
            if isinstance(f, k.FrameWrongIndex):
                for off in offsets:
                    buf[off + 1] ^= 0x80
                self._spend(e)
                break
            if isinstance(f, k.FrameReplay):
                self._spend(e)
                prev = self._last_answer
                if prev is not None:
                    buf[: len(prev)] = prev
                    return len(prev)
                break
            if isinstance(f, k.FrameDelay):
                self._spend(e)
                end = time.monotonic_ns() + f.us * 1000
                while time.monotonic_ns() < end:
                    time.sleep(0)
                break
        self._last_answer = bytes(buf[:n])
        return n

    def _datagram_hit(self, buf: bytearray, off: int, f: k.WkcOffset) -> bool:
        from gtecat.eni.ethercat import Command

        cmd = buf[off]
        if f.command is not None and Command.__members__.get(f.command.upper()) != cmd:
            return False
        if f.area is None:
            return True
        if f.command is None and Command(cmd).name not in _LOGICAL:
            return False
        laddr = struct.unpack_from("<I", buf, off + 2)[0]
        dlen = struct.unpack_from("<H", buf, off + 6)[0] & 0x07FF
        if self._lbase is None or laddr < self._lbase:
            self._lbase = laddr
        a0 = laddr - self._lbase
        return f.area[0] < a0 + dlen and a0 < f.area[1]


# --- mailbox messages ----------------------------------------
_STEP_OF_CCS = {1: "download_init", 0: "download_segment", 2: "upload_init", 3: "upload_segment"}


class _StandIn:
    """A slave's mailbox with the injector in front (:meth:`Injector.mailbox`).  While the
    injector holds no fault that concerns this slave's SDOs (:func:`_sees_sdos`: a mailbox
    fault of this slave, a trigger counting its SDO requests) it sees nothing of them: it
    then says what the slave's own mailbox says of itself, ``sdo_server_only``, and the
    in-process backend may hand an expedited transfer to the slave's SDO server unframed, as
    it does without faults (a bus brought up with ``gtecat.faults`` imported, or with a
    machine description's faults armed: every InitCmd SDO framed and parsed twice otherwise)."""

    __slots__ = ("injector", "inner", "position")

    def __init__(self, injector: Injector, position: int, inner: Any) -> None:
        self.injector, self.position, self.inner = injector, position, inner

    def __call__(self, request: bytes) -> bytes | None:
        return self.injector.mailbox(self.position, request, self.inner)

    @property
    def sdo_server_only(self) -> bool:
        if not getattr(self.inner, "sdo_server_only", False):
            return False
        position = self.position
        return not any(_sees_sdos(e, position) for e in self.injector.entries)


def _sees_sdos(e: Entry, position: int) -> bool:
    """Whether entry ``e``, in any state, may act on an SDO request to slave ``position`` in
    :meth:`Injector.mailbox`: a mailbox fault of that slave, or a trigger that counts SDO
    requests (its :meth:`Trigger.sdo` of its own) of that slave; a fault or trigger that
    names no slave concerns every one."""
    f = e.fault
    if f.depth == "mailbox" and getattr(f, "slave", position) == position:
        return True
    t = e.trigger
    return type(t).sdo is not Trigger.sdo and getattr(t, "slave", position) == position


def _sdo_request(request: bytes) -> tuple[str, int | None, int | None] | None:
    """(step, index or None for a segment, subindex) of a CoE SDO request, else None."""
    try:
        mbx = parse_mailbox(bytes(request))
    except ValueError:
        return None
    data = mbx.data
    if mbx.mbx_type != 3 or len(data) < 3:  # CoE (ETG.1000.6 Table 29)
        return None
    service = struct.unpack_from("<H", data)[0] >> 12
    if service != CoeService.SDO_REQUEST:
        return None
    ccs = data[2] >> 5
    step = _STEP_OF_CCS.get(ccs)
    if step is None:
        return None
    if step.endswith("init") and len(data) >= 6:
        return step, struct.unpack_from("<H", data, 3)[0], data[5]
    return step, None, None


def _counter(request: bytes) -> int:
    try:
        return parse_mailbox(bytes(request)).counter
    except ValueError:
        return 1


def _abort(request: bytes, index: int, subindex: int, code: int) -> bytes:
    body = struct.pack("<BHBI", 0x80, index, subindex, code & 0xFFFFFFFF)
    return build_coe(CoeService.SDO_REQUEST, body, counter=_counter(request))


def _protocol_fault(request: bytes, variant: str) -> bytes:
    counter = _counter(request)
    if variant == "mailbox_error":
        return mailbox_error(MailboxError.SERVICE_NOT_SUPPORTED, counter=counter)
    if variant == "wrong_service":
        # an answer of another CoE service, not an emergency: a master takes an emergency
        # for what it is (ETG.1000.6 5.6.4: logged) and waits on for the SDO's answer
        return build_coe(CoeService.SDO_INFORMATION, bytes(8), counter=counter)
    return build_coe(CoeService.SDO_RESPONSE, b"", counter=counter)  # "short": no SDO frame


__all__ = ["ANSWERED", "LOST", "PREVIOUS", "Entry", "Injector"]
