"""GT calls of coordinated motion (interpolation): coordinate systems, segments, look-ahead.

The vendor header's coordinated-motion subset (gts-header-facts.md, "Coordinated
motion"; table 10-2 names GT_CrdSpace, GT_CrdStart, GT_CrdStatus, GT_GetCrdVel,
GT_SetOverride).  :mod:`gtecat.controller.crd` holds the semantics and its
docstring the decisions; these wrappers check arguments and turn pointers into
Python.

Return 1 (with a reason) when: the system has no GT_SetCrdPrm yet; a mapped
profile moves or is inactive (GT_SetCrdPrm), or has left interpolation mode
(GT_PrfTrap ...) since; the FIFO is full (segments), or runs (GT_CrdClear);
GT_CrdStart: the system moves, the FIFO is empty, or an axis cannot move (servo
off, not CSP, a latched flag); ``mask`` selects no system.  Return 7: a crd
other than 1/2, fifo other than 0/1, dimension out of 1..4, a coordinate mapped
twice or not at all, synVelMax/synAccMax/synVel/synAcc <= 0, velEnd < 0, a
segment needing more coordinates than the system has, an arc whose end lies off
its circle, a radius shorter than half the chord, an axis missing.
"""

from __future__ import annotations

import math
from typing import Any

from ..controller.core import Controller
from ..controller.crd import CRD_COUNT, CoordSystem, CrdParams, arc_center, bank, make_arc
from ..controller.crd.path import PLANES, Line
from ..controller.crd.system import DIM_MAX, BufIO, BufMove, Delay, LookAhead, Motion
from ..controller.motion import TrapParams
from ..controller.motion.stop import StopDecel
from ..controller.profile import PrfMode
from ..controller.resources import axis_resources
from ..errors import CommandError, ParameterError
from ._core import gt_function, store, store_array, struct_arg
from .constants import MC_GPO
from .crd_structs import CRD_FIFO_MAX, CRD_MAX, INTERPOLATION_AXIS_MAX, TCrdPrm


def _crd(ctl: Controller, crd: int) -> CoordSystem:
    return bank(ctl).get(crd)


def _real(name: str, value: Any) -> float:
    x = float(value)
    if not math.isfinite(x):
        raise ParameterError(f"{name}={value!r} is not a finite number")
    return x


# --- parameters ----------------------------------------------------------------------------
@gt_function
def GT_SetCrdPrm(ctl: Controller, crd: int, pCrdPrm: Any) -> int:
    """Set up coordinate system ``crd``: its profiles enter interpolation mode."""
    c = _crd(ctl, crd)
    s = struct_arg(pCrdPrm, TCrdPrm, "pCrdPrm")
    dim = int(s.dimension)
    if not 1 <= dim <= DIM_MAX:
        raise ParameterError(f"dimension={dim}: 1..{DIM_MAX}")
    prof = tuple(int(x) for x in s.profile)
    for k, v in enumerate(prof):
        if not 0 <= v <= dim:
            raise ParameterError(f"profile[{k}]={v}: 0 (none) or a coordinate 1..{dim}")
    for coord in range(1, dim + 1):
        n = prof.count(coord)
        if n != 1:
            raise ParameterError(
                f"coordinate {coord} is mapped to {n} profiles (profile[k] = {coord}); exactly 1"
            )
    vmax, amax = _real("synVelMax", s.synVelMax), _real("synAccMax", s.synAccMax)
    if vmax <= 0 or amax <= 0:
        raise ParameterError(f"synVelMax={vmax}, synAccMax={amax}: both must be > 0")
    if s.evenTime < 0:
        raise ParameterError(f"evenTime={s.evenTime}: must be >= 0")
    if s.setOriginFlag not in (0, 1):
        raise ParameterError(f"setOriginFlag={s.setOriginFlag}: 0 or 1")
    prm = CrdParams(
        dimension=dim,
        profile=prof,
        syn_vel_max=vmax,
        syn_acc_max=amax,
        even_time=int(s.evenTime),
        set_origin=int(s.setOriginFlag),
        origin=tuple(float(x) for x in s.originPos),
    )
    profiles = {}
    for n in prm.axes():
        res = axis_resources(ctl, n)
        if not res.profile.active:
            raise CommandError(f"GT_SetCrdPrm: profile {n} is not active (configuration file)")
        profiles[n] = res.profile
    for other in bank(ctl).systems.values():
        if other is not c and other.prm is not None:
            shared = set(other.prm.axes()) & set(prm.axes())
            if shared and other.running:
                raise CommandError(
                    f"GT_SetCrdPrm: profile {min(shared)} moves in coordinate system {other.number}"
                )
    c.configure(prm, profiles)
    return 0


