"""Checks of the application's own behaviour: what a real drive or controller would punish.

:class:`Checker` watches the GT call stream (:mod:`.tap`) and, once the bus is up, every
cycle of the drives; each finding is printed once per call site and rule as
``check: FILE:LINE: text [source]`` (on stderr) and kept in :attr:`Checker.findings`.
The rules and where they come from:

* ``cw-skip`` - a controlword that asks for a state the CiA-402 state machine cannot reach
  from the present one in one transition (CiA 402-2 / IEC 61800-7-201 Figure 4, the
  transition table: e.g. enable operation from SWITCH ON DISABLED);
* ``enable-in-fault`` - an enable command while the drive is in FAULT without a fault reset
  (rising edge of controlword bit 7) first (CiA 402 transition 15);
* ``csp-step`` - a CSP target position step (607Ah from one cycle to the next) larger than
  the following-error window (6065h): the drive faults with 8611h (CiA 402 6.3.4;
  ETG.6010 cyclic synchronous position);
* ``mode-while-moving`` - a new mode of operation (6060h) while the axis moves (ETG.6010
  6.2: a mode change is made at standstill; drives refuse or jerk);
* ``sdo-on-pdo`` - an SDO write, in OP, to an object that is mapped in an RxPDO: the next
  cycle overwrites it, many drives abort with 06010006h (ETG.1000.6 5.6.2; CiA 301);
* ``ready-poll`` - waiting for the bus without a time limit: ``GT_IsEcatReady`` polled from
  one line 200 times in a row, each answered *not ready* (status not 1, or a non-zero
  return), with no clock read in between.  Such a loop hangs the program when the bus never
  comes up (the manual's example 5-5 loops so; entry 80 gives no limit).  What does not
  count: a poll answered *ready* (the bus is up: a health check that watches it, not a
  wait; it starts the count again); what ends the count: a clock read between two polls,
  ``GT_GetClock`` or the program's own clock (``time.monotonic``, ``time.time``,
  ``time.perf_counter`` and their ``_ns`` forms, called from the polling file), since a
  loop that reads a clock can have a time limit.  A pause in the loop (``GTE_Wait``,
  ``time.sleep``) paces it but does not end it: it still counts;
* ``move-with-alarm`` - a move started (``GT_Update`` and the other start calls) on an axis
  whose status has the alarm bit set (manual 7.1, table 6-2 bit 1: clear it with GT_ClrSts
  once the cause is gone).
"""

from __future__ import annotations

import ctypes
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TextIO

from gtecat.drives.cia402 import State

from .tap import Listener, call_site, tap, untap

SOURCES = {
    "cw-skip": "CiA 402 state machine",
    "enable-in-fault": "CiA 402 transition 15",
    "csp-step": "CiA 402 6065h / ETG.6010 CSP",
    "mode-while-moving": "ETG.6010 modes of operation",
    "sdo-on-pdo": "ETG.1000.6 / CiA 301",
    "ready-poll": "manual entry 80, example 5-5",
    "move-with-alarm": "manual table 6-2 bit 1",
}
#: GT_IsEcatReady calls in a row from one line, answered "not ready", with no clock read:
#: a "poll without a limit"
READY_POLLS = 200
#: the program's own clocks: a loop that reads one can have a time limit (``ready-poll``)
_CLOCKS = ("monotonic", "monotonic_ns", "time", "time_ns", "perf_counter", "perf_counter_ns")
_START_CALLS = frozenset({"GT_Update", "GT_MoveAbsolute", "GT_MoveRelative", "GT_MoveVelocity"})


#: cycles a drive may take to make an SDO-written 6060h its mode (the finding then still
#: names the SDO call, not the one running when the drive took it up)
_MODE_TAKE_UP_CYCLES = 4


