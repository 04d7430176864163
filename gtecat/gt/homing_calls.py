"""GT homing and touch-probe calls of EtherCAT axes, and the emulator's machine position.

Manual 5.2.2.2 (homing), 5.2.2.3 (touch probe), examples 5-2 and 5-3, chapter 13
entries 43, 73, 103, 112, 123, 124, 130, 133.  The controller only sets parameters,
switches the mode, starts, reads the status and stops; the drive does the rest
(``drives/homing.py``, ``drives/touch_probe.py``).

Objects travel by PDO when the ENI maps them, else by SDO.  The manual grants the
SDO fallback for 6060h/6061h (5.2.2.2); here it also covers the homing parameters
(6098h, 6099h:01/02, 609Ah, 607Ch, which are SDO objects on most drives) and the
touch-probe objects 60B8h-60BDh, so the figure 5-2 bus (which maps only
6040/607A/6041/6064/60FD) can still home and probe.  Return 1 then means the SDO
failed too; the reason names the object and the abort code.  6041h must be mapped
(it defines the axis).

Decisions where the manual is silent:

* **Units** (entry 103: "the drive's user units"): ``speed1``/``speed2`` go to
  6099h:01/02 in drive counts/s, ``acc`` to 609Ah in counts/s², ``offset`` to 607Ch
  in drive counts - not pulses (``GT_SetPosScale`` does not apply).  Values are
  rounded to integers; a negative, non-finite or too large value returns 7, and
  so does a zero speed or acceleration for a method that searches (all but 35/37).
* **probeFunction** (entry 103: only for probe-based methods, which are
  vendor-specific; the virtual drive has none): a non-zero value is written to
  60B8h with the other parameters, so a drive whose method uses a touch probe finds
  it armed; 0 leaves 60B8h as it is.
* **GT_SetHomingMode(axis, mode)** writes 6060h and waits (at most
  :data:`_MODE_TIMEOUT_MS` of controller time, python-canopen's bound) until 6061h
  shows the mode; 1 if it does not.  Leaving homing mode while the drive still moves
  first lets it come to rest: a search that has not found the home point is
  interrupted (CW4 low), one that has finishes its move onto it.  Entering CSP takes the
  actual position as the planned position, so the axis never jumps.  Asking for the mode
  the drive already shows does nothing (example 5-2 asks on every scan once homed).
  1 while the controller is planning a motion (entry 112).
* **GT_StartEcatHoming** checks the three conditions of 5.2.2.2 (drive in operation
  enabled, 6061h = 6, parameters set by ``GT_SetEcatHomingPrm`` since the bus came
  up), then raises CW4 (clearing it for one cycle first when it is still high from a
  previous run, so the drive sees a rising edge) and returns once the drive has
  answered the start, so a status read right after it is never stale (cia402-facts
  §7 pitfall 2).  That starts a *run*, which the status below follows.
* **GT_StopEcatHoming** drops CW4, which CiA 402 defines as "interrupt homing": the
  drive decelerates at 609Ah and reports "interrupted" once stopped (status 5, below).
  It returns after the command has gone out, without waiting for the stop.
* **GT_GetEcatHomingStatus** (manual entry 43: bit 0 "homing finished", bit 1
  "finished successfully", bit 2 "error") takes only three values, so that the
  vendor's own loop ``do { GT_GetEcatHomingStatus(axis, &st); } while (st == 0);``
  followed by "anything but 3 is an error" (its Qt demo, example 5-2's ``= 3``)
  is right on every path:

  - **0** (:data:`HOMING_IN_PROGRESS`) exactly while a run started by
    GT_StartEcatHoming is active: from the start (also the cycles before the drive
    has seen CW4: statusword still "not started", SW10 alone) until the drive
    stands, SW10 = 1.  "Home point found, still moving onto it" (SW12 = 1,
    SW10 = 0), an error still braking (SW13 = 1, SW10 = 0) and an interrupt still
    braking are all 0.
  - **3** (:data:`HOMING_DONE`): the run ended with SW10 = SW12 = 1, SW13 = 0
    (CiA 402 "homing procedure completed successfully"; the home point found and
    reached).
  - **5** (:data:`HOMING_FAILED`, finished + error): every other end - SW13 (a
    homing error), interrupted (GT_StopEcatHoming, GT_SetHomingMode to another mode
    before the home point was found, the drive answering SW10 alone), the drive
    leaving *operation enabled* (servo off, fault, GT_Reset) or homing mode
    (GT_SetEcatAxisMode) during the run, or no answer to the start.  The result is
    the drive's verdict: a GT_StopEcatHoming after the home point was found ends 3
    when the drive then reports SW10 = SW12 = 1 (the position is defined).

  Between runs the call reports the last run's result, in any mode (the bits of
  6041h mean other things outside homing mode); **before any run** (since the bus
  came up) it reports **5**: 0 would hang the vendor loop for ever when the
  application polls without starting, 3 would claim a home the drive never found,
  and 5 - "finished, not successfully" - says what is true: this axis is not
  homed, which the demo's error branch reports.  A start that GT_StartEcatHoming
  refuses (return 1) starts no run and leaves the last result.  The run is
  followed every cycle after the exchange (an axis post-cycle hook), so its result
  never depends on when, or whether, the application polls; the drive's answer to
  CW4 is the first statusword exchanged after it (the virtual drives answer in
  that very exchange).
* **GT_SetTouchProbeFunction** sends ``ProbePrm`` to 60B8h as a 16-bit pattern
  (a negative ``short`` is taken bit for bit).  Bits 2-3 / 10-11, "reserved" in
  entry 123, select the source as ETG.6010 defines (00 probe input, 01 encoder
  index).  Both set calls return once the drive has taken the new 60B8h (at least one
  exchange after the write) and shows its enable bits in 60B9h, so a status read right
  after is not stale and two successive calls are two values on the wire (the ETG.6010
  re-arm, edge bit 4 off then on, needs the drive to see the 0).
* **GT_SetTouchProbeFunctionEx** constants (the vendor header's values are not
  public; these are ours, the 60B8h bit patterns): ``ECAT_PROBE_TRIGGER_TYPE_FIRST_EVENT``
  0, ``..._CONTINUES`` 1 (bit 1); ``ECAT_PROBE_TRIGGER_LEVEL_POS`` 1, ``..._NEG`` 2,
  ``..._DUL`` 3 (bits 5:4).  The source is the probe input.
* **GT_GetTouchProbeStatus** reports 60B9h as the drive has it: the manual's bits
  0-2 and 8-10 (entry 73) and the drive's toggle bits, which flip on every new
  capture in continuous mode: bit 6 probe 1 rising (GTHD, example 5-3), bit 7
  probe 1 falling, bit 14 probe 2 rising, bit 15 probe 2 falling.  A NULL (None)
  pointer skips that object.
* **GTE_GetMachinePos(axis, pValue)** (emulator only): where the mechanics really
  are, in machine counts (what a scale on the machine reads), unaffected by homing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import IntFlag
from typing import Any

from gtecat.drives.abort import SdoAbort

from .._attrs import PerObject
from ..controller.axis import ECAT_HOMING, Axis, PdsState
from ..controller.core import Controller
from ..errors import CommandError, ParameterError
from ..master.backends.emulated import EmulatedBackend
from . import _core
from ._core import check_range, gt_function, store
from .axis_calls import ECAT_MODES, bus_axis

# --- constants of GT_SetTouchProbeFunctionEx (entry 124) ------------------------------------
ECAT_PROBE_TRIGGER_TYPE_FIRST_EVENT = 0
ECAT_PROBE_TRIGGER_TYPE_CONTINUES = 1
ECAT_PROBE_TRIGGER_LEVEL_POS = 1
ECAT_PROBE_TRIGGER_LEVEL_NEG = 2
ECAT_PROBE_TRIGGER_LEVEL_DUL = 3

_HOMING_MODE = 6
_CSP_MODE = 8
_CW_HOMING_START = 0x0010  # CW4 in homing mode (cia402-facts §3.1)
_CW_HALT = 0x0100  # CW8
_SW10, _SW12, _SW13 = 1 << 10, 1 << 12, 1 << 13
_SW_HOMING = _SW10 | _SW12 | _SW13
_SW_NOT_STARTED = _SW10  # "homing interrupted or not started"
_SW_DONE = _SW10 | _SW12  # "homing procedure completed successfully"

#: GT_GetEcatHomingStatus values (manual entry 43; module docstring)
HOMING_IN_PROGRESS = 0
HOMING_DONE = 3  # bit 0 finished | bit 1 successfully
HOMING_FAILED = 5  # bit 0 finished | bit 2 error

#: controller time GT_SetHomingMode waits for 6061h (python-canopen's 0.5 s)
_MODE_TIMEOUT_MS = 500.0
#: controller time leaving homing mode waits for a moving drive to stop
_STOP_TIMEOUT_MS = 10_000.0
#: controller time GT_StartEcatHoming waits for the drive to answer CW4
_START_TIMEOUT_MS = 50.0
#: controller time the probe set calls wait for 60B9h to show the enable bits
_PROBE_TIMEOUT_MS = 20.0
_METHODS_WITHOUT_MOTION = (35, 37)


class ProbeStatus(IntFlag):
    """60B9h as GT_GetTouchProbeStatus reports it (entry 73 and the drive's toggle bits)."""

    PROBE1_ENABLED = 1 << 0
    PROBE1_RISE_STORED = 1 << 1
    PROBE1_FALL_STORED = 1 << 2
    PROBE1_RISE_TOGGLE = 1 << 6
    PROBE1_FALL_TOGGLE = 1 << 7
    PROBE2_ENABLED = 1 << 8
    PROBE2_RISE_STORED = 1 << 9
    PROBE2_FALL_STORED = 1 << 10
    PROBE2_RISE_TOGGLE = 1 << 14
    PROBE2_FALL_TOGGLE = 1 << 15


@dataclass(slots=True)
class _AxisHoming:
    """What the controller remembers about one axis's homing (lives as long as the axis)."""

    #: the axis bank knows this hook: an inactive one does nothing, and while a claimed
    #: drive searches its answer stays "in progress" (gtecat.controller.bank)
    bank_homing_hook = True
    params_set: bool = False
    #: a run started by GT_StartEcatHoming has not ended yet (status 0)
    active: bool = False
    #: the drive has answered this run's CW4 (statusword no longer "not started")
    answered: bool = False
    #: the last run's result, reported between runs (5 before any run)
    result: int = HOMING_FAILED
    #: why the running search cannot end (the machine lacks its switch), None if it can
    hint: str | None = None

    def begin(self) -> None:
        self.active, self.answered, self.hint = True, False, None

    def end(self, result: int) -> None:
        self.active = False
        self.result = result

    def answered_with(self, statusword: int) -> None:
        """What :meth:`post` makes of the cycle in which the drive answers this run's CW4
        with ``statusword``, known before that cycle runs: the axis bank starts a homing that
        ends at once (the current position is home) on the drive's row
        (gtecat.controller.bank_home_start), its drive in homing mode and operation enabled."""
        self._follow(statusword, True)

    def post(self, ax: Axis, t_ns: int, dt_ns: int) -> None:
        """Post-cycle hook: follow an active run with the drive's answer of this cycle."""
        if not self.active:
            return
        if ax.mode_cmd != _HOMING_MODE or ax.state != PdsState.OPERATION_ENABLED:
            self.end(HOMING_FAILED)  # the drive no longer runs the procedure
            return
        self._follow(ax.statusword, bool(ax.cw & _CW_HOMING_START))

    def _follow(self, sw: int, cw4: bool) -> None:
        """The run followed by the drive's statusword ``sw`` of a cycle (``cw4``: the
        controller's controlword of it holds CW4)."""
        if sw & _SW_HOMING != _SW_NOT_STARTED:
            self.answered = True
        status = homing_status_value(sw, waiting=not self.answered and cw4)
        if status != HOMING_IN_PROGRESS:
            self.end(status)


_STATE: PerObject[_AxisHoming] = ECAT_HOMING
#: how many run states :func:`_state` has made (an axis's is made once and kept while it
#: lives; the GT fast path looks one up again only when this count moved)
MADE = [0]


def _state(ax: Axis) -> _AxisHoming:
    st = _STATE.get(ax)  # (kept on the axis, read past a claimed axis's guard)
    if st is None:
        st = _STATE[ax] = _AxisHoming()
        MADE[0] += 1
        ax.post_hooks.append(st.post)
    return st


# --- object access: PDO if mapped, else SDO ---------------------------------------------------
def _read(ax: Axis, index: int, subindex: int, size: int, signed: bool) -> int:
    try:
        return ax.io.read_or_sdo(index, subindex, size, signed)
    except SdoAbort as e:
        raise CommandError(
            f"axis {ax.number}: 0x{ax.io.index(index):04X}:{subindex:02X} is not mapped as PDO "
            f"and the SDO upload failed: {e}"
        ) from None


def _write(ax: Axis, index: int, subindex: int, value: int, size: int) -> None:
    try:
        ax.io.write_or_sdo(index, subindex, value, size)
    except SdoAbort as e:
        raise CommandError(
            f"axis {ax.number}: writing {value} to 0x{ax.io.index(index):04X}:{subindex:02X} "
            f"failed: {e}"
        ) from None


def _statusword(ax: Axis) -> int:
    """6041h, which must be mapped (return 1 naming it, entry 43)."""
    return ax.io.read(0x6041)


def homing_status_value(statusword: int, waiting: bool = False) -> int:
    """What a homing-mode statusword means for an active run: 0, 3 or 5 (module docstring).

    ``waiting``: the drive has not answered CW4 yet, so SW10 alone ("not started")
    is the state before the start, not an interrupt.
    """
    if not statusword & _SW10:
        return HOMING_IN_PROGRESS  # moving: searching, onto the home point, braking
    bits = statusword & _SW_HOMING
    if bits == _SW_DONE:
        return HOMING_DONE
    if bits == _SW_NOT_STARTED and waiting:
        return HOMING_IN_PROGRESS
    return HOMING_FAILED


def _wait_cycles(ctl: Controller, n: int = 1) -> None:
    """Let ``n`` whole bus cycles run, so what was written has been exchanged."""
    c0 = ctl.clock.cycles
    ctl.clock.run_until(lambda: ctl.clock.cycles >= c0 + n, (n + 2) * ctl.clock.cycle_ns / 1e6)


def _homing_moving(ax: Axis) -> bool:
    """The drive is in a homing procedure that has not come to rest."""
    if ax.state != PdsState.OPERATION_ENABLED:
        return False
    return not _statusword(ax) & _SW10


# --- the Pythonic layer -----------------------------------------------------------------------
def set_homing_mode(ctl: Controller, ax: Axis, mode: int) -> None:
    """Switch the drive's mode of operation (6060h) and wait for 6061h (GT_SetHomingMode)."""
    if mode not in ECAT_MODES:
        raise ParameterError(f"mode {mode} is not one of {ECAT_MODES} (manual entry 112)")
    was = ax.mode_cmd
    if mode == was and _mode_display(ax) == mode:
        return  # already there (example 5-2 calls it on every scan once homed)
    if getattr(ax, "moving", False):
        raise CommandError(
            f"axis {ax.number} is planning a motion: call GT_Stop first (manual entry 112)"
        )
    if was == _HOMING_MODE and mode != _HOMING_MODE and _mode_display(ax) == _HOMING_MODE:
        _settle_homing(ctl, ax)  # an active run ends here, with the drive at rest
    if mode != was:
        ax.cw &= ~(_CW_HOMING_START | _CW_HALT)
    if mode == _CSP_MODE:
        ax.sync_to_actual()  # the planned position starts where the axis stands
    _write(ax, 0x6060, 0, mode, 1)
    ax.mode_cmd = mode
    if not ctl.clock.run_until(lambda: _mode_display(ax) == mode, _MODE_TIMEOUT_MS):
        raise CommandError(
            f"axis {ax.number}: 6061h still shows mode {_mode_display(ax)} "
            f"{_MODE_TIMEOUT_MS:g} ms after 6060h = {mode} was written"
        )
    if mode == _CSP_MODE:
        ax.sync_to_actual()


def _mode_display(ax: Axis) -> int:
    return _read(ax, 0x6061, 0, 1, True)


def _settle_homing(ctl: Controller, ax: Axis) -> None:
    """Before leaving homing mode, let the axis come to rest.

    A search that has not found the home point is interrupted (CW4 low); one that has
    (SW12) finishes its short move onto the home point, so the axis ends where 6064h
    reads the home offset.
    """
    if not _homing_moving(ax):
        return
    if not _statusword(ax) & _SW12:
        ax.cw &= ~_CW_HOMING_START
    if not ctl.clock.run_until(lambda: not _homing_moving(ax), _STOP_TIMEOUT_MS):
        raise CommandError(
            f"axis {ax.number}: the homing drive did not report standstill (SW10) within "
            f"{_STOP_TIMEOUT_MS:g} ms; mode not changed"
        )


def set_homing_parameters(
    ax: Axis,
    method: int,
    speed1: float,
    speed2: float,
    acc: float,
    offset: int,
    probe_function: int,
) -> None:
    """GT_SetEcatHomingPrm: 6098h, 6099h:01/02, 609Ah, 607Ch (and 60B8h when non-zero)."""
    # (the call as the C signature makes it, integers and doubles in range, passes the
    # checks below as they are: the same values without their calls)
    if not (
        type(method) is int
        and -0x80 <= method <= 0x7F
        and type(offset) is int
        and -0x80000000 <= offset <= 0x7FFFFFFF
        and type(probe_function) is int
        and 0 <= probe_function <= 0xFFFF
    ):
        method = check_range("method", method, -128, 127)
        offset = check_range("offset", offset, -(1 << 31), (1 << 31) - 1)
        probe_function = check_range("probeFunction", probe_function, 0, 0xFFFF)
    searches = method not in _METHODS_WITHOUT_MOTION
    low = 1.0 if searches else 0.0  # (a search's speeds and acceleration are not 0)
    if (
        type(speed1) is float
        and type(speed2) is float
        and type(acc) is float
        and low <= speed1 <= 4294967295.0
        and low <= speed2 <= 4294967295.0
        and low <= acc <= 4294967295.0
    ):
        values = (round(speed1), round(speed2), round(acc))
    else:
        values = tuple(
            _unsigned32(name, v, positive=searches)
            for name, v in (("speed1", speed1), ("speed2", speed2), ("acc", acc))
        )
    if ax.mode_cmd == _HOMING_MODE and ax.cw & _CW_HOMING_START and _homing_moving(ax):
        raise CommandError(
            f"axis {ax.number} is homing: stop it (GT_StopEcatHoming) before changing "
            "its parameters"
        )
    st = _state(ax)
    st.params_set = False
    items = [
        (0x6098, 0, method, 1),
        (0x6099, 1, values[0], 4),
        (0x6099, 2, values[1], 4),
        (0x609A, 0, values[2], 4),
        (0x607C, 0, offset, 4),
    ]
    if probe_function:
        items.append((0x60B8, 0, probe_function, 2))
    try:
        ax.io.write_all_or_sdo(items)
    except SdoAbort as e:
        value = next(
            (v for i, k, v, _ in items if ax.io.index(i) == e.index and k == e.subindex), "?"
        )
        raise CommandError(
            f"axis {ax.number}: writing {value} to 0x{e.index:04X}:{e.subindex:02X} failed: {e}"
        ) from None
    st.params_set = True


def _unsigned32(name: str, value: float, *, positive: bool) -> int:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name}={value!r} is not a number") from None
    if not math.isfinite(v) or v < 0 or round(v) > 0xFFFFFFFF:
        raise ParameterError(f"{name}={value!r} out of range 0..4294967295 (drive units)")
    if positive and round(v) == 0:
        raise ParameterError(f"{name}={value!r}: a homing search needs a non-zero {name}")
    return round(v)


