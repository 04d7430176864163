"""The controller: one emulated iDEABOX core (bus master, clock, axes, recorder).

This is the Pythonic API the ``GT_*`` functions are a thin layer over: methods
return values and raise typed exceptions.  Options come from the caller, then
the ``GTECAT_*`` environment (DESIGN.md "The stable surface"), then defaults.

Every cycle runs in this order (STYLE.md "Cycle"): the axes write their
outputs (``pre_cycle`` hooks) -> the master exchanges the process image (each
slave steps) -> the axes of slaves the master found offline are stopped ->
the axes read their inputs (``post_cycle`` hooks) -> the recorder samples ->
the clock advances.

Decisions where the manual is silent:

* **Bring-up state.**  :attr:`Controller.init_error` keeps why the last
  ``GT_InitEcatComm`` failed (None after a success, before any and after
  ``GT_TerminateEcatComm``), so ``GT_IsEcatReady`` can say why it will never
  report 1 (:mod:`gtecat.gt.bus_calls`).  :attr:`Controller.started` is set by
  ``GT_StartEcatComm`` (entry 129) and cleared by a new init or a terminate.
* **Comm loss.**  An axis whose slave is in ``Master.offline``
  (:mod:`gtecat.master.bus`: it stopped answering, or fell below OP, while the
  bus should be in OP) is stopped in the cycle the master finds out: servo off
  (table 6-2 bit 9 clear, controlword 0 = disable voltage, so the drive comes
  back switched off, never enabled by itself), the motion dropped at once (the
  drive cannot be reached, so no ramp: the planned position takes the last
  encoder value and follows it, bit 10 clear, no runaway) and the drive alarm
  flag latched (bit 1: "the drive of the axis is in alarm" is what a user must
  see; a drive that cannot be reached is treated as one in alarm, whatever
  GT_AlarmOn/Off say, since the controller detects it, not the drive's alarm
  signal).  No other bit is set: bit 4 cannot trigger, the plan follows the
  encoder; bits 7/8 name IO inputs.  While the slave stays offline the flag
  cannot be cleared (GT_ClrSts keeps it, GT_Reset sets it again at once) and
  GT_AxisOn returns 1 naming the slave.  Once the slave is back in OP:
  GT_ClrSts (resets the drive fault the loss caused, clears bit 1), then
  GT_AxisOn; before GT_ClrSts, GT_AxisOn returns 1 saying so.  Axes of other
  slaves keep running.  The master reads the slaves' states in the first cycle of
  short working counter, so the axes stop in that cycle; one lost frame (every
  slave still in OP when asked) does not stop a machine.
"""

from __future__ import annotations

import gc
import os
from array import array
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

from gtecat.drives.machine import MachineDescription, load_machine
from gtecat.drives.machine import read_note as machine_read_note
from gtecat.drives.slave import VirtualSlave
from gtecat.eni.errors import EniError
from gtecat.eni.layout import Layout, build_layout
from gtecat.eni.reader import read_eni

from .._attrs import in_array, own_dict
from ..errors import BusError, NoEniError, ParameterError
from ..master.bus import Master
from ..master.clock import ARMS, Clock, ClockMode, hook_list
from ..master.masterlog import MasterLog
from . import clock_options
from .axis import Axis, AxisIo
from .axis_status import AxisStatus
from .bank import AxisBank
from .bank_kernel import _DEFERRED as _KERNEL_DEFERRED
from .bank_kernel import FP_DT as _FP_DT
from .bank_kernel import IN_DT_NS as _IN_DT_NS
from .bank_kernel import IN_MAXC as _IN_MAXC
from .bank_kernel import IN_T_NS as _IN_T_NS
from .bank_kernel import OUT_DONE as _OUT_DONE
from .bank_kernel import OUT_FIN as _OUT_FIN
from .bank_kernel import prebuild as prebuild_kernel
from .bank_kernel import start_deferred as start_kernel_build
from .epoch import EPOCH
from .epoch import changed as readers_changed
from .input_sense import changed as sense_changed
from .resources import install as install_resources

_T = TypeVar("_T")

if TYPE_CHECKING:
    from concurrent.futures import ThreadPoolExecutor

    from .card import Card

_REALTIME = ClockMode.REALTIME  # (looked up once: every wait asks)
_AUTO = ClockMode.AUTO
#: the armed quick cycles' budget where no hook counts them (Clock.quick[11]: never spent)
_NO_BUDGET = 1 << 62


@dataclass
class Options:
    """How a controller is opened (explicit > ``GTECAT_*`` environment > default)."""

    eni: str | None = None
    machine: str | MachineDescription | None = None
    clock: str | None = None
    backend: str | None = None
    iface: str | None = None
    cycle_ms: float | None = None
    call_latency_us: float = 50.0
    log: str | None = None
    op_delay_cycles: int = 10
    #: ENI describing the emulated hardware when it differs from ``eni`` (GTECAT_BUS)
    bus: str | None = None
    #: a pulse card instead of a bus, ``gts:N`` (GTECAT_CARD; :mod:`gtecat.controller.card`)
    card: str | None = None
    #: the MRAM store file (GTECAT_MRAM; default Gecat.mram beside the log, manual 11.8)
    mram: str | None = None
    #: a pcap of the frames the emulated bus stands for (GTECAT_PCAP; gtecat.master.pcap)
    pcap: str | None = None
    #: the vectorised axis bank: auto | on | off (GTECAT_BANK; gtecat.controller.bank)
    bank: str | None = None
    #: False: the ``GTECAT_*`` environment is not read (the options of another card or
    #: core, derived from the first card's: :mod:`gtecat.controller.cards`)
    use_env: bool = True

    def resolved(self) -> Options:
        env = os.environ if self.use_env else {}
        return Options(
            eni=self.eni or env.get("GTECAT_ENI") or "Gecat.eni",
            machine=self.machine if self.machine is not None else env.get("GTECAT_MACHINE"),
            backend=(backend := (self.backend or env.get("GTECAT_BACKEND") or "emulated").lower()),
            # a real NIC needs cycles on the wall clock: realtime unless asked otherwise
            clock=(
                self.clock
                or env.get("GTECAT_CLOCK")
                or ("realtime" if backend == "pysoem" else "auto")
            ).lower(),
            iface=self.iface or env.get("GTECAT_IFACE"),
            cycle_ms=self.cycle_ms,
            call_latency_us=self.call_latency_us,
            log=self.log if self.log is not None else env.get("GTECAT_LOG", "Gecat.log"),
            op_delay_cycles=self.op_delay_cycles,
            bus=self.bus or env.get("GTECAT_BUS"),
            card=self.card or env.get("GTECAT_CARD") or None,
            mram=self.mram or env.get("GTECAT_MRAM"),
            pcap=self.pcap or env.get("GTECAT_PCAP") or None,
            bank=(self.bank or env.get("GTECAT_BANK") or "auto").lower(),
            use_env=self.use_env,
        )