@gt_function
def GT_GetCrdPrm(ctl: Controller, crd: int, pCrdPrm: Any) -> int:
    c = _crd(ctl, crd)
    prm = c.require_prm("GT_GetCrdPrm")
    s = struct_arg(pCrdPrm, TCrdPrm, "pCrdPrm")
    s.dimension = prm.dimension
    for k in range(8):
        s.profile[k] = prm.profile[k]
        s.originPos[k] = round(prm.origin[k])
    s.synVelMax, s.synAccMax = prm.syn_vel_max, prm.syn_acc_max
    s.evenTime, s.setOriginFlag = prm.even_time, prm.set_origin
    return 0


# --- FIFOs ------------------------------------------------------------------------------------
@gt_function
def GT_CrdSpace(ctl: Controller, crd: int, pSpace: Any, fifo: int = 0) -> int:
    c = _crd(ctl, crd)
    c.require_prm("GT_CrdSpace")
    store(pSpace, c.now().space(fifo))
    return 0


@gt_function
def GT_CrdClear(ctl: Controller, crd: int, fifo: int) -> int:
    c = _crd(ctl, crd)
    c.require_prm("GT_CrdClear")
    c.clear(fifo)
    return 0


def _target(c: CoordSystem, what: str, fifo: int, values: dict[int, int]) -> tuple:
    """The segment's end: the FIFO tail with coordinates ``values`` (index -> pulse) replaced."""
    prm = c.require_prm(what)
    need = max(values) + 1
    if prm.dimension < need:
        raise ParameterError(
            f"{what}: coordinate system {c.number} has {prm.dimension} dimension(s), {need} needed"
        )
    start = c.tail(fifo)
    end = list(start)
    for k, v in values.items():
        end[k] = float(v)
    return start, tuple(end)


def _push_line(c, what, fifo, values, synVel, synAcc, velEnd) -> int:
    v, a, ve = c.motion_params(
        _real("synVel", synVel), _real("synAcc", synAcc), _real("velEnd", velEnd)
    )
    start, end = _target(c, what, fifo, values)
    c.push(Motion(Line(start, end), v, a, ve), fifo)
    return 0


@gt_function
def GT_LnXY(ctl, crd, x, y, synVel, synAcc, velEnd=0.0, fifo=0) -> int:
    """Line to (x, y) (the other coordinates stay)."""
    return _push_line(_crd(ctl, crd), "GT_LnXY", fifo, {0: x, 1: y}, synVel, synAcc, velEnd)


@gt_function
def GT_LnXYZ(ctl, crd, x, y, z, synVel, synAcc, velEnd=0.0, fifo=0) -> int:
    return _push_line(_crd(ctl, crd), "GT_LnXYZ", fifo, {0: x, 1: y, 2: z}, synVel, synAcc, velEnd)


@gt_function
def GT_LnXYZA(ctl, crd, x, y, z, aPos, synVel, synAcc, velEnd=0.0, fifo=0) -> int:
    return _push_line(
        _crd(ctl, crd), "GT_LnXYZA", fifo, {0: x, 1: y, 2: z, 3: aPos}, synVel, synAcc, velEnd
    )


@gt_function
def GT_LnXYG0(ctl, crd, x, y, synVel, synAcc, fifo=0) -> int:
    """Rapid line to (x, y): a line that stops at its end."""
    return _push_line(_crd(ctl, crd), "GT_LnXYG0", fifo, {0: x, 1: y}, synVel, synAcc, 0.0)


