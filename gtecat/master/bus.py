"""The EtherCAT master: bring-up, cyclic exchange, working counter, mailbox.

Bring-up follows ETG.1000.6 / ETG.2100 the way an IgH-style master does it:
scan, compare what answered with the ENI (vendor, product, revision), INIT ->
PREOP (CoE InitCmds of transition ``IP``), PREOP -> SAFEOP (``PS``: PDO
assignment/mapping and start-up parameters; the slave checks its sync-manager
sizes), then, once cyclic data flows, SAFEOP -> OP (``SO``).  A slave that
rejects an InitCmd or a transition stays below OP and the reason is logged and
kept in :attr:`Master.error`.

The OP request is made ``op_delay_cycles`` cycles after SAFEOP is reached
(the real master waits for the DC clocks and the first valid inputs), so
``GT_IsEcatReady`` polling loops see 0 before 1, as on the real controller.

Comm loss: once the bus has been asked for OP, the first cycle whose working
counter is short makes the master read every slave's AL state at once (the
master knows in that very cycle: ETG.1000.4 counts every slave that processes
the LRW, so a slave behind a pulled cable lowers it in the next frame).  A slave
that does not answer, or is below OP, is *offline* (:attr:`Master.offline`:
position -> reason) from that cycle until a later state read finds it in OP
again.  The manual names no filter of lost frames for the controller (its
entries of ``GT_IsEcatReady``, ``GT_GetEcatSlaves`` and the chapter 5 and 13
reads of PDO objects give no delay), so there is none here: what
``GT_IsEcatReady``/``GT_GetEcatSlaves`` show and what the reads of the slave's
objects return agree from the first cycle.  One lost frame, or a short stall of
the wire, is still no loss: the state read is answered, every slave in OP, and
nothing goes offline.  While the working counter stays short the states are read
again after :attr:`Master.loss_confirm_ns` (10 ms), every
:attr:`Master.recover_every` cycles from then on, and in every cycle whose count
differs from the cycle's before (slaves gone, or back behind a cut mended in part).
``GT_GetEcatSlaves`` counts what these reads found, as the others do: no read of its
own.  The controller stops the axes of offline slaves and the GT layer refuses process
data that touches them (:mod:`gtecat.controller.core`, :mod:`gtecat.gt.bus_calls`).

Lost SDO answer: a master that sends an SDO request and gets no answer waits its
mailbox timeout before it gives up with 0x05040000 (SDO protocol timed out).  The
manual and the ENI (CoE InitCmd ``Timeout`` 0: the master's default) name no value,
so the emulated master waits what its hardware backend waits (SOEM's mailbox
receive timeout, 700 ms: :data:`SDO_TIMEOUT_MS`), in controller time: the cycles
run while the call waits (:attr:`Master.mailbox_wait`), in lockstep and auto
alike, so a loop that polls by SDO sees the time a real one would.

Mailbox on a wire: a backend whose SDOs wait for a real slave's answer
(:attr:`Backend.mailbox_on_wire`: pysoem) takes that time on the wall clock.  A real
controller's firmware keeps the cyclic exchange going while a mailbox transfer is
pending, so the master hands such a transfer to :attr:`Master.mailbox_transfer` (set
by the controller), which keeps the cycles running at the bus cycle meanwhile and
counts them on the controller's clock: a lost answer costs 700 ms of controller time
in which the axes move and the slaves' watchdogs stay fed, on both backends.
"""

from __future__ import annotations

from array import array
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

from gtecat.drives.slave import AlState, AlStatusCode
from gtecat.eni.errors import GtecatError
from gtecat.eni.layout import Layout
from gtecat.eni.model import InitCmd

from .._attrs import in_array
from ..errors import BusError, ConfigMismatch, NoSlavesError, StateError
from .backends.base import Backend
from .clock import hook_list
from .image import ProcessImage

_T = TypeVar("_T")

#: looked up once: the cycle and :meth:`Master.steady` compare with it (an enum member's
#: lookup costs more than the comparison)
_OP = AlState.OP

#: how long the master waits for an SDO answer before it reports 0x05040000 (module
#: docstring "Lost SDO answer"): SOEM's mailbox receive timeout, which the pysoem
#: backend waits on the wire
SDO_TIMEOUT_MS = 700


@dataclass
class CycleResult:
    wkc: int
    expected: int

    @property
    def ok(self) -> bool:
        return self.wkc == self.expected


