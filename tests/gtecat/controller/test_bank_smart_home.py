"""Smart homing (GT_GoHome) in the axis bank against the scalar path, cycle by cycle.

Twelve EtherCAT axes home at once in different smart-home modes (home ahead or behind, a
limit that turns the search, starting on the switch, limit then home both ways, limit with
escapes both ways, forced home, home and index through the touch probe, a search stopped by
GT_Stop, one stopped by GT_Stop while it stands between two legs (the touch probe arming
before the index search), one that does not end in the run) on switches close enough that
every search meets its events in the run. Each event (a home edge, a limit, a leg's end
sample) sends an axis back to its scalar objects and the bank takes it again after, and
between events the bank runs the cycles many at once while the homings say they stay quiet:
that is where a difference would show. Compared exactly with the bank off, every cycle:
GT_GetSts, planned and encoder positions of every axis, every axis's THomeStatus and the
whole GT raw image; the drives' mechanics at the end.
"""

from __future__ import annotations

import os
from ctypes import byref, c_double, c_long, c_ubyte
from pathlib import Path
from typing import Any

import pytest

from gtecat import gt
from tests.gtecat.controller.test_bank import ENI, HAS_CC, _ok, open_bus

AXES = 12
#: axis -> (THomePrm fields, machine keys); positions in counts (pulse = count here)
SETUP: dict[int, tuple[dict[str, object], dict[str, object]]] = {
    1: (  # the first index ahead, fast
        {"mode": 30},
        {"index_offset": 2_500, "counts_per_rev": 10_000},
    ),
    2: (  # forced home, then the first index beyond it
        {"mode": 41, "homeOffset": 120, "velLow": 10.0},
        {"home_switch": [[2_500, 7_000]], "index_offset": 650, "counts_per_rev": 2_000},
    ),
    3: (  # limit, home on the way back, back to it, the first index beyond it
        {"mode": 13, "velHigh": 20.0, "velLow": 10.0},
        {
            "positive_limit": 3_600,
            "home_switch": [[2_000, 3_000]],
            "index_offset": 170,
            "counts_per_rev": 1_000,
        },
    ),
    4: ({"mode": 10, "moveDir": -1, "escapeStep": 400}, {"negative_limit": -4_000}),
    5: ({"mode": 20}, {"position": 1_000, "home_switch": [[500, 2_500]]}),
    6: ({"mode": 20}, {"positive_limit": 3_000, "home_switch": [[-3_000, -2_000]]}),
    7: (
        {"mode": 22, "homeOffset": -300},
        {"home_switch": [[2_000, 3_000]], "index_offset": 100, "counts_per_rev": 1_000},
    ),
    8: (  # the negative limit, then slowly up to the first index
        {"mode": 12, "moveDir": -1, "indexDir": 1, "velHigh": 20.0, "homeOffset": 150},
        {"negative_limit": -3_500, "index_offset": 600, "counts_per_rev": 1_000},
    ),
    9: ({"mode": 20, "moveDir": -1, "edge": 1}, {"home_switch": [[-5_000, -3_500]]}),
    10: ({"mode": 20, "homeOffset": 250}, {"home_switch": [[4_000, 6_000]]}),  # GT_Stop
    11: ({"mode": 20}, {"home_switch": [[400_000, 410_000]]}),  # still searching at the end
    12: (  # GT_Stop while it stands between the home return and the index search
        {"mode": 22},
        {"home_switch": [[1_500, 2_500]], "index_offset": 700, "counts_per_rev": 1_000},
    ),
}
CYCLES = 650
STOP_AT = 90  # GT_Stop of axis 10 in the middle of its search
#: GT_Stop of axis 12 after this many cycles: it stands at the captured home, in stage 30,
#: while the drive's touch probe arms (two cycles), before the index search moves it
STAND_STOP_AT = 317


