"""Coordinate systems (坐标系) of one core: segment FIFOs, vector speed, look-ahead, stops.

A :class:`CoordSystem` maps 1-4 coordinates (X, Y, Z, A) onto profiles
(``TCrdPrm.profile[k] = c``: profile ``k+1`` is coordinate ``c``, 0 = none,
as the vendor's examples write ``profile[0] = 1; /* 规划器1对应到X轴 */``).
:meth:`CoordSystem.configure` puts each mapped profile into interpolation
mode (``PrfMode.INTERPOLATION``) with an :class:`AxisSlot` planner, so the
axis layer samples, stops and holds it like any mode's planner.  The system
itself advances once per cycle in the controller's ``pre_cycle`` hook, before
the axes take their samples, and writes each slot's position.

Decisions where the manual is silent:

* **Origin**: ``setOriginFlag = 0`` puts the origin at the profiles' planned
  positions when GT_SetCrdPrm is called; ``1`` at ``originPos[c-1]`` for
  coordinate ``c`` (profile pulses).  Coordinates are profile positions minus
  the origin.
* **FIFOs** 0 and 1 hold :data:`FIFO_SIZE` entries each; a segment's start is the
  previous entry's end (or the system's position when the FIFO is empty), so
  GT_ArcXYC's relative centre is known when it is pushed.  GT_CrdStart
  ``option`` bit ``n-1`` picks FIFO 1 for system ``n``.  A start runs the FIFO to
  its end; entries pushed while it runs are run too.
* **Speed**: ``synVel``/``synAcc`` above synVelMax/synAccMax are cut to them;
  each segment is a :class:`~.velocity.Trapezoid` from the speed the previous one
  ended with.  Its exit speed is decided when it starts: ``velEnd`` (capped by
  this and the next segment's synVel) when the next motion segment is already in
  the FIFO, else 0; and never more than the next segment can stop from.  With
  look-ahead (GT_InitLookAhead) ``velEnd`` is not used: the exit speed is the
  largest the next ``n`` segments allow, where a corner whose unit tangents differ
  by ``d`` passes at ``accMax·T/|d|`` and an arc at ``sqrt(accMax·r)``, and the
  path stops at the end of the window.
* **Override** (GT_SetOverride, 0..2): the path time runs at that ratio (speed ×
  ratio, acceleration × ratio²); a GT_BufDelay still lasts its milliseconds.
* **Stops**: a stop of any axis of the system (GT_Stop, a limit, the following
  error, a stop input) stops the whole system along its path with GT_SetCrdStopDec's
  smooth or abrupt deceleration (defaults 1 and 1000 pulse/ms², as table 4-4 for a
  profile); the rest of the FIFO is dropped.  A hold (servo off, alarm, another drive
  mode) drops the motion at once; the other axes stand where they are.  A soft
  limit passed in a cycle starts the path stop from that cycle's sample.
* **Segments counted** by GT_CrdStatus: every FIFO entry finished since GT_CrdStart
  (lines, arcs, BufIO, BufDelay, BufMove alike).
* **A segment's own speed plan** (``Motion.speed_plan``, the pulse-card compat layers):
  the segment runs that plan (base pulses, :mod:`.base_pulse`) instead of the trapezoid;
  it gets the entry speed and the previous segment's plan, and decides its exit speed.
* **GT_BufIO** records ``(doType, doMask, doValue)`` in :attr:`CoordSystem.io_log`
  and :attr:`CoordSystem.outputs` (value per doType) when the path reaches it; for
  ``MC_GPO`` it also sets the masked bits of the general-purpose outputs (what
  GT_SetDo / GT_GetDo use).  **GT_BufMove** starts a Trap move of an axis outside the
  system; ``modal = 1`` waits until it stands.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import CommandError, ParameterError
from ..motion.stop import StopDecel, StopKind
from ..profile import PrfMode
from .path import Arc, Line, Segment
from .velocity import Trapezoid

_get = object.__getattribute__

CRD_COUNT = 2
FIFO_SIZE = 4096
DIM_MAX = 4
OVERRIDE_MAX = 2.0
#: the geometries whose cycles :meth:`CoordSystem.run` takes many at a time
_VECTOR = (Line, Arc)


@dataclass(frozen=True, slots=True)
class CrdParams:
    dimension: int
    profile: tuple[int, ...]  #: 8 entries: coordinate of profile k+1 (0 = none)
    syn_vel_max: float
    syn_acc_max: float
    even_time: int = 0
    set_origin: int = 0
    origin: tuple[float, ...] = (0.0,) * 8

    def axes(self) -> list[int]:
        """Profile number of each coordinate, X first."""
        out = [0] * self.dimension
        for k, c in enumerate(self.profile):
            if c:
                out[c - 1] = k + 1
        return out


@dataclass(slots=True)
class Motion:
    geom: Segment
    vel: float
    acc: float
    vel_end: float
    #: the segment's own speed plan instead of the trapezoid: called as
    #: ``speed_plan(geom, entry_speed, previous_plan)`` when the segment starts (the
    #: pulse-card compat layers: :class:`~.base_pulse.BaseSpeed`)
    speed_plan: Callable[[Segment, float, Any], Any] | None = field(repr=False, default=None)


@dataclass(slots=True)
class Delay:
    ms: float


@dataclass(slots=True)
class BufIO:
    do_type: int
    mask: int
    value: int
    apply: Callable[[int, int], None] | None = field(repr=False, default=None)


@dataclass(slots=True)
class BufMove:
    axis: int
    pos: int
    vel: float
    acc: float
    modal: int
    run: Callable[[], Callable[[], bool]] = field(repr=False, default=lambda: lambda: True)


@dataclass(slots=True)
class BufGear:
    """An axis outside the system that moves with the next motion segment: ``start()``
    (called when the path reaches this entry) returns ``follow(fraction)``, which the
    system calls every cycle of that segment with the share of its length done (1.0 at
    its end) and with None when the path stops before the segment's end."""

    axis: int
    delta: float
    start: Callable[[], Callable[[float | None], None]] = field(repr=False)


