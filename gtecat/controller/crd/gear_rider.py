"""The planner of an axis that a coordinate system carries along (GT_BufGear).

The system sets where the axis must be each cycle (:meth:`GearRider.follow`: its start
plus the share of the segment done times the distance); the planner gives that position,
its velocity and acceleration.  At the segment's end (or when the path stops) the ride is
over: the planner is at rest and ``on_done`` runs (the GT layer hands the profile back to
Trap mode there).
"""

from __future__ import annotations

from collections.abc import Callable

from ..motion.stop import StopKind


class GearRider:
    __slots__ = (
        "_acc",
        "_cyc",
        "_done",
        "_ending",
        "_pos",
        "_target",
        "_vel",
        "on_done",
        "saved",
        "stopping",
    )

    def __init__(self, cycle_ms: float, pos: float, on_done: Callable[[], None]) -> None:
        self._cyc = cycle_ms
        self._pos = self._target = pos
        self._vel = self._acc = 0.0
        self._done = False
        self._ending = False
        self.on_done = on_done
        #: the profile's own Gear planner while the ride borrows the mode (None: none)
        self.saved: object = None
        self.stopping = StopKind.NONE

    @property
    def done(self) -> bool:
        return self._done

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
    def target(self) -> float:
        return self._target

    @property
    def ending(self) -> bool:
        """Told its last position: a ride that ends this cycle (the next one may take over)."""
        return self._ending and not self._done

    def follow(self, target: float, last: bool) -> None:
        self._target = target
        self._ending = last
        self._done = False

    def step(self) -> tuple[float, float, float]:
        if not self._done:
            v = (self._target - self._pos) / self._cyc
            self._acc = (v - self._vel) / self._cyc
            self._pos, self._vel = self._target, v
            if self._ending:
                self._done = True
                self._vel = self._acc = 0.0
                self.on_done()
        return self._pos, self._vel, self._acc

    def stop(self, dec: float, abrupt: bool = False, origin: tuple[float, float] | None = None):
        """The path decides: a GT_Stop of the axis ends the ride where it is."""
        self._target = self._pos
        self._ending = True

    def hold(self, pos: float) -> None:
        self._pos = self._target = pos
        self._vel = self._acc = 0.0
        self._done = True
