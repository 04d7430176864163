"""PT mode through ``from gtecat import gt`` (lockstep clock): manual 7.4, chapter 13 entries 66-68,
89, 92-95, 119-120.  Positions are compared sample by sample with the velocity pieces of 7.4.2
integrated independently (``tests/gtecat/motion/test_pt.py``: written from the manual's text)."""

from __future__ import annotations

from ctypes import byref, c_double, c_int32, c_long, c_short

import numpy as np
import pytest

from gtecat import gt
from tests.gtecat.controller.motion.test_pt import integrate, velocity_pieces

from .conftest import bring_up

N, E, S = gt.PT_SEGMENT_NORMAL, gt.PT_SEGMENT_EVEN, gt.PT_SEGMENT_STOP
MOVING = 1 << 10
EX_7_3 = [(1024, 1024, N), (3072, 2048, N), (4096, 3072, N)]


def up(eni: str = "manual_fig5_2.eni", axes: tuple[int, ...] = (1,)) -> None:
    bring_up(eni, clock="lockstep")
    for a in axes:
        assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()
        assert gt.GT_ZeroPos(a, 1) == 0, gt.GTE_GetLastError()


def pos(axis: int = 1) -> float:
    p = c_double()
    assert gt.GT_GetPrfPos(axis, byref(p)) == 0
    return p.value


def vel(axis: int = 1) -> float:
    v = c_double()
    assert gt.GT_GetPrfVel(axis, byref(v)) == 0
    return v.value


def moving(axis: int = 1) -> bool:
    s = c_long()
    assert gt.GT_GetSts(axis, byref(s)) == 0
    return bool(s.value & MOVING)


def space(axis: int = 1, fifo: int = 0) -> int:
    s = c_short()
    assert gt.GT_PtSpace(axis, byref(s), fifo) == 0, gt.GTE_GetLastError()
    return s.value


def remainder(axis: int = 1) -> int:
    r = c_long()
    assert gt.GT_GetPtRemainder(axis, byref(r)) == 0, gt.GTE_GetLastError()
    return r.value


def push(axis: int, points, fifo: int = 0) -> None:
    for p, t, kind in points:
        assert gt.GT_PtData(axis, p, t, kind, fifo) == 0, gt.GTE_GetLastError()


def samples(axes=(1,), limit: int = 200_000) -> np.ndarray:
    """One cycle at a time until no axis of ``axes`` moves: rows of positions."""
    rows = []
    while True:
        gt.GTE_Wait(1)
        rows.append([pos(a) for a in axes])
        if not any(moving(a) for a in axes):
            return np.array(rows)
        assert len(rows) < limit


def rc_reason(rc: int, expected: int, *words: str) -> None:
    reason = gt.GTE_GetLastError()
    assert rc == expected, reason
    for w in words:
        assert w in reason, reason


# --- shapes -----------------------------------------------------------------------------------
def test_example_7_3_static_fifo_sample_by_sample():
    up()
    assert gt.GT_PrfPt(1, gt.PT_MODE_STATIC) == 0
    mode = c_long()
    assert gt.GT_GetPrfMode(1, byref(mode)) == 0 and mode.value == 2
    push(1, EX_7_3)
    assert space() == 29 and remainder() == 3
    assert gt.GT_PtStart(1, 0) == 0, gt.GTE_GetLastError()
    assert moving()
    out = samples()[:, 0]
    assert len(out) == 3072
    ref = integrate(velocity_pieces(EX_7_3), np.arange(1, 3073, dtype=float))
    np.testing.assert_allclose(out, ref, atol=1e-9)
    assert out[-1] == 4096 and vel() == 0.0
    assert remainder() == 3 and space() == 29  # static data stays


def test_random_sequences_match_the_integrated_reference_and_start_where_the_axis_stands():
    """20 random mixes of NORMAL / EVEN / STOP segments, each from where the last ended."""
    up()
    assert gt.GT_PrfPt(1) == 0
    rng = np.random.default_rng(7)
    here = 0.0
    for _ in range(20):
        assert gt.GT_PtClear(1, 0) == 0
        n = int(rng.integers(1, 9))
        pts = []
        p = t = 0
        for _ in range(n):
            p += int(rng.integers(-300, 300))
            t += int(rng.integers(1, 40))
            pts.append((p, t, int(rng.choice([N, N, E, S]))))
        push(1, pts)
        assert gt.GT_PtStart(1) == 0, gt.GTE_GetLastError()
        out = samples()[:, 0]
        assert len(out) == t
        ref = here + integrate(velocity_pieces(pts), np.arange(1, t + 1, dtype=float))
        np.testing.assert_allclose(out[:-1], ref[:-1], atol=1e-7)
        assert out[-1] == pytest.approx(here + p, abs=1e-9)
        here = out[-1]


