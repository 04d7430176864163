"""Faults armed on the auto clock: while the fault injector waits (a time, a count of cycles,
a position, a homing's stage) and smart homing has nothing to do, the cycles a polling loop's
calls make due run the quick way - in the GT readers' C entries, as many as the hooks say
they stay quiet in, counted for them when Python next looks (Controller.settle_hooks) - and
every fault fires in the very cycle it fires in when every cycle runs one at a time.

The same session runs three ways: the quick ways, every cycle one by one through the hooks
(the reference), and the quick ways with the C entries' cycles budgeted one at a time (the
way before the budget).  Every GT result of every pass of the polling loop, with the
controller time it was read at, the master log, the faults' listing and their start and end
events are the same."""

from __future__ import annotations

from ctypes import byref, c_double, c_long, c_short, c_ulong, c_ushort
from pathlib import Path
from typing import Any

import pytest

from gtecat import faults, gt
from gtecat.controller.core import Controller
from gtecat.faults.injector import Injector
from tools.session_hard import ENI, trap_move

AXES = 12
DRIVE_HOMING, SMART_HOMING = 1, 5
MACHINE = (
    "".join(
        f"[axis.{a}]\ncounts_per_rev = 10000\nindex_offset = 3000\n"
        "negative_limit = -2000000\npositive_limit = 2000000\n"
        + ("position = 112000\nhome_switch = [[100000, 2000000]]\n" if a == DRIVE_HOMING else "")
        + ("home_switch = [[15000, 2000000]]\n" if a == SMART_HOMING else "")
        + "\n"
        for a in range(1, AXES + 1)
    )
    # a time, and a count of cycles, from the machine description
    + '[[fault]]\nkind = "drive_fault"\naxis = 7\ncode = 0x2310\nat_ms = 333\n'
    "duration_ms = 40\n\n"
    '[[fault]]\nkind = "switch_chatter"\naxis = 3\nswitch = "positive"\nperiod_cycles = 3\n'
    "after_cycles = 517\nduration_ms = 45\n\n"
)
#: from Python: a position, a homing's stages, a step after another fault, a far one
INJECTED = (
    {
        "kind": "drive_fault",
        "axis": 9,
        "code": 0x2310,
        "when_position": [2, 9000],
        "duration_ms": 30,
    },
    {"kind": "link_down", "after_slave": 4, "at_homing": [1, "index"], "duration_ms": 25},
    {
        "kind": "encoder_noise",
        "axis": 6,
        "counts": 4,
        "at_homing": [1, "completed"],
        "duration_ms": 60,
    },
    {"kind": "sto", "axis": 11, "at_ms": 100_000},
)
SECONDS = 1.4
#: every fault but the far one is over by then (the encoder noise, the last, at ~904 ms)
QUIET_FROM_MS = 1000


def _session(log: Path) -> dict[str, Any]:
    """The polling loop (module docstring) on the 12-axis example bus: every pass reads each
    axis's status and the planned positions through the readers' C entries; axis 1 homes in
    the drive, axis 5 by smart homing, axis 2 moves in Trap, the others rest; an error
    handler resets an alarm every 20 ms; every 7th pass waits 2 ms.  What it read, and the
    faults' story."""
    machine = log.parent / "cell.toml"
    machine.write_text(MACHINE)
    assert gt.GT_Open(eni=str(ENI), machine=str(machine), clock="auto", log=str(log)) == 0
    assert gt.GT_InitEcatComm() == 0
    st, clock = c_short(), c_ulong()
    while not (gt.GT_IsEcatReady(byref(st)) == 0 and st.value == 1):
        gt.GTE_Wait(1)
    gt.GT_StartEcatComm()
    gt.GT_Reset()
    for a in range(1, AXES + 1):
        gt.GT_AxisOn(a)
    gt.GTE_Wait(10)
    ids = [faults.inject(d.pop("kind"), **d) for d in map(dict, INJECTED)]
    # a script's step: 30 ms after the drive fault of axis 7 started, axis 8's for 20 ms
    ids += faults.script(
        [{"kind": "drive_fault", "axis": 8, "code": 0x2310, "after": 1, "after_ms": 30,
          "duration_ms": 20}]
    )  # fmt: skip
    gt.GT_SetHomingMode(DRIVE_HOMING, 6)
    gt.GT_SetEcatHomingPrm(DRIVE_HOMING, 3, 40000, 20000, 400000, 0, 0)
    gt.GT_StartEcatHoming(DRIVE_HOMING)
    home = gt.THomePrm()
    gt.GT_GetHomePrm(SMART_HOMING, byref(home))
    home.mode, home.moveDir, home.velHigh, home.velLow = gt.HOME_MODE_HOME, 1, 40.0, 10.0
    home.acc = home.dec = 1.0
    gt.GT_PrfTrap(SMART_HOMING)
    assert gt.GT_GoHome(SMART_HOMING, byref(home)) == 0
    trap = gt.TTrapPrm()
    trap.acc = trap.dec = 0.25
    assert gt.GT_SetAxisBand(2, 20, 5) == 0  # (in position after 5 ms in the band: timed)
    trap_move(gt, 2, 12_000, trap)
    one, prf, hs = c_long(), (c_double * AXES)(), c_ushort()
    home_st = gt.THomeStatus()
    seen: list[tuple[Any, ...]] = []
    listings: list[list[str]] = []
    reset_at = dict.fromkeys(range(1, AXES + 1), 0)
    k = 0
    while True:
        gt.GT_GetClock(byref(clock))
        if clock.value >= SECONDS * 1000:
            break
        k += 1
        sts = []
        for a in range(1, AXES + 1):
            gt.GT_GetSts(a, byref(one))
            sts.append(one.value)
        gt.GT_GetPrfPos(1, prf, AXES, None)
        seen.append((clock.value, *sts, *prf))
        if k % 50 == 0:
            gt.GT_GetEcatHomingStatus(DRIVE_HOMING, byref(hs))
            gt.GT_GetHomeStatus(SMART_HOMING, byref(home_st))
            seen.append((hs.value, home_st.run, home_st.stage, home_st.error))
            listings.append([f["describe"] + f["state"] for f in faults.listing()])
        for a, s in enumerate(sts, 1):
            if s & 0x62 and clock.value - reset_at[a] >= 20:  # an alarm, a limit: reset
                reset_at[a] = clock.value
                gt.GT_ClrSts(a, 1)
                gt.GT_AxisOn(a)
        if k % 7 == 0:  # (a wait now and then: the cycle after it armed too)
            gt.GTE_Wait(2)
    ctl = gt.GTE_Controller()
    inj = faults.injector_for(ctl)
    out = {
        "seen": seen,
        "listings": listings,
        "events": list(inj.events),
        "ids": ids,
        "cycles": ctl.clock.cycles,
        "passes": k,
    }
    gt.GT_Close()
    out["log"] = log.read_text()
    return out


