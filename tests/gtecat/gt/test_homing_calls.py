"""GT homing calls through ``from gtecat import gt``, against hand-computed home points.

Manual 5.2.2.2, example 5-2, chapter 13 entries 43, 103, 112, 130, 133; CiA 402 homing
methods as digested in cia402-facts §3.  Every expected home point below was computed by
hand from the method table (initial direction, reversal limit, edge, index side), not
from the code.  The machines put index pulses at 700 + 4000k (..., -15300, -11300, -7300,
-3300, 700, 4700, 8700, 12700, 16700, ...) and switch edges between them, so a wrong edge,
a wrong index pulse or a wrong direction lands on a different number.

The home point is read where a scale on the machine would read it (``GTE_GetMachinePos``);
6064h then reads the home offset there (6064 = machine - home + 607C).
"""

from __future__ import annotations

import importlib.util
import random
import sys
from ctypes import byref, c_double, c_long, c_short, c_ubyte, c_uint32, c_ushort
from pathlib import Path

import pytest

from gtecat import gt
from gtecat.drives.machine import AxisMachine, MachineDescription
from gtecat.eni.topology import parse_topology
from gtecat.eni.writer import write_eni_file
from tests.conftest import EXAMPLES, LONG, campaign_seed

from .conftest import bring_up

# one drive with five channels (axes 1-5); 6060h/6061h mapped (manual figure 5-1)
FIVE_AXES = """
cycle_time_us = 1000
[[slave]]
kind = "servo"
name = "five-axis module"
channels = 5
rx = ["0x6040:0:16", "0x607A:0:32", "0x6060:0:8"]
tx = ["0x6041:0:16", "0x6064:0:32", "0x6061:0:8"]
"""

SPEED1, SPEED2, ACC = 50_000, 5_000, 1_000_000  # counts/s, counts/s, counts/s²
LIMITS = {"negative_limit": -20000, "positive_limit": 20000}
INDEX = {"counts_per_rev": 4000, "index_offset": 700}
SW10, SW12, SW13 = 1 << 10, 1 << 12, 1 << 13
_NO_MOTION = (35, 37)  # methods that home on the current position, without motion