Entry = Motion | Delay | BufIO | BufMove | BufGear


@dataclass(slots=True)
class LookAhead:
    T: float
    acc_max: float
    n: int
    #: pulses per user unit of each coordinate when the look-ahead was set up in user
    #: units (GT_InitLookAheadEx): the ``Ex`` lines and arcs of the FIFO are in those units
    unit: tuple[float, ...] | None = None
    #: the fastest speed along the path in pulse/ms (the axes' vMax), None = no limit
    vel_max: float | None = None


class AxisSlot:
    """The planner of a profile in interpolation mode: its coordinate of one system."""

    __slots__ = ("_acc", "_fresh", "_pos", "_vel", "coord", "crd", "stopping")

    def __init__(self, crd: CoordSystem, coord: int, pos: float) -> None:
        self.crd = crd
        self.coord = coord
        self._pos = pos
        self._vel = 0.0
        self._acc = 0.0
        self._fresh = False  # a sample the axis has not taken yet (the path's last one)
        self.stopping = StopKind.NONE

    @property
    def done(self) -> bool:
        # the cycle the path ends in still sends its end point to the axis
        return not self.crd.running and not self._fresh

    @property
    def pos(self) -> float:
        return self._pos

    @property
    def vel(self) -> float:
        return self._vel

    @property
    def acc(self) -> float:
        return self._acc

    def step(self) -> tuple[float, float, float]:
        self._fresh = False
        return self._pos, self._vel, self._acc  # the system advanced in pre_cycle

    def stop(self, dec: float, abrupt: bool = False, origin: Any = None) -> None:
        self.crd.stop(abrupt)

    def hold(self, pos: float) -> None:
        self._pos, self._vel, self._acc = pos, 0.0, 0.0
        self._fresh = False
        if self.crd.running:
            self.crd.abort()

    def sample(self, pos: float, vel: float, acc: float) -> None:
        self._pos, self._vel, self._acc = pos, vel, acc
        self._fresh = True
        self.stopping = self.crd.stopping


