"""Interpolation speed counted in base pulses, as the MCX314-family chips count it.

Sources: the MCX314 thesis and the ADT850 manual.

On those chips the set speed of an interpolation is the rate of *base pulses*, not the
vector speed (the ADT850 manual, 9.2.6 "插补速度": "并不是代表X轴是以这个速度运动,而是长轴的速度"):

* a **line**'s base pulses are the long axis's pulses, ``N = max|Δ_i|``; the path moves
  ``L/N`` per base pulse, so the vector speed is ``V·L/N`` (between ``V`` and ``V·√dim``);
* an **arc**'s base pulses are those of the axis that pulses on every base pulse in each
  octant (the ADT850 manual, 5.2: the axis with the smaller coordinate about the centre, i.e. the
  one moving faster), ``dn/dθ = r·max(|sin θ|, |cos θ|)``; over a full circle
  ``N = 8·r/√2`` - the figure the ADT850 manual's arc example computes for its manual
  deceleration point.  The vector speed varies between ``V`` and ``V·√2`` along the arc.

:class:`BaseSpeed` puts a :class:`~gtecat.controller.motion.scurve.DriveProfile` (planned in
base pulses: T or S ramps, manual deceleration points in base pulses as the seeds give
them) under a segment of a coordinate system: it answers ``duration``, ``s(t)`` and
``v(t)`` in path units like :class:`~.velocity.Trapezoid`, so
:class:`~.system.CoordSystem` samples it the same way.  ``base_v_end`` carries the base
rate into the next segment of a continuous interpolation.
"""

from __future__ import annotations

import math

from ..motion.scurve import DriveProfile
from .path import Arc, Line, Segment

_R2 = math.sqrt(2.0)
_Q = 0.5 * math.pi


def octant_integral(phi: float) -> float:
    """``∫_0^phi max(|sin|, |cos|)``: base pulses per unit radius from angle 0 to ``phi``."""
    k = math.floor(phi / _Q)
    rem = phi - k * _Q
    g = math.sin(rem) if rem <= 0.25 * math.pi else _R2 - math.cos(rem)
    return k * _R2 + g


def octant_inverse(x: float) -> float:
    """The angle ``phi`` with ``octant_integral(phi) == x``."""
    k = math.floor(x / _R2)
    rem = x - k * _R2
    h = 1.0 / _R2
    phi = math.asin(min(rem, h)) if rem <= h else math.acos(max(_R2 - rem, 0.0))
    return k * _Q + phi


def base_length(geom: Segment) -> float:
    """Base pulses of a segment (module docstring)."""
    if isinstance(geom, Line):
        return max((abs(b - a) for a, b in zip(geom.start, geom.end, strict=True)), default=0.0)
    if isinstance(geom, Arc):
        r = 0.5 * (geom.r0 + geom.r1)
        t0 = geom.theta0
        return r * abs(octant_integral(t0 + geom.sweep) - octant_integral(t0))
    raise TypeError(f"no base-pulse length for {type(geom).__name__}")


class BaseSpeed:
    """A segment's speed plan in base pulses, answered in path length (module docstring)."""

    __slots__ = ("_g0", "_sgn", "base", "base_v_end", "duration", "geom", "length", "profile")

    def __init__(self, geom: Segment, profile: DriveProfile) -> None:
        self.geom = geom
        self.profile = profile
        self.base = base_length(geom)
        self.length = geom.length
        self.duration = profile.duration
        self.base_v_end = profile.v_end
        if isinstance(geom, Arc):
            self._g0 = octant_integral(geom.theta0)
            self._sgn = 1.0 if geom.sweep > 0 else -1.0

    @property
    def v_end(self) -> float:
        return self.base_v_end * self._dsdn(self.base)

    def _path(self, n: float) -> float:
        if self.base <= 0.0:
            return self.length
        n = min(max(n, 0.0), self.base)
        g = self.geom
        if isinstance(g, Line):
            return self.length * n / self.base
        assert isinstance(g, Arc)
        r = 0.5 * (g.r0 + g.r1)
        theta = octant_inverse(self._g0 + self._sgn * n / r)
        frac = (theta - g.theta0) / g.sweep
        return min(max(frac, 0.0), 1.0) * self.length

    def _dsdn(self, n: float) -> float:
        g = self.geom
        if self.base <= 0.0:
            return 0.0
        if isinstance(g, Line):
            return self.length / self.base
        assert isinstance(g, Arc)
        s = self._path(n)
        theta = g.theta0 + g.sweep * (s / self.length if self.length else 0.0)
        r = 0.5 * (g.r0 + g.r1)
        return self.length / (abs(g.sweep) * r * max(abs(math.sin(theta)), abs(math.cos(theta))))

    def state(self, t: float) -> tuple[float, float, float, float]:
        """``(n, v_base, a_base, j_base)``: base pulses out, their rate and its derivatives."""
        n, v, a, j, _ = self.profile.state(t)
        return n, v, a, j

    def s(self, t: float) -> float:
        if t >= self.duration:
            return self.length
        return self._path(self.profile.s(t))

    def v(self, t: float) -> float:
        n, v, _, _, _ = self.profile.state(t)
        return v * self._dsdn(n)


__all__ = ["BaseSpeed", "base_length", "octant_integral", "octant_inverse"]
