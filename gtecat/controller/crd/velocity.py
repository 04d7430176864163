"""The vector speed profile of one segment: a trapezoid in path speed.

From the entry speed ``v0`` the path speed goes with ``acc`` to a peak
``vp <= vmax``, holds it, and goes to the exit speed ``ve`` with ``acc``
(synAcc of the segment: the same value accelerates and decelerates).  Cases:

* the segment is too short to reach ``ve`` from ``v0``: the speed ramps the
  whole length and exits at what it reached (``v_end`` says so; the next
  segment starts with it: speed continuity);
* too short to reach ``vmax``: a triangle, ``vp = sqrt(acc·L + (v0² + ve²)/2)``;
* ``even_time`` (TCrdPrm.evenTime, ms): a segment that cruises shorter than
  that gets a lower peak so it cruises ``even_time`` (``vp²/acc + vp·Te =
  L + (v0² + ve²)/(2·acc)``), never below ``max(v0, ve)``.

``s(t)`` and ``v(t)`` are closed forms; ``s(duration) == length``.
"""

from __future__ import annotations

import math

import numpy as np


class Trapezoid:
    __slots__ = ("acc", "d1", "dc", "duration", "length", "t1", "tc", "v0", "v_end", "vp")

    def __init__(
        self, length: float, v0: float, vmax: float, ve: float, acc: float, even_time: float = 0.0
    ) -> None:
        ln, a = length, acc
        ve = min(ve, vmax)
        self.length, self.acc, self.v0 = ln, a, v0
        if ln <= 0.0:
            vp, ve = v0, v0
        elif ve > v0 and (ve * ve - v0 * v0) / (2 * a) >= ln:
            ve = vp = math.sqrt(v0 * v0 + 2 * a * ln)
        elif v0 > ve and (v0 * v0 - ve * ve) / (2 * a) >= ln:
            vp, ve = v0, math.sqrt(max(v0 * v0 - 2 * a * ln, 0.0))
        else:
            vp = min(vmax, math.sqrt(a * ln + 0.5 * (v0 * v0 + ve * ve)))
            vp = max(vp, v0, ve)
            cruise = (ln - (2 * vp * vp - v0 * v0 - ve * ve) / (2 * a)) / vp
            if even_time > 0.0 and cruise < even_time:
                c = ln + (v0 * v0 + ve * ve) / (2 * a)
                te = even_time
                v = 0.5 * a * (-te + math.sqrt(te * te + 4.0 * c / a))
                vp = max(min(v, vp), v0, ve)
        self.vp, self.v_end = vp, ve
        self.t1 = abs(vp - v0) / a if ln > 0 else 0.0
        self.d1 = 0.5 * (v0 + vp) * self.t1
        t3 = abs(vp - ve) / a if ln > 0 else 0.0
        d3 = 0.5 * (vp + ve) * t3
        self.dc = max(ln - self.d1 - d3, 0.0)
        self.tc = self.dc / vp if vp > 0 else 0.0
        self.duration = self.t1 + self.tc + t3

    def s(self, t: float) -> float:
        """Path distance at ``t`` ms after the segment's start (``length`` from ``duration`` on)."""
        if t >= self.duration:
            return self.length
        if t <= 0.0:
            return 0.0
        a, v0, vp = self.acc, self.v0, self.vp
        if t < self.t1:
            a1 = a if vp >= v0 else -a
            return v0 * t + 0.5 * a1 * t * t
        t2 = t - self.t1
        if t2 < self.tc:
            return self.d1 + vp * t2
        t3 = t2 - self.tc
        a3 = -a if self.v_end <= vp else a
        return min(self.d1 + self.dc + vp * t3 + 0.5 * a3 * t3 * t3, self.length)

    def v(self, t: float) -> float:
        if t >= self.duration:
            return self.v_end
        if t <= 0.0:
            return self.v0
        a, v0, vp = self.acc, self.v0, self.vp
        if t < self.t1:
            return v0 + (a if vp >= v0 else -a) * t
        t2 = t - self.t1
        if t2 < self.tc:
            return vp
        return vp - a * (t2 - self.tc)

    def s_v(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`s` and :meth:`v` of each of the rising times ``t``, all before
        ``duration``: the same operations in the same order, so each value is bit for bit
        the scalar one.  Rising times meet the cases in their order (a rounded difference
        rises with its operand), so each case is one stretch of ``t``."""
        a, v0, vp, t1, tc = self.acc, self.v0, self.vp, self.t1, self.tc
        s = np.empty(len(t))
        v = np.empty(len(t))
        i0 = int(np.searchsorted(t, 0.0, "right"))  # t <= 0.0: the start
        s[:i0], v[:i0] = 0.0, v0
        i1 = max(int(np.searchsorted(t, t1)), i0)  # t < t1: the first ramp
        if i1 > i0:
            x = t[i0:i1]
            a1 = a if vp >= v0 else -a
            s[i0:i1] = v0 * x + 0.5 * a1 * x * x
            v[i0:i1] = v0 + a1 * x
        if i1 == len(t):
            return s, v
        t2 = t[i1:] - t1
        i2 = int(np.searchsorted(t2, tc))  # t2 < tc: the cruise
        s[i1 : i1 + i2] = self.d1 + vp * t2[:i2]
        v[i1 : i1 + i2] = vp
        if i1 + i2 < len(t):  # the last ramp
            t3 = t2[i2:] - tc
            a3 = -a if self.v_end <= vp else a
            s3 = self.d1 + self.dc + vp * t3 + 0.5 * a3 * t3 * t3
            s[i1 + i2 :] = np.where(self.length < s3, self.length, s3)  # min(s3, length)
            v[i1 + i2 :] = vp - a * t3
        return s, v