class Controller:
    """One core: clock, master and the per-cycle hooks of the axis layer."""

    # the cycle hooks (lists whose changes, in place or by assignment, are seen:
    # gtecat.master.clock.Hooks); set in __init__
    before_cycle = hook_list("before_cycle")
    pre_cycle = hook_list("pre_cycle")
    post_cycle = hook_list("post_cycle")
    sample = hook_list("sample")
    watch = hook_list("watch")
    before_bank = hook_list("before_bank")
    reset_ns = in_array("origin", 0, "The controller time GT_GetClock counts from (GT_Reset's).")

    #: called with every controller whose bus comes up (``gtecat run --trace`` uses it)
    bus_up_hooks: list[Callable[[Controller], None]] = []  # noqa: RUF012 - a process-wide registry
    #: called with every controller whose bus is about to be brought up: its slaves are
    #: there, the state walk with the InitCmds not yet run (the machine's faults arm here)
    bus_opening_hooks: list[Callable[[Controller], None]] = []  # noqa: RUF012 - likewise

    def __init__(self, options: Options | None = None) -> None:
        # (the clock options checked here too, for a controller made without GT_Open)
        self.options = clock_options.check((options or Options()).resolved())
        try:
            mode = ClockMode(self.options.clock)
        except ValueError:
            raise ParameterError(
                f"clock mode {self.options.clock!r} unknown; use auto, lockstep or realtime"
            ) from None
        if self.options.bank not in ("auto", "on", "off"):
            raise ParameterError(f"bank={self.options.bank!r} unknown; use auto, on or off")
        if self.options.backend not in ("emulated", "pysoem"):
            raise ParameterError(
                f"backend {self.options.backend!r} unknown; use emulated or pysoem"
            )
        if self.options.bank != "off" and self.options.backend == "emulated":
            # a first build of the bank's compiled cycle on this machine runs in a process of
            # its own once the bus is in OP (the bank takes it when it is there)
            prebuild_kernel(defer=True)
        #: what other modules keep per controller (gtecat._attrs.PerObject: capture, IO, ...)
        self.extensions: dict[str, Any] = {}
        cycle_ns = round((self.options.cycle_ms or 1.0) * 1_000_000)
        self.clock = Clock(
            self._cycle,
            cycle_ns=cycle_ns,
            mode=mode,
            call_latency_ns=round(self.options.call_latency_us * 1000),
        )
        #: (the clock's way of many cycles: this one's, unless something replaced it)
        self._own_many = self.clock.run_many = self.run_cycles
        #: the armed quick cycle's kernel call (:meth:`arm_quick`): the function's address,
        #: its three arguments, the cycle time it was armed for, the address of the field
        #: inputs' watch (Backend.fields_watch: 0, none) - kept in _quick_fields - and of the
        #: outputs the cycle takes to the field itself (Backend.outputs_watch: 0, none)
        self._quick_call = array("q", bytes(8 * 7))
        self._quick_fields: Any = None
        self._quick_outs: Any = None
        self._quick_armed: Any = None
        #: the armed quick cycle's book in C (:meth:`_book_in_c`): [0] 1 while the entry that
        #: runs the cycle may count it itself, [1] the kernel's io, [2] the bank's counts,
        #: [3] its drives' (CspBank.counts), [4] the master's, [5] the bank's and [6] this
        #: controller's own dicts (ids), [7] the bank's live rows, [8:11] io's places of the
        #: cycle done, a move ended and the next cycle's time, [11:14] its homing, resting
        #: and switched-off rows, [14] 1 where such a cycle changes no status flag (no
        #: in-position band), [15] 1 where GTE_Wait's C entry may run a wait's cycles on
        #: the armed call and count them so (:meth:`_book_in_c`); _quick_keep holds them
        self.quick_cbook = array("q", bytes(8 * 16))
        self._quick_keep: Any = None
        #: the clock's cycle as this controller gave it (one that wraps it, an inspection
        #: endpoint's, stops the runs of cycles at once: :meth:`_run_cycles`)
        self._own_cycle = self.clock._run_cycle
        # (every cycle and run of cycles goes through the clock: once their time is counted,
        # what the readers kept is stale, their clock value included - epoch.py)
        self.clock.counted = readers_changed
        #: a run of cycles at once is under way (:meth:`run_cycles`): the inspection
        #: endpoint's idle path waits for its end (it runs no request beside cycles)
        self.in_batch = False
        self._cycle_fixed = self.options.cycle_ms is not None
        #: [0] the controller time GT_Reset last counted GT_GetClock from (:attr:`reset_ns`),
        #: in memory compiled code reads: the GT readers' C entries write a ``pClock`` from it
        #: and the clock's time (gtecat.gt.centry.set_clock_ms)
        self.origin = array("q", (0,))
        # the master log is the controller's: its lines carry the controller's time, what
        # GT_GetClock reads (counted from GT_Reset, chapter 13: GT_Reset resets the
        # controller, GT_GetClock reads its clock), so a line and a clock read agree
        self.log = MasterLog(self.options.log, clock_ms=self.clock_ms)
        self.machine = self._load_machine(self.options.machine)
        self.layout: Layout | None = None
        self.master: Master | None = None
        self.backend = None
        self.started = False
        #: why the last GT_InitEcatComm failed (None: it succeeded, or none was made)
        self.init_error: Exception | None = None
        self._links_down = False  # some axis's slave was offline at the last cycle
        #: run first in a cycle, before its time is read: motion programs, whose GT calls
        #: may themselves wait for cycles (GT_AxisOn), so the cycle then starts later
        self.before_cycle: list[Callable[[], None]] = []
        self.pre_cycle: list[Callable[[int, int], None]] = []
        self.post_cycle: list[Callable[[int, int], None]] = []
        self.sample: list[Callable[[int], None]] = []
        #: looked at after every cycle *and* after every run of cycles at once
        #: (:meth:`run_cycles`), so unlike ``sample`` it never stops such a run: for what only
        #: reads the clock now and then (the status line of ``gtecat run``)
        self.watch: list[Callable[[], None]] = []
        #: called before every cycle :meth:`_cycle` runs, before the axis bank's part of it,
        #: and never stopping cycles at once (whose hooks' ``quiet_cycles`` are asked before
        #: every run instead): the fault triggers that watch the machine look at it here
        self.before_bank: list[Callable[[], None]] = []
        #: GT axes (1-based) once the bus is up
        self.axes: dict[int, Axis] = {}
        self._axis_list: list[Axis] = []
        #: the axes the scalar cycle runs (all but the ones the bank runs)
        self._run_axes: list[Axis] = []
        #: the vectorised axis bank (None: off, or no bus yet)
        self.bank: AxisBank | None = None
        self.resources: dict = {}
        self.on_bus_up: list[Callable[[Controller], None]] = []
        self.on_reset: list[Callable[[Controller], None]] = []
        #: the GT fast path's readers of GT_GetDi, GT_GetDiRaw and GT_GetDo, by type (+16, +32),
        #: kept until the next change of the inputs' sense (gtecat.controller.input_sense)
        self.input_plans: dict[int, Any] = {}
        #: the pulse card this controller is (None: an EtherCAT master)
        self.card: Card | None = None
        if self.options.card:
            from .card import open_card

            open_card(self, self.options.card)
        # its attributes are read by every GT call; vars(ctl) elsewhere must not slow them
        own_dict(self)  # (gtecat._attrs; before a cycle thread starts)
        if mode is ClockMode.REALTIME:
            self.clock.start_realtime()

    @staticmethod
    def _load_machine(m: str | MachineDescription | None) -> MachineDescription:
        if isinstance(m, MachineDescription):
            return m
        if not m:
            return MachineDescription()
        return load_machine(m)

    # --- bus --------------------------------------------------------------------------
    def eni_path(self) -> Path:
        return Path(self.options.eni or "Gecat.eni")

    def init_ecat(self) -> Master:
        """Read the ENI, open the backend, scan, compare, bring slaves to SAFEOP.

        OP follows after a few cycles; :attr:`ready` tells when.  A failure is kept in
        :attr:`init_error` (and raised).
        """
        self.init_error = None
        # the bus model is hundreds of thousands of long-lived objects made at once (ENI
        # tree, object dictionaries, PDO codecs): the cyclic collector would walk them
        # again and again while they are made (half the time of a 512-axis bring-up)
        paused = gc.isenabled()
        if paused:
            gc.disable()
        _thaw_bus()
        try:
            master = self._init_ecat()
        except Exception as e:
            self.init_error = e
            raise
        finally:
            if paused:
                gc.enable()
        _freeze_bus(len(master.layout.slaves))
        return master

    def _init_ecat(self) -> Master:
        path = self.eni_path()
        if path.is_dir():
            raise NoEniError(
                folder_message(path, "set GTECAT_ENI to the file (Python: GT_Open(eni=...)), e.g.")
            )
        if not path.is_file():
            raise NoEniError(
                f"no ENI file at {path.resolve()}: set GTECAT_ENI to your ENI (any program: "
                "C, C++, C#, Python), or put it in the working folder as Gecat.eni "
                "(Python may pass GT_Open(eni=...), the command line --eni)"
            )
        banked = self.options.bank != "off" and self.options.backend == "emulated"
        if banked:
            prebuild_kernel(defer=True)  # (as GT_Open; again for options changed since)
        try:
            config = read_eni(path, _eni_cache(path))
        except EniError:
            raise
        layout = build_layout(config)
        if not self._cycle_fixed and config.cycle_time_ns:
            self.clock.cycle_ns = int(config.cycle_time_ns)
        backend = self._make_backend()
        kept = _machine_positions(self.backend)
        if self.master is not None:
            self.terminate_ecat()
        master = Master(layout, backend, log=self.log, op_delay_cycles=self.options.op_delay_cycles)
        master.mailbox_wait = self._mailbox_wait
        master.mailbox_transfer = self._mailbox_transfer
        self.layout, self.backend, self.master = layout, backend, master
        note = machine_read_note(self.machine)
        if note:
            self.log(note)  # (what the drives are built from: two runs' inputs compared)
        self.started = False
        self.axes = {
            ref.axis: Axis(ref.axis, AxisIo.on(master, layout, ref)) for ref in layout.axes
        }
        self._axis_list = list(self.axes.values())
        self._run_axes = self._axis_list
        sense_changed()  # (other axes: their inputs' sense is looked up again)
        self.bank = None
        self._links_down = False
        install_resources(self)  # profile, encoder, status and safety of every axis (chapter 4)
        if _relatch_link_alarms not in self.on_reset:
            self.on_reset.append(_relatch_link_alarms)  # after the resources' own reset
        master.on_opened = lambda: [hook(self) for hook in list(Controller.bus_opening_hooks)]
        master.open()
        _put_back(backend, kept)
        if banked:
            self.bank = AxisBank(self, self.options.bank)
        for hook in [*self.on_bus_up, *Controller.bus_up_hooks]:
            hook(self)
        return master

    def _make_backend(self):
        if self.options.backend == "pysoem":
            from ..master.backends.pysoem_backend import PysoemBackend  # optional extra

            return PysoemBackend(self.options.iface, log=self.log)
        from ..master.backends.emulated import EmulatedBackend

        hardware = None
        if self.options.bus:
            bus_path = Path(self.options.bus)
            if not bus_path.is_file():
                raise NoEniError(f"hardware description {bus_path} not found (GTECAT_BUS)")
            hardware = build_layout(read_eni(bus_path))
        return EmulatedBackend(self.machine, hardware=hardware, pcap=self.options.pcap)

    def require_master(self) -> Master:
        if self.master is None or not self.master.opened:
            raise BusError("EtherCAT communication is not initialised (call GT_InitEcatComm)")
        return self.master

    @property
    def ready(self) -> bool:
        if self.master is None or not self.master.ready:
            return False
        if _KERNEL_DEFERRED:  # the bus is up: a first build of the bank's cycle starts now
            start_kernel_build()
        return True

    def start_ecat(self) -> None:
        """GT_StartEcatComm: start bus motion control; the bus must be in OP."""
        m = self.require_master()
        if not m.ready:
            raise BusError(
                "EtherCAT communication is not fully established yet "
                f"({m.error or 'slaves not yet in OP'}); poll GT_IsEcatReady until it reports 1"
            )
        start_kernel_build()  # (deferred by GT_Open until the bus is up)
        self.started = True

    def terminate_ecat(self) -> None:
        if self.bank is not None:
            self.bank.release_all()
            self.bank = None
            self._run_axes = self._axis_list
        if self.master is not None:
            self.master.terminate()
            self.backend.close()
        self.started = False
        self.init_error = None

    def close(self) -> None:
        self.clock.stop_realtime()
        pool, self._mailbox_pool = self._mailbox_pool, None
        if pool is not None:
            pool.shutdown(wait=True)  # (a transfer under way ends by its own timeout)
        self.terminate_ecat()
        self.log.close()

    # --- the cycle --------------------------------------------------------------------------
    def _cycle(self) -> None:
        if self._owed is not None:  # (the hooks count the cycle themselves: settled first)
            self.settle_hooks()
        for g in self.before_cycle:
            g()  # (a motion program's GT call may wait for cycles here, as the application's)
        self.cycling = True
        try:
            for g in self.before_bank:
                g()
            t = self.clock.now_ns
            dt = self.clock.cycle_ns
            bank = self.bank
            if bank is not None:
                bank.cycle(t, dt)  # the axes it runs, whole; the ones it lets go run below
            for f in self.pre_cycle:
                f(t, dt)
            run = self._axis_list if bank is None else self._run_axes
            for ax in run:
                ax.pre(t, dt)
            if self.master is not None:
                self.master.cycle(t, dt)
                if self.master.offline or self._links_down:
                    self._watch_links(self.master.offline)
            for ax in run:
                ax.post(t, dt)
            for f in self.post_cycle:
                f(t, dt)
            for f in self.sample:
                # stamped when the cycle's values become visible (= GT_GetClock after it)
                f(t + dt)
            for w in self.watch:
                w()
        finally:
            self.cycling = False

    #: a cycle is running (:meth:`_cycle`, after its ``before_cycle`` hooks): an SDO made
    #: inside it (a touch probe read by SDO) cannot wait for cycles
    cycling = False

    def _mailbox_wait(self, ms: float) -> None:
        """A lost SDO answer: the master's mailbox timeout passes, cycles running
        (:mod:`gtecat.master.bus` "Lost SDO answer"); not inside a cycle, where no cycle
        can run (the next ones come after it anyway)."""
        if not self.cycling:
            self.clock.advance(ms)

    #: the worker thread of mailbox transfers on a wire in virtual time (made at the first)
    _mailbox_pool: ThreadPoolExecutor | None = None

    def _mailbox_transfer(self, transfer: Callable[[], _T]) -> _T:
        """A mailbox transfer that waits for a slave on a wire (the pysoem backend): it takes
        the time the slave takes to answer, and a lost answer the master's mailbox timeout
        (700 ms).  A real controller's firmware keeps the cyclic exchange going while a
        mailbox transfer is pending, so the cycles run meanwhile, one per bus cycle of the
        wall clock, and the clock counts those that ran (:mod:`gtecat.master.bus` "Mailbox
        on a wire"): the axes move on and the slaves' watchdogs stay fed.

        - realtime: the cycle thread runs them; the call lets go of the cycle lock while it
          waits (the transfer touches the mailbox only, never the process image);
        - lockstep and auto: the transfer waits in a worker thread while this one runs a
          cycle each time one bus cycle of wall time has passed;
        - inside a cycle (an SDO a cycle's hook makes) no cycle can run: the transfer alone.
        """
        clock = self.clock
        if self.cycling or clock.in_cycle_thread:
            return transfer()
        if clock.threaded:
            with clock.unlocked():
                return transfer()
        # (imported here: only a wire's backend waits so; every other process skips them)
        from concurrent import futures
        from concurrent.futures import ThreadPoolExecutor

        pool = self._mailbox_pool
        if pool is None:
            pool = self._mailbox_pool = ThreadPoolExecutor(1, thread_name_prefix="gtecat-mbx")
        future = pool.submit(transfer)
        clock.pace(lambda seconds: bool(futures.wait((future,), timeout=seconds).done))
        return future.result()  # (or the transfer's exception)

    def run_cycles(self, n: int) -> int:
        """Up to ``n`` cycles at once, when nothing but the axis bank's compiled cycle has
        anything to do in them: every axis claimed by the bank, no hook (or only hooks that
        say they stay quiet that long: :func:`_quiet_way`), the bus steady
        (:meth:`Master.steady`: a plain exchange would change nothing).  Each cycle is the
        one :meth:`_cycle` would run, bit for bit; the clock counts the time.  Returns the
        cycles run, 0 when the next one must go through :meth:`_cycle`.

        :attr:`in_batch` is set before the clock's cycle is compared with ours: an endpoint
        that wraps the cycle (so no run starts after that) and then sees it False knows no
        run is under way, however long the compiled kernel holds this thread."""
        self.in_batch = True
        try:
            done = self._run_cycles(n)
        finally:
            self.in_batch = False
        if done:
            for w in self.watch:
                w()
        return done

    def _run_cycles(self, n: int) -> int:
        if self._owed is not None:
            self.settle_hooks()
        bank = self.bank
        if (
            bank is None
            or bank.kernel is None
            or self.before_cycle
            or self.sample
            or self._links_down
            or self.clock._run_cycle is not self._own_cycle
        ):
            return 0
        if bank._opened or bank._frozen_call >= 0:
            return 0  # (a row opened for a call steps in Python: AxisBank.call_opened)
        settled = bank.dirty or bank._stale or (bank._countdown <= 1 and bank.n_alive != bank.n)
        if settled:
            bank.settle()  # what the next cycle does first: claim axes given back
        if self._run_axes:
            return 0
        n = min(n, self.BATCH_CYCLES)
        hooks = ()
        if self.pre_cycle or self.post_cycle:
            hooks = self._hook_ways()
            n = self._hooks_quiet(n)
            if n <= 0:
                return 0
        master = self.master
        if master is None or master.on_cycle:  # (the master's hooks: not kept, asked here)
            return 0
        clock = self.clock
        seen = self._steady_marks(master, settled)
        if seen is None:
            return 0
        done = bank.run_cycles(clock.now_ns, clock.cycle_ns, n)
        master.cycles += done
        if done:
            # the bus stays steady through the bank's runs: the next run asks again only when
            # something else happened in between (its marks are not these plus this run's)
            self._steady_seen = (seen[0] + 1, seen[1] + done, seen[2], seen[3])
            for _, passed in hooks:
                if passed is not None:
                    passed(done)
        return done

    def _steady_marks(self, master: Any, settled: bool = False) -> tuple[int, ...] | None:
        """The steady verdict's marks as they stand (readers' epoch, clock cycles, AL and
        outside changes of the slaves), or None where the bus is not steady: the last
        verdict (:attr:`_steady_seen`) stands while the marks are its own, else (or
        ``settled``: the bank just settled) :meth:`Master.steady` is asked.  A field write
        the slaves could not count (the buffer protocol) is counted first, so it moves them."""
        seen = (EPOCH.n, self.clock.cycles, VirtualSlave.al_changes, VirtualSlave.outside_changes)
        if not settled and seen == self._steady_seen:
            master.backend.look_at_fields()  # (steady() looks itself)
            if seen[3] == VirtualSlave.outside_changes:
                return seen
            seen = (*seen[:3], VirtualSlave.outside_changes)
        return seen if master.steady() else None

    def due_cycle(self, pending: int) -> bool:
        """The auto clock's one due cycle, run the quick way: ``pending`` (the host latency
        accumulated with this call's, between one and two cycle times) reached a cycle on a
        clock alone, the bank's compiled kernel runs every axis, no hook but quiet ones and
        the bus is steady.  Then the cycle is exactly the one :meth:`run_cycles` runs for one
        cycle, and its time is counted as :meth:`Clock.advance_ns` counts it - in one call,
        without the layers between them (at ~20 calls a cycle they were most of a polling
        call's cost).  False: nothing ran, nothing was counted; the caller takes the
        general way (:meth:`Clock.advance_ns`).

        Everything :meth:`_run_cycles` asks at every run is asked here too, in the same
        terms: the hooks' lists as they stand, the bank's flags, the kernel's binding, and
        the steady verdict's marks (:attr:`_steady_seen`; :meth:`Master.steady` itself where
        they moved).  A cycle the kernel declines goes the clock's one-cycle way
        (:meth:`Clock.cycle`), as the general way goes after it.  A cycle that ran whole
        arms the next one for the GT readers' C entries (:meth:`arm_quick`).  A
        ``pre_cycle`` or ``post_cycle`` hook that says it is quiet in the next cycle
        (:func:`_quiet_way`: the fault injector waiting for a time, smart homing with no
        homing running) lets it run here as :meth:`_run_cycles` runs one cycle, and the
        entries run as many after it as the hooks say they stay quiet (:meth:`quick_book`);
        the hooks count them (``cycles_passed``) when Python next looks
        (:meth:`settle_hooks`).  This way takes them as the entries do: while the cycle
        armed after the last one stands (nothing else happened since) and the budget is
        not spent, the hooks are not asked again."""
        clock = self.clock
        q = clock.quick
        quiet = False
        if self._owed is not None:
            if q[11] > 0 and q[4] == EPOCH.n and q[5] == ARMS[0]:
                quiet = True  # (the budget says so for this cycle)
            else:
                self.settle_hooks()
        k = self._quick_kernel(quiet)
        if k is None:
            return False
        if self._steady_marks(self.master) is None:  # (_quick_kernel: a master)
            return False
        _one_cycle(k, clock)
        # (in_batch before the clock's cycle is compared with ours, as in run_cycles)
        self.in_batch = True
        try:
            if clock._cycle_fn is not self._own_cycle:  # (an endpoint wrapped it)
                return False
            q[0] = pending - q[2]
            # nothing armed while it runs, as the entries' quick cycle: only its book arms the
            # next one (a cycle declined went the general way, which may release rows the
            # kernel would then leave standing, their drives not stepped)
            q[4] = 0
            if quiet:
                q[11] -= 1  # (one of the budget: the entries' count)
            elif self._unhooked != ARMS[0]:  # (hooked: they count this cycle as owed)
                self._owed = (q[10], self._passes())
                q[11] = 0  # (the budget is asked after it)
            rc = k.run_fn(*k._args)
        finally:
            self.in_batch = False
        self.quick_book(rc, False)  # (arms the next one again where it may: io[T_NS] too)
        if q[4]:  # (quick_book armed it: with all else that it relies on, taken now)
            self.arm_quick(k)
        self._armed_left = -1  # (calls make cycles due: a wait arms the next one)
        return True

    def _quick_kernel(self, quiet: bool = False) -> Any:
        """The bank's kernel where a quick cycle (:meth:`due_cycle`) may run: what
        :meth:`_run_cycles` and :meth:`AxisBank.run_cycles` ask, no hook but ``pre_cycle`` and
        ``post_cycle`` ones quiet in the next cycle (:meth:`due_cycle`; ``quiet``: their
        budget says so); else None."""
        bank = self.bank
        master = self.master
        if (
            bank is None
            or master is None
            or self._links_down
            or self._run_axes
            or self.clock.counted is not readers_changed
        ):
            return None
        hooked = False
        if self._unhooked != ARMS[0]:  # (no hook since: every change of them is a new one)
            if self.before_cycle or self.sample or self.watch or master.on_cycle:
                return None
            hooked = bool(self.pre_cycle or self.post_cycle)
            if not hooked:
                self._unhooked = ARMS[0]
        k = _kernel_runs(bank, master, self.clock.quick[2])
        if k is None:
            return None
        if hooked and not quiet:  # (asked last, as _run_cycles asks them after the bank's flags)
            for ask, _ in self._hook_ways():
                if ask(1) < 1:
                    return None
        return k

    def _passes(self) -> tuple[Callable[[int], None], ...]:
        """The hooks' ``cycles_passed`` (:meth:`_hook_ways`), those that have one."""
        self._hook_ways()
        return self._hooks_seen[3]  # type: ignore[index]

    def settle_hooks(self) -> None:
        """Count for the ``pre_cycle`` and ``post_cycle`` hooks the quick cycles run since
        they said they were quiet (:meth:`quick_book`: the GT readers' C entries run them
        without Python): ``cycles_passed(n)``, as after a run of ``n`` cycles at once, to
        the hooks that said so.  Asked before anything asks the hooks again or runs a cycle
        (:meth:`_cycle`, :meth:`_run_cycles`, :meth:`due_cycle`), and by a hook's owner
        before it reads what they count (the fault injector: adding or clearing a fault).
        The armed cycle is disarmed with it: cycles from now count themselves."""
        owed = self._owed
        if owed is None:
            return
        self._owed = None
        q = self.clock.quick
        q[4] = 0  # (its budget left as it is: what the entries spent of it stays seen)
        n = q[10] - owed[0]
        if n:
            for passed in owed[1]:
                passed(n)

    def _quiet_budget(self) -> int:
        """After a quick cycle with quiet hooks (:meth:`quick_book`): how many of the next
        cycles every hook says it stays quiet in, as :meth:`_run_cycles` asks before a run
        of cycles at once (at most :attr:`BATCH_CYCLES`, as such a run), the cycles run so
        far counted first; the entries may run that many, owed to the hooks from now."""
        self.settle_hooks()
        n = self._hooks_quiet(self.BATCH_CYCLES)
        if n > 0:
            self._owed = (self.clock.quick[10], self._passes())
        return n

    def _hooks_quiet(self, n: int) -> int:
        """How many of the next ``n`` cycles every ``pre_cycle`` and ``post_cycle`` hook
        says it stays quiet in (:func:`_quiet_way`; 0: some hook must run in the next)."""
        for quiet, _ in self._hook_ways():
            q = quiet(n)
            if q < n:  # (an answer above n stands for n)
                if q <= 0:
                    return 0
                n = q
        return n

    def quick_book(self, rc: int, book: bool = True) -> None:
        """What follows the kernel's run of a quick cycle (:meth:`due_cycle`, or a GT
        reader's C entry that ran the armed cycle: :meth:`arm_quick`), the clock's lock held
        and the pending latency already less the cycle: ``rc`` the kernel's code.  The
        bookkeeping of :meth:`AxisBank.run_cycles` and :meth:`_run_cycles` for one cycle,
        the clock's count, the readers' epoch; a declined cycle runs the numpy way.  Where
        the next cycle may be a quick one too, it is armed again for the new epoch (what
        else was armed stands: the entry that ran this one found it so), its book in C made
        anew unless ``book`` is False (:meth:`due_cycle`: :meth:`arm_quick` makes it)."""
        clock = self.clock
        bank = self.bank
        k = bank.kernel  # type: ignore[union-attr]
        io = k._io
        if not io[_OUT_DONE]:  # declined: the numpy cycle runs it (bank.run_cycles's 0)
            clock.cycle()
            return
        again = bank.quick_cycle_done(k, rc)  # type: ignore[union-attr]
        self.master.cycles += 1  # type: ignore[union-attr]
        epoch = EPOCH.n + 1
        clock.cycles = cycles = clock.cycles + 1
        self._steady_seen = (epoch, cycles, VirtualSlave.al_changes, VirtualSlave.outside_changes)
        q = clock.quick
        clock.now_ns = now = clock.now_ns + q[2]
        EPOCH.n = epoch  # (clock.counted: readers_changed)
        if again:
            if self._owed is None:
                q[11] = _NO_BUDGET
            elif q[11] <= 0 or io[_OUT_FIN]:
                # hooked, the budget spent (or a move ended, where a run of cycles at once
                # stops and asks again): as many as the hooks stay quiet in from here
                q[11] = self._quiet_budget()
                if q[11] <= 0:
                    return
            io[_IN_T_NS] = now  # (the rest of the kernel's call as this one's)
            q[4] = epoch
            if book:
                self._book_in_c(k)

    def _book_in_c(self, k: Any) -> None:
        """Whether the entry that runs the next armed cycle may count it itself, in C
        (gtecat.gt.centry's quick cycle): where this book's Python would do no more than
        count - the cycle not declined, no move ended (the entry looks at both), nothing
        settled before it, no drive's input to count, the following-error timers looked at
        already where there are any, no table for Python to fill - the entry adds to the
        counts (the bank's,
        its drives', the master's, the clock's), makes the bank's lists anew, sets the steady
        verdict's marks and the readers' epoch, and arms the next cycle, as this book does.
        These conditions change only with the epoch (a call, a cycle the general way), which
        disarms the cycle; the book is made again at every arm."""
        b = self.quick_cbook
        bank = self.bank
        csp = bank.csp  # type: ignore[union-attr]
        master = self.master
        if (
            bank._settled  # type: ignore[union-attr]
            or bank._declined  # type: ignore[union-attr]
            or csp._din_safe
            or (csp.any_fe and not csp.fe_running)  # (set already: it stays so)
            or (bank.n_moving and not bank._c_fill)  # type: ignore[union-attr]
            or master is None
        ):
            b[0] = 0
            return
        keep = (k, bank.counts, csp.counts, master.counts, vars(bank), vars(self))  # type: ignore[union-attr]
        self._quick_keep = keep
        b[0] = 0  # (nothing to book with while it is being made)
        b[1] = k._args[1]
        b[2], b[3], b[4] = (
            keep[1].buffer_info()[0],
            keep[2].buffer_info()[0],
            keep[3].buffer_info()[0],
        )
        b[5], b[6] = id(keep[4]), id(keep[5])
        b[7] = bank.n_alive  # type: ignore[union-attr]
        b[8], b[9], b[10] = _OUT_DONE, _OUT_FIN, _IN_T_NS
        b[11], b[12], b[13] = bank.n_hm, bank.n_rest, bank.n_frz  # type: ignore[union-attr]
        # (no in-position band: a cycle that ends no move changes no status flag, so the
        # status words the bank made stand for the next epoch: AxisBank._sts_epoch)
        b[14] = not bank.any_band  # type: ignore[union-attr]
        self._c_waits = self._waits_in_c(bank)
        b[15] = self.QUICK_WAIT and self._c_waits
        b[0] = 1

    def _waits_in_c(self, bank: Any) -> bool:
        """Whether GTE_Wait's C entry (gtecat.gt.centry's wait) may run a wait's cycles
        on the armed call, as :meth:`wait_quick` would run them where its quick way is on
        (its checks that the armed cycle's do not make: the clock alone, an EtherCAT master,
        the runs of cycles as written here)."""
        return (
            self.card is None
            and bool(self.clock.quick[3])
            and self.clock.run_many is self._own_many
            and self._own_many.__func__ is _RUN_CYCLES
            and type(bank).run_cycles is _BANK_RUN_CYCLES
            and "run_cycles" not in bank.__dict__
        )

    def arm_quick(self, k: Any) -> None:
        """Arm the next due cycle for the GT readers' C entries (gtecat.gt.centry): right
        after a quick cycle that ran whole, everything :meth:`_quick_kernel` asked holds,
        and the bus is steady (the marks of :attr:`_steady_seen` are now's).  The entries
        run it themselves - the clock's lock taken, the kernel's cycle called, then
        :meth:`quick_book` - while the readers' epoch, the slaves' AL and outside changes,
        the IO slaves' field inputs (compared with a copy: a write through the buffer
        protocol is not counted), the generation of :data:`~gtecat.master.clock.ARMS` (a
        hook added or replaced anywhere, a cycle wrapped) and the clock's cycle time are
        the ones armed here.  Every other change that could make :meth:`_quick_kernel` say no comes
        with a new epoch: a GT call of the table, a cycle the general way, a fault, an
        endpoint's request, a claim or a release of the bank."""
        q = self.clock.quick
        q[4] = 0  # (nothing armed while it is being armed)
        call = self._quick_call
        if self._quick_armed is not k:  # (a kernel's function and arguments stay its own)
            call[0] = k.run_address
            call[1], call[2], call[3] = k._args
            self._quick_armed = k  # (its arrays live while the entries may call it)
            q[8] = call.buffer_info()[0]
        call[4] = q[2]  # (the kernel's call as due_cycle's: io and fp set for this cycle time)
        # the field inputs as the steady verdict saw them: a write the slaves could not count
        # (through the buffer protocol) makes the entries decline the armed cycle
        watch = self._quick_fields = self.master.backend.fields_watch()  # type: ignore[union-attr]
        call[5] = 0 if watch is None else watch[0]
        # the plain IO slaves' outputs the entries copy to the field before the kernel's
        # cycle: a GT_ write that changes only them leaves the cycle armed (the readers'
        # epoch grows all the same)
        outs = self._quick_outs = self.master.backend.outputs_watch()  # type: ignore[union-attr]
        call[6] = 0 if outs is None else outs[0]
        q[5] = ARMS[0]
        q[6] = VirtualSlave.al_changes
        q[7] = VirtualSlave.outside_changes
        self._book_in_c(k)
        q[4] = EPOCH.n
        self._armed_left = q[11]

    def _hook_ways(self) -> tuple[tuple[Callable[[int], int], Any], ...]:
        """Per ``pre_cycle`` hook, then per ``post_cycle`` hook: how many of the next cycles
        it is quiet in (``n`` -> :func:`_quiet_way`), and its object's ``cycles_passed``
        (None: it has none); looked up once while the hooks stay the same."""
        cached = self._hooks_seen
        # (the lists compared as they stand: a hook added or taken away in place is seen)
        if cached is not None and cached[0] == self.pre_cycle and cached[1] == self.post_cycle:
            return cached[2]
        pre = (*self.pre_cycle, *self.post_cycle)
        ways = tuple(
            (
                _quiet_way(f),
                getattr(getattr(f, "__self__", None), "cycles_passed", None),
            )
            for f in pre
        )
        passes = tuple(p for _, p in ways if p is not None)  # (for _passes)
        self._hooks_seen = (list(self.pre_cycle), list(self.post_cycle), ways, passes)
        return ways

    #: the most cycles one call of :meth:`run_cycles` runs (a long wait stays interruptible)
    BATCH_CYCLES = 1000
    #: what the next run of cycles finds when nothing but runs of cycles happened since the
    #: last one (:meth:`_run_cycles`): the readers' epoch grown once by the clock's count of
    #: the run (``Clock.counted``), the clock's cycles, the slaves' AL changes and outside
    #: changes as they were.  Then the bus is as steady as the last run found it: the bank's
    #: compiled cycles touch none of what :meth:`Master.steady` looks at (the IO slaves'
    #: areas, the states, the hooks), and every other change makes one of the four grow
    #: (a GT call, a raw write, a fault, an endpoint request, an AL change, a change from
    #: outside a slave's cycle: its field inputs or wires, an emergency queued) or is asked
    #: at every run (the master's ``on_cycle`` hooks).
    _steady_seen: tuple[int, int, int, int] = (0, 0, 0, 0)
    #: the generation of :data:`~gtecat.master.clock.ARMS` in which no cycle hook was
    #: found (:meth:`_quick_kernel`; a hook added, taken away or replaced, a master made
    #: anew: a new generation)
    _unhooked = 0
    #: the pre_cycle and post_cycle hooks last looked at, their ways and their
    #: ``cycles_passed`` (:meth:`_hook_ways`)
    _hooks_seen: tuple[list[Any], list[Any], Any, Any] | None = None
    #: quick cycles owed to the quiet hooks (:meth:`settle_hooks`): the clock's cycles when
    #: they last counted, and their ``cycles_passed``; None: nothing owed (no hook, or the
    #: cycles count themselves)
    _owed: tuple[int, tuple[Callable[[int], None], ...]] | None = None
    #: the armed cycles' budget as :meth:`arm_quick` left it, -1 after a due cycle ran
    #: here: where the entries spent none of it since, a wait arms again only a few times
    #: in a row (:meth:`_arm_after_wait`)
    _armed_left = -1
    #: the armings after waits in a row that found none of the arming before spent
    #: (:meth:`_arm_after_wait`), and how many such a wait still makes
    _idle_arms = 0
    IDLE_ARMS = 3

    def _watch_links(self, offline: dict[int, str]) -> None:
        """Stop the axes of offline slaves (module docstring "Comm loss"), every cycle
        while they are offline; mark the others reachable again."""
        down = False
        bank = self.bank
        for ax in self._axis_list:
            reason = offline.get(ax.io.slave, "")
            if reason:
                down = True
                if bank is not None:  # (a row of the bank: its objects speak for it from now)
                    bank.release_axis_object(ax)
                if not ax.link_lost:
                    self.log(
                        f"Axis {ax.number}: {reason}; motion stopped, servo off, "
                        "alarm set (GT_GetSts bit 1)."
                    )
                ax.lose_link(reason)
                if ax.motion is not None:
                    ax.motion.latched |= int(AxisStatus.ALARM)  # (the word stays a plain int)
            elif ax.link_lost:
                ax.link_lost = ""  # reachable again; bit 1 stays until GT_ClrSts
                self.log(f"Axis {ax.number}: slave {ax.io.slave} back; GT_ClrSts, GT_AxisOn.")
        self._links_down = down

    # --- axes -----------------------------------------------------------------------------
    def axis(self, n: int) -> Axis:
        """GT axis ``n`` (1-based); ParameterError (7) when it does not exist."""
        try:
            n = int(n)
        except (TypeError, ValueError):
            raise ParameterError(f"axis={n!r} is not an integer") from None
        ax = self.axes.get(n)
        if ax is None:
            if not self.axes:
                raise ParameterError(
                    f"axis {n}: no EtherCAT axis exists (bus not initialised or no CiA-402 "
                    "slave in the ENI)"
                )
            raise ParameterError(f"axis {n} out of range 1..{max(self.axes)}")
        return ax

    # --- time -------------------------------------------------------------------------------
    def reset_clock(self) -> None:
        """GT_Reset: GT_GetClock, and the master log's time with it, count from now; the log
        says so, as its time goes back to 0 there."""
        if self.reset_ns != self.clock.now_ns:
            was = self.clock_ms()
            self.log(f"GT_Reset: the controller's clock counts from 0 again (it read {was} ms).")
        self.reset_ns = self.clock.now_ns

    def clock_ms(self) -> int:
        return (self.clock.now_ns - self.reset_ns) // 1_000_000

    #: called between the slices of a long wait (:meth:`wait_ms`), None: nothing.  The
    #: controller server sets it to let other clients' calls in (it releases its lock for
    #: a moment); a hook may run GT calls, whose time counts toward the wait.
    slice_hook: Callable[[], None] | None = None
    #: controller time one slice of a wait runs before the hook is called
    WAIT_SLICE_NS = 100_000_000

    def wait_ms(self, ms: float) -> None:
        """GTE_Wait: let ``ms`` of controller time pass, in any clock mode.

        Virtual time runs in slices of :attr:`WAIT_SLICE_NS` up to the controller time
        the wait ends at: between slices, a KeyboardInterrupt (Ctrl-C) reaches the
        caller, and :attr:`slice_hook` serves others (a day's wait no longer holds every
        native client for the hour it takes to compute).  Without a hook the cycles run
        are exactly those of one advance of ``ms``.
        """
        if ms < 0:
            raise ParameterError("wait time must be >= 0")
        clock = self.clock
        total = round(ms * 1_000_000)
        e0 = EPOCH.n
        if total <= self.WAIT_SLICE_NS and clock.mode is not _REALTIME and self.wait_quick(total):
            return
        if clock.mode is _REALTIME or total <= self.WAIT_SLICE_NS:
            clock.advance_ns(total)
        else:
            end = clock.now_ns + clock._pending_ns + total
            while True:
                left = end - (clock.now_ns + clock._pending_ns)
                if left <= 0:
                    break
                clock.advance_ns(min(left, self.WAIT_SLICE_NS))
                hook = self.slice_hook
                if hook is not None and left > self.WAIT_SLICE_NS:
                    hook()
        if clock.mode is not _REALTIME:
            self._wait_end(e0)

    #: waits take :meth:`wait_quick` where it applies (False: always the general way, which
    #: the tests compare it with)
    QUICK_WAIT = True
    #: GTE_Wait has its C entry (gtecat.gt.fast sets it where the entry is made): a wait
    #: runs there on the cycle armed for the readers' entries, so a wait arms the next one
    #: on the lockstep clock too (:meth:`_arm_after_wait`), and where nothing but reads
    #: happened since the last wait
    C_WAITS = False
    #: the readers' epoch the last wait in Python left (:meth:`_wait_end`)
    _wait_epoch = -1
    #: the last arming found that the C entry's waits may run on it (:meth:`_waits_in_c`;
    #: its book says so where the quick way is on too)
    _c_waits = False

    def wait_quick(self, total: int) -> bool:
        """A wait of ``total`` ns (at most :attr:`WAIT_SLICE_NS`) on the lockstep or the auto
        clock, in its common case, in one call: every axis in the bank's compiled kernel, no
        hook but quiet ones, the bus steady as the last run of cycles left it.  Then the wait
        is exactly :meth:`wait_ms`'s general way - :meth:`Clock.advance_ns`, whose first run
        of cycles (:meth:`run_cycles`, :meth:`AxisBank.run_cycles`) is this one's, then
        :meth:`_arm_after_wait` - with what each of those layers asks and books done once,
        inline: the kernel called for the run's cycles, the counts added in their arrays.  A
        field application paced by waits (a pass every controller millisecond) paid those
        layers at every wait.  Where the run stops short (a move ended, a cycle the kernel
        declines) or the bus needs a look, the rest of the wait goes the clock's general way
        from there, as it would have.  ``pre_cycle`` and ``post_cycle`` hooks that say they
        stay quiet (:func:`_quiet_way`: a fault armed for later, smart homing idle or in a
        Trap leg) are asked and told as :meth:`_run_cycles` asks and tells them: the quick
        cycles owed to them counted first (:meth:`settle_hooks`), the run no longer than
        every hook stays quiet, its cycles counted to them (``cycles_passed``); the cycle a
        hook is due in and the rest of the wait go the general way, so a fault fires in the
        same cycle.  False: nothing was done (another hook, an axis out of the bank, a link
        down, a bank to settle, a clock shared or wrapped, ...); the caller takes the
        general way."""
        clock = self.clock
        q = clock.quick
        bank = self.bank
        master = self.master
        e0 = EPOCH.n
        if (
            not self.QUICK_WAIT
            or bank is None
            or master is None
            or not q[3]  # (a clock's group shares the time: Clock.advance_ns)
            or self._links_down
            or self._run_axes
            or clock._cycle_fn is not self._own_cycle
            or clock.counted is not readers_changed
            or clock.run_many is not self._own_many
            or self._own_many.__func__ is not _RUN_CYCLES  # (its layers as written here)
        ):
            return False
        hooked = False
        if self._unhooked != ARMS[0]:  # (no hook since: every change of them is a new one)
            if self.before_cycle or self.sample or self.watch or master.on_cycle:
                return False
            hooked = bool(self.pre_cycle or self.post_cycle)  # (asked below, as _run_cycles)
            if not hooked:
                self._unhooked = ARMS[0]  # (as _quick_kernel finds it)
        dt_ns = q[2]
        if (
            type(bank).run_cycles is not _BANK_RUN_CYCLES  # (a run wrapped: it runs it)
            or "run_cycles" in bank.__dict__
        ):
            return False
        k = _kernel_runs(bank, master, dt_ns)  # (and nothing for AxisBank.settle to do)
        if k is None:
            return False
        csp = bank.csp
        # the steady verdict's marks as _steady_marks reads them: the last run's, or the
        # general way asks Master.steady
        seen = (EPOCH.n, q[10], VirtualSlave.al_changes, VirtualSlave.outside_changes)
        if seen != self._steady_seen:
            return False
        pending = q[0] + total  # (Clock.advance_ns)
        q[0] = pending
        if pending >= dt_ns:
            done = 0
            n = pending // dt_ns
            if n > self.BATCH_CYCLES:
                n = self.BATCH_CYCLES
            passes: tuple[Callable[[int], None], ...] = ()
            # the cycle armed for the readers' C entries stands (nothing but their reads and
            # quick cycles since it was armed) and the hooks' quiet budget holds the whole run:
            # the hooks are not asked, they said so (the entries and due_cycle run such cycles
            # on it); the run is counted to them with what they are owed, after it
            spent = (
                hooked
                and self._owed is not None
                and q[11] >= n
                and q[4] == seen[0]
                and q[5] == ARMS[0]
            )
            self.in_batch = True  # (run_cycles)
            try:
                if self._owed is not None and not spent:  # (_run_cycles: counted first)
                    self.settle_hooks()
                if hooked and not spent:
                    # as many as every hook stays quiet in (_run_cycles): a hook due sooner
                    # runs in the general way's cycle, as without this one
                    n = self._hooks_quiet(n)
                    passes = self._hooks_seen[3]  # type: ignore[index]  # (_passes: looked up)
                    # (asking may look at the machine: the marks as _run_cycles reads them)
                    seen = self._steady_marks(master) if n > 0 else None  # type: ignore[assignment]
                else:
                    master.backend.look_at_fields()  # (_steady_marks)
                    if seen[3] != VirtualSlave.outside_changes:
                        seen = (*seen[:3], VirtualSlave.outside_changes)
                        if not master.steady():
                            seen = None  # type: ignore[assignment]
                if seen is not None:
                    # Kernel.run for the run's cycles (bank.run_cycles), then its book and
                    # _after_kernel's (_wait_book)
                    io = k._io
                    io[_IN_T_NS] = q[9]
                    io[_IN_DT_NS] = dt_ns
                    io[_IN_MAXC] = n
                    k._fp[_FP_DT] = csp._dt
                    done = self._wait_book(k, k.run_fn(*k._args), seen, passes)
            finally:
                self.in_batch = False
            # (_wait_counted, inline: a wait's every call in Python counts)
            if done:  # (Clock.advance_ns's count of a run)
                q[0] = pending - done * dt_ns
                q[10] += done
                q[9] += done * dt_ns
                EPOCH.n += 1  # (clock.counted)
                if spent:  # (the owed cycles and the run's: cycles_passed, the arming off)
                    self.settle_hooks()
            else:  # (Clock.advance_ns's cycle where no run could start)
                q[0] = pending - dt_ns
                clock.cycle()
            if q[0] >= dt_ns:
                clock.advance_ns(0)  # the rest of the wait the general way, from here
        if self.C_WAITS:
            self._wait_end(e0)
        elif (  # (_wait_end's look on the auto clock, inline: a loop of waits alone arms nothing)
            clock.mode is _AUTO
            and q[4] != EPOCH.n
            and (q[11] != self._armed_left or self._idle_arms < self.IDLE_ARMS)
        ):
            self._arm_after_wait()
        return True

    def _wait_book(
        self, k: Any, rc: int, seen: tuple[int, ...], passes: tuple[Callable[[int], None], ...]
    ) -> int:
        """The book of a wait's run of cycles the kernel ran (:meth:`wait_quick`, or
        GTE_Wait's C entry: :meth:`waited`; ``rc`` its code, ``seen`` the steady verdict's
        marks before it): :meth:`AxisBank.run_cycles`'s and :meth:`_after_kernel`'s, the
        counts in their arrays (AxisBank._COUNTS' order), the hooks told (``passes``), as
        :meth:`_run_cycles` tells them.  The cycles it ran."""
        # (as quick_cycle_done: a count that stays - a zero added, a flag already so - is
        # not written)
        bank = self.bank
        csp = bank.csp  # type: ignore[union-attr]
        io = k._io
        done = io[_OUT_DONE]
        if rc:
            bank._declined = done > 0  # type: ignore[union-attr]
        if done:
            c = bank.counts  # type: ignore[union-attr]
            if bank._settled:  # type: ignore[union-attr]  # (its count of the first cycle: in settle)
                c[0] -= done - 1
                bank._settled = False  # type: ignore[union-attr]
            else:
                c[0] -= done
            c[1] -= done
            bank._lists = {}  # type: ignore[union-attr]
            c[9] = 0
            csp.counts[0] += done
            if csp._din_safe:
                csp._din_safe = 0
            if csp.any_fe:
                csp.fe_running = True
            if io[_OUT_FIN]:
                bank.n_moving = int(np.count_nonzero(bank.moving))  # type: ignore[union-attr]
                bank._count_standing()  # type: ignore[union-attr]
            c[2] += bank.n_alive * done  # type: ignore[union-attr]
            c[3] += done
            c[4] += done
            c[5] += done
            if bank.n_hm:  # type: ignore[union-attr]
                c[6] += bank.n_hm * done  # type: ignore[union-attr]
            if bank.n_rest:  # type: ignore[union-attr]
                c[7] += bank.n_rest * done  # type: ignore[union-attr]
            if bank.n_frz:  # type: ignore[union-attr]
                c[8] += bank.n_frz * done  # type: ignore[union-attr]
            self.master.counts[0] += done  # type: ignore[union-attr]
            self._steady_seen = (seen[0] + 1, seen[1] + done, seen[2], seen[3])
            for passed in passes:  # (_run_cycles: the hooks count the run)
                passed(done)
        return done

    def _wait_counted(self, done: int, pending: int, spent: bool) -> None:
        """After a wait's run of cycles (:meth:`_wait_book`; ``pending`` the latency with
        the wait's time before it): the clock's count of the run as
        :meth:`Clock.advance_ns` counts it - or its one cycle where no run could start -,
        the hooks' owed cycles counted where the run was taken on their budget
        (``spent``), and the rest of the wait the clock's general way."""
        clock = self.clock
        q = clock.quick
        dt_ns = q[2]
        if done:  # (Clock.advance_ns's count of a run)
            q[0] = pending - done * dt_ns
            q[10] += done
            q[9] += done * dt_ns
            EPOCH.n += 1  # (clock.counted)
            if spent:  # (the owed cycles and the run's: cycles_passed, the arming off)
                self.settle_hooks()
        else:  # (Clock.advance_ns's cycle where no run could start)
            q[0] = pending - dt_ns
            clock.cycle()
        if q[0] >= dt_ns:
            clock.advance_ns(0)  # the rest of the wait the general way, from here

    def _wait_end(self, e0: int) -> None:
        """The end of a wait in Python that began at the readers' epoch ``e0``:
        :meth:`_arm_after_wait`'s first look, inline (a loop of waits alone arms nothing),
        on the auto clock, or on either where GTE_Wait has its C entry (:attr:`C_WAITS`);
        there a wait that found the epoch the last one left (nothing but reads between:
        the entry would have taken it armed, where the last arming said it may) arms again
        whatever the armings before."""
        clock = self.clock
        q = clock.quick
        if self.C_WAITS:
            if e0 == self._wait_epoch and self._c_waits:
                self._idle_arms = 0
        elif clock.mode is not _AUTO:
            return
        if q[4] != EPOCH.n and (q[11] != self._armed_left or self._idle_arms < self.IDLE_ARMS):
            self._arm_after_wait()
        self._wait_epoch = EPOCH.n

    def waited(self, rc: int, pending: int) -> None:
        """The rest of a wait whose run of cycles GTE_Wait's C entry ran on the armed call
        (gtecat.gt.centry's wait: the clock's lock held, the cycle disarmed, the pending
        latency ``pending`` with the wait's time; the kernel's code ``rc``) where its book
        in C does not count it (a move ended, a cycle declined, the run stopped short):
        :meth:`wait_quick`'s book of it and the rest of the wait, as there where the armed
        budget held the run (the hooks not asked, their owed cycles counted after it)."""
        k = self.bank.kernel  # type: ignore[union-attr]
        e0 = EPOCH.n
        spent = self._owed is not None
        self.in_batch = True
        try:
            done = self._wait_book(k, rc, self._steady_seen, ())
        finally:
            self.in_batch = False
        self._wait_counted(done, pending, spent)
        self._wait_end(e0)

    def _arm_after_wait(self) -> None:
        """After a wait whose cycles ran (their last in a run at once, or one by one): the
        next due cycle armed for the GT readers' C entries, as a quick cycle arms the one
        after it (:meth:`due_cycle`; what :meth:`_quick_kernel` asks, the bus steady, the
        hooks' budget), so that an application polling between waits (a pass every few
        ms) has its calls' cycles run there from the first.  Only where a call made a cycle
        due since one of the last :attr:`IDLE_ARMS` armings: a loop of waits alone arms
        nothing after its first few, and a program whose calls make a cycle due in most of
        its passes between waits (the latency of a pass a little below the cycle time) has
        every one armed, not every other."""
        clock = self.clock
        q = clock.quick
        if q[4] == EPOCH.n or not q[3]:
            return  # (armed already, or a clock's group)
        if q[11] != self._armed_left:  # (some of the last arming spent: a call's cycle)
            self._idle_arms = 0
        elif self._idle_arms >= self.IDLE_ARMS:
            return  # (none of the last ones spent: waits alone)
        else:
            self._idle_arms += 1
        if self._owed is not None:
            self.settle_hooks()
        k = self._quick_kernel(True)  # (the hooks asked below, for the budget)
        if (
            k is None
            or clock._cycle_fn is not self._own_cycle
            or self._steady_marks(self.master) is None
        ):
            return
        _one_cycle(k, clock)  # (a run at once left its own start and count there)
        if self._unhooked == ARMS[0]:
            q[11] = _NO_BUDGET
        else:
            q[11] = self._quiet_budget()
            if q[11] <= 0:
                return
        self.arm_quick(k)


