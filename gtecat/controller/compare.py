"""Position compare: outputs fired where the motion passes a list of positions.

One :class:`CompareChannel` is one compare unit of the card: a list of points (one
coordinate, or two for the 2D compare of GTS cards), the position sources it watches,
and an output.  Every cycle, after the axes have read their encoders, the unit looks at
the path the watched positions made during the cycle (a straight line from the last
cycle's values to this cycle's: the motor moves linearly within a cycle) and fires once
for every point that path reaches, in list order, within ``band`` on every coordinate.
A fast motion passes several points in one cycle: each fires, none is lost.

What firing does: the output count grows by one; a pulse output (``pulse``) stays as it
was (the pulse is shorter than a cycle), a level output toggles its level.  The point's
own output bits (``hso``/``gpo`` of the GTN structures) and segment number become the
unit's last output.

Two FIFOs feed a unit (the GTS 2D compare's double buffer): the running one is read to
its end, then the other takes over when it holds points; otherwise the unit has finished
(``done``).  Only the data is kept per unit here; the GT layer
(:mod:`gtecat.gt.compare_calls`) says what its functions mean.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from .._attrs import PerObject
from ..errors import CommandError, ParameterError

#: points one FIFO of a unit holds (the vendor header's COMPARE_DATA_MAX)
FIFO_POINTS = 4096


@dataclass(frozen=True, slots=True)
class Point:
    x: float
    y: float = 0.0
    hso: int = 0
    gpo: int = 0
    segment: int = 0


@dataclass(slots=True)
class CompareChannel:
    """One compare unit (the module docstring)."""

    dims: int = 1
    band: float = 0.0
    pulse: bool = True  #: False: a level output (toggles at each point)
    sources: tuple[Callable[[], float], ...] = ()
    fifos: tuple[deque[Point], deque[Point]] = field(default_factory=lambda: (deque(), deque()))
    active: int = 0  #: the FIFO being read
    running: bool = False
    started: bool = False  #: started at least once since the last clear
    count: int = 0  #: outputs fired
    level: int = 0
    last: Point | None = None
    #: called with the new level after a level output toggles (the output routed to a
    #: terminal: GT_SetComparePort)
    on_level: Callable[[int], None] | None = None
    received: int = 0  #: points pushed since the last clear
    sent: int = 0  #: points that fired since the last clear
    _prev: tuple[float, ...] | None = None

    # --- data ---------------------------------------------------------------------------
    def space(self, fifo: int) -> int:
        return FIFO_POINTS - len(self.fifos[fifo])

    def push(self, fifo: int, points: list[Point]) -> None:
        if fifo not in (0, 1):
            raise ParameterError(f"fifo={fifo}: 0 or 1")
        if len(points) > self.space(fifo):
            raise CommandError(
                f"compare FIFO {fifo} has room for {self.space(fifo)} points, {len(points)} given"
            )
        self.fifos[fifo].extend(points)
        self.received += len(points)

    def clear_data(self) -> None:
        for q in self.fifos:
            q.clear()
        self.active = 0

    @property
    def idle_fifo(self) -> int:
        """The FIFO that the running motion does not read (the one to fill next)."""
        return 1 - self.active if self.running else self.active

    @property
    def done(self) -> bool:
        return not self.running

    # --- run ----------------------------------------------------------------------------
    def start(self) -> None:
        if not self.sources:
            raise CommandError("the compare unit has no position source: set its parameters first")
        if not self.fifos[self.active] and self.fifos[1 - self.active]:
            self.active = 1 - self.active
        if not self.fifos[self.active]:
            raise CommandError("the compare FIFOs hold no points: push data first")
        self.running = self.started = True
        self._prev = None

    def stop(self) -> None:
        self.running = False
        self._prev = None

    def fire(self, point: Point | None = None) -> None:
        self.count += 1
        if not self.pulse:
            self.level ^= 1
            if self.on_level is not None:
                self.on_level(self.level)
        if point is not None:
            self.last = point
            self.sent += 1

    def step(self) -> None:
        if not self.running:
            return
        now = tuple(f() for f in self.sources)
        prev = self._prev if self._prev is not None else now
        self._prev = now
        q = self.fifos[self.active]
        while True:
            if not q:
                other = self.fifos[1 - self.active]
                if not other:
                    self.running = False
                    return
                self.active = 1 - self.active
                q = other
            if not _reached(q[0], prev, now, self.dims, self.band):
                return
            self.fire(q.popleft())


def _reached(p: Point, a: tuple[float, ...], b: tuple[float, ...], dims: int, band: float) -> bool:
    """Some point of the straight path a -> b lies within ``band`` of ``p`` on every
    coordinate (the intersection of each coordinate's parameter interval is not empty)."""
    lo, hi = 0.0, 1.0
    for k, target in enumerate((p.x, p.y)[:dims]):
        x0, x1 = a[k], b[k]
        d = x1 - x0
        if abs(d) < 1e-12:
            if abs(x0 - target) > band + 1e-9:
                return False
            continue
        t0, t1 = (target - band - x0) / d, (target + band - x0) / d
        if t0 > t1:
            t0, t1 = t1, t0
        lo, hi = max(lo, t0), min(hi, t1)
        if lo > hi + 1e-12:
            return False
    return True


class CompareUnits:
    """Every compare unit of one controller, by key (``("2d", chn)``, ``("pos", index)``),
    stepped once per cycle after the axes have read their inputs."""

    def __init__(self, ctl: Any) -> None:
        self.units: dict[Any, CompareChannel] = {}
        #: the GT layer's settings of each unit, by the same key (cleared with the units)
        self.settings: dict[Any, Any] = {}
        ctl.post_cycle.append(self._post)
        ctl.on_reset.append(self._reset)

    def get(self, key: Any) -> CompareChannel:
        u = self.units.get(key)
        if u is None:
            u = self.units[key] = CompareChannel()
        return u

    def _post(self, t_ns: int, dt_ns: int) -> None:
        for u in self.units.values():
            if u.running:
                u.step()

    def _reset(self, ctl: Any) -> None:
        self.units.clear()
        self.settings.clear()


_UNITS: PerObject[CompareUnits] = PerObject("compare_units")


def compare_units(ctl: Any) -> CompareUnits:
    base = getattr(ctl, "_base", ctl)
    u = _UNITS.get(base)
    if u is None:
        u = _UNITS[base] = CompareUnits(base)
    return u


__all__ = ["FIFO_POINTS", "CompareChannel", "CompareUnits", "Point", "compare_units"]
