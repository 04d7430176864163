"""The ``Ex`` forms of the buffered lines and arcs, and ``GT_BufGear``.

The vendor's GTN header gives every line and arc an ``Ex`` form for its look-ahead
(``GT_InitLookAheadEx``): double coordinates, a user segment number and a second
override flag instead of an end speed.  Decisions (the header says no more):

* Coordinates are pulses as doubles and are kept as given (no rounding): a path of
  fractional points is followed as written.  After ``GT_InitLookAheadEx`` on the FIFO
  they are the user's units instead (mm: coordinates times ``scale[k]``, ``synVel`` in
  units/s, ``synAcc`` in units/s², as the vendor's samples use them;
  :mod:`gtecat.gt.look_ahead_ex_calls`).
* There is no ``velEnd``: a segment ends at the speed the look-ahead allows
  (``GT_InitLookAhead`` on the FIFO), else at 0 - the non-``Ex`` forms' default.
  The ``G0Ex`` forms end at 0 like ``GT_LnXYG0``.
* ``segNum`` (any ``long``) is the application's own label of the segment; it is
  checked and kept with nothing that reads it back here.  ``override2`` (0 or 1) picks
  the second override of the vendor's firmware, which the emulation does not have: both
  values run at ``GT_SetOverride``'s ratio.
* ``GT_CrdDataEx`` is ``GT_CrdData``: NULL flushes (nothing is held back), a segment
  given as ``TCrdData`` is 1.

``GT_BufGear(crd, gearAxis, pos, fifo)``: when the path reaches this entry, axis
``gearAxis`` (not one of the system's) moves ``pos`` pulses (relative) during the next
motion segment, starting and ending with it, its position in proportion to the share of
the segment's length done.  Several BufGear entries before one segment move several
axes.  During the ride the axis's profile is in Gear mode (``GT_GetPrfMode`` 3); at the
segment's end it is back in Trap mode where it stands.  An axis that is moving when the
ride should begin is left alone (a master-log line says so).  A stop of the path ends
the ride where the axis is.  ``GT_BufGearEx`` is the same with a double distance.
"""

from __future__ import annotations

from typing import Any

from ..controller.core import Controller
from ..controller.crd.gear_rider import GearRider
from ..controller.crd.path import PLANES
from ..controller.crd.system import BufGear
from ..controller.profile import PrfMode
from ..controller.resources import axis_resources
from ..errors import ParameterError
from ._core import gt_function
from .buffered_calls import GT_CrdData
from .crd_calls import _crd, _push_arc, _push_line, _real


def _ex(segNum: Any, override2: Any) -> None:
    int(segNum)  # checked by the table (long)
    if int(override2) not in (0, 1):
        raise ParameterError(f"override2={override2}: 0 or 1")


def _units(c, fifo: Any, synVel: Any, synAcc: Any):
    """The FIFO's pulses per user unit (None: pulses) and the speed and acceleration in
    pulse/ms and pulse/ms² (``GT_InitLookAheadEx``: :mod:`gtecat.gt.look_ahead_ex_calls`)."""
    la = c.look[int(fifo)] if int(fifo) in (0, 1) else None
    unit = la.unit if la is not None else None
    v, a = _real("synVel", synVel), _real("synAcc", synAcc)
    if unit is None:
        return None, v, a
    v, a = v * unit[0] / 1e3, a * unit[0] / 1e6
    if la.vel_max is not None and v > la.vel_max:
        v = la.vel_max
    return unit, v, a


def _scale(unit, k: int) -> float:
    return unit[k] if unit is not None and k < len(unit) else 1.0


def _line(ctl, crd, what, values, synVel, synAcc, segNum, override2, fifo, g0=False) -> int:
    _ex(segNum, override2)
    c = _crd(ctl, crd)
    unit, synVel, synAcc = _units(c, fifo, synVel, synAcc)
    vals = {k: _real(f"coordinate {k + 1}", v) * _scale(unit, k) for k, v in values.items()}
    return _push_line(c, what, fifo, vals, synVel, synAcc, 0.0)


