"""The manual's examples 7-3 to 7-8 as scripts (examples/), run in the lockstep clock and checked
sample by sample against independently integrated plans, plus the shapes their figures show.

References: PT velocity pieces of 7.4.2 (``tests/gtecat/controller/motion/test_pt.py``), the
gear's area under the ratio in master travel (``test_gear.py``) and the Follow ratio curve of
7.6.2 (5) (``test_follow.py``) - each written from the manual's text, not from the planners.
"""

from __future__ import annotations

import importlib.util
import math
import sys
from ctypes import c_double

import numpy as np
import pytest

from gtecat import gt
from tests.conftest import EXAMPLES
from tests.gtecat.controller.motion.test_follow import cam, cam_at
from tests.gtecat.controller.motion.test_gear import clutch_reference, jog
from tests.gtecat.controller.motion.test_pt import integrate, velocity_pieces

MOVING = 1 << 10
PN, PE, PS = gt.PT_SEGMENT_NORMAL, gt.PT_SEGMENT_EVEN, gt.PT_SEGMENT_STOP
FN, FE, FC = gt.FOLLOW_SEGMENT_NORMAL, gt.FOLLOW_SEGMENT_EVEN, gt.FOLLOW_SEGMENT_CONTINUE


@pytest.fixture(autouse=True)
def _closed_controller():
    gt.GT_Close()
    yield
    gt.GT_Close()


def example(name: str):
    """examples/<name>.py as a module (examples/ is not a package)."""
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
        assert spec is not None and spec.loader is not None
        mod = importlib.util.module_from_spec(spec)
        sys.modules[name] = mod  # dataclasses look their module up while the class is built
        spec.loader.exec_module(mod)
    return sys.modules[name]


# --- 7-3 PT static FIFO ---------------------------------------------------------------------
def test_example_7_3_trapezoid_sample_by_sample():
    r = example("example_7_3_pt").run(clock="lockstep")
    assert r["errors"] == []
    t = np.array(r["t"], dtype=float)
    assert np.array_equal(t, np.arange(1, 3073))  # 3072 ms, one sample per cycle
    points = [(1024, 1024, PN), (3072, 2048, PN), (4096, 3072, PN)]
    np.testing.assert_allclose(r["pos"], integrate(velocity_pieces(points), t), atol=1e-9)
    vel = np.array(r["vel"])
    # figure 7-8: 0 -> 2 pulse/ms in 1024 ms, 2 until 2048 ms, back to 0 at 3072 ms
    assert vel[511] == pytest.approx(1.0) and vel.max() == pytest.approx(2.0)
    assert np.all(np.abs(vel[1023:2047] - 2.0) < 1e-12)
    assert r["pos"][-1] == 4096 and vel[-1] == 0.0 and not r["sts"][-1] & MOVING


@pytest.mark.long
def test_example_7_3_in_the_auto_clock_keeps_its_shape():
    r = example("example_7_3_pt").run(clock="auto")
    assert r["errors"] == [] and r["pos"][-1] == 4096
    assert max(r["vel"]) == pytest.approx(2.0)
    assert 3072 <= r["t"][-1] <= 3074


# --- 7-4 PT dynamic FIFO ---------------------------------------------------------------------
def manual_sine_stream():
    """The GT_PtData calls of example 7-4's listing (A 50, T 1 s, DELTA 16 ms, 2 periods,
    PI = 3.1415926 as the listing writes it)."""
    a, period, delta, loops, pi = 50, 1, 0.016, 2, 3.1415926
    t = pos = vel_pre = 0.0
    loop = 1
    while loop <= loops:
        t += delta
        vel = a * math.sin(2 * pi / period * t)
        pos += 1000 * (vel + vel_pre) * delta / 2
        vel_pre = vel
        if t < loop * period:
            yield pos, round(t * 1000), PN
        else:
            yield 0.0, loop * period * 1000, PS
            pos, t, vel_pre = 0.0, loop * period, 0.0
            loop += 1


@pytest.mark.long
def test_example_7_4_sine_through_the_dynamic_fifos_sample_by_sample():
    r = example("example_7_4_pt_dynamic").run(clock="lockstep")
    assert r["errors"] == []
    stream = list(manual_sine_stream())
    assert len(stream) == 126 > 64  # more than both FIFOs hold: the hand-over is needed
    t = np.array(r["t"], dtype=float)
    assert np.array_equal(t, np.arange(0, 2001))
    ref = integrate(velocity_pieces(stream, dynamic=True), t)
    np.testing.assert_allclose(r["pos"], ref, atol=1e-8)
    assert r["pos"][-1] == 0.0 and r["pos"][1000] == pytest.approx(0.0, abs=1e-9)
    # started with both FIFOs full; later a used-up FIFO came back empty and was refilled
    space = r["space"]
    assert space[0] == 0 and 32 in space
    assert r["pushing"][0] and not r["pushing"][-1]  # everything was sent before the end
    # figure 7-9: speed follows 50 sin(2πt / 1 s) within the 16 ms linearisation
    vel = np.array(r["vel"])
    assert np.max(np.abs(vel[1:-1] - 50 * np.sin(2 * np.pi * t[1:-1] / 1000))) < 0.1


