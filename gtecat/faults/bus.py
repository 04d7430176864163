"""The buses a fault acts on: the emulated bus in-process, and the chain ``gtecat serve`` serves.

A fault kind (:mod:`.kinds`) says what goes wrong; a :class:`FaultBus` says how that is
done on its bus, so the same fault object means the same thing on both:

* frames: the emulated bus has one cyclic logical frame per cycle; what happens to its
  answer (lost, the previous one again, a working counter off) is decided by
  :meth:`gtecat.faults.injector.Injector.answer` through the backend's ``answer_hook``.
  On the wire the answered frame itself is changed (:meth:`Injector.frame`: cut short,
  another index, the previous answer, late, working counters changed) through the
  server's ``frame_hook``.  Frame faults act on cyclic (process-data) frames only, on both
  buses, so bring-up and mailbox traffic are not what they hit;
* the link: the emulated backend's unplugged set; the chain's :meth:`~gtecat.drives.esc.
  chain.Chain.cut_after`;
* slaves, mailboxes, drives and the field: the very same virtual slave objects on both.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

from gtecat.drives.drive import Channel, Cia402Drive
from gtecat.drives.faults import FieldOverride
from gtecat.drives.slave import AlState, AlStatusCode, VirtualSlave

from ..errors import ParameterError


def _no_objects(_od: Any) -> None:
    pass


class FaultBus:
    """What an injector needs of a bus (subclasses: :class:`EmulatedBus`, :class:`WireBus`)."""

    name = "bus"
    cycle_ns = 1_000_000
    #: :meth:`boundary` calls its hook before every cycle (else the triggers that watch the
    #: machine are asked in each cycle's tick)
    between = False

    def image_bytes(self) -> int | None:
        """Size of the process image, bytes, where the bus knows it (a ``wkc_offset`` area
        wholly past it would never act); None where it does not."""
        return None

    @property
    def slaves(self) -> list[VirtualSlave]:
        raise NotImplementedError

    def now_ms(self, ahead: int = 0) -> float:
        """Controller time, ms: what GT_GetClock reads (``at_ms``); ``ahead`` cycles on."""
        raise NotImplementedError

    def t_ms(self, ahead: int = 0) -> float:
        """Time that never goes back (a GT_Reset does not move it): durations, ``after_ms``."""
        return self.now_ms(ahead)

    def cycle_mark(self) -> tuple[int, ...] | None:
        """(time ns, cycles run, cycle time ns, the time GT_Reset counts from, ns) where a
        bus counts its cycles, so that a count of quiet cycles made at one mark holds at a
        later one less the cycles between them (:meth:`Injector.quiet_cycles`); None: it
        does not."""
        return None

    def healthy(self) -> bool:
        return True

    def settle(self) -> None:
        """Before the injector reads what it counts outside a cycle (a fault added or
        cleared): the cycles the bus ran without asking it counted first
        (``Controller.settle_hooks``; nothing on a bus that asks it every cycle)."""

    def log(self, message: str) -> None:
        pass

    def cut_after(self, position: int) -> None:
        """A link fault starts: the cable behind ``position`` is pulled.  Link faults may
        overlap: the bus is cut at the first of those active, and each one's end mends
        only its own (:meth:`mend`)."""
        links = self.__dict__.setdefault("_links", [])
        before = min(links, default=None)
        links.append(position)
        if before is None or position < before:
            self._open_link(position)

    def mend(self, position: int | None = None) -> None:
        """The link fault cut at ``position`` ends (None: every one): the bus is whole
        again, or cut where another one still is."""
        links = self.__dict__.setdefault("_links", [])
        before = min(links, default=None)
        if position is None:
            links.clear()
        elif position in links:
            links.remove(position)
        now = min(links, default=None)
        if now is None:
            self._close_link()
        elif now != before:
            self._open_link(now)

    def _open_link(self, position: int) -> None:
        """Cut the bus behind ``position`` (only there: a cut elsewhere is closed)."""
        raise NotImplementedError

    def _close_link(self) -> None:
        raise NotImplementedError

    def before_change(self) -> None:
        """Called before a fault touches slaves (the emulated bus gives back banked axes)."""

    def set_frame_faults(self, injector: Any) -> None:
        """Route the cyclic answers through ``injector`` (None: no longer)."""

    def watch_axes(self, axes: frozenset[int]) -> None:
        """A fault may meet the drives of ``axes`` in the next cycle, or a script's step
        reads them in every tick (the emulated bus keeps them off the axis bank, the other
        axes stay on it)."""

    # --- what the faults reach ----------------------------------------
    def slave(self, position: int) -> VirtualSlave:
        slaves = self.slaves
        if not 0 <= position < len(slaves):
            raise ParameterError(f"no slave {position}: the bus has slaves 0..{len(slaves) - 1}")
        return slaves[position]

    def channels(self) -> list[Channel]:
        """The CiA-402 channels in bus order: GT axis k is ``channels()[k - 1]``."""
        out: list[Channel] = []
        for s in sorted(self.slaves, key=lambda s: s.position):
            if isinstance(s, Cia402Drive):
                out.extend(s.channels)
        return out

    def channel(self, axis: int) -> Channel:
        chans = self.channels()
        if not 1 <= axis <= len(chans):
            raise ParameterError(
                f"no axis {axis}: the bus has axes 1..{len(chans)}"
                if chans
                else f"no axis {axis}: the bus has no CiA-402 drive"
            )
        return chans[axis - 1]

    def override(self, axis: int) -> FieldOverride:
        ch = self.channel(axis)
        if ch.field is None:
            self.before_change()
            ch.field = FieldOverride()
        return ch.field

    def forget_override(self, axis: int) -> None:
        ch = self.channel(axis)
        if ch.field is not None and ch.field.idle:
            ch.field = None

    def position(self, axis: int) -> float:
        return self.channel(axis).machine_position

    def homing_stage(self, axis: int) -> str:
        h = self.channel(axis).homing
        return "" if h is None else h.phase.name.lower()

    def position_now(self, axis: int) -> float:
        """:meth:`position` between two cycles, wherever the drive's state is kept (the
        emulated bus: the axis bank's row, which it leaves there)."""
        return self.position(axis)

    def max_step(self, axis: int) -> float:
        """The most the mechanics of ``axis`` can move in one cycle, machine counts, with a
        margin for rounding (inf: the bus cannot tell)."""
        return math.inf

    def banked(self, axis: int) -> bool:
        """Whether the axis bank runs the drive of ``axis`` now (the emulated bus)."""
        return False

    def homing_stage_now(self, axis: int) -> str:
        """:meth:`homing_stage` between two cycles (the emulated bus: of a drive the axis
        bank runs too, without giving it back)."""
        return self.homing_stage(axis)

    def boundary(self, hook: Any) -> None:
        """Call ``hook()`` before every cycle from now on, before anything of it has run
        (None: no longer); cycles run at once ask the injector's ``quiet_cycles`` first
        instead: a trigger that watches the machine looks at it there
        (:meth:`Injector.look`)."""

    # --- slaves ----------------------------------------
    def power_cycle(self, position: int) -> None:
        """Power gone and back: INIT, the AL error gone, the drive's settings at power-on
        values (its mechanics stay where they are; an incremental encoder forgets its home)."""
        s = self.slave(position)
        self.before_change()
        old = s.al_state
        if old != AlState.INIT:
            s.on_state_change(old, AlState.INIT)
        s.enter_state(AlState.INIT)
        s.al_error = False
        s.al_status_code = AlStatusCode.NO_ERROR
        s.outputs_valid = False
        if isinstance(s, Cia402Drive):
            for ch in s.channels:
                pos, ff = ch.mech.pos, ch.field
                # the power-on values of every setting; the objects stay registered
                ch._add_objects = _no_objects  # type: ignore[method-assign]
                try:
                    Channel.__init__(ch, s, ch.k, replace(ch.machine, position=pos))
                finally:
                    del ch._add_objects
                ch.field = ff

    def fall(self, position: int, state: AlState, code: int) -> None:
        """The slave leaves its state for ``state`` by itself, with AL status ``code``."""
        s = self.slave(position)
        self.before_change()
        old = s.al_state
        if old > state:
            s.on_state_change(old, state)
            s.enter_state(state)
            if state < AlState.OP:
                s.outputs_valid = False
        if code:
            s.al_error = True
            s.al_status_code = (
                AlStatusCode(code) if code in AlStatusCode._value2member_map_ else code
            )  # type: ignore[assignment]


