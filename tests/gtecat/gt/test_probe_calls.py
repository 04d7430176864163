"""GT touch-probe calls through ``from gtecat import gt``: example 5-3 and the 60B8h/60B9h rules.

Manual 5.2.2.3, example 5-3, chapter 13 entries 73, 123, 124; ETG.6010 / CiA 402
touch probe (cia402-facts §4).  Marks sit between whole counts (x.3) and the axes
sweep at speeds whose per-cycle travel (7.301, 14.2, 33.333, 260 counts) puts every
edge between two position samples: a capture taken at a sample would be off by up to
the travel of one cycle; the exact crossing is within one count.
"""

from __future__ import annotations

import importlib.util
import sys
from ctypes import byref, c_long, c_short, c_uint16, c_ushort

import pytest
from hypothesis import given
from hypothesis import strategies as st

from gtecat import gt
from gtecat.drives.machine import AxisMachine, MachineDescription
from gtecat.gt.homing_calls import probe_function_ex
from tests.conftest import EXAMPLES

from .conftest import bring_up

RISING = [x + 0.3 for x in range(10037, 45038, 5000)]  # homing_probe_machine.toml axis 2
FALLING = [x + 200 for x in RISING]


def _example_5_3():
    """examples/example_5_3_probe.py as a module (examples/ is not a package)."""
    name = "example_5_3_probe"
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
        assert spec is not None and spec.loader is not None
        mod = importlib.util.module_from_spec(spec)
        sys.modules[name] = mod  # dataclasses look their module up while the class is built
        spec.loader.exec_module(mod)
    return sys.modules[name]


def within_one_count(captured: list[int], edges: list[float]) -> bool:
    return len(captured) == len(edges) and all(
        abs(c - e) <= 1.0 for c, e in zip(captured, edges, strict=True)
    )


def probe_status(axis: int) -> tuple[int, list[int]]:
    sts = c_ushort()
    vals = [c_long() for _ in range(4)]
    rc = gt.GT_GetTouchProbeStatus(axis, byref(sts), *(byref(v) for v in vals))
    assert rc == 0, gt.GTE_GetLastError()
    return sts.value, [v.value for v in vals]


def sweep(axis: int, speed: int, until: float, on_scan=None) -> None:
    """Cyclic synchronous velocity (entries 100, 102) until the encoder passes ``until``."""
    assert gt.GT_SetEcatAxisMode(axis, 9) == 0, gt.GTE_GetLastError()
    assert gt.GT_SetEcatAxisPV(axis, speed) == 0, gt.GTE_GetLastError()
    enc = c_long()
    for _ in range(100_000):
        gt.GTE_Wait(1)
        if on_scan is not None:
            on_scan()
        gt.GT_GetEcatEncPos(axis, byref(enc))
        if (enc.value - until) * speed >= 0:
            break
    assert gt.GT_SetEcatAxisPV(axis, 0) == 0
    gt.GTE_Wait(100)


# --- example 5-3 ------------------------------------------------------------------------------
@pytest.mark.parametrize("speed", [7301, 14200, 33333, 260000])
@pytest.mark.sample(1)
def test_example_5_3_captures_every_rising_edge_within_one_count(speed: int) -> None:
    r = _example_5_3().run(speed=speed)
    assert r["rtn"] == 0
    assert within_one_count(r["captures"], RISING), r["captures"]
    assert r["last_value"] == r["captures"][-1]
    # after GT_SetTouchProbeFunction(axis, 0): enabled and stored bits cleared (5.2.2.3)
    assert r["status_after_stop"] & 0x0707 == 0


@pytest.mark.long
def test_example_5_3_in_lockstep() -> None:
    r = _example_5_3().run(clock="lockstep")
    assert within_one_count(r["captures"], RISING)


