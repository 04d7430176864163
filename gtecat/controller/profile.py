"""The profile resource (规划器, manual 4.2.2 and 4.3.3): one motion mode and its planner per axis.

A profile plans in its own units (pulse, pulse/ms, pulse/ms²) and holds, at any
time, exactly one motion mode (7.1: "每一个轴在任一时刻只能处在一种运动模式下") with
one planner in :attr:`Profile.planner`.  Any object following
:class:`gtecat.controller.motion.Planner` (``step/stop/hold/done/pos/vel/acc/stopping``)
plugs in: Trap and Jog are built here; the PT, Gear and Follow GT wrappers put
their planners in the same slot with :meth:`Profile.enter`, and so do the pulse-card
compat layers (:mod:`gtecat.compat`) with the T/S-curve drive planner in ``CARD_DRIVE``.

A mode changes only while the profile stands still (7.1: "在设置或切换运动模式时，要保证
轴处于规划静止状态"); the new planner starts held at the current position.

Defaults where the manual is silent (GT_GetTrapPrm / GT_GetJogPrm right after
GT_Reset): Trap acc = dec = 0.1 pulse/ms², velStart 0, smoothTime 0; Jog acc =
dec = 0.1 pulse/ms², smooth 0; no Trap speed (GT_Update refuses the move until
GT_SetVel), Jog speed 0.  The stop decelerations are table 4-4's (1 and 1000
pulse/ms²).  Parameters persist across mode changes until GT_Reset; the Trap
target is set to the current position when the profile enters Trap mode, and by
GT_SetPrfPos / GT_ZeroPos, so a GT_Update without GT_SetPos never moves.
"""

from __future__ import annotations

from collections.abc import Callable
from enum import IntEnum

from ..errors import CommandError
from .motion import JogParams, JogPlanner, Planner, StopDecel, TrapParams, TrapPlanner
from .motion.stop import StopKind


class PrfMode(IntEnum):
    """GT_GetPrfMode values (chapter 13 entry 63)."""

    TRAP = 0
    JOG = 1
    PT = 2
    GEAR = 3
    FOLLOW = 4
    INTERPOLATION = 5
    PVT = 6
    #: not a manual mode: the pulse-card drive of the compat layers (the MCX314 thesis and
    #: the ADT850 manual, :mod:`gtecat.controller.motion.scurve`), what GT_GetPrfMode
    #: reports for such an axis
    CARD_DRIVE = 16


DEFAULT_TRAP = TrapParams(acc=0.1, dec=0.1, vel_start=0.0, smooth_time=0)
DEFAULT_JOG = JogParams(acc=0.1, dec=0.1, smooth=0.0)


class Profile:
    """One profile: the current mode, its planner, the Trap/Jog settings and stop decelerations."""

    def __init__(self, number: int, cycle_ms: float) -> None:
        self.number = number
        self.cycle_ms = cycle_ms
        self.trap = TrapPlanner(cycle_ms)
        self.jog = JogPlanner(cycle_ms)
        self.reset()

    def reset(self, pos: float = 0.0) -> None:
        """Table 4-4 / GT_Reset: Trap mode at rest at ``pos``, default parameters."""
        self.active = True
        self.mode = PrfMode.TRAP
        self.planner: Planner = self.trap
        #: planners of the other modes, kept while the profile is in another mode
        self.planners: dict[PrfMode, Planner] = {PrfMode.TRAP: self.trap, PrfMode.JOG: self.jog}
        self.trap_prm = DEFAULT_TRAP
        self.trap_target = round(pos)
        self.trap_vel = 0.0  # not set
        self.jog_prm = DEFAULT_JOG
        self.jog_vel = 0.0
        self.stop_dec = StopDecel()
        self.trap.hold(pos)
        self.jog.hold(pos)

    # --- state ---------------------------------------------------------------------------
    @property
    def moving(self) -> bool:
        """Bit 10 of GT_GetSts: the planner is not at rest (a stop ramp counts as motion)."""
        return not self.planner.done

    @property
    def pos(self) -> float:
        return self.planner.pos

    @property
    def vel(self) -> float:
        return self.planner.vel

    @property
    def acc(self) -> float:
        return self.planner.acc

    # --- modes ---------------------------------------------------------------------------
    def require_idle(self, what: str) -> None:
        if not self.planner.done:
            raise CommandError(
                f"profile {self.number} is moving ({self.mode.name} mode): call GT_Stop and wait "
                f"until it stands (GT_GetSts bit 10 = 0) before {what}"
            )

    def require_mode(self, what: str, *modes: PrfMode) -> None:
        if self.mode not in modes:
            names = " or ".join(m.name.capitalize() for m in modes)
            calls = " / ".join(f"GT_Prf{m.name.capitalize()}" for m in modes)
            raise CommandError(
                f"{what}: profile {self.number} is in {self.mode.name.capitalize()} mode, not "
                f"{names}; call {calls} first"
            )

    def enter(
        self,
        mode: PrfMode,
        planner: Planner | None = None,
        factory: Callable[[], Planner] | None = None,
    ) -> Planner:
        """Switch to ``mode`` (the profile must stand still); the planner starts held here.

        ``planner`` replaces the mode's planner; ``factory`` makes one if the
        mode has none yet; otherwise the mode's previous planner is reused.
        """
        self.require_idle(f"switching to {mode.name.capitalize()} mode")
        pos = self.planner.pos
        if planner is None:
            planner = self.planners.get(mode)
            if planner is None:
                if factory is None:
                    raise CommandError(f"{mode.name} mode is not available on this controller")
                planner = factory()
        self.planners[mode] = planner
        planner.hold(pos)
        if mode == PrfMode.TRAP and self.mode != PrfMode.TRAP:
            self.trap_target = round(pos)
        self.mode = mode
        self.planner = planner
        return planner

    def hold(self, pos: float) -> None:
        """Stand still at ``pos`` (servo off, GT_SetPrfPos, GT_ZeroPos): any motion is dropped."""
        self.planner.hold(pos)

    def redefine(self, pos: float) -> None:
        """GT_SetPrfPos / GT_ZeroPos: the position becomes ``pos``; the Trap target too."""
        self.planner.hold(pos)
        self.trap_target = round(pos)

    # --- stops ---------------------------------------------------------------------------
    def stop(self, abrupt: bool) -> None:
        """GT_Stop for this profile: smooth (decSmoothStop) or abrupt (decAbruptStop)."""
        p = self.planner
        if p.done:
            return
        if abrupt and p.stopping == StopKind.ABRUPT:
            return  # already braking with the abrupt deceleration
        p.stop(self.stop_dec.for_kind(abrupt), abrupt)
