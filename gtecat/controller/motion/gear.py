"""Electronic gear planner: manual 7.5, GT_PrfGear, GT_SetGearMaster / GT_GetGearMaster,
GT_SetGearRatio / GT_GetGearRatio, GT_GearStart.

Model (what an independent computation must reproduce)
------------------------------------------------------
* **Ratio.** ``GT_SetGearRatio(masterEven, slaveEven, masterSlope)``: while the
  master moves ``masterEven`` the slave moves ``slaveEven`` (example 7-5:
  ``2, 1`` = master speed : slave speed = 2 : 1), so the slave follows
  ``ratio = slaveEven / masterEven`` times each master increment.
* **Clutch zone** ("离合器区", figure 7-10): when the ratio changes (at
  GT_GearStart from 0, or by GT_SetGearRatio during motion from the ratio in
  effect at that moment) it goes linearly, *in master travel*, from the old
  to the new ratio over ``masterSlope`` pulses of master travel ("离合器位移是指
  从轴平滑变速过程中主轴运动的位移").  The slave therefore moves
  ``(r_old + r_new)/2 · masterSlope`` during the clutch; each cycle integrates
  the ratio exactly over the master increment (a clutch end inside a cycle is
  split there), so this holds whatever the master speed.  Master travel is
  counted as distance (a reversing master still advances the clutch).
  ``masterSlope`` 0 switches at once.
* **Direction** (GT_PrfGear ``dir``): see :mod:`gtecat.controller.motion.master`.
* **Sampling.** ``start`` samples the master; each ``step()`` reads it again,
  so a master axis numbered below the slave (stepped first by the controller)
  is followed without lag, as 7.5.2 recommends.  The output velocity is the
  slave increment of the cycle divided by ``cycle_ms``, the acceleration the
  change of that velocity.  A gear never ends by itself; GT_Stop hands over to
  :class:`~gtecat.controller.motion.stop.StopRamp`.
"""

from __future__ import annotations

from ...errors import CommandError, ParameterError
from . import checks
from .master import MasterSource, SlavePlanner, passed
from .stop import StopKind, StopRamp

_IDLE, _MOVE, _STOP = 0, 1, 2


