"""GT calls of the FIFO and master/slave modes: PT (7.4), electronic gear (7.5), Follow (7.6).

Chapter 13 entries 19-24, 48-51, 53-54, 66-68, 86-87, 89, 92-95, 106-111,
119-120.  The planners (:mod:`gtecat.controller.motion.pt`, :mod:`~gtecat.controller.motion.gear`,
:mod:`~gtecat.controller.motion.follow`) hold the semantics; these wrappers put them in the
profile's mode slot (:meth:`gtecat.controller.profile.Profile.enter`), resolve a master
choice to a per-cycle position (:func:`gtecat.controller.resources.position_source`) and
turn the pointer, ``mask`` and ``option`` forms into Python.

Return 1 (with a reason), as chapter 13 lists, when:

* every call of a mode: the profile is not in that mode (call GT_PrfPt /
  GT_PrfGear / GT_PrfFollow first);
* GT_PrfPt / GT_PrfGear / GT_PrfFollow: the profile is moving, or (Gear,
  Follow) it is already in that mode with another ``dir``;
* GT_PtData / GT_FollowData: no space left in the FIFO (dynamic PT: both full);
* GT_PtClear: static, the FIFO the running motion uses; dynamic, any FIFO while
  moving.  GT_FollowClear: the running FIFO, or the target of a pending switch;
* GT_SetPtLoop: dynamic FIFO mode ("动态模式下该指令无效");
* GT_SetPtMemory / GT_SetFollowMemory / GT_SetGearMaster / GT_SetFollowMaster:
  the profile is moving (a smaller memory that cannot hold the data: clear first);
* GT_PtStart / GT_GearStart / GT_FollowStart: for an axis of the mask, the
  profile moves, the selected FIFO holds no data, no master or ratio is set,
  or the axis cannot move (servo off, drive not in CSP, latched alarm /
  following error / stop input, a triggered limit in the first segment's
  direction - the checks GT_Update makes).  All or nothing: when one axis
  fails none starts.  ``mask`` 0 (no axis) is 1 (entries 22 (5), 23 (4));
* GT_FollowSwitch: not moving, or the other FIFO is empty (entry 23).

Return 7: an argument out of its range (segment type, fifo, memory flag,
``dir``, masterType / masterItem, masterIndex equal to the profile or naming no
axis, masterEven <= 0, masterSlope < 0 or 1, negative PT loop, Follow loop out
of a short, non-increasing times / master points, a mask bit of an axis the bus
does not have).

Decisions where the manual is silent:

* ``time`` (GT_PtData) and ``masterSegment`` (GT_FollowData) are C ``long``: a
  float within 1e-6 of a whole number (``t * 1000`` computed in seconds) is
  taken as that number, any other fraction is 7 - never silently truncated.
* A profile that leaves a mode and comes back keeps that mode's settings and
  FIFO data until GT_Reset (as Trap/Jog parameters do); GT_PrfGear /
  GT_PrfFollow with a new ``dir`` keep master, ratio, loop, event, memory and data.
* GT_GetGearMaster / GT_GetFollowMaster before any Set report masterIndex 0,
  type PROFILE, item 0; GT_GetGearRatio before any Set reports 0, 0, 0.
* GT_PtStart / GT_FollowStart: bit n-1 of ``option`` picks FIFO2 for axis n
  (static PT and Follow; dynamic PT ignores it).  The motion starts at the
  current cycle: the k-th cycle after the call samples the plan at k·cycle.
* A master numbered above its slave is read as it was in the previous cycle
  (axes are planned in number order), the lag 7.5.2 / 7.6.2 warn about.  An
  encoder master (or axis master, item 1) is what the last exchange brought
  back (6064h), read before this cycle's exchange.
"""

from __future__ import annotations

import math
from numbers import Real
from typing import Any, TypeVar, cast

from ..controller.core import Controller
from ..controller.motion import checks
from ..controller.motion.follow import FollowPlanner
from ..controller.motion.gear import GearPlanner
from ..controller.motion.master import MasterSource, MasterSpec, MasterType, direction
from ..controller.motion.pt import PtMode, PtPlanner
from ..controller.profile import PrfMode
from ..controller.resources import AxisResources, axes_in_mask, axis_resources, position_source
from ..errors import CommandError, ParameterError
from ._core import gt_function, store
from .constants import (
    FOLLOW_MASTER_PROFILE,
    FOLLOW_SEGMENT_NORMAL,
    GEAR_MASTER_PROFILE,
    PT_MODE_STATIC,
    PT_SEGMENT_NORMAL,
)