def _push_arc(
    c,
    what,
    fifo,
    plane,
    a,
    b,
    synVel,
    synAcc,
    velEnd,
    direction,
    *,
    radius=None,
    center=None,
    z=None,
) -> int:
    i, j = PLANES[plane]
    vals = {i: a, j: b}
    if z is not None:
        vals[2] = z
    v, acc, ve = c.motion_params(
        _real("synVel", synVel), _real("synAcc", synAcc), _real("velEnd", velEnd)
    )
    start, end = _target(c, what, fifo, vals)
    if radius is not None:
        ctr = arc_center(start, end, (i, j), _real("radius", radius), int(direction))
    else:
        ctr = (start[i] + _real("center", center[0]), start[j] + _real("center", center[1]))
    geom = make_arc(start, end, ctr, (i, j), int(direction), axis3=2 if z is not None else None)
    c.push(Motion(geom, v, acc, ve), fifo)
    return 0


@gt_function
def GT_ArcXYR(ctl, crd, x, y, radius, circleDir, synVel, synAcc, velEnd=0.0, fifo=0) -> int:
    """Arc to (x, y) of ``radius`` (> 0 at most 180°, < 0 more); circleDir 0 cw, 1 ccw."""
    return _push_arc(
        _crd(ctl, crd),
        "GT_ArcXYR",
        fifo,
        "XY",
        x,
        y,
        synVel,
        synAcc,
        velEnd,
        circleDir,
        radius=radius,
    )


@gt_function
def GT_ArcXYC(ctl, crd, x, y, xCenter, yCenter, circleDir, synVel, synAcc, velEnd=0.0, fifo=0):
    """Arc to (x, y) around the centre (xCenter, yCenter) relative to the start point."""
    return _push_arc(
        _crd(ctl, crd),
        "GT_ArcXYC",
        fifo,
        "XY",
        x,
        y,
        synVel,
        synAcc,
        velEnd,
        circleDir,
        center=(xCenter, yCenter),
    )


@gt_function
def GT_ArcYZR(ctl, crd, y, z, radius, circleDir, synVel, synAcc, velEnd=0.0, fifo=0) -> int:
    return _push_arc(
        _crd(ctl, crd),
        "GT_ArcYZR",
        fifo,
        "YZ",
        y,
        z,
        synVel,
        synAcc,
        velEnd,
        circleDir,
        radius=radius,
    )


@gt_function
def GT_ArcYZC(ctl, crd, y, z, yCenter, zCenter, circleDir, synVel, synAcc, velEnd=0.0, fifo=0):
    return _push_arc(
        _crd(ctl, crd),
        "GT_ArcYZC",
        fifo,
        "YZ",
        y,
        z,
        synVel,
        synAcc,
        velEnd,
        circleDir,
        center=(yCenter, zCenter),
    )


@gt_function
def GT_ArcZXR(ctl, crd, z, x, radius, circleDir, synVel, synAcc, velEnd=0.0, fifo=0) -> int:
    return _push_arc(
        _crd(ctl, crd),
        "GT_ArcZXR",
        fifo,
        "ZX",
        z,
        x,
        synVel,
        synAcc,
        velEnd,
        circleDir,
        radius=radius,
    )


@gt_function
def GT_ArcZXC(ctl, crd, z, x, zCenter, xCenter, circleDir, synVel, synAcc, velEnd=0.0, fifo=0):
    return _push_arc(
        _crd(ctl, crd),
        "GT_ArcZXC",
        fifo,
        "ZX",
        z,
        x,
        synVel,
        synAcc,
        velEnd,
        circleDir,
        center=(zCenter, xCenter),
    )


@gt_function
def GT_HelixXYRZ(ctl, crd, x, y, z, radius, circleDir, synVel, synAcc, velEnd=0.0, fifo=0):
    """Helix: an XY arc by radius while Z moves linearly to ``z``."""
    return _push_arc(
        _crd(ctl, crd),
        "GT_HelixXYRZ",
        fifo,
        "XY",
        x,
        y,
        synVel,
        synAcc,
        velEnd,
        circleDir,
        radius=radius,
        z=z,
    )


