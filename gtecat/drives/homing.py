"""Homing mode (6060h = 6) inside the virtual drive: the search, the home point, SW10/12/13.

CiA 402-2 / IEC 61800-7-201 "Homing mode"; digest in ``cia402-facts.md`` §3.  The
controller only sets 6098h/6099h/609Ah/607Ch, starts with CW4 and reads the status
(manual 5.2.2.2); everything else happens here.  The drive creates one
:class:`Homing` when CW4 rises in homing mode and calls :meth:`Homing.step` once per
cycle with the actual machine position; :meth:`step` returns the demanded machine
position, which the drive's position loop follows.

Decisions (the standard leaves them open; tested in ``tests/drives/test_homing.py``):

* **Edges are exact.**  Switch and index positions crossed inside a cycle are computed
  from the two actual position samples, so the home point never depends on cycle time,
  speed, or position-loop lag.  An index pulse lying exactly on the reference edge is
  not "beyond" it.
* **Speeds.**  6099h:01 while searching for the switch; 6099h:02 for the final
  approach after reversing on the reference edge and for the index search (also
  33/34).  Every speed change is a ramp at 609Ah.  The return onto the home point is a
  positioning move capped at 6099h:01 (after a creep-speed approach it never gets
  near that cap; after a fast direct crossing it does not crawl back).
* **After the home point is found** (SW12 = 1, "attained") the drive decelerates and
  moves back onto it, stopping exactly there; SW10 = 1 ("completed") once at rest.
  So the mechanics end on the home point, whatever the approach speed.
* **Home offset 607Ch** (CiA 402 / Elmo convention): after homing the home point
  reads 607Ch, i.e. ``6064 = machine_pos - home_machine_position + 607Ch``;
  :meth:`encoder_offset` returns ``home_machine_position - 607Ch``.  Methods 35 and 37
  (identical here): the current position becomes the home point, so it reads 607Ch;
  they complete at once without motion.
* **The switches read as the drive reads them** (its 60FDh bits 0..2): a switch the field
  forces (``switch_stuck``, ``switch_chatter`` of :mod:`gtecat.faults`, handed in as the
  ``forced`` masks) is what the search sees too.  A forced switch has no position: its
  level is sampled once per cycle and an edge of it lies at the cycle's sample (where the
  drive saw the input change), never at the machine description's window edge.  A home
  switch stuck inactive gives no edge, so the search runs on to a limit (or its travel
  bound) and ends in a homing error; stuck active, the method starts as on the switch
  (heading for the edge that leaves it) and never finds it; a chattering one gives an edge
  wherever it toggles, and the drive takes the first that fits the method, as a real
  drive would.  Limits likewise: a limit stuck inactive is never met (the search runs to
  its travel bound); one stuck active is met at once when the search heads into it.  A
  limit counts only when it lies in the direction of travel (the positive one while moving
  positive, the negative one while moving negative), as outside homing: a forced limit
  behind the axis, stuck or chattering, is ignored.  A limit is a level, not an edge: one
  stuck active behind the axis is met as soon as the search turns toward it (a real drive
  refuses travel into an active limit input), so a search that reverses or heads for the
  index pulse toward it ends there.
* **Errors** (SW13): a limit switch hit where the method does not reverse on it, a
  second hit of the reversal limit, no index pulse within one revolution after the
  reference edge, or the search exceeding ``max_travel`` or ``timeout_s``.  The axis
  decelerates at 609Ah; SW10 = 1 once it stands still.
* **Halt (CW8)** interrupts the procedure: decelerate at 609Ah and hold; SW10 = 1 once
  stopped ("interrupted", or "completed" if the home point was already found).
  Releasing halt does not resume: a new CW4 rising edge (a new :class:`Homing`)
  starts over.  A drive may use :meth:`halt` for CW4 falling too.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from enum import IntEnum

from gtecat.eni.errors import GtecatError

from .faults import forced_level
from .homing_methods import SUPPORTED_METHODS, MethodKind, MethodSpec, Signal, method_spec
from .machine import AxisMachine
from .signal_edges import level, merge_windows, window_edges

__all__ = [
    "SUPPORTED_METHODS",
    "Homing",
    "HomingError",
    "HomingParams",
    "HomingPhase",
    "UnsupportedHomingMethodError",
]

POSITION_WINDOW = 1.0  # counts: actual within this of the demand at rest = "stopped"
SETTLE_TIME_S = 0.05  # or the demand has rested this long (a drive that never settles)
DEFAULT_TIMEOUT_S = 300.0


class HomingError(GtecatError):
    """Homing parameters that cannot be used (not a homing *failure*: that is SW13)."""


class UnsupportedHomingMethodError(HomingError):
    """6098h holds a method this drive does not implement."""

    def __init__(self, method: int) -> None:
        self.method = method
        supported = ", ".join(str(m) for m in sorted(SUPPORTED_METHODS))
        super().__init__(
            f"homing method {method} (0x6098) is not supported; supported: {supported}"
        )


@dataclass(slots=True)
class HomingParams:
    """The homing objects, in drive counts.

    ``max_travel`` bounds the search path (default: 3x the travel between the limit
    switches plus braking distances, or 1000 revolutions when a limit is missing);
    ``timeout_s`` bounds the search time.  Both only turn an endless search into SW13.
    """

    method: int  # 0x6098
    speed_switch: float  # 0x6099:01, counts/s
    speed_zero: float  # 0x6099:02, counts/s
    acceleration: float  # 0x609A, counts/s²
    home_offset: int  # 0x607C
    max_travel: float | None = None
    timeout_s: float = DEFAULT_TIMEOUT_S

    def validate(self) -> MethodSpec:
        """The method's spec; raises :class:`HomingError` for unusable values."""
        spec = method_spec(self.method)
        if spec is None:
            raise UnsupportedHomingMethodError(self.method)
        if spec.kind is MethodKind.CURRENT_POSITION:
            return spec
        for name, value, obj in (
            ("speed_switch", self.speed_switch, "0x6099:01"),
            ("speed_zero", self.speed_zero, "0x6099:02"),
            ("acceleration", self.acceleration, "0x609A"),
        ):
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
                raise HomingError(f"homing {name} ({obj}) must be > 0, got {value!r}")
        if self.timeout_s <= 0 or (self.max_travel is not None and self.max_travel <= 0):
            raise HomingError("homing max_travel and timeout_s must be > 0")
        return spec