class GearPlanner(SlavePlanner):
    """One slave profile in Gear mode."""

    MODE = "Gear"

    __slots__ = (
        "_T",
        "_acc",
        "_cl",
        "_m_prev",
        "_pos",
        "_r0",
        "_r1",
        "_ratio",
        "_stop",
        "_vel",
        "_x",
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
        self._ratio: tuple[int, int, int] | None = None
        self._r0 = self._r1 = 0.0
        self._cl = self._x = 0.0
        self._m_prev = 0.0
        self.hold(pos)

    # ------------------------------------------------------------ settings
    @property
    def ratio(self) -> tuple[int, int, int] | None:
        """GT_GetGearRatio ``(masterEven, slaveEven, masterSlope)``; None until set."""
        return self._ratio

    @property
    def ratio_now(self) -> float:
        """slave/master ratio in effect (inside a clutch zone: where the clutch is)."""
        if self._cl > 0.0:
            return self._r0 + (self._r1 - self._r0) * self._x / self._cl
        return self._r1 if self._state != _IDLE else 0.0

    @property
    def in_clutch(self) -> bool:
        return self._state == _MOVE and self._cl > 0.0

    def set_ratio(self, master_even: object, slave_even: object, master_slope: object = 0) -> None:
        """GT_SetGearRatio; during motion the new ratio is reached over a new clutch zone."""
        me = checks.integer("masterEven", master_even)
        se = checks.integer("slaveEven", slave_even)
        sl = checks.integer("masterSlope", master_slope)
        if me <= 0:
            raise ParameterError(f"masterEven must be a positive integer, got {master_even!r}")
        if sl < 0 or sl == 1:
            raise ParameterError(
                f"masterSlope must be 0 or >= 2 (chapter 13: not < 0, not 1), got {master_slope!r}"
            )
        self._ratio = (me, se, sl)
        if self._state == _MOVE:
            self._begin_clutch(self.ratio_now, se / me, float(sl))

    # ------------------------------------------------------------- motion
    @property
    def done(self) -> bool:
        return self._state == _IDLE

    @property
    def moving(self) -> bool:
        return self._state != _IDLE

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
        self._cl = self._x = 0.0
        self._state = _IDLE
        self.stopping = StopKind.NONE

    def start(self, pos: float | None = None) -> None:
        """GT_GearStart for this profile: engage from ratio 0 through the clutch zone."""
        if self._state != _IDLE:
            raise CommandError("GT_GearStart: the profile is moving; call GT_Stop first")
        if self._master is None:
            raise CommandError("GT_GearStart: no master set; call GT_SetGearMaster first")
        if self._ratio is None:
            raise CommandError("GT_GearStart: no gear ratio set; call GT_SetGearRatio first")
        if self._source is None:
            raise CommandError("GT_GearStart: the master has no position source bound")
        if pos is not None:
            self._pos = checks.real("pos", pos)
        me, se, sl = self._ratio
        self._m_prev = float(self._source())
        self._vel = self._acc = 0.0
        self._begin_clutch(0.0, se / me, float(sl))
        self._state = _MOVE
        self.stopping = StopKind.NONE

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
        self._stop.start(origin[0], origin[1], dec)
        self._pos, self._vel = origin
        self._state = _STOP
        self._cl = 0.0
        self.stopping = StopKind.ABRUPT if abrupt else StopKind.SMOOTH
        if self._stop.done:
            self._state = _IDLE
            self._vel = self._acc = 0.0

    def step(self) -> tuple[float, float, float]:
        """One controller cycle: ``(pos, vel, acc)`` in pulse, pulse/ms, pulse/ms²."""
        state = self._state
        if state == _MOVE:
            m = float(self._source())  # type: ignore[misc]
            d = passed(m - self._m_prev, self._dir)
            self._m_prev = m
            if self._cl > 0.0 and d != 0.0:
                ds = self._through_clutch(d)
            else:
                ds = self._r1 * d
            self._pos += ds
            v = ds / self._T
            self._acc = (v - self._vel) / self._T
            self._vel = v
        elif state == _STOP:
            self._pos, self._vel, self._acc = self._stop.step()
            if self._stop.done:
                self._state = _IDLE
                self._vel = self._acc = 0.0
        return self._pos, self._vel, self._acc

    def run(self, masters: list[float]) -> tuple[list[float], list[float], list[float], int]:
        """:meth:`step` once per master position of ``masters`` (the axis bank's tables), the
        same operations: the samples, and -1 (a gear never ends by itself)."""
        if self._state != _MOVE:
            return self.run_steps(masters)
        ps: list[float] = []
        vs_: list[float] = []
        as_: list[float] = []
        cyc, r1, dir_ = self._T, self._r1, self._dir
        m_prev, pos, vel = self._m_prev, self._pos, self._vel
        acc = self._acc
        for m in masters:
            m = float(m)
            d = passed(m - m_prev, dir_)
            m_prev = m
            if self._cl > 0.0 and d != 0.0:
                ds = self._through_clutch(d)
            else:
                ds = r1 * d
            pos += ds
            v = ds / cyc
            acc = (v - vel) / cyc
            vel = v
            ps.append(pos)
            vs_.append(vel)
            as_.append(acc)
        self._m_prev, self._pos, self._vel, self._acc = m_prev, pos, vel, acc
        return ps, vs_, as_, -1

    # ------------------------------------------------------------ internals
    def _begin_clutch(self, r_from: float, r_to: float, length: float) -> None:
        self._r0, self._r1 = r_from, r_to
        self._x = 0.0
        self._cl = length if r_from != r_to else 0.0

    def _through_clutch(self, d: float) -> float:
        """Slave increment for master increment ``d`` with the ratio ramping over the clutch."""
        r0, r1, span = self._r0, self._r1, self._cl
        x0 = self._x
        travel = abs(d)
        ra = r0 + (r1 - r0) * x0 / span
        if x0 + travel >= span:
            dist = (span - x0) * (ra + r1) * 0.5 + r1 * (x0 + travel - span)
            self._cl = self._x = 0.0
        else:
            x1 = x0 + travel
            dist = travel * (ra + r0 + (r1 - r0) * x1 / span) * 0.5
            self._x = x1
        return dist if d > 0.0 else -dist