@pytest.mark.long
def test_loops_repeat_the_fifo_and_get_pt_loop_counts_passes():
    up()
    assert gt.GT_PrfPt(1) == 0
    push(1, EX_7_3)
    assert gt.GT_SetPtLoop(1, 3) == 0
    loops = c_long()
    done = []
    assert gt.GT_PtStart(1, 0) == 0
    rows = []
    while True:
        gt.GTE_Wait(1)
        rows.append(pos())
        assert gt.GT_GetPtLoop(1, byref(loops)) == 0
        done.append(loops.value)
        if not moving():
            break
    out = np.array(rows)
    assert len(out) == 3 * 3072
    ref = integrate(velocity_pieces(EX_7_3, loops=3), np.arange(1, len(out) + 1, dtype=float))
    np.testing.assert_allclose(out, ref, atol=1e-8)
    assert done[3070] == 0 and done[3072] == 1 and done[6144] == 2 and done[-1] == 3
    assert out[-1] == 3 * 4096


def test_option_bits_pick_each_axis_fifo():
    """GT_PtStart(mask 0b11, option 0b10): axis 1 runs its FIFO1, axis 2 its FIFO2."""
    up(axes=(1, 2))
    for a in (1, 2):
        assert gt.GT_PrfPt(a, gt.PT_MODE_STATIC) == 0
    a_fifo1 = [(100, 100, E)]
    b_fifo1 = [(-999, 10, E)]
    b_fifo2 = [(300, 50, N), (600, 100, S)]
    push(1, a_fifo1, 0)
    push(1, [(5, 5, E)], 1)
    push(2, b_fifo1, 0)
    push(2, b_fifo2, 1)
    assert gt.GT_PtStart(0b11, 0b10) == 0, gt.GTE_GetLastError()
    out = samples(axes=(1, 2))
    assert len(out) == 100
    np.testing.assert_allclose(out[:, 0], np.arange(1, 101), atol=1e-9)
    ref = integrate(velocity_pieces(b_fifo2), np.arange(1, 101, dtype=float))
    np.testing.assert_allclose(out[:-1, 1], ref[:-1], atol=1e-9)
    assert out[-1, 1] == 600


def test_gtn_twin_takes_the_core_first():
    up()
    assert gt.GTN_PrfPt(1, 1, gt.PT_MODE_STATIC) == 0
    assert gt.GTN_PtData(1, 1, 10, 10, E, 0) == 0
    s = c_short()
    assert gt.GTN_PtSpace(1, 1, byref(s), 0) == 0 and s.value == 31
    assert gt.GTN_PtStart(1, 1, 0) == 0
    assert samples()[-1, 0] == 10
    assert gt.GTN_PtSpace(3, 1, byref(s), 0) == 7  # core 3 does not exist


def test_float_times_are_7_the_prototype_takes_a_long():
    """Hosts computing t·1000 in seconds (example 7-4) get 48.00000000000001: ``long time``
    (entry 93) refuses a float, as ctypes does for the DLL; rounding it works."""
    up()
    assert gt.GT_PrfPt(1) == 0
    rc_reason(gt.GT_PtData(1, 16, 0.016 * 3 * 1000, E), 7, "time", "integer")
    t = 0.0
    for _ in range(3):
        t += 0.016
        assert gt.GT_PtData(1, 16 * round(t / 0.016), round(t * 1000), E) == 0
    rc_reason(gt.GT_PtData(1, 100, 60.5, E), 7, "time")
    assert gt.GT_PtStart(1) == 0
    out = samples()[:, 0]
    assert len(out) == 48 and out[-1] == 48