P = TypeVar("P")
_LONG_MIN, _LONG_MAX = -(1 << 31), (1 << 31) - 1
_WHOLE_TOL = 1e-6


# --- argument helpers ---------------------------------------------------------------------
def _long(name: str, value: Any) -> int:
    """A C ``long``: an integer (a float only when whole) in [-2**31, 2**31 - 1]."""
    v = checks.integer(name, value)
    if not _LONG_MIN <= v <= _LONG_MAX:
        raise ParameterError(f"{name}={v} out of the long range [-2147483648, 2147483647]")
    return v


def _long_count(name: str, value: Any) -> int:
    """A ``long`` the host may compute in floating point: 48.00000000000001 -> 48, 2.5 -> 7."""
    if isinstance(value, Real) and not isinstance(value, bool):
        x = float(value)
        if math.isfinite(x) and abs(x - round(x)) <= _WHOLE_TOL:
            value = round(x)
    return _long(name, value)


def _planner(res: AxisResources, what: str, mode: PrfMode, kind: type[P]) -> P:
    """The profile's planner of ``mode``; CommandError (1) when the profile is in another mode."""
    res.profile.require_mode(what, mode)
    return cast(P, res.profile.planner)


def _mode_planner(ctl: Controller, profile: int, what: str, mode: PrfMode, kind: type[P]) -> P:
    return _planner(axis_resources(ctl, profile), what, mode, kind)


def _require_free(res: AxisResources, what: str) -> None:
    """What a mode switch needs: an active profile at rest (entries 86, 87, 89)."""
    p = res.profile
    if not p.active:
        raise CommandError(
            f"{what}: profile {res.number} is not active (configuration file 'active = 0')"
        )
    p.require_idle(what)


def _mask32(name: str, value: Any) -> int:
    """A 32-bit ``long`` mask: bit 31 (axis 32) may come as a negative ``long`` or, as the
    argument layer hands a mask over, as the unsigned word; the word is returned."""
    v = checks.integer(name, value)
    if not _LONG_MIN <= v <= 0xFFFFFFFF:
        raise ParameterError(f"{name}={v} is not a 32-bit mask")
    return v & 0xFFFFFFFF


def _mask_axes(ctl: Controller, mask: Any, what: str) -> list[AxisResources]:
    """Axes of ``mask`` (bit 0 = axis 1); a bit of a missing axis is 7, no axis at all is 1."""
    m = _mask32("mask", mask)
    axes = axes_in_mask(ctl, m, strict=True)
    if not axes:
        raise CommandError(f"{what}: mask {m:#x} selects no axis (chapter 13: check mask)")
    return axes


def _option_fifo(option: int, axis: int) -> int:
    """FIFO of ``axis`` in an ``option`` word: bit n-1 = 0 -> FIFO1 (0), 1 -> FIFO2 (1)."""
    return (option >> (axis - 1)) & 1


def _master_source(ctl: Controller, spec: MasterSpec) -> MasterSource:
    try:
        return position_source(ctl, int(spec.type), spec.index, int(spec.item))
    except ParameterError as e:
        raise ParameterError(f"masterIndex={spec.index}: {e}") from None


def _store_master(spec: MasterSpec | None, pIndex: Any, pType: Any, pItem: Any) -> None:
    if spec is None:
        store(pIndex, 0)
        store(pType, int(MasterType.PROFILE))
        store(pItem, 0)
        return
    store(pIndex, spec.index)
    store(pType, int(spec.type))
    store(pItem, int(spec.item))