class EmulatedBus(FaultBus):
    """The in-process emulated bus of one controller."""

    name = "emulated"
    between = True

    def image_bytes(self) -> int | None:
        m = self.ctl.master
        if m is None:
            return None
        return int(m.image.outputs_bytes + m.image.inputs_bytes)

    def __init__(self, ctl: Any) -> None:
        from ..master.backends.emulated import EmulatedBackend

        if not isinstance(ctl.backend, EmulatedBackend):
            raise ParameterError(
                "faults act on the emulated bus (and on gtecat serve); this controller's bus "
                f"is {type(ctl.backend).__name__}"
            )
        self.ctl = ctl
        self.backend = ctl.backend
        self._cut: list[int] = []
        self._chans: dict[int, Channel] = {}
        self._boundary: Any = None  # (the hook in ctl.before_bank)

    @property
    def cycle_ns(self) -> int:  # type: ignore[override]
        return int(self.ctl.clock.cycle_ns)

    @property
    def slaves(self) -> list[VirtualSlave]:
        return self.backend.slaves

    def now_ms(self, ahead: int = 0) -> float:
        clock = self.ctl.clock
        return (clock.now_ns + ahead * clock.cycle_ns - self.ctl.reset_ns) / 1e6

    def t_ms(self, ahead: int = 0) -> float:
        clock = self.ctl.clock
        return (clock.now_ns + ahead * clock.cycle_ns) / 1e6

    def cycle_mark(self) -> tuple[int, ...] | None:
        clock = self.ctl.clock
        return (clock.now_ns, clock.cycles, clock.cycle_ns, self.ctl.reset_ns)

    def healthy(self) -> bool:
        m = self.ctl.master
        return m is not None and m.last.ok and m.last.expected > 0

    def settle(self) -> None:
        with self.ctl.clock.lock:  # (another thread's calls may be running quick cycles)
            self.ctl.settle_hooks()

    def log(self, message: str) -> None:
        self.ctl.log(message)

    def before_change(self) -> None:
        bank = self.ctl.bank
        if bank is not None:
            bank.release_all()
            bank.dirty = True

    def watch_axes(self, axes: frozenset[int]) -> None:
        bank = self.ctl.bank
        if bank is not None:
            bank.hold(axes)

    def _chan(self, axis: int) -> Channel:
        ch = self._chans.get(axis)
        if ch is None:
            ch = self._chans[axis] = self.channel(axis)
        return ch

    def position_now(self, axis: int) -> float:
        ch = self._chan(axis)
        bank = self.ctl.bank
        if bank is not None:
            pos = bank.row_position(ch)
            if pos is not None:
                return pos
        return ch.machine_position

    def max_step(self, axis: int) -> float:
        # (Mechanics.track, drive_torque and coast keep |vel| within vmax; the bank's rows
        # do the same operations)
        vmax = object.__getattribute__(self._chan(axis), "mech").vmax
        return abs(vmax) * (self.ctl.clock.cycle_ns * 1e-9) * (1.0 + 1e-9) + 1e-6

    def banked(self, axis: int) -> bool:
        bank = self.ctl.bank
        return bank is not None and bank.row_position(self._chan(axis)) is not None

    def homing_stage_now(self, axis: int) -> str:
        if self.banked(axis):
            ch = self._chan(axis)
            h = object.__getattribute__(ch, "homing")  # (read past its guard: it stays)
            return "" if h is None else h.phase.name.lower()
        return self.homing_stage(axis)

    def boundary(self, hook: Any) -> None:
        hooks = self.ctl.before_bank
        if self._boundary is not None and self._boundary in hooks:
            hooks.remove(self._boundary)
        self._boundary = hook
        if hook is not None:
            hooks.append(hook)

    def _open_link(self, position: int) -> None:
        self.before_change()
        behind = range(position + 1, len(self.slaves))
        for pos in [p for p in self._cut if p not in behind]:
            self.backend.replug(pos)
            self._cut.remove(pos)
        for pos in behind:  # a slave already cut keeps its silence (its watchdog's count)
            if pos not in self.backend.unplugged:
                self.backend.unplug(pos)
                self._cut.append(pos)

    def _close_link(self) -> None:
        for pos in self._cut:
            self.backend.replug(pos)
        self._cut = []

    def set_frame_faults(self, injector: Any) -> None:
        self.backend.answer_hook = None if injector is None else injector.answer
        if injector is not None:
            self.before_change()
        elif self.ctl.bank is not None:
            self.ctl.bank.dirty = True