# --- 7-5 electronic gear ---------------------------------------------------------------------
@pytest.mark.long
def test_example_7_5_clutch_of_100000_master_pulses_sample_by_sample():
    r = example("example_7_5_gear").run(clock="lockstep")
    assert r["errors"] == []
    assert r["t"] == list(range(1, 2001))
    master = np.array(r["master"])
    slave = np.array(r["slave"])
    assert master[-1] > 100000
    expected = clutch_reference(master, 0.0, 0.5, 100000)
    np.testing.assert_allclose(slave, expected, atol=1e-7)
    # figures 7-11 / 7-12: master at 100 pulse/ms, slave reaching 50 when the clutch closes
    k = int(np.argmax(master >= 100000))
    assert slave[k] == pytest.approx(25000.0)  # (0 + 1/2) / 2 · 100000
    vs = np.array(r["vslave"])
    assert np.all(vs[k + 1 :] == pytest.approx(50.0))
    assert np.all(np.diff(vs[: k + 1]) > 0)  # the slave speeds up through the clutch
    assert np.all(np.array(r["vmaster"])[200:] == 100.0)


def test_example_7_5_master_is_the_manual_jog():
    """The master samples are the Jog closed form (acc 1, 100 pulse/ms) shifted by the
    controller's half-step integration; the gear follows what the master actually did."""
    r = example("example_7_5_gear").run(scans=300, clock="lockstep")
    master = np.array(r["master"])
    t = np.arange(1, 301, dtype=float)
    assert np.max(np.abs(master - jog(t, 1.0, 100.0))) <= 50.0


# --- 7-6 flying shear --------------------------------------------------------------------------
REGION_1 = [(5000, 2500, FN)]
REGION_2 = [
    (1000, 1000, FE),
    (4000, 3400, FN),
    (6000, 4600, FN),
    (9000, 7000, FN),
    (10000, 8000, FE),
]


