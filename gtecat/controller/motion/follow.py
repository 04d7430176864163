"""Follow (electronic cam) planner: manual 7.6, GT_PrfFollow, GT_SetFollowMaster, GT_SetFollowLoop,
GT_SetFollowEvent, GT_FollowData, GT_FollowSpace, GT_FollowClear, GT_FollowStart, GT_FollowSwitch,
GT_SetFollowMemory (and their GT_Get* twins).

Model (what an independent computation must reproduce)
------------------------------------------------------
1. **Data.** ``GT_FollowData(masterSegment, slaveSegment, type, fifo)`` pushes a
   *position point*: master and slave positions relative to the zero point of
   the pass (7.6.3 note 1-3: the start point, or the pass point of a
   ``FOLLOW_EVENT_PASS`` start; after a FIFO switch or at each loop pass, where
   the previous pass ended).  Example 7-7 pushes 20000/10000, 40000/30000,
   60000/40000.  Master points must move strictly one way (the sign of the
   first point sets it; a negative FIFO describes a master moving negative).

2. **Velocity ratio** ``r = ds/dx`` of the slave over master travel ``x`` is
   linear in ``x`` inside a segment (figure 7-13: the slave displacement is the
   area under ``r(x)``).  For a segment with master length ``ΔM`` and slave
   length ``ΔS`` (7.6.2 (5)):

   * ``FOLLOW_SEGMENT_NORMAL``: ``rs`` = end ratio of the previous segment of the
     pass, 0 for the first segment of a FIFO; ``re = 2·ΔS/ΔM - rs``;
   * ``FOLLOW_SEGMENT_EVEN``: ``rs = re = ΔS/ΔM``;
   * ``FOLLOW_SEGMENT_STOP``: ``rs = 2·ΔS/ΔM``, ``re = 0``;
   * ``FOLLOW_SEGMENT_CONTINUE``: as NORMAL, but the first segment of a FIFO
     starts from the end ratio of the pass that ran before it (the previous
     FIFO after a switch, the previous pass of the same FIFO in a loop; 0 at
     the start).

   ``s(x) = S0 + rs·u + (re - rs)·u²/(2·ΔM)``, ``u = x - M0``: each segment ends
   exactly on its point, whatever the sampling.

3. **Start** (GT_FollowStart, GT_SetFollowEvent).  ``FOLLOW_EVENT_START``: the
   zero point is the master position at GT_FollowStart.  ``FOLLOW_EVENT_PASS``:
   the slave waits (the profile counts as moving) until a cycle in which the
   master crosses ``pos`` in ``masterDir`` (``m_prev < pos <= m`` for 1,
   ``m_prev > pos >= m`` for -1); the zero point is ``pos`` itself, so the
   slave already follows the part of that cycle's master motion beyond it.

4. **Loops and switches.**  A FIFO is run ``loop`` times (GT_SetFollowLoop,
   < 1 = endless; GT_GetFollowLoop reads the passes completed of the running
   FIFO).  GT_FollowSwitch (only while moving, the other FIFO must hold data)
   takes effect at the end of the current pass: the used FIFO is cleared and
   the other one runs, ``loop`` times again.  Without a switch the data stays.

5. **Master travel.**  ``x`` accumulates the master increments that pass the
   follow direction (GT_PrfFollow ``dir``, :mod:`gtecat.controller.motion.master`); with
   ``dir`` 0 a master moving back takes the slave back along the curve, down
   to the start of the current pass (the slave waits there for it).

6. **Sampling.**  Each ``step()`` reads the master, evaluates ``s(x)`` and
   returns the slave position; velocity = increment / ``cycle_ms``.  The first
   sample at or past the end of the last pass is exactly its end point with
   zero velocity and sets ``done``.  GT_Stop hands over to
   :class:`~gtecat.controller.motion.stop.StopRamp`; the FIFOs keep their data.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

from ...errors import CommandError, ParameterError
from . import checks
from .fifo import FOLLOW_MEMORY_SIZES, FifoPair, fifo_index
from .master import MasterSource, SlavePlanner, passed
from .stop import StopKind, StopRamp

_IDLE, _WAIT, _MOVE, _STOP = 0, 1, 2, 3


class FollowSegmentType(IntEnum):
    """Segment types of GT_FollowData (chapter 13 entry 20)."""

    NORMAL = 0
    EVEN = 1
    STOP = 2
    CONTINUE = 3


class FollowEvent(IntEnum):
    """Start conditions of GT_SetFollowEvent (chapter 13 entry 106)."""

    START = 1
    PASS = 2


@dataclass(frozen=True, slots=True)
class FollowPoint:
    """One GT_FollowData point: master and slave positions from the zero point of the pass."""

    master: int
    slave: float
    type: FollowSegmentType = FollowSegmentType.NORMAL


@dataclass(frozen=True, slots=True)
class FollowTrigger:
    """GT_GetFollowEvent: start condition, master direction, pass position."""

    event: FollowEvent = FollowEvent.START
    master_dir: int = 1
    pos: int = 0


@dataclass(frozen=True, slots=True)
class _Seg:
    """An executing segment in cam coordinates: ``s = s0 + u·(rs + k·u)``, ``u = x - x0``."""

    x0: float
    x1: float
    s0: float
    s1: float
    rs: float
    re: float
    k: float


class FollowPlanner(SlavePlanner):
    """One slave profile in Follow mode."""

    MODE = "Follow"

    __slots__ = (
        "_T",
        "_acc",
        "_carry",
        "_fifos",
        "_i",
        "_loop",
        "_loops_done",
        "_m_prev",
        "_origin",
        "_pos",
        "_r",
        "_s0",
        "_sd",
        "_segs",
        "_stop",
        "_switch",
        "_trigger",
        "_vel",
        "_x",
        "_x0",
        "stopping",
    )

    def __init__(
        self,
        profile: int | None = None,
        dir: int = 0,
        cycle_ms: float = 1.0,
        pos: float = 0.0,
        source: MasterSource | None = None,
    ) -> None:
        self._init_master(profile, dir, source)
        self._T = checks.positive("cycle_ms", cycle_ms)
        self._stop = StopRamp(self._T)
        self._fifos: FifoPair[FollowPoint] = FifoPair(FOLLOW_MEMORY_SIZES, "Follow")
        self._loop = 1
        self._loops_done = 0
        self._trigger = FollowTrigger()
        self._r = 0
        self._switch = False
        self._segs: list[_Seg] = []
        self._i = 0
        self._x = self._x0 = self._s0 = self._carry = self._m_prev = self._origin = 0.0
        self._sd = 1.0
        self.hold(pos)

    # ------------------------------------------------------------ settings
    @property
    def loop(self) -> int:
        """Passes GT_SetFollowLoop asked for (< 1 = endless)."""
        return self._loop

    @property
    def loops_done(self) -> int:
        """GT_GetFollowLoop: passes completed of the running (or last run) FIFO."""
        return self._loops_done

    def set_loop(self, loop: object) -> None:
        """GT_SetFollowLoop: a short, < 1 = endless."""
        n = checks.integer("loop", loop)
        if not -32768 <= n <= 32767:
            raise ParameterError(f"loop must be in [-32768, 32767], got {loop!r}")
        self._loop = n

    @property
    def trigger(self) -> FollowTrigger:
        """GT_GetFollowEvent."""
        return self._trigger

    def set_event(self, event: object, master_dir: object = 1, pos: object = 0) -> None:
        """GT_SetFollowEvent; applies to the next GT_FollowStart."""
        e = checks.integer("event", event)
        if e not in tuple(FollowEvent):
            raise ParameterError(
                f"event must be 1 (FOLLOW_EVENT_START) or 2 (FOLLOW_EVENT_PASS), got {event!r}"
            )
        d = checks.integer("masterDir", master_dir)
        p = checks.integer("pos", pos)
        if e == FollowEvent.PASS and d not in (1, -1):
            raise ParameterError(f"masterDir must be 1 or -1 for a pass event, got {master_dir!r}")
        self._trigger = FollowTrigger(FollowEvent(e), d, p)

    @property
    def memory(self) -> int:
        """GT_GetFollowMemory flag: 0 = 16, 1 = 512 segments per FIFO."""
        return self._fifos.memory

    @property
    def capacity(self) -> int:
        return self._fifos.capacity

    def set_memory(self, flag: object) -> None:
        """GT_SetFollowMemory: refused while moving (return 1)."""
        self._require_idle("GT_SetFollowMemory")
        self._fifos.set_memory(flag)

    # ---------------------------------------------------------------- data
    def data(
        self,
        master: object,
        slave: float,
        type: FollowSegmentType | int = FollowSegmentType.NORMAL,
        fifo: object = 0,
    ) -> None:
        """GT_FollowData: push one point (positions from the zero point of the pass)."""
        m = checks.integer("masterSegment", master)
        s = checks.real("slaveSegment", slave)
        kind = checks.integer("type", type)
        if kind not in tuple(FollowSegmentType):
            raise ParameterError(
                f"type must be 0 (normal), 1 (even), 2 (stop) or 3 (continue), got {type!r}"
            )
        q = self._fifos[fifo_index(fifo)]
        first = q[0] if len(q) else None
        last = q.last
        if first is None or last is None:
            if m == 0:
                raise ParameterError("masterSegment of the first point must not be 0")
        elif (m - last.master) * (1 if first.master > 0 else -1) <= 0:
            raise ParameterError(
                f"masterSegment must move on from {last.master} in the direction of the "
                f"first point ({first.master}), got {m}"
            )
        q.push(FollowPoint(m, s, FollowSegmentType(kind)))

    def space(self, fifo: object = 0) -> int:
        """GT_FollowSpace: free segments of ``fifo``."""
        return self._fifos[fifo_index(fifo)].space

    def clear(self, fifo: object = 0) -> None:
        """GT_FollowClear: not the FIFO in use (or the pending switch target) while moving."""
        i = fifo_index(fifo)
        if self._state in (_WAIT, _MOVE):
            if i == self._r:
                raise CommandError(
                    f"GT_FollowClear: FIFO {i} is in use by the running Follow motion"
                )
            if self._switch:
                raise CommandError(
                    f"GT_FollowClear: FIFO {i} is the target of a pending GT_FollowSwitch"
                )
        self._fifos[i].clear()

    def points(self, fifo: int) -> tuple[FollowPoint, ...]:
        """The points held in one FIFO (for inspection)."""
        return tuple(self._fifos[fifo_index(fifo)])

    # ------------------------------------------------------------- motion
    @property
    def done(self) -> bool:
        return self._state == _IDLE

    @property
    def moving(self) -> bool:
        return self._state != _IDLE

    @property
    def waiting(self) -> bool:
        """Started with a pass event, the master has not crossed yet."""
        return self._state == _WAIT

    @property
    def running_fifo(self) -> int | None:
        return self._r if self._state in (_WAIT, _MOVE) else None

    @property
    def switch_pending(self) -> bool:
        return self._switch

    @property
    def master_travel(self) -> float:
        """Master travel since the zero point of the current pass (cam coordinate)."""
        return self._x - self._x0

    @property
    def pos(self) -> float:
        return self._pos

    @property
    def vel(self) -> float:
        return self._vel

    @property
    def acc(self) -> float:
        return self._acc

    def hold(self, pos: float) -> None:
        """Stand still at ``pos``; forgets any motion."""
        self._pos = checks.real("pos", pos)
        self._vel = self._acc = 0.0
        self._state = _IDLE
        self._switch = False
        self.stopping = StopKind.NONE

    def start(self, fifo: object = 0, pos: float | None = None) -> None:
        """GT_FollowStart for this profile; ``fifo`` is its ``option`` bit (0 FIFO1, 1 FIFO2)."""
        i = fifo_index(fifo)
        if self._state != _IDLE:
            raise CommandError("GT_FollowStart: the profile is moving; call GT_Stop first")
        if self._master is None:
            raise CommandError("GT_FollowStart: no master set; call GT_SetFollowMaster first")
        if len(self._fifos[i]) == 0:
            raise CommandError(f"GT_FollowStart: Follow FIFO {i} holds no data; push points first")
        if self._source is None:
            raise CommandError("GT_FollowStart: the master has no position source bound")
        if pos is not None:
            self._pos = checks.real("pos", pos)
        self._origin = self._pos
        self._vel = self._acc = 0.0
        self._r = i
        self._switch = False
        self._loops_done = 0
        self._m_prev = float(self._source())
        self._x = 0.0
        self._begin_pass(0.0, 0.0, 0.0)
        self._state = _WAIT if self._trigger.event == FollowEvent.PASS else _MOVE
        self.stopping = StopKind.NONE

    def switch(self) -> None:
        """GT_FollowSwitch: run the other FIFO once the current pass ends (then clear this one)."""
        if self._state not in (_WAIT, _MOVE):
            raise CommandError("GT_FollowSwitch: only a moving Follow profile can switch FIFO")
        target = 1 - self._r
        if len(self._fifos[target]) == 0:
            raise CommandError(f"GT_FollowSwitch: the target FIFO {target} holds no data")
        self._switch = True

    def stop(
        self, dec: float, abrupt: bool = False, origin: tuple[float, float] | None = None
    ) -> None:
        """GT_Stop: the slave brakes with ``dec`` and no longer follows the master.

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
        self._switch = False
        self._stop.start(origin[0], origin[1], dec)
        self._pos, self._vel = origin
        self._state = _STOP
        self.stopping = StopKind.ABRUPT if abrupt else StopKind.SMOOTH
        if self._stop.done:
            self._state = _IDLE
            self._vel = self._acc = 0.0

    def step(self) -> tuple[float, float, float]:
        """One controller cycle: ``(pos, vel, acc)`` in pulse, pulse/ms, pulse/ms²."""
        state = self._state
        if state == _MOVE:
            m = float(self._source())  # type: ignore[misc]
            self._x += passed(m - self._m_prev, self._dir)
            self._m_prev = m
            self._follow()
        elif state == _WAIT:
            m = float(self._source())  # type: ignore[misc]
            m_prev, self._m_prev = self._m_prev, m
            trig = self._trigger
            p = float(trig.pos)
            if m_prev < p <= m if trig.master_dir > 0 else m_prev > p >= m:
                self._state = _MOVE
                self._x = passed(m - p, self._dir)
                self._follow()
            else:
                self._vel = self._acc = 0.0
        elif state == _STOP:
            self._pos, self._vel, self._acc = self._stop.step()
            if self._stop.done:
                self._state = _IDLE
                self._vel = self._acc = 0.0
        return self._pos, self._vel, self._acc

    def run(self, masters: list[float]) -> tuple[list[float], list[float], list[float], int]:
        """:meth:`step` once per master position of ``masters`` (the axis bank's tables), the
        same operations: the samples up to the end and its index (-1: the motion goes on).
        Inside the current cam segment the sample is :meth:`_follow`'s closed form; anything
        else (a segment, pass or FIFO boundary, a master moving back) is :meth:`_follow`."""
        if self._state != _MOVE:
            return self.run_steps(masters)
        ps: list[float] = []
        vs_: list[float] = []
        as_: list[float] = []
        cyc, dir_ = self._T, self._dir
        x, m_prev = self._x, self._m_prev
        pos, vel, acc = self._pos, self._vel, self._acc
        sd, i = self._sd, self._i
        seg = self._segs[i]
        x0, x1, base, rs, k = seg.x0, seg.x1, self._origin + seg.s0, seg.rs, seg.k
        for j, m in enumerate(masters):
            m = float(m)
            x += passed(m - m_prev, dir_)
            m_prev = m
            if (x - x1) * sd >= 0.0 or (i > 0 and (x - x0) * sd < 0.0):
                self._x, self._m_prev = x, m_prev
                self._pos, self._vel, self._acc = pos, vel, acc
                self._follow()
                pos, vel, acc = self._pos, self._vel, self._acc
                if self._state == _IDLE:
                    ps.append(pos)
                    vs_.append(vel)
                    as_.append(acc)
                    return ps, vs_, as_, j
                sd, i = self._sd, self._i
                seg = self._segs[i]
                x0, x1, base, rs, k = seg.x0, seg.x1, self._origin + seg.s0, seg.rs, seg.k
            else:
                u = x - x0
                if u * sd < 0.0:
                    u = 0.0  # behind the start of the pass: wait there
                s = base + u * (rs + k * u)
                v = (s - pos) / cyc
                acc = (v - vel) / cyc
                vel = v
                pos = s
            ps.append(pos)
            vs_.append(vel)
            as_.append(acc)
        self._x, self._m_prev = x, m_prev
        self._pos, self._vel, self._acc = pos, vel, acc
        return ps, vs_, as_, -1

    # ------------------------------------------------------------ internals
    def _follow(self) -> None:
        """Slave position for the current master travel ``_x``."""
        x = self._x
        sd = self._sd
        segs = self._segs
        i = self._i
        seg = segs[i]
        while (x - seg.x1) * sd >= 0.0:
            if not self._advance():
                self._finish(self._origin + seg.s1)
                return
            segs, i, sd = self._segs, self._i, self._sd
            seg = segs[i]
        while i > 0 and (x - seg.x0) * sd < 0.0:
            i -= 1
            seg = segs[i]
        self._i = i
        u = x - seg.x0
        if u * sd < 0.0:
            u = 0.0  # behind the start of the pass: wait there
        s = self._origin + seg.s0 + u * (seg.rs + seg.k * u)
        v = (s - self._pos) / self._T
        self._acc = (v - self._vel) / self._T
        self._vel = v
        self._pos = s

    def _begin_pass(self, x0: float, s0: float, carry: float) -> None:
        self._x0, self._s0, self._carry = x0, s0, carry
        self._segs = []
        self._i = 0
        self._sd = 1.0 if self._fifos[self._r][0].master > 0 else -1.0
        self._segs.append(self._segment(0))

    def _segment(self, i: int) -> _Seg:
        """Cam segment ``i`` of the current pass (manual 7.6.2 (5) ratio rules)."""
        q = self._fifos[self._r]
        pt = q[i]
        if i:
            prev = q[i - 1]
            pm, ps = float(prev.master), prev.slave
            r_prev = self._segs[i - 1].re
        else:
            pm, ps = 0.0, 0.0
            r_prev = self._carry
        dm = pt.master - pm
        ds = pt.slave - ps
        kind = pt.type
        if kind == FollowSegmentType.EVEN:
            rs = re = ds / dm
        elif kind == FollowSegmentType.STOP:
            rs, re = 2.0 * ds / dm, 0.0
        else:
            rs = r_prev if (i or kind == FollowSegmentType.CONTINUE) else 0.0
            re = 2.0 * ds / dm - rs
        return _Seg(
            self._x0 + pm,
            self._x0 + pt.master,
            self._s0 + ps,
            self._s0 + pt.slave,
            rs,
            re,
            (re - rs) / (2.0 * dm),
        )

    def _advance(self) -> bool:
        """Next segment, next pass or the switched FIFO; False when the motion is complete."""
        q = self._fifos[self._r]
        i = self._i + 1
        if i < len(q):
            self._i = i
            if i == len(self._segs):
                self._segs.append(self._segment(i))
            return True
        last = self._segs[self._i]
        if self._switch:
            q.clear()
            self._r = 1 - self._r
            self._switch = False
            self._loops_done = 0
        else:
            self._loops_done += 1
            if self._loop >= 1 and self._loops_done >= self._loop:
                return False
        self._begin_pass(last.x1, last.s1, last.re)
        return True

    def _finish(self, pos: float) -> None:
        self._pos = pos
        self._vel = self._acc = 0.0
        self._state = _IDLE