@gt_function
def GT_HelixXYCZ(
    ctl, crd, x, y, z, xCenter, yCenter, circleDir, synVel, synAcc, velEnd=0.0, fifo=0
):
    """Helix: an XY arc around a centre relative to the start while Z moves to ``z``."""
    return _push_arc(
        _crd(ctl, crd),
        "GT_HelixXYCZ",
        fifo,
        "XY",
        x,
        y,
        synVel,
        synAcc,
        velEnd,
        circleDir,
        center=(xCenter, yCenter),
        z=z,
    )


# --- buffered operations ----------------------------------------------------------------------
@gt_function
def GT_BufIO(ctl, crd, doType, doMask, doValue, fifo=0) -> int:
    """Set the ``doMask`` bits of ``doType`` to ``doValue`` when the path reaches this point
    (MC_GPO: the general-purpose outputs of GT_SetDo; other types are recorded only)."""
    c = _crd(ctl, crd)
    c.require_prm("GT_BufIO")
    t, mask, value = int(doType), int(doMask), int(doValue)
    apply = None
    if t == MC_GPO:

        def apply(m: int, v: int) -> None:
            from .io_calls import read_do, write_do

            write_do(ctl, MC_GPO, (read_do(ctl, MC_GPO) & ~m) | (v & m))

    c.push(BufIO(t, mask, value, apply=apply), fifo)
    return 0


@gt_function
def GT_BufDelay(ctl, crd, delayTime, fifo=0) -> int:
    """Wait ``delayTime`` ms at this point of the path."""
    c = _crd(ctl, crd)
    c.require_prm("GT_BufDelay")
    c.push(Delay(float(delayTime)), fifo)
    return 0


@gt_function
def GT_BufMove(ctl, crd, moveAxis, pos, vel, acc, modal, fifo=0) -> int:
    """Start a Trap move of an axis outside the system here; ``modal`` 1 waits for its end."""
    c = _crd(ctl, crd)
    prm = c.require_prm("GT_BufMove")
    res = axis_resources(ctl, moveAxis)
    if res.number in prm.axes():
        raise ParameterError(f"moveAxis={moveAxis} belongs to coordinate system {c.number}")
    v, a = _real("vel", vel), _real("acc", acc)
    if v <= 0 or a <= 0:
        raise ParameterError(f"vel={v}, acc={a}: both must be > 0")
    target = int(pos)

    def run():
        try:
            if res.profile.mode != PrfMode.TRAP:
                res.prf_trap()
            res.set_trap_prm(TrapParams(acc=a, dec=a, vel_start=0.0, smooth_time=0))
            res.set_target(target)
            res.set_vel(v)
            res.check_update()
            res.start()
        except (CommandError, ParameterError) as e:
            ctl.log(f"GT_BufMove (coordinate system {c.number}, axis {res.number}): {e}")
            return lambda: True
        return lambda: res.profile.planner.done

    c.push(BufMove(res.number, target, v, a, int(modal), run=run), fifo)
    return 0


