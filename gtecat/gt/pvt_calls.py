"""PVT motion: ``GT_PrfPvt``, tables, ``GT_PvtTableSelect``, ``GT_PvtStart`` and the status.

Decisions where the vendor header says no more (its manual of the advanced functions
is not public):

* Tables are the controller's (1..32, shared by every profile), 2..1024 points each; the
  times (ms) rise strictly, by :data:`MIN_STEP_MS` at least; positions are pulses,
  velocities pulse/ms, every value within ±:data:`VALUE_LIMIT` (beyond both, the cubics'
  velocities and accelerations leave the doubles' range: code 7 with the reason, never an
  internal error while the table runs).  Between two
  points the position is the cubic that meets both points' positions and velocities.
* ``GT_PvtTable(tableId, count, pTime, pPos, pVel)``: each point has one velocity.
  ``GT_PvtTableEx(..., pVelBegin, pVelEnd)``: segment ``k`` (point ``k`` to ``k+1``) starts at
  ``pVelBegin[k]`` and ends at ``pVelEnd[k]`` (the last elements are not used).
  ``GT_PvtTableComplete(..., pA, pB, pC, velBegin, velEnd)``: the velocities are those of
  the clamped cubic spline through the points (continuous acceleration), starting at
  ``velBegin`` and ending at ``velEnd``; it writes back, for each point ``k``, ``pA[k]``
  its velocity (pulse/ms), ``pB[k]`` half the acceleration and ``pC[k]`` a sixth of the jerk
  of the segment that starts there (0 for the last point): the segment's position is
  ``pos[k] + pA[k]·τ + pB[k]·τ² + pC[k]·τ³`` (τ ms after ``pTime[k]``).
* A table written while a profile runs it takes effect at that profile's next start; a
  table may be rewritten at any time (``GT_PvtTableClear`` empties it).  Each core holds its
  own tables (``GTN_PvtTable(2, 1, ...)`` is core 2's table 1, the profiles of core 2 run it).
* The motion is relative: the table's first point is where the profile stands at
  ``GT_PvtStart``; the profile runs its table from the first point's time to the last's.
  ``GT_SetPvtLoop(profile, loop)``: passes (0 endless, default 1), each from where the
  last ended.  ``GT_GetPvtLoop`` gives the passes completed and the setting.
* ``GT_PvtStatus(profile, pTableId, pTime, count)``: the table selected and the table time
  (ms) of the current pass (0 at rest), for ``count`` profiles from ``profile``.
* ``GT_PvtStart(mask)``: every profile of the mask must be in PVT mode with a table that
  holds data and able to move (the checks of ``GT_Update``); all or nothing (1).  An
  endless loop over a table lasting less than half a controller cycle is refused (1), at
  the start or by ``GT_SetPvtLoop(profile, 0)`` while it runs: each cycle's passes would
  never end.
"""

from __future__ import annotations

from typing import Any

from .._attrs import PerObject
from ..controller.bank_pvt import now as banked_now
from ..controller.core import Controller
from ..controller.motion.pvt import PvtPlanner, PvtSegment, never_ends
from ..controller.profile import PrfMode
from ..controller.resources import axis_resources, axis_span
from ..errors import CommandError, ParameterError
from ._core import check_range, gt_function, store, store_array
from .motion_ext_calls import _long, _mask_axes, _planner, _require_free

TABLES = 32
POINTS = 1024
#: the shortest time between two points of a table (ms): a nanosecond, far below any
#: controller cycle, and long enough that a segment's acceleration stays a finite double
MIN_STEP_MS = 1e-6
#: the largest magnitude of a table value (time, position, velocity): 2^40 pulses is
#: beyond any 32-bit position the controller reports
VALUE_LIMIT = float(2**40)
#: per controller, per core, per table id: its segments
_TABLES: PerObject[dict[int, dict[int, tuple[PvtSegment, ...]]]] = PerObject("pvt_tables")


def _tables(ctl: Controller) -> dict[int, tuple[PvtSegment, ...]]:
    """The tables of the call's core: each core of a multi-core controller holds its own
    (GTN_PvtTable(2, 1, ...) is core 2's table 1, not core 1's), core views of one bus
    included; GT_Reset empties every core's."""
    base = getattr(ctl, "_base", ctl)
    cores = _TABLES.get(base)
    if cores is None:
        cores = _TABLES[base] = {}
        base.on_reset.append(lambda c: cores.clear())
    core = getattr(ctl, "core", 1) if base is not ctl else 1
    t = cores.get(core)
    if t is None:
        t = cores[core] = {}
    return t


