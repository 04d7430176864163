"""Point-to-point (Trap) planner: manual 7.2, GT_SetTrapPrm, GT_SetPos, GT_SetVel, GT_Update.

Model (what an independent computation must reproduce)
------------------------------------------------------
Units are the manual's: pulse, pulse/ms, pulse/ms², ms.

1. **Raw profile**, continuous time, constant-acceleration pieces.  From the
   state ``(p, v)`` the raw profile goes to ``target`` with speed limit
   ``vel`` (GT_SetVel), using ``acc`` while the speed magnitude grows and
   ``dec`` while it falls:

   * standing (or slower than velStart): jump to ``velStart`` toward the
     target (``velStart`` is capped at ``vel``);
   * moving away from the target: brake with ``dec`` down to ``velStart``,
     drop to 0, then start as from standstill;
   * moving toward the target too fast to stop on it (braking distance
     ``(v² - velStart²)/(2·dec)`` longer than the distance): brake with
     ``dec`` to ``velStart``, drop to 0 (past the target), come back;
   * otherwise trapezoid: reach ``vp`` (accelerating with ``acc``, or braking
     with ``dec`` if faster than ``vel``), cruise, decelerate with ``dec`` to
     ``velStart`` exactly at the target, then drop to 0.  ``vp = vel`` if the
     distance allows it, else (triangle)
     ``vp² = (2·acc·dec·D + dec·v² + acc·velStart²) / (acc + dec)``.

   Before the start the raw profile rests at the start position (or, when
   started while moving at ``v0``, moves steadily at ``v0`` so that the
   smoothed output starts exactly at ``(pos, v0)``).  Velocity jumps happen
   only by velStart (start, arrival, reversal); with velStart 0 the raw speed
   is continuous.  From standstill with velStart 0 this is the textbook trapezoid
   ``t_acc = vel/acc``, ``t_dec = vel/dec``,
   ``t_cruise = (D - vel²/(2acc) - vel²/(2dec)) / vel``.

2. **Smoothing** (smoothTime ``Ts``, 0..50 ms: "the time over which the
   acceleration changes", 7.2.2): the output is the moving average of the raw
   position over the last ``Ts`` ms, ``p(t) = 1/Ts ∫[t-Ts, t] p_raw``, so
   ``v(t) = (p_raw(t) - p_raw(t-Ts))/Ts`` and
   ``a(t) = (v_raw(t) - v_raw(t-Ts))/Ts``.  Each acceleration step of the raw
   profile becomes a linear ramp lasting exactly ``Ts`` (jerk ``acc/Ts``,
   at most ``(acc+dec)/Ts`` where an acceleration meets a deceleration
   within ``Ts``); ``|v| <= vel`` and ``|a| <= max(acc, dec)`` still hold
   (a velStart jump becomes a ramp of ``velStart/Ts``, faster than acc when
   ``velStart > acc·Ts``); the output is an average of positions that never
   pass the target, so it never passes it either; the move lasts ``Ts``
   longer than the raw profile.  ``Ts = 0`` is the raw profile itself.

3. **Sampling**: ``start`` happens at the current cycle (t = 0); the k-th
   ``step()`` returns the closed-form output at ``t = k·cycle_ms``
   (floats).  The first sample with ``t >= t_end`` (raw end + ``Ts``) is
   exactly ``(target, 0, 0)`` and sets ``done``; so the move takes
   ``ceil(t_end / cycle_ms)`` cycles.  Samples of the final monotone
   approach are clamped onto the target side, so float rounding can never
   put one past it.

4. **GT_Update while moving** (``update``): the raw profile is re-planned at
   the current cycle from its own state (position, speed), so a new target
   or speed takes effect at once without a position or speed jump, without
   exceeding acc/dec, reversing when the new target is behind; the
   smoothing window keeps averaging the raw history, so the output stays
   smooth too.  An update with unchanged target and speed leaves the
   trajectory unchanged.

A stop (GT_Stop) hands over to :class:`~gtecat.controller.motion.stop.StopRamp` from the
current output.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ...errors import CommandError, ParameterError
from . import checks
from .stop import StopKind, StopRamp

#: smoothTime range of GT_SetTrapPrm, ms (chapter 13, 7.2.2)
SMOOTH_TIME_MAX = 50

_IDLE, _MOVE, _STOP = 0, 1, 2
#: a TrapPlanner's ``_mode`` when it stands still (``done``): the GT fast path reads the
#: status word's bit 10 of a Trap axis without the property's call (gtecat.gt.fast)
IDLE_MODE = _IDLE
_EPS_T = 1e-9  # ms: a sample this close to the end time is the end sample


@dataclass(frozen=True, slots=True)
class TrapParams:
    """TTrapPrm as plain data (GT_SetTrapPrm, chapter 13).

    ``acc``, ``dec`` > 0 pulse/ms²; ``dec == 0`` means "not set" and takes
    ``acc`` (the manual: "未设置减速度时，默认减速度和加速度相同");
    ``vel_start`` >= 0 pulse/ms; ``smooth_time`` an integer in [0, 50] ms.
    """

    acc: float
    dec: float = 0.0
    vel_start: float = 0.0
    smooth_time: int = 0

    def __post_init__(self) -> None:
        acc = checks.positive("acc", self.acc)
        dec = checks.non_negative("dec", self.dec) or acc
        vs = checks.non_negative("velStart", self.vel_start)
        ts = checks.integer("smoothTime", self.smooth_time)
        if not 0 <= ts <= SMOOTH_TIME_MAX:
            raise ParameterError(f"smoothTime must be in [0, 50] ms, got {self.smooth_time!r}")
        for name, value in (("acc", acc), ("dec", dec), ("vel_start", vs), ("smooth_time", ts)):
            object.__setattr__(self, name, value)


Segment = tuple[float, float, float, float]
"""One raw piece ``(t0, p0, v0, a)``: ``p = p0 + v0·τ + a·τ²/2`` from ``t0`` to the next piece."""


def raw_plan(
    t: float, p: float, v: float, target: float, vel: float, acc: float, dec: float, vs: float
) -> tuple[list[Segment], float, float, float]:
    """The raw profile from ``(p, v)`` at time ``t`` to ``target`` (module docstring, 1).

    Returns ``(segments, t_end, t_final, direction)``: the pieces (the last
    one is the rest piece at ``target``), the arrival time, the time the
    final monotone approach begins and its direction (+1/-1).
    """
    segs: list[Segment] = []
    vs = min(vs, vel)
    t_final = t
    s = 1.0
    for _ in range(4):  # at most: brake away, start, brake past, come back
        dist = target - p
        if dist == 0.0 and v == 0.0:
            break
        s = 1.0 if dist > 0.0 else -1.0 if dist < 0.0 else (-1.0 if v > 0.0 else 1.0)
        t_final = t
        if v * s < 0.0:  # moving away: brake to velStart, drop to 0
            u = abs(v)
            if u > vs:
                dur = (u - vs) / dec
                segs.append((t, p, v, s * dec))
                p += dur * (v + 0.5 * s * dec * dur)
                t += dur
            v = 0.0
            continue
        u = max(abs(v), vs)
        dabs = abs(dist)
        brake = (u * u - vs * vs) / (2.0 * dec)
        tol = 1e-9 * max(1.0, dabs)
        if brake > dabs + tol:  # cannot stop on the target: brake past it and come back
            dur = (u - vs) / dec
            segs.append((t, p, s * u, -s * dec))
            p += s * dur * (u - 0.5 * dec * dur)
            t += dur
            v = 0.0
            continue
        if brake >= dabs - tol:  # just a deceleration onto the target
            if u > vs:
                d_eff = (u * u - vs * vs) / (2.0 * dabs)
                segs.append((t, p, s * u, -s * d_eff))
                t += (u - vs) / d_eff
            break
        if u > vel:  # slower speed asked: brake to vel first
            vp = vel
            t1 = (u - vp) / dec
            d1 = (u * u - vp * vp) / (2.0 * dec)
            a1 = -dec
        else:
            vp = math.sqrt((2.0 * acc * dec * dabs + dec * u * u + acc * vs * vs) / (acc + dec))
            vp = max(min(vp, vel), u)
            t1 = (vp - u) / acc
            d1 = (vp * vp - u * u) / (2.0 * acc)
            a1 = acc
        d3 = (vp * vp - vs * vs) / (2.0 * dec)
        t3 = (vp - vs) / dec
        d2 = max(dabs - d1 - d3, 0.0)
        t2 = d2 / vp
        if t1 > 0.0:
            segs.append((t, p, s * u, s * a1))
            p += s * d1
            t += t1
        if t2 > 0.0:
            segs.append((t, p, s * vp, 0.0))
            p += s * d2
            t += t2
        if t3 > 0.0:
            segs.append((t, p, s * vp, -s * dec))
            t += t3
        break
    segs.append((t, float(target), 0.0, 0.0))
    return segs, t, t_final, s


class TrapPlanner:
    """One profile's Trap planner: ``start``/``update`` (GT_Update), ``step`` per cycle, ``stop``.

    Positions are floats in pulse (the end position is the integer target
    exactly); ``step()`` costs a few µs of pure Python.
    """

    __slots__ = (
        "_T",
        "_acc",
        "_dir",
        "_i",
        "_j",
        "_k",
        "_mode",
        "_pos",
        "_prm",
        "_segs",
        "_speed",
        "_stop",
        "_t_done",
        "_t_final",
        "_target",
        "_ts",
        "_vel",
        "stopping",
    )

    def __init__(self, cycle_ms: float = 1.0, pos: float = 0.0) -> None:
        self._T = checks.positive("cycle_ms", cycle_ms)
        self._stop = StopRamp(self._T)
        self._prm: TrapParams | None = None
        self._target = 0
        self._speed = 0.0
        self.hold(pos)

    # ---------------------------------------------------------------- state
    def hold(self, pos: float) -> None:
        """Stand still at ``pos`` (GT_SetPrfPos, GT_ZeroPos, mode change); forgets any motion."""
        self._pos = checks.real("pos", pos)
        self._vel = self._acc = 0.0
        self._mode = _IDLE
        self._segs: list[Segment] = []
        self._i = self._j = self._k = 0
        self._ts = 0.0
        self._t_done = self._t_final = 0.0
        self._dir = 1.0
        self.stopping = StopKind.NONE

    @property
    def done(self) -> bool:
        """True when the planner stands still (motion finished, stopped, or never started)."""
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
    def target(self) -> int:
        """Target of the current (or last) move, pulse."""
        return self._target

    @property
    def speed(self) -> float:
        """Speed limit of the current (or last) move, pulse/ms."""
        return self._speed

    @property
    def params(self) -> TrapParams | None:
        """Parameters of the current (or last) move."""
        return self._prm

    @property
    def time(self) -> float:
        """ms since the move started (the time of the last sample)."""
        return self._k * self._T

    @property
    def t_end(self) -> float:
        """ms from the start to the end sample of the planned move (raw end + smoothTime)."""
        return self._t_done

    # ------------------------------------------------------------- commands
    def start(self, pos: float, target: int, vel: float, prm: TrapParams, v0: float = 0.0) -> None:
        """GT_Update on an axis at ``pos`` moving at ``v0`` (0 when standing): go to ``target``.

        ``vel`` is GT_SetVel's speed (> 0).  With smoothing and ``v0 != 0`` the
        history before the start is taken as steady motion at ``v0``, so the
        output continues from ``(pos, v0)`` without a jump.
        """
        if not isinstance(prm, TrapParams):
            raise ParameterError(f"prm must be TrapParams, got {type(prm).__name__}")
        p = checks.real("pos", pos)
        v = checks.real("v0", v0)
        self._target = checks.integer("target", target)
        self._speed = checks.positive("vel", vel)
        self._prm = prm
        self._ts = ts = float(prm.smooth_time)
        self._k = 0
        self._pos, self._vel, self._acc = p, v, 0.0
        self.stopping = StopKind.NONE
        p_raw = p + 0.5 * v * ts  # a steady history averaging to (p, v) at t = 0
        self._segs = [(-ts - 1.0, p_raw - v * (ts + 1.0), v, 0.0)]
        self._i = self._j = 0
        if v == 0.0 and p == self._target:
            self._mode = _IDLE
            self._pos = float(self._target)
            return
        self._mode = _MOVE
        self._replan(0.0, p_raw, v)

    def update(self, target: int | None = None, vel: float | None = None) -> None:
        """GT_Update with a new target and/or speed; takes effect at the current cycle."""
        new_target = self._target if target is None else checks.integer("target", target)
        new_speed = self._speed if vel is None else checks.positive("vel", vel)
        if self._mode != _MOVE:
            if self._prm is None:
                raise CommandError("Trap update before any start: no Trap parameters yet")
            self.start(self._pos, new_target, new_speed, self._prm, self._vel)
            return
        self._target, self._speed = new_target, new_speed
        t = self._k * self._T
        segs = self._segs
        i = self._i
        while i + 1 < len(segs) and segs[i + 1][0] <= t:
            i += 1
        t0, p0, v0, a = segs[i]
        tau = t - t0
        p, v = p0 + tau * (v0 + 0.5 * a * tau), v0 + a * tau
        if v == 0.0 and p == new_target:
            return  # the raw profile already rests there (smoothing tail): nothing to re-plan
        self._replan(t, p, v)

    def stop(
        self, dec: float, abrupt: bool = False, origin: tuple[float, float] | None = None
    ) -> None:
        """GT_Stop: brake from the current output with ``dec`` (smooth or abrupt deceleration).

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
        if self._stop.done:
            self._finish(self._pos)

    # ----------------------------------------------------------------- cycle
    def step(self) -> tuple[float, float, float]:
        """One controller cycle: ``(pos, vel, acc)`` of the planned profile."""
        mode = self._mode
        if mode == _MOVE:
            self._k += 1
            t = self._k * self._T
            if t >= self._t_done - _EPS_T * (1.0 + self._t_done * 1e-3):
                self._finish(float(self._target))
                return self._pos, 0.0, 0.0
            self._sample(t)
        elif mode == _STOP:
            self._pos, self._vel, self._acc = self._stop.step()
            if self._stop.done:
                self._finish(self._pos)
        return self._pos, self._vel, self._acc

    # ------------------------------------------------------------ internals
    def _finish(self, pos: float) -> None:
        # at rest, a stop has ended: its kind is forgotten (as PvtPlanner does), so nothing
        # that asks "is this axis stopping?" (the axis bank's claim among them) sees a stop
        # that is over
        self._pos = pos
        self._vel = self._acc = 0.0
        self._mode = _IDLE
        self.stopping = StopKind.NONE
        self._segs = []
        self._i = self._j = 0

    def _replan(self, t: float, p: float, v: float) -> None:
        """Replace the raw profile from time ``t`` on; keep the history the window still needs."""
        prm = self._prm
        assert prm is not None
        new, t_end, t_final, s = raw_plan(
            t, p, v, self._target, self._speed, prm.acc, prm.dec, prm.vel_start
        )
        segs = self._segs
        keep = 0  # last piece starting at or before t
        while keep + 1 < len(segs) and segs[keep + 1][0] <= t:
            keep += 1
        first = 0  # first piece the smoothing window [t - Ts, t] still touches
        while first + 1 <= keep and segs[first + 1][0] <= t - self._ts:
            first += 1
        self._segs = segs[first : keep + 1] + new
        self._i = self._j = 0
        self._t_done = t_end + self._ts
        self._t_final = t_final
        self._dir = s

    def _sample(self, t: float) -> None:
        segs = self._segs
        n = len(segs)
        i = self._i
        while i + 1 < n and segs[i + 1][0] <= t:
            i += 1
        self._i = i
        t0, p0, v0, a = segs[i]
        tau = t - t0
        p = p0 + tau * (v0 + 0.5 * a * tau)
        v = v0 + a * tau
        ts = self._ts
        if ts > 0.0:
            ta = t - ts
            j = self._j
            while j + 1 < n and segs[j + 1][0] <= ta:
                j += 1
            self._j = j
            # integrals of (p_raw - p) and of v_raw over [ta, t], piece by piece, each from
            # its local state (no large-number cancellation far from the origin)
            t0, p0, v0, ak = segs[j]
            tau = ta - t0
            pk = p0 + tau * (v0 + 0.5 * ak * tau) - p
            va = vk = v0 + ak * tau
            lo = ta
            total = dist = 0.0
            k = j
            while True:
                hi = t if k == i else segs[k + 1][0]
                span = hi - lo
                if span > 0.0:
                    total += span * (pk + span * (0.5 * vk + ak * span / 6.0))
                    dist += span * (vk + 0.5 * ak * span)
                if k == i:
                    break
                k += 1
                lo, pk, vk, ak = segs[k]
                pk -= p
            p += total / ts
            v, a = dist / ts, (v - va) / ts
        if t - ts >= self._t_final:  # final monotone approach: never past the target
            tgt = float(self._target)
            p = min(p, tgt) if self._dir > 0.0 else max(p, tgt)
        self._pos, self._vel, self._acc = p, v, a
