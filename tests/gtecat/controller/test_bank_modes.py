"""PT, Gear, Follow and coordinated motion in the axis bank against the scalar reference: the
same GT program, cycle by cycle, with ``bank="on"`` and ``bank="off"`` (the harness of
``test_bank.py``: every axis's GT_GetSts word, planned and encoder positions and speeds, the
whole GT raw image, and at the end the drives' mechanics and each mode's own counters, all
compared with ``==``).

The programs reach the boundaries of the bank's tables (gtecat/controller/bank_modes.py): runs
longer than a table (refills), calls in the middle of a table (a rewind: GT_GetPtLoop,
GT_SetGearRatio while geared), smooth and abrupt stops, soft limits and limit switches crossed
at many different cycles (so some in a refill cycle), PT passes ending inside a table, mode
changes (PT -> Trap, Trap -> PT), a master numbered above its slave, chains of slaves, a
slave that reads an encoder (kept scalar: the other axes stay in the bank), a coordinate
system with a GT_BufIO in its FIFO (scalar until the path passes it) and one stopped on its
path.  Each program also runs with its waits in one GTE_Wait (the cycles run many at a time).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from ctypes import byref, c_double, c_long, c_short
from pathlib import Path
from typing import Any

import pytest

from gtecat import gt
from gtecat.controller import bank_crd
from tests.gtecat.controller.test_bank import AXES, _bring_up, _machine_file, _ok, _sample

Script = list[tuple[int, Callable[[], object]]]


def _bit(*axes: int) -> int:
    return sum(1 << (a - 1) for a in axes)


def _trap(a: int, target: int, vel: float, acc: float = 0.5, smooth: int = 0) -> int:
    gt.GT_PrfTrap(a)
    prm = gt.TTrapPrm()
    prm.acc, prm.dec, prm.velStart, prm.smoothTime = acc, acc, 0.0, smooth
    gt.GT_SetTrapPrm(a, byref(prm))
    gt.GT_SetPos(a, target)
    gt.GT_SetVel(a, vel)
    return gt.GT_Update(_bit(a))


# --- PT --------------------------------------------------------------------------------------
def _pt_load(a: int, speed: float, loop: int, seg_ms: int, n: int = 6) -> None:
    _ok(gt.GT_PrfPt(a, gt.PT_MODE_STATIC), "PrfPt")
    gt.GT_PtClear(a, 0)
    for k in range(1, n + 1):
        t = seg_ms * k + (a % 3)
        kind = gt.PT_SEGMENT_EVEN if k % 3 == 2 else gt.PT_SEGMENT_NORMAL
        if k == n and loop == 1:
            kind = gt.PT_SEGMENT_STOP
        _ok(gt.GT_PtData(a, speed * t * (1.0 if k % 2 else 0.9), t, kind, 0), "PtData")
    _ok(gt.GT_SetPtLoop(a, loop), "SetPtLoop")


def _pt_setup() -> object:
    for a in range(1, AXES + 1):
        speed = {2: 250.0, 10: 150.0}.get(a, 3.0 + a)
        loop = 0 if a <= 4 or a == 10 else (2 if a <= 8 else 1)
        _pt_load(a, speed, loop, 7 + a % 4)
        # soft limits crossed at cycles spread over a table's 32
        gt.GT_SetSoftLimit(a, int(speed * (60 + 9 * a)), -(1 << 30))
    return gt.GT_PtStart(_bit(*range(1, AXES + 1)), 0)


def _edge_setup() -> object:
    """Constant speed from the start (EVEN segments: sample k at 10·k pulses): the first table
    holds samples 1-32, the refill 33-64.  Soft limits crossed at samples 31-36 on axes 1-4
    and 6 (each PT axis is a cluster of its own), on a geared pair's slave (7 follows 5 1:1) at
    sample 33, so one of each is crossed in a refill cycle whatever cycle the claim took."""
    for a in (1, 2, 3, 4, 5, 6):
        _ok(gt.GT_PrfPt(a, gt.PT_MODE_STATIC), "PrfPt")
        gt.GT_PtClear(a, 0)
        for k in range(1, 9):
            _ok(gt.GT_PtData(a, 200.0 * k, 20 * k, gt.PT_SEGMENT_EVEN, 0), "PtData")
    for a, k in ((1, 31), (2, 32), (3, 33), (4, 34), (6, 35)):
        gt.GT_SetSoftLimit(a, 10 * k - 5, -(1 << 30))
    _gear(7, 5, gt.GEAR_MASTER_PROFILE, (1, 1, 0))
    gt.GT_SetSoftLimit(7, 10 * 33 - 5, -(1 << 30))
    _gear(8, 5, gt.GEAR_MASTER_PROFILE, (1, 1, 0))
    gt.GT_SetSoftLimit(8, 10 * 34 - 5, -(1 << 30))
    return (gt.GT_PtStart(_bit(1, 2, 3, 4, 5, 6), 0), gt.GT_GearStart(_bit(7, 8)))


EDGE: Script = [(0, _edge_setup), (40, lambda: gt.GT_ClrSts(1, AXES))]


def _loops() -> tuple:
    out = []
    for a in range(1, AXES + 1):
        v = c_long()
        out.append((gt.GT_GetPtLoop(a, byref(v)), v.value))
    return tuple(out)


PT: Script = [
    (0, _pt_setup),
    (37, lambda: gt.GT_Stop(_bit(5), 0)),  # smooth
    (8, lambda: gt.GT_Stop(_bit(6), _bit(6))),  # abrupt
    (17, _loops),  # every PT axis back to the scalar objects, mid-table
    (30, lambda: _trap(9, 5_000, 4.0)),  # PT ended -> Trap
    (25, lambda: gt.GT_Stop(_bit(3, 4), 0)),
    (40, lambda: (gt.GT_ClrSts(1, AXES), _pt_load(3, 6.0, 2, 11), gt.GT_PtStart(_bit(3), 0))),
    (60, _loops),
]


# --- Gear and Follow ---------------------------------------------------------------------------
def _gear(a: int, master: int, kind: int, ratio: tuple[int, int, int], d: int = 0) -> None:
    _ok(gt.GT_PrfGear(a, d), "PrfGear")
    _ok(gt.GT_SetGearMaster(a, master, kind, 0), "SetGearMaster")
    _ok(gt.GT_SetGearRatio(a, *ratio), "SetGearRatio")


def _follow(a: int, master: int) -> None:
    _ok(gt.GT_PrfFollow(a, 0), "PrfFollow")
    _ok(gt.GT_SetFollowMaster(a, master, gt.FOLLOW_MASTER_PROFILE, 0), "SetFollowMaster")
    gt.GT_FollowClear(a, 0)
    for k in range(1, 9):
        _ok(gt.GT_FollowData(a, 300 * k, 100.0 * min(k, 9 - k), 0, 0), "FollowData")
    _ok(gt.GT_SetFollowLoop(a, 0), "SetFollowLoop")


def _gear_setup() -> object:
    # twelve_axes.eni: axes 1-4 on drives of their own, 5-8 and 9-12 on two 4-axis drives
    for a in (1, 5, 8, 9, 10, 12):
        _trap(a, 40_000 if a != 8 else -30_000, 3.0 + a / 4, 0.2, 10)
    _gear(2, 1, gt.GEAR_MASTER_PROFILE, (2, 1, 400))
    _gear(3, 1, gt.GEAR_MASTER_PROFILE, (1, 3, 0), 1)
    _gear(4, 3, gt.GEAR_MASTER_PROFILE, (3, 2, 100))  # a chain: 4 follows 3 follows 1
    _follow(6, 8)  # the master numbered above its slave
    _follow(7, 5)
    _gear(11, 12, gt.GEAR_MASTER_ENCODER, (1, 1, 0))  # reads an encoder: its drive stays scalar
    gt.GT_SetSoftLimit(2, 4_000, -(1 << 30))
    gt.GT_SetSoftLimit(4, 1 << 30, -(1 << 30))
    return (gt.GT_GearStart(_bit(2, 3, 4, 11)), gt.GT_FollowStart(_bit(6, 7), 0))


GEAR: Script = [
    (0, _gear_setup),
    (45, lambda: gt.GT_SetGearRatio(3, 1, 2, 600)),  # mid-table, while geared
    (40, lambda: gt.GT_Stop(_bit(1), 0)),  # the master of a cluster stops
    (70, lambda: _trap(1, -20_000, 5.0, 0.3)),  # and moves again
    (35, lambda: gt.GT_Stop(_bit(3), _bit(3))),  # a slave in the middle of a chain
    (50, lambda: gt.GT_Stop(_bit(6), 0)),
    (40, lambda: gt.GT_ClrSts(1, AXES)),
]


# --- the compiled slaves (bank_slaves) -------------------------------------------------------
def _cam(a: int, master: int, points: list[tuple[int, float, int]], loop: int, d: int = 0) -> None:
    _ok(gt.GT_PrfFollow(a, d), "PrfFollow")
    _ok(gt.GT_SetFollowMaster(a, master, gt.FOLLOW_MASTER_PROFILE, 0), "SetFollowMaster")
    gt.GT_FollowClear(a, 0)
    for m, sv, kind in points:
        _ok(gt.GT_FollowData(a, m, sv, kind, 0), "FollowData")
    _ok(gt.GT_SetFollowLoop(a, loop), "SetFollowLoop")


def _slaves_setup() -> object:
    """Slaves of two Trap masters with ratios, clutches and cams whose values are not powers
    of two (an operation done in another order gives other bits): Gear with a clutch both
    ways and one way, cams of every segment type, forwards and backwards, a one-point cam, a
    cam that ends after its passes, a slave waiting for a pass event (Python until its cluster
    is taken again), masters numbered below and above their slaves."""
    _trap(1, 9_000, 23.7, 0.37, 7)
    _trap(9, -7_000, 19.3, 0.29)
    _gear(2, 1, gt.GEAR_MASTER_PROFILE, (7, 3, 997))
    _gear(3, 1, gt.GEAR_MASTER_PROFILE, (3, -5, 0), -1)
    kinds = (0, 1, 3, 2, 0, 0, 1)
    cam = [
        (173 * (k + 1) + 11 * k * k, 97.3 * (k + 1) - 41.9 * (k % 3), kinds[k]) for k in range(7)
    ]
    _cam(4, 1, cam, 2)  # ends after two passes
    _cam(5, 9, [(-211 * (k + 1), 61.7 * (k + 1) ** 1.5, k % 3) for k in range(5)], 0)
    _gear(6, 9, gt.GEAR_MASTER_PROFILE, (11, 13, 2001))
    _cam(7, 1, cam, 0)
    _ok(gt.GT_SetFollowEvent(7, gt.FOLLOW_EVENT_PASS, 1, 1_500), "SetFollowEvent")
    _cam(8, 9, [(-377, 211.9, 0)], 0, -1)  # one point: a pass every 377 pulses
    _cam(10, 9, [(-300 * (k + 1), 77.7 * k, 3) for k in range(4)], 2)
    return (gt.GT_GearStart(_bit(2, 3, 6)), gt.GT_FollowStart(_bit(4, 5, 7, 8, 10), 0))


def _follow_loops() -> tuple:
    out = []
    for a in (4, 5, 7, 8, 10):
        v = c_long()
        out.append((gt.GT_GetFollowLoop(a, byref(v)), v.value))
    return out


SLAVES: Script = [
    (0, _slaves_setup),
    (57, lambda: gt.GT_SetGearRatio(2, 9, -4, 1_501)),  # a clutch from ratio 3/7 to -4/9
    (41, _follow_loops),  # every cam slave back to its planner mid-table, then taken again
    (66, lambda: _trap(1, 1_000, 17.1, 0.41)),  # master 1 turns back: the cams run backwards
    (150, lambda: gt.GT_Stop(_bit(5), 0)),
    (40, lambda: gt.GT_FollowStart(_bit(5), 0)),  # again, from where it stopped
    (60, _follow_loops),
]


# --- coordinated motion ---------------------------------------------------------------------
def _crd_system(crd: int, axes: tuple[int, int], io: bool, laps: int) -> None:
    prm = gt.TCrdPrm()
    prm.dimension = 2
    prm.profile[axes[0] - 1], prm.profile[axes[1] - 1] = 1, 2
    prm.synVelMax, prm.synAccMax = 100.0, 2.0
    _ok(gt.GT_SetCrdPrm(crd, byref(prm)), "SetCrdPrm")
    _ok(gt.GT_CrdClear(crd, 0), "CrdClear")
    v, acc = 8.0 + 2 * crd, 0.4
    for lap in range(laps):
        _ok(gt.GT_LnXY(crd, 300, 0, v, acc, v, 0), "LnXY")
        _ok(gt.GT_ArcXYC(crd, 300, 300, 0, 150, 1, v, acc, v, 0), "ArcXYC")
        if io and lap == 0:
            _ok(gt.GT_BufIO(crd, gt.MC_GPO, 0x3, 0x1, 0), "BufIO")
        if crd == 1 and lap == 1:
            _ok(gt.GT_BufDelay(crd, 7, 0), "BufDelay")
        _ok(gt.GT_LnXY(crd, 0, 300, v, acc, v, 0), "LnXY")
        _ok(gt.GT_ArcXYC(crd, 0, 0, 0, -150, 1, v, acc, 0.0, 0), "ArcXYC")


def _crd_setup() -> object:
    _crd_system(1, (1, 2), False, 2)
    _crd_system(2, (3, 4), True, 4)
    gt.GT_SetSoftLimit(4, 1 << 30, -(1 << 30))
    gt.GT_SetSoftLimit(2, 290, -(1 << 30))  # crossed on the first lap's arc
    for a in range(5, AXES + 1):
        _trap(a, 10_000 * (a - 4), 2.0 + a, 0.3)
    return gt.GT_CrdStart(0b11, 0)


def _crd_again() -> object:
    gt.GT_SetSoftLimit(2, 1 << 30, -(1 << 30))
    gt.GT_ClrSts(1, AXES)
    _crd_system(1, (1, 2), False, 1)
    return gt.GT_CrdStart(1, 0)


def _crd_status() -> tuple:
    out = []
    for crd in (1, 2):
        run, seg = c_short(), c_long()
        out.append((gt.GT_CrdStatus(crd, byref(run), byref(seg), 0), run.value, seg.value))
    return tuple(out)


CRD: Script = [
    (0, _crd_setup),
    (150, _crd_status),
    (60, _crd_again),
    (90, lambda: gt.GT_Stop(_bit(3), 0)),  # a smooth stop of system 2 along its path
    (60, _crd_status),
]


def _look(size: int) -> tuple:
    """test_bank's sample and every axis's planned acceleration."""
    acc = (c_double * AXES)()
    gt.GT_GetPrfAcc(1, acc, AXES)
    return (_sample(size), tuple(acc))


def _play(script: Script, size: int, chunked: bool, trace: list) -> None:
    """Run ``script`` ((wait, action) pairs), its looks into ``trace``: after every cycle,
    or at the end of each wait when ``chunked``; each action's result after its wait."""
    for wait, action in script:
        if chunked:
            if wait:
                gt.GTE_Wait(wait)
            trace.append(_look(size))
        else:
            for _ in range(wait):
                gt.GTE_Wait(1)
                trace.append(_look(size))
        trace.append(("call", action()))


