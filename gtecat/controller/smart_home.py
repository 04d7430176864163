"""Smart homing (GT_GoHome): the controller's own search for the home of an axis.

Not the drive's homing (6098h methods, :mod:`gtecat.drives.homing`): here the controller moves
the axis in Trap mode, watches its limit inputs and captures home / index edges with its
own capture (:mod:`gtecat.controller.capture`), on any axis - a GTS card's pulse axis or an
EtherCAT drive in CSP.  The facts are the vendor header's (``THomePrm``, ``THomeStatus``,
``HOME_MODE_*``, ``HOME_STAGE_*``, ``HOME_ERROR_*``: the "Smart home" part of the vendor's GTS
header); what each mode does follows the GTS manual as a user's C++ homing program reads
it.  Units are the Trap mode's: pulse, pulse/ms, pulse/ms².

Every move is a Trap move of the axis's profile with ``acc``, ``dec`` and ``smoothTime`` of
THomePrm; searches run at ``velHigh`` ("Home 搜索速度"), the final approach at ``velLow``
("Index 搜索速度").  ``d`` is ``moveDir``; a search distance of 0 is 805306367 pulses (the
vendor header: "0 表示搜索距离为 805306367"), i.e. unlimited.  Every search ends standing:
once its event is seen the axis stops with ``dec`` (a limit stops it abruptly through the
limit check as usual), so what it captured lies behind it.

Modes (stages in brackets):

* **10 limit**: fast in ``d`` to the limit [10], stop [11]; back by ``escapeStep`` (again
  while the limit is still active) [13]; slowly in ``d`` until the limit triggers again
  [15]: that position is the capture; stop [16].
* **11 limit + home**: limit [10, 11]; then the home search in ``-d`` from the limit [20].
* **12 limit + index**: limit [10, 11]; then slowly in ``indexDir`` (which must differ
  from ``moveDir``) to the first index pulse [30].
* **13 limit + home + index**: limit [10, 11], home in ``-d`` [20], back to the captured
  home [25], then slowly in ``indexDir`` to the first index pulse beyond the home [30].
* **20 home**: the home search in ``d`` [20].
* **22 home + index**: home [20], back to it [25], first index beyond it in ``indexDir`` [30].
* **30 index**: fast in ``d`` to the first index pulse [30] (a user's C++ homing program:
  "fast with capture armed until the index pulse"); a limit on the way turns the search round once.
* **40 forced home**: the trigger - GPI ``triggerIndex`` (1..16), or the axis's home input
  when -1 - is sampled by the controller instead of latched: fast in ``d`` until it is
  active [40] (a limit first turns the search round once, as in mode 20), stop, slowly
  back in ``-d`` until it is inactive again [45]: the middle of that cycle's travel is the
  capture (within ``velLow * T / 2``).  The active zone must be longer than the stopping
  distance ``velHigh² / (2·dec)``, so the axis stops inside it.
* **41 forced home + index**: 40, back to the capture, then the first index beyond it in
  ``indexDir`` [30].

Then **go home** [80]: to ``targetPos = capturePos + homeOffset`` at ``velLow``; the axis
stands there in Trap mode [100, run 0].  Positions are not zeroed (``GT_ZeroPos`` after,
as a user's C++ homing program does).  ``capturePos`` is the encoder value of the capture
(of the trigger's encoder); the target is a profile position: profile and encoder are taken
to count the same pulses (GT_ZeroPos makes them agree; GT_ProfileScale/GT_EncScale 1:1).

**The home search** [20] (modes 11, 13, 20, 22) moves fast in its direction with the home
capture armed for ``edge`` (0: where the switch is reached, 1: where it is left; the
capture module says why).  Starting *on* the switch with ``edge`` 0 it first leaves the
switch backwards [1], so it always captures the same physical edge.  In modes 20/22 a
limit reached before the home turns the search round: back over the whole switch, stop,
and search again in ``d`` [20 throughout], so the capture is the same edge from either
side of the switch; a second limit, or no home within ``searchHomeDistance``, is
``HOME_ERROR_NO_HOME``.  In modes 11/13 the search starts from a limit and the other limit
ends it with that error.  ``triggerIndex`` -1 = this axis's home input and encoder;
``k`` = those of axis ``k`` (modes 11..30).

**The index search** [30] arms the index capture (``searchIndexDistance``); an index found
"beyond the home" must lie past the captured home in ``indexDir`` (found from the home
position, not from where the axis stopped after the home).  No index within the distance
(or a limit first) is ``HOME_ERROR_NO_INDEX``; an axis that cannot capture the index (an
EtherCAT drive without touch probe) ``HOME_ERROR_SET_CAPTURE_INDEX`` at GT_GoHome.

**Limits.**  A limit the search reaches latches GT_GetSts bit 5/6 as any limit does and
stops the axis abruptly (with GT_LmtsOff the search sees the input anyway and stops with
``dec``).  A search that starts on the limit it looks for has reached it at once (the limit
modes go on with the escape, the home and index searches turn).  Before every move toward
one side the search clears that side's limit flag if its cause is gone (the axis left the
switch), whoever raised it, and at the end the flags it raised itself, as the
``GT_ClrSts`` in a user's C++ homing program's polling loop would; other latched flags
(alarm, following error, stop inputs) refuse the search with ``HOME_ERROR_STOP`` /
``_ALARM``, as they refuse GT_Update (the vendor's demo calls GT_ClrSts first:
"无清除状态会导致回零失败").  A limit mode on an axis whose
limit input in ``moveDir`` is *none* (a configuration file's index -1 takes it
away from the limit check: no stop, no bit 5/6) reads the axis's own limit terminal
(60FDh of the axis; on a card its terminal N) and stops there with ``dec``, with a line in
the master log: the vendor's own ``smarthome_test.cfg`` (its smart-home demo) wires none to
axes 2-4, and a user's C++ limit homing on them must still find the switch
the machine has.  Only an axis with no limit terminal at all (no 60FDh) is refused with
``HOME_ERROR_HOME_MODE``: that search could never end.

**Errors** end the homing (the axis is stopped with ``dec``; ``run`` drops once it stands;
``stage`` stays where it failed): 1 not in Trap mode (a Jog is taken over instead:
:meth:`SmartHome._leave_jog`), 2 servo off (at the start or on the way), 3 drive alarm, 4
stopped by someone else (GT_Stop, a stop input, the following error: at any moment, also
while the axis stands between two legs or brakes at a limit; the axis does not move again)
or a search refused by a latched flag, 5 another motion command or a limit where none
belongs (escape, return, go home), 6 unknown mode / no limit input, 7 no home input to
capture, 8 no home (or no limit in mode 10) within the distance, 9 the index cannot be
captured, 10 no index. GT_GoHome returns 1 with the reason when it refuses to start (the
status says the same); 7 for a parameter out of range.
"""

