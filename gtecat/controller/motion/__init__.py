"""Motion planners, one per mode of manual chapter 7, plus the stop ramps of 9.4.

Every planner works in the manual's units (pulse, pulse/ms, pulse/ms²) and
gives one sample per controller cycle of ``cycle_ms``; the controller calls
``step()`` once per cycle and writes the position (scaled, rounded) to 607Ah.
They share one small surface, :class:`Planner`, so the controller can stop,
hold and sample any mode alike.  ``stop(dec, abrupt, origin)`` brakes from the
current output, or from ``origin = (pos, vel)`` taken as the state at the previous
sample: the soft-limit stop of 9.2.2 replaces the sample that passed the limit so.
"""

from __future__ import annotations

from typing import Protocol

from .jog import JogParams, JogPlanner
from .scurve import SCurveParams, SCurvePlanner
from .stop import STOP_DEC_MAX, StopDecel, StopKind, StopRamp, ramp_through, stop_distance
from .trap import SMOOTH_TIME_MAX, TrapParams, TrapPlanner, raw_plan


class Planner(Protocol):
    """What the controller needs from any mode's planner."""

    stopping: StopKind

    @property
    def done(self) -> bool: ...
    @property
    def pos(self) -> float: ...
    @property
    def vel(self) -> float: ...
    @property
    def acc(self) -> float: ...
    def step(self) -> tuple[float, float, float]: ...
    def stop(
        self, dec: float, abrupt: bool = False, origin: tuple[float, float] | None = None
    ) -> None: ...
    def hold(self, pos: float) -> None: ...


__all__ = [
    "SMOOTH_TIME_MAX",
    "STOP_DEC_MAX",
    "JogParams",
    "JogPlanner",
    "Planner",
    "SCurveParams",
    "SCurvePlanner",
    "StopDecel",
    "StopKind",
    "StopRamp",
    "TrapParams",
    "TrapPlanner",
    "ramp_through",
    "raw_plan",
    "stop_distance",
]