def _kernel_runs(bank: AxisBank, master: Master, dt_ns: int) -> Any:
    """The bank's kernel where its next cycles may run in one call of it with nothing else
    to do first - what :meth:`Controller._run_cycles` and :meth:`AxisBank.run_cycles` ask of
    the bank (nothing to settle, claim or release, no run stopped before a declined cycle,
    no table for Python to fill, the kernel bound to the image, this cycle time) - else
    None (:meth:`Controller._quick_kernel`, :meth:`Controller.wait_quick`)."""
    k = bank.kernel
    if (
        k is None
        or bank.dirty
        or bank._stale
        or bank._declined
        or bank.evt_rows
        or bank._post_next
        or bank._tp_apply
        or not bank.n
        or bank.n_alive != bank.n
        or (bank.n_moving and not bank._c_fill)
        or not k.bound
        or master.image.buffer is not k.buffer
        or dt_ns * 1e-9 != bank.csp._dt
    ):
        return None
    return k


#: the runs of cycles as :meth:`Controller.wait_quick` does them inline (a run wrapped or
#: replaced - a test's, an endpoint's - is called the general way)
_RUN_CYCLES = Controller.run_cycles
_BANK_RUN_CYCLES = AxisBank.run_cycles


def _one_cycle(k: Any, clock: Clock) -> None:
    """The kernel's call set for one quick cycle from the clock's time now (Kernel.run's
    inputs: the start, the cycle time, one cycle)."""
    q = clock.quick
    io = k._io
    io[_IN_T_NS] = clock.now_ns
    io[_IN_DT_NS] = q[2]
    io[_IN_MAXC] = 1
    k._fp[_FP_DT] = q[2] * 1e-9