def start_homing(ctl: Controller, ax: Axis) -> None:
    """GT_StartEcatHoming: the three conditions of 5.2.2.2, then a rising CW4."""
    state = ax.state
    if state != PdsState.OPERATION_ENABLED:
        raise CommandError(
            f"axis {ax.number}: the drive is not servo-enabled (state {state.name}); "
            "call GT_AxisOn first (manual 5.2.2.2 condition 1)"
        )
    shown = _mode_display(ax)
    if shown != _HOMING_MODE:
        raise CommandError(
            f"axis {ax.number}: 6061h shows mode {shown}, not homing (6); call "
            "GT_SetHomingMode(axis, 6) first (manual 5.2.2.2 condition 2)"
        )
    if not _state(ax).params_set:
        raise CommandError(
            f"axis {ax.number}: homing parameters not set; call GT_SetEcatHomingPrm first "
            "(manual 5.2.2.2 condition 3)"
        )
    if ax.cw & _CW_HOMING_START and _homing_moving(ax):
        raise CommandError(
            f"axis {ax.number} is already homing; GT_StopEcatHoming first to start afresh"
        )
    ax.mode_cmd = _HOMING_MODE
    st = _state(ax)
    if ax.cw & (_CW_HOMING_START | _CW_HALT):
        ax.cw &= ~(_CW_HOMING_START | _CW_HALT)
        _wait_cycles(ctl)  # the drive must see CW4 low before it can see it rise
    ax.cw |= _CW_HOMING_START
    st.begin()
    c0 = ctl.clock.cycles

    def answered() -> bool:
        return ctl.clock.cycles > c0 and (st.answered or not st.active)

    if not ctl.clock.run_until(answered, _START_TIMEOUT_MS):
        st.end(HOMING_FAILED)
        raise CommandError(
            f"axis {ax.number}: the drive did not start homing within {_START_TIMEOUT_MS:g} ms "
            f"of CW4 rising (statusword 0x{_statusword(ax):04X})"
        )
    st.hint = _search_hint(ctl, ax)
    if st.hint is not None:
        ctl.log(f"Axis {ax.number}: {st.hint}")