def _run(
    script: Script, machine: str, bank: str, chunked: bool = False, kernel: str = "c"
) -> tuple[list, int]:
    """The script's trace (every cycle, or the end of each wait when ``chunked``) and the
    samples the bank stepped ahead; ``kernel``: the bank's cycle compiled or numpy alone."""
    old = os.environ.get("GTECAT_BANK_KERNEL")
    os.environ["GTECAT_BANK_KERNEL"] = kernel
    try:
        _bring_up(machine, bank)
    finally:
        if old is None:
            del os.environ["GTECAT_BANK_KERNEL"]
        else:
            os.environ["GTECAT_BANK_KERNEL"] = old
    ctl = gt.GTE_Controller()
    size = ctl.layout.gt_raw_bytes
    trace: list = []
    try:
        _play(script, size, chunked, trace)
        gt.GTE_Wait(20)
        trace.append(_look(size))
        trace.append(_loops())
        trace.append(_crd_status())
        trace.append(
            tuple(
                (ch.mech.pos, ch.mech.vel, ch.statusword)
                for s in ctl.backend.slaves
                for ch in getattr(s, "channels", [])
            )
        )
        got = ctl.bank.sampled_samples if ctl.bank is not None else 0
        sf = ctl.bank.__dict__.get("_slave_fill") if ctl.bank is not None else None
        COMPILED_SLAVES[0] = sf.samples if sf else 0
        cf = ctl.bank.__dict__.get("_crd_fill") if ctl.bank is not None else None
        COMPILED_CRD[0] = cf.samples if cf else 0
    finally:
        gt.GT_Close()
    return trace, got