class WireBus(FaultBus):
    """The chain of software ESCs a :class:`gtecat.wire.serve.WireServer` serves."""

    name = "wire"

    def __init__(self, chain: Any, server: Any = None, log: Any = None) -> None:
        self.chain = chain
        self.server = server
        self._t_ns = 0
        self._log = log
        if server is not None:
            self.cycle_ns = int(server.cycle_ns)

    def at(self, t_ns: int) -> None:
        """The slaves' time now (ns since the server started)."""
        self._t_ns = t_ns

    @property
    def slaves(self) -> list[VirtualSlave]:
        return self.chain.slaves

    def now_ms(self, ahead: int = 0) -> float:
        return (self._t_ns + ahead * self.cycle_ns) / 1e6

    def log(self, message: str) -> None:
        if self._log is not None:
            self._log(message)

    def _open_link(self, position: int) -> None:
        self.chain.cut_after(position)

    def _close_link(self) -> None:
        self.chain.mend()

    def power_cycle(self, position: int) -> None:
        super().power_cycle(position)
        esc = next(e for e in (*self.chain.escs, *self.chain.cut) if e.position == position)
        esc.mem[:] = bytes(len(esc.mem))  # station address, SMs and FMMUs: gone
        esc._reset_registers()
        esc._decode_sms()
        esc._decode_fmmus()
        esc.on_station_change(esc)
        esc.on_fmmu_change(esc)
        esc.on_sm_change(esc)

    def set_frame_faults(self, injector: Any) -> None:
        if self.server is not None:
            self.server.frame_hook = None if injector is None else injector.frame


__all__ = ["EmulatedBus", "FaultBus", "WireBus"]