class CoordSystem:
    """One coordinate system: parameters, two FIFOs, the running path."""

    def __init__(self, number: int, cycle_ms: Callable[[], float]) -> None:
        self.number = number
        self._cycle_ms = cycle_ms
        #: the axis bank (gtecat.controller.bank) steps this system ahead with its axes'
        #: samples while it runs them: the controller's hook then leaves it alone
        self.banked = False
        #: while banked, what the system was in each cycle the bank stepped it ahead
        #: (:class:`gtecat.controller.bank_modes.SystemTrace`): :meth:`now` reads it
        self.trace: Any = None
        #: set by the axis bank for one push onto the system it holds ahead (AxisBank.before_call):
        #: called with (system, entry, fifo) after the entry is in the FIFO
        self.push_hook: Callable[[CoordSystem, Entry, int], None] | None = None
        #: while not None, every entry taken off a FIFO is appended to it (the axis bank's
        #: record for putting the FIFO back as it was: bank_modes.keep)
        self.popped: list[Entry] | None = None
        self._out: np.ndarray | None = None  # run's samples
        self.reset()

    def reset(self) -> None:
        self.prm: CrdParams | None = None
        self.slots: list[AxisSlot] = []
        self.origin: list[float] = []
        self.fifos: tuple[deque[Entry], deque[Entry]] = (deque(), deque())
        self.tails: list[tuple[float, ...] | None] = [None, None]
        self.look: list[LookAhead | None] = [None, None]
        #: GT_SetupLookAheadCrd's machine mode and the planner modes (``...ModeLa``) by name
        self.la_modes: dict[str, Any] = {}
        self.stop_dec = StopDecel()
        self.override = 1.0
        self.outputs: dict[int, int] = {}
        self.io_log: list[tuple[int, int, int]] = []
        self._idle()
        self.segments_done = [0, 0]

    def _idle(self) -> None:
        self.running = False
        self.fifo = 0
        self.stopping = StopKind.NONE
        self.entry: Entry | None = None
        self.plan: Any = None  # Trapezoid, or a segment's own speed plan
        self.t = 0.0
        self.s = 0.0
        self.speed = 0.0
        self.stop_acc = 0.0
        self.waiting: Callable[[], bool] | None = None
        self._gear_end(None)
        #: BufGear riders waiting for the next motion segment, and those riding this one
        self.gears_next: list[Callable[[float | None], None]] = []
        self.gears: list[Callable[[float | None], None]] = []
        self.gear_entry: Motion | None = None

    def _gear_end(self, fraction: float | None) -> None:
        for follow in getattr(self, "gears", ()):
            follow(fraction)
        self.gears = []

    # --- configuration ----------------------------------------------------------------
    def configure(self, prm: CrdParams, profiles: dict[int, Any]) -> None:
        """GT_SetCrdPrm: ``profiles`` maps profile number -> its Profile (all at rest)."""
        if self.running:
            raise CommandError(f"coordinate system {self.number} is moving")
        axes = prm.axes()
        for n in axes:
            profiles[n].require_idle("GT_SetCrdPrm")
        slots = []
        origin = []
        for c, n in enumerate(axes):
            p = profiles[n]
            pos = p.planner.pos
            slot = AxisSlot(self, c, pos)
            p.enter(PrfMode.INTERPOLATION, planner=slot)
            slots.append(slot)
            origin.append(prm.origin[c] if prm.set_origin else pos)
        self.prm, self.slots, self.origin = prm, slots, origin
        self.fifos[0].clear()
        self.fifos[1].clear()
        self.tails = [None, None]

    def require_prm(self, what: str) -> CrdParams:
        if self.prm is None:
            raise CommandError(
                f"{what}: coordinate system {self.number} has no parameters; call GT_SetCrdPrm"
            )
        return self.prm

    def position(self) -> tuple[float, ...]:
        """The coordinates now (profile positions minus the origin)."""
        return tuple(s.pos - o for s, o in zip(self.slots, self.origin, strict=True))

    def now(self) -> Any:
        """What the read calls look at (``running``, ``fifo``, ``segments_done``,
        :meth:`position`, :meth:`vector_speed`, :meth:`space`): the system itself, or, while
        the axis bank has stepped it ahead of the controller's time, its state in this cycle."""
        t = self.trace
        if t is not None:
            return t.now(self)
        # claimed but not yet stepped ahead: its own state, read past the slots' guards
        return CrdNow(self, self.state()) if self.banked else self

    def state(self) -> tuple:
        """What :meth:`now` reports, as one tuple (the axis bank's record of a cycle)."""
        f0, f1 = self.fifos
        return (
            self.running,
            self.fifo,
            self.segments_done[0],
            self.segments_done[1],
            len(f0),
            len(f1),
            self.speed,
            tuple(_get(s, "_pos") - o for s, o in zip(self.slots, self.origin, strict=True)),
            self.entry is not None,
        )

    def remainder(self, fifo: int) -> int:
        """Entries of ``fifo`` not finished yet (the running one included)."""
        running = 1 if self.running and self.fifo == fifo and self.entry is not None else 0
        return len(self.fifos[fifo]) + running

    # --- the FIFOs ----------------------------------------------------------------------
    def _fifo(self, fifo: int) -> deque[Entry]:
        if fifo not in (0, 1):
            raise ParameterError(f"fifo={fifo}: 0 or 1")
        return self.fifos[fifo]

    def space(self, fifo: int) -> int:
        return FIFO_SIZE - len(self._fifo(fifo))

    def tail(self, fifo: int) -> tuple[float, ...]:
        """Where the next segment of ``fifo`` starts."""
        t = self.tails[fifo] if self._fifo(fifo) or self._runs(fifo) else None
        return t if t is not None else self.position()

    def _runs(self, fifo: int) -> bool:
        return self.running and self.fifo == fifo

    def push(self, entry: Entry, fifo: int) -> None:
        q = self._fifo(fifo)
        if len(q) >= FIFO_SIZE:
            raise CommandError(f"FIFO {fifo} of coordinate system {self.number} is full")
        if isinstance(entry, Motion):
            self.tails[fifo] = entry.geom.end
        elif not q and not self._runs(fifo):
            self.tails[fifo] = self.position()
        q.append(entry)
        hook = self.push_hook
        if hook is not None:
            self.push_hook = None
            hook(self, entry, fifo)

    def clear(self, fifo: int) -> None:
        if self._runs(fifo):
            raise CommandError(
                f"GT_CrdClear: FIFO {fifo} of coordinate system {self.number} is running"
            )
        self._fifo(fifo).clear()
        self.tails[fifo] = None

    def motion_params(self, vel: float, acc: float, vel_end: float) -> tuple[float, float, float]:
        prm = self.require_prm("segment")
        if not (math.isfinite(vel) and vel > 0.0):
            raise ParameterError(f"synVel={vel}: must be > 0")
        if not (math.isfinite(acc) and acc > 0.0):
            raise ParameterError(f"synAcc={acc}: must be > 0")
        if not (math.isfinite(vel_end) and vel_end >= 0.0):
            raise ParameterError(f"velEnd={vel_end}: must be >= 0")
        vel = min(vel, prm.syn_vel_max)
        return vel, min(acc, prm.syn_acc_max), min(vel_end, vel)

    # --- start, stop --------------------------------------------------------------------
    def start(self, fifo: int) -> None:
        q = self._fifo(fifo)
        if not q:
            raise CommandError(
                f"GT_CrdStart: FIFO {fifo} of coordinate system {self.number} holds no segment"
            )
        self._idle()
        self.running, self.fifo = True, fifo
        self.segments_done[fifo] = 0
        self.speed = 0.0
        self._next(0.0)

    def stop(self, abrupt: bool) -> None:
        if not self.running or self.stopping == StopKind.ABRUPT:
            return
        self.stopping = StopKind.ABRUPT if abrupt else StopKind.SMOOTH
        self.stop_acc = self.stop_dec.for_kind(abrupt)
        self.waiting = None
        if not isinstance(self.entry, Motion) or self.speed <= 0.0:
            self._end_stop()

    def abort(self) -> None:
        self._drop_fifo()
        self._finish()
        for s in self.slots:
            s._vel = s._acc = 0.0

    def _drop_fifo(self) -> None:
        q = self.fifos[self.fifo]
        if self.popped is not None:
            self.popped.extend(q)
        q.clear()
        self.tails[self.fifo] = None

    def _end_stop(self) -> None:
        self._drop_fifo()
        self._finish()

    def _finish(self) -> None:
        fifo = self.fifo
        done = self.segments_done
        self._idle()
        self.fifo = fifo
        self.segments_done = done

    # --- the cycle ----------------------------------------------------------------------
    def step(self) -> None:
        if not self.running:
            return
        cyc = self._cycle_ms()
        slots = self.slots
        before = [s._pos for s in slots]
        if self.stopping:  # StopKind.NONE is 0
            self._step_stop(cyc * max(self.override, 1e-3))
        else:
            self._advance(cyc * self.override)
        e = self.entry
        if type(e) is Motion:  # _sample_point(), without its checks: the common case
            self._sample_point_of(e, self.s)
        else:
            self._sample_point()
        stopping = self.stopping
        for slot, old in zip(slots, before, strict=True):  # AxisSlot.sample, inline
            v = (slot._pos - old) / cyc
            slot._acc = (v - slot._vel) / cyc
            slot._vel = v
            slot._fresh = True
            slot.stopping = stopping
        if not self.running:
            for slot in self.slots:
                slot._vel = slot._acc = 0.0
                slot.stopping = StopKind.NONE

    def run(
        self,
        n: int,
        speeds: list[float] | None = None,
        marks: list[tuple[int, tuple]] | None = None,
        segment: Callable[..., int] | None = None,
    ) -> tuple[np.ndarray, int]:
        """``n`` cycles of :meth:`step`, each followed by every axis taking its slot's sample
        (``AxisSlot.step``), for the axis bank's tables: the samples (``out[0|1|2, k, j]``:
        position, speed, acceleration of slot ``k`` in cycle ``j``; the system's own array,
        which its next run overwrites) and the index of the cycle the path ended in (-1: it
        goes on; the cycles after it are not filled).  The cycles inside a motion segment are
        step's own common case, for a trapezoid along a line or an arc all of them at once
        (:meth:`_run_segment`, the same operations in the same order); any other is
        :meth:`step`.  ``speeds``/``marks``: the path speed after each
        cycle, and (cycle, :meth:`state`) after each cycle that was not the common case;
        ``segment``: :meth:`_run_segment` compiled, called with the system first
        (:class:`gtecat.controller.bank_crd.CrdFill`)."""
        slots = self.slots
        rec = speeds is not None and marks is not None
        origin = self.origin
        # the system's own array, used again by its next run (the axis bank copies the
        # samples into its tables; its record of this run is replaced at the next)
        out = self._out
        if out is None or out.shape != (3, len(slots), n):
            out = self._out = np.empty((3, len(slots), n))
        j = 0
        while j < n:
            e = self.entry
            if not self.stopping and type(e) is Motion and self.waiting is None and not self.gears:
                plan = self.plan
                if type(plan) is Trapezoid and type(e.geom) in _VECTOR:
                    if segment is None:
                        j += self._run_segment(e, plan, out, j, speeds if rec else None)
                    else:
                        j += segment(self, e, plan, out, j, speeds if rec else None)
                    if j >= n:
                        break
                else:  # a segment's own speed plan: one cycle
                    cyc = self._cycle_ms()
                    t = self.t + cyc * self.override
                    if t < plan.duration:
                        self.t = t
                        s = plan.s(t)
                        self.s = s
                        self.speed = sp = plan.v(t)
                        if rec:
                            speeds.append(sp)  # type: ignore[union-attr]
                        for k, (slot, o, x) in enumerate(
                            zip(slots, origin, e.geom.point(s), strict=True)
                        ):
                            p = o + x
                            v = (p - slot._pos) / cyc
                            a = (v - slot._vel) / cyc
                            slot._pos, slot._vel, slot._acc = p, v, a
                            slot._fresh = False  # the axis took it
                            out[0, k, j], out[1, k, j], out[2, k, j] = p, v, a
                        j += 1
                        continue
            self.step()
            for k, slot in enumerate(slots):
                out[0, k, j], out[1, k, j], out[2, k, j] = slot.step()
            if rec:
                speeds.append(self.speed)  # type: ignore[union-attr]
                marks.append((j, self.state()))  # type: ignore[union-attr]
            if not self.running:
                return out, j
            j += 1
        return out, -1

    def _run_segment(
        self, e: Motion, plan: Trapezoid, out: np.ndarray, j: int, speeds: list[float] | None
    ) -> int:
        """The cycles from ``j`` on (at most to the end of ``out``) that stay inside the motion
        segment ``e``, at once: their samples into ``out``; how many.  Every value is the
        scalar cycle's bit for bit: the path time by repeated addition (a cumulative sum adds
        one after the other, as the cycles do), the trapezoid's and the geometry's formulas
        elementwise in the scalar order (:meth:`Trapezoid.s_v`, ``points``), then per slot
        ``p = o + x``, ``v = (p - p_before) / cyc``, ``a = (v - v_before) / cyc``."""
        cyc = self._cycle_ms()
        dt = cyc * self.override
        m = out.shape[2] - j
        if not dt >= 0.0:  # (a NaN) the times would not rise: one cycle at a time
            return 0
        ts = np.full(m + 1, dt)
        ts[0] = self.t
        np.cumsum(ts, out=ts)
        k = int(np.searchsorted(ts[1:], plan.duration))  # the times before the segment's end
        if k == 0:
            return 0
        t = ts[1 : k + 1]
        s, sp = plan.s_v(t)
        slots = self.slots
        d = len(slots)
        # positions and speeds, each slot's before the first cycle in column 0
        pe = np.empty((d, k + 1))
        ve = np.empty((d, k + 1))
        pe[:, 0] = [slot._pos for slot in slots]
        ve[:, 0] = [slot._vel for slot in slots]
        p, v = pe[:, 1:], ve[:, 1:]
        e.geom.points(s, p)
        p += np.array(self.origin)[:, None]
        np.subtract(p, pe[:, :-1], out=v)
        v /= cyc
        a = out[2, :, j : j + k]
        np.subtract(v, ve[:, :-1], out=a)
        a /= cyc
        out[0, :, j : j + k] = p
        out[1, :, j : j + k] = v
        for slot, pi, vi, ai in zip(
            slots, pe[:, -1].tolist(), ve[:, -1].tolist(), a[:, -1].tolist(), strict=True
        ):
            slot._pos, slot._vel, slot._acc = pi, vi, ai
            slot._fresh = False  # the axis took it
        self.t = t[-1].item()
        self.s = s[-1].item()
        self.speed = sp[-1].item()
        if speeds is not None:
            speeds.extend(sp.tolist())
        return k

    def _advance(self, dt: float) -> None:
        self.t += dt
        e = self.entry
        if type(e) is Motion and self.waiting is None:  # the common case: inside a segment
            plan = self.plan
            t = self.t
            if t < plan.duration:
                self.s = plan.s(t)
                self.speed = plan.v(t)
                return
        while self.running:
            e = self.entry
            if self.waiting is not None:
                if not self.waiting():
                    self.t = 0.0
                    return
                self.waiting = None
                self._done_entry(0.0)
                continue
            if isinstance(e, Motion):
                plan = self.plan
                if self.t < plan.duration:
                    self.s = plan.s(self.t)
                    self.speed = plan.v(self.t)
                    return
                self._done_entry(self.t - plan.duration)
                continue
            if isinstance(e, Delay):  # controller time: path time x override
                span = e.ms * self.override
                if self.t < span or (span <= 0.0 and self.override <= 0.0):
                    return
                self._done_entry(self.t - span)
                continue
            return

    def _done_entry(self, leftover: float) -> None:
        e = self.entry
        if isinstance(e, Motion):
            self.s = e.geom.length
            self.speed = self.plan.v_end
            self._sample_point_of(e, e.geom.length)
        self.segments_done[self.fifo] += 1
        self._next(leftover)

    def _next(self, leftover: float) -> None:
        """Take the next FIFO entry with ``leftover`` ms of this cycle already spent in it."""
        q = self.fifos[self.fifo]
        while q:
            e = q.popleft()
            if self.popped is not None:
                self.popped.append(e)
            self.entry, self.t = e, leftover
            if isinstance(e, Motion):
                if e.geom.length <= 0.0:
                    self.segments_done[self.fifo] += 1
                    continue
                self.s = 0.0
                self._gear_end(None)
                self.gears, self.gears_next, self.gear_entry = self.gears_next, [], e
                if e.speed_plan is not None:
                    self.plan = e.speed_plan(e.geom, self.speed, self.plan)
                    return
                self.plan = Trapezoid(
                    e.geom.length,
                    self.speed,
                    self._vmax(e),
                    self._exit_speed(e),
                    e.acc,
                    float(self.prm.even_time) if self.prm else 0.0,
                )
                return
            self.speed = 0.0
            if isinstance(e, Delay):
                return
            if isinstance(e, BufIO):
                old = self.outputs.get(e.do_type, 0)
                self.outputs[e.do_type] = (old & ~e.mask) | (e.value & e.mask)
                self.io_log.append((e.do_type, e.mask, e.value))
                if e.apply is not None:
                    e.apply(e.mask, e.value)
                self.segments_done[self.fifo] += 1
                continue
            if isinstance(e, BufGear):
                self.gears_next.append(e.start())
                self.segments_done[self.fifo] += 1
                continue
            if isinstance(e, BufMove):
                done = e.run()
                if e.modal:
                    self.waiting = done
                    return
                self.segments_done[self.fifo] += 1
                continue
        # the FIFO ran out: the path ends here (the last segment's exit speed was 0)
        self.entry = None
        self._finish()

    def _vmax(self, e: Motion) -> float:
        la = self.look[self.fifo]
        v = e.vel
        if la is not None and isinstance(e.geom, Arc):
            v = min(v, math.sqrt(la.acc_max * max(e.geom.r0, 1e-9)))
        return v

    def _exit_speed(self, e: Motion) -> float:
        q = self.fifos[self.fifo]
        la = self.look[self.fifo]
        window: list[Motion] = []
        for nxt in q:
            if not isinstance(nxt, Motion):
                if isinstance(nxt, BufIO | BufGear):
                    continue
                break  # a delay or a modal move: the path stops before it
            if nxt.geom.length <= 0.0:
                continue
            window.append(nxt)
            if len(window) >= (la.n if la is not None else 1):
                break
        if not window:
            return 0.0
        chain = [e, *window]
        # corner limits between chain[k] and chain[k+1]
        limits = []
        for k in range(len(chain) - 1):
            a, b = chain[k], chain[k + 1]
            lim = min(self._vmax(a), self._vmax(b))
            if la is None:
                lim = min(lim, a.vel_end)
            else:
                ta, tb = a.geom.tangent(True), b.geom.tangent(False)
                d = math.sqrt(sum((x - y) ** 2 for x, y in zip(ta, tb, strict=True)))
                if d > 1e-9:
                    lim = min(lim, la.acc_max * la.T / d)
            limits.append(lim)
        w = 0.0  # speed at the end of the window
        for k in range(len(chain) - 1, 0, -1):
            seg = chain[k]
            w = min(limits[k - 1], math.sqrt(w * w + 2.0 * seg.acc * seg.geom.length))
        return w

    def _step_stop(self, dt: float) -> None:
        """Brake along the path: the constant-deceleration ramp's distance this cycle, through
        as many queued segments as it takes (entries other than motion are skipped)."""
        v0 = self.speed
        dec = self.stop_acc
        v1 = max(v0 - dec * dt, 0.0)
        tb = (v0 - v1) / dec
        ds = v0 * tb - 0.5 * dec * tb * tb
        self.speed = v1
        q = self.fifos[self.fifo]
        e = self.entry
        s = self.s + ds
        while isinstance(e, Motion) and s > e.geom.length:
            s -= e.geom.length
            nxt = None
            while q:
                cand = q.popleft()
                if self.popped is not None:
                    self.popped.append(cand)
                if isinstance(cand, Motion) and cand.geom.length > 0.0:
                    nxt = cand
                    break
            if nxt is None:  # the path ends before the ramp: stop at its end
                s = e.geom.length
                self.speed = 0.0
                break
            self._sample_point_of(e, e.geom.length)
            self.segments_done[self.fifo] += 1
            self.entry = e = nxt
        self.s = s
        if self.speed <= 0.0:
            self._sample_point()
            if isinstance(e, Motion) and s >= e.geom.length:
                self.segments_done[self.fifo] += 1
            self._end_stop()

    def _sample_point(self) -> None:
        e = self.entry
        if isinstance(e, Motion):
            self._sample_point_of(e, self.s)

    def _sample_point_of(self, e: Motion, s: float) -> None:
        if self.gears and e is self.gear_entry:
            frac = min(max(s / e.geom.length, 0.0), 1.0)
            for follow in self.gears:
                follow(frac)
            if frac >= 1.0:
                self.gears = []
        for slot, o, x in zip(self.slots, self.origin, e.geom.point(s), strict=True):
            slot._pos = o + x

    def vector_speed(self) -> float:
        return self.speed * self.override if self.running else 0.0