# ============================================================================ PT (7.4)
@gt_function
def GT_PrfPt(ctl: Controller, profile: int, mode: int = PT_MODE_STATIC) -> int:
    """PT mode with a static (0) or dynamic (1) FIFO use (entry 89; 1 while moving)."""
    res = axis_resources(ctl, profile)
    m = checks.integer("mode", mode)
    if m not in tuple(PtMode):
        raise ParameterError(
            f"mode must be 0 (PT_MODE_STATIC) or 1 (PT_MODE_DYNAMIC), got {mode!r}"
        )
    _require_free(res, "GT_PrfPt")
    p = res.profile
    if p.mode == PrfMode.PT:
        planner = cast(PtPlanner, p.planner)
    else:
        planner = cast(
            PtPlanner,
            p.enter(PrfMode.PT, factory=lambda: PtPlanner(PtMode(m), res.cycle_ms, p.pos)),
        )
    planner.set_mode(m)  # another FIFO mode empties both FIFOs
    return 0


@gt_function
def GT_PtData(
    ctl: Controller,
    profile: int,
    pos: float,
    time: int,
    type: int = PT_SEGMENT_NORMAL,
    fifo: int = 0,
) -> int:
    """Push one segment end point: pos (pulse) and time (ms) from the PT start (entry 93)."""
    pt = _mode_planner(ctl, profile, "GT_PtData", PrfMode.PT, PtPlanner)
    pt.data(checks.real("pos", pos), _long_count("time", time), type, fifo)
    return 0


@gt_function
def GT_PtSpace(ctl: Controller, profile: int, pSpace: Any, fifo: int = 0) -> int:
    """Free segments of ``fifo`` (dynamic: of the FIFO the next segment goes to) (entry 94)."""
    pt = _mode_planner(ctl, profile, "GT_PtSpace", PrfMode.PT, PtPlanner)
    store(pSpace, pt.space(fifo))
    return 0


@gt_function
def GT_PtClear(ctl: Controller, profile: int, fifo: int = 0) -> int:
    """Empty ``fifo`` (static; not the one in use) or both (dynamic; only at rest) (entry 92)."""
    pt = _mode_planner(ctl, profile, "GT_PtClear", PrfMode.PT, PtPlanner)
    pt.clear(fifo)
    return 0


@gt_function
def GT_PtStart(ctl: Controller, mask: int, option: int = 0) -> int:
    """Start PT on the axes of ``mask``; ``option`` bit n-1 picks FIFO2 for axis n (entry 95)."""
    axes = _mask_axes(ctl, mask, "GT_PtStart")
    opt = _mask32("option", option)
    plan: list[tuple[PtPlanner, int]] = []
    for r in axes:
        what = f"GT_PtStart (axis {r.number})"
        pt = _planner(r, what, PrfMode.PT, PtPlanner)
        if pt.moving:
            raise CommandError(f"{what}: the profile is moving; call GT_Stop first")
        fifo = _option_fifo(opt, r.number) if pt.mode == PtMode.STATIC else 0
        points = pt.points(fifo)
        if not points:
            which = f"FIFO{fifo + 1} (option bit {r.number - 1} = {fifo})"
            if pt.mode == PtMode.DYNAMIC:
                which = "both FIFOs (dynamic mode)"
            raise CommandError(f"{what}: {which} holds no data; push segments with GT_PtData")
        r.check_motion(what, points[0].pos)
        plan.append((pt, fifo))
    for pt, fifo in plan:
        pt.start(fifo)
    return 0


@gt_function
def GT_SetPtLoop(ctl: Controller, profile: int, loop: int) -> int:
    """Passes of a static PT FIFO, 0 = endless (entry 119; 1 in dynamic mode)."""
    pt = _mode_planner(ctl, profile, "GT_SetPtLoop", PrfMode.PT, PtPlanner)
    pt.set_loop(_long("loop", loop))
    return 0


@gt_function
def GT_GetPtLoop(ctl: Controller, profile: int, pLoop: Any) -> int:
    """Passes completed of the running (or last run) static PT motion (entry 66)."""
    pt = _mode_planner(ctl, profile, "GT_GetPtLoop", PrfMode.PT, PtPlanner)
    store(pLoop, pt.loops_done)
    return 0


@gt_function
def GT_SetPtMemory(ctl: Controller, profile: int, memory: int) -> int:
    """FIFO size flag: 0 = 32, 1 = 1024 segments per FIFO (entry 120; 1 while moving)."""
    pt = _mode_planner(ctl, profile, "GT_SetPtMemory", PrfMode.PT, PtPlanner)
    pt.set_memory(memory)
    return 0