# --- dynamic FIFO ---------------------------------------------------------------------------------
def test_dynamic_stream_hands_over_between_fifos_and_stops_when_both_run_dry():
    """7.4.2 (4): FIFO1 then FIFO2 fill; a used-up FIFO is cleared and refilled while moving."""
    up()
    assert gt.GT_PrfPt(1, gt.PT_MODE_DYNAMIC) == 0
    stream = [(k * 10 + (k % 3), k * 10, N) for k in range(1, 101)]  # 100 segments of 10 ms
    pushed = 0
    while space() > 0:
        push(1, [stream[pushed]], 1)  # the fifo argument means nothing in dynamic mode
        pushed += 1
    assert pushed == 64 and remainder() == 64
    assert gt.GT_PtStart(1, 0b1) == 0  # option ignored too
    rows, spaces = [], []
    while True:
        spaces.append(space())
        while pushed < len(stream) and space() > 0:
            push(1, [stream[pushed]])
            pushed += 1
        gt.GTE_Wait(1)
        rows.append(pos())
        if not moving():
            break
    out = np.array(rows)
    assert pushed == 100 and len(out) == 1000
    assert 32 in spaces  # a used-up FIFO came back empty
    ref = integrate(velocity_pieces(stream, dynamic=True), np.arange(1, 1001, dtype=float))
    np.testing.assert_allclose(out[:-1], ref[:-1], atol=1e-7)
    assert out[-1] == stream[-1][0]
    assert remainder() == 0 and space() == 32  # both used up and cleared


def test_dynamic_starved_stream_ends_and_the_next_data_starts_a_new_time_base():
    up()
    assert gt.GT_PrfPt(1, gt.PT_MODE_DYNAMIC) == 0
    push(1, [(50, 10, E)])
    assert gt.GT_PtStart(1) == 0
    out = samples()[:, 0]
    assert len(out) == 10 and out[-1] == 50
    push(1, [(20, 4, E)])  # time 4 < 10: a new motion has its own zero
    assert gt.GT_PtStart(1) == 0
    assert samples()[-1, 0] == 70


def test_pt_memory_1024():
    up()
    assert gt.GT_PrfPt(1) == 0
    m = c_short(9)
    assert gt.GT_GetPtMemory(1, byref(m)) == 0 and m.value == 0
    assert gt.GT_SetPtMemory(1, 1) == 0
    assert gt.GT_GetPtMemory(1, byref(m)) == 0 and m.value == 1
    assert space(1, 0) == 1024 and space(1, 1) == 1024
    push(1, [(k, k, E) for k in range(1, 1025)])
    rc_reason(gt.GT_PtData(1, 2000, 2000, E, 0), 1, "full")
    rc_reason(gt.GT_SetPtMemory(1, 0), 1, "clear it first")


# --- stop -----------------------------------------------------------------------------------------
def test_gt_stop_brakes_a_pt_motion_with_the_smooth_deceleration():
    up()
    assert gt.GT_PrfPt(1) == 0
    push(1, [(10000, 2000, E)])  # 5 pulse/ms
    assert gt.GT_PtStart(1) == 0
    gt.GTE_Wait(100)
    p0 = pos()
    assert gt.GT_SetStopDec(1, 0.5, 1000) == 0, gt.GTE_GetLastError()
    assert gt.GT_Stop(1, 0) == 0
    out = samples()[:, 0]
    assert len(out) == 10 and out[-1] == pytest.approx(p0 + 25.0)  # v²/(2·dec)
    assert remainder() == 1  # static data stays for a new start


# --- return codes ------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "call",
    [
        lambda: gt.GT_PtData(1, 10, 10, N, 0),
        lambda: gt.GT_PtSpace(1, byref(c_short()), 0),
        lambda: gt.GT_PtClear(1, 0),
        lambda: gt.GT_PtStart(1, 0),
        lambda: gt.GT_SetPtLoop(1, 2),
        lambda: gt.GT_GetPtLoop(1, byref(c_int32())),
        lambda: gt.GT_SetPtMemory(1, 1),
        lambda: gt.GT_GetPtMemory(1, byref(c_short())),
        lambda: gt.GT_GetPtRemainder(1, byref(c_int32())),
    ],
)
def test_every_pt_call_returns_1_outside_pt_mode(call):
    up()
    assert gt.GT_PrfTrap(1) == 0
    rc_reason(call(), 1, "Trap mode", "GT_PrfPt")