# --- the 60B8h / 60B9h rules through the GT calls --------------------------------------------
@pytest.mark.long
def test_both_edges_continuous_toggle_bits_6_and_7() -> None:
    bring_up("homing_probe.eni", machine=str(EXAMPLES / "homing_probe_machine.toml"))
    assert gt.GT_AxisOn(2) == 0
    assert gt.GT_SetTouchProbeFunction(2, 0x0033) == 0  # probe 1, continuous, both edges
    rises, falls = [], []
    last = {"sts": probe_status(2)[0]}

    def scan() -> None:
        sts, vals = probe_status(2)
        if (sts ^ last["sts"]) & (1 << 6):
            rises.append(vals[0])
        if (sts ^ last["sts"]) & (1 << 7):
            falls.append(vals[1])
        last["sts"] = sts

    sweep(2, 9999, 47000, scan)
    assert within_one_count(rises, RISING)
    assert within_one_count(falls, FALLING)
    sts, _ = probe_status(2)
    assert sts & 0b111 == 0b111  # enabled, both edges stored; they stay until disabled


@pytest.mark.long
def test_first_event_keeps_the_first_capture_until_rearmed() -> None:
    bring_up("homing_probe.eni", machine=str(EXAMPLES / "homing_probe_machine.toml"))
    assert gt.GT_AxisOn(2) == 0
    assert (
        gt.GT_SetTouchProbeFunctionEx(
            2, 1, gt.ECAT_PROBE_TRIGGER_TYPE_FIRST_EVENT, gt.ECAT_PROBE_TRIGGER_LEVEL_POS, 0, 0, 0
        )
        == 0
    )
    fn = c_uint16()
    assert gt.GT_GetEcatAxisPdoData(2, 0x60B8, byref(fn)) == 0 and fn.value == 0x0011
    sweep(2, 14200, 22000)
    sts, vals = probe_status(2)
    assert sts & 0b11 == 0b11 and not sts & (1 << 6)  # stored; no toggle in first-event mode
    assert abs(vals[0] - RISING[0]) <= 1  # the first mark, not the later ones
    # re-arm: switch the probe off and on again; the old value stays until the next edge
    assert gt.GT_SetTouchProbeFunction(2, 0) == 0
    assert gt.GT_SetTouchProbeFunction(2, 0x0011) == 0
    sts, vals = probe_status(2)
    assert sts & 0b11 == 0b01 and abs(vals[0] - RISING[0]) <= 1
    sweep(2, 14200, 27000)
    sts, vals = probe_status(2)
    assert sts & 0b11 == 0b11 and abs(vals[0] - RISING[3]) <= 1


@pytest.mark.parametrize("eni", ["homing_probe.eni", "manual_fig5_2.eni"])
def test_rearm_by_the_edge_bit_in_lockstep(eni: str) -> None:
    """ETG.6010 re-arm: 60B8h bit 4 off, then on.  In lockstep no time passes between the
    two calls, so each set call must let the drive take its value (else the 0 never reaches
    the wire and the probe stays stored); the status read right after is the new one."""
    machine = MachineDescription(
        {1: AxisMachine(probe1=((10000.0, 10300.0), (20000.0, 20300.0)))}, "two marks"
    )
    bring_up(eni, machine=machine, clock="lockstep")
    assert gt.GT_AxisOn(1) == 0
    assert gt.GT_SetTouchProbeFunction(1, 0x0011) == 0
    prm = gt.TTrapPrm(acc=5.0, dec=5.0)

    def move(target: int) -> None:
        for call in (
            gt.GT_PrfTrap(1),
            gt.GT_SetTrapPrm(1, byref(prm)),
            gt.GT_SetPos(1, target),
            gt.GT_SetVel(1, 50.0),
            gt.GT_Update(1),
        ):
            assert call == 0, gt.GTE_GetLastError()
        sts = c_long()
        while gt.GT_GetSts(1, byref(sts)) == 0 and sts.value & (1 << 10):
            gt.GTE_Wait(1)

    move(15000)
    sts, vals = probe_status(1)
    assert sts & 0b11 == 0b11 and vals[0] == 10000
    assert gt.GT_SetTouchProbeFunction(1, 0x0001) == 0  # rising edge off: bit 1 cleared
    assert probe_status(1)[0] & 0b11 == 0b01
    assert gt.GT_SetTouchProbeFunction(1, 0x0011) == 0  # on again: armed
    assert probe_status(1)[0] & 0b11 == 0b01
    move(25000)
    sts, vals = probe_status(1)
    assert sts & 0b11 == 0b11 and vals[0] == 20000


