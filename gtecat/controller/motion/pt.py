"""PT (position-time) planner: manual 7.4, GT_PrfPt, GT_PtData, GT_PtSpace, GT_PtClear, GT_PtStart,
GT_SetPtLoop / GT_GetPtLoop, GT_SetPtMemory / GT_GetPtMemory, GT_GetPtRemainder.

Model (what an independent computation must reproduce)
------------------------------------------------------
1. **Data.** ``GT_PtData(pos, time, type)`` pushes a segment *end point*: the
   position (pulse) and time (ms) relative to the start of the PT motion,
   whose first segment starts at position 0, time 0 ("压入控制器的数据为位置点,
   即相对于第 1 段的起点的绝对值", 7.4.2).  Times must increase strictly.

2. **Segment velocities** (7.4.2, figure 7-5..7-7).  A segment from
   ``(T0, P0)`` to ``(T1, P1)`` has ``ΔT = T1 - T0``, ``ΔP = P1 - P0`` and a
   velocity linear in time (constant acceleration) from ``vs`` to ``ve``:

   * ``PT_SEGMENT_NORMAL``: ``vs`` = end velocity of the previous segment (0 for
     the first segment), ``ve = 2·ΔP/ΔT - vs``;
   * ``PT_SEGMENT_EVEN``: ``vs = ve = ΔP/ΔT``;
   * ``PT_SEGMENT_STOP``: ``vs = 2·ΔP/ΔT`` (whatever the previous segment ended
     with), ``ve = 0``.

   So ``p(t) = P0 + vs·τ + (ve - vs)·τ²/(2·ΔT)`` with ``τ = t - T0``, and
   every segment ends exactly on its point.  "First segment" is the first of
   the FIFO in static mode (also on each loop pass), the first of the motion
   in dynamic mode (the data stream runs on across the two FIFOs, example 7-4).

3. **Static FIFO mode** (``PT_MODE_STATIC``): ``GT_PtStart`` runs the FIFO
   its ``option`` bit selects, ``loop`` times (GT_SetPtLoop, 0 = endless,
   default 1); every pass starts where the previous one ended (positions and
   times of a pass are offset by the end point of the previous pass) and its
   first segment starts from velocity 0.  The data stays in the FIFO.
   ``GT_GetPtLoop`` reads the passes completed.

4. **Dynamic FIFO mode** (``PT_MODE_DYNAMIC``): the FIFO arguments are ignored.
   Data fills one FIFO, then the other once the first is full (a FIFO is
   written again only after it was emptied); ``GT_PtSpace`` is the free space
   of the FIFO the next segment goes into (0 when both are full).  The motion runs FIFO1, and when a
   FIFO is used up the controller clears it and runs on in the other one;
   when both are used up the motion ends (the position stays at the last
   point, the velocity drops to 0) and the stream starts afresh.

5. **Sampling** (as the Trap planner): ``start`` is t = 0 at the current
   cycle; the k-th ``step()`` returns the closed form at ``t = k·cycle_ms``.
   The first sample at or after the end of the last segment is exactly the
   last point with zero velocity and sets ``done``.

``GT_GetPtRemainder`` counts the segments not finished yet in the current
pass (the executing one included; dynamic mode: in both FIFOs), so a dynamic
stream that ran dry reads 0; at rest a static profile reports the segments
of the FIFO it last started (FIFO1 before any start).  GT_Stop hands
over to :class:`~gtecat.controller.motion.stop.StopRamp`; a stopped dynamic stream is
cleared (its time base is gone), static data is kept.
"""

from __future__ import annotations

from enum import IntEnum
from typing import NamedTuple

from ...errors import CommandError, ParameterError
from . import checks
from .fifo import PT_MEMORY_SIZES, FifoPair, fifo_index
from .stop import StopKind, StopRamp

_IDLE, _MOVE, _STOP = 0, 1, 2
_EPS_T = 1e-9  # ms: a sample this close to a segment end is on it


class PtMode(IntEnum):
    """FIFO use of GT_PrfPt (chapter 13 entry 89)."""

    STATIC = 0
    DYNAMIC = 1


class PtSegmentType(IntEnum):
    """Segment types of GT_PtData (chapter 13 entry 93)."""

    NORMAL = 0
    EVEN = 1
    STOP = 2


#: a GT_PtData type -> its segment type (a look-up: GT_PtData is called per streamed point)
_SEGMENT_TYPES = {int(k): k for k in PtSegmentType}


class PtPoint(NamedTuple):
    """One GT_PtData segment: end position (pulse) and end time (ms) from the PT start
    (a named tuple: made per streamed point, several times cheaper than a frozen class)."""

    pos: float
    time: float
    type: PtSegmentType = PtSegmentType.NORMAL


