"""Motor, load and the drive's control loop, in drive counts (floats).

One rigid axis: position ``pos`` (machine counts), velocity ``vel`` (counts/s).
The drive's cascaded position/velocity loop is reduced to what a master can
observe at its cycle:

- position control with velocity feed-forward ``kff`` and a proportional
  position gain ``kp``.  Over one cycle with a demand moving at ``vff``, the
  following error obeys de/dt = (1 - kff)·vff - kp·e, integrated exactly, so
  the model is stable for every cycle time.  At constant speed the lag is
  (1 - kff)·v/kp: 0.01·100000/1000 = 1 count at 10 rev/s with the defaults,
  a few counts at top speed;
- acceleration limited by the maximum torque (6072h) and the rated
  acceleration, velocity limited by the maximum speed; when the acceleration
  limit bites, the commanded speed is also capped at the speed from which the
  axis can still stop on the demand, and the axis never runs past the demand
  within a cycle (no wind-up overshoot after a step, monotonic approach);
- torque (6077h, per mille of rated torque) = inertia term + viscous friction;
  the current (6078h) is taken proportional to torque.

Pure Python floats and no allocation: this runs every cycle for every axis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class MechanicsParams:
    """Motor and loop constants (speeds and accelerations per motor revolution)."""

    counts_per_rev: int = 10000
    max_speed_rpm: float = 5000.0
    #: acceleration of the loaded motor at rated torque (1000 per mille), rev/s²
    rated_accel_rps2: float = 300.0
    #: position loop gain, 1/s
    kp: float = 1000.0
    #: velocity feed-forward, fraction of the demand velocity
    kff: float = 0.99
    #: viscous friction at maximum speed, per mille of rated torque
    viscous_permille: float = 50.0
    #: deceleration of the unpowered (coasting) motor, rev/s²
    coast_decel_rps2: float = 20.0


class Mechanics:
    """State and one-cycle integrators of one axis."""

    __slots__ = (
        "_c",
        "_dt",
        "_e",
        "a_rated",
        "acc",
        "amax",
        "coast_decel",
        "kff",
        "kp",
        "limited",
        "pos",
        "torque",
        "vel",
        "visc",
        "vmax",
    )

    def __init__(self, params: MechanicsParams, position: float = 0.0, max_torque: int = 3000):
        cpr = params.counts_per_rev
        self.pos = float(position)
        self.vel = 0.0
        self.acc = 0.0
        self.torque = 0.0  # per mille of rated torque
        self.vmax = params.max_speed_rpm / 60.0 * cpr
        self.a_rated = params.rated_accel_rps2 * cpr
        self.kp = params.kp
        self.kff = params.kff
        #: per mille of rated torque per count/s
        self.visc = params.viscous_permille / self.vmax if self.vmax else 0.0
        self.coast_decel = params.coast_decel_rps2 * cpr
        self.amax = 0.0
        self.set_max_torque(max_torque)
        self.limited = False  # a speed or torque limit acted in the last cycle
        self._dt = 0.0
        self._e = 0.0
        self._c = 0.0

    def set_max_torque(self, permille: float) -> None:
        """6072h changed: the acceleration the motor can reach."""
        self.amax = max(float(permille), 0.0) / 1000.0 * self.a_rated

    def _prepare(self, dt: float) -> None:
        self._dt = dt
        self._e = math.exp(-self.kp * dt)
        self._c = (1.0 - self.kff) * (1.0 - self._e) / self.kp

    # --- one cycle ---------------------------------------------------------------
    def track(self, demand: float, vff: float, dt: float) -> None:
        """Position control: ``demand`` is where the axis should be at the end of the cycle."""
        if dt != self._dt:
            self._prepare(dt)
        p = self.pos
        v0 = self.vel
        vmax = self.vmax
        if vff > vmax:
            vff = vmax
        elif vff < -vmax:
            vff = -vmax
        e1 = (demand - vff * dt - p) * self._e + self._c * vff
        v = (demand - e1 - p) / dt
        lim = self.amax * dt
        limited = False
        # closing speed on the (moving) demand that still lets the axis brake onto it
        # within the acceleration limit (exact for the discrete cycle, _closing_speed)
        dist = demand - p
        vstop = _closing_speed(abs(dist), lim, dt)
        if dist > 0.0 and v > vff + vstop:
            v, limited = vff + vstop, True
        elif dist < 0.0 and v < vff - vstop:
            v, limited = vff - vstop, True
        dv = v - v0
        if dv > lim:
            v, limited = v0 + lim, True
        elif dv < -lim:
            v, limited = v0 - lim, True
        if limited:
            # landing: never run past the demand (with the exact braking curve this only
            # bites when a cycle is longer than the one before it)
            if dist > 0.0 and v * dt > dist:
                v = dist / dt
            elif dist < 0.0 and v * dt < dist:
                v = dist / dt
        if v > vmax:
            v, limited = vmax, True
        elif v < -vmax:
            v, limited = -vmax, True
        self.limited = limited
        a = (v - v0) / dt
        self.acc = a
        self.vel = v
        self.pos = p + v * dt
        self.torque = a / self.a_rated * 1000.0 + v * self.visc

    def drive_torque(self, torque: float, dt: float) -> None:
        """Torque control: ``torque`` in per mille of rated torque (already within 6072h)."""
        v0 = self.vel
        a = (torque - v0 * self.visc) / 1000.0 * self.a_rated
        v = v0 + a * dt
        limited = False
        if v > self.vmax:
            v, limited = self.vmax, True
        elif v < -self.vmax:
            v, limited = -self.vmax, True
        self.limited = limited
        self.acc = (v - v0) / dt
        self.vel = v
        self.pos += v * dt
        self.torque = torque if not limited else self.acc / self.a_rated * 1000.0 + v * self.visc

    def coast(self, dt: float) -> None:
        """Power stage off: friction slows the motor down; no torque from the drive."""
        v0 = self.vel
        step = self.coast_decel * dt
        if v0 > step:
            v = v0 - step
        elif v0 < -step:
            v = v0 + step
        else:
            v = 0.0
        self.acc = (v - v0) / dt
        self.vel = v
        self.pos += v * dt
        self.torque = 0.0
        self.limited = False

    def stopped(self, threshold: float) -> bool:
        return -threshold < self.vel < threshold


def _closing_speed(dist: float, lim: float, dt: float) -> float:
    """The highest speed to step with now and still stop exactly ``dist`` ahead.

    Discrete braking: after stepping ``v`` for one cycle the speed can drop by at
    most ``lim`` per cycle, so the least distance left to cover is
    ``dt * sum(max(v - j*lim, 0) for j >= 1)``.  With ``m = floor(v / lim)`` that is
    ``dt * (m*v - lim*m*(m+1)/2)``; solving ``v*dt + that <= dist`` per segment ``m``
    gives the exact bound, so landing never needs more than 6083h allows.
    """
    if dist <= 0.0 or lim <= 0.0:
        return 0.0
    d = dist / dt
    half = 0.5 * lim
    m = int((math.sqrt(half * half + 2.0 * lim * d) - half) // lim)  # continuous estimate
    for _ in range(8):
        v = (d + lim * m * (m + 1) / 2.0) / (m + 1)
        if v < m * lim and m > 0:
            m -= 1
        elif v >= (m + 1) * lim:
            m += 1
        else:
            return v
    return min(v, d)