def test_probe_2_both_edges_by_description() -> None:
    marks = [(-3000.7, -2500.2), (-9000.4, -8000.9)]
    m = MachineDescription({1: AxisMachine(position=0, probe2=marks)})
    bring_up("homing_probe.eni", machine=m)
    assert gt.GT_AxisOn(1) == 0
    rc = gt.GT_SetTouchProbeFunctionEx(
        1, 0, 0, 0, 1, gt.ECAT_PROBE_TRIGGER_TYPE_CONTINUES, gt.ECAT_PROBE_TRIGGER_LEVEL_DUL
    )
    assert rc == 0, gt.GTE_GetLastError()
    fn = c_uint16()
    assert gt.GT_GetEcatAxisPdoData(1, 0x60B8, byref(fn)) == 0 and fn.value == 0x3300
    sweep(1, -21_000, -10_000)  # moving -: the mark's high end is the rising edge
    sts, vals = probe_status(1)
    assert sts & 0x0701 == 0x0700
    assert sts & (1 << 14) == 0 and sts & (1 << 15) == 0  # two captures each: toggled twice
    assert abs(vals[2] - (-8000.9)) <= 1 and abs(vals[3] - (-9000.4)) <= 1  # the last mark


def test_encoder_index_source() -> None:
    """60B8h bits 3:2 = 01 (ETG.6010 "encoder zero impulse"): passed through as written."""
    m = MachineDescription({1: AxisMachine(counts_per_rev=10000, index_offset=1234.6)})
    bring_up("homing_probe.eni", machine=m)
    assert gt.GT_AxisOn(1) == 0
    assert gt.GT_SetTouchProbeFunction(1, 0x0017) == 0
    seen: list[int] = []
    last = {"sts": 0}

    def scan() -> None:
        sts, vals = probe_status(1)
        if (sts ^ last["sts"]) & (1 << 6):
            seen.append(vals[0])
        last["sts"] = sts

    sweep(1, 33333, 32000, scan)
    assert within_one_count(seen, [1234.6, 11234.6, 21234.6, 31234.6])


# --- SDO fallback (figure 5-2 maps no probe object) --------------------------------------------
def test_probe_over_sdo_during_homing_on_the_figure_5_2_bus() -> None:
    """The probe armed on a bus without probe PDOs: captures during an index search."""
    m = MachineDescription(
        {1: AxisMachine(counts_per_rev=10000, index_offset=9000, probe1=[(3000.3, 3100.3)])}
    )
    bring_up(machine=m)
    assert gt.GT_AxisOn(1) == 0
    assert gt.GT_SetTouchProbeFunction(1, 0x0031) == 0  # first event, both edges
    assert gt.GT_SetHomingMode(1, 6) == 0
    assert gt.GT_SetEcatHomingPrm(1, 34, 5000, 5000, 100000, 0, 0) == 0
    assert gt.GT_StartEcatHoming(1) == 0
    hs = c_short()
    for _ in range(5000):
        gt.GT_GetEcatHomingStatus(1, byref(hs))
        if hs.value & 1:
            break
        gt.GTE_Wait(1)
    assert hs.value == 3
    sts, vals = probe_status(1)
    assert sts & 0b111 == 0b111
    assert abs(vals[0] - 3000.3) <= 1 and abs(vals[1] - 3100.3) <= 1  # before 6064 moved home


def test_null_pointers_skip_objects() -> None:
    bring_up("homing_probe.eni")
    sts = c_ushort(0xFFFF)
    assert gt.GT_GetTouchProbeStatus(1, byref(sts)) == 0 and sts.value == 0
    rise = c_long(7)
    assert gt.GT_GetTouchProbeStatus(1, None, byref(rise), None, None, None) == 0
    assert rise.value == 0