#: the scalar path's runs by (run function, script, machine, chunked), with what they were
#: made of (kept alive: the key holds their ids)
_REFERENCES: dict[tuple, tuple[object, object, object]] = {}


def reference(run: Callable[..., Any], script: object, machine: str, chunked: bool) -> Any:
    """``run(script, machine, "off", chunked)``, made once per test run: the tests that compare
    two bank modes (compiled, numpy) with the same script share the scalar path's trace, which
    the lockstep clock makes the same every time (the tests only read it)."""
    key = (id(run), id(script), machine, chunked)
    if key not in _REFERENCES:
        _REFERENCES[key] = (run, script, run(script, machine, "off", chunked))
    return _REFERENCES[key][2]


#: the samples of the last _run's compiled slaves (bank_slaves.SlaveFill)
COMPILED_SLAVES = [0]
#: ... and of its compiled coordinate-system segments (bank_crd.CrdFill)
COMPILED_CRD = [0]


@pytest.fixture(scope="module")
def machine(tmp_path_factory: pytest.TempPathFactory) -> str:
    return _machine_file(Path(tmp_path_factory.mktemp("modes")))


_CHUNKED = pytest.mark.long("the script again in short waits")


@pytest.mark.parametrize(
    ("script", "least", "chunked"),
    [
        (PT, 800, False),
        pytest.param(PT, 800, True, marks=_CHUNKED),
        (GEAR, 1500, False),
        (GEAR, 1500, True),  # the default run's one script in short waits
        (CRD, 800, False),
        pytest.param(CRD, 800, True, marks=_CHUNKED),
        (EDGE, 300, False),
        (SLAVES, 2500, False),
        pytest.param(SLAVES, 2500, True, marks=_CHUNKED),
    ],
    ids=[
        "pt",
        "pt-chunked",
        "gear-follow",
        "gear-follow-chunked",
        "crd",
        "crd-chunked",
        "edge",
        "slaves",
        "slaves-chunked",
    ],
)
def test_modes_in_the_bank_match_the_scalar_path(machine, script, least, chunked) -> None:
    if script is CRD:
        bank_crd.library()  # (its build waited for: the bank takes it from its first table)
    ref, none = reference(_run, script, machine, chunked)
    assert none == 0
    got, samples = _run(script, machine, "on", chunked)
    for k, (a, b) in enumerate(zip(ref, got, strict=True)):
        assert a == b, f"step {k}: the bank and the scalar path differ"
    assert samples >= least, "the bank hardly ran this mode"
    if script is SLAVES:
        assert COMPILED_SLAVES[0] >= 1500, "the compiled slaves hardly ran"
    if script is CRD and bank_crd.library()[0] is not None:
        assert COMPILED_CRD[0] >= 300, "the compiled segments hardly ran"