def _machine(tmp: Path, setup: dict = SETUP) -> str:
    lines = []
    for axis, (_, keys) in setup.items():
        lines.append(f"[axis.{axis}]")
        lines += [f"{k} = {v}" for k, v in keys.items()]
    path = tmp / "machine.toml"
    path.write_text("\n".join(lines) + "\n")
    return str(path)


def _sample(size: int, axes: int = AXES) -> tuple:
    sts = (c_long * axes)()
    prf = (c_double * axes)()
    enc = (c_double * axes)()
    gt.GT_GetSts(1, sts, axes)
    gt.GT_GetPrfPos(1, prf, axes)
    gt.GT_GetEncPos(1, enc, axes)
    homes = []
    hs = gt.THomeStatus()
    for a in range(1, axes + 1):
        _ok(gt.GT_GetHomeStatus(a, byref(hs)), "status")
        homes.append((hs.run, hs.stage, hs.error, hs.capturePos, hs.targetPos))
    raw = (c_ubyte * size)()
    gt.GT_GetEcatRawData(0, size, raw)
    return tuple(sts), tuple(prf), tuple(enc), tuple(homes), bytes(raw)


def _end_state(ctl: Any) -> tuple:
    """After a run: every drive channel's motion, statusword and position, and each
    slave's mailbox counters (the bank given everything back first: the uploads of the
    cycles it ran are counted at a release)."""
    if ctl.bank is not None:
        ctl.bank.release_all()
    backend = ctl.backend
    mailboxes = [
        (backend._clients[p].counter, backend.slaves[p].sdo.counter)
        for p in sorted(backend._clients)
    ]
    return tuple(
        (ch.mech.pos, ch.mech.vel, ch.statusword, ch.position_actual)
        for s in backend.slaves
        for ch in getattr(s, "channels", [])
    ) + tuple(mailboxes)