def stop_homing(ctl: Controller, ax: Axis) -> None:
    """GT_StopEcatHoming: CW4 low (CiA 402 "interrupt homing"), sent this cycle."""
    if ax.cw & _CW_HOMING_START:
        ax.cw &= ~_CW_HOMING_START
        _wait_cycles(ctl)


def homing_status(ax: Axis) -> int:
    """GT_GetEcatHomingStatus's value, 0, 3 or 5 (module docstring); the polling hot path.
    While a search that cannot end runs, GTE_GetLastError says why (a note, the call is 0)."""
    # read past the axis bank's guard (the polling hot path must not give a banked axis back)
    lost = object.__getattribute__(ax, "link_lost")
    if lost:  # the drive cannot be reached: its homing is not known (entry 43: 1)
        raise CommandError(
            f"axis {object.__getattribute__(ax, 'number')}: {lost}: the homing state is "
            "unknown (a homing in progress was interrupted; home again once the slave is back)"
        )
    st = _STATE.get(ax)
    if st is None:
        _statusword(ax)  # 6041h must be mapped (return 1 naming it, entry 43)
        return HOMING_FAILED  # no run since the bus came up: not homed
    if st.active and st.hint is not None:
        _core.note(f"axis {ax.number}: {st.hint}")
    return HOMING_IN_PROGRESS if st.active else st.result