@pytest.mark.parametrize("script", [PT, GEAR, CRD], ids=["pt", "gear-follow", "crd"])
@pytest.mark.sample(1)
def test_modes_in_the_numpy_bank_match_the_scalar_path(machine, script) -> None:
    """The same without the compiled cycle (no C compiler): numpy runs the bank's cycle and
    Python every table."""
    ref, _ = reference(_run, script, machine, True)
    got, samples = _run(script, machine, "on", True, kernel="numpy")
    assert got == ref
    assert samples >= 500


# --- coordinated motion polled every cycle ----------------------------------------------------
def _crd_reads() -> tuple:
    """Every read call of both systems (and of their axes), as a field application polls them
    after each cycle: the bank answers them from its record of the cycle (CoordSystem.now)."""
    out: list = []
    run, seg, space = c_short(), c_long(), c_long()
    vel = c_double()
    for crd in (1, 2):
        for fifo in (0, 1):
            out.append((gt.GT_CrdStatus(crd, byref(run), byref(seg), fifo), run.value, seg.value))
            out.append((gt.GT_CrdSpace(crd, byref(space), fifo), space.value))
            out.append((gt.GT_GetRemainderSegNum(crd, byref(seg), fifo), seg.value))
        pos = (c_double * 2)()
        out.append((gt.GT_GetCrdPos(crd, pos), tuple(pos)))
        out.append((gt.GT_GetCrdVel(crd, byref(vel)), vel.value))
    out.append(gt.GT_CrdStatus(1, byref(run), byref(seg), 2))  # a FIFO that does not exist
    sts, prf, pv = (c_long * 4)(), (c_double * 4)(), (c_double * 4)()
    out.append((gt.GT_GetSts(1, sts, 4), tuple(sts)))
    out.append((gt.GT_GetPrfPos(1, prf, 4), tuple(prf)))
    out.append((gt.GT_GetPrfVel(1, pv, 4), tuple(pv)))
    return tuple(out)