# --- machines and hand-computed home points -----------------------------------------------
# family: (switch layout, starts, {method: home point per start})
FAMILIES: dict[str, tuple[dict, tuple[float, ...], dict[int, tuple[float, ...]]]] = {
    # limit switches only.  1: NL, leave it moving +, first index right of -20000;
    # 2: PL, leave it moving -, first index left of 20000; 17/18: the edges themselves.
    "limit switch": (
        {},
        (-5000, 5000, 13000),
        {
            1: (-19300, -19300, -19300),
            2: (16700, 16700, 16700),
            17: (-20000, -20000, -20000),
            18: (20000, 20000, 20000),
        },
    ),
    # "positive" home switch active from 6000 up past PL.  Start 0 (off): move +;
    # start 10000 (on).  3: edge crossed moving -, index left (4700); 4: edge crossed
    # moving + into the switch, index right (8700); 19/20: the edge.
    "positive home switch": (
        {"home_switch": [(6000, 30000)]},
        (0, 10000),
        {3: (4700, 4700), 4: (8700, 8700), 19: (6000, 6000), 20: (6000, 6000)},
    ),
    # "negative" home switch active from past NL up to -6000.  Start 0 (off): move -;
    # start -10000 (on).  5: edge crossed moving + out of it, index right (-3300);
    # 6: edge crossed moving - into it, index left (-7300); 21/22: the edge.
    "negative home switch": (
        {"home_switch": [(-30000, -6000)]},
        (0, -10000),
        {5: (-3300, -3300), 6: (-7300, -7300), 21: (-6000, -6000), 22: (-6000, -6000)},
    ),
    # two cams C1 = [-14500, -6000), C2 = [2000, 10500); starts left of C1, in C1, between,
    # in C2, right of C2.  7-10 start + and reverse on PL, 11-14 start - and reverse on NL;
    # low edges: index left -15300 / 700, right -11300 / 4700; high edges: left -7300 / 8700,
    # right -3300 / 12700.  From the right of C2, 7-10 run to PL and come back to C2; from
    # the left of C1, 11-14 run to NL and come back to C1.
    "home cam": (
        {"home_switch": [(-14500, -6000), (2000, 10500)]},
        (-17000, -10000, -2000, 6000, 15000),
        {
            7: (-15300, -15300, 700, 700, 700),  # low edge, approach -, index left
            8: (-11300, -11300, 4700, 4700, 4700),  # low edge, approach +, index right
            9: (-7300, -7300, 8700, 8700, 8700),  # high edge, approach -, index left
            10: (-3300, -3300, 12700, 12700, 12700),  # high edge, approach +, index right
            11: (-3300, -3300, -3300, 12700, 12700),  # high edge, approach +, index right
            12: (-7300, -7300, -7300, 8700, 8700),  # high edge, approach -, index left
            13: (-11300, -11300, -11300, 4700, 4700),  # low edge, approach +, index right
            14: (-15300, -15300, -15300, 700, 700),  # low edge, approach -, index left
            23: (-14500, -14500, 2000, 2000, 2000),
            24: (-14500, -14500, 2000, 2000, 2000),
            25: (-6000, -6000, 10500, 10500, 10500),
            26: (-6000, -6000, 10500, 10500, 10500),
            27: (-6000, -6000, -6000, 10500, 10500),
            28: (-6000, -6000, -6000, 10500, 10500),
            29: (-14500, -14500, -14500, 2000, 2000),
            30: (-14500, -14500, -14500, 2000, 2000),
        },
    ),
    # index pulse only: 33 the first one moving -, 34 the first one moving +
    "index pulse": (
        {},
        (0, 2000),
        {33: (-3300, 700), 34: (700, 4700)},
    ),
    # 35/37: where the axis stands is home, no motion
    "current position": (
        {},
        (1234.0, -777.0),
        {35: (1234.0, -777.0), 37: (1234.0, -777.0)},
    ),
}
ALL_CASES = [(f, method) for f, (_, _, table) in FAMILIES.items() for method in sorted(table)]


def _sampled(cases: list[tuple[str, int]]) -> list[tuple[str, int]]:
    """Every method under GTECAT_LONG=1; else one method of each family, a seeded sample
    (each method's home point is also checked at the drive, tests/drives/test_homing.py)."""
    if LONG:
        return cases
    rng = random.Random(campaign_seed())
    return [rng.choice([c for c in cases if c[0] == f]) for f in FAMILIES]


CASES = _sampled(ALL_CASES)