# --- run, status ----------------------------------------------------------------------------
@gt_function
def GT_CrdStart(ctl: Controller, mask: int, option: int) -> int:
    """Start the systems of ``mask`` (bit 0 = crd 1); ``option`` bit n-1 = FIFO of crd n."""
    m, opt = int(mask), int(option)
    if m & ~((1 << CRD_COUNT) - 1) & 0xFFFF:
        raise ParameterError(f"mask={m:#x}: bits 0..{CRD_COUNT - 1} (coordinate systems)")
    chosen = [bank(ctl).get(n) for n in range(1, CRD_COUNT + 1) if m >> (n - 1) & 1]
    if not chosen:
        raise CommandError(f"GT_CrdStart: mask {m:#x} selects no coordinate system")
    plan = []
    for c in chosen:
        what = f"GT_CrdStart (coordinate system {c.number})"
        prm = c.require_prm(what)
        if c.running:
            raise CommandError(f"{what}: it is moving; GT_Stop it first")
        fifo = opt >> (c.number - 1) & 1
        if not c.fifos[fifo]:
            raise CommandError(f"{what}: FIFO {fifo} holds no segment")
        first = next((e for e in c.fifos[fifo] if isinstance(e, Motion)), None)
        heading = first.geom.tangent(False) if first is not None and first.geom.length else None
        for n, slot in zip(prm.axes(), c.slots, strict=True):
            res = axis_resources(ctl, n)
            if res.profile.planner is not slot:
                raise CommandError(
                    f"{what}: profile {n} left interpolation mode ({res.profile.mode.name}); "
                    "call GT_SetCrdPrm again"
                )
            res.check_motion(what, heading[slot.coord] if heading is not None else 0.0)
        plan.append((c, fifo))
    for c, fifo in plan:
        c.start(fifo)
    return 0


@gt_function
def GT_CrdStatus(ctl: Controller, crd: int, pRun: Any, pSegment: Any, fifo: int = 0) -> int:
    """Whether ``fifo`` runs and how many of its entries finished since GT_CrdStart."""
    c = _crd(ctl, crd)
    c.require_prm("GT_CrdStatus")
    f = int(fifo)
    now = c.now()  # (the axis bank's record of this cycle while it holds the system)
    store(pRun, 1 if now.running and now.fifo == f else 0)
    store(pSegment, now.segments_done[f])
    return 0


@gt_function
def GT_GetCrdPos(ctl: Controller, crd: int, pPos: Any) -> int:
    """The coordinates now, X first (``dimension`` doubles)."""
    c = _crd(ctl, crd)
    c.require_prm("GT_GetCrdPos")
    store_array(pPos, list(c.now().position()))
    return 0


@gt_function
def GT_GetCrdVel(ctl: Controller, crd: int, pSynVel: Any) -> int:
    """The vector (path) speed now, pulse/ms."""
    c = _crd(ctl, crd)
    c.require_prm("GT_GetCrdVel")
    store(pSynVel, c.now().vector_speed())
    return 0


@gt_function
def GT_SetOverride(ctl: Controller, crd: int, synVelRatio: float) -> int:
    """Path speed ratio 0..2 (1 = as programmed)."""
    c = _crd(ctl, crd)
    c.override = _real("synVelRatio", synVelRatio)
    return 0


@gt_function
def GT_SetCrdStopDec(ctl: Controller, crd: int, decSmoothStop: float, decAbruptStop: float):
    """The system's smooth and abrupt stop decelerations along the path (pulse/ms²)."""
    c = _crd(ctl, crd)
    c.stop_dec = StopDecel(
        _real("decSmoothStop", decSmoothStop), _real("decAbruptStop", decAbruptStop)
    )
    return 0


@gt_function
def GT_GetCrdStopDec(ctl: Controller, crd: int, pDecSmoothStop: Any, pDecAbruptStop: Any):
    c = _crd(ctl, crd)
    store(pDecSmoothStop, c.stop_dec.smooth)
    store(pDecAbruptStop, c.stop_dec.abrupt)
    return 0


@gt_function
def GT_InitLookAhead(ctl, crd, fifo, T, accMax, n, pLookAheadBuf=None) -> int:
    """Look-ahead over ``n`` segments for ``fifo``: corners at ``accMax·T/|Δtangent|``."""
    c = _crd(ctl, crd)
    c.require_prm("GT_InitLookAhead")
    t, a = _real("T", T), _real("accMax", accMax)
    if t <= 0 or a <= 0:
        raise ParameterError(f"T={t}, accMax={a}: both must be > 0")
    if c.running and c.fifo == int(fifo):
        raise CommandError(f"GT_InitLookAhead: FIFO {fifo} of coordinate system {crd} is running")
    c.look[int(fifo)] = LookAhead(t, a, int(n))
    return 0


__all__ = ["CRD_FIFO_MAX", "CRD_MAX", "INTERPOLATION_AXIS_MAX"]