def _quiet_way(hook: Callable[[int, int], None]) -> Callable[[int], int]:
    """``quiet(n)``: how many of the next ``n`` cycles a ``pre_cycle`` or ``post_cycle`` hook
    has nothing to do in (0: it must run in the next one); its object says so:
    ``quiet_cycles(n)`` (the fault injector: until its first trigger is due; smart homing:
    until a homing's Trap leg ends), or ``bank_quiet()`` for all or none (the coordinate
    systems while the axis bank steps every running one).  After cycles run at once, the
    object's ``cycles_passed(k)``, if it has one, counts them (:meth:`Controller._hook_ways`)."""
    obj = getattr(hook, "__self__", None)
    horizon = getattr(obj, "quiet_cycles", None)
    if horizon is not None:
        return horizon  # (an answer above n: the caller takes n)
    quiet = getattr(obj, "bank_quiet", None)
    if quiet is None:
        return lambda n: 0
    return lambda n: n if quiet() else 0


def folder_message(path: Path, how: str) -> str:
    """Why a folder is no ENI, naming the ENI files it holds (one text for GT and CLI):
    ``how`` is followed by the file to give instead."""
    inside = sorted(p.name for p in path.iterdir() if p.suffix.lower() == ".eni")
    hint = f" (it holds {', '.join(inside)})" if inside else ""
    return (
        f"{path} is a folder, not an ENI file{hint}; {how} "
        f"{path / (inside[0] if inside else 'Gecat.eni')}"
    )


