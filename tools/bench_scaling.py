"""Real-time factor against the number of axes (1..128), idle, moving and homing, as JSON.

    python tools/bench_scaling.py [--axes 1,12,64] [--states idle,moving] [--seconds 1.5]
    python tools/bench_scaling.py --plot docs/performance.png --table docs/performance.md

Each (axes, state) point opens a fresh controller on a generated bus of N single-axis
CSP drives (:mod:`tools.gen_axes_eni`) with the lockstep clock, brings it up with
``GT_InitEcatComm`` / ``GT_IsEcatReady`` / ``GT_StartEcatComm``, enables every axis and
puts it in the state, then lets controller time pass with ``GTE_Wait`` and counts the
1 ms cycles per wall second (best of ``--repeat`` windows).  States:

* ``idle``: enabled and holding (``GT_AxisOn``, nothing planned);
* ``moving``: Trap, smoothTime 25, every axis a move far longer than the measurement;
* ``homing``: drive homing method 17 (negative limit switch) through
  ``GT_SetHomingMode`` / ``GT_SetEcatHomingPrm`` / ``GT_StartEcatHoming``; the machine
  description puts each axis's negative limit a billion counts away, so the search
  outlasts the measurement;
* ``homed6`` (not in the default set): drive homing method 35 run to its end, the drives
  left in homing mode 6 (an application that never switches back to CSP);
* ``pt``, ``gear``, ``follow``, ``crd`` (not in the default set): PT over a static FIFO
  looped endlessly; per core a Trap master and the other axes in Gear / Follow on it;
  per core two XY coordinate systems on a path of lines and arcs, the other axes holding
  (:func:`start_pt`, :func:`start_gear`, :func:`start_follow`, :func:`start_crd`).

Everything goes through the public GT API, axis by axis through :func:`core_axis`
and the ``GTN_*`` functions: the real ``GT_Update(long mask)`` reaches 32 axes per
core, so bus axis 33..64 is axis 1..32 of core 2, 65..96 of core 3, 97..128 of core 4
(issue 17 item 4).  A point whose core does not exist is reported with an ``error``
and no figures, never measured some other way.  ``--addressing flat`` keeps every
axis on core 1 instead (what the emulator accepted before issue 17: idle and homing
beyond axis 32 work, a Trap start there does not, as ``GT_Update`` takes 32 bits);
the JSON says which addressing ran.  ``tools/bench.py`` builds on :func:`run_bus`.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from collections.abc import Callable, Mapping, Sequence
from ctypes import byref, c_double, c_long, c_short, c_ulong, c_ushort
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from tools.gen_axes_eni import write_axes_eni  # noqa: E402

AXES = (1, 2, 4, 8, 12, 16, 32, 64, 96, 128)
STATES = ("idle", "moving", "homing")
#: the other motion modes (``--states pt,pvt,gear,follow,crd,screw``): see their ``start_*``
MODES = ("pt", "pvt", "gear", "follow", "crd", "homed6", "screw")
AXES_PER_CORE = 32
#: axes per core that :func:`core_axis` uses; ``--addressing flat`` puts every axis on
#: core 1 (the emulator's own extension before issue 17: no GT_Update beyond axis 32)
ADDRESSING = {"cores": AXES_PER_CORE, "flat": 1 << 16}
_per_core = AXES_PER_CORE
STS_SERVO_ON = 1 << 9  # GT_GetSts bits (manual table 6-1)
STS_MOVING = 1 << 10
STS_ALARM = 1 << 1
HOMING_METHOD = 17  # CiA 402: search the negative limit switch
HOMING_IN_PROGRESS = 0
FAR = 1_000_000_000.0  # counts to the negative limit: the homing search never ends here
#: controller ms all the windows of a homing bus may take together: the drive's search
#: gives up after gtecat.drives.homing.DEFAULT_TIMEOUT_S (300 s), which a fast machine
#: reached within three windows of 1.5 s
HOMING_WINDOW_MS = 240_000
#: the shortest of start_trap's moves (50,000,000 counts at 31 counts/ms at the most) and
#: the controller time the windows of a moving bus take together, well within it
TRAP_MOVE_MS = 50_000_000 // 31
TRAP_WINDOW_MS = TRAP_MOVE_MS // 2
WARM_UP_MS = 50
CHUNK_MS = 20


class BenchError(RuntimeError):
    """A GT call of the set-up failed; the message names it and gives its reason."""


class CoreUnavailable(BenchError):
    """An axis beyond 32 needs a core (``GTN_*(2, ...)``) the controller does not have."""


def core_axis(a: int) -> tuple[int, int]:
    """Bus axis ``a`` (1-based) as (core, axis on that core): 32 axes per core."""
    if a < 1:
        raise ValueError(f"axis must be >= 1, not {a}")
    return (a - 1) // _per_core + 1, (a - 1) % _per_core + 1


def set_addressing(mode: str) -> None:
    """``cores`` (32 axes per core, the default) or ``flat`` (every axis on core 1)."""
    global _per_core
    _per_core = ADDRESSING[mode]


def _gt() -> Any:
    from gtecat import gt

    return gt


def _ok(rc: int, what: str, core: int = 1) -> None:
    if rc == 0:
        return
    reason = _gt().GTE_GetLastError() or f"{what} returned {rc}"
    if core > 1 and f"core {core}" in reason:
        raise CoreUnavailable(
            f"{what}: {reason} - bus axes beyond {AXES_PER_CORE} are reached through "
            f"core {core} (GTN_*({core}, axis)), which this controller does not offer"
            "; nothing was measured"
        )
    raise BenchError(f"{what}: {reason}")


def gtn(name: str, a: int, *args: Any) -> None:
    """Call ``GTN_<name>(core, local_axis, *args)`` for bus axis ``a``; raise on non-zero."""
    core, local = core_axis(a)
    fn: Callable[..., int] = getattr(_gt(), "GTN_" + name)
    _ok(fn(core, local, *args), f"GTN_{name}({core}, {local}) for bus axis {a}", core)


def update(axes: Sequence[int]) -> None:
    """``GTN_Update(core, mask)`` once per core for the bus axes given."""
    masks: dict[int, int] = {}
    for a in axes:
        core, local = core_axis(a)
        masks[core] = masks.get(core, 0) | 1 << (local - 1)
    for core, mask in sorted(masks.items()):
        _ok(_gt().GTN_Update(core, mask), f"GTN_Update({core}, {mask:#x})", core)


def status(a: int) -> int:
    """``GTN_GetSts`` of bus axis ``a``."""
    sts = c_long()
    gtn("GetSts", a, byref(sts))
    return sts.value


def homing_status(a: int) -> int:
    """``GTN_GetEcatHomingStatus`` of bus axis ``a``."""
    st = c_short()
    gtn("GetEcatHomingStatus", a, byref(st))
    return st.value


def machine(n: int) -> Any:
    """Every axis at 0 with a negative limit switch :data:`FAR` counts away."""
    from gtecat.drives.machine import AxisMachine, MachineDescription

    return MachineDescription({a: AxisMachine(negative_limit=-FAR) for a in range(1, n + 1)})


def bring_up(eni: Path, n: int, bank: str | None = None, description: Any = None) -> None:
    """Open the controller on ``eni`` (lockstep clock) and take the bus to OP; ``bank``:
    GT_Open's ``bank`` (None: its default, ``off``: the scalar path alone); ``description``:
    the machine (None: :func:`machine`)."""
    gt = _gt()
    gt.GT_Close()
    opts = {} if bank is None else {"bank": bank}
    mach = machine(n) if description is None else description
    rc = gt.GT_Open(eni=str(eni), machine=mach, clock="lockstep", log="", **opts)
    _ok(rc, "GT_Open")
    _ok(gt.GT_InitEcatComm(), "GT_InitEcatComm")
    ready = c_short()
    for _ in range(10_000):
        if gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1:
            break
        gt.GTE_Wait(1)
    else:
        raise BenchError("the bus did not become ready in 10 s of controller time")
    _ok(gt.GT_StartEcatComm(), "GT_StartEcatComm")


def start_trap(axes: Sequence[int]) -> None:
    """Every axis a Trap move (smoothTime 25) far longer than any measurement."""
    gt = _gt()
    for a in axes:
        prm = gt.TTrapPrm()
        prm.acc, prm.dec, prm.velStart, prm.smoothTime = 0.5, 0.5, 0, 25
        gtn("PrfTrap", a)
        gtn("SetTrapPrm", a, byref(prm))
        gtn("SetPos", a, (-1) ** a * 50_000_000)
        gtn("SetVel", a, 20 + a % 12)
    update(axes)


def start_trap_lead_screw(axes: Sequence[int]) -> None:
    """:func:`start_trap` with lead-screw compensation on every axis: 11 points over 100000
    pulses from 0, a table for each direction (GT_SetLeadScrewComp, GT_EnableLeadScrewComp)."""
    pos = (c_long * 11)(*[(-1) ** k * 5 * k for k in range(11)])
    neg = (c_long * 11)(*[3 * k for k in range(11)])
    for a in axes:
        gtn("SetLeadScrewComp", a, 11, 0, 100_000, pos, neg)
        gtn("EnableLeadScrewComp", a, 1)
    start_trap(axes)


def start_homing(axes: Sequence[int]) -> None:
    """Drive homing method 17 on every axis (5000 / 1000 counts/s, 100000 counts/s²)."""
    for a in axes:
        gtn("SetHomingMode", a, 6)
        gtn("SetEcatHomingPrm", a, HOMING_METHOD, 5000, 1000, 100000, 0, 0)
    for a in axes:
        gtn("StartEcatHoming", a)


def start_homed_mode6(axes: Sequence[int]) -> None:
    """Drive homing method 35 (the current position) on every axis, run to its end; the
    drives are left in homing mode 6 (no ``GT_SetHomingMode(axis, 8)`` after it)."""
    for a in axes:
        gtn("SetHomingMode", a, 6)
        gtn("SetEcatHomingPrm", a, 35, 4000, 800, 100000, 0, 0)
    for a in axes:
        gtn("StartEcatHoming", a)
    _gt().GTE_Wait(100)
    left = [a for a in axes if homing_status(a) != HOMING_DONE]
    if left:
        raise BenchError(f"{len(left)} axes did not finish homing: {left[:8]}")


HOMING_DONE = 3


def start_pt(axes: Sequence[int], points: int = 400) -> None:
    """PT, static FIFO, endless loop over a table of ``points`` 10 ms segments (a there
    and back ramp of 20000 pulses), on every axis."""
    gt = _gt()
    for a in axes:
        gtn("PrfPt", a, gt.PT_MODE_STATIC)
        gtn("PtClear", a, 0)
        gtn("SetPtLoop", a, 0)
        space = c_short()
        gtn("PtSpace", a, byref(space), 0)
        half = min(points, space.value) // 2
        for k in range(1, 2 * half + 1):
            pos = 20000.0 * (k if k <= half else 2 * half - k) / half
            gtn("PtData", a, pos, 10 * k, gt.PT_SEGMENT_NORMAL, 0)
    masks: dict[int, int] = {}
    for a in axes:
        core, local = core_axis(a)
        masks[core] = masks.get(core, 0) | 1 << (local - 1)
    for core, mask in sorted(masks.items()):
        _ok(gt.GTN_PtStart(core, mask, 0), f"GTN_PtStart({core}, {mask:#x})", core)


def start_pvt(axes: Sequence[int]) -> None:
    """PVT, endless loop (``GT_SetPvtLoop(a, 0)``) over one table per core of 3 points
    (0, 500, 1000 ms; 0, 5000, 0 pulses; at rest at each), on every axis."""
    gt = _gt()
    t, p, v = (c_double * 3)(0, 500, 1000), (c_double * 3)(0, 5000, 0), (c_double * 3)(0, 0, 0)
    groups = by_core(axes)
    for core in groups:
        _ok(gt.GTN_PvtTable(core, 1, 3, t, p, v), f"GTN_PvtTable({core}, 1)", core)
    for a in axes:
        gtn("PrfPvt", a)
        gtn("PvtTableSelect", a, 1)
        gtn("SetPvtLoop", a, 0)
    for core, on_core in sorted(groups.items()):
        mask = sum(1 << (core_axis(a)[1] - 1) for a in on_core)
        _ok(gt.GTN_PvtStart(core, mask), f"GTN_PvtStart({core}, {mask:#x})", core)


def by_core(axes: Sequence[int]) -> dict[int, list[int]]:
    """The bus axes of ``axes`` grouped by their core, in axis order."""
    out: dict[int, list[int]] = {}
    for a in sorted(axes):
        out.setdefault(core_axis(a)[0], []).append(a)
    return out


def _master_trap(a: int) -> None:
    """Bus axis ``a`` a Trap move in the positive direction, far longer than any measurement."""
    prm = _gt().TTrapPrm()
    prm.acc, prm.dec, prm.velStart, prm.smoothTime = 0.5, 0.5, 0, 25
    gtn("PrfTrap", a)
    gtn("SetTrapPrm", a, byref(prm))
    gtn("SetPos", a, 50_000_000)
    gtn("SetVel", a, 20)
    update([a])


def _start_slaves(axes: Sequence[int], setup: Callable[[int, int], None], start: str) -> None:
    """Per core: the first axis of ``axes`` is the master (a Trap move), the others are set
    up as its slaves by ``setup(bus_axis, master_profile)`` and started together with
    ``GTN_<start>(core, mask)``."""
    gt = _gt()
    for core, group in sorted(by_core(axes).items()):
        master, slaves = group[0], group[1:]
        _master_trap(master)
        local = core_axis(master)[1]
        mask = 0
        for a in slaves:
            setup(a, local)
            mask |= 1 << (core_axis(a)[1] - 1)
        if mask:
            fn = getattr(gt, "GTN_" + start)
            args = (core, mask) if start == "GearStart" else (core, mask, 0)
            _ok(fn(*args), f"GTN_{start}({core}, {mask:#x})", core)


def start_gear(axes: Sequence[int]) -> None:
    """Per core, the first axis moves in Trap and every other axis follows its planned
    position in Gear (slave : master = 1 : 2, a 4000-pulse clutch zone)."""
    gt = _gt()

    def setup(a: int, master: int) -> None:
        gtn("PrfGear", a, 0)
        gtn("SetGearMaster", a, master, gt.GEAR_MASTER_PROFILE, 0)
        gtn("SetGearRatio", a, 2, 1, 4000)

    _start_slaves(axes, setup, "GearStart")


#: the cam of the Follow figure: (master, slave, type) points of one pass, 16 segments
#: of 2000 master pulses up 8000 pulses and back (the FIFO's default 16 points)
FOLLOW_CAM = tuple((2000 * (k + 1), 1000.0 * min(k + 1, 15 - k), 0) for k in range(16))


def start_follow(axes: Sequence[int]) -> None:
    """Per core, the first axis moves in Trap and every other axis follows its planned
    position in Follow over :data:`FOLLOW_CAM`, looped endlessly (FIFO 0)."""
    gt = _gt()

    def setup(a: int, master: int) -> None:
        gtn("PrfFollow", a, 0)
        gtn("SetFollowMaster", a, master, gt.FOLLOW_MASTER_PROFILE, 0)
        gtn("FollowClear", a, 0)
        for m, s, kind in FOLLOW_CAM:
            gtn("FollowData", a, m, s, kind, 0)
        gtn("SetFollowLoop", a, 0)

    _start_slaves(axes, setup, "FollowStart")


#: coordinate systems per core (GT_SetCrdPrm's crd 1..2)
CRD_SYSTEMS = 2
#: laps of the crd figure's path (4 segments each: line, half circle, line, half circle)
CRD_LAPS = 250


def crd_plan(n: int) -> dict[int, str]:
    """The crd figure's plan for ``n`` axes: on each core, local axes 1-2 are coordinate
    system 1 and 3-4 system 2 (the controller's two per core); the other axes hold."""
    plan = dict.fromkeys(range(1, n + 1), "idle")
    for a in plan:
        if core_axis(a)[1] <= 2 * CRD_SYSTEMS:
            plan[a] = "crd"
    return plan


def start_crd(axes: Sequence[int]) -> None:
    """Pairs of ``axes`` on one core as XY coordinate systems 1, 2 (at most two per core),
    each running :data:`CRD_LAPS` laps of a 10000 x 10000 stadium (lines and half circles,
    tangent joints passed at speed: synVel 20, synAcc 0.5, velEnd 20)."""
    gt = _gt()
    for core, group in sorted(by_core(axes).items()):
        mask = 0
        for crd in range(1, CRD_SYSTEMS + 1):
            pair = group[2 * crd - 2 : 2 * crd]
            if len(pair) < 2:
                break
            prm = gt.TCrdPrm()
            prm.dimension = 2
            for c, a in enumerate(pair, 1):
                prm.profile[core_axis(a)[1] - 1] = c
            prm.synVelMax, prm.synAccMax = 100.0, 2.0
            _ok(gt.GTN_SetCrdPrm(core, crd, byref(prm)), f"GTN_SetCrdPrm({core}, {crd})", core)
            _ok(gt.GTN_CrdClear(core, crd, 0), f"GTN_CrdClear({core}, {crd})", core)
            v, acc = 20.0, 0.5
            for _ in range(CRD_LAPS):
                for rc, what in (
                    (gt.GTN_LnXY(core, crd, 10_000, 0, v, acc, v, 0), "LnXY"),
                    (gt.GTN_ArcXYC(core, crd, 10_000, 10_000, 0, 5_000, 1, v, acc, v, 0), "Arc"),
                    (gt.GTN_LnXY(core, crd, 0, 10_000, v, acc, v, 0), "LnXY"),
                    (gt.GTN_ArcXYC(core, crd, 0, 0, 0, -5_000, 1, v, acc, v, 0), "Arc"),
                ):
                    _ok(rc, f"GTN_{what}({core}, {crd})", core)
            mask |= 1 << (crd - 1)
        if mask:
            _ok(gt.GTN_CrdStart(core, mask, 0), f"GTN_CrdStart({core}, {mask:#x})", core)


STARTERS: dict[str, Callable[[Sequence[int]], None]] = {
    "homed6": start_homed_mode6,  # (first: the moving axes of a mixed plan start after it)
    "moving": start_trap,
    "homing": start_homing,
    "pt": start_pt,
    "pvt": start_pvt,
    "screw": start_trap_lead_screw,
    "gear": start_gear,
    "follow": start_follow,
    "crd": start_crd,
}


def check(plan: Mapping[int, str]) -> None:
    """Raise unless every axis is still in its planned state."""
    bad = []
    for a, state in plan.items():
        sts = status(a)
        ok = bool(sts & STS_SERVO_ON) and not sts & STS_ALARM
        if state == "idle":
            ok = ok and not sts & STS_MOVING
        elif state == "homed6":
            ok = ok and not sts & STS_MOVING and homing_status(a) == HOMING_DONE
        elif state == "homing":
            ok = ok and homing_status(a) == HOMING_IN_PROGRESS
        else:
            ok = ok and bool(sts & STS_MOVING)
        if not ok:
            bad.append(f"{a} ({state}, sts {sts:#x})")
    if bad:
        raise BenchError(f"{len(bad)} axes left their state: {', '.join(bad[:8])}")


def _clock() -> tuple[int, int]:
    clk, loop = c_ulong(), c_ulong()
    _ok(_gt().GT_GetClock(byref(clk), byref(loop)), "GT_GetClock")
    return clk.value, loop.value


def measure(seconds: float, repeat: int, limit_ms: float | None = None) -> dict[str, float]:
    """Let controller time pass for ``repeat`` windows of ``seconds / repeat`` wall
    seconds each (``limit_ms``: or that much controller time, whichever ends first); the
    fastest window's cycles per wall second and controller milliseconds per wall
    millisecond (and per CPU millisecond of this process)."""
    gt = _gt()
    window = seconds / max(1, repeat)
    best: tuple[float, float, float] = (0.0, 0.0, 0.0)
    for _ in range(max(1, repeat)):
        ms0, loop0 = _clock()
        t0, c0 = time.perf_counter(), time.process_time()
        waited = 0
        while True:
            gt.GTE_Wait(CHUNK_MS)
            waited += CHUNK_MS
            el = time.perf_counter() - t0
            if el >= window or (limit_ms is not None and waited >= limit_ms):
                break
        cpu = max(time.process_time() - c0, 1e-9)
        ms1, loop1 = _clock()
        cps = (loop1 - loop0) / el
        if cps > best[0]:
            best = (cps, (ms1 - ms0) / 1000 / el, (ms1 - ms0) / 1000 / cpu)
    return {"cycles_per_s": best[0], "rtf": best[1], "rtf_cpu": best[2]}


def run_bus(
    n: int,
    plan: Mapping[int, str],
    *,
    seconds: float = 1.5,
    repeat: int = 3,
    eni_dir: str | Path | None = None,
    after: Callable[[], dict[str, Any]] | None = None,
    bank: str | None = None,
    eni_file: str | Path | None = None,
) -> dict[str, Any]:
    """Bring up ``n`` axes, put axis ``a`` in ``plan[a]`` (missing: ``idle``), measure
    (``bank``: as :func:`bring_up`).

    Returns cycles_per_s, rtf, us_per_cycle, us_per_axis, bringup_s, and whatever
    ``after()`` adds (called with the controller still open); ``error`` instead of
    the figures when an axis cannot be addressed or set up.  ``eni_file``: the bus
    already written (by :func:`write_axes_eni` for ``n`` axes), else it is written here.
    """
    full = {a: plan.get(a, "idle") for a in range(1, n + 1)}
    gt = _gt()
    with tempfile.TemporaryDirectory(dir=eni_dir) as tmp:
        eni = Path(eni_file) if eni_file else write_axes_eni(n, Path(tmp) / f"axes{n}.eni")
        t0 = time.perf_counter()
        try:
            bring_up(eni, n, bank)
            for a in full:
                gtn("AxisOn", a)
            for state, start in STARTERS.items():
                axes = [a for a, s in full.items() if s == state]
                if axes:
                    start(axes)
            gt.GTE_Wait(WARM_UP_MS)
            check(full)
            bring_s = time.perf_counter() - t0
            # a drive ends a homing search after DEFAULT_TIMEOUT_S of controller time: every
            # window of a homing bus stops short of it, however fast the machine runs
            limit = None
            if "homing" in full.values():
                limit = HOMING_WINDOW_MS / max(1, repeat)
            elif "moving" in full.values() or "screw" in full.values():
                # a Trap move ends after TRAP_MOVE_MS at the least: every window of a moving
                # bus stops short of it, however fast the machine runs
                limit = TRAP_WINDOW_MS / max(1, repeat)
            m = measure(seconds, repeat, limit)
            check(full)
            extra = after() if after is not None else {}
        except BenchError as exc:
            return {"error": str(exc)}
        finally:
            gt.GT_Close()
    us = 1e6 / m["cycles_per_s"]
    return {
        "cycles_per_s": round(m["cycles_per_s"], 1),
        "rtf": round(m["rtf"], 3),
        "rtf_cpu": round(m["rtf_cpu"], 3),
        "us_per_cycle": round(us, 2),
        "us_per_axis": round(us / n, 3),
        "bringup_s": round(bring_s, 3),
        **extra,
    }


#: smart homing (GT_GoHome) of the gohome figures: pulse, pulse/ms, pulse/ms²
GOHOME_VEL_HIGH, GOHOME_VEL_LOW, GOHOME_ACC = 20.0, 2.0, 0.5
#: how often the gohome figures look at every axis's THomeStatus (controller ms); each look
#: is 64 GT calls of 7-20 µs (the GT layer's cost, not the homing's)
GOHOME_POLL_MS = 100


def gohome_machine(n: int) -> Any:
    """Every axis at 0 with its own switches, a few hundred counts apart from axis to axis
    (so their events fall in different cycles): a home switch [40000, 44000), a positive
    limit at 70000 and a negative one at -70000, an index pulse at 1500 and every 10000
    counts, each shifted by 37 counts per axis."""
    from gtecat.drives.machine import AxisMachine, MachineDescription

    return MachineDescription(
        {
            a: AxisMachine(
                home_switch=((40_000 + 37 * a, 44_000 + 37 * a),),
                positive_limit=70_000 + 37 * a,
                negative_limit=-70_000 - 37 * a,
                counts_per_rev=10_000,
                index_offset=1_500 + 37 * a,
            )
            for a in range(1, n + 1)
        }
    )


def start_gohome(axes: Sequence[int], mode: int) -> None:
    """GT_GoHome on every axis (Trap mode first) in smart-home ``mode``, toward the positive
    side: mode 20 finds the home switch ahead (about 2 s of search), mode 11 the positive
    limit first (3.5 s), then the home switch on the way back; the index modes then look
    for the next index pulse slowly in the positive direction (in the negative one in mode
    12, which must search away from the limit), mode 30 fast for the first one ahead;
    modes 40 and 41 take the home switch for their trigger; mode 10 the positive limit itself
    (3.5 s), its home offset back off it."""
    gt = _gt()
    for a in axes:
        gtn("PrfTrap", a)
        prm = gt.THomePrm()
        index_dir = -1 if mode == 12 else 1
        prm.mode, prm.moveDir, prm.indexDir, prm.edge, prm.triggerIndex = mode, 1, index_dir, 0, -1
        prm.velHigh, prm.velLow = GOHOME_VEL_HIGH, GOHOME_VEL_LOW
        prm.acc = prm.dec = GOHOME_ACC
        # (mode 10's home is the positive limit itself: its offset goes back off it)
        prm.homeOffset, prm.escapeStep = -100 if mode == 10 else 100, 1000
        gtn("GoHome", a, byref(prm))


def run_gohome(
    n: int, mode: int, *, repeat: int = 3, bank: str | None = None, limit_ms: int = 30_000
) -> dict[str, Any]:
    """``n`` axes home with GT_GoHome in ``mode`` from start to end, ``repeat`` times (a
    fresh controller each): controller time over wall and CPU time of the whole homing,
    as an application waits for it (GTE_Wait of 20 ms, every axis's GT_GetHomeStatus every
    :data:`GOHOME_POLL_MS`); the best run counts.  ``error`` when a homing does not end in
    stage 100 without error."""
    gt = _gt()
    hs = gt.THomeStatus()

    def running(a: int) -> bool:
        gtn("GetHomeStatus", a, byref(hs))
        return bool(hs.run)

    def bad(a: int) -> str:
        gtn("GetHomeStatus", a, byref(hs))
        ok = not hs.run and hs.stage == 100 and not hs.error
        return "" if ok else f"{a} (stage {hs.stage}, error {hs.error})"

    return _run_homing(
        n, lambda axes: start_gohome(axes, mode), running, bad, repeat, bank, limit_ms
    )


#: the older cards' homing (GT_Home): the end of its search, its home offset
LEGACY_HOME_POS, LEGACY_HOME_OFFSET = 60_000, 100


def run_legacy_home(
    n: int, *, repeat: int = 3, bank: str | None = None, limit_ms: int = 30_000
) -> dict[str, Any]:
    """``n`` axes home with the older cards' calls on the machine of :func:`gohome_machine`:
    ``GT_HomeInit``, then ``GTN_Home(core, axis, 60000, velHigh, acc, 100)`` per axis (the
    home switch ahead captured, the axis back at the capture + 100), every axis's
    ``GTN_HomeSts`` every :data:`GOHOME_POLL_MS` until it gives 1, as :func:`run_gohome`;
    timed from ``GT_HomeInit`` (the start calls included).  ``error`` when one does not end
    at its target (``GT_HomeSts`` not 1, or not 0 returned)."""
    gt = _gt()
    sts = c_ushort()

    def start(axes: Sequence[int]) -> None:
        _ok(gt.GT_HomeInit(), "GT_HomeInit", 1)
        for a in axes:
            gtn("Home", a, LEGACY_HOME_POS, GOHOME_VEL_HIGH, GOHOME_ACC, LEGACY_HOME_OFFSET)

    def status(a: int) -> tuple[int, int]:
        core, local = core_axis(a)
        sts.value = 0
        return gt.GTN_HomeSts(core, local, byref(sts)), sts.value

    return _run_homing(
        n,
        start,
        lambda a: status(a) == (0, 0),
        lambda a: "" if (s := status(a)) == (0, 1) else f"{a} (rc, status {s})",
        repeat,
        bank,
        limit_ms,
        setup=True,
    )


#: drive homing (GT_SetEcatHomingPrm): 6099h:01, 6099h:02 (counts/s), 609Ah (counts/s²)
DRIVE_HOMING_SPEEDS = (20_000, 2_000, 150_000)


def run_drive_homing(
    n: int,
    method: int,
    *,
    repeat: int = 3,
    bank: str | None = None,
    limit_ms: int = 30_000,
    setup: bool = False,
) -> dict[str, Any]:
    """``n`` axes home by their drives (homing mode 6, CiA-402 ``method``) on the machine of
    :func:`gohome_machine`, start to end, as :func:`run_gohome` (every axis's
    GT_GetEcatHomingStatus every :data:`GOHOME_POLL_MS`); ``error`` when one does not end
    homed (3).  ``setup``: timed from the first GT_SetHomingMode (each axis switched to
    homing mode and given its parameters, then each started, as an application does)."""
    st = c_short()
    v1, v2, acc = DRIVE_HOMING_SPEEDS

    def start(axes: Sequence[int]) -> None:
        for a in axes:
            gtn("SetHomingMode", a, 6)
            gtn("SetEcatHomingPrm", a, method, v1, float(v2), acc, 0, 0)
        for a in axes:
            gtn("StartEcatHoming", a)

    def status(a: int) -> int:
        gtn("GetEcatHomingStatus", a, byref(st))
        return st.value

    return _run_homing(
        n,
        start,
        lambda a: status(a) == 0,
        lambda a: "" if (s := status(a)) == 3 else f"{a} (status {s})",
        repeat,
        bank,
        limit_ms,
        setup,
    )


def _run_homing(
    n: int,
    start: Callable[[Sequence[int]], None],
    running: Callable[[int], bool],
    bad: Callable[[int], str],
    repeat: int,
    bank: str | None,
    limit_ms: int,
    setup: bool = False,
) -> dict[str, Any]:
    """The homings of :func:`run_gohome` and :func:`run_drive_homing`: ``start`` on every
    axis, then wait until no axis is ``running``; ``bad`` names an axis that did not home.
    ``setup``: ``start`` timed too."""
    gt = _gt()
    best: dict[str, Any] | None = None
    with tempfile.TemporaryDirectory() as tmp:
        eni = write_axes_eni(n, Path(tmp) / f"axes{n}.eni")
        for _ in range(max(1, repeat)):
            try:
                bring_up(eni, n, bank, gohome_machine(n))
                axes = list(range(1, n + 1))
                for a in axes:
                    gtn("AxisOn", a)
                gt.GTE_Wait(WARM_UP_MS)
                if setup:
                    ms0, _ = _clock()
                    t0, c0 = time.perf_counter(), time.process_time()
                start(axes)
                if not setup:
                    ms0, _ = _clock()
                    t0, c0 = time.perf_counter(), time.process_time()
                waited = 0
                while True:
                    gt.GTE_Wait(CHUNK_MS)
                    waited += CHUNK_MS
                    if waited % GOHOME_POLL_MS:
                        continue
                    if not sum(running(a) for a in axes) or waited >= limit_ms:
                        break
                wall, cpu = time.perf_counter() - t0, max(time.process_time() - c0, 1e-9)
                ms1, _ = _clock()
                failed = [why for why in map(bad, axes) if why]
                if failed:
                    raise BenchError(f"{len(failed)} axes did not home: {', '.join(failed[:8])}")
            except BenchError as exc:
                return {"error": str(exc)}
            finally:
                gt.GT_Close()
            ms = ms1 - ms0
            r = {
                "controller_ms": ms,
                "rtf": round(ms / 1000 / wall, 3),
                "rtf_cpu": round(ms / 1000 / cpu, 3),
            }
            if best is None or r["rtf"] > best["rtf"]:
                best = r
    assert best is not None
    return best


def bench_point(n: int, state: str, *, seconds: float = 1.5, repeat: int = 3) -> dict[str, Any]:
    """One (axes, state) point: every axis in ``state``."""
    if state not in STATES + MODES:
        raise ValueError(f"state must be one of {', '.join(STATES + MODES)}, not {state!r}")
    plan = crd_plan(n) if state == "crd" else dict.fromkeys(range(1, n + 1), state)
    r = run_bus(n, plan, seconds=seconds, repeat=repeat)
    addressing = "cores" if _per_core == AXES_PER_CORE else "flat"
    return {"axes": n, "state": state, **r, "addressing": addressing}


def bench_scaling(
    axes: Sequence[int] = AXES,
    states: Sequence[str] = STATES,
    *,
    seconds: float = 1.5,
    repeat: int = 3,
    progress: Callable[[dict[str, Any]], None] | None = None,
) -> list[dict[str, Any]]:
    """Every point of ``axes`` x ``states``."""
    out = []
    for n in axes:
        for state in states:
            r = bench_point(n, state, seconds=seconds, repeat=repeat)
            if progress is not None:
                progress(r)
            out.append(r)
    return out


BEGIN, END = "<!-- bench_scaling table: begin -->", "<!-- bench_scaling table: end -->"


def _provenance() -> str:
    """When, at which commit and under what load the figures were taken."""
    import subprocess

    try:
        rev = subprocess.run(
            ["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
            capture_output=True,
            text=True,
            check=False,
        ).stdout.strip()
    except OSError:
        rev = ""
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg()) if hasattr(os, "getloadavg") else "?"
    when = time.strftime("%Y-%m-%d %H:%M")
    return f"Measured {when} at commit `{rev or '?'}`, {os.cpu_count()} CPUs, load average {load}."


def write_table(results: Sequence[Mapping[str, Any]], path: str | Path) -> None:
    """A markdown table: one row per axis count, µs per cycle and real-time factor per state.

    When ``path`` holds the :data:`BEGIN` / :data:`END` markers (``docs/performance.md``),
    only the text between them is replaced; otherwise the file is the table alone.
    """
    states = [s for s in STATES + MODES if any(r["state"] == s for r in results)]
    by = {(r["axes"], r["state"]): r for r in results}
    head = "| axes | " + " | ".join(f"{s} µs/cycle | {s} RTF" for s in states) + " |"
    rule = "|---:|" + "---:|---:|" * len(states)
    rows = [head, rule]
    for n in sorted({r["axes"] for r in results}):
        cells = []
        for s in states:
            r = by.get((n, s))
            if r is None or "error" in r:
                cells += ["n/a", "n/a"]
            else:
                cells += [f"{r['us_per_cycle']:.0f}", f"{r['rtf']:.2f}×"]
        rows.append(f"| {n} | " + " | ".join(cells) + " |")
    errors = sorted({r["error"] for r in results if "error" in r})
    text = _provenance() + "\n\n" + "\n".join(rows) + "\n"
    if errors:
        text += "\nn/a: " + "; ".join(errors) + "\n"
    p = Path(path)
    old = p.read_text(encoding="utf-8") if p.exists() else ""
    head, sep, rest = old.partition(BEGIN)
    if sep and END in rest:
        text = head + BEGIN + "\n" + text + END + rest.partition(END)[2]
    p.write_text(text, encoding="utf-8")


def write_plot(results: Sequence[Mapping[str, Any]], path: str | Path, title: str = "") -> None:
    """µs per cycle and real-time factor against axes, log-log, one line per state."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    for s in STATES + MODES:
        pts = sorted((r["axes"], r) for r in results if r["state"] == s and "error" not in r)
        if not pts:
            continue
        xs = [n for n, _ in pts]
        left.plot(xs, [r["us_per_cycle"] for _, r in pts], "o-", label=s)
        right.plot(xs, [r["rtf"] for _, r in pts], "o-", label=s)
    left.set_ylabel("µs per 1 ms cycle")
    right.set_ylabel("real-time factor (controller ms per wall ms)")
    for target, label in ((20, "12 axes ≥ 20×"), (10, "64 axes ≥ 10×"), (5, "128 axes ≥ 5×")):
        right.axhline(target, color="grey", lw=0.6, ls=":")
        right.annotate(label, (AXES[-1], target), fontsize=7, color="grey", va="bottom", ha="right")
    right.axhline(1, color="red", lw=0.8, ls="--")
    for ax in (left, right):
        ax.set_xscale("log", base=2)
        ax.set_yscale("log")
        ax.set_xlabel("axes")
        ax.set_xticks(AXES, [str(a) for a in AXES], fontsize=7)
        ax.grid(True, which="both", lw=0.3)
        ax.legend()
    fig.suptitle(title or "gtecat, lockstep clock, CSP drives, GT API")
    errors = [r for r in results if "error" in r]
    fig.tight_layout(rect=(0, 0.05 if errors else 0, 1, 1))
    if errors:
        why = str(errors[0]["error"]).partition(" - ")[0]
        fig.text(0.5, 0.01, f"{len(errors)} points not measured: {why}", ha="center", fontsize=7)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _ints(text: str) -> list[int]:
    return [int(x) for x in text.split(",") if x]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--axes", type=_ints, default=list(AXES), help="e.g. 1,12,64")
    ap.add_argument(
        "--states",
        default=",".join(STATES),
        help="idle,moving,homing (also pt,pvt,gear,follow,crd,homed6,screw)",
    )
    ap.add_argument("--seconds", type=float, default=1.5, help="wall seconds per point")
    ap.add_argument("--repeat", type=int, default=3, help="windows per point (best counts)")
    ap.add_argument(
        "--addressing",
        choices=sorted(ADDRESSING),
        default="cores",
        help="cores: axes 33+ on GTN_*(2..4, ...) (default); flat: all on core 1",
    )
    ap.add_argument("--plot", metavar="FILE.png")
    ap.add_argument("--table", metavar="FILE.md")
    ap.add_argument("--json", metavar="FILE.json", help="also write the results here")
    args = ap.parse_args(argv)
    states = [s for s in args.states.split(",") if s]
    set_addressing(args.addressing)

    def progress(r: dict[str, Any]) -> None:
        print(json.dumps(r), file=sys.stderr, flush=True)

    results = bench_scaling(
        args.axes, states, seconds=args.seconds, repeat=args.repeat, progress=progress
    )
    text = json.dumps(results, indent=1)
    print(text)
    if args.json:
        Path(args.json).write_text(text + "\n", encoding="utf-8")
    title = f"gtecat, lockstep, {os.cpu_count()} CPUs, best of {args.repeat} windows"
    if args.addressing != "cores":
        title += f", {args.addressing} addressing"
    if args.plot:
        write_plot(results, args.plot, title)
    if args.table:
        write_table(results, args.table)
    return 1 if any("error" in r for r in results) else 0


if __name__ == "__main__":
    sys.exit(main())