class PtPlanner:
    """One profile in PT mode: two FIFOs, static or dynamic use, one sample per cycle."""

    __slots__ = (
        "_T",
        "_a",
        "_acc",
        "_fifos",
        "_i",
        "_k",
        "_loop",
        "_loops_done",
        "_mode",
        "_origin",
        "_p0",
        "_p1",
        "_poff",
        "_pos",
        "_r",
        "_sel",
        "_state",
        "_stop",
        "_stream_t",
        "_t0",
        "_t1",
        "_toff",
        "_ve",
        "_vel",
        "_vs",
        "_w",
        "stopping",
    )

    def __init__(
        self, mode: PtMode | int = PtMode.STATIC, cycle_ms: float = 1.0, pos: float = 0.0
    ) -> None:
        self._T = checks.positive("cycle_ms", cycle_ms)
        self._stop = StopRamp(self._T)
        self._fifos: FifoPair[PtPoint] = FifoPair(PT_MEMORY_SIZES, "PT")
        self._mode = _pt_mode(mode)
        self._loop = 1
        self._loops_done = 0
        self._sel = 0
        self._state = _IDLE
        self._reset_stream()
        self.hold(pos)

    # ------------------------------------------------------------ settings
    @property
    def mode(self) -> PtMode:
        return self._mode

    def set_mode(self, mode: PtMode | int) -> None:
        """GT_PrfPt on a profile already in PT mode: a new FIFO mode empties both FIFOs."""
        m = _pt_mode(mode)
        self._require_idle("GT_PrfPt")
        if m != self._mode:
            self._fifos[0].clear()
            self._fifos[1].clear()
            self._reset_stream()
            self._mode = m

    @property
    def loop(self) -> int:
        """Passes GT_SetPtLoop asked for (0 = endless)."""
        return self._loop

    @property
    def loops_done(self) -> int:
        """Passes completed (GT_GetPtLoop)."""
        return self._loops_done

    def set_loop(self, loop: object) -> None:
        """GT_SetPtLoop: a non-negative count, 0 = endless; refused in dynamic mode."""
        n = checks.integer("loop", loop)
        if self._mode == PtMode.DYNAMIC:
            raise CommandError("GT_SetPtLoop does not apply in dynamic FIFO mode (7.4.1)")
        if n < 0:
            raise ParameterError(f"loop must be >= 0 (0 = endless), got {loop!r}")
        self._loop = n

    @property
    def memory(self) -> int:
        """GT_GetPtMemory flag: 0 = 32, 1 = 1024 segments per FIFO."""
        return self._fifos.memory

    @property
    def capacity(self) -> int:
        """Segments per FIFO."""
        return self._fifos.capacity

    def set_memory(self, flag: object) -> None:
        """GT_SetPtMemory: refused while moving (return 1)."""
        self._require_idle("GT_SetPtMemory")
        self._fifos.set_memory(flag)

    # ---------------------------------------------------------------- data
    def data(
        self,
        pos: float,
        time: float,
        type: PtSegmentType | int = PtSegmentType.NORMAL,
        fifo: object = 0,
    ) -> None:
        """GT_PtData: push one segment end point (``fifo`` is ignored in dynamic mode)."""
        p = checks.real("pos", pos)
        t = checks.real("time", time)
        kind = _SEGMENT_TYPES.get(checks.integer("type", type))
        if kind is None:
            raise ParameterError(f"type must be 0 (normal), 1 (even) or 2 (stop), got {type!r}")
        point = PtPoint(p, t, kind)
        if self._mode == PtMode.STATIC:
            q = self._fifos[fifo_index(fifo)]
            last = q.last
            prev = 0.0 if last is None else last.time
            if t <= prev:
                raise ParameterError(
                    f"time must be > {prev:g} ms (the previous point), got {time!r}"
                )
            q.push(point)
            return
        if t <= self._stream_t:
            raise ParameterError(
                f"time must be > {self._stream_t:g} ms (the previous point), got {time!r}"
            )
        q = self._fifos[self._w]
        if q.space == 0:  # full: the other one next, once it was emptied
            other = self._fifos[1 - self._w]
            if len(other) != 0 or other.space == 0:
                raise CommandError("both PT FIFOs are full (dynamic mode): wait until space > 0")
            self._w = 1 - self._w
            q = other
        q.push(point)
        self._stream_t = t

    def space(self, fifo: object = 0) -> int:
        """GT_PtSpace: free segments of ``fifo`` (dynamic: of the FIFO the next segment goes to)."""
        if self._mode == PtMode.STATIC:
            return self._fifos[fifo_index(fifo)].space
        q, other = self._fifos[self._w], self._fifos[1 - self._w]
        if q.space == 0 and len(other) == 0:
            return other.capacity
        return q.space

    def clear(self, fifo: object = 0) -> None:
        """GT_PtClear: static - not the FIFO in use while moving; dynamic - both, only at rest."""
        if self._mode == PtMode.DYNAMIC:
            if self._state != _IDLE:
                raise CommandError("GT_PtClear: dynamic-mode FIFOs cannot be cleared while moving")
            self._fifos[0].clear()
            self._fifos[1].clear()
            self._reset_stream()
            return
        i = fifo_index(fifo)
        if self._state == _MOVE and i == self._r:
            raise CommandError(f"GT_PtClear: FIFO {i} is in use by the running PT motion")
        self._fifos[i].clear()

    def points(self, fifo: int) -> tuple[PtPoint, ...]:
        """The segments held in one FIFO (for inspection)."""
        return tuple(self._fifos[fifo_index(fifo)])

    @property
    def remainder(self) -> int:
        """GT_GetPtRemainder: segments not finished yet (the executing one included)."""
        f = self._fifos
        if self._state == _MOVE:
            n = len(f[self._r]) - self._i
            return n + (len(f[1 - self._r]) if self._mode == PtMode.DYNAMIC else 0)
        if self._mode == PtMode.DYNAMIC:
            return len(f[0]) + len(f[1])
        return len(f[self._sel])

    # ------------------------------------------------------------- motion
    @property
    def done(self) -> bool:
        return self._state == _IDLE

    @property
    def moving(self) -> bool:
        return self._state != _IDLE

    @property
    def running_fifo(self) -> int | None:
        """The FIFO the motion reads, None at rest."""
        return self._r if self._state == _MOVE else None

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
        """ms since GT_PtStart (time of the last sample)."""
        return self._k * self._T

    def hold(self, pos: float) -> None:
        """Stand still at ``pos`` (GT_SetPrfPos, GT_ZeroPos, mode change); forgets any motion."""
        self._pos = checks.real("pos", pos)
        self._abandon()
        self._vel = self._acc = 0.0
        self._state = _IDLE
        self._k = 0
        self.stopping = StopKind.NONE

    def start(self, fifo: object = 0, pos: float | None = None) -> None:
        """GT_PtStart for this profile; ``fifo`` is its ``option`` bit (ignored in dynamic mode).

        ``pos`` is where the motion starts (the profile's planned position;
        default: where the planner stands).
        """
        if self._state != _IDLE:
            raise CommandError("GT_PtStart: the profile is moving; call GT_Stop first")
        f = self._fifos
        if self._mode == PtMode.STATIC:
            i = fifo_index(fifo)
            self._sel = i
            if len(f[i]) == 0:
                raise CommandError(f"GT_PtStart: PT FIFO {i} holds no data; push segments first")
        else:
            i = 0
            if len(f[0]) == 0:
                raise CommandError("GT_PtStart: the PT FIFOs hold no data; push segments first")
        if pos is not None:
            self._pos = checks.real("pos", pos)
        self._origin = self._pos
        self._vel = self._acc = 0.0
        self._r = i
        self._i = 0
        self._k = 0
        self._toff = self._poff = 0.0
        self._t1 = self._p1 = self._ve = 0.0
        self._loops_done = 0
        self._enter(f[i][0], first=True)
        self._state = _MOVE
        self.stopping = StopKind.NONE

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
            if self._state == _IDLE:
                return
            origin = (self._pos, self._vel)
        self._stop.start(origin[0], origin[1], dec)
        self._pos, self._vel = origin
        self._abandon()
        self._state = _STOP
        self.stopping = StopKind.ABRUPT if abrupt else StopKind.SMOOTH
        if self._stop.done:
            self._finish(self._pos)

    def step(self) -> tuple[float, float, float]:
        """One controller cycle: ``(pos, vel, acc)`` in pulse, pulse/ms, pulse/ms²."""
        state = self._state
        if state == _MOVE:
            self._k += 1
            t = self._k * self._T
            while t >= self._t1 - _EPS_T * (1.0 + abs(self._t1) * 1e-3):
                if not self._next():
                    self._finish(self._origin + self._p1)
                    return self._pos, 0.0, 0.0
            tau = t - self._t0
            a = self._a
            self._pos = self._origin + self._p0 + tau * (self._vs + 0.5 * a * tau)
            self._vel = self._vs + a * tau
            self._acc = a
        elif state == _STOP:
            self._pos, self._vel, self._acc = self._stop.step()
            if self._stop.done:
                self._finish(self._pos)
        return self._pos, self._vel, self._acc

    def run(self, n: int) -> tuple[list[float], list[float], list[float], int]:
        """``n`` calls of :meth:`step` at once (the axis bank's tables): the positions, speeds
        and accelerations up to the end sample, and its index (-1: the motion goes on).
        Inside a segment the samples are the closed form of :meth:`step`, the same
        operations in the same order; a segment boundary is :meth:`step` itself."""
        ps: list[float] = []
        vs_: list[float] = []
        as_: list[float] = []
        if self._state != _MOVE:
            for j in range(n):
                p, v, a = self.step()
                ps.append(p)
                vs_.append(v)
                as_.append(a)
                if self._state == _IDLE:
                    return ps, vs_, as_, j
            return ps, vs_, as_, -1
        cyc = self._T
        k = self._k
        j = 0
        while j < n:
            t1 = self._t1
            lim = t1 - _EPS_T * (1.0 + abs(t1) * 1e-3)
            t0, a, vs = self._t0, self._a, self._vs
            base = self._origin + self._p0
            half = 0.5 * a
            while j < n:
                t = (k + 1) * cyc
                if t >= lim:
                    break
                k += 1
                tau = t - t0
                ps.append(base + tau * (vs + half * tau))
                vs_.append(vs + a * tau)
                as_.append(a)
                j += 1
            else:
                break
            self._k = k  # a segment boundary: step() itself
            p, v, acc = self.step()
            k = self._k
            ps.append(p)
            vs_.append(v)
            as_.append(acc)
            j += 1
            if self._state != _MOVE:
                return ps, vs_, as_, j - 1
        self._k = k
        if ps:
            self._pos, self._vel, self._acc = ps[-1], vs_[-1], as_[-1]
        return ps, vs_, as_, -1

    # ------------------------------------------------------------ internals
    def _require_idle(self, what: str) -> None:
        if self._state != _IDLE:
            raise CommandError(f"{what}: the profile is moving; call GT_Stop first")

    def _reset_stream(self) -> None:
        self._w = 0
        self._r = 0
        self._stream_t = 0.0

    def _abandon(self) -> None:
        """A dynamic stream that stops before its end cannot resume: drop its data."""
        if self._mode == PtMode.DYNAMIC and self._state == _MOVE:
            self._fifos[0].clear()
            self._fifos[1].clear()
            self._reset_stream()

    def _enter(self, point: PtPoint, first: bool) -> None:
        """Make ``point`` the executing segment, starting where the previous one ended."""
        t0, p0, v_prev = self._t1, self._p1, self._ve
        t1 = point.time + self._toff
        p1 = point.pos + self._poff
        dt = t1 - t0
        dp = p1 - p0
        kind = point.type
        if kind == PtSegmentType.EVEN:
            vs = ve = dp / dt
        elif kind == PtSegmentType.STOP:
            vs, ve = 2.0 * dp / dt, 0.0
        else:
            vs = 0.0 if first else v_prev
            ve = 2.0 * dp / dt - vs
        self._t0, self._p0, self._t1, self._p1 = t0, p0, t1, p1
        self._vs, self._ve = vs, ve
        self._a = (ve - vs) / dt

    def _next(self) -> bool:
        """Move on to the next segment; False when the motion has run out of data/passes."""
        f = self._fifos
        q = f[self._r]
        if self._i + 1 < len(q):
            self._i += 1
            self._enter(q[self._i], first=False)
            return True
        if self._mode == PtMode.STATIC:
            self._loops_done += 1
            if self._loop != 0 and self._loops_done >= self._loop:
                return False
            self._toff, self._poff = self._t1, self._p1
            self._i = 0
            self._enter(q[0], first=True)
            return True
        other = 1 - self._r
        if len(f[other]) == 0:
            return False
        q.clear()  # a used-up FIFO is emptied and refilled by the host (7.4.2 (4))
        self._r = other
        self._i = 0
        self._enter(f[other][0], first=False)
        return True

    def _finish(self, pos: float) -> None:
        if self._state == _MOVE and self._mode == PtMode.DYNAMIC:
            self._fifos[0].clear()
            self._fifos[1].clear()
            self._reset_stream()
        self._pos = pos
        self._vel = self._acc = 0.0
        self._state = _IDLE


def _pt_mode(mode: object) -> PtMode:
    m = checks.integer("mode", mode)
    if m not in (0, 1):
        raise ParameterError(
            f"mode must be 0 (PT_MODE_STATIC) or 1 (PT_MODE_DYNAMIC), got {mode!r}"
        )
    return PtMode(m)
