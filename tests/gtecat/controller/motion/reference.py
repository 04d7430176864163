"""Independent closed-form references for the planner tests (textbook trapezoid, numpy).

Written from the formulas, not from the planner: a move of ``dist`` pulses
from standstill, speed ``vel``, ``acc``/``dec``, start/end speed ``vs``,
then (optionally) the moving average over ``ts`` ms computed numerically.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Trapezoid:
    dist: float  # signed
    vs: float
    vp: float  # peak speed reached
    acc: float
    dec: float
    t1: float  # acceleration time
    t2: float  # cruise time
    t3: float  # deceleration time

    @property
    def duration(self) -> float:
        return self.t1 + self.t2 + self.t3

    @classmethod
    def plan(cls, dist: float, vel: float, acc: float, dec: float, vs: float = 0.0) -> Trapezoid:
        vs = min(vs, vel)
        d = abs(dist)
        full = (vel**2 - vs**2) / (2 * acc) + (vel**2 - vs**2) / (2 * dec)
        if full <= d:
            vp = vel
        else:  # triangle: (vp² - vs²)(1/2acc + 1/2dec) = d
            vp = math.sqrt(vs**2 + 2 * d * acc * dec / (acc + dec))
        t1 = (vp - vs) / acc
        t3 = (vp - vs) / dec
        d1 = (vp + vs) / 2 * t1
        d3 = (vp + vs) / 2 * t3
        t2 = (d - d1 - d3) / vp if vp > 0 else 0.0
        return cls(dist, vs, vp, acc, dec, t1, max(t2, 0.0), t3)

    def at(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(pos, vel, acc) at times t (ms), for t < 0 at rest at 0, after the end at dist."""
        t = np.asarray(t, dtype=float)
        s = 1.0 if self.dist >= 0 else -1.0
        vs, vp, a, d = self.vs, self.vp, self.acc, self.dec
        ta, tb, tc = self.t1, self.t1 + self.t2, self.duration
        pa = (vs + vp) / 2 * self.t1
        pb = pa + vp * self.t2
        u = np.clip(t, 0, None)
        p = np.select(
            [t < 0, t < ta, t < tb, t < tc],
            [
                0.0,
                vs * u + a * u**2 / 2,
                pa + vp * (u - ta),
                pb + vp * (u - tb) - d * (u - tb) ** 2 / 2,
            ],
            abs(self.dist),
        )
        v = np.select(
            [t < 0, t < ta, t < tb, t < tc], [0.0, vs + a * u, vp, vp - d * (u - tb)], 0.0
        )
        acc = np.select([t < 0, t < ta, t < tb, t < tc], [0.0, a, 0.0, -d], 0.0)
        return s * p, s * v, s * acc

    def integral(self, t: np.ndarray) -> np.ndarray:
        """∫[0, t] p (exact, piecewise cubic); 0 for t < 0 (at rest at 0 before the start)."""
        t = np.asarray(t, dtype=float)
        s = 1.0 if self.dist >= 0 else -1.0
        vs, vp, a, d = self.vs, self.vp, self.acc, self.dec
        ta, tb, tc = self.t1, self.t1 + self.t2, self.duration
        pa = (vs + vp) / 2 * ta
        pb = pa + vp * self.t2
        ia = vs * ta**2 / 2 + a * ta**3 / 6
        ib = ia + pa * self.t2 + vp * self.t2**2 / 2
        t3 = self.t3
        ic = ib + pb * t3 + vp * t3**2 / 2 - d * t3**3 / 6
        u = np.clip(t, 0, None)
        i = np.select(
            [t < 0, t < ta, t < tb, t < tc],
            [
                0.0,
                vs * u**2 / 2 + a * u**3 / 6,
                ia + pa * (u - ta) + vp * (u - ta) ** 2 / 2,
                ib + pb * (u - tb) + vp * (u - tb) ** 2 / 2 - d * (u - tb) ** 3 / 6,
            ],
            ic + abs(self.dist) * (u - tc),
        )
        return s * i

    def smoothed_exact(self, t: np.ndarray, ts: float) -> np.ndarray:
        """Moving average over [t - ts, t] from the exact integral."""
        t = np.asarray(t, dtype=float)
        return (self.integral(t) - self.integral(t - ts)) / ts

    def smoothed(self, t: np.ndarray, ts: float, n: int = 4001) -> tuple[np.ndarray, np.ndarray]:
        """Moving average of position over [t - ts, t] by the trapezoid rule, and its slope."""
        t = np.asarray(t, dtype=float)
        grid = t[:, None] - ts + np.linspace(0.0, ts, n)[None, :]
        p, _, _ = self.at(grid)
        mean = np.trapezoid(p, dx=ts / (n - 1), axis=1) / ts
        p_now, _, _ = self.at(t)
        p_then, _, _ = self.at(t - ts)
        return mean, (p_now - p_then) / ts