def test_return_1_while_moving_and_for_fifo_states():
    up(axes=(1, 2))
    assert gt.GT_PrfPt(1) == 0
    rc_reason(gt.GT_PtStart(1, 0), 1, "FIFO1", "no data")  # entry 95
    rc_reason(gt.GT_PtStart(1, 1), 1, "FIFO2", "no data")
    push(1, [(1000, 100, E)])
    push(1, [(10, 10, E)], 1)
    assert gt.GT_PtStart(1, 0) == 0
    gt.GTE_Wait(1)
    rc_reason(gt.GT_PrfPt(1, gt.PT_MODE_DYNAMIC), 1, "moving")  # entry 89
    rc_reason(gt.GT_PrfTrap(1), 1, "moving")
    rc_reason(gt.GT_SetPtMemory(1, 1), 1, "moving")  # entry 120 (1)
    rc_reason(gt.GT_PtStart(1, 0), 1, "moving")
    rc_reason(gt.GT_PtClear(1, 0), 1, "in use")  # entry 92 (1)
    assert gt.GT_PtClear(1, 1) == 0  # the other FIFO may be cleared
    assert gt.GT_SetPtLoop(1, 2) == 0  # loop for the next start
    samples()
    assert gt.GT_PrfPt(1, gt.PT_MODE_DYNAMIC) == 0
    rc_reason(gt.GT_SetPtLoop(1, 2), 1, "dynamic")  # entry 119
    push(1, [(1000, 100, E)])
    assert gt.GT_PtStart(1, 0) == 0
    rc_reason(gt.GT_PtClear(1, 0), 1, "while moving")  # entry 92 (2)


def test_start_is_all_or_nothing_and_needs_a_servo():
    up(axes=(1,))
    for a in (1, 2):
        assert gt.GT_PrfPt(a) == 0
        push(a, [(10, 10, E)])
    rc_reason(gt.GT_PtStart(0b11, 0), 1, "axis 2", "GT_AxisOn")
    assert not moving(1)  # axis 1 did not start either
    assert gt.GT_AxisOn(2) == 0
    assert gt.GT_PtClear(2, 0) == 0
    rc_reason(gt.GT_PtStart(0b11, 0), 1, "axis 2", "no data")
    assert not moving(1)
    rc_reason(gt.GT_PtStart(0, 0), 1, "selects no axis")


@pytest.mark.parametrize(
    ("call", "word"),
    [
        (lambda: gt.GT_PrfPt(1, 2), "mode"),
        (lambda: gt.GT_PtData(1, 10, 10, 3, 0), "type"),
        (lambda: gt.GT_PtData(1, 10, 10, N, 2), "fifo"),
        (lambda: gt.GT_PtData(1, 10, 0, N, 0), "time"),
        (lambda: gt.GT_PtData(1, 10, 10.5, N, 0), "time"),
        (lambda: gt.GT_PtData(1, float("nan"), 10, N, 0), "pos"),
        (lambda: gt.GT_PtSpace(1, byref(c_short()), -1), "fifo"),
        (lambda: gt.GT_PtClear(1, 2), "fifo"),
        (lambda: gt.GT_SetPtLoop(1, -1), "loop"),
        (lambda: gt.GT_SetPtMemory(1, 2), "memory"),
        (lambda: gt.GT_PtStart(1 << 5, 0), "axis 6"),
        (lambda: gt.GT_PtData(9, 10, 10, N, 0), "axis 9"),
        (lambda: gt.GT_PtData(1, 10), "arguments"),
    ],
)
def test_bad_arguments_return_7(call, word):
    up()
    assert gt.GT_PrfPt(1) == 0
    rc_reason(call(), 7, word)


def test_times_must_increase_within_a_fifo():
    up()
    assert gt.GT_PrfPt(1) == 0
    push(1, [(10, 10, N)])
    rc_reason(gt.GT_PtData(1, 20, 10, N, 0), 7, "time must be > 10")
    push(1, [(5, 5, N)], 1)  # FIFO2 has its own time base


def test_pt_data_survives_a_trip_through_another_mode_until_gt_reset():
    up()
    assert gt.GT_PrfPt(1) == 0
    push(1, [(10, 10, E)])
    assert gt.GT_PrfTrap(1) == 0
    assert gt.GT_PrfPt(1) == 0 and space() == 31
    assert gt.GT_PrfPt(1, gt.PT_MODE_DYNAMIC) == 0 and space() == 32  # new FIFO mode: emptied
    assert gt.GT_Reset() == 0
    assert gt.GT_PrfPt(1) == 0 and space() == 32