def _search_hint(ctl: Controller, ax: Axis) -> str | None:
    """What the emulated drive's search lacks in the machine description (None elsewhere)."""
    if not isinstance(ctl.backend, EmulatedBackend):
        return None
    try:
        channel = ctl.backend.slaves[ax.io.slave].channel(ax.io.channel)
    except (AttributeError, IndexError, KeyError):
        return None
    homing = getattr(channel, "homing", None)
    return getattr(homing, "missing", None)


def set_probe_function(ctl: Controller, ax: Axis, function: int) -> None:
    """Write 60B8h and wait until 60B9h shows the enable bits (both probe set calls)."""
    function &= 0xFFFF
    _write(ax, 0x60B8, 0, function, 2)
    _wait_cycles(ctl)  # the drive takes 60B8h in the next exchange (module docstring)
    mask = ProbeStatus.PROBE1_ENABLED | ProbeStatus.PROBE2_ENABLED  # = 60B8h bits 0 and 8
    enables = function & mask
    if not ctl.clock.run_until(
        lambda: _read(ax, 0x60B9, 0, 2, False) & mask == enables, _PROBE_TIMEOUT_MS
    ):
        raise CommandError(
            f"axis {ax.number}: 60B9h does not show the probe enable bits of 60B8h = "
            f"0x{function:04X} within {_PROBE_TIMEOUT_MS:g} ms"
        )