def _polled_setup() -> object:
    _crd_system(1, (1, 2), False, 2)  # a delay in its second lap
    _crd_system(2, (3, 4), True, 3)  # a GT_BufIO in its first lap: scalar until it passes
    # axis 5 geared to system 2's X: that system's cluster is stepped cycle by cycle with the
    # slave (system 1 alone: CoordSystem.run)
    _gear(5, 3, gt.GEAR_MASTER_PROFILE, (1, 2, 0))
    for a in range(6, AXES + 1):
        _trap(a, 10_000 * (a - 4), 2.0 + a, 0.3)
    return (gt.GT_GearStart(_bit(5)), gt.GT_CrdStart(0b11, 0))


#: (cycle, a call that changes a running path) of the polled program
POLLED_CALLS: list[tuple[int, Callable[[], object]]] = [
    (0, _polled_setup),
    # segments streamed onto system 1's running FIFO (kept in the bank: pushed ahead), a
    # delay, a segment into its other FIFO (given back), a line of no length
    *[
        (100 + 5 * k, lambda k=k: gt.GT_LnXY(1, 40 * (k % 2), 40 * k, 9.0, 0.4, 9.0, 0))
        for k in range(6)
    ],
    (131, lambda: gt.GT_BufDelay(1, 3, 0)),
    (140, lambda: gt.GT_LnXY(1, 0, 0, 9.0, 0.4, 0.0, 1)),
    (145, lambda: gt.GT_LnXY(1, 40, 200, 9.0, 0.4, 0.0, 0)),
    (150, lambda: gt.GT_LnXY(1, 40, 200, 9.0, 0.4, 0.0, 0)),
    (170, lambda: gt.GT_LnXY(1, 100, 100, 9.0, 0.4, 0.0, 0)),
    # near the end of system 1's path: pushes the bank's window may reach (given back then)
    *[(440 + 12 * k, lambda k=k: gt.GT_LnXY(1, 60 * k, 0, 9.0, 0.4, 9.0, 0)) for k in range(6)],
    (230, lambda: gt.GT_SetOverride(2, 1.5)),
    (330, lambda: gt.GT_Stop(1 << 13, 0)),  # system 2 stops along its path
]