@pytest.mark.long
def test_example_7_6_flying_shear_8000_knife_pulses_per_10000_belt_pulses():
    r = example("example_7_6_flying_shear").run(clock="lockstep")
    assert r["errors"] == []
    master = np.array(r["master"])
    slave = np.array(r["slave"])
    n = int(master[-1] // 10000) + 2
    expected = cam_at(cam([REGION_1] + [REGION_2] * n), master)
    np.testing.assert_allclose(slave, expected, atol=1e-7)
    # region 1 catches up: knife at 2500 when the belt reaches 5000, with the belt's speed
    k = int(np.argmax(master >= 5000))
    assert master[k] == 5000 and slave[k] == pytest.approx(2500)
    vm, vs = np.array(r["vmaster"]), np.array(r["vslave"])
    assert vs[k] == pytest.approx(vm[k], abs=0.5)  # the last cycle's mean ratio: 0.995
    assert vs[k + 1] == pytest.approx(vm[k + 1], abs=1e-9)
    # FIFO1 cleared when region 2 takes over, then region 2 repeats
    assert r["space0"][k - 1] == 15 and r["space0"][k + 1] == 16
    cuts = [(m, s) for m, s in zip(master, slave, strict=True) if m >= 5000 and m % 10000 == 5000]
    assert len(cuts) >= 10
    for m, s in cuts:
        assert s == pytest.approx(2500 + 0.8 * (m - 5000), abs=1e-7)  # 10000 belt <-> 8000 knife
    # speed-synchronous zones: ratio exactly 1 (knife speed = belt speed) 1000 either side of a cut
    x = (master - 5000) % 10000
    prev = np.concatenate([[0.0], master[:-1]])
    xp = (prev - 5000) % 10000
    inside = (master > 5000) & (prev >= 5000) & (((xp < x) & (x <= 1000)) | (xp >= 9000))
    assert inside.sum() > 200
    assert np.all(np.abs(vs[inside] - vm[inside]) < 1e-9)
    # between the zones the knife slows down to ratio 0.6 (1200 over 2000 belt pulses)
    slow = (master > 5000) & (xp >= 4000) & (x <= 6000) & (xp < x)
    assert slow.sum() > 100
    assert np.all(np.abs(vs[slow] - 0.6 * vm[slow]) < 1e-9)
    assert r["loop"][-1] == len(cuts) - 1  # passes of region 2 completed


# --- 7-7 Follow single FIFO -------------------------------------------------------------------
TABLE_7_10 = [(20000, 10000, FN), (40000, 30000, FN), (60000, 40000, FN)]


@pytest.mark.long
def test_example_7_7_start_after_the_50000_pass_endless_trapezoid_cam():
    r = example("example_7_7_follow").run(clock="lockstep")
    assert r["errors"] == []
    master = np.array(r["master"])
    slave = np.array(r["slave"])
    x = np.clip(master - 50000, 0, None)
    n = int(x[-1] // 60000) + 2
    np.testing.assert_allclose(slave, cam_at(cam([TABLE_7_10] * n), x), atol=1e-7)
    start = int(np.argmax(master > 50000))
    assert np.all(slave[:start] == 0)  # waiting for the pass
    assert all(s & MOVING for s in r["sts"])  # waiting counts as motion
    np.testing.assert_array_equal(r["loop"], (x // 60000).astype(int))
    assert r["loop"][-1] >= 4
    # figure 7-18 per pass: ratio 0 -> 1, 1, 1 -> 0 (the master runs at 50 by then)
    vs = np.array(r["vslave"])
    phase = x % 60000
    cruise = (x > 0) & (phase > 20000 + 50) & (phase < 40000 - 50)
    assert np.all(np.abs(vs[cruise] - 50.0) < 1e-9)
    assert vs.max() == pytest.approx(50.0)
    near_end = (x > 0) & ((phase < 100) | (phase > 60000 - 100))
    assert np.all(vs[near_end] < 1.0)


# --- 7-8 Follow double-FIFO switch ------------------------------------------------------------
TABLE_7_11 = [(20000, 10000, FN), (40000, 30000, FN), (60000, 40000, FN)]
TABLE_7_12 = [(20000, 10000, FC), (40000, 30000, FN), (60000, 46000, FN)]
TABLE_7_13 = [(20000, 16000, FC), (40000, 36000, FN), (60000, 52000, FN)]


@pytest.mark.long
def test_example_7_8_strategy_changed_through_the_two_fifos():
    r = example("example_7_8_follow_switch").run(clock="lockstep")
    assert r["errors"] == []
    master = np.array(r["master"])
    slave = np.array(r["slave"])
    assert 30000 < master[r["pressed"]] < 60000  # the second xStart during FIFO1's first pass
    n = int(master[-1] // 60000) + 2
    expected = cam_at(cam([TABLE_7_11, TABLE_7_12] + [TABLE_7_13] * n), master)
    np.testing.assert_allclose(slave, expected, atol=1e-7)
    stage = np.array(r["stage"])
    # STAGE_TO_FIFO2 until FIFO1 is cleared at master 60000, STAGE_TO_FIFO1 until 120000
    assert stage[-1] == 4
    assert np.all(stage[(master > r["master"][r["pressed"]]) & (master < 60000)] == 2)
    assert np.all(stage[(master > 60000 + 50) & (master < 120000)] == 3)
    # figure 7-20: after the transition the ratio runs 0.6 -> 1 -> 1 -> 0.6 for ever
    vs, vm = np.array(r["vslave"]), np.array(r["vmaster"])
    phase = (master - 120000) % 60000
    after = master > 120000 + 100
    assert np.all(np.abs(vs[after & (phase > 59900)] / vm[after & (phase > 59900)] - 0.6) < 0.01)
    assert np.all(np.abs(vs[after & (phase > 20100) & (phase < 39900)] - 50) < 1e-9)
    # and the transition started with the ratio curve 1 ended with (0, CONTINUE)
    k = int(np.argmax(master > 60000))
    assert vs[k] < 1.0


# --- 7-5, 7-7, 7-8: 8 profiles read on a 2-axis bus -------------------------------------------
@pytest.mark.parametrize(
    "name", ["example_7_5_gear", "example_7_7_follow", "example_7_8_follow_switch"]
)
def test_examples_7_5_7_7_7_8_read_8_profiles_as_printed(name):
    """Examples 7-5, 7-7 and 7-8 end every scan with ``GT_GetPrfVel(1, ADR(arrPrfVel), 8, 0)``
    on the figure 5-2 bus of 2 drives: the controller's 12 profiles exist whatever the bus
    holds (the count rule of ``resources.axis_span``), so the read returns 0 (the scripts log
    any non-zero return into ``errors``) and profiles 3..8 read 0."""
    mod = example(name)
    mod.LOG.clear()
    mod.bring_up(clock="lockstep")
    try:
        v = mod.PlcVars()
        mod.plc_prg(v)
        v.xStart = True
        mod.plc_prg(v)
        for _ in range(5):
            gt.GTE_Wait(1)
            mod.plc_prg(v)
        assert list(mod.LOG) == []
        assert len(v.arrPrfVel) == 8 and v.arrPrfVel[2:] == [0.0] * 6
        assert gt.GT_ClrSts(1, 8) == 0  # the same rule as the examples' GT_ClrSts(1, 8)
        assert gt.GT_GetPrfVel(1, (c_double * 13)(), 13, 0) == 7  # past axis 12
    finally:
        gt.GT_Close()