def _run(
    machine: str,
    bank: str,
    step: int = 0,
    eni: Path = ENI,
    setup: dict = SETUP,
    cycles: int = CYCLES,
    calls: dict[int, Any] | None = None,
) -> tuple[list, dict[str, Any]]:
    """The homings, sampled after every cycle (``step`` 0: one cycle at a time, now and then
    seven) or after every ``step`` cycles run at once (a long wait: the controller runs
    them in as few calls as the homings let it); the stops of axes 10 and 12 with
    :data:`SETUP` alone; ``calls``: cycle -> a call made before it (a GPI set)."""
    stops = setup is SETUP
    trace: list = []
    try:
        open_bus(str(eni), machine, bank)
        for a, (fields, _) in setup.items():
            _ok(gt.GT_AxisOn(a), f"axis on {a}")
            _ok(gt.GT_PrfTrap(a), f"trap {a}")
            if fields is None:
                continue  # (an axis moved by the test's calls)
            prm = gt.THomePrm()
            prm.mode, prm.moveDir, prm.indexDir, prm.edge, prm.triggerIndex = 20, 1, -1, 0, -1
            prm.velHigh, prm.velLow, prm.acc, prm.dec = 40.0, 4.0, 1.0, 1.0
            prm.escapeStep = 1000
            for name, value in fields.items():
                setattr(prm, name, value)
            _ok(gt.GT_GoHome(a, byref(prm)), f"go home {a}")
        ctl = gt.GTE_Controller()
        size = ctl.layout.gt_raw_bytes
        k = searching = banked = on_limit = braking = 0
        while k < cycles:
            for at, call in (calls or {}).items():
                if k <= at < k + max(step, 1):
                    call()
            if stops and k <= STOP_AT < k + max(step, 1):
                _ok(gt.GT_Stop(1 << 9, 0), "stop")
            if stops and k <= STAND_STOP_AT < k + max(step, 1):
                if not step:  # (the one-cycle run: it must stand there now)
                    hs = gt.THomeStatus()
                    _ok(gt.GT_GetHomeStatus(12, byref(hs)), "status")
                    sts = c_long()
                    gt.GT_GetSts(12, byref(sts))
                    assert (hs.run, hs.stage, sts.value & 1 << 10) == (1, 30, 0)
                _ok(gt.GT_Stop(1 << 11, 0), "stop between legs")
            # mostly one cycle at a time, sometimes many at once (a polling loop)
            wait = step or (1 if k % 50 else 7)
            gt.GTE_Wait(wait)
            k += wait
            trace.append(_sample(size, len(setup)))
            # an index search (stage 30) after its probe armed: which axes the bank runs
            for a, (run, stage, *_) in enumerate(trace[-1][3], 1):
                if run and stage == 30:
                    searching += 1
                    banked += ctl.bank is not None and ctl.bank.holds(ctl.axes[a])
            # the rows the bank holds on a limit switch (its 60FDh), braking on it or not
            b = ctl.bank
            if b is not None and b.n:
                on = b.alive & ((b.csp.din & 3) != 0)
                on_limit += int(on.sum())
                braking += int((on & b.csp.lstop).sum())
        bank_ = ctl.bank
        stats = {
            "rows": bank_.rows_run if bank_ is not None else 0,
            "many": bank_.many_cycles if bank_ is not None else 0,
            "kernel": bank_ is not None and bank_.kernel is not None,
            "index_search": (banked, searching),
            "on_limit": (on_limit, braking),
            # steps on a claimed row, edges taken after the bank's cycle (inputs, probes)
            "in_place": (
                (bank_.steps_in_place, bank_.posted_inputs, bank_.posted_probes)
                if bank_ is not None
                else (0, 0, 0)
            ),
            "armed": bank_.probes_armed if bank_ is not None else 0,
            "trap_holds": bank_.trap_holds if bank_ is not None else 0,
        }
        if bank_ is not None and not stops:
            # axis 1's probe stays armed after its homing: the bank holds it, and a read of
            # the drive's probe (its status, by the slave's object dictionary) gives it back
            held = bank_.holds(ctl.axes[1])
            ctl.backend.slaves[0].od.upload(0x60B9, 0)
            stats["probe_guard"] = (held, bank_.holds(ctl.axes[1]))
        trace.append(_end_state(ctl))
    finally:
        gt.GT_Close()
    return trace, stats


@pytest.fixture(scope="module")
def machine(tmp_path_factory: pytest.TempPathFactory) -> str:
    return _machine(tmp_path_factory.mktemp("smart_home"))


@pytest.fixture(scope="module")
def runs(machine: str) -> tuple:
    return _run(machine, "off"), _run(machine, "on")


def test_smart_homing_in_the_bank_matches_the_scalar_path(runs: tuple) -> None:
    (ref, ref_stats), (got, _) = runs
    assert ref_stats["rows"] == 0
    for k, (a, b) in enumerate(zip(ref, got, strict=True)):
        assert a == b, f"cycle {k}: the bank and the scalar path differ"
    # every homing ended as planned: stage 100 without error, axis 10 stopped (error 4),
    # axis 11 still searching, axis 12 stopped where it stood (error 4, not moved again)
    homes = ref[-2][3]
    ended = {a: (run, stage, error) for a, (run, stage, error, _, _) in enumerate(homes, 1)}
    assert ended[10] == (0, 20, 4)
    assert ended[11] == (1, 20, 0)
    assert ended[12] == (0, 30, 4)
    assert all(ended[a] == (0, 100, 0) for a in ended if a not in (10, 11, 12)), str(ended)
    stood = {prf[11] for _, prf, _, homes_k, _ in ref[:-1] if homes_k[11][0] == 0}
    assert len(stood) == 1, "axis 12 moved after GT_Stop"