def _relatch_link_alarms(ctl: Controller) -> None:
    """GT_Reset: bit 1 of an axis whose slave is still offline is set again at once."""
    for ax in ctl.axes.values():
        if ax.link_lost:
            if ax.motion is not None:
                ax.motion.latched |= int(AxisStatus.ALARM)  # (the word stays a plain int)
        else:
            ax.link_alarm = ""


def _machine_positions(backend: Any) -> dict[tuple[int, Any, int], float]:
    """Where the emulated machine's mechanics stand: (slave position, identity, channel) ->
    machine position.  Read before GT_InitEcatComm builds the bus again."""
    out: dict[tuple[int, Any, int], float] = {}
    for slave in getattr(backend, "slaves", None) or ():
        for k, ch in enumerate(getattr(slave, "channels", None) or ()):
            out[(slave.position, getattr(slave, "identity", None), k)] = ch.machine_position
    return out


def _put_back(backend: Any, kept: dict[tuple[int, Any, int], float]) -> None:
    """GT_InitEcatComm again (an application restarting, a second client's bring-up) finds
    the load where the last bus left it: re-initialising the bus does not move a real
    machine.  Only the power-on of a new controller (GT_Open) starts from the machine
    description's ``position``.  The drives themselves start as after power-on (their
    state machine, their object dictionary), as the slaves of a bus walked from INIT do.
    A slave whose identity changed (another bus) starts from its description."""
    if not kept:
        return
    for slave in getattr(backend, "slaves", None) or ():
        for k, ch in enumerate(getattr(slave, "channels", None) or ()):
            pos = kept.get((slave.position, getattr(slave, "identity", None), k))
            if pos is not None:
                ch.machine_position = pos