from __future__ import annotations

import heapq
import math
import weakref
from collections.abc import Callable, Generator
from dataclasses import dataclass, fields, replace
from enum import IntEnum
from typing import Any

from .._attrs import PerObject
from ..errors import CommandError, ParameterError
from .axis_status import AxisStatus
from .capture import CAPTURE_HOME, CAPTURE_INDEX, CaptureUnit, capture_unit, unit_of
from .digital_io import GPIO_COUNT, digital_io
from .motion import StopKind, TrapParams
from .motion.trap import SMOOTH_TIME_MAX
from .profile import PrfMode
from .resources import AxisResources, axis_resources

#: how long GT_GoHome waits (controller time) for a Jog it takes over to stop
JOG_STOP_TIMEOUT_MS = 60_000


class HomeMode(IntEnum):
    LIMIT = 10
    LIMIT_HOME = 11
    LIMIT_INDEX = 12
    LIMIT_HOME_INDEX = 13
    HOME = 20
    HOME_INDEX = 22
    INDEX = 30
    FORCED_HOME = 40
    FORCED_HOME_INDEX = 41


class Stage(IntEnum):
    IDLE = 0
    START = 1
    SEARCH_LIMIT = 10
    SEARCH_LIMIT_STOP = 11
    SEARCH_LIMIT_ESCAPE = 13
    SEARCH_LIMIT_RETURN = 15
    SEARCH_LIMIT_RETURN_STOP = 16
    SEARCH_HOME = 20
    SEARCH_HOME_RETURN = 25
    SEARCH_INDEX = 30
    SEARCH_GPI = 40
    SEARCH_GPI_RETURN = 45
    GO_HOME = 80
    END = 100


class HomeError(IntEnum):
    NONE = 0
    NOT_TRAP_MODE = 1
    DISABLE = 2
    ALARM = 3
    STOP = 4
    STAGE = 5
    HOME_MODE = 6
    SET_CAPTURE_HOME = 7
    NO_HOME = 8
    SET_CAPTURE_INDEX = 9
    NO_INDEX = 10


#: what a search distance of 0 means (the vendor header)
UNLIMITED = 805306367
#: escape steps tried before the limit counts as stuck
MAX_ESCAPES = 100
LIMIT_MODES = (HomeMode.LIMIT, HomeMode.LIMIT_HOME, HomeMode.LIMIT_INDEX, HomeMode.LIMIT_HOME_INDEX)
HOME_MODES = (HomeMode.LIMIT_HOME, HomeMode.LIMIT_HOME_INDEX, HomeMode.HOME, HomeMode.HOME_INDEX)
INDEX_MODES = (
    HomeMode.LIMIT_INDEX,
    HomeMode.LIMIT_HOME_INDEX,
    HomeMode.HOME_INDEX,
    HomeMode.INDEX,
    HomeMode.FORCED_HOME_INDEX,
)
FORCED_MODES = (HomeMode.FORCED_HOME, HomeMode.FORCED_HOME_INDEX)
_LONG = (-(1 << 31), (1 << 31) - 1)
_POS, _NEG = int(AxisStatus.POSITIVE_LIMIT), int(AxisStatus.NEGATIVE_LIMIT)
_ALARM = int(AxisStatus.ALARM)
#: flags whose cause stops the axis (a stop input, the following error): the homing ends
_STOPPED = int(AxisStatus.SMOOTH_STOP | AxisStatus.ABRUPT_STOP | AxisStatus.POS_ERROR)
_LIMIT_POS_BIT, _LIMIT_NEG_BIT = 1 << 1, 1 << 0  # 60FDh


@dataclass(frozen=True, slots=True)
class HomeParams:
    """THomePrm as plain data (field names of the header, in its order); the defaults
    are what GT_GetHomePrm reports after GT_Reset (the header leaves them open)."""

    mode: int = HomeMode.HOME
    moveDir: int = 1  # noqa: N815 - the header's names
    indexDir: int = 1  # noqa: N815
    edge: int = 0
    triggerIndex: int = -1  # noqa: N815
    velHigh: float = 10.0  # noqa: N815
    velLow: float = 1.0  # noqa: N815
    acc: float = 1.0
    dec: float = 1.0
    smoothTime: int = 0  # noqa: N815
    homeOffset: int = 0  # noqa: N815
    searchHomeDistance: int = 0  # noqa: N815
    searchIndexDistance: int = 0  # noqa: N815
    escapeStep: int = 1000  # noqa: N815

    def check(self, axes: int) -> None:
        """ParameterError (GT_GoHome 7) naming the first field out of range; the mode is
        checked by :meth:`SmartHome.start` (HOME_ERROR_HOME_MODE)."""
        if self.moveDir not in (-1, 1):
            raise ParameterError(f"moveDir={self.moveDir}: -1 (negative) or 1 (positive)")
        if self.indexDir not in (-1, 1):
            raise ParameterError(f"indexDir={self.indexDir}: -1 (negative) or 1 (positive)")
        if self.edge not in (0, 1):
            raise ParameterError(f"edge={self.edge}: 0 (falling edge) or 1 (rising edge)")
        if self.mode in FORCED_MODES:
            if self.triggerIndex != -1 and not 1 <= self.triggerIndex <= GPIO_COUNT:
                raise ParameterError(
                    f"triggerIndex={self.triggerIndex}: -1 (the axis's home input) or a GPI "
                    f"1..{GPIO_COUNT} in the forced-home modes"
                )
        elif self.triggerIndex != -1 and not 1 <= self.triggerIndex <= axes:
            raise ParameterError(
                f"triggerIndex={self.triggerIndex}: -1 (this axis) or an encoder 1..{axes}"
            )
        for name in ("velHigh", "velLow", "acc"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0.0):
                raise ParameterError(f"{name}={v!r} must be > 0")
        if not (math.isfinite(self.dec) and self.dec >= 0.0):
            raise ParameterError(f"dec={self.dec!r} must be >= 0 (0: the same as acc)")
        if not 0 <= self.smoothTime <= SMOOTH_TIME_MAX:
            raise ParameterError(f"smoothTime={self.smoothTime}: 0..{SMOOTH_TIME_MAX} ms")
        for name in ("searchHomeDistance", "searchIndexDistance"):
            if getattr(self, name) < 0:
                raise ParameterError(f"{name}={getattr(self, name)} must be >= 0 (0: unlimited)")
        if self.mode == HomeMode.LIMIT and self.escapeStep <= 0:
            raise ParameterError(f"escapeStep={self.escapeStep}: the limit mode needs it > 0")
        if self.mode == HomeMode.LIMIT_INDEX and self.indexDir == self.moveDir:
            raise ParameterError(
                "indexDir must differ from moveDir in the limit + index mode (the index is "
                "searched away from the limit)"
            )

    def trap(self) -> TrapParams:
        return TrapParams(self.acc, self.dec, 0.0, int(self.smoothTime))