def test_the_bank_ran_the_homing_axes(runs: tuple) -> None:
    """Without this the differential test could pass with the bank never engaged."""
    _, (_, stats) = runs
    assert stats["rows"] > AXES * CYCLES * 0.4
    assert stats["kernel"] or not HAS_CC or os.environ.get("GTECAT_BANK_KERNEL") == "numpy"
    # the homings stepped on their claimed rows, and home edges and the touch probe's were
    # taken after the bank's cycles (this bus maps the probe's objects: the image shows them)
    steps, inputs, probes = stats["in_place"]
    assert steps > 5 and inputs > 0 and probes > 0, stats["in_place"]
    if stats["kernel"]:
        assert stats["many"] > 20  # cycles the homings let the controller run at once
        # the index searches too, their drives' touch probes armed (all but the cycles
        # around their edges and the probe's arming)
        banked, searching = stats["index_search"]
        assert searching > 100 and banked > 0.7 * searching, stats["index_search"]
        # drives standing on a limit switch, and braking on it (the drive's own reaction to
        # a demand into the switch), in the compiled cycle: the limit homings' escapes
        on_limit, braking = stats["on_limit"]
        assert on_limit > 20 and braking > 0, stats["on_limit"]


def test_long_waits_give_the_same_homings(machine: str) -> None:
    """Waits of 37 ms: the controller runs each in as few calls as the homings' quiet cycles
    allow, the events one cycle at a time in between; every 37th cycle is the scalar one."""
    (ref, _), (got, stats) = _run(machine, "off", 37), _run(machine, "on", 37)
    for k, (a, b) in enumerate(zip(ref, got, strict=True)):
        assert a == b, f"after {37 * (k + 1)} cycles: the bank and the scalar path differ"
    if stats["kernel"]:
        assert stats["many"] > 20


#: a bus whose drives map no touch-probe object: the capture polls 60B9h by SDO every cycle
SDO_SETUP: dict[int, tuple[dict[str, object] | None, dict[str, object]]] = {
    1: (
        {"mode": 22, "indexDir": 1, "velLow": 10.0},
        {"home_switch": [[1_500, 2_500]], "index_offset": 1_800, "counts_per_rev": 1_000},
    ),
    2: ({"mode": 30, "moveDir": -1}, {"index_offset": -1_900, "counts_per_rev": 4_000}),
    3: (
        {"mode": 12, "indexDir": -1, "velHigh": 20.0, "velLow": 10.0},
        {"positive_limit": 2_500, "index_offset": 1_234, "counts_per_rev": 2_000},
    ),
    4: (  # the trigger is GPI 3 (active from cycle 60 to 140), then the index beyond
        {"mode": 41, "triggerIndex": 3, "indexDir": 1, "velLow": 10.0},
        {"index_offset": 3_777, "counts_per_rev": 5_000},
    ),
    5: (None, {"home_switch": [[1_500, 2_500]]}),  # moved by a call: axis 6's trigger
    6: ({"mode": 20, "triggerIndex": 5, "velHigh": 10.0}, {}),
}


def _move_axis_5() -> None:
    prm = gt.TTrapPrm()
    prm.acc, prm.dec = 1.0, 1.0
    for rc in (
        gt.GT_SetTrapPrm(5, byref(prm)),
        gt.GT_SetPos(5, 3_000),
        gt.GT_SetVel(5, 10.0),
        gt.GT_Update(1 << 4),
    ):
        _ok(rc, "move axis 5")


#: GPI 3, axis 4's trigger, set and cleared (a sensor the axis passes, as a scenario would
#: set it); axis 5 moved across its home switch, where axis 6's homing captures
CALLS = {
    20: _move_axis_5,
    60: lambda: gt.GTE_SetGpi(3, 1),
    140: lambda: gt.GTE_SetGpi(3, 0),
}