def probe_function_ex(
    enable1: int, type1: int, level1: int, enable2: int, type2: int, level2: int
) -> int:
    """The 60B8h word GT_SetTouchProbeFunctionEx describes (source: probe input)."""
    word = 0
    for shift, (n, en, typ, lev) in (
        (0, (1, enable1, type1, level1)),
        (8, (2, enable2, type2, level2)),
    ):
        en = check_range(f"Probe{n}Enable", en, 0, 1)
        if not en:
            continue
        typ = check_range(f"Probe{n}TriggerType", typ, 0, 1)
        lev = check_range(f"Probe{n}TriggerLevel", lev, 1, 3)
        word |= (1 | typ << 1 | lev << 4) << shift
    return word


def machine_position(ctl: Controller, ax: Axis) -> float:
    """Where the axis's mechanics are (emulated backend only), machine counts."""
    from ..master.backends.emulated import EmulatedBackend

    slaves = ctl.backend.slaves if isinstance(ctl.backend, EmulatedBackend) else None
    if slaves is None:
        raise CommandError(
            f"axis {ax.number}: the machine position exists only on the emulated backend "
            f"(this bus runs on {ctl.options.backend})"
        )
    channel = slaves[ax.io.slave].channel(ax.io.channel)
    return float(channel.machine_position)