def _pointee(x: Any) -> Any:
    """The value a pointer argument holds (``byref(c_short())``, ``pointer(...)``, an array's
    first element); None when it cannot be read."""
    try:
        x = getattr(x, "_obj", x)  # byref
        if isinstance(x, ctypes._Pointer):  # type: ignore[attr-defined]
            x = x.contents
        if isinstance(x, ctypes.Array):
            x = x[0]
        return getattr(x, "value", x)
    except (ValueError, IndexError, TypeError):
        return None


def _is_mode_index(index: int) -> bool:
    """6060h of a drive's first channel, or of another (each 800h further: CiA 402 ch. 2)."""
    return index >= 0x6060 and (index - 0x6060) % 0x800 == 0 and index <= 0x6060 + 0x800 * 7


def _command(cw: int) -> str:
    """The command of a controlword (CiA 402 Table 2)."""
    if cw & 0x80:
        return "fault_reset"
    if not cw & 0x02:
        return "disable_voltage"
    if not cw & 0x04:
        return "quick_stop"
    if cw & 0x0F == 0x06:
        return "shutdown"
    if cw & 0x0F == 0x07:
        return "switch_on"
    if cw & 0x0F == 0x0F:
        return "enable"
    return ""


#: state -> the commands that are one transition from it (or hold it)
_ALLOWED = {
    State.SWITCH_ON_DISABLED: {"shutdown", "disable_voltage", "quick_stop", "fault_reset"},
    State.READY_TO_SWITCH_ON: {"shutdown", "switch_on", "disable_voltage", "quick_stop", "enable"},
    State.SWITCHED_ON: {"switch_on", "enable", "shutdown", "disable_voltage", "quick_stop"},
    State.OPERATION_ENABLED: {"enable", "switch_on", "shutdown", "disable_voltage", "quick_stop"},
}


class GtecatCheckWarning(UserWarning):
    """A finding of ``--gtecat-check`` in a pytest run: shown in the run's warnings summary
    at the application's file and line; ``-W error::gtecat.faults.checks.GtecatCheckWarning``
    makes a test with a finding fail at its teardown."""


@dataclass
class Finding:
    rule: str
    file: str
    line: int
    text: str

    def __str__(self) -> str:
        return f"check: {self.file}:{self.line}: {self.text} [{SOURCES[self.rule]}]"


