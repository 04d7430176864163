"""Jog planner: manual 7.3, GT_SetJogPrm, GT_SetVel (signed speed), GT_Update.

Model
-----
1. **Raw ramp**, continuous time: the raw speed moves toward the target speed
   ``vel`` (its sign is the direction) with ``acc`` while the speed magnitude
   grows and ``dec`` while it falls; reversing brakes with ``dec`` to 0 then
   accelerates with ``acc``.  Each cycle integrates it exactly (a ramp end
   inside a cycle is split there), so with smooth = 0 the sampled position
   is the exact integral of the trapezoidal speed.

2. **Smoothing** (``smooth`` in [0, 1), "the closer to 1, the smoother the
   acceleration", 7.3.2): the output is the raw profile through a
   continuous-time first-order low-pass filter ``τ·y' = x - y`` with
   ``τ = -1 ms / ln(smooth)`` (``smooth`` is the fraction of the filter state
   kept after 1 ms: 0.5 → τ = 1.44 ms, 0.9 → 9.5 ms, 0.99 → 99.5 ms),
   solved in closed form over every constant-acceleration piece, so samples
   do not depend on the cycle time and position, speed and acceleration stay
   each other's derivatives.  The filter has unit gain and a positive impulse
   response: the speed never goes beyond the raw speed's range (no overshoot
   of the target speed), ``|a| <= max(acc, dec)``, and the acceleration
   becomes continuous (an acceleration step turns into an exponential rise,
   jerk at most ``max(acc, dec)/τ``... ``(acc+dec)/τ`` on a reversal).  The
   speed approaches its target asymptotically; it is snapped onto it once
   within 1e-9 (relative).  Starting from a moving state, the raw profile is
   put ``τ·v0`` ahead so the filter starts in its steady state (no jump).

3. **Stopping**: ``update(0)`` ramps down with ``dec`` (a normal jog stop);
   when the raw ramp stands still and the filter has settled (within 1e-6
   pulse/ms, and 1e-6 pulse or the float resolution at that position) the
   output is snapped onto the raw position and the planner is ``done``.  GT_Stop hands over to
   :class:`~gtecat.controller.motion.stop.StopRamp` from the current output.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ...errors import CommandError, ParameterError
from . import checks
from .stop import StopKind, StopRamp

_IDLE, _MOVE, _STOP = 0, 1, 2
_SETTLE = 1e-6  # pulse, pulse/ms: filter residue below which a stopping jog is at rest


@dataclass(frozen=True, slots=True)
class JogParams:
    """TJogPrm as plain data (GT_SetJogPrm, chapter 13).

    ``acc``, ``dec`` > 0 pulse/ms² (``dec == 0`` = not set = ``acc``, as the
    manual says); ``smooth`` in [0, 1).
    """

    acc: float
    dec: float = 0.0
    smooth: float = 0.0

    def __post_init__(self) -> None:
        acc = checks.positive("acc", self.acc)
        dec = checks.non_negative("dec", self.dec) or acc
        smooth = checks.real("smooth", self.smooth)
        if not 0.0 <= smooth < 1.0:
            raise ParameterError(f"smooth must be in [0, 1), got {self.smooth!r}")
        for name, value in (("acc", acc), ("dec", dec), ("smooth", smooth)):
            object.__setattr__(self, name, value)


def ramp(
    p: float, v: float, goal: float, acc: float, dec: float, dt: float
) -> tuple[float, float, float]:
    """Advance the raw ramp by ``dt`` ms exactly; returns ``(p, v, a)`` with ``a`` the
    acceleration in force from then on (0 once the speed is ``goal``)."""
    p, v, a, _, _, _ = advance(p, v, goal, acc, dec, dt, 0.0, 0.0, 0.0, 0.0)
    return p, v, a


def advance(
    p: float,
    v: float,
    goal: float,
    acc: float,
    dec: float,
    dt: float,
    tau: float,
    fp: float,
    fv: float,
    fa: float,
) -> tuple[float, float, float, float, float, float]:
    """Raw ramp and (``tau > 0``) its low-pass filtered copy ``(fp, fv, fa)`` over ``dt`` ms.

    The raw speed is split into constant-acceleration pieces; over a piece of
    length ``h`` the filter of a polynomial input ``x`` has the exact solution
    ``y(h) = x_p(h) + (y(0) - x_p(0))·e^(-h/τ)`` with the particular solution
    ``x_p = x - τ·x' + τ²·x''``.
    """
    while True:
        if v == goal:
            a, h, reached = 0.0, dt, False
        else:
            if v == 0.0 or ((v > 0.0) == (goal > 0.0) and abs(goal) > abs(v)):
                rate, aim = acc, goal  # speeding up (from rest or in the same direction)
            elif (v > 0.0) == (goal > 0.0) and goal != 0.0:
                rate, aim = dec, goal  # slowing down to a lower speed
            else:
                rate, aim = dec, 0.0  # braking to reverse or to stop
            a = rate if aim > v else -rate
            t_reach = (aim - v) / a
            reached = t_reach <= dt
            h = t_reach if reached else dt
        if h > 0.0:
            p1 = p + h * (v + 0.5 * a * h)
            v1 = v + a * h
            if tau > 0.0:
                e = math.exp(-h / tau)
                ta = tau * a
                fp = p1 - tau * (v1 - ta) + (fp - p + tau * (v - ta)) * e
                fv = v1 - ta + (fv - v + ta) * e
                fa = a + (fa - a) * e
            p, v = p1, (aim if reached else v1)
            dt -= h
        elif reached:
            v = aim
        if not reached:
            if tau <= 0.0:
                fp, fv, fa = p, v, a
            return p, v, a, fp, fv, fa


def ramp_step(
    rp: float,
    rv: float,
    goal: float,
    acc: float,
    dec: float,
    dt: float,
    tau: float,
    p: float,
    v: float,
    a: float,
) -> tuple[float, float, float, float, float]:
    """One cycle of a moving jog (:meth:`JogPlanner.step` without its settling, which a jog
    heading for a speed other than 0 never reaches): the raw ramp's new position and speed
    and the output ``(rp, rv, p, v, a)``.  The axis bank's rows take it (its compiled cycle
    the same operations)."""
    rp, rv, _, p, v, a = advance(rp, rv, goal, acc, dec, dt, tau, p, v, a)
    if rv == goal and v != goal and abs(v - goal) <= 1e-9 * (1.0 + abs(goal)):
        v, a = goal, 0.0
    return rp, rv, p, v, a


class JogPlanner:
    """One profile's Jog planner: ``start``/``update`` (GT_Update), ``step`` per cycle, ``stop``."""

    __slots__ = (
        "_T",
        "_acc",
        "_goal",
        "_mode",
        "_pos",
        "_prm",
        "_raw_p",
        "_raw_v",
        "_settle_ulps",
        "_stop",
        "_tau",
        "_vel",
        "stopping",
    )

    def __init__(self, cycle_ms: float = 1.0, pos: float = 0.0) -> None:
        self._T = checks.positive("cycle_ms", cycle_ms)
        self._stop = StopRamp(self._T)
        self._prm: JogParams | None = None
        self._tau = 0.0
        self._settle_ulps = 0.0
        self._goal = 0.0
        self.hold(pos)

    def hold(self, pos: float) -> None:
        """Stand still at ``pos``; forgets any motion."""
        self._pos = self._raw_p = checks.real("pos", pos)
        self._vel = self._acc = self._raw_v = 0.0
        self._mode = _IDLE
        self.stopping = StopKind.NONE

    @property
    def done(self) -> bool:
        """True when the planner stands still."""
        return self._mode == _IDLE

    @property
    def pos(self) -> float:
        """Last planned position, pulse."""
        return self._pos

    @property
    def vel(self) -> float:
        """Last planned velocity, pulse/ms."""
        return self._vel

    @property
    def acc(self) -> float:
        """Last planned acceleration, pulse/ms²."""
        return self._acc

    @property
    def target_vel(self) -> float:
        """The speed the jog is heading for (GT_SetVel + GT_Update), pulse/ms."""
        return self._goal

    @property
    def params(self) -> JogParams | None:
        """Parameters of the current (or last) jog."""
        return self._prm

    @property
    def tau(self) -> float:
        """Time constant of the smoothing filter, ms (0 = no smoothing)."""
        return self._tau

    def start(self, pos: float, vel: float, prm: JogParams, v0: float = 0.0) -> None:
        """GT_Update on an axis at ``pos`` moving at ``v0``: head for the signed speed ``vel``."""
        if not isinstance(prm, JogParams):
            raise ParameterError(f"prm must be JogParams, got {type(prm).__name__}")
        p = checks.real("pos", pos)
        v = checks.real("v0", v0)
        self._goal = checks.real("vel", vel)
        self._prm = prm
        self._tau = tau = -1.0 / math.log(prm.smooth) if prm.smooth > 0.0 else 0.0
        # far from 0 the filter's last step shrinks the lag by less than half an ulp and the
        # lag stops decreasing at about 1/(1 - e^(-T/τ)) ulps: settle there too
        self._settle_ulps = 2.0 / -math.expm1(-self._T / tau) if tau > 0.0 else 0.0
        self._pos, self._vel, self._acc = p, v, 0.0
        self._raw_p, self._raw_v = p + tau * v, v  # filter in its steady state
        self.stopping = StopKind.NONE
        self._mode = _IDLE if (v == 0.0 and self._goal == 0.0) else _MOVE

    def update(self, vel: float) -> None:
        """GT_SetVel + GT_Update while jogging: new signed target speed, at once."""
        goal = checks.real("vel", vel)
        if self._mode != _MOVE:
            if self._prm is None:
                raise CommandError("Jog update before any start: no Jog parameters yet")
            self.start(self._pos, goal, self._prm, self._vel)
            return
        self._goal = goal

    def stop(
        self, dec: float, abrupt: bool = False, origin: tuple[float, float] | None = None
    ) -> None:
        """GT_Stop: brake from the current output with ``dec``.

        ``origin``: brake from this ``(pos, vel)``, taken as the state at the previous
        sample, instead of from the current output; the next ``step()`` gives the ramp
        one cycle after it.  The soft-limit stop of 9.2.2 replaces the sample that passed
        the limit so (:mod:`gtecat.controller.resources`), also when the planner
        finished in that step.
        """
        if origin is None:
            if self._mode == _IDLE:
                return
            origin = (self._pos, self._vel)
        self._stop.start(origin[0], origin[1], dec)
        self._pos, self._vel = origin
        self._mode = _STOP
        self.stopping = StopKind.ABRUPT if abrupt else StopKind.SMOOTH
        self._goal = 0.0
        if self._stop.done:
            self._settle(self._pos)

    def step(self) -> tuple[float, float, float]:
        """One controller cycle: ``(pos, vel, acc)``."""
        mode = self._mode
        if mode == _MOVE:
            prm = self._prm
            assert prm is not None
            goal = self._goal
            rp, rv, p, v, a = ramp_step(
                self._raw_p,
                self._raw_v,
                goal,
                prm.acc,
                prm.dec,
                self._T,
                self._tau,
                self._pos,
                self._vel,
                self._acc,
            )
            self._raw_p, self._raw_v = rp, rv
            self._pos, self._vel, self._acc = p, v, a
            if (
                rv == 0.0
                and goal == 0.0
                and abs(v) <= _SETTLE
                and abs(p - rp) <= _SETTLE + self._settle_ulps * math.ulp(rp)
            ):
                self._settle(rp)
        elif mode == _STOP:
            self._pos, self._vel, self._acc = self._stop.step()
            if self._stop.done:
                self._settle(self._pos)
        return self._pos, self._vel, self._acc

    def _settle(self, pos: float) -> None:
        self._pos = self._raw_p = pos
        self._vel = self._acc = self._raw_v = 0.0
        self._mode = _IDLE
        self.stopping = StopKind.NONE  # (a stop that has ended: TrapPlanner._finish)
