"""PVT motion: a table of (time, position, velocity) points followed by cubic segments.

A table is a list of segments; segment ``i`` runs from ``t0`` to ``t1`` (ms) and from
``p0`` to ``p1`` (pulse) with velocity ``v0`` at its start and ``v1`` at its end
(pulse/ms).  Within it the position is the cubic (Hermite) polynomial that meets all
four values, so a table of points with velocities is followed with continuous position
and, where the table says so, continuous velocity.  The GT layer
(:mod:`gtecat.gt.pvt_calls`) builds segments from the vendor's table forms.

The motion is relative: the table's first point is where the profile stands at
``start``; a table is run ``loop`` times (0: endlessly), each pass from where the last
ended.  A stop brakes with the stop deceleration from the current sample
(:class:`~gtecat.controller.motion.stop.StopRamp`).
"""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import CommandError
from . import checks
from .stop import StopKind, StopRamp

_IDLE, _MOVE, _STOP = 0, 1, 2


@dataclass(frozen=True, slots=True)
class PvtSegment:
    t0: float
    t1: float
    p0: float
    p1: float
    v0: float
    v1: float

    def at(self, t: float) -> tuple[float, float, float]:
        """Position, velocity and acceleration at table time ``t`` (t0 <= t <= t1)."""
        h = self.t1 - self.t0
        s = (t - self.t0) / h
        dp = self.p1 - self.p0
        # Hermite basis in s, velocities scaled by h
        m0, m1 = self.v0 * h, self.v1 * h
        c2 = 3 * dp - 2 * m0 - m1
        c3 = -2 * dp + m0 + m1
        pos = self.p0 + s * (m0 + s * (c2 + s * c3))
        vel = (m0 + s * (2 * c2 + 3 * s * c3)) / h
        acc = (2 * c2 + 6 * s * c3) / (h * h)
        return pos, vel, acc


def never_ends(segments: tuple[PvtSegment, ...], loop: int, cycle_ms: float) -> bool:
    """An endless loop (``loop`` 0) over a table lasting less than half a cycle: a cycle's
    passes would never end (the time a pass carries over rounds to a whole cycle past the
    table's end again), so such a start is refused."""
    return not loop and 2 * (segments[-1].t1 - segments[0].t0) < cycle_ms


class PvtPlanner:
    """One profile in PVT mode."""

    MODE = "PVT"

    def __init__(self, cycle_ms: float, pos: float = 0.0) -> None:
        self._T = checks.positive("cycle_ms", cycle_ms)
        self._stop = StopRamp(self._T)
        self.table_id = 0  #: the table selected (0: none)
        self.loop = 1
        self.loops_done = 0
        self._segs: tuple[PvtSegment, ...] = ()
        self._pos = float(pos)
        self._vel = self._acc = 0.0
        self._state = _IDLE
        self._k = 0
        self._i = 0
        self._origin = 0.0
        self.running_table = 0
        self.stopping = StopKind.NONE

    # --- planner protocol ----------------------------------------------------------------
    @property
    def done(self) -> bool:
        return self._state == _IDLE

    @property
    def pos(self) -> float:
        return self._pos

    @property
    def vel(self) -> float:
        return self._vel

    @property
    def acc(self) -> float:
        return self._acc

    @property
    def time(self) -> float:
        """Table time of the last sample (ms) in the current pass."""
        if self._state != _MOVE or not self._segs:
            return 0.0
        return self._segs[0].t0 + self._k * self._T

    def hold(self, pos: float) -> None:
        self._pos = checks.real("pos", pos)
        self._vel = self._acc = 0.0
        self._state = _IDLE
        self.stopping = StopKind.NONE

    def start(self, table_id: int, segments: tuple[PvtSegment, ...]) -> None:
        if self._state != _IDLE:
            raise CommandError("GT_PvtStart: the profile is moving; call GT_Stop first")
        if not segments:
            raise CommandError(f"GT_PvtStart: table {table_id} holds no data")
        self._segs = segments
        self.running_table = table_id
        self._origin = self._pos - segments[0].p0
        self._k = self._i = 0
        self.loops_done = 0
        self._vel = segments[0].v0
        self._acc = 0.0
        self._state = _MOVE
        self.stopping = StopKind.NONE

    def stop(
        self, dec: float, abrupt: bool = False, origin: tuple[float, float] | None = None
    ) -> None:
        if origin is None:
            if self._state == _IDLE:
                return
            origin = (self._pos, self._vel)
        self._stop.start(origin[0], origin[1], dec)
        self._pos, self._vel = origin
        self._state = _STOP
        self.stopping = StopKind.ABRUPT if abrupt else StopKind.SMOOTH
        if self._stop.done:
            self._finish(self._pos)

    def step(self) -> tuple[float, float, float]:
        if self._state == _MOVE:
            self._k += 1
            segs = self._segs
            t = segs[0].t0 + self._k * self._T
            end = segs[-1].t1
            while t > end + 1e-9:
                self.loops_done += 1
                if self.loop and self.loops_done >= self.loop:
                    self._vel = segs[-1].v1
                    self._finish(self._origin + segs[-1].p1)
                    return self._pos, self._vel, 0.0
                self._origin += segs[-1].p1 - segs[0].p0  # the next pass from here
                self._k = round((t - end) / self._T)
                self._i = 0
                t = segs[0].t0 + self._k * self._T
            # (a sample up to 1e-9 ms past the table's end is the last segment's: its end
            # rounded below the cycle's multiple, as 14.21 + 57 * 1.0 > 71.21)
            last = len(segs) - 1
            while self._i < last and segs[self._i].t1 < t:
                self._i += 1
            p, v, a = segs[self._i].at(t)
            self._pos, self._vel, self._acc = self._origin + p, v, a
        elif self._state == _STOP:
            self._pos, self._vel, self._acc = self._stop.step()
            if self._stop.done:
                self._finish(self._pos)
        return self._pos, self._vel, self._acc

    def run(self, n: int) -> tuple[list[float], list[float], list[float], int]:
        """``n`` calls of :meth:`step` at once (the axis bank's tables): the positions, speeds
        and accelerations up to the end sample, and its index (-1: the motion goes on)."""
        ps: list[float] = []
        vs: list[float] = []
        as_: list[float] = []
        step = self.step
        for j in range(n):
            p, v, a = step()
            ps.append(p)
            vs.append(v)
            as_.append(a)
            if self._state == _IDLE:
                return ps, vs, as_, j
        return ps, vs, as_, -1

    def _finish(self, pos: float) -> None:
        self._pos = pos
        self._vel = self._acc = 0.0
        self._state = _IDLE
        self.stopping = StopKind.NONE


__all__ = ["PvtPlanner", "PvtSegment", "never_ends"]