def _points(count: int, *arrays: Any) -> list[list[float]]:
    n = check_range("count", count, 2, POINTS)
    out = []
    for ref in arrays:
        if ref is None:
            raise ParameterError("a table array is NULL")
        vals = [float(v) for v in ref.load_values(n)]
        if any(v != v or v in (float("inf"), float("-inf")) for v in vals):
            raise ParameterError("a table value is not a finite number")
        if any(abs(v) > VALUE_LIMIT for v in vals):
            raise ParameterError(f"a table value is beyond ±{VALUE_LIMIT:.0f}")
        out.append(vals)
    t = out[0]
    for k in range(1, n):
        if t[k] - t[k - 1] < MIN_STEP_MS:
            raise ParameterError(
                f"pTime[{k}]={t[k]} is not {MIN_STEP_MS:g} ms or more after "
                f"pTime[{k - 1}]={t[k - 1]}"
            )
    return out


def _store(ctl: Controller, tableId: int, t, p, v0, v1) -> None:
    segs = tuple(
        PvtSegment(t[k], t[k + 1], p[k], p[k + 1], v0[k], v1[k]) for k in range(len(t) - 1)
    )
    _tables(ctl)[int(tableId)] = segs


@gt_function
def GT_PvtTable(ctl: Controller, tableId: int, count: int, pTime: Any, pPos: Any, pVel: Any):
    """Points with one velocity each: time (ms), position (pulse), velocity (pulse/ms)."""
    t, p, v = _points(count, pTime, pPos, pVel)
    _store(ctl, tableId, t, p, v[:-1], v[1:])
    return 0


@gt_function
def GT_PvtTableEx(
    ctl: Controller, tableId: int, count: int, pTime: Any, pPos: Any, pVelBegin: Any, pVelEnd: Any
) -> int:
    """Segment ``k`` starts at ``pVelBegin[k]`` and ends at ``pVelEnd[k]``."""
    t, p, vb, ve = _points(count, pTime, pPos, pVelBegin, pVelEnd)
    _store(ctl, tableId, t, p, vb[:-1], ve[:-1])
    return 0


def _spline_velocities(t: list[float], p: list[float], vb: float, ve: float) -> list[float]:
    """Clamped cubic spline: the point velocities that make the acceleration continuous."""
    n = len(t)
    v = [0.0] * n
    v[0], v[-1] = vb, ve
    m = n - 2
    if m <= 0:
        return v
    h = [t[k + 1] - t[k] for k in range(n - 1)]
    a = [0.0] * m  # sub-diagonal
    b = [0.0] * m
    c = [0.0] * m
    d = [0.0] * m
    for j in range(m):
        i = j + 1
        a[j], c[j] = 1 / h[i - 1], 1 / h[i]
        b[j] = 2 * (a[j] + c[j])
        d[j] = 3 * ((p[i] - p[i - 1]) / h[i - 1] ** 2 + (p[i + 1] - p[i]) / h[i] ** 2)
    d[0] -= a[0] * vb
    d[-1] -= c[-1] * ve
    for j in range(1, m):  # Thomas algorithm
        w = a[j] / b[j - 1]
        b[j] -= w * c[j - 1]
        d[j] -= w * d[j - 1]
    x = [0.0] * m
    x[-1] = d[-1] / b[-1]
    for j in range(m - 2, -1, -1):
        x[j] = (d[j] - c[j] * x[j + 1]) / b[j]
    v[1:-1] = x
    return v


@gt_function
def GT_PvtTableComplete(
    ctl: Controller,
    tableId: int,
    count: int,
    pTime: Any,
    pPos: Any,
    pA: Any,
    pB: Any,
    pC: Any,
    velBegin: float = 0.0,
    velEnd: float = 0.0,
) -> int:
    """Points with the velocities of a clamped cubic spline (module docstring)."""
    t, p = _points(count, pTime, pPos)
    v = _spline_velocities(t, p, float(velBegin), float(velEnd))
    _store(ctl, tableId, t, p, v[:-1], v[1:])
    b2, c3 = [], []
    for k in range(len(t) - 1):
        h = t[k + 1] - t[k]
        dp = p[k + 1] - p[k]
        b2.append((3 * dp / h - 2 * v[k] - v[k + 1]) / h)
        c3.append((-2 * dp / h + v[k] + v[k + 1]) / (h * h))
    store_array(pA, v)
    store_array(pB, [*b2, 0.0])
    store_array(pC, [*c3, 0.0])
    return 0