def test_index_homing_polled_by_sdo(tmp_path: Path) -> None:
    """The capture reads the touch probe's 60B9h by SDO: the bank runs the index searches
    and counts those uploads at each release, so the mailboxes' counters (both sides) end
    where the scalar path's do, as does everything the differential test compares.  Axis 4
    homes on a GPI the test sets and clears (GTE_SetGpi gives the axes back; in between
    its searches stay in the bank); axis 6 on axis 5's home capture (``triggerIndex`` 5)
    while axis 5 moves in Trap across its home switch."""
    from tools.gen_axes_eni import write_axes_eni

    eni = write_axes_eni(len(SDO_SETUP), tmp_path / "axes.eni")
    machine = _machine(tmp_path, SDO_SETUP)
    out = []
    for bank in ("off", "on"):
        trace, stats = _run(machine, bank, 0, eni, SDO_SETUP, 420, CALLS)
        out.append((trace, stats))
    (ref, _), (got, stats) = out
    for k, (a, b) in enumerate(zip(ref, got, strict=True)):
        assert a == b, f"cycle {k}: the bank and the scalar path differ"
    ended = ref[-2][3]
    assert all(h[:3] == (0, 100, 0) for a, h in enumerate(ended, 1) if a != 5), ended
    assert 1_500 <= ended[5][3] <= 1_510  # (axis 6 captured axis 5 reaching its switch)
    assert ref[-1] == got[-1]  # (the drives' mechanics, the mailbox counters)
    assert stats["probe_guard"] == (True, False)
    # the probe's edges taken after the bank's cycles (no probe object mapped), with the
    # uploads and mailbox counters the scalar path leaves
    steps, inputs, probes = stats["in_place"]
    assert steps > 5 and inputs > 0 and probes > 3, stats["in_place"]
    if stats["kernel"]:
        banked, searching = stats["index_search"]
        assert searching > 100 and banked > 0.7 * searching, stats["index_search"]


#: forced home and the first index beyond it (mode 41), the trigger the axis's own home
#: input: the stop after the switch is found ends beyond the switch, so the way back at
#: velLow (stage 45) ends at its first step, the level already inactive (no edge says so)
BEYOND_SETUP: dict[int, tuple[dict[str, object] | None, dict[str, object]]] = {
    1: (
        {"mode": 41, "indexDir": -1, "edge": 1, "velLow": 10.0, "acc": 2.0, "dec": 0.5},
        {
            "home_switch": [[1_000, 1_800]],
            "index_offset": 600,
            "counts_per_rev": 1_000,
            "positive_limit": 3_500,
        },
    ),
}


def test_forced_home_stopped_beyond_the_switch(tmp_path: Path) -> None:
    """The leg back to the switch's end starts with the level already inactive: the step
    after the move starts reads it (the bank found the homing quiet there, waiting for an
    edge that never came, and the homing stayed in stage 45)."""
    machine = _machine(tmp_path, BEYOND_SETUP)
    (ref, _), (got, stats) = (_run(machine, b, 0, ENI, BEYOND_SETUP, 260) for b in ("off", "on"))
    for k, (a, b) in enumerate(zip(ref, got, strict=True)):
        assert a == b, f"cycle {k}: the bank and the scalar path differ"
    run, stage, error, capture, target = ref[-2][3][0]
    # (the index beyond the home the way back found; homeOffset 0)
    assert (run, stage, error) == (0, 100, 0) and 1_800 < capture == target, ref[-2][3]
    assert stats["rows"] > 0


#: searches whose capture latches in the first cycle of their leg: the leg is quiet from
#: its start (nothing to read before an edge), so the edge of that very cycle must reach
#: the homing - the index right ahead of an index search (the drive's touch probe, by SDO),
#: the home switch right ahead of a home search, and the same from the other side
FIRST_CYCLE_SETUP: dict[int, tuple[dict[str, object] | None, dict[str, object]]] = {
    1: ({"mode": 30, "acc": 4.0}, {"index_offset": 1, "counts_per_rev": 1_000}),
    2: ({"mode": 20, "acc": 4.0}, {"home_switch": [[1, 500]]}),
    3: ({"mode": 20, "moveDir": -1, "acc": 4.0}, {"home_switch": [[-500, -1]]}),
    4: (
        {"mode": 22, "indexDir": 1, "acc": 4.0, "velLow": 10.0},
        {"home_switch": [[1, 500]], "index_offset": 150},
    ),
}