@gt_function
def GT_GetPtMemory(ctl: Controller, profile: int, pMemory: Any) -> int:
    pt = _mode_planner(ctl, profile, "GT_GetPtMemory", PrfMode.PT, PtPlanner)
    store(pMemory, pt.memory)
    return 0


@gt_function
def GT_GetPtRemainder(ctl: Controller, profile: int, pRemainder: Any) -> int:
    """Segments not finished yet, the executing one included (entry 68)."""
    pt = _mode_planner(ctl, profile, "GT_GetPtRemainder", PrfMode.PT, PtPlanner)
    store(pRemainder, pt.remainder)
    return 0


# ==================================================================== electronic gear (7.5)
@gt_function
def GT_PrfGear(ctl: Controller, profile: int, dir: int = 0) -> int:
    """Gear mode following the master both ways (0), positive (1), negative (-1) (entry 87)."""
    res = axis_resources(ctl, profile)
    d = direction(dir)
    _require_free(res, "GT_PrfGear")
    p = res.profile
    if p.mode == PrfMode.GEAR:
        cast(GearPlanner, p.planner).set_direction(d)  # another dir: 1
        return 0
    old = cast(GearPlanner | None, p.planners.get(PrfMode.GEAR))
    if old is not None and old.direction == d:
        p.enter(PrfMode.GEAR)
        return 0
    g = GearPlanner(profile=res.number, dir=d, cycle_ms=res.cycle_ms, pos=p.pos)
    if old is not None:  # settings persist across mode changes
        if old.master is not None:
            m = old.master
            g.set_master(m.index, m.type, m.item, source=_master_source(ctl, m))
        if old.ratio is not None:
            g.set_ratio(*old.ratio)
    p.enter(PrfMode.GEAR, planner=g)
    return 0


@gt_function
def GT_SetGearMaster(
    ctl: Controller,
    profile: int,
    masterIndex: int,
    masterType: int = GEAR_MASTER_PROFILE,
    masterItem: int = 0,
) -> int:
    """Master: profile / encoder / axis ``masterIndex`` (entry 110; 1 while moving)."""
    res = axis_resources(ctl, profile)
    g = _planner(res, "GT_SetGearMaster", PrfMode.GEAR, GearPlanner)
    spec = MasterSpec.checked(res.number, masterIndex, masterType, masterItem)
    g.set_master(spec.index, spec.type, spec.item, source=_master_source(ctl, spec))
    return 0


@gt_function
def GT_GetGearMaster(
    ctl: Controller, profile: int, pMasterIndex: Any, pMasterType: Any, pMasterItem: Any
) -> int:
    g = _mode_planner(ctl, profile, "GT_GetGearMaster", PrfMode.GEAR, GearPlanner)
    _store_master(g.master, pMasterIndex, pMasterType, pMasterItem)
    return 0


@gt_function
def GT_SetGearRatio(
    ctl: Controller, profile: int, masterEven: int, slaveEven: int, masterSlope: int = 0
) -> int:
    """Slave moves slaveEven per masterEven; clutch over masterSlope master pulses (entry 111)."""
    g = _mode_planner(ctl, profile, "GT_SetGearRatio", PrfMode.GEAR, GearPlanner)
    g.set_ratio(
        _long("masterEven", masterEven),
        _long("slaveEven", slaveEven),
        _long("masterSlope", masterSlope),
    )
    return 0


@gt_function
def GT_GetGearRatio(
    ctl: Controller, profile: int, pMasterEven: Any, pSlaveEven: Any, pMasterSlope: Any
) -> int:
    g = _mode_planner(ctl, profile, "GT_GetGearRatio", PrfMode.GEAR, GearPlanner)
    me, se, sl = g.ratio if g.ratio is not None else (0, 0, 0)
    store(pMasterEven, me)
    store(pSlaveEven, se)
    store(pMasterSlope, sl)
    return 0


@gt_function
def GT_GearStart(ctl: Controller, mask: int) -> int:
    """Engage the gear of every axis of ``mask`` through its clutch zone (entry 24)."""
    axes = _mask_axes(ctl, mask, "GT_GearStart")
    gears: list[GearPlanner] = []
    for r in axes:
        what = f"GT_GearStart (axis {r.number})"
        g = _planner(r, what, PrfMode.GEAR, GearPlanner)
        if g.moving:
            raise CommandError(f"{what}: the profile is moving; call GT_Stop first")
        if g.master is None:
            raise CommandError(f"{what}: no master set; call GT_SetGearMaster first")
        if g.ratio is None:
            raise CommandError(f"{what}: no gear ratio set; call GT_SetGearRatio first")
        r.check_motion(what)
        gears.append(g)
    for g in gears:
        g.start()
    return 0