#: whether this module moved a bus model out of the cyclic collector's walks (gc.freeze)
_FROZEN: list[bool] = [False]
#: how many objects gtecat's own import froze (:func:`freeze_import`): a freeze count beyond
#: it is the process's own (the count only falls otherwise: frozen objects that die leave it)
_IMPORT_FROZEN: list[int] = [0]
#: buses from this many slaves on are frozen (a small bus costs the collector little)
FREEZE_MIN_SLAVES = 64


def _freeze_bus(slaves: int) -> None:
    """After the bring-up of a large bus: what exists now (the bus model: hundreds of
    thousands of long-lived objects, millions at a thousand axes) is never walked by the
    cyclic collector again, so the running bus has no long collector pauses and the
    process's end no last walk of it (half a second at a thousand axes).  A process that
    froze objects itself is left as it is (the import's own freeze, :func:`freeze_import`,
    is not the process's: with it counted as one, a 512-axis bus went unfrozen and its
    process's end walked it, 0.3 s)."""
    if slaves >= FREEZE_MIN_SLAVES and not process_froze():
        gc.freeze()
        _FROZEN[0] = True


def process_froze() -> bool:
    """Whether the process froze objects itself (``gc.freeze``) beyond what gtecat's own
    import froze (:func:`freeze_import`): code of gtecat's that freezes what it made (a
    large bus, a replay's plan) leaves such a process as it is."""
    return gc.get_freeze_count() > _IMPORT_FROZEN[0]