class HomingPhase(IntEnum):
    SEARCH = 1  # looking for the reference signal (6099:01)
    APPROACH = 2  # reversed on the reference edge; crossing it again in the final direction
    INDEX = 3  # past the reference edge; looking for the first index pulse (6099:02)
    RETURN = 4  # home point found: decelerate and move back onto it
    COMPLETED = 5  # at rest on the home point (or halted after finding it)
    INTERRUPTED = 6  # halted before the home point was found
    FAILED = 7  # homing error


_SEARCHING = (HomingPhase.SEARCH, HomingPhase.APPROACH, HomingPhase.INDEX)

#: the switches a search reads, without / with the home switch (the limits always)
_SIGNALS_READ = (
    (Signal.NEGATIVE_LIMIT, Signal.POSITIVE_LIMIT),
    (Signal.HOME_SWITCH, Signal.NEGATIVE_LIMIT, Signal.POSITIVE_LIMIT),
)
#: 60FDh bits of the switches a search reads (bit n = :class:`Signal` n)
SWITCH_BITS = 0b111
#: (bits forced on, bits forced off) of 60FDh: nothing forced
NOT_FORCED: tuple[int, int] = (0, 0)


def _not_forced() -> tuple[int, int]:
    return NOT_FORCED


# event kinds inside one cycle
_EV_INDEX, _EV_NL, _EV_PL, _EV_HS = 0, 1, 2, 3
_EV_OF_SIGNAL = {
    Signal.NEGATIVE_LIMIT: _EV_NL,
    Signal.POSITIVE_LIMIT: _EV_PL,
    Signal.HOME_SWITCH: _EV_HS,
}
#: the direction of travel that runs into each limit
_LIMIT_DIR = {_EV_NL: -1, _EV_PL: 1}