def test_captures_in_the_first_cycle_of_a_leg(tmp_path: Path) -> None:
    from tools.gen_axes_eni import write_axes_eni

    eni = write_axes_eni(len(FIRST_CYCLE_SETUP), tmp_path / "axes.eni")
    machine = _machine(tmp_path, FIRST_CYCLE_SETUP)
    (ref, _), (got, stats) = (
        _run(machine, b, 0, eni, FIRST_CYCLE_SETUP, 200) for b in ("off", "on")
    )
    for k, (a, b) in enumerate(zip(ref, got, strict=True)):
        assert a == b, f"cycle {k}: the bank and the scalar path differ"
    assert ref[-1] == got[-1]  # (the drives' mechanics, the mailbox counters)
    ended = ref[-2][3]
    assert all(h[:3] == (0, 100, 0) for h in ended), ended
    assert ended[0][3] == 1 and ended[1][3] <= 2 and ended[2][3] >= -2, ended
    assert stats["rows"] > 0


#: the first index ahead (mode 30) on a bus whose drives map no touch-probe object (the
#: capture writes 60B8h and reads 60B9h/60BAh by SDO), GT_GoHome called on axes the bank
#: runs: the touch probe armed while the bank keeps running them (60B8h off, then on, which
#: the drive applies at its next cycle); the index at varied places, one where the axis
#: stands, one behind the positive limit (the search turns there), one stopped in its
#: search; later, homings started again from where they stood, one stopped after the first
#: cycle of its probe's arming, one after the second, one still searching at the end
ARM_SETUP: dict[int, tuple[dict[str, object] | None, dict[str, object]]] = {
    1: ({"mode": 30}, {"index_offset": 1_537, "counts_per_rev": 10_000}),
    2: ({"mode": 30, "moveDir": -1, "homeOffset": -75}, {"index_offset": 2_222}),
    3: ({"mode": 30, "velHigh": 13.0}, {"index_offset": 0, "counts_per_rev": 3_000}),
    4: (
        {"mode": 30, "homeOffset": 40},
        {"index_offset": -900, "counts_per_rev": 100_000, "positive_limit": 1_200},
    ),
    5: ({"mode": 30}, {"index_offset": 4_000, "counts_per_rev": 10_000}),
    6: ({"mode": 30}, {"index_offset": 3_100, "counts_per_rev": 10_000}),  # GT_Stop, search
    7: ({"mode": 30, "acc": 0.3, "dec": 0.2}, {"index_offset": 777, "counts_per_rev": 5_000}),
    8: ({"mode": 30, "moveDir": -1}, {"index_offset": 9_999, "counts_per_rev": 10_000}),
}


def _go_home_again(axis: int) -> None:
    """GT_GoHome on an axis whose homing ended, standing (in the bank): the first index
    ahead of where it stands now."""
    prm = gt.THomePrm()
    _ok(gt.GT_GetHomePrm(axis, byref(prm)), "home prm")
    _ok(gt.GT_ClearCaptureStatus(axis), "clear capture")  # (as a user's program does)
    _ok(gt.GT_PrfTrap(axis), "trap again")  # (standing in Trap: a hold where it stands)
    _ok(gt.GT_GoHome(axis, byref(prm)), f"go home again {axis}")


def _stop(axis: int) -> None:
    _ok(gt.GT_Stop(1 << (axis - 1), 0), f"stop {axis}")