@dataclass(slots=True)
class HomeStatus:
    """THomeStatus as plain data."""

    run: int = 0
    stage: int = Stage.IDLE
    error: int = HomeError.NONE
    capturePos: int = 0  # noqa: N815
    targetPos: int = 0  # noqa: N815


class HomeRefused(CommandError):
    """GT_GoHome cannot start (return 1); ``error`` is what THomeStatus reports."""

    def __init__(self, error: HomeError, reason: str) -> None:
        super().__init__(reason)
        self.error = error


class _Abort(Exception):
    def __init__(self, error: HomeError, reason: str) -> None:
        super().__init__(reason)
        self.error = error


_Steps = Generator[None, None, Any]
_get = object.__getattribute__  # a claimed axis's objects read without giving it back


class SmartHome:
    """The smart homing of one axis (module docstring)."""

    def __init__(self, ctl: Any, res: AxisResources) -> None:
        self.ctl = ctl
        self.res = res
        self.number = res.number
        self.unit = unit_of(ctl, res)  # the axis's own encoder and capture
        self._din = _get(res.ax, "io").get(0x60FD)  # (the bank may hold the axis: kept)
        self.reset()

    def reset(self) -> None:
        """GT_Reset: default parameters, status idle, no homing."""
        self.params = HomeParams()
        self.status = HomeStatus()
        self.reason = ""
        self._gen: _Steps | None = None
        self._failing = False
        self._before = 0
        self._raised = 0
        self._stops = 0  # the axis's GT_Stop count when the homing started
        self._expect: int | None = None
        #: the search waits in a loop that only its own axis can end (the end of the Trap
        #: leg, a limit or home input of the axis: :meth:`quiet`)
        self._waiting = False
        #: (controller time, claim) up to which :meth:`quiet` found nothing to do
        self._q_due = 0
        self._q_claim = 0  # (0: none)
        self._q_row = 0
        self._h_due = -1  # (_Homings._settle: its time in the heap, -1: none)
        #: what the last step saw of what a call may change (:meth:`quiet`)
        self._seen_latched = -1
        self._seen_changes: tuple[int, int] = (-1, -1)
        #: the controller's GPI registers while a forced homing's trigger is a GPI (only a
        #: call changes them), and their value at the last step
        self._gpio: Any = None
        self._seen_gpi = -1
        #: the leg under way watches the trigger (its capture, its level or a GPI)
        self._watching = False
        #: the leg under way has read its watch once since it started (:meth:`quiet`)
        self._looked = True
        #: the direction whose limit the wait under way looks at (0: none, a stop)
        self._dir = 0
        #: the clock's cycle count at which the touch probe's arming ends (0: none)
        self._arm_due = 0

    @property
    def running(self) -> bool:
        return self._gen is not None

    @property
    def _waiting(self) -> bool:
        return self._wait

    @_waiting.setter
    def _waiting(self, on: bool) -> None:
        """The search waits in a loop only its own axis can end (:meth:`quiet`); while it
        runs otherwise, it steps every cycle, so the axis bank leaves the axis alone
        (``bank_hold``) instead of taking it for a cycle and giving it back."""
        self._wait = on
        self.res.bank_hold = self._gen is not None and not on
        if on and self.res.bank is None:
            bank = getattr(self.ctl, "bank", None)
            if bank is not None:
                bank.dirty = True  # the axis may be taken now: looked at before the next cycle

    # --- GT_GoHome ------------------------------------------------------------------------------
    def start(self, prm: HomeParams, caller: Any = None) -> None:
        """Start homing with ``prm`` (already range-checked); HomeRefused when it cannot.

        ``caller``: the controller the call came through, whose numbering ``triggerIndex``
        uses (a core beyond 1 names its own encoders 1..32); the bus controller when None."""
        numbering = self.ctl if caller is None else caller
        if self.running:
            raise CommandError(
                f"axis {self.number} is homing (stage {self.status.stage}); wait until "
                "GT_GetHomeStatus reports run 0 (or GT_Stop it)"
            )
        prm.check(len(numbering.axes))
        res = self.res
        if res.profile.mode == PrfMode.JOG:
            self._leave_jog(res)
        if res.moving:
            raise CommandError(f"axis {self.number} is moving: GT_Stop it first")
        self.params = prm
        st = self.status = HomeStatus()
        try:
            mode = HomeMode(prm.mode)
        except ValueError:
            self._refuse(
                HomeError.HOME_MODE,
                f"mode={prm.mode} is no smart-home mode (10, 11, 12, 13, 20, 22, 30, 40, 41)",
            )
        if res.profile.mode != PrfMode.TRAP:
            self._refuse(
                HomeError.NOT_TRAP_MODE,
                f"axis {self.number} is in {res.profile.mode.name.capitalize()} mode; call "
                "GT_PrfTrap first",
            )
        if res.latched & _ALARM:
            self._refuse(HomeError.ALARM, f"axis {self.number} has its alarm flag set (bit 1)")
        if not res.ax.servo_on:
            self._refuse(HomeError.DISABLE, f"axis {self.number} is off; call GT_AxisOn first")
        if mode in LIMIT_MODES and self._limit(prm.moveDir) is None:
            side = "positive" if prm.moveDir > 0 else "negative"
            self._refuse(
                HomeError.HOME_MODE,
                f"mode {int(mode)} searches the {side} limit, and axis {self.number} has no "
                f"{side} limit input (no 60FDh)",
            )
        if mode in LIMIT_MODES and res.limit_input(prm.moveDir > 0) is None:
            side = "positive" if prm.moveDir > 0 else "negative"
            self.ctl.log(
                f"Axis {self.number}: GT_GoHome mode {int(mode)} reads the axis's own {side} "
                "limit terminal: the configuration file wired none to the axis"
            )
        trigger = self._trigger_unit(prm, mode, numbering)
        if mode in HOME_MODES or (mode in FORCED_MODES and prm.triggerIndex == -1):
            why = trigger.available(CAPTURE_HOME)
            if why:
                self._refuse(HomeError.SET_CAPTURE_HOME, why)
        if mode in INDEX_MODES:
            try:  # an EtherCAT drive's touch probe answers now or never
                trigger.try_index()
            except CommandError as e:
                self._refuse(HomeError.SET_CAPTURE_INDEX, str(e))
        self._trigger = trigger
        self._mode = mode
        self._trap = prm.trap()
        self._before = res.latched
        self._raised = 0
        self._stops = res.stops
        self._failing = False
        self._expect = None
        self._q_claim = 0
        self._gpio = None
        self.reason = ""
        st.run, st.stage = 1, Stage.START
        self._gen = self._run()
        # its first step comes after the next cycle: an axis the bank runs (GT_GoHome ran on
        # its row in place) stays there for it, any other stays scalar until the search waits
        self._waiting = res.bank is not None
        _register(self.ctl, self)

    def _refuse(self, error: HomeError, reason: str) -> None:
        self.status = HomeStatus(0, Stage.IDLE, error)
        self.reason = reason
        raise HomeRefused(error, f"GT_GoHome on axis {self.number}: {reason}")

    def _leave_jog(self, res: AxisResources) -> None:
        """GT_GoHome on an axis in Jog mode starts the homing, as the card does.

        The vendor's smart-home demo jogs with a button (GT_PrfJog, GT_SetJogPrm, GT_SetVel,
        GT_Update; GT_Stop on release) and its home button calls GT_ClrSts, GT_GetHomePrm and
        GT_GoHome with no GT_PrfTrap between: on the card the homing runs.  So here a Jog
        that still moves (still running, or on its GT_Stop ramp) is brought to a stop with the
        smooth-stop deceleration (decSmoothStop, GT_SetStopDec) - GT_GoHome returns once the
        axis stands, within :data:`JOG_STOP_TIMEOUT_MS` of controller time - and the profile
        is put in Trap mode, which the homing moves in; a master-log line says so.  Other
        modes (PT, Gear, Follow, interpolation) are still refused with
        ``HOME_ERROR_NOT_TRAP_MODE``."""
        was_moving = res.moving
        if was_moving:
            res.stop(False)
            if not self.ctl.clock.run_until(lambda: not res.moving, JOG_STOP_TIMEOUT_MS):
                raise CommandError(
                    f"axis {self.number}: its Jog motion did not stop within "
                    f"{JOG_STOP_TIMEOUT_MS} ms (GT_SetStopDec's smooth deceleration); "
                    "GT_Stop it and home again"
                )
        res.prf_trap()
        self.ctl.log(
            f"GT_GoHome axis {self.number}: the axis was in Jog mode"
            f"{' and moving (stopped first)' if was_moving else ''}; homing in Trap mode as "
            "the card does"
        )

    def _trigger_unit(self, prm: HomeParams, mode: HomeMode, numbering: Any) -> CaptureUnit:
        if mode in FORCED_MODES or prm.triggerIndex == -1:
            return self.unit
        return capture_unit(numbering, prm.triggerIndex)

    # --- the cycle ----------------------------------------------------------------------------
    def quiet(self, bank: Any) -> int | None:
        """None when the next :meth:`cycle` may have something to do; else the cycles after
        the next one in which it surely has nothing either.

        That holds while the search waits in a Trap leg (or a stop, or the move home) that
        only its own axis can end and the axis bank runs that axis in the middle of the
        move: no input of the axis changed (a limit, the home input of its capture unit:
        each gives the axis back before its cycle), no flag latched, no call touched it
        (that too gives it back), so the loop would only look and wait again.  The count
        ends before the cycle that takes the move's end sample (:meth:`AxisBank.trap_quiet`)."""
        if not self._wait or self._failing or self._gen is None or bank is None:
            return None
        if not self._looked:
            # the leg's watch may hold already (a level the stop before it left behind,
            # which no edge will announce): the step after the move starts reads it
            return None
        trigger = self._trigger
        foreign = self._watching and trigger is not self.unit
        if foreign and not self._trigger_held(bank):
            return None
        res = self.res
        if res.bank is not bank:
            return None
        r = res.bank_row
        if self._arm_due:
            return self._arm_quiet(bank, r)
        if not (bank.alive[r] and bank.moving[r]) or r in bank.evt_rows:
            return None  # (evt_rows: the bank ran a cycle that changed an input it watches)
        # what a call may have changed since the last step (a call gives the axis back
        # first, and the bank may take it again before the next cycle): as the step saw it
        if res.latched != self._seen_latched or res.stops != self._stops:
            return None
        if (self.unit.changes, self._trigger.changes) != self._seen_changes:
            return None
        if self._gpio is not None and self._gpio.gpi != self._seen_gpi:
            return None
        if foreign and (trigger.status or trigger.edges):
            return None  # (the trigger's axis ran a cycle of its own that saw an edge)
        prof = res.profile
        if prof.mode != PrfMode.TRAP:
            return None
        trap = prof.trap
        if _get(trap, "stopping") != StopKind.NONE or _get(trap, "_target") != self._expect:
            return None
        # (a limit behind the move - the one a limit homing leaves - ends no wait: the bank
        # gives the row back when a limit becomes active, or when a latched one's is not)
        if not _get(res.ax, "servo_on") or (self._dir and self._limit(self._dir)):
            return None
        return bank.trap_quiet(r)

    def _arm_quiet(self, bank: Any, r: int) -> int | None:
        """:meth:`quiet` while the touch probe arms (:meth:`_arming`) on a row the bank
        runs: the cycles before the step that goes on, unless something a step looks at
        changed (a flag, a stop, a call's capture settings, an edge the bank took)."""
        res = self.res
        if not bank.alive[r] or r in bank.evt_rows or not _get(res.ax, "servo_on"):
            return None
        if res.latched != self._seen_latched or res.stops != self._stops:
            return None
        if (self.unit.changes, self._trigger.changes) != self._seen_changes:
            return None
        if res.profile.mode != PrfMode.TRAP:
            return None
        left = self._arm_due - self.ctl.clock.cycles
        return None if left <= 0 else left - 1

    def _trigger_held(self, bank: Any) -> bool:
        """Another axis's capture is the trigger (``triggerIndex``): it latches, and its home
        level changes, only in a cycle that axis runs on its scalar objects (the bank gives
        it back before such a cycle while a home capture is armed, the level is watched or
        the touch probe is armed), after which the homings look again
        (:meth:`_Homings._settle`).  True while the bank runs that axis; otherwise this
        homing steps every cycle, and its own axis stays out of the bank (``bank_hold``)
        instead of being taken for a cycle and given back."""
        tres = self._trigger.res
        held = tres.bank is bank and bool(bank.alive[tres.bank_row])
        if self.res.bank_hold == held:
            self.res.bank_hold = not held
            if held:
                bank.dirty = True  # this axis may be taken now
        return held

    def cycle(self) -> None:
        """After every cycle (all axes have read their inputs)."""
        if self._gen is None:
            return
        res = self.res
        if self._failing:
            if res.profile.planner.done or not res.ax.servo_on:
                self._end()
            return
        self._raised |= res.latched & (_POS | _NEG) & ~self._before
        error = self._watch()
        if error is not None:
            self._fail(*error)
            return
        try:
            next(self._gen)
        except StopIteration:
            self._finish()
        except _Abort as a:
            self._fail(a.error, str(a))
        self._seen_latched = res.latched
        self._seen_changes = (self.unit.changes, self._trigger.changes)
        if self._gpio is not None:
            self._seen_gpi = self._gpio.gpi

    def _watch(self) -> tuple[HomeError, str] | None:
        res = self.res
        if res.latched & _ALARM:  # before the servo: an alarm switches it off too
            return HomeError.ALARM, f"axis {self.number}: drive alarm (GT_GetSts bit 1)"
        if not res.ax.servo_on:
            return HomeError.DISABLE, f"axis {self.number} was switched off"
        if res.profile.mode != PrfMode.TRAP:
            return HomeError.NOT_TRAP_MODE, f"axis {self.number} left Trap mode"
        # a stop at any moment ends the homing, also one of an axis standing between two
        # legs (nothing of the Trap profile shows it then) or in a stop of the search's own
        if res.stops != self._stops:
            return HomeError.STOP, f"axis {self.number} was stopped (GT_Stop)"
        if res.latched & _STOPPED:
            return HomeError.STOP, (
                f"axis {self.number} was stopped (a stop input or the following error)"
            )
        return None

    def _fail(self, error: HomeError, reason: str) -> None:
        self.status.error = int(error)
        self.reason = reason
        trap = self.res.profile.trap
        if self.res.profile.planner is trap and not trap.done and trap.stopping == StopKind.NONE:
            trap.stop(self._trap.dec)
        self._failing = True
        if self.res.profile.planner.done or not self.res.ax.servo_on:
            self._end()
        self.ctl.log(f"Axis {self.number}: smart home error {int(error)}: {reason}")

    def _end(self) -> None:
        """The homing is over (status run 0); the axis bank may take the axis again."""
        self._gen = None
        self.status.run = 0
        self.res.bank_hold = False

    def _finish(self) -> None:
        st = self.status
        st.stage = Stage.END
        self._end()
        self._clear_raised(self._raised)
        self.res.profile.trap_target = round(self.res.profile.trap.pos)

    # --- the modes ----------------------------------------------------------------------------
    def _run(self) -> _Steps:
        p, mode, st = self.params, self._mode, self.status
        d = p.moveDir
        if mode in LIMIT_MODES:
            yield from self._find_limit(d)
            if mode == HomeMode.LIMIT:
                cap = yield from self._limit_return(d)
            elif mode == HomeMode.LIMIT_HOME:
                cap = yield from self._search_home(-d, turn=False)
            elif mode == HomeMode.LIMIT_INDEX:
                cap = yield from self._search_index(p.indexDir, p.velLow)
            else:
                home = yield from self._search_home(-d, turn=False)
                cap = yield from self._index_beyond(home, Stage.SEARCH_HOME_RETURN)
        elif mode == HomeMode.HOME:
            cap = yield from self._search_home(d, turn=True)
        elif mode == HomeMode.HOME_INDEX:
            home = yield from self._search_home(d, turn=True)
            cap = yield from self._index_beyond(home, Stage.SEARCH_HOME_RETURN)
        elif mode == HomeMode.INDEX:
            cap = yield from self._search_index(d, p.velHigh, turn=True)
        else:
            cap = yield from self._search_gpi(d)
            if mode == HomeMode.FORCED_HOME_INDEX:
                cap = yield from self._index_beyond(cap, Stage.SEARCH_INDEX)
        st.capturePos = _long(round(cap))
        st.targetPos = _long(st.capturePos + p.homeOffset)
        st.stage = Stage.GO_HOME
        yield from self._goto(st.targetPos, p.velLow)

    def _find_limit(self, d: int) -> _Steps:
        p, st = self.params, self.status
        st.stage = Stage.SEARCH_LIMIT
        if not self._limit(d):  # not on it already
            why, _ = yield from self._leg(d, p.searchHomeDistance or UNLIMITED, p.velHigh)
            if why != "limit":
                raise _Abort(
                    HomeError.NO_HOME, f"no limit within searchHomeDistance={p.searchHomeDistance}"
                )
        st.stage = Stage.SEARCH_LIMIT_STOP
        yield from self._stop()

    def _limit_return(self, d: int) -> _Steps:
        p, st = self.params, self.status
        st.stage = Stage.SEARCH_LIMIT_ESCAPE
        escaped = 0
        for _ in range(MAX_ESCAPES):
            why, _ = yield from self._leg(-d, p.escapeStep, p.velHigh)
            if why != "end":
                raise _Abort(HomeError.STAGE, "the other limit while escaping from the limit")
            escaped += p.escapeStep
            if not self._limit(d):
                break
        else:
            raise _Abort(
                HomeError.STAGE,
                f"still on the limit after {MAX_ESCAPES} x escapeStep={p.escapeStep}",
            )
        st.stage = Stage.SEARCH_LIMIT_RETURN
        why, pos = yield from self._leg(d, escaped + p.escapeStep, p.velLow)
        if why != "limit":
            raise _Abort(HomeError.NO_HOME, "the limit did not trigger again on the way back")
        st.capturePos = _long(round(pos))
        st.stage = Stage.SEARCH_LIMIT_RETURN_STOP
        yield from self._stop()
        return pos

    def _search_home(self, d: int, turn: bool) -> _Steps:
        p, st, unit = self.params, self.status, self._trigger
        unit.refresh_wiring()
        dist = p.searchHomeDistance or UNLIMITED
        if p.edge == 0 and unit.home_level():
            st.stage = Stage.START  # on the switch: leave it first, backwards
            why, _ = yield from self._leg(
                -d, dist, p.velHigh, lambda: not unit.home_level() or None, unit
            )
            if why != "event":
                raise _Abort(HomeError.NO_HOME, "the axis did not get off the home switch")
            yield from self._stop()
        st.stage = Stage.SEARCH_HOME
        for attempt in (0, 1):
            self._arm(unit, CAPTURE_HOME, p.edge)
            why, pos = yield from self._leg(
                d, dist, p.velHigh, lambda: unit.pos if unit.status else None, latch=unit
            )
            if why == "event":
                st.capturePos = _long(round(pos))
                yield from self._stop()
                return pos
            if why == "limit" and turn and attempt == 0:
                yield from self._stop()  # the home is behind: back over the whole switch
                why, _ = yield from self._leg(-d, dist, p.velHigh, self._passed(unit), unit)
                if why != "event":
                    raise _Abort(HomeError.NO_HOME, "no home switch between the limits")
                yield from self._stop()
                continue
            break
        where = "a limit came first" if why == "limit" else f"searchHomeDistance={dist}"
        raise _Abort(HomeError.NO_HOME, f"no home ({where})")

    def _passed(self, unit: CaptureUnit) -> Callable[[], bool | None]:
        seen = [unit.home_level()]

        def passed() -> bool | None:
            for e in unit.edges:
                if e.signal != CAPTURE_HOME:
                    continue
                if e.active:
                    seen[0] = True
                elif seen[0]:
                    return True
            if unit.home_level():
                seen[0] = True
            return None

        return passed

    def _search_index(
        self, d: int, vel: float, after: float | None = None, turn: bool = False
    ) -> _Steps:
        p, st, unit = self.params, self.status, self._trigger
        st.stage = Stage.SEARCH_INDEX
        dist = p.searchIndexDistance or UNLIMITED
        for attempt in (0, 1):
            accept = None if after is None else _beyond(after, d)
            self._arm(unit, CAPTURE_INDEX, None, accept)
            if not unit.on_card:
                yield from self._arming()
            why, pos = yield from self._leg(
                d, dist, vel, lambda: unit.pos if unit.status else None, latch=unit
            )
            if why == "event":
                st.capturePos = _long(round(pos))
                yield from self._stop()
                return pos
            if why == "limit" and turn and attempt == 0:
                yield from self._stop()
                d = -d
                continue
            break
        where = "a limit came first" if why == "limit" else f"searchIndexDistance={dist}"
        raise _Abort(HomeError.NO_INDEX, f"no index pulse ({where})")

    def _index_beyond(self, home: float, stage: Stage) -> _Steps:
        """Back to the captured home, then the first index beyond it in indexDir."""
        p = self.params
        self.status.stage = stage
        yield from self._goto(round(home), p.velLow)
        return (yield from self._search_index(p.indexDir, p.velLow, after=home))

    def _search_gpi(self, d: int) -> _Steps:
        p, st, unit = self.params, self.status, self.unit
        own = p.triggerIndex == -1
        if own:
            unit.refresh_wiring()
            level: Callable[[], bool] = unit.home_level
        else:
            # a GPI of the controller's IO: only a call (GTE_SetGpi) changes it, and a
            # call gives every axis back first, so the waits stay quiet (:meth:`quiet`
            # compares the registers with what the last step saw)
            io = self._gpio = digital_io(self.ctl)
            k = p.triggerIndex
            level = lambda: io.gpi_level(k)  # noqa: E731
        dist = p.searchHomeDistance or UNLIMITED
        st.stage = Stage.SEARCH_GPI
        for attempt in (0, 1):
            if level():
                break
            why, _ = yield from self._leg(
                d, dist, p.velHigh, lambda: level() or None, unit if own else None
            )
            if why == "event":
                break
            if why != "limit" or attempt:
                raise _Abort(HomeError.NO_HOME, "the trigger did not become active")
            yield from self._stop()  # behind: back over the whole active zone, then again
            why, _ = yield from self._leg(
                -d, dist, p.velHigh, _passed_level(level), unit if own else None
            )
            if why != "event":
                raise _Abort(HomeError.NO_HOME, "the trigger is not active between the limits")
            yield from self._stop()
        yield from self._stop()
        st.stage = Stage.SEARCH_GPI_RETURN

        def gone() -> float | None:
            return None if level() else unit.enc - 0.5 * unit.step

        why, pos = yield from self._leg(-d, dist, p.velLow, gone, unit if own else None)
        if why != "event":
            raise _Abort(HomeError.NO_HOME, "the trigger did not become inactive on the way back")
        st.capturePos = _long(round(pos))
        yield from self._stop()
        return pos

    # --- moves --------------------------------------------------------------------------------
    def _arm(self, unit: CaptureUnit, mode: int, edge: int | None, accept=None) -> None:
        try:
            unit.arm(mode, edge, accept)
        except CommandError as e:
            error = (
                HomeError.SET_CAPTURE_HOME if mode == CAPTURE_HOME else HomeError.SET_CAPTURE_INDEX
            )
            raise _Abort(error, str(e)) from None

    def _arming(self) -> _Steps:
        """The drive's touch probe arms in two cycles (60B8h off, then on): the search
        goes on at the second step after the one that armed it.  Counted in the clock's
        cycles (a step comes after every cycle), so the wait is :meth:`quiet` where the
        axis bank runs the axis: nothing but the cycles' count ends it."""
        clock = self.ctl.clock
        self._arm_due = clock.cycles + 2
        self._waiting = True
        try:
            while clock.cycles < self._arm_due:
                yield
        finally:
            self._waiting = False
            self._arm_due = 0

    def _begin(self, d: int, target: int, vel: float) -> None:
        """Start a Trap move toward ``target`` (direction ``d``), as GT_Update would."""
        self._clear_raised(_POS if d > 0 else _NEG)
        res = self.res
        try:
            res.check_motion("GT_GoHome", d)
        except CommandError as e:
            if not res.ax.servo_on:
                raise _Abort(HomeError.DISABLE, str(e)) from None
            if res.latched & _ALARM:
                raise _Abort(HomeError.ALARM, str(e)) from None
            if res.latched & (_POS if d > 0 else _NEG):  # a target in the limit (go home)
                raise _Abort(HomeError.STAGE, str(e)) from None
            raise _Abort(HomeError.STOP, str(e)) from None
        trap = res.profile.trap
        trap.start(trap.pos, target, vel, self._trap, trap.vel)
        self._expect = target

    def _leg(
        self,
        d: int,
        distance: float,
        vel: float,
        watch: Callable[[], Any] | None = None,
        levels: CaptureUnit | None = None,
        latch: CaptureUnit | None = None,
    ) -> _Steps:
        """Move up to ``distance`` in ``d``; returns ("event", watch's value), ("limit",
        position) when the limit in ``d`` is reached, or ("end", None).  ``watch`` reads
        the trigger's capture (this axis's or another's: ``triggerIndex``), its home level
        or a GPI: what changes them is an input edge of a cycle run on the scalar objects
        or a call, so the wait may be :meth:`quiet`; ``levels``: the capture unit whose
        home level or edges ``watch`` reads (:meth:`CaptureUnit.watch_level`); ``latch``:
        the capture unit whose latch (its status) ``watch`` alone reads - a latch armed
        and empty when the leg starts holds nothing until a cycle's edge sets it, which
        the homings look at (a posted edge, a scalar cycle), so the step after the move
        starts need not read it."""
        trap = self.res.profile.trap
        if self._limit(d):  # standing on that limit already: reached at once
            return "limit", self.unit.enc
        self._begin(d, _long(round(trap.pos + d * distance)), vel)
        bit = _POS if d > 0 else _NEG
        before = self.res.latched & bit
        if levels is not None:
            levels.watch_level(True)
        self._watching = watch is not None
        self._looked = watch is None or (latch is not None and not latch.status)
        self._dir = d
        self._waiting = True
        try:
            while True:
                yield
                if watch is not None:
                    value = watch()
                    if value is not None:
                        return "event", value
                    self._looked = True
                if self._limit(d) or self.res.latched & bit & ~before:
                    return "limit", self.unit.enc - 0.5 * self.unit.step
                self._check_plan(trap)
                if trap.done:
                    return "end", None
        finally:
            self._waiting = self._watching = False
            self._looked = True
            self._dir = 0
            if levels is not None:
                levels.watch_level(False)

    def _check_plan(self, trap: Any) -> None:
        if trap.stopping != StopKind.NONE:
            raise _Abort(
                HomeError.STOP,
                f"axis {self.number} was stopped (GT_Stop, a stop input or the following error)",
            )
        if trap.target != self._expect:
            raise _Abort(HomeError.STAGE, f"another motion command moved axis {self.number}")

    def _stop(self) -> _Steps:
        """Come to a stand with ``dec`` (Trap re-planned to the stopping point)."""
        trap = self.res.profile.trap
        if not trap.done and trap.stopping == StopKind.NONE:
            v, dec = trap.vel, self._trap.dec
            reach = v * abs(v) / (2.0 * dec) + v * self._trap.smooth_time / 2.0
            x = trap.pos + reach
            target = math.ceil(x) if v > 0 else math.floor(x)
            trap.update(target=target)
            self._expect = target
        self._waiting = True
        try:
            while not trap.done:
                yield
        finally:
            self._waiting = False

    def _goto(self, target: int, vel: float) -> _Steps:
        trap = self.res.profile.trap
        if trap.pos == target:
            return
        d = 1 if target > trap.pos else -1
        self._begin(d, target, vel)
        bit = _POS if d > 0 else _NEG
        before = self.res.latched & bit
        self._dir = d
        self._waiting = True
        try:
            while True:
                yield
                if self._limit(d) or self.res.latched & bit & ~before:
                    raise _Abort(HomeError.STAGE, f"a limit on the way to {target}")
                self._check_plan(trap)
                if trap.done:
                    return
        finally:
            self._waiting = False
            self._dir = 0

    def _limit(self, d: int) -> bool | None:
        """The limit input in direction ``d``: as wired (module docstring, "Limits"), else
        the axis's own terminal (60FDh bit 1 / 0); None when there is neither."""
        level = self.res.limit_input(d > 0)
        if level is not None:
            return level
        din = self._din
        if din is None:
            return None
        return bool(din.get() & (_LIMIT_POS_BIT if d > 0 else _LIMIT_NEG_BIT))

    def _clear_raised(self, bits: int) -> None:
        """Clear the limit flags (of ``bits``) whose cause is gone (module docstring)."""
        res = self.res
        flags = res.latched & bits
        if flags:
            res.latched &= ~(flags & ~res.causes())