# --- the GT functions ---------------------------------------------------------------------------
@gt_function
def GT_SetHomingMode(ctl: Controller, axis: int, mode: int) -> int:
    """Switch the drive's mode of operation, e.g. 6 homing, 8 CSP (entry 112)."""
    set_homing_mode(ctl, bus_axis(ctl, axis), check_range("mode", mode, -128, 127))
    return 0


@gt_function
def GT_SetEcatHomingPrm(
    ctl: Controller,
    axis: int,
    method: int,
    speed1: float,
    speed2: float,
    acc: float,
    offset: int,
    probeFunction: int,
) -> int:
    """Homing method, speeds, acceleration, home offset and probe function (entry 103)."""
    set_homing_parameters(bus_axis(ctl, axis), method, speed1, speed2, acc, offset, probeFunction)
    return 0


@gt_function
def GT_StartEcatHoming(ctl: Controller, axis: int) -> int:
    """Start homing: 1 unless servo on, mode homing and parameters set (entry 130)."""
    start_homing(ctl, bus_axis(ctl, axis))
    return 0


@gt_function
def GT_StopEcatHoming(ctl: Controller, axis: int) -> int:
    """Interrupt homing (CW4 low); the drive stops at 609Ah (entry 133)."""
    stop_homing(ctl, bus_axis(ctl, axis))
    return 0