# ============================================================================ Follow (7.6)
def _follow_like(old: FollowPlanner, new: FollowPlanner, ctl: Controller) -> None:
    """Carry master, loop, event, memory and FIFO data to a Follow planner with another dir."""
    if old.master is not None:
        m = old.master
        new.set_master(m.index, m.type, m.item, source=_master_source(ctl, m))
    new.set_loop(old.loop)
    t = old.trigger
    new.set_event(t.event, t.master_dir, t.pos)
    new.set_memory(old.memory)
    for fifo in (0, 1):
        for pt in old.points(fifo):
            new.data(pt.master, pt.slave, pt.type, fifo)


@gt_function
def GT_PrfFollow(ctl: Controller, profile: int, dir: int = 0) -> int:
    """Follow mode following the master both ways (0), positive (1), negative (-1) (entry 86)."""
    res = axis_resources(ctl, profile)
    d = direction(dir)
    _require_free(res, "GT_PrfFollow")
    p = res.profile
    if p.mode == PrfMode.FOLLOW:
        cast(FollowPlanner, p.planner).set_direction(d)  # another dir: 1
        return 0
    old = cast(FollowPlanner | None, p.planners.get(PrfMode.FOLLOW))
    if old is not None and old.direction == d:
        p.enter(PrfMode.FOLLOW)
        return 0
    f = FollowPlanner(profile=res.number, dir=d, cycle_ms=res.cycle_ms, pos=p.pos)
    if old is not None:
        _follow_like(old, f, ctl)
    p.enter(PrfMode.FOLLOW, planner=f)
    return 0


@gt_function
def GT_SetFollowMaster(
    ctl: Controller,
    profile: int,
    masterIndex: int,
    masterType: int = FOLLOW_MASTER_PROFILE,
    masterItem: int = 0,
) -> int:
    """Master: profile / encoder / axis ``masterIndex`` (entry 108; 1 while moving)."""
    res = axis_resources(ctl, profile)
    f = _planner(res, "GT_SetFollowMaster", PrfMode.FOLLOW, FollowPlanner)
    spec = MasterSpec.checked(res.number, masterIndex, masterType, masterItem)
    f.set_master(spec.index, spec.type, spec.item, source=_master_source(ctl, spec))
    return 0


@gt_function
def GT_GetFollowMaster(
    ctl: Controller, profile: int, pMasterIndex: Any, pMasterType: Any, pMasterItem: Any
) -> int:
    f = _mode_planner(ctl, profile, "GT_GetFollowMaster", PrfMode.FOLLOW, FollowPlanner)
    _store_master(f.master, pMasterIndex, pMasterType, pMasterItem)
    return 0


@gt_function
def GT_SetFollowLoop(ctl: Controller, profile: int, loop: int) -> int:
    """Passes of each FIFO, a short; < 1 = endless (entry 107)."""
    f = _mode_planner(ctl, profile, "GT_SetFollowLoop", PrfMode.FOLLOW, FollowPlanner)
    f.set_loop(loop)
    return 0


@gt_function
def GT_GetFollowLoop(ctl: Controller, profile: int, pLoop: Any) -> int:
    """Passes completed of the running (or last run) FIFO (entry 49)."""
    f = _mode_planner(ctl, profile, "GT_GetFollowLoop", PrfMode.FOLLOW, FollowPlanner)
    store(pLoop, f.loops_done)
    return 0


@gt_function
def GT_SetFollowEvent(
    ctl: Controller, profile: int, event: int, masterDir: int = 1, pos: int = 0
) -> int:
    """Start at once (1) or when the master passes ``pos`` in ``masterDir`` (2) (entry 106)."""
    f = _mode_planner(ctl, profile, "GT_SetFollowEvent", PrfMode.FOLLOW, FollowPlanner)
    f.set_event(event, masterDir, _long("pos", pos))
    return 0


