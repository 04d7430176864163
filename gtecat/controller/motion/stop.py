"""Stop ramps: GT_Stop's smooth stop and abrupt (emergency) stop, manual 9.4 and GT_SetStopDec.

A stop starts from whatever the axis is commanding *now* - the last output
sample ``(pos, vel)`` of any planner (Trap, Jog, later PT/Gear/Follow) - and
brings the speed to zero with a constant deceleration: ``decSmoothStop`` for a
smooth stop, ``decAbruptStop`` for an emergency stop (defaults 1 and 1000
pulse/ms², table 4-4).  The ramp is not smoothed (a stop is a stop: it must
not be delayed by a Trap smoothTime window of up to 50 ms), so the
acceleration jumps to ``-dec`` at the first cycle.

Sampling: the ramp is the closed-form ``p(τ) = p0 + v0·τ - s·dec·τ²/2`` for
``τ = k·cycle_ms``; the first sample with ``τ >= |v0|/dec`` is the exact end
point ``p0 + s·v0²/(2·dec)`` with zero speed.  The end point is not rounded
to a whole pulse: the planned position is a double in the GT API
(``GT_GetPrfPos``) and the controller rounds when it writes 607Ah.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

from ...errors import ParameterError
from . import checks

#: GT_SetStopDec range for both decelerations: (0, 32767] pulse/ms² (chapter 13)
STOP_DEC_MAX = 32767.0


class StopKind(IntEnum):
    """What a planner is doing about a stop request (GT_Stop ``option`` bit)."""

    NONE = 0
    SMOOTH = 1
    ABRUPT = 2


@dataclass(frozen=True, slots=True)
class StopDecel:
    """A profile's two stop decelerations (GT_SetStopDec / GT_GetStopDec; table 4-4 defaults)."""

    smooth: float = 1.0
    abrupt: float = 1000.0

    def __post_init__(self) -> None:
        for name, value in (("decSmoothStop", self.smooth), ("decAbruptStop", self.abrupt)):
            x = checks.positive(name, value)
            if x > STOP_DEC_MAX:
                raise ParameterError(f"{name} must be in (0, 32767] pulse/ms², got {value!r}")

    def for_kind(self, abrupt: bool) -> float:
        """The deceleration GT_Stop uses for one axis (``option`` bit set = abrupt)."""
        return self.abrupt if abrupt else self.smooth


def stop_distance(vel: float, dec: float) -> float:
    """Signed distance covered while braking from ``vel`` to zero with ``dec`` (pulse)."""
    return vel * abs(vel) / (2.0 * dec)


def ramp_through(pos: float, vel: float, dec: float, before: float) -> tuple[float, float]:
    """The state ``before`` ms earlier on the braking ramp (``dec``) that passes ``(pos, vel)``.

    A :class:`StopRamp` started from the returned ``(pos0, vel0)`` is at ``(pos, vel)``
    ``before`` ms later and comes to rest at ``pos + stop_distance(vel, dec)``: how a
    stop that begins between two samples (the soft-limit stop of 9.2.2) is sampled on
    the controller's cycle grid.  ``vel == 0``: ``(pos, 0)``, a ramp that is already over.
    """
    if vel == 0.0:
        return pos, 0.0
    a = -dec if vel > 0.0 else dec
    v0 = vel - a * before
    return pos - before * (v0 + 0.5 * a * before), v0


class StopRamp:
    """Constant-deceleration ramp from ``(pos, vel)`` to standstill, one sample per cycle.

    ``start(pos, vel, dec)`` at the current cycle; each ``step()`` returns
    ``(pos, vel, acc)`` one cycle later; ``done`` once the end sample was given.
    """

    __slots__ = ("_T", "_a", "_k", "_p0", "_p_end", "_pos", "_t_end", "_v0", "_vel", "done")

    def __init__(self, cycle_ms: float = 1.0) -> None:
        self._T = checks.positive("cycle_ms", cycle_ms)
        self._k = 0
        self._p0 = self._p_end = self._pos = 0.0
        self._v0 = self._vel = self._a = 0.0
        self._t_end = 0.0
        self.done = True

    def start(self, pos: float, vel: float, dec: float) -> None:
        """Begin braking at the current cycle from the commanded ``pos``/``vel``."""
        p = checks.real("pos", pos)
        v = checks.real("vel", vel)
        d = checks.positive("dec", dec)
        self._k = 0
        self._p0 = self._pos = p
        self._v0 = self._vel = v
        self._a = -d if v > 0.0 else d
        self._t_end = abs(v) / d
        self._p_end = p + stop_distance(v, d)
        self.done = v == 0.0
        if self.done:
            self._a = 0.0

    @property
    def t_end(self) -> float:
        """Braking time in ms from the start of the ramp."""
        return self._t_end

    @property
    def end_pos(self) -> float:
        """Where the ramp comes to rest."""
        return self._p_end

    def step(self) -> tuple[float, float, float]:
        """Advance one cycle; returns ``(pos, vel, acc)`` in pulse, pulse/ms, pulse/ms²."""
        if self.done:
            return self._pos, 0.0, 0.0
        self._k += 1
        tau = self._k * self._T
        if tau >= self._t_end:
            self.done = True
            self._pos, self._vel = self._p_end, 0.0
            return self._p_end, 0.0, 0.0
        a = self._a
        self._vel = self._v0 + a * tau
        self._pos = self._p0 + tau * (self._v0 + 0.5 * a * tau)
        return self._pos, self._vel, a