@gt_function
def GT_GetEcatHomingStatus(ctl: Controller, axis: int, pHomingStatus: Any) -> int:
    """0 homing, 3 homed, 5 failed or not homed (entry 43: bit 0 done, 1 success, 2 error)."""
    store(pHomingStatus, homing_status(bus_axis(ctl, axis)))
    return 0


@gt_function
def GT_SetTouchProbeFunction(ctl: Controller, axis: int, ProbePrm: int) -> int:
    """Write the 60B8h bit pattern (entry 123)."""
    prm = check_range("ProbePrm", ProbePrm, -0x8000, 0xFFFF)
    set_probe_function(ctl, bus_axis(ctl, axis), prm)
    return 0


@gt_function
def GT_SetTouchProbeFunctionEx(
    ctl: Controller,
    axis: int,
    Probe1Enable: int,
    Probe1TriggerType: int,
    Probe1TriggerLevel: int,
    Probe2Enable: int,
    Probe2TriggerType: int,
    Probe2TriggerLevel: int,
) -> int:
    """The probe function by description, ``ECAT_PROBE_TRIGGER_*`` constants (entry 124)."""
    ax = bus_axis(ctl, axis)
    word = probe_function_ex(
        Probe1Enable,
        Probe1TriggerType,
        Probe1TriggerLevel,
        Probe2Enable,
        Probe2TriggerType,
        Probe2TriggerLevel,
    )
    set_probe_function(ctl, ax, word)
    return 0


@gt_function
def GT_GetTouchProbeStatus(
    ctl: Controller,
    axis: int,
    probeStatus: Any,
    probe1RiseValue: Any = None,
    probe1FallValue: Any = None,
    probe2RiseValue: Any = None,
    probe2FallValue: Any = None,
) -> int:
    """60B9h and the captured positions 60BAh-60BDh (entry 73)."""
    ax = bus_axis(ctl, axis)
    if probeStatus is not None:
        store(probeStatus, _read(ax, 0x60B9, 0, 2, False))
    for index, ptr in (
        (0x60BA, probe1RiseValue),
        (0x60BB, probe1FallValue),
        (0x60BC, probe2RiseValue),
        (0x60BD, probe2FallValue),
    ):
        if ptr is not None:
            store(ptr, _read(ax, index, 0, 4, True))
    return 0


@gt_function
def GTE_GetMachinePos(ctl: Controller, axis: int, pValue: Any) -> int:
    """Emulator only: the true position of the axis's mechanics, machine counts."""
    store(pValue, machine_position(ctl, bus_axis(ctl, axis)))
    return 0