def unfreeze() -> None:
    """``gc.unfreeze()``, the import's frozen objects counted back to the collector too."""
    gc.unfreeze()
    _IMPORT_FROZEN[0] = 0


def freeze_import() -> None:
    """What :mod:`gtecat.gt`'s import made (it lives as long as the process) moved out of the
    collector's walks, counted as gtecat's own: a large bus is frozen after its bring-up as
    in a process that froze nothing (:func:`_freeze_bus`).  Objects the process froze before
    stay its own: a bus is then left as it is."""
    own = gc.get_freeze_count() == 0
    gc.freeze()
    if own:
        _IMPORT_FROZEN[0] = gc.get_freeze_count()


def _thaw_bus() -> None:
    """Before the next bring-up: the objects frozen after the last one go back to the
    collector, and the closed bus (garbage by then) is collected now, before the new one
    would freeze it again: a closed large bus's memory returns with the next
    GT_InitEcatComm, or with the end of the process."""
    if _FROZEN[0]:
        _FROZEN[0] = False
        unfreeze()  # (the import's with the bus: frozen again with the next)
        gc.collect()


#: ENI files from this size on keep their parsed model in the user's cache: a 12-axis TwinCAT
#: file (~250 KB) parses in tens of milliseconds and loads back in a few (a replay's or a
#: script's process opens it every time), a thousand axes, 20 MB, parse in a second; the
#: small files of the examples and tests parse in a few milliseconds and are not kept
ENI_CACHE_MIN_BYTES = 128 << 10


def _eni_cache(path: Path) -> Path | None:
    """Where a large ENI's model is kept between processes (``GTECAT_ENI_CACHE=0``: nowhere)."""
    if os.environ.get("GTECAT_ENI_CACHE", "1").strip() == "0":
        return None
    try:
        if path.stat().st_size < ENI_CACHE_MIN_BYTES:
            return None
    except OSError:
        return None  # read_eni says why
    from .. import __version__
    from .._cache import cache_root

    return cache_root() / __version__ / "eni"