def _passed_level(level: Callable[[], bool]) -> Callable[[], bool | None]:
    """True once a sampled input has been active and is inactive again."""
    seen = [False]

    def passed() -> bool | None:
        if level():
            seen[0] = True
            return None
        return True if seen[0] else None

    return passed


def _beyond(home: float, d: int) -> Callable[[float], bool]:
    return lambda x: (x - home) * d > 0.0


def _long(v: int) -> int:
    return max(_LONG[0], min(_LONG[1], int(v)))


# --- the controller side ----------------------------------------------------------------------
_HOMES: PerObject[SmartHome] = PerObject("smart_home")
_RUNNING: PerObject[_Homings] = PerObject("smart_homings")


class _Homings:
    """The smart homings running on one controller, stepped after every cycle (its
    ``post_cycle`` hook, :meth:`cycle`).

    The axis bank may run their axes: a homing step reaches a claimed axis only through its
    guards, which give it back first (``bank_safe``).  A homing whose axis the bank runs in
    the middle of a Trap leg has nothing to do until the leg's end sample or an input of the
    axis changes, which gives the axis back before that cycle (:meth:`SmartHome.quiet`).
    Such homings are not stepped, and :meth:`quiet_cycles` tells the controller how many
    cycles it may run at once (:func:`gtecat.controller.core._quiet_way`).  Times are the
    controller's (ns): :attr:`_due` is the start of the first cycle after which some homing
    may have to step, valid while the bank has released nothing since (:attr:`_seen`)."""

    bank_safe = True

    def __init__(self, ctl: Any) -> None:
        self._ref = weakref.ref(ctl)
        self.running: list[SmartHome] = []
        self._due = 0
        self._seen = -1
        #: the last look found a homing that steps every cycle (:meth:`quiet_cycles`)
        self._stepping = True
        #: (time, count, homing): when each quiet homing looks again (:meth:`_settle`)
        self._heap: list[tuple[int, int, SmartHome]] = []
        self._seq = 0
        #: the homings not found quiet, those watching another axis's capture, and each
        #: homing's bank row, as the last look at all of them found them
        self._busy: list[SmartHome] = []
        self._foreign: list[SmartHome] = []
        self._by_row: dict[int, SmartHome] = {}
        self._rows: dict[int, int] | None = None  # (the bank's rows they were found for)

    def bank_steps_row(self, bank: Any, r: int) -> bool:
        """The axis bank's row ``r`` had an edge posted in this cycle: its homing steps it
        after the cycle (:meth:`_settle`: a waiting homing whose row had an event is never
        quiet), so the bank may leave the row open for that step (AxisBank._post_event)."""
        home = _HOMES.get(bank.res[r])
        return (
            home is not None
            and home._gen is not None
            and not home._failing
            and home in self.running
            and home.res.bank is bank
        )

    def add(self, home: SmartHome) -> None:
        if home not in self.running:
            self.running.append(home)
        self._seen = -1
        self._rows = None

    def clear(self) -> None:
        self.running.clear()
        self._seen = -1
        self._rows = None

    def cycle(self, t: int, dt: int) -> None:
        """After the cycle that started at ``t``: step every homing that may have to."""
        running = self.running
        if not running:
            return
        ctl = self._ref()
        if ctl is None:
            return
        bank = ctl.bank
        if bank is not None and self._seen == bank.releases and t < self._due:
            if not bank.evt_rows:
                return  # nothing to do for any of them in this cycle
        self._settle(bank, t + dt, step=True)
        if bank is not None and bank._open:
            bank.close_open()  # (an open row whose homing did not step: as the post leaves it)

    def quiet_cycles(self, n: int) -> int:
        """How many of the next ``n`` cycles no homing has anything to do in."""
        if not self.running:
            return n
        ctl = self._ref()
        if ctl is None:
            return n
        bank = ctl.bank
        t0, dt = ctl.clock.now_ns, ctl.clock.cycle_ns
        if bank is None or self._seen != bank.releases or t0 >= self._due:
            if (
                t0 == self._due
                and not self._stepping
                and bank is not None
                and self._seen == bank.releases
                and not bank.evt_rows
            ):
                return 0  # a homing found quiet up to this cycle steps after it: as found
            self._settle(bank, t0, step=False)
        return min(n, max(0, -((t0 - self._due) // dt)))

    def _settle(self, bank: Any, t_next: int, step: bool) -> None:
        """Find :attr:`_due` for the cycles from the one starting at ``t_next``; ``step``:
        step the homings that may have something to do in the cycle that just ran.

        A homing found quiet up to some cycle, on a claim of its row that is still the row's,
        has nothing to look at before then.  While the bank has released nothing since the
        last look (a release may have given any row back and a claim taken it again), only
        these look again: the ones due by now (:attr:`_heap`: each quiet homing's time, older
        entries left behind and skipped), the ones not found quiet (:attr:`_busy`), the ones
        whose rows had an event in the bank this cycle (a posted edge: a new claim) and the
        ones watching another axis's capture; the others keep their times, unlooked at."""
        dt = self._ref().clock.cycle_ns
        seen = bank.releases if bank is not None else -1
        ids = bank.claim_ids if bank is not None else ()
        t_prev = t_next - dt
        heap = self._heap
        rows = getattr(bank, "_row_of", None)
        if bank is not None and self._seen == seen and self._rows is rows is not None:
            visit = self._busy
            for home in visit:
                home._h_due = -1  # (looked at once)
            while heap and heap[0][0] <= t_prev:
                d, _, home = heapq.heappop(heap)
                if home._h_due == d and home._gen is not None:
                    home._h_due = -1
                    visit.append(home)
            for home in self._foreign:
                if home._h_due != -1 and home._gen is not None:
                    home._h_due = -1
                    visit.append(home)
            if bank.evt_rows:
                by_row = self._by_row
                for r in bank.evt_rows:
                    home = by_row.get(r)
                    if home is not None and home._h_due != -1 and home._gen is not None:
                        home._h_due = -1
                        visit.append(home)
        else:
            visit = list(self.running)
            heap.clear()
            self._foreign = [h for h in visit if h._trigger is not h.unit]
            # every homing's row, claimed now or later (the bank's rows: fixed when built)
            self._rows = rows
            self._by_row = (
                {}
                if rows is None
                else {rows[id(h.res.ax)]: h for h in visit if id(h.res.ax) in rows}
            )
        busy: list[SmartHome] = []  # not found quiet: they look again next time
        for home in visit:
            d = home._q_due
            if not (
                t_prev < d
                and home._q_claim
                and ids[home._q_row] == home._q_claim
                and home._trigger is home.unit
            ):
                # not found quiet before, another claim since, or another axis's capture
                # (that axis may have been given back for an edge: quiet() looks)
                q = home.quiet(bank)
                if q is None:
                    home._q_claim = 0
                    if step:
                        if bank is not None and home.res.bank is bank:
                            # its row stays claimed (a release and a claim, the drive kept)
                            bank.step_claimed(home.res.bank_row, home.cycle)
                        else:
                            home.cycle()
                        if not home.running:
                            self.running.remove(home)
                            home._h_due = -1
                            continue
                        # (a leg the step started in the bank: quiet from now on, as the
                        # next look would find it)
                        q = home.quiet(bank)
                    if q is None:
                        home._h_due = -1
                        busy.append(home)
                        continue
                r = home.res.bank_row
                d = home._q_due = t_next + q * dt
                home._q_row, home._q_claim = r, ids[r]
            home._h_due = d
            self._seq += 1
            heapq.heappush(heap, (d, self._seq, home))
        while heap and (heap[0][2]._h_due != heap[0][0] or heap[0][2]._gen is None):
            heapq.heappop(heap)  # (entries left behind)
        self._busy = busy
        self._due = t_next if busy or not heap else heap[0][0]
        self._stepping = bool(busy)  # some homing steps every cycle (not found quiet)
        # a step that gave an axis back may have changed another homing's axis: look again
        self._seen = seen if bank is not None and bank.releases == seen else -1


def smart_home(ctl: Any, axis: int) -> SmartHome:
    """The smart homing of ``axis`` (made on first use).

    ``axis`` is in the caller's numbering: on a core beyond 1 (a
    :class:`~gtecat.controller.core_view.CoreView`) its local axis, mapped to the bus axis
    once, here.  The homing itself belongs to the bus controller and knows the axis by its
    bus number only, so a core's axis 1 and core 1's axis 33 share one homing."""
    res = axis_resources(ctl, axis)
    base = getattr(ctl, "_base", ctl)
    home = _HOMES.get(res)
    if home is None:
        home = _HOMES[res] = SmartHome(base, res)
    if base not in _RUNNING:
        homings = _RUNNING[base] = _Homings(base)
        base.post_cycle.append(homings.cycle)
        base.on_reset.append(_reset)
    return home


def _register(ctl: Any, home: SmartHome) -> None:
    _RUNNING[ctl].add(home)


def _reset(ctl: Any) -> None:
    for ax in ctl.axes.values():
        home = _HOMES.get(ax.motion) if ax.motion is not None else None
        if home is not None:
            home.reset()
    if ctl in _RUNNING:
        _RUNNING[ctl].clear()


def params_from_fields(values: dict[str, Any]) -> HomeParams:
    """HomeParams from THomePrm's fields (extra fields such as pads are ignored)."""
    names = {f.name for f in fields(HomeParams)}
    return replace(HomeParams(), **{k: v for k, v in values.items() if k in names})


__all__ = [
    "UNLIMITED",
    "HomeError",
    "HomeMode",
    "HomeParams",
    "HomeRefused",
    "HomeStatus",
    "SmartHome",
    "Stage",
    "params_from_fields",
    "smart_home",
]