@gt_function
def GT_LnXYEx(ctl, crd, x, y, synVel, synAcc, segNum, override2, fifo=0) -> int:
    """Line to (x, y), double coordinates."""
    return _line(ctl, crd, "GT_LnXYEx", {0: x, 1: y}, synVel, synAcc, segNum, override2, fifo)


@gt_function
def GT_LnXYG0Ex(ctl, crd, x, y, synVel, synAcc, segNum, override2, fifo=0) -> int:
    """Rapid line to (x, y): it stops at its end."""
    return _line(ctl, crd, "GT_LnXYG0Ex", {0: x, 1: y}, synVel, synAcc, segNum, override2, fifo)


@gt_function
def GT_LnXYZEx(ctl, crd, x, y, z, synVel, synAcc, segNum, override2, fifo=0) -> int:
    v = {0: x, 1: y, 2: z}
    return _line(ctl, crd, "GT_LnXYZEx", v, synVel, synAcc, segNum, override2, fifo)


@gt_function
def GT_LnXYZG0Ex(ctl, crd, x, y, z, synVel, synAcc, segNum, override2, fifo=0) -> int:
    v = {0: x, 1: y, 2: z}
    return _line(ctl, crd, "GT_LnXYZG0Ex", v, synVel, synAcc, segNum, override2, fifo)


@gt_function
def GT_LnXYZAEx(ctl, crd, x, y, z, aPos, synVel, synAcc, segNum, override2, fifo=0) -> int:
    v = {0: x, 1: y, 2: z, 3: aPos}
    return _line(ctl, crd, "GT_LnXYZAEx", v, synVel, synAcc, segNum, override2, fifo)


@gt_function
def GT_LnXYZAG0Ex(ctl, crd, x, y, z, aPos, synVel, synAcc, segNum, override2, fifo=0) -> int:
    v = {0: x, 1: y, 2: z, 3: aPos}
    return _line(ctl, crd, "GT_LnXYZAG0Ex", v, synVel, synAcc, segNum, override2, fifo)


def _arc(ctl, crd, what, plane, a, b, d, synVel, synAcc, segNum, override2, fifo, **kw) -> int:
    _ex(segNum, override2)
    c = _crd(ctl, crd)
    unit, synVel, synAcc = _units(c, fifo, synVel, synAcc)
    i, j = PLANES[plane]
    a, b = _real("end", a) * _scale(unit, i), _real("end", b) * _scale(unit, j)
    if unit is not None:
        if kw.get("radius") is not None:
            kw["radius"] = _real("radius", kw["radius"]) * _scale(unit, i)
        if kw.get("center") is not None:
            ca, cb = kw["center"]
            kw["center"] = (
                _real("center", ca) * _scale(unit, i),
                _real("center", cb) * _scale(unit, j),
            )
    return _push_arc(c, what, fifo, plane, a, b, synVel, synAcc, 0.0, d, **kw)


@gt_function
def GT_ArcXYREx(ctl, crd, x, y, radius, circleDir, synVel, synAcc, segNum, override2, fifo=0):
    """Arc to (x, y) of ``radius`` (> 0 at most 180 degrees); circleDir 0 cw, 1 ccw."""
    return _arc(
        ctl, crd, "GT_ArcXYREx", "XY", x, y, circleDir, synVel, synAcc, segNum, override2,
        fifo, radius=radius,
    )  # fmt: skip


@gt_function
def GT_ArcXYCEx(
    ctl, crd, x, y, xCenter, yCenter, circleDir, synVel, synAcc, segNum, override2, fifo=0
):
    """Arc to (x, y) around the centre (xCenter, yCenter) relative to the start point."""
    return _arc(
        ctl, crd, "GT_ArcXYCEx", "XY", x, y, circleDir, synVel, synAcc, segNum, override2,
        fifo, center=(xCenter, yCenter),
    )  # fmt: skip


@gt_function
def GT_ArcYZREx(ctl, crd, y, z, radius, circleDir, synVel, synAcc, segNum, override2, fifo=0):
    return _arc(
        ctl, crd, "GT_ArcYZREx", "YZ", y, z, circleDir, synVel, synAcc, segNum, override2,
        fifo, radius=radius,
    )  # fmt: skip