def _transition(a: AlState, b: AlState) -> str:
    letter = {
        AlState.INIT: "I",
        AlState.PREOP: "P",
        AlState.SAFEOP: "S",
        AlState.OP: "O",
        AlState.BOOT: "B",
    }
    return letter[a] + letter[b]


class Master:
    """One EtherCAT master on one backend."""

    #: called with the master after every cycle (a list whose changes are seen: Hooks)
    on_cycle = hook_list("on_cycle")

    cycles = in_array("counts", 0, "The cycles run.")

    def __init__(
        self,
        layout: Layout,
        backend: Backend,
        *,
        log: Callable[[str], None] = lambda _m: None,
        op_delay_cycles: int = 10,
    ) -> None:
        self.layout = layout
        self.backend = backend
        self.image = ProcessImage(layout)
        self.log = log
        self.op_delay_cycles = op_delay_cycles
        self.error: str = ""  # why the bus is not (or no longer) fully up
        self.last = CycleResult(0, 0)
        self.wkc_errors = 0
        #: [0] the cycles run (:attr:`cycles`), in memory compiled code adds to (a quick
        #: cycle's book: gtecat.controller.core.Controller.arm_quick)
        self.counts = array("q", (0,))
        self.emergency_count = 0
        self._wkc_bad = False
        #: cycles between recovery attempts while the working counter is short
        self.recover_every = 100
        self.opened = False
        #: called once the scan found the ENI's slaves, before the state walk and its InitCmds
        self.on_opened: Callable[[], None] | None = None
        self.target = AlState.INIT
        self._op_countdown = -1
        self.states: list[AlState] = [AlState.INIT] * len(layout.slaves)
        self._codes: list[int] = [0] * len(layout.slaves)
        #: slaves out of the process-data exchange although the bus should be in OP:
        #: position -> reason ("slave 1 (Drive) does not answer"); empty while all is well
        self.offline: dict[int, str] = {}
        #: lets ``ms`` of controller time pass, cycles running (set by the controller):
        #: the wait for an SDO answer that never comes (module docstring "Lost SDO answer")
        self.mailbox_wait: Callable[[float], None] | None = None
        #: runs one mailbox transfer of a backend whose mailbox waits on a wire (module
        #: docstring "Mailbox on a wire") while the cycles keep running; None: in place
        self.mailbox_transfer: Callable[[Callable[[], Any]], Any] | None = None
        #: a short working counter this long in a row is worth a second state read (the
        #: first is made in the first short cycle)
        self.loss_confirm_ns = 10_000_000
        self._bad_ns = 0
        self._op_requested = False  # the OP walk ran: from now on below OP is offline
        self.on_cycle: list[Callable[[Master], None]] = []  # recorders etc. (Hooks)
        #: states an operator asked of single slaves on the running bus (``gtecat states -p 2
        #: PREOP``): position -> state; recovery leaves them there until OP is asked again or
        #: the application brings the bus up anew (GT_InitEcatComm makes a new master)
        self.held: dict[int, AlState] = {}
        backend.held = self.held  # a backend that recovers by itself skips them too

    # --- bring-up ------------------------------------------------------------------
    def open(self) -> None:
        """Scan, compare with the ENI and bring every slave to SAFEOP.

        Raises :class:`NoSlavesError` (GT -10), :class:`ConfigMismatch` (GT -8) or
        :class:`BusError` with the reason.
        """
        self.log("Scanning bus.")
        self.backend.open(self.layout, self.image)
        found = self.backend.scan()
        if not found:
            raise NoSlavesError(self.backend.empty_scan())
        self.log(f"Found {len(found)} slaves.")
        expected = self.layout.config.slaves
        for cfg, got in zip(expected, found, strict=False):
            e, g = cfg.identity, got.identity
            for what, a, b in (
                ("vendor id", e.vendor_id, g.vendor_id),
                ("product code", e.product_code, g.product_code),
                ("revision", e.revision_no, g.revision_no),
            ):
                if a and a != b:
                    raise ConfigMismatch(
                        f"slave {cfg.position}: ENI expects {cfg.name!r} {what} 0x{a:08X}, "
                        f"bus has 0x{b:08X} ({got.name or 'unnamed'}); export the ENI again "
                        "for this bus or check the cabling order"
                    )
        if len(found) != len(expected):
            raise ConfigMismatch(
                f"ENI lists {len(expected)} slaves, the bus has {len(found)} "
                "(check the cabling and power, or export the ENI again for this bus)"
                + (
                    f" (first missing: slave {len(found)} {expected[len(found)].name!r})"
                    if len(found) < len(expected)
                    else ""
                )
            )
        self.opened = True
        if self.on_opened is not None:
            self.on_opened()  # before the InitCmds: faults of the machine meet the bring-up
        self._walk(AlState.PREOP)
        self._walk(AlState.SAFEOP)
        self.target = AlState.OP
        self._op_countdown = self.op_delay_cycles
        self.log("Slave states: SAFEOP")

    def _walk(self, target: AlState) -> None:
        """Move every slave from its state to ``target`` (one step), with InitCmds."""
        for cfg in self.layout.config.slaves:
            pos = cfg.position
            cur, _ = self.backend.state(pos)
            if cur == target:
                continue
            tr = _transition(cur, target)
            # CoE InitCmds run where the mailbox works: before the request for
            # PS/SO, after reaching PREOP for IP.
            if cur >= AlState.PREOP:
                self._init_cmds(pos, tr)
            code = self.backend.request_state(pos, target)
            if code:
                state, _ = self.backend.state(pos)
                msg = (
                    f"slave {pos} ({cfg.name}): {tr} refused, AL status code "
                    f"0x{int(code):04X} {_code_name(code)}; stays in {state.name}"
                )
                self.log(msg)
                self.error = msg
                raise StateError(msg, expected=target, actual=state, slave=pos)
            if target == AlState.PREOP:
                self._init_cmds(pos, tr)
            self.states[pos] = target
        self.log(f"Slave states: {target.name}")

    def _init_cmds(self, pos: int, transition: str) -> None:
        cfg = self.layout.config.slaves[pos]
        for cmd in cfg.init_cmds:
            if transition not in cmd.transitions:
                continue
            try:
                self._run_init_cmd(pos, cmd)
            except GtecatError as e:
                msg = (
                    f"slave {pos} ({cfg.name}): InitCmd {transition} "
                    f"0x{cmd.index:04X}:{cmd.subindex:02X} "
                    f"{cmd.comment or ''} failed: {e}"
                ).replace("  ", " ")
                self.log(msg)
                self.error = msg
                raise StateError(msg, expected=transition, slave=pos) from e

    def _run_init_cmd(self, pos: int, cmd: InitCmd) -> None:
        if cmd.upload:
            self.backend.sdo_upload(pos, cmd.index, cmd.subindex, cmd.complete_access)
        else:
            self.backend.sdo_download(pos, cmd.index, cmd.subindex, cmd.data, cmd.complete_access)

    def request_op(self) -> None:
        """SO InitCmds and the OP request (made automatically after the delay)."""
        self._op_requested = True
        try:
            self._walk(AlState.OP)
            self.log("All slaves are in OP mode.")
            self.error = ""
        except GtecatError as e:
            self.error = str(e)
            self.refresh_states()

    def terminate(self) -> None:
        """Every slave back to INIT (GT_TerminateEcatComm)."""
        for cfg in self.layout.config.slaves:
            try:
                self.backend.request_state(cfg.position, AlState.INIT)
                self.states[cfg.position] = AlState.INIT
            except GtecatError:
                pass
        self.target = AlState.INIT
        self._op_countdown = -1
        self._op_requested = False
        self.offline = {}
        self.log("Slave states: INIT")
        self.opened = False

    # --- cycle -----------------------------------------------------------------------
    def cycle(self, t_ns: int, dt_ns: int) -> CycleResult:
        if not self.opened:
            return self.last
        wkc = self.backend.exchange(t_ns, dt_ns)
        self.cycles += 1
        expected = self.backend.expected_wkc() if self.target == _OP else wkc
        before = self.last.wkc
        self.last = CycleResult(wkc, expected)
        ok = wkc == expected  # (CycleResult.ok, asked once)
        if self._op_countdown >= 0:
            self._op_countdown -= 1
            if self._op_countdown < 0:
                self.request_op()
        elif self.target == _OP and ok and not self.all_op():
            # the working counter is whole again (a slave came back and the backend
            # recovered it): take the states as they are now
            self.refresh_states()
        elif self.target == _OP and not ok:
            self.wkc_errors += 1
            if not self._wkc_bad:
                self._wkc_bad = True
                self.error = f"working counter {wkc}/{expected}: a slave does not answer"
                self.log(f"Working counter changed to {wkc}/{expected}.")
            bad, self._bad_ns = self._bad_ns, self._bad_ns + dt_ns
            confirmed = self._bad_ns >= self.loss_confirm_ns  # not one lost frame
            periodic = confirmed and self.cycles % self.recover_every == 0
            if periodic and not self.backend.recovers_itself:
                self.recover()
            elif (
                periodic or bad == 0 or bad < self.loss_confirm_ns <= self._bad_ns or wkc != before
            ):
                # who is gone, from the first short cycle on (comm loss, module docstring),
                # and again whenever the count changes while short (slaves gone or back)
                self.refresh_states()
        if ok:
            self._bad_ns = 0
        if self._wkc_bad and ok and self.all_op():
            self._wkc_bad = False
            self.error = ""
            self.log(f"Working counter changed to {wkc}/{expected}. All slaves are in OP mode.")
        for pos, emcy in self.backend.emergencies():
            self.emergency_count += 1
            self.log(
                f"WARNING {pos}: CoE EMERGENCY 0x{emcy.code:04X} 0x{emcy.register:02X} "
                f"{emcy.data.hex(' ')}"
            )
        for hook in self.on_cycle:
            hook(self)
        return self.last

    def steady(self) -> bool:
        """A cycle now would change nothing but the time and :attr:`cycles`: every slave in OP
        as asked, the working counter whole, nothing to log, no hook, and a backend whose
        exchange would change nothing (:meth:`Backend.steady`)."""
        return (
            self.opened
            and not self.on_cycle
            and self._op_countdown < 0
            and not self._wkc_bad
            and not self.offline
            and self.target == _OP
            and self.last.ok
            and self.all_op()
            and self.backend.steady()
        )

    def recover(self) -> None:
        """Bring back slaves that answer again but fell below OP (acknowledge, re-walk).

        Like an IgH master after a cable is plugged back: the slave's error is
        acknowledged, its InitCmds are applied again on the way up, and it is
        asked for OP.  Slaves that still do not answer are left for the next try.
        """
        for cfg in self.layout.config.slaves:
            pos = cfg.position
            if pos in self.held:
                continue
            try:
                state, code = self.backend.state(pos)
            except GtecatError:
                self.states[pos] = AlState.NONE
                continue
            self.states[pos], self._codes[pos] = state, int(code)
            if state == AlState.OP:
                continue
            self.log(
                f"Slave {pos}: state {state.name}"
                + (f" + ERROR 0x{int(code):04X}" if code else "")
                + "; recovering."
            )
            try:
                if code:
                    self.backend.request_state(pos, state)  # acknowledge the error
                for target in (AlState.PREOP, AlState.SAFEOP, AlState.OP):
                    cur, _ = self.backend.state(pos)
                    if cur >= target:
                        continue
                    tr = _transition(cur, target)
                    if cur >= AlState.PREOP:
                        self._init_cmds(pos, tr)
                    if self.backend.request_state(pos, target):
                        raise StateError(f"slave {pos}: {tr} refused", slave=pos)
                    if target == AlState.PREOP:
                        self._init_cmds(pos, tr)
                self.states[pos], self._codes[pos] = AlState.OP, 0
                self.log(f"Slave {pos}: back in OP.")
            except GtecatError as e:
                self.error = str(e)
        self._update_offline()

    def all_op(self) -> bool:
        states = self.states
        return states.count(_OP) == len(states)  # (asked every cycle: no generator)

    @property
    def ready(self) -> bool:
        """All slaves in OP and the last cycle's working counter as expected."""
        return self.opened and self.all_op() and self.last.ok and self.last.expected > 0

    def refresh_states(self) -> list[AlState]:
        """Read every slave's AL state (NONE: no answer); updates :attr:`offline`."""
        for pos, got in enumerate(self.backend.states(len(self.states))):
            self.states[pos], self._codes[pos] = got if got is not None else (AlState.NONE, 0)
        self._update_offline()
        return self.states

    def _update_offline(self) -> None:
        if not self._op_requested:
            return
        offline: dict[int, str] = {}
        for pos, state in enumerate(self.states):
            if state == AlState.OP:
                continue
            name = self.layout.config.slaves[pos].name
            if state == AlState.NONE:
                why = "does not answer"
            else:
                code = self._codes[pos]
                why = f"is in {state.name}" + (
                    f" + ERROR 0x{code:04X} {_code_name(code)}" if code else ""
                )
            offline[pos] = f"slave {pos} ({name}) {why}"
        if offline.keys() != self.offline.keys():
            gone = sorted(offline.keys() - self.offline.keys())
            back = sorted(self.offline.keys() - offline.keys())
            if gone:
                self.log("Lost: " + "; ".join(offline[p] for p in gone) + ".")
            if back:
                self.log("Back in process data: slaves " + ", ".join(map(str, back)) + ".")
        self.offline = offline

    # --- mailbox ------------------------------------------------------------------------
    def sdo_upload(
        self,
        pos: int,
        index: int,
        subindex: int,
        complete_access: bool = False,
        *,
        wait: bool = True,
    ) -> bytes:
        """The object's bytes; ``wait=False``: a lost answer costs no controller time (the
        inspection verbs, which run beside the application, never run its cycles)."""
        self._check_slave(pos)
        backend = self.backend
        if wait and backend.mailbox_on_wire:
            return self._on_wire(lambda: backend.sdo_upload(pos, index, subindex, complete_access))
        if not complete_access:
            # (served in this process: answered at once, nothing to count or wait for)
            got = backend.sdo_in_process(pos, index, subindex, None)
            if got is not None:
                return got
        lost = self._unanswered(pos) if wait else -1
        try:
            return backend.sdo_upload(pos, index, subindex, complete_access)
        finally:
            self._timed_out(lost, pos)

    def sdo_download(
        self,
        pos: int,
        index: int,
        subindex: int,
        data: bytes,
        complete_access: bool = False,
        *,
        wait: bool = True,
    ) -> None:
        """Write ``data`` to the object; ``wait`` as for :meth:`sdo_upload`."""
        self._check_slave(pos)
        backend = self.backend
        if wait and backend.mailbox_on_wire:
            self._on_wire(lambda: backend.sdo_download(pos, index, subindex, data, complete_access))
            return
        if backend.sdo_in_process(pos, index, subindex, data, complete_access):
            return  # (served in this process: answered at once)
        lost = self._unanswered(pos) if wait else -1
        try:
            backend.sdo_download(pos, index, subindex, data, complete_access)
        finally:
            self._timed_out(lost, pos)

    def sdo_download_values(self, pos: int, items: Sequence[tuple[int, int, int, int]]) -> None:
        """Write integers ``(index, subindex, value, size)`` to slave ``pos`` in order, each
        one SDO download of the value's ``size`` little-endian bytes (two's complement when
        negative; the value fits them) as :meth:`sdo_download` sends it (served in this
        process in one go where the backend can, the values as they are:
        :meth:`Backend.sdo_values_in_process`), stopping at the first abort (raised)."""
        self._check_slave(pos)
        backend = self.backend
        done = 0 if backend.mailbox_on_wire else backend.sdo_values_in_process(pos, items)
        if done == len(items):
            return
        for index, subindex, value, size in items[done:]:
            data = value.to_bytes(size, "little", signed=value < 0)
            self.sdo_download(pos, index, subindex, data)

    def _on_wire(self, transfer: Callable[[], _T]) -> _T:
        """A transfer of a mailbox on a wire: the cycles run while it waits (module
        docstring "Mailbox on a wire"), as long as the slave takes to answer."""
        run = self.mailbox_transfer
        return transfer() if run is None else run(transfer)

    def _unanswered(self, pos: int) -> int:
        """The SDO requests the backend sent to slave ``pos`` without an answer so far (-1: it
        cannot tell, as on the wire, where the backend waits its timeout itself)."""
        count = getattr(self.backend, "unanswered", None)
        return count(pos) if count is not None and self.mailbox_wait is not None else -1

    def _timed_out(self, before: int, pos: int) -> None:
        """The master's mailbox timeout for each request of this call left unanswered."""
        if before < 0 or self.mailbox_wait is None:
            return
        lost = self._unanswered(pos) - before
        if lost > 0:
            self.mailbox_wait(lost * SDO_TIMEOUT_MS)

    def _check_slave(self, pos: int) -> None:
        if not self.opened:
            raise BusError("EtherCAT communication is not initialised (call GT_InitEcatComm)")
        if not 0 <= pos < len(self.layout.slaves):
            raise BusError(f"no slave {pos}: the bus has slaves 0..{len(self.layout.slaves) - 1}")


def _code_name(code: int) -> str:
    try:
        return AlStatusCode(code).name.lower().replace("_", " ")
    except ValueError:
        return "vendor specific"