@gt_function
def GT_PvtTableClear(ctl: Controller, tableId: int) -> int:
    _tables(ctl).pop(int(tableId), None)
    return 0


@gt_function
def GT_PrfPvt(ctl: Controller, profile: int) -> int:
    """PVT mode (the profile must stand still)."""
    res = axis_resources(ctl, profile)
    _require_free(res, "GT_PrfPvt")
    if res.profile.mode != PrfMode.PVT:
        p = res.profile
        p.enter(PrfMode.PVT, factory=lambda: PvtPlanner(res.cycle_ms, p.pos))
    return 0


def _pvt(ctl: Controller, profile: int, what: str) -> PvtPlanner:
    return _planner(axis_resources(ctl, profile), what, PrfMode.PVT, PvtPlanner)


@gt_function
def GT_PvtTableSelect(ctl: Controller, profile: int, tableId: int) -> int:
    pl = _pvt(ctl, profile, "GT_PvtTableSelect")
    if pl.stopping or not pl.done:
        raise CommandError(f"GT_PvtTableSelect: profile {profile} is moving")
    pl.table_id = int(tableId)
    return 0


@gt_function
def GT_SetPvtLoop(ctl: Controller, profile: int, loop: int) -> int:
    """Passes of the table, 0 = endless."""
    pl = _pvt(ctl, profile, "GT_SetPvtLoop")
    n = _long("loop", loop)
    if n < 0:
        raise ParameterError(f"loop={n}: 0 (endless) or more")
    if not pl.done and never_ends(pl._segs, n, pl._T):
        raise CommandError(
            f"GT_SetPvtLoop: profile {profile} runs a table lasting less than half a "
            "controller cycle: endless passes of it would never end a cycle"
        )
    pl.loop = n
    return 0


@gt_function
def GT_GetPvtLoop(ctl: Controller, profile: int, pLoopCount: Any, pLoop: Any) -> int:
    res = axis_resources(ctl, profile)
    pl = _planner(res, "GT_GetPvtLoop", PrfMode.PVT, PvtPlanner)
    got = banked_now(res, pl)  # (an axis the bank runs: read there, not given back)
    done, loop = (pl.loops_done, pl.loop) if got is None else got[2:]
    store(pLoopCount, done)
    store(pLoop, loop)
    return 0


@gt_function
def GT_PvtStatus(ctl: Controller, profile: int, pTableId: Any, pTime: Any, count: int = 1) -> int:
    """The selected table and the table time of the current pass, per profile."""
    span = axis_span(ctl, profile, count)
    ids, times = [], []
    for res in span:
        pl = res.profile.planner if res is not None else None
        # (the planner's type, not isinstance: that reads a guarded Trap or Gear planner's
        # __class__, which gives its axis back)
        if res is not None and res.profile.mode == PrfMode.PVT and PvtPlanner in type(pl).__mro__:
            got = banked_now(res, pl)  # (an axis the bank runs: read there, not given back)
            ids.append(pl.table_id if got is None else got[0])
            times.append(pl.time if got is None else got[1])
        else:
            ids.append(0)
            times.append(0.0)
    store(pTableId, ids[0])
    store_array(pTime, times)
    return 0


@gt_function
def GT_PvtStart(ctl: Controller, mask: int) -> int:
    """Start the profiles of ``mask`` on their selected tables, together."""
    plan = []
    tables = _tables(ctl)
    for res in _mask_axes(ctl, mask, "GT_PvtStart"):
        what = f"GT_PvtStart (axis {res.number})"
        pl = _planner(res, what, PrfMode.PVT, PvtPlanner)
        if not pl.done:
            raise CommandError(f"{what}: the profile is moving; call GT_Stop first")
        segs = tables.get(pl.table_id, ())
        if not segs:
            raise CommandError(
                f"{what}: table {pl.table_id} holds no data (GT_PvtTable, GT_PvtTableSelect)"
            )
        if never_ends(segs, pl.loop, res.cycle_ms):
            raise CommandError(
                f"{what}: table {pl.table_id} lasts less than half a controller cycle "
                f"({res.cycle_ms:g} ms) and the loop is endless (GT_SetPvtLoop 0): its passes "
                "would never end a cycle"
            )
        res.check_motion(what, segs[0].p1 - segs[0].p0)
        plan.append((pl, segs))
    for pl, segs in plan:
        pl.start(pl.table_id, segs)
    return 0