ARM_CALLS = {
    80: lambda: _stop(6),
    420: lambda: (_go_home_again(1), _go_home_again(5)),
    421: lambda: _stop(5),  # (after the cycle that wrote 60B8h off)
    430: lambda: _go_home_again(3),
    432: lambda: _stop(3),  # (after the cycle that wrote the function, before it applies)
}


def _probe_pdo_eni(n: int, path: Path) -> Path:
    """``n`` drives that map the touch probe as PDO (60B8h out, 60B9h and 60BAh in), as
    a common real ENI does."""
    from gtecat.eni.topology import build_config
    from gtecat.eni.writer import write_eni_file
    from tools.gen_axes_eni import axes_topology

    topo = axes_topology(n)
    for slave in topo["slave"]:
        slave["rx"] = [*slave["rx"], "0x60B8:0:16"]
        slave["tx"] = [*slave["tx"], "0x60B9:0:16", "0x60BA:0:32"]
    write_eni_file(build_config(topo, "<probe PDO>"), path)
    return path


#: the default run: the probe read by SDO cycle by cycle and mapped as PDO every 13 cycles;
#: GTECAT_LONG=1 also the other two
_OTHER_PAIR = pytest.mark.long("the probe by SDO every 13 cycles, as PDO cycle by cycle")


@pytest.mark.parametrize(
    ("step", "pdo"),
    [
        (0, False),
        pytest.param(13, False, marks=_OTHER_PAIR),
        pytest.param(0, True, marks=_OTHER_PAIR),
        (13, True),
    ],
)
def test_index_homing_armed_in_the_bank(tmp_path: Path, step: int, pdo: bool) -> None:
    """The bank and the scalar path cycle by cycle (or every 13 cycles), the mailbox
    counters and mechanics at the end; the probes armed with the bank running the axes,
    their objects read by SDO or (``pdo``) mapped as PDO: 60B8h written into the image,
    60B9h/60BAh read from it (the whole GT raw image compared every sample)."""
    from tools.gen_axes_eni import write_axes_eni

    if pdo:
        eni = _probe_pdo_eni(len(ARM_SETUP), tmp_path / "axes.eni")
    else:
        eni = write_axes_eni(len(ARM_SETUP), tmp_path / "axes.eni")
    machine = _machine(tmp_path, ARM_SETUP)
    out = [_run(machine, b, step, eni, ARM_SETUP, 700, ARM_CALLS) for b in ("off", "on")]
    (ref, _), (got, stats) = out
    for k, (a, b) in enumerate(zip(ref, got, strict=True)):
        assert a == b, f"sample {k}: the bank and the scalar path differ"
    assert ref[-1] == got[-1]  # (the drives' mechanics, the mailbox counters)
    ended = {a: h[:3] for a, h in enumerate(ref[-2][3], 1)}
    assert ended[1][:2] == (1, 30) and ended[6] == (0, 30, 4), ended
    assert ended[3][::2] == ended[5][::2] == (0, 4), ended
    if not step:  # (stopped while their probes armed: the search had not begun)
        assert ended[3][1] == ended[5][1] == 30, ended
    assert all(ended[a] == (0, 100, 0) for a in (2, 4, 7, 8)), ended
    caps = {a: h[3] for a, h in enumerate(ref[-2][3], 1)}
    assert caps[2] == 2_222 - 10_000 and caps[4] == -900 and caps[7] == 777, caps
    steps, _, probes = stats["in_place"]
    assert steps > 20 and probes >= 6, stats["in_place"]
    if stats["kernel"]:
        # the probes armed while the bank ran their axes: the first homings' and axis 1's
        assert stats["armed"] >= 8, stats
        # a read of axis 1's armed probe (mapped or not) gives its axis back
        assert stats["probe_guard"] == (True, False), stats