@pytest.mark.parametrize(
    ("call", "args", "words"),
    [
        ("GT_SetTouchProbeFunction", (0x10000,), "ProbePrm"),
        ("GT_SetTouchProbeFunction", (-0x8001,), "ProbePrm"),
        ("GT_SetTouchProbeFunctionEx", (2, 0, 1, 0, 0, 0), "Probe1Enable"),
        ("GT_SetTouchProbeFunctionEx", (1, 2, 1, 0, 0, 0), "Probe1TriggerType"),
        ("GT_SetTouchProbeFunctionEx", (1, 0, 4, 0, 0, 0), "Probe1TriggerLevel"),
        ("GT_SetTouchProbeFunctionEx", (0, 0, 0, 1, 1, 0), "Probe2TriggerLevel"),
    ],
)
def test_bad_probe_parameters_return_7(call: str, args: tuple, words: str) -> None:
    bring_up("homing_probe.eni")
    assert getattr(gt, call)(1, *args) == 7
    assert words in gt.GTE_GetLastError()
    fn = c_uint16(0xFFFF)
    assert gt.GT_GetEcatAxisPdoData(1, 0x60B8, byref(fn)) == 0 and fn.value == 0  # unchanged


def test_negative_short_is_taken_bit_for_bit() -> None:
    bring_up("homing_probe.eni")
    assert gt.GT_SetTouchProbeFunction(1, -32749) == 0  # 0x8013
    fn = c_uint16()
    assert gt.GT_GetEcatAxisPdoData(1, 0x60B8, byref(fn)) == 0 and fn.value == 0x8013


def test_drive_without_touch_probe_returns_1_naming_the_object() -> None:
    bring_up()  # figure 5-2: 60B8h-60BDh not mapped, so SDO
    drive = gt.GTE_Slave(0)
    for index in range(0x60B8, 0x60BE):
        drive.od.objects.pop(index)  # a drive without touch probe
    assert gt.GT_GetTouchProbeStatus(1, byref(c_ushort())) == 1
    reason = gt.GTE_GetLastError()
    assert "0x60B9" in reason and "not mapped" in reason and "0x06020000" in reason
    assert gt.GT_SetTouchProbeFunction(1, 0x0013) == 1
    assert "0x60B8" in gt.GTE_GetLastError()
    # axis 2 still has its probe
    assert gt.GT_SetTouchProbeFunction(2, 0x0013) == 0
    assert probe_status(2)[0] & 1


def test_constants_are_exported() -> None:
    assert gt.ECAT_PROBE_TRIGGER_TYPE_FIRST_EVENT == 0
    assert gt.ECAT_PROBE_TRIGGER_TYPE_CONTINUES == 1
    assert (
        gt.ECAT_PROBE_TRIGGER_LEVEL_POS,
        gt.ECAT_PROBE_TRIGGER_LEVEL_NEG,
        gt.ECAT_PROBE_TRIGGER_LEVEL_DUL,
    ) == (1, 2, 3)
    assert callable(gt.GTN_SetTouchProbeFunctionEx) and callable(gt.GTN_GetTouchProbeStatus)


@given(
    st.tuples(st.integers(0, 1), st.integers(0, 1), st.integers(1, 3)),
    st.tuples(st.integers(0, 1), st.integers(0, 1), st.integers(1, 3)),
)
def test_probe_description_is_the_60b8_bit_pattern(p1, p2) -> None:
    """Enable bit 0/8, continuous bit 1/9, source 00, level in bits 5:4 / 13:12 (entry 124)."""
    word = probe_function_ex(*p1, *p2)
    for (en, typ, lev), shift in ((p1, 0), (p2, 8)):
        byte = (word >> shift) & 0xFF
        if en:
            assert byte & 1 and (byte >> 1) & 1 == typ and (byte >> 4) & 3 == lev
            assert (byte >> 2) & 3 == 0  # source: the probe input
            assert (lev == gt.ECAT_PROBE_TRIGGER_LEVEL_DUL) == (byte & 0x30 == 0x30)
        else:
            assert byte == 0