@gt_function
def GT_GetFollowEvent(
    ctl: Controller, profile: int, pEvent: Any, pMasterDir: Any, pPos: Any
) -> int:
    f = _mode_planner(ctl, profile, "GT_GetFollowEvent", PrfMode.FOLLOW, FollowPlanner)
    t = f.trigger
    store(pEvent, int(t.event))
    store(pMasterDir, t.master_dir)
    store(pPos, t.pos)
    return 0


@gt_function
def GT_FollowData(
    ctl: Controller,
    profile: int,
    masterSegment: int,
    slaveSegment: float,
    type: int = FOLLOW_SEGMENT_NORMAL,
    fifo: int = 0,
) -> int:
    """Push one point: master and slave positions from the zero point of the pass (entry 20)."""
    f = _mode_planner(ctl, profile, "GT_FollowData", PrfMode.FOLLOW, FollowPlanner)
    f.data(_long_count("masterSegment", masterSegment), slaveSegment, type, fifo)
    return 0


@gt_function
def GT_FollowSpace(ctl: Controller, profile: int, pSpace: Any, fifo: int = 0) -> int:
    """Free segments of ``fifo`` (entry 21)."""
    f = _mode_planner(ctl, profile, "GT_FollowSpace", PrfMode.FOLLOW, FollowPlanner)
    store(pSpace, f.space(fifo))
    return 0


@gt_function
def GT_FollowClear(ctl: Controller, profile: int, fifo: int = 0) -> int:
    """Empty ``fifo``; not the running one, nor a pending switch's target (entry 19)."""
    f = _mode_planner(ctl, profile, "GT_FollowClear", PrfMode.FOLLOW, FollowPlanner)
    f.clear(fifo)
    return 0


@gt_function
def GT_FollowStart(ctl: Controller, mask: int, option: int = 0) -> int:
    """Start Follow on the axes of ``mask``; ``option`` bit n-1: FIFO2 for axis n (entry 22)."""
    axes = _mask_axes(ctl, mask, "GT_FollowStart")
    opt = _mask32("option", option)
    plan: list[tuple[FollowPlanner, int]] = []
    for r in axes:
        what = f"GT_FollowStart (axis {r.number})"
        f = _planner(r, what, PrfMode.FOLLOW, FollowPlanner)
        if f.moving:
            raise CommandError(f"{what}: the profile is moving; call GT_Stop first")
        if f.master is None:
            raise CommandError(f"{what}: no master set; call GT_SetFollowMaster first")
        fifo = _option_fifo(opt, r.number)
        if not f.points(fifo):
            raise CommandError(
                f"{what}: FIFO{fifo + 1} (option bit {r.number - 1} = {fifo}) holds no data; "
                "push points with GT_FollowData"
            )
        r.check_motion(what)
        plan.append((f, fifo))
    for f, fifo in plan:
        f.start(fifo)
    return 0


@gt_function
def GT_FollowSwitch(ctl: Controller, mask: int) -> int:
    """Run the other FIFO once the running one's pass ends, then clear it (entry 23)."""
    axes = _mask_axes(ctl, mask, "GT_FollowSwitch")
    planners: list[FollowPlanner] = []
    for r in axes:
        what = f"GT_FollowSwitch (axis {r.number})"
        f = _planner(r, what, PrfMode.FOLLOW, FollowPlanner)
        running = f.running_fifo
        if running is None:
            raise CommandError(f"{what}: only a moving Follow profile can switch FIFO")
        if not f.points(1 - running):
            raise CommandError(
                f"{what}: the target FIFO{2 - running} (fifo {1 - running}) holds no data"
            )
        planners.append(f)
    for f in planners:
        f.switch()
    return 0


@gt_function
def GT_SetFollowMemory(ctl: Controller, profile: int, memory: int) -> int:
    """FIFO size flag: 0 = 16, 1 = 512 segments per FIFO (entry 109; 1 while moving)."""
    f = _mode_planner(ctl, profile, "GT_SetFollowMemory", PrfMode.FOLLOW, FollowPlanner)
    f.set_memory(memory)
    return 0


@gt_function
def GT_GetFollowMemory(ctl: Controller, profile: int, pMemory: Any) -> int:
    f = _mode_planner(ctl, profile, "GT_GetFollowMemory", PrfMode.FOLLOW, FollowPlanner)
    store(pMemory, f.memory)
    return 0