class CrdNow:
    """A coordinate system as its read calls see it in one cycle (:meth:`CoordSystem.now`
    while the axis bank holds it): a :meth:`CoordSystem.state` tuple."""

    __slots__ = ("_c", "_st", "fifo", "running", "segments_done")

    def __init__(self, c: CoordSystem, st: tuple) -> None:
        self._c, self._st = c, st
        self.running, self.fifo = st[0], st[1]
        self.segments_done = [st[2], st[3]]

    def position(self) -> tuple[float, ...]:
        return self._st[7]

    def vector_speed(self) -> float:
        return self._st[6] * self._c.override if self.running else 0.0

    def space(self, fifo: int) -> int:
        self._c._fifo(fifo)  # its check of the number
        return FIFO_SIZE - self._st[4 + int(fifo)]

    def remainder(self, fifo: int) -> int:
        st = self._st
        running = 1 if self.running and self.fifo == fifo and st[8] else 0
        return st[4:6][fifo] + running


class CrdBank:
    """The coordinate systems of one controller, stepped in its ``pre_cycle`` hook."""

    def __init__(self, ctl: Any) -> None:
        self.ctl = ctl
        cyc = lambda: ctl.clock.cycle_ns / 1e6  # noqa: E731
        self.systems = {n: CoordSystem(n, cyc) for n in range(1, CRD_COUNT + 1)}
        ctl.pre_cycle.append(self._pre)
        ctl.on_reset.append(self._reset)

    def _pre(self, t_ns: int, dt_ns: int) -> None:
        for c in self.systems.values():
            if c.running and not c.banked:
                c.step()

    _pre.bank_safe = True  # type: ignore[attr-defined]  # touches interpolating axes only

    def bank_quiet(self) -> bool:
        """No cycle of this hook does anything: every running system is stepped by the axis
        bank (the controller may then run its cycles many at a time)."""
        return all(c.banked or not c.running for c in self.systems.values())

    def _reset(self, ctl: Any) -> None:
        for c in self.systems.values():
            c.reset()

    def get(self, n: Any) -> CoordSystem:
        try:
            k = int(n)
        except (TypeError, ValueError):
            raise ParameterError(f"crd={n!r} is not an integer") from None
        c = self.systems.get(k)
        if c is None:
            raise ParameterError(f"crd={k}: coordinate systems are 1..{CRD_COUNT}")
        return c


def bank(ctl: Any) -> CrdBank:
    """The coordinate systems of a core (made on first use): each core has its own
    (``GTN_SetCrdPrm(2, 1, ...)`` sets up system 1 of core 2 over that core's profiles),
    so a core's view (:mod:`gtecat.controller.core_view`) never reaches core 1's."""
    b = vars(ctl).get("crd_bank")
    if b is None:
        b = CrdBank(ctl)
        ctl.crd_bank = b
    return b