class Homing:
    """One homing procedure, from CW4 rising to done (see the module docstring)."""

    def __init__(
        self,
        params: HomingParams,
        machine: AxisMachine,
        start_pos: float,
        forced: Callable[[], tuple[int, int]] | None = None,
    ) -> None:
        """``forced``: the 60FDh bits the field forces on and off now (the drive's
        :meth:`~gtecat.drives.drive.Channel.forced_switches`; module docstring)."""
        self.params = params
        self._spec = spec = params.validate()
        self._m = machine
        self._hs = merge_windows(machine.home_switch)
        self._forced_now = forced or _not_forced
        #: the forced masks at the last sample scanned (``_last``)
        self._forced = self._read_forced()
        self._edge_sampled = False  # the reference edge found on the way out was a sampled one
        self._p = float(start_pos)  # demanded position (end of the last cycle)
        self._v = 0.0  # demanded velocity
        self._last = float(start_pos)  # actual position at the last step
        self._acc = float(params.acceleration)
        self._dir = spec.final_dir  # commanded direction of travel
        self._edge: float | None = None  # reference edge found on the way out
        self._index_from = float(start_pos)
        self._reversed = False
        self._travel = 0.0
        self._elapsed = 0.0
        self._rest_time = 0.0
        self._stopping = False
        self._settled = False
        self.reason: str | None = None  # why homing failed (SW13), for the GT last error
        self.home_machine_position: float | None = None
        self.attained = False
        self.error = False
        self.phase = HomingPhase.SEARCH

        if spec.kind is MethodKind.CURRENT_POSITION:
            self._found(float(start_pos))
            self.phase = HomingPhase.COMPLETED
            self._settled = True
            return

        self._max_travel = (
            self._default_max_travel() if params.max_travel is None else float(params.max_travel)
        )
        #: what the search needs that the machine description lacks (None: nothing); the
        #: search still runs (a real drive would too) and fails at its travel limit
        self.missing = self._missing_signal()
        if spec.kind is MethodKind.INDEX_ONLY:
            self.phase = HomingPhase.INDEX
        else:
            assert spec.signal is not None
            self._dir = spec.initial_direction(self._signal_level(spec.signal, start_pos))
        # starting inside the limit switch that lies ahead
        ahead = Signal.POSITIVE_LIMIT if self._dir > 0 else Signal.NEGATIVE_LIMIT
        if ahead != spec.signal and self._signal_level(ahead, start_pos):
            if self.phase is HomingPhase.SEARCH and ahead == spec.reversal_limit:
                self._dir = -self._dir
                self._reversed = True
            else:
                self._fail(f"started on the {ahead.name.lower().replace('_', ' ')} switch")
                self._settled = True

    # --- public surface ----------------------------------------------------
    @property
    def done(self) -> bool:
        """The procedure is over (completed, failed or interrupted) and the axis is at rest."""
        return self.phase in (
            HomingPhase.COMPLETED,
            HomingPhase.FAILED,
            HomingPhase.INTERRUPTED,
        ) and (self._settled or self.phase is HomingPhase.COMPLETED)

    @property
    def moving(self) -> bool:
        """The axis is (still) in motion: demanded velocity non-zero or not yet settled."""
        return not self._settled

    def status_bits(self) -> tuple[bool, bool, bool]:
        """(SW10, SW12, SW13) per CiA 402 (cia402-facts §3.1 table)."""
        if self.error:
            return (self._settled, False, True)
        if self.attained:
            return (self._settled, True, False)
        if self.phase is HomingPhase.INTERRUPTED:
            return (self._settled, False, False)
        return (False, False, False)

    def encoder_offset(self) -> float | None:
        """What the drive subtracts from the machine position for 6064 once homed."""
        if self.home_machine_position is None:
            return None
        return self.home_machine_position - self.params.home_offset

    def shift_demand(self, counts: float) -> None:
        """The encoder slipped by ``counts`` (:meth:`Channel.lose_counts`): the demand, kept in
        the drive's measured frame, now lies ``counts`` further on in machine counts."""
        self._p += counts

    def halt(self, on: bool) -> None:
        """CW8: decelerate and hold; the search does not resume (module docstring)."""
        if not on or self._stopping:
            return
        if self.phase in _SEARCHING:
            self.phase = HomingPhase.INTERRUPTED
            self._stopping = True
        elif self.phase is HomingPhase.RETURN:
            self._stopping = True

    def step(self, dt_s: float, pos: float) -> float:
        """One cycle: look at the travel since the last call, return the next demand."""
        dt = dt_s if dt_s > 0.0 else 0.0
        p0, self._last = self._last, pos
        if self.phase in _SEARCHING and not self._stopping:
            self._elapsed += dt
            if pos != p0:
                self._travel += abs(pos - p0)
                forced = self._read_forced()
                self._scan(p0, pos, forced)
                self._forced = forced
            if self.phase in _SEARCHING:
                self._check_bounds(pos)
        self._move(dt)
        if self._v == 0.0 and (
            self._stopping or self.phase is not HomingPhase.RETURN or self._p == self._home
        ):
            self._rest_time += dt
            self._settled = (
                abs(pos - self._p) <= POSITION_WINDOW or self._rest_time >= SETTLE_TIME_S
            )
        else:
            self._rest_time = 0.0
            self._settled = False
        if self._settled and self.phase is HomingPhase.RETURN:
            self.phase = HomingPhase.COMPLETED
        return self._p

    # --- motion ------------------------------------------------------------
    @property
    def _home(self) -> float:
        h = self.home_machine_position
        return self._p if h is None else h

    def _move(self, dt: float) -> None:
        a_dt = self._acc * dt
        phase = self.phase
        if self._stopping or phase in (HomingPhase.FAILED, HomingPhase.COMPLETED):
            v_target = 0.0
        elif phase is HomingPhase.RETURN:
            self._p, self._v = _toward(
                self._p, self._v, self._home, self.params.speed_switch, self._acc, dt
            )
            return
        else:
            speed = (
                self.params.speed_switch
                if phase is HomingPhase.SEARCH
                else (self.params.speed_zero)
            )
            v_target = self._dir * float(speed)
        v = self._v
        if v < v_target:
            v = min(v + a_dt, v_target)
        elif v > v_target:
            v = max(v - a_dt, v_target)
        self._v = v
        self._p += v * dt

    # --- events ------------------------------------------------------------
    @property
    def forced(self) -> bool:
        """A switch the search reads was forced by the field at its last sample (the axis
        bank, which knows only the machine description's edges, leaves such a search alone)."""
        on, off = self._forced
        return bool(on | off)

    def _read_forced(self) -> tuple[int, int]:
        on, off = self._forced_now()
        return (on & SWITCH_BITS, off & SWITCH_BITS)

    def _signal_level(self, sig: Signal, pos: float, forced: tuple[int, int] | None = None) -> bool:
        """The level the drive reads (60FDh): the machine's switch at ``pos``, unless the
        field forces it (``forced`` masks, default: those of the last sample)."""
        if sig is Signal.NEGATIVE_LIMIT:
            active = self._m.negative_limit_active(pos)
        elif sig is Signal.POSITIVE_LIMIT:
            active = self._m.positive_limit_active(pos)
        else:
            active = level(self._hs, pos)
        on, off = self._forced if forced is None else forced
        bit = 1 << sig
        return bool(forced_level(bit if active else 0, on, off) & bit)

    def _scan(self, p0: float, p1: float, forced: tuple[int, int] = NOT_FORCED) -> None:
        """Handle every relevant event crossed from p0 to p1, in the order met.

        A switch forced at either sample (``self._forced`` at p0, ``forced`` at p1) is
        sampled: an edge where its level differs, placed at p1 (module docstring)."""
        spec = self._spec
        d = 1 if p1 > p0 else -1
        # (dist, prio, pos, kind, rising, sampled)
        events: list[tuple[float, int, float, int, bool, bool]] = []
        prev = self._forced
        sampled = prev[0] | prev[1] | forced[0] | forced[1]
        if sampled:
            for sig in _SIGNALS_READ[spec.signal is Signal.HOME_SWITCH]:
                if not sampled & (1 << sig):
                    continue
                now = self._signal_level(sig, p1, forced)
                kind = _EV_OF_SIGNAL[sig]
                if now != self._signal_level(sig, p0, prev):
                    events.append((abs(p1 - p0), 1, p1, kind, now, True))
                elif now and _LIMIT_DIR.get(kind) == d:
                    # a limit is a level: one held active ahead of the travel is met
                    # although it gave no edge (it was active behind the axis before)
                    events.append((abs(p1 - p0), 1, p1, kind, True, True))
        if spec.signal is Signal.HOME_SWITCH and not sampled & (1 << Signal.HOME_SWITCH):
            for x, rising in window_edges(self._hs, p0, p1):
                events.append((abs(x - p0), 1, x, _EV_HS, rising, False))
        nl, pl = self._m.negative_limit, self._m.positive_limit
        if nl is not None and not sampled & (1 << Signal.NEGATIVE_LIMIT):
            if d < 0 and p1 <= nl < p0:
                events.append((p0 - nl, 1, nl, _EV_NL, True, False))
            elif d > 0 and p0 <= nl < p1:
                events.append((nl - p0, 1, nl, _EV_NL, False, False))
        if pl is not None and not sampled & (1 << Signal.POSITIVE_LIMIT):
            if d > 0 and p0 < pl <= p1:
                events.append((pl - p0, 1, pl, _EV_PL, True, False))
            elif d < 0 and p1 < pl <= p0:
                events.append((p0 - pl, 1, pl, _EV_PL, False, False))
        if spec.uses_index:
            # priority 0: a pulse exactly on the reference edge is not beyond it
            for x in self._m.index_positions(p0, p1):
                events.append((abs(x - p0), 0, x, _EV_INDEX, True, False))
        if not events:
            return
        events.sort()
        for _, _, x, kind, rising, at_sample in events:
            self._on_event(kind, x, rising, d, at_sample)
            if self.phase not in _SEARCHING:
                return

    def _on_event(self, kind: int, x: float, rising: bool, d: int, sampled: bool = False) -> None:
        spec = self._spec
        fd = spec.final_dir
        if self.phase is HomingPhase.INDEX:
            if kind == _EV_INDEX:
                if d == fd and (x - self._index_from) * fd > 0:
                    self._found(x)
            elif kind in (_EV_NL, _EV_PL) and rising and d == self._dir == _LIMIT_DIR[kind]:
                self._fail(f"{_limit_name(kind)} hit while searching the index pulse")
            return
        if kind == _EV_INDEX:
            return
        if spec.signal is not None and kind == _EV_OF_SIGNAL[spec.signal]:
            if self.phase is HomingPhase.SEARCH and d != self._dir:
                return  # still braking for a limit reversal
            if d == fd and rising == spec.active_after:
                # (in APPROACH the edge left on the way out: a forced switch's edges lie
                # where it toggled, so any of its edges, or any after one, is taken)
                if (
                    self.phase is HomingPhase.SEARCH
                    or x == self._edge
                    or sampled
                    or self._edge_sampled
                ):
                    self._reference(x)
            elif d == -fd and rising != spec.active_after and self.phase is HomingPhase.SEARCH:
                self._edge = x
                self._edge_sampled = sampled
                self.phase = HomingPhase.APPROACH
                self._dir = fd
            return
        if kind in (_EV_NL, _EV_PL) and rising:
            if d != self._dir:
                return  # braking for a reversal already commanded
            if d != _LIMIT_DIR[kind]:
                return  # a limit behind the axis (only a forced one can rise there)
            lim = Signal.NEGATIVE_LIMIT if kind == _EV_NL else Signal.POSITIVE_LIMIT
            if (
                self.phase is HomingPhase.SEARCH
                and lim == spec.reversal_limit
                and not self._reversed
            ):
                self._reversed = True
                self._dir = -self._dir
                return
            why = "again" if lim == spec.reversal_limit else "(method does not reverse on it)"
            self._fail(f"{_limit_name(kind)} hit {why}: home switch not found")

    def _reference(self, x: float) -> None:
        if self._spec.uses_index:
            self.phase = HomingPhase.INDEX
            self._index_from = x
            self._dir = self._spec.final_dir
        else:
            self._found(x)

    def _found(self, x: float) -> None:
        self.home_machine_position = x
        self.attained = True
        self.phase = HomingPhase.RETURN

    def _fail(self, reason: str) -> None:
        self.error = True
        self.reason = f"homing method {self._spec.number}: {reason}"
        self.phase = HomingPhase.FAILED
        self._stopping = True

    def _check_bounds(self, pos: float) -> None:
        if self.phase is HomingPhase.INDEX:
            cpr = self._m.counts_per_rev
            if (pos - self._index_from) * self._spec.final_dir > cpr + 0.5:
                self._fail("no index pulse within one revolution")
                return
        if self._travel > self._max_travel:
            self._fail(f"search travel exceeded {self._max_travel:.0f} counts")
        elif self._elapsed > self.params.timeout_s:
            self._fail(f"search took longer than {self.params.timeout_s:g} s")

    def _missing_signal(self) -> str | None:
        spec, m = self._spec, self._m
        need = []
        if spec.signal is Signal.HOME_SWITCH and not m.home_switch:
            need.append("a home switch (home_switch)")
        if spec.signal is Signal.NEGATIVE_LIMIT and m.negative_limit is None:
            need.append("a negative limit switch (negative_limit)")
        if spec.signal is Signal.POSITIVE_LIMIT and m.positive_limit is None:
            need.append("a positive limit switch (positive_limit)")
        if spec.uses_index and m.index_offset is None:
            need.append("an index pulse (index_offset)")
        if not need:
            return None
        return (
            f"homing method {spec.number} searches for {' and '.join(need)}, but the machine "
            "description gives this axis none, so the search cannot find it; it ends only "
            f"after {self._max_travel:.0f} counts of travel (set the key in [axis.N] of the "
            "machine TOML, or choose a method that needs no switch, e.g. 35/37)"
        )

    def _default_max_travel(self) -> float:
        p = self.params
        brake = float(p.speed_switch) ** 2 / (2.0 * self._acc)
        cpr = float(self._m.counts_per_rev)
        nl, pl = self._m.negative_limit, self._m.positive_limit
        if nl is None or pl is None:
            return 1000.0 * cpr + 4.0 * brake
        outside = max(nl - self._p, self._p - pl, 0.0)
        return 3.0 * (pl - nl) + 2.0 * outside + 4.0 * brake + 2.0 * cpr


def _limit_name(kind: int) -> str:
    return "negative limit switch" if kind == _EV_NL else "positive limit switch"


def _toward(
    p: float, v: float, target: float, vmax: float, a: float, dt: float
) -> tuple[float, float]:
    """One cycle of a move onto ``target`` (ramp ``a``, top speed ``vmax``), stopping exactly.

    The speed is capped by the fastest speed from which stopping within the remaining
    distance is still possible when the speed drops by ``a*dt`` per cycle.
    """
    if dt <= 0.0:
        return p, v
    d = target - p
    a_dt = a * dt
    if abs(d) <= 1e-9 and abs(v) <= a_dt:
        return target, 0.0
    s = 1.0 if d > 0 else -1.0
    half = 0.5 * a_dt
    v_stop = math.sqrt(half * half + 2.0 * a * abs(d)) - half
    v_des = s * min(float(vmax), v_stop)
    v_new = v + max(-a_dt, min(a_dt, v_des - v))
    step = v_new * dt
    if step * s >= abs(d):
        return target, 0.0
    return p + step, v_new