def _run_polled(
    machine: str, bank: str
) -> tuple[list, list[tuple[bool, bool]], int, dict[int, bool]]:
    """The polled program's reads after every cycle; on the bank, whether each system was in
    it at each poll, the samples it stepped, and whether system 1 was still in it right after
    each call (before the cycle that follows)."""
    _bring_up(machine, bank)
    ctl = gt.GTE_Controller()
    calls = dict(POLLED_CALLS)
    trace: list = []
    banked: list[tuple[bool, bool]] = []
    after_call: dict[int, bool] = {}
    try:
        for k in range(540):
            action = calls.get(k)
            if action is not None:
                trace.append(("call", action()))
                after_call[k] = ctl.crd_bank.systems[1].banked
            gt.GTE_Wait(1)
            trace.append(_crd_reads())
            systems = ctl.crd_bank.systems
            banked.append((systems[1].banked, systems[2].banked))
        got = ctl.bank.sampled_samples if ctl.bank is not None else 0
    finally:
        gt.GT_Close()
    return trace, banked, got, after_call


def test_crd_reads_polled_every_cycle_match_the_scalar_path_without_a_release(machine) -> None:
    """GT_CrdStatus, GT_CrdSpace, GT_GetRemainderSegNum, GT_GetCrdPos, GT_GetCrdVel and the
    axes' GT_GetSts/GT_GetPrfPos/GT_GetPrfVel after every cycle: the bank's answers equal the
    scalar path's, and the polling keeps the systems in the bank (a call that changes one
    system's path gives back that system alone)."""
    ref, _, _, _ = _run_polled(machine, "off")
    got, banked, samples, after_call = _run_polled(machine, "on")
    for k, (a, b) in enumerate(zip(ref, got, strict=True)):
        assert a == b, f"step {k}: the bank and the scalar path differ"
    assert samples >= 500, "the bank hardly ran the paths"
    # system 1 is in the bank from its first cycles to its end (a call that gives it back:
    # the bank takes it again before the next cycle); system 2 from the end of its first lap
    # (the GT_BufIO) to its stop
    assert sum(b[0] for b in banked[:300]) >= 280
    assert sum(b[1] for b in banked[160:330]) >= 165
    assert banked[170][1] and banked[171][1], "a call on system 1 gave back system 2"
    for k in (100, 105, 110, 115, 120, 125, 131, 145, 150, 170):
        assert banked[k - 1][0] and after_call[k], f"the push at cycle {k} gave back system 1"
    assert not after_call[140], "a push into the FIFO that does not run stays in the bank"
    assert banked[140][0], "system 1 given back by a call is not taken again"