def _home_all_standing() -> None:
    """What an application homing many axes does: for each axis (standing in Trap mode,
    the bank running it) its parameters read, its capture cleared, GT_PrfTrap again, then
    GT_GoHome with :data:`ARM_SETUP`'s fields."""
    for a, (fields, _) in ARM_SETUP.items():
        prm = gt.THomePrm()
        _ok(gt.GT_GetHomePrm(a, byref(prm)), "home prm")
        prm.mode, prm.moveDir, prm.indexDir, prm.edge, prm.triggerIndex = 20, 1, -1, 0, -1
        prm.velHigh, prm.velLow, prm.acc, prm.dec = 40.0, 4.0, 1.0, 1.0
        prm.escapeStep = 1000
        for name, value in (fields or {}).items():
            setattr(prm, name, value)
        _ok(gt.GT_ClearCaptureStatus(a), "clear capture")
        _ok(gt.GT_PrfTrap(a), "trap")
        _ok(gt.GT_GoHome(a, byref(prm)), f"go home {a}")


@pytest.mark.parametrize(
    "pdo", [pytest.param(False, marks=pytest.mark.long("the probe read by SDO")), True]
)
def test_homings_started_on_standing_axes(tmp_path: Path, pdo: bool) -> None:
    """The index homings of :data:`ARM_SETUP` started on axes the bank runs standing (a
    capture unit and homing made then, the capture cleared, GT_PrfTrap of an axis standing
    in Trap mode, GT_GoHome in place), the touch probe read by SDO or mapped as PDO: the
    bank and the scalar path cycle by cycle."""
    from tools.gen_axes_eni import write_axes_eni

    n = len(ARM_SETUP)
    eni = _probe_pdo_eni(n, tmp_path / "a.eni") if pdo else write_axes_eni(n, tmp_path / "a.eni")
    machine = _machine(tmp_path, ARM_SETUP)
    setup = {a: (None, keys) for a, (_, keys) in ARM_SETUP.items()}
    calls = {10: _home_all_standing, 80: lambda: _stop(6)}
    out = [_run(machine, b, 0, eni, setup, 400, calls) for b in ("off", "on")]
    (ref, _), (got, stats) = out
    for k, (a, b) in enumerate(zip(ref, got, strict=True)):
        assert a == b, f"sample {k}: the bank and the scalar path differ"
    assert ref[-1] == got[-1]  # (the drives' mechanics, the mailbox counters)
    ended = {a: h[:3] for a, h in enumerate(ref[-2][3], 1)}
    assert ended[6] == (0, 30, 4) and all(ended[a] == (0, 100, 0) for a in (1, 3)), ended
    if stats["kernel"]:
        assert stats["trap_holds"] == n and stats["armed"] >= n, stats


def test_trap_held_keeps_the_planner_guarded(machine: str) -> None:
    """GT_PrfTrap of an axis standing in Trap mode runs as it stands (``trap_holds``), its
    planner's guard off for the call only: afterwards the planner still gives its axis back
    when anything touches it, as every object of a claimed row does."""
    from gtecat.controller.bank import _GUARD_SET

    open_bus(str(ENI), machine, "on")
    try:
        for a in (1, 2):
            _ok(gt.GT_AxisOn(a), "on")
            _ok(gt.GT_PrfTrap(a), "trap")
        gt.GTE_Wait(5)
        ctl = gt.GTE_Controller()
        bank = ctl.bank
        if bank is None or bank.kernel is None or not bank.holds(ctl.axes[1]):
            pytest.skip("no compiled bank kernel here")
        holds = bank.trap_holds
        _ok(gt.GT_PrfTrap(1), "trap again")
        assert bank.trap_holds == holds + 1 and bank.holds(ctl.axes[1])
        # (past the axis's own guard: the row stays)
        planner = object.__getattribute__(ctl.axes[1], "motion").profile.planner
        assert bank.holds(ctl.axes[1]) and type(planner) in _GUARD_SET
        assert planner.done  # (a touch: the axis goes back to its objects)
        assert not bank.holds(ctl.axes[1]) and bank.holds(ctl.axes[2])
    finally:
        gt.GT_Close()