class Checker(Listener):
    """The application checks (module docstring)."""

    bank_safe = False  # it reads the drives every cycle

    def __init__(self, out: TextIO | None = None) -> None:
        self.out = out if out is not None else sys.stderr
        self.findings: list[Finding] = []
        self._seen: set[tuple[str, str, int]] = set()
        self._site: tuple[str, int] = ("?", 0)
        self._ctl: Any = None
        self._prev: dict[int, tuple[int, int, int, int]] = {}
        self._polls = 0
        self._poll_site: tuple[str, int] = ("", 0)
        self._clocks: dict[str, Callable[[], float | int]] = {}
        self._cycles = 0
        #: (slave, 6060h of a channel) -> (call site, cycle it ended in): the call that wrote
        #: a mode by SDO; the drive takes it up a cycle or two later, maybe inside the next
        #: call, and the finding must name the call that made the change
        self._mode_writes: dict[tuple[int, int], tuple[tuple[str, int], int]] = {}
        self._pending_write: tuple[tuple[int, int], tuple[str, int]] | None = None

    def start(self) -> Checker:
        tap(self)
        for name in _CLOCKS:  # the program's clock reads end a ready-poll count
            real = getattr(time, name)
            if getattr(real, "__wrapped__", None) is None:
                self._clocks[name] = real
                setattr(time, name, self._clock(real))
        return self

    def _clock(self, real: Callable[[], float | int]) -> Callable[[], float | int]:
        def read() -> float | int:
            if self._polls and sys._getframe(1).f_code.co_filename == self._poll_site[0]:
                self._polls = 0
            return real()

        read.__wrapped__ = real  # type: ignore[attr-defined]
        read.__name__ = real.__name__
        return read

    def stop(self) -> None:
        untap(self)
        for name, real in self._clocks.items():
            if getattr(getattr(time, name), "__wrapped__", None) is real:
                setattr(time, name, real)
        self._clocks.clear()
        ctl = self._ctl
        if ctl is not None and self._cycle in ctl.pre_cycle:
            ctl.pre_cycle.remove(self._cycle)

    def report(self, rule: str, text: str, site: tuple[str, int] | None = None) -> None:
        file, line = site or self._site
        key = (rule, file, line)
        if key in self._seen:
            return
        self._seen.add(key)
        f = Finding(rule, file, line, text)
        self.findings.append(f)
        print(str(f), file=self.out, flush=True)

    def report_here(self, rule: str, text: str) -> None:
        self.report(rule, text, getattr(self, "_now", None))

    # --- the call stream -----------------------------------------------------------------------
    def before(self, name: str, args: tuple, kwargs: dict) -> Any:
        site = call_site()
        self._now = site
        if not name.startswith(("GT_Get", "GTN_Get", "GT_IsEcatReady", "GTN_IsEcatReady")) and (
            name not in ("GTE_Wait", "GT_GetClock")
        ):
            self._site = site  # what a cycle's finding is about: the last call that acts
        ctl = self._attach()
        if name.startswith("GTN_") and args:
            name, args = "GT_" + name[4:], args[1:]
        if name == "GT_GetClock":  # a loop that reads the clock can have a time limit
            self._polls = 0
        if ctl is None:
            return None
        if name in _START_CALLS and args:
            self._check_start(ctl, name, args)
        elif name == "GT_EcatSDODownload" and len(args) >= 2:
            self._check_sdo(ctl, int(args[0]), int(args[1]))
            if _is_mode_index(int(args[1])):
                self._pending_write = ((int(args[0]), int(args[1])), site)
        return None

    def after(self, name: str, args: tuple, kwargs: dict, rc: Any, token: Any) -> None:
        if name in ("GT_IsEcatReady", "GTN_IsEcatReady"):
            status = args[1 if name[2] == "N" else 0] if len(args) > (name[2] == "N") else None
            self._ready_poll(rc == 0 and _pointee(status) == 1)
        pending, self._pending_write = self._pending_write, None
        if pending is not None and rc == 0:
            self._mode_writes[pending[0]] = (pending[1], self._cycles)

    def _ready_poll(self, ready: bool) -> None:
        """One GT_IsEcatReady answer: ``ready-poll`` counts the "not ready" ones in a row."""
        site = getattr(self, "_now", ("?", 0))
        if ready:  # the bus is up: a health check, not a wait for the bus
            self._polls = 0
            return
        self._polls = self._polls + 1 if site == self._poll_site else 1
        self._poll_site = site
        if self._polls == READY_POLLS:
            self.report(
                "ready-poll",
                f"GT_IsEcatReady answered not ready {READY_POLLS} times in a row without a "
                "clock read: give the wait a time limit (GT_GetClock, or the program's clock) "
                "so that a bus that never comes up (a cable, a slave missing) ends it instead "
                "of hanging",
                site,
            )

    def _attach(self) -> Any:
        from ..gt._core import SESSION

        ctl = SESSION.controllers.get(1)
        if ctl is not self._ctl:
            self._ctl = ctl
            self._prev.clear()
        if ctl is not None and ctl.master is not None and self._cycle not in ctl.pre_cycle:
            ctl.pre_cycle.append(self._cycle)
        return ctl

    def _check_start(self, ctl: Any, name: str, args: tuple) -> None:
        try:
            mask = int(args[0])
        except (TypeError, ValueError):
            return
        axes = [a for a in range(1, 33) if mask >> (a - 1) & 1] if name == "GT_Update" else [mask]
        for a in axes:
            ax = ctl.axes.get(a)
            res = ctl.resources.get(a) if hasattr(ctl, "resources") else None
            if ax is None or res is None:
                continue
            try:
                sts = int(res.status())
            except Exception:
                continue
            if sts & 0x2:
                self.report_here(
                    "move-with-alarm",
                    f"{name} starts axis {a} while its alarm bit is set (GT_GetSts bit 1): "
                    "find the cause, GT_ClrSts, servo on again first",
                )

    def _check_sdo(self, ctl: Any, slave: int, index: int) -> None:
        m = ctl.master
        if m is None or not 0 <= slave < len(m.layout.slaves):
            return
        from gtecat.drives.slave import AlState

        if m.states[slave] != AlState.OP:
            return
        for e in m.layout.slaves[slave].entries:
            if (
                getattr(e, "direction", None) is not None
                and e.direction.name == "OUT"
                and e.index == index
            ):
                self.report_here(
                    "sdo-on-pdo",
                    f"SDO write to 0x{index:04X} of slave {slave} in OP: the object is mapped "
                    "in its RxPDO, the next cycle overwrites it (write the process data, or "
                    "write it before OP)",
                )
                return

    # --- every cycle ------------------------------------------------------------------------------
    def _cycle(self, _t: int, _dt: int) -> None:
        ctl = self._ctl
        backend = getattr(ctl, "backend", None)
        slaves = getattr(backend, "slaves", None)
        if not slaves:
            return
        self._cycles += 1
        axis = 0
        for pos, s in enumerate(slaves):
            for k, ch in enumerate(getattr(s, "channels", ())):
                axis += 1
                self._channel(axis, ch, (pos, 0x6060 + 0x800 * k))

    def _mode_site(self, key: tuple[int, int]) -> tuple[str, int] | None:
        """The call that wrote this mode object by SDO, when it did so a few cycles ago."""
        got = self._mode_writes.pop(key, None)
        if got is None or self._cycles - got[1] > _MODE_TAKE_UP_CYCLES:
            return None
        return got[0]

    def _channel(self, axis: int, ch: Any, mode_key: tuple[int, int] = (-1, 0)) -> None:
        cw, state = int(ch.controlword), ch.psm.state
        target, mode = int(ch.target_position), int(ch.mode_req)
        prev = self._prev.get(axis)
        self._prev[axis] = (cw, target, mode, int(ch.prev_cw))
        if prev is None:
            return
        pcw, ptarget, pmode, _ = prev
        if cw != pcw:
            cmd = _command(cw)
            if state in (State.FAULT, State.FAULT_REACTION_ACTIVE):
                if cmd in ("enable", "switch_on", "shutdown") and not pcw & 0x80:
                    self.report(
                        "enable-in-fault",
                        f"axis {axis}: controlword 0x{cw:04X} while the drive is in FAULT "
                        "without a fault reset (bit 7 rising) first",
                    )
            elif state in _ALLOWED and cmd and cmd not in _ALLOWED[state]:
                self.report(
                    "cw-skip",
                    f"axis {axis}: controlword 0x{cw:04X} ({cmd.replace('_', ' ')}) in "
                    f"{state.name.replace('_', ' ')} skips a state of the CiA-402 machine",
                )
        window = int(ch.following_error_window)
        if (
            ch.mode == 8
            and state is State.OPERATION_ENABLED
            and 0 < window < 0xFFFFFFFF
            and abs(target - ptarget) > window
        ):
            self.report(
                "csp-step",
                f"axis {axis}: CSP target jumps {target - ptarget} counts in one cycle, more "
                f"than the following-error window {window}: the drive faults (8611h)",
            )
        if mode != pmode and abs(ch.mech.vel) > max(ch.standstill, 1.0):
            self.report(
                "mode-while-moving",
                f"axis {axis}: mode of operation {pmode} -> {mode} while the axis moves "
                f"({ch.mech.vel:.0f} counts/s)",
                self._mode_site(mode_key),
            )
        elif mode != pmode:
            self._mode_writes.pop(mode_key, None)


__all__ = ["SOURCES", "Checker", "Finding"]