@gt_function
def GT_ArcYZCEx(
    ctl, crd, y, z, yCenter, zCenter, circleDir, synVel, synAcc, segNum, override2, fifo=0
):
    return _arc(
        ctl, crd, "GT_ArcYZCEx", "YZ", y, z, circleDir, synVel, synAcc, segNum, override2,
        fifo, center=(yCenter, zCenter),
    )  # fmt: skip


@gt_function
def GT_ArcZXREx(ctl, crd, z, x, radius, circleDir, synVel, synAcc, segNum, override2, fifo=0):
    return _arc(
        ctl, crd, "GT_ArcZXREx", "ZX", z, x, circleDir, synVel, synAcc, segNum, override2,
        fifo, radius=radius,
    )  # fmt: skip


@gt_function
def GT_ArcZXCEx(
    ctl, crd, z, x, zCenter, xCenter, circleDir, synVel, synAcc, segNum, override2, fifo=0
):
    return _arc(
        ctl, crd, "GT_ArcZXCEx", "ZX", z, x, circleDir, synVel, synAcc, segNum, override2,
        fifo, center=(zCenter, xCenter),
    )  # fmt: skip


@gt_function
def GT_CrdDataEx(ctl: Controller, crd: int, pCrdData: Any = None, fifo: int = 0) -> int:
    """``GT_CrdData``: NULL flushes the look-ahead (nothing is held back here)."""
    return GT_CrdData.__wrapped__(ctl, crd, pCrdData, fifo)


def _buf_gear(ctl: Controller, crd: int, gearAxis: int, delta: float, fifo: int, what: str) -> int:
    c = _crd(ctl, crd)
    prm = c.require_prm(what)
    res = axis_resources(ctl, gearAxis)
    if res.number in prm.axes():
        raise ParameterError(f"gearAxis={gearAxis} belongs to coordinate system {c.number}")

    def start():
        state: dict[str, Any] = {}

        def back_to_trap() -> None:
            rider = state["rider"]
            planners = res.profile.planners
            if rider.saved is None:
                planners.pop(PrfMode.GEAR, None)
            else:
                planners[PrfMode.GEAR] = rider.saved  # the axis's own Gear mode is kept
            res.profile.enter(PrfMode.TRAP)

        def follow(fraction: float | None) -> None:
            rider = state.get("rider")
            if fraction is None:
                if rider is not None and not rider.done:
                    rider.stop(0.0)
                return
            if rider is None:
                if state.get("skipped"):
                    return
                cur = res.profile.planner
                if isinstance(cur, GearRider) and cur.ending:  # the ride before ends now
                    rider, state["start"] = cur, cur.target
                    rider.on_done = back_to_trap
                elif res.moving:
                    state["skipped"] = True
                    ctl.log(f"{what} (coordinate system {c.number}): axis {res.number} is moving")
                    return
                else:
                    saved = res.profile.planners.get(PrfMode.GEAR)
                    rider = GearRider(res.cycle_ms, res.profile.planner.pos, back_to_trap)
                    res.profile.enter(PrfMode.GEAR, planner=rider)
                    rider.saved, state["start"] = saved, rider.pos
                state["rider"] = rider
            rider.follow(state["start"] + delta * fraction, fraction >= 1.0)

        return follow

    c.push(BufGear(res.number, delta, start), int(fifo))
    return 0


@gt_function
def GT_BufGear(ctl: Controller, crd: int, gearAxis: int, pos: int, fifo: int = 0) -> int:
    """Axis ``gearAxis`` moves ``pos`` pulses with the next segment of the path."""
    return _buf_gear(ctl, crd, gearAxis, float(pos), fifo, "GT_BufGear")


@gt_function
def GT_BufGearEx(ctl: Controller, crd: int, gearAxis: int, deltaPos: float, fifo: int = 0) -> int:
    """``GT_BufGear`` with a double distance."""
    return _buf_gear(ctl, crd, gearAxis, _real("deltaPos", deltaPos), fifo, "GT_BufGearEx")