@pytest.fixture(scope="module")
def five_axes(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("eni") / "five_axes.eni"
    write_eni_file(parse_topology(FIVE_AXES), path)
    return path


def machine(starts: tuple[float, ...], **layout) -> MachineDescription:
    axes = {
        n: AxisMachine(position=float(s), **INDEX, **LIMITS, **layout)
        for n, s in enumerate(starts, 1)
    }
    return MachineDescription(axes)


def machine_pos(axis: int) -> float:
    p = c_double()
    assert gt.GTE_GetMachinePos(axis, byref(p)) == 0, gt.GTE_GetLastError()
    return p.value


def enc_pos(axis: int) -> int:
    p = c_long()
    assert gt.GT_GetEcatEncPos(axis, byref(p)) == 0, gt.GTE_GetLastError()
    return p.value


def statusword(axis: int) -> int:
    sw = c_ushort()
    assert gt.GT_GetEcatAxisPdoData(axis, 0x6041, byref(sw)) == 0, gt.GTE_GetLastError()
    return sw.value


def status(axis: int) -> int:
    s = c_short()
    assert gt.GT_GetEcatHomingStatus(axis, byref(s)) == 0, gt.GTE_GetLastError()
    return s.value


def start(axis: int, method: int, offset: int = 0, speed1: float = SPEED1) -> None:
    """Example 5-2's start sequence: servo on, homing mode, parameters, start."""
    assert gt.GT_AxisOn(axis) == 0, gt.GTE_GetLastError()
    assert gt.GT_SetHomingMode(axis, 6) == 0, gt.GTE_GetLastError()
    assert gt.GT_SetEcatHomingPrm(axis, method, speed1, SPEED2, ACC, offset, 0) == 0, (
        gt.GTE_GetLastError()
    )
    assert gt.GT_StartEcatHoming(axis) == 0, gt.GTE_GetLastError()


def wait_done(axis: int, limit_ms: int = 20_000) -> int:
    for _ in range(limit_ms):
        s = status(axis)
        if s & 1:
            return s
        gt.GTE_Wait(1)
    raise AssertionError(f"axis {axis}: homing not done within {limit_ms} ms")


# --- the vendor's polling loop (manual entry 43) -----------------------------------------------
# The vendor's Qt demo: do { GT_GetEcatHomingStatus(axis, &st); } while (st == 0); then any
# st != 3 is an error and the homing is aborted.  Manual entry 43 allows only 0 (in progress),
# 3 (finished successfully) and 5 (finished with an error) on that path.
ERROR_CASES = [
    # method 3 with no home switch runs into the positive limit, where it may not reverse
    ("no home switch", {}, (0, 5000), 3),
    # method 6 with no home switch runs into the negative limit
    ("no negative home switch", {}, (0, -5000), 6),
]


def vendor_loop(axes: range, limit_ms: int = 20_000) -> dict[int, list[int]]:
    """Run the demo's loop on every axis at once, one poll per ms; the values each one saw."""
    seen: dict[int, list[int]] = {a: [] for a in axes}
    pending = set(axes)
    for _ in range(limit_ms):
        for a in sorted(pending):
            s = status(a)
            if not seen[a] or seen[a][-1] != s:
                seen[a].append(s)
            if s != 0:  # } while (st == 0);
                pending.discard(a)
        if not pending:
            return seen
        gt.GTE_Wait(1)
    raise AssertionError(f"the vendor loop never ended on axes {sorted(pending)}: {seen}")


# --- one test per method, all starts of its family at once (one axis per start) --------------
# and the vendor's polling loop on each of them (manual entry 43): 0 ... 0 3, never 1/2/4
@pytest.mark.parametrize(("family", "method"), CASES, ids=[f"{f}-{m}" for f, m in CASES])
@pytest.mark.sample(2)
def test_home_point_matches_the_method_table(five_axes: Path, family: str, method: int) -> None:
    layout, starts, table = FAMILIES[family]
    offset = 250
    bring_up(str(five_axes), machine=machine(starts, **layout))
    axes = range(1, len(starts) + 1)
    for a in axes:
        start(a, method, offset)
    seen = vendor_loop(axes)
    expected = [3] if method in _NO_MOTION else [0, 3]  # 35/37 are done at the start
    for a, home in zip(axes, table[method], strict=True):
        assert seen[a] == expected, f"axis {a} from {starts[a - 1]}: {gt.GTE_GetLastError()}"
        assert machine_pos(a) == pytest.approx(home, abs=1.0), f"start {starts[a - 1]}"
    gt.GTE_Wait(50)
    for a, home in zip(axes, table[method], strict=True):
        assert status(a) == 3  # and it stays the result
        assert machine_pos(a) == pytest.approx(home, abs=1e-3)  # at rest on the home point
        assert enc_pos(a) == offset  # 6064 = machine - home + 607C


def test_index_methods_over_sdo_on_the_figure_5_2_bus() -> None:
    """6060/6061 and the homing objects not mapped (figure 5-2): all by SDO (5.2.2.2)."""
    bring_up(machine=machine((0, 2000)))
    for a, method, home in ((1, 34, 700), (2, 33, 700)):
        start(a, method, offset=-1000)
        assert wait_done(a) == 3
        gt.GTE_Wait(50)
        assert machine_pos(a) == pytest.approx(home, abs=1e-3)
        assert enc_pos(a) == -1000
        mode = c_short()
        abort = c_uint32()
        assert gt.GT_EcatSDOUpload(a - 1, 0x6061, 0, byref(mode), 1, None, byref(abort)) == 0
        assert mode.value == 6
        speed = c_uint32()
        assert gt.GT_EcatSDOUpload(a - 1, 0x6099, 1, byref(speed), 4) == 0
        assert speed.value == SPEED1


# --- example 5-2 -----------------------------------------------------------------------------
def _example_5_2():
    """examples/example_5_2_homing.py as a module (examples/ is not a package)."""
    name = "example_5_2_homing"
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
        assert spec is not None and spec.loader is not None
        mod = importlib.util.module_from_spec(spec)
        sys.modules[name] = mod  # dataclasses look their module up while the class is built
        spec.loader.exec_module(mod)
    return sys.modules[name]


@pytest.mark.parametrize("clock", ["auto", "lockstep"])
def test_example_5_2_homes_with_method_3_and_returns_to_csp(clock: str) -> None:
    """Axis 1 at 80000 below a positive home switch at 100000: home = index 93000."""
    r = _example_5_2().run(clock=clock)
    assert r["home_status"] == 3 and r["homing"] is False and r["rtn"] == 0
    assert r["machine_position"] == pytest.approx(93000, abs=1.0)
    assert r["encoder"] == 0
    assert r["mode"] == 8
    # 80000 -> 100000 at 5000/s, back to 93000 at 3000/s: about 6.4 s of controller time
    assert 6000 < r["clock_ms"] < 8000


def test_example_5_2_stop_branch_interrupts_and_returns_to_csp_without_a_jump() -> None:
    ex = _example_5_2()
    ex.bring_up()
    v = ex.PlcVars()
    assert gt.GT_AxisOn(1) == 0
    v.xStart = True
    ex.plc_prg(v)
    assert v.xHoming and v.iHomeSts == 0
    gt.GTE_Wait(1000)  # searching at 5000 counts/s, 5000 counts from the start
    v.xStop = True
    ex.plc_prg(v)
    assert not v.xHoming and v.rtn == 0
    stopped = machine_pos(1)
    assert 84000 < stopped < 86000
    assert status(1) == 5  # interrupted: finished, not homed (manual entry 43)
    gt.GTE_Wait(300)
    assert machine_pos(1) == pytest.approx(stopped, abs=0.5)  # 607Ah holds whole counts
    mode = c_short()
    assert gt.GT_GetEcatAxisMode(1, byref(mode)) == 0 and mode.value == 8


# --- leaving homing mode never jumps -----------------------------------------------------------
def test_csp_after_homing_holds_the_home_point(five_axes: Path) -> None:
    bring_up(str(five_axes), machine=machine((5000,)))
    start(1, 34, offset=123)
    assert wait_done(1) == 3
    assert gt.GT_SetHomingMode(1, 8) == 0
    enc, ctl = enc_pos(1), gt.GTE_Controller()
    assert enc == 123
    ax = ctl.axis(1)
    assert ax.prf_pos == pytest.approx(ax.counts_to_pulses(enc))  # planned := actual
    for _ in range(50):
        gt.GTE_Wait(2)
        assert machine_pos(1) == pytest.approx(8700, abs=1e-3)
    assert status(1) == 3  # the result of the last homing, outside homing mode


def test_switching_to_csp_mid_search_interrupts_waits_and_holds(five_axes: Path) -> None:
    """GT_SetHomingMode(axis, 8) while the drive still searches: no jump back or forth."""
    bring_up(str(five_axes), machine=machine((0,), home_switch=[(15000, 30000)]))
    start(1, 3)
    gt.GTE_Wait(150)  # well into the search at 50000 counts/s
    assert status(1) == 0
    assert gt.GT_SetHomingMode(1, 8) == 0, gt.GTE_GetLastError()
    stood = machine_pos(1)
    assert 5000 < stood < 12000
    assert status(1) == 5  # interrupted: not homed
    for _ in range(20):
        gt.GTE_Wait(5)
        assert machine_pos(1) == pytest.approx(stood, abs=0.5)


def test_switching_to_csp_after_the_home_point_was_found_finishes_on_it(five_axes: Path) -> None:
    """Home found, moving onto it (SW12, not SW10): still 0; GT_SetHomingMode(axis, 8) lets
    it arrive, and the run ends 3."""
    bring_up(str(five_axes), machine=machine((0,)), clock="lockstep")
    start(1, 34, offset=-9)
    while not statusword(1) & SW12:
        assert status(1) == 0
        gt.GTE_Wait(1)
    assert statusword(1) & (SW10 | SW12 | SW13) == SW12
    assert status(1) == 0  # CiA "homing attained, target not reached": in progress
    assert machine_pos(1) > 700  # past the index pulse, braking to come back
    assert gt.GT_SetHomingMode(1, 8) == 0
    assert status(1) == 3
    assert machine_pos(1) == pytest.approx(700, abs=1.0)
    gt.GTE_Wait(50)
    assert machine_pos(1) == pytest.approx(700, abs=1e-3) and enc_pos(1) == -9


@pytest.mark.long
def test_example_5_2_scans_on_quietly_once_homed() -> None:
    """The manual's program asks for mode 8 on every scan while the status reads 3."""
    ex = _example_5_2()
    ex.bring_up()
    v = ex.PlcVars()
    assert gt.GT_AxisOn(1) == 0
    v.xStart = True
    ex.plc_prg(v)
    while v.xHoming:
        gt.GTE_Wait(1)
        ex.plc_prg(v)
    for _ in range(200):
        gt.GTE_Wait(1)
        ex.plc_prg(v)
        assert v.rtn == 0 and v.iHomeSts == 3
    assert machine_pos(1) == pytest.approx(93000, abs=1e-3)
    assert enc_pos(1) == 0


def test_stop_homing_interrupts_at_the_homing_deceleration(five_axes: Path) -> None:
    bring_up(str(five_axes), machine=machine((0,)), clock="lockstep")
    start(1, 34, speed1=SPEED1)  # index search at 5000 counts/s: first pulse at 700
    gt.GTE_Wait(60)  # moving at full speed2 (ramp 5 ms)
    before = machine_pos(1)
    assert gt.GT_StopEcatHoming(1) == 0
    assert status(1) == 0  # still braking: in progress, not yet at rest
    for _ in range(100):
        gt.GTE_Wait(1)
        if status(1) != 0:
            break
    assert status(1) == 5  # interrupted at rest: finished, not homed
    # braking from 5000 counts/s at 1e6 counts/s² takes 12.5 counts
    assert 10 < machine_pos(1) - before < 25
    assert machine_pos(1) < 700  # the index pulse was never reached


# --- status bits: consistent from the first cycle after CW4 rises ------------------------------
def test_status_right_after_start_is_in_progress_then_3(five_axes: Path) -> None:
    """Manual entry 43: 0 from the very first read after the start until done, then 3;
    5 before any start (not homed: the vendor loop must neither hang nor see success)."""
    bring_up(str(five_axes), machine=machine((0,)), clock="lockstep")
    assert status(1) == 5  # never started
    assert gt.GT_AxisOn(1) == 0
    assert gt.GT_SetHomingMode(1, 6) == 0
    assert status(1) == 5  # not started
    assert gt.GT_SetEcatHomingPrm(1, 34, SPEED1, SPEED2, ACC, 0, 0) == 0
    assert gt.GT_StartEcatHoming(1) == 0
    seen = [status(1)]  # no time passes in lockstep: the very next read
    while seen[-1] != 3 and len(seen) < 5000:
        gt.GTE_Wait(1)
        seen.append(status(1))
    assert seen[0] == 0
    assert seen[-1] == 3
    collapsed = [s for i, s in enumerate(seen) if i == 0 or s != seen[i - 1]]
    assert collapsed == [0, 3]  # in progress (also while moving onto the home point), done


def test_homing_can_be_started_again_after_completion(five_axes: Path) -> None:
    bring_up(str(five_axes), machine=machine((0,)))
    start(1, 34, offset=10)
    assert wait_done(1) == 3
    assert gt.GT_SetEcatHomingPrm(1, 2, SPEED1, SPEED2, ACC, 20, 0) == 0
    assert gt.GT_StartEcatHoming(1) == 0  # CW4 still high: dropped for a cycle, raised again
    assert status(1) == 0
    assert wait_done(1) == 3
    gt.GTE_Wait(50)
    assert machine_pos(1) == pytest.approx(16700, abs=1e-3)  # PL, first index left of it
    assert enc_pos(1) == 20


@pytest.mark.long
def test_homing_error_when_the_switch_is_never_found(five_axes: Path) -> None:
    """Method 3 without a home switch runs into PL, where it may not reverse: SW13."""
    bring_up(str(five_axes), machine=machine((0,)))
    start(1, 3)
    seen, braking = set(), False
    for _ in range(5000):
        s = status(1)
        seen.add(s)
        braking |= statusword(1) & (SW10 | SW13) == SW13 and s == 0
        if s & 1:
            break
        gt.GTE_Wait(1)
    assert s == 5  # done (at rest) with an error
    assert seen == {0, 5}
    assert braking  # SW13 while still braking reads 0: the result comes with standstill
    assert machine_pos(1) >= 20000  # it went as far as the positive limit
    assert gt.GT_SetHomingMode(1, 8) == 0
    assert status(1) == 5


# --- return codes ------------------------------------------------------------------------------
def test_start_refused_with_reasons_and_does_nothing(five_axes: Path) -> None:
    """5.2.2.2: servo on, mode homing and parameters set, else 1 and no action."""
    bring_up(str(five_axes), machine=machine((0,)))
    ax = gt.GTE_Controller().axis(1)
    assert gt.GT_StartEcatHoming(1) == 1
    assert "GT_AxisOn" in gt.GTE_GetLastError()
    assert gt.GT_AxisOn(1) == 0
    assert gt.GT_StartEcatHoming(1) == 1
    assert "GT_SetHomingMode" in gt.GTE_GetLastError()
    assert gt.GT_SetHomingMode(1, 6) == 0
    assert gt.GT_StartEcatHoming(1) == 1
    assert "GT_SetEcatHomingPrm" in gt.GTE_GetLastError()
    assert not ax.cw & 0x10
    gt.GTE_Wait(100)
    assert machine_pos(1) == 0.0 and status(1) == 5  # refused starts start no run
    assert gt.GT_SetEcatHomingPrm(1, 34, SPEED1, SPEED2, ACC, 0, 0) == 0
    assert gt.GT_StartEcatHoming(1) == 0
    assert gt.GT_StartEcatHoming(1) == 1  # already homing
    assert "already homing" in gt.GTE_GetLastError()
    assert gt.GTN_StopEcatHoming(1, 1) == 0  # the GTN twin, core 1
    assert gt.GT_GetEcatHomingStatus(1, byref(c_short())) == 0


def test_mode_refused_while_not_reached_by_the_drive(five_axes: Path) -> None:
    bring_up(str(five_axes), machine=machine((0,)))
    assert gt.GT_SetHomingMode(1, 5) == 7  # not a mode the controller knows (entry 100)
    assert gt.GT_SetHomingMode(1, 2) == 7
    assert gt.GT_SetHomingMode(9, 6) == 7  # no axis 9
    assert gt.GT_SetHomingMode(1, 6) == 0
    mode = c_short()
    assert gt.GT_GetEcatAxisMode(1, byref(mode)) == 0 and mode.value == 6  # at once
    out = c_ubyte()
    assert gt.GT_GetEcatAxisPdoData(1, 0x6060, byref(out)) == 0 and out.value == 6  # by PDO


@pytest.mark.parametrize(
    ("args", "code", "words"),
    [
        ((3, -1, 3000, 100000, 0, 0), 7, "speed1"),
        ((3, 5000, 0, 100000, 0, 0), 7, "speed2"),
        ((3, 5000, 3000, float("nan"), 0, 0), 7, "acc"),
        ((3, 5000, 3000, 2.0**33, 0, 0), 7, "acc"),
        ((3, 5000, 3000, 100000, 1 << 31, 0), 7, "offset"),
        ((3, 5000, 3000, 100000, 0, 0x10000), 7, "probeFunction"),
        ((200, 5000, 3000, 100000, 0, 0), 7, "method"),
        ((15, 5000, 3000, 100000, 0, 0), 1, "0x6098"),  # reserved method: the drive refuses
        ((-3, 5000, 3000, 100000, 0, 0), 1, "0x06090030"),
    ],
)
def test_homing_parameters_refused(five_axes: Path, args, code: int, words: str) -> None:
    bring_up(str(five_axes), machine=machine((0,)))
    assert gt.GT_SetEcatHomingPrm(1, *args) == code
    assert words in gt.GTE_GetLastError()
    assert gt.GT_AxisOn(1) == 0 and gt.GT_SetHomingMode(1, 6) == 0
    assert gt.GT_StartEcatHoming(1) == 1  # parameters not (successfully) set


def test_methods_35_37_take_zero_speeds() -> None:
    bring_up(machine=machine((4321,)))
    assert gt.GT_AxisOn(1) == 0 and gt.GT_SetHomingMode(1, 6) == 0
    assert gt.GT_SetEcatHomingPrm(1, 37, 0, 0, 0, -5, 0) == 0
    assert gt.GT_StartEcatHoming(1) == 0
    assert status(1) == 3
    assert enc_pos(1) == -5 and machine_pos(1) == pytest.approx(4321)


def test_probe_function_parameter_arms_the_probe_with_homing() -> None:
    """probeFunction != 0 goes to 60B8h (for probe-based methods); 0 leaves it alone."""
    bring_up("homing_probe.eni", machine=machine((0,), probe1=[(300.25, 400)]))
    assert gt.GT_SetEcatHomingPrm(1, 34, SPEED1, SPEED2, ACC, 0, 0x0011) == 0
    fn = c_long()
    assert gt.GT_GetEcatAxisPdoData(1, 0x60B8, byref(fn)) == 0 and fn.value == 0x0011
    start(1, 34)  # probeFunction 0 this time: the armed probe stays armed
    assert wait_done(1) == 3
    sts, rise = c_short(), c_long()
    assert gt.GT_GetTouchProbeStatus(1, byref(sts), byref(rise)) == 0
    assert sts.value & 0b11 == 0b11  # enabled, rising edge stored
    assert abs(rise.value - 300.25) <= 1


def test_machine_position_helper_errors() -> None:
    assert gt.GTE_GetMachinePos(1, byref(c_double())) == -1  # not open
    assert gt.GT_Open(eni=str(EXAMPLES / "manual_fig5_2.eni"), log="") == 0
    assert gt.GTE_GetMachinePos(1, byref(c_double())) == 7  # bus not up: no axes
    gt.GT_Close()
    bring_up(machine=machine((2500.5, -3)))
    assert machine_pos(1) == 2500.5 and machine_pos(2) == -3.0
    assert gt.GTE_GetMachinePos(3, byref(c_double())) == 7


def test_vendor_loop_on_the_figure_5_2_bus_by_sdo() -> None:
    bring_up(machine=machine((0, 2000)), clock="lockstep")
    start(1, 34)
    start(2, 33)
    assert vendor_loop(range(1, 3)) == {1: [0, 3], 2: [0, 3]}


@pytest.mark.parametrize(
    ("layout", "starts", "method"),
    [c[1:] for c in ERROR_CASES],
    ids=[c[0] for c in ERROR_CASES],
)
@pytest.mark.long
def test_vendor_loop_sees_0_then_5_on_a_homing_error(
    five_axes: Path, layout: dict, starts: tuple, method: int
) -> None:
    """Manual entry 43: a homing error (SW13) reads 0 until the drive stands, then 5."""
    axes = {
        n: AxisMachine(position=float(s), **{**INDEX, **LIMITS, **layout})
        for n, s in enumerate(starts, 1)
    }
    bring_up(str(five_axes), machine=MachineDescription(axes), clock="lockstep")
    for a in range(1, len(starts) + 1):
        start(a, method)
    seen = vendor_loop(range(1, len(starts) + 1))
    assert all(s == [0, 5] for s in seen.values()), seen
    assert all(statusword(a) & SW13 for a in seen)


def test_vendor_do_while_loop_terminates_in_auto_clock(five_axes: Path) -> None:
    """The loop exactly as the demo writes it: no wait, each call costs virtual latency."""
    bring_up(str(five_axes), machine=machine((0,)))
    start(1, 34)
    st, seen = c_short(), []
    while True:  # do { GT_GetEcatHomingStatus(axis, &st); } while (st == 0);
        assert gt.GT_GetEcatHomingStatus(1, byref(st)) == 0
        seen.append(st.value)
        if st.value != 0 or len(seen) > 1_000_000:
            break
    assert set(seen[:-1]) == {0} and seen[-1] == 3
    assert machine_pos(1) == pytest.approx(700, abs=1.0)


def test_never_started_reads_5_so_the_vendor_loop_ends_without_success(five_axes: Path) -> None:
    """Before any start, in any mode: 5 (not homed), neither 0 (would hang) nor 3 (a lie)."""
    bring_up(str(five_axes), machine=machine((0,)), clock="lockstep")
    assert status(1) == 5
    assert gt.GT_AxisOn(1) == 0 and status(1) == 5
    assert gt.GT_SetHomingMode(1, 6) == 0 and status(1) == 5
    assert gt.GT_SetEcatHomingPrm(1, 34, SPEED1, SPEED2, ACC, 0, 0) == 0
    gt.GTE_Wait(10)
    assert status(1) == 5  # parameters alone start nothing
    assert gt.GT_StopEcatHoming(1) == 0 and status(1) == 5  # nor does a stop


@pytest.mark.parametrize("how", ["stop", "axis off", "axis mode 8", "homing mode 8"])
def test_a_run_ended_from_outside_reads_5(five_axes: Path, how: str) -> None:
    """GT_StopEcatHoming, servo off, another mode: the vendor loop ends with 5, never hangs."""
    bring_up(str(five_axes), machine=machine((0,), home_switch=[(15000, 30000)]), clock="lockstep")
    start(1, 3)
    gt.GTE_Wait(100)  # searching for the switch
    assert status(1) == 0
    calls = {
        "stop": lambda: gt.GT_StopEcatHoming(1),
        "axis off": lambda: gt.GT_AxisOff(1),
        "axis mode 8": lambda: gt.GT_SetEcatAxisMode(1, 8),
        "homing mode 8": lambda: gt.GT_SetHomingMode(1, 8),
    }
    assert calls[how]() == 0, gt.GTE_GetLastError()
    seen = vendor_loop(range(1, 2), limit_ms=1000)[1]
    assert seen in ([0, 5], [5])
    gt.GTE_Wait(50)
    assert status(1) == 5


def test_a_second_run_reads_0_until_done_again(five_axes: Path) -> None:
    """A restart after a completed run: the old 3 never shows before the drive has answered."""
    bring_up(str(five_axes), machine=machine((0,)), clock="lockstep")
    start(1, 34)
    assert vendor_loop(range(1, 2)) == {1: [0, 3]}
    assert gt.GT_SetEcatHomingPrm(1, 2, SPEED1, SPEED2, ACC, 0, 0) == 0
    assert gt.GT_StartEcatHoming(1) == 0
    assert vendor_loop(range(1, 2)) == {1: [0, 3]}
    gt.GTE_Wait(50)
    assert machine_pos(1) == pytest.approx(16700, abs=1e-3)  # PL, first index left of it


# --- a search the machine description cannot end ------------------------------------------------
def test_a_search_for_a_switch_the_machine_lacks_says_so_in_the_log_and_when_polled() -> None:
    """Method 24 (home switch, manual 5.2.2.2's table) on a machine without home_switch: the
    drive searches (a real one would), and the master log and GTE_GetLastError after each
    status poll say why it cannot end; a method that needs nothing says nothing."""
    bring_up(machine=MachineDescription({1: AxisMachine(), 2: AxisMachine()}), log="")
    start(1, 24)
    log = "\n".join(gt.GTE_Controller().log.lines)
    assert "Axis 1: homing method 24 searches for a home switch (home_switch)" in log
    st = c_short()
    assert gt.GT_GetEcatHomingStatus(1, byref(st)) == 0 and st.value == 0
    reason = gt.GTE_GetLastError()
    assert reason.startswith("GT_GetEcatHomingStatus returned 0: axis 1: homing method 24")
    assert "machine description gives this axis none" in reason
    assert gt.GT_GetPrfPos(1, byref(c_double())) == 0 and gt.GTE_GetLastError() == ""
    start(2, 35)  # the current position: nothing to search for, no hint
    assert gt.GT_GetEcatHomingStatus(2, byref(st)) == 0 and gt.GTE_GetLastError() == ""