def _fired(mp: pytest.MonkeyPatch) -> list[str]:
    started: list[str] = []
    start = Injector._start

    def _start(inj: Injector, e: Any) -> None:
        started.append(f"{inj.bus.now_ms():g} {e.describe()}")
        start(inj, e)

    mp.setattr(Injector, "_start", _start)
    return started


def test_faults_fire_in_the_same_cycles_with_the_quick_cycles_budgeted(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    runs = {}
    python_cycles = {}
    for way in ("quick", "one_by_one", "unbudgeted"):
        with pytest.MonkeyPatch.context() as mp:
            started = _fired(mp)
            due = Controller.due_cycle
            count = [0]

            def counted(self: Controller, pending: int, _due: Any = due, _n: Any = count) -> bool:
                _n[0] += self.clock.now_ns >= QUIET_FROM_MS * 1_000_000
                return _due(self, pending)

            mp.setattr(Controller, "due_cycle", counted)
            if way == "one_by_one":
                mp.setattr(Controller, "run_cycles", lambda self, n: 0)
                mp.setattr(Controller, "due_cycle", lambda self, pending: False)
            elif way == "unbudgeted":  # (each quick cycle asks the hooks in Python)
                mp.setattr(Controller, "_quiet_budget", lambda self: self.settle_hooks() or 0)
            runs[way] = _session(tmp_path / f"{way}.log")
            runs[way]["started"] = started
            python_cycles[way] = count[0]
    quick = runs["quick"]
    assert len(quick["started"]) == 6, quick["started"]  # (every fault but the far one)
    for way in ("one_by_one", "unbudgeted"):
        for key in quick:
            assert runs[way][key] == quick[key], (way, key)
    # once every fault is over (the far one waits), the due cycles ran in the readers' C
    # entries: hardly any reached Python
    assert python_cycles["unbudgeted"] > 200
    assert python_cycles["quick"] <= 5


def _injected_between_polls() -> list[tuple[float, str, int, str]]:
    """The manual's figure 5-2 bus polled through the C entries with a far fault armed (the
    quick cycles budgeted a thousand at a time); faults injected between two polls, with no
    other GT call: a time a few cycles on, a count of cycles, one cleared before its time."""
    from tests.gtecat.gt.conftest import bring_up

    bring_up()
    assert gt.GT_AxisOn(1) == 0
    gt.GTE_Wait(20)
    faults.inject("sto", axis=2, at_ms=100_000)
    s, clock = c_long(), c_ulong()

    def polls(n: int) -> None:
        for _ in range(n):
            gt.GT_GetSts(1, byref(s))

    polls(300)
    gt.GT_GetClock(byref(clock))
    faults.inject("drive_fault", axis=1, code=0x2310, at_ms=clock.value + 3, duration_ms=5)
    polls(300)
    faults.inject("drive_fault", axis=2, code=0x2310, after_cycles=7, duration_ms=4)
    polls(300)
    gt.GT_GetClock(byref(clock))
    gone = faults.inject("drive_fault", axis=1, code=0x2310, at_ms=clock.value + 8)
    polls(100)
    faults.clear(gone)
    polls(500)
    events = list(faults.injector_for(gt.GTE_Controller()).events)
    gt.GT_Close()
    return events


def test_a_fault_injected_between_polls_fires_in_its_cycle() -> None:
    """A fault added or cleared between two polls (the readers' C entries only, no GT call
    of the table) ends the quick cycles' budget: it fires in the cycle it fires in with every
    cycle run one at a time, and one cleared before its time never does."""
    quick = _injected_between_polls()
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(Controller, "run_cycles", lambda self, n: 0)
        mp.setattr(Controller, "due_cycle", lambda self, pending: False)
        reference = _injected_between_polls()
    assert [e[1] for e in quick] == ["start", "end", "start", "end"]
    assert quick == reference
