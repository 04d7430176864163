"""PT planner against independently integrated profiles (manual 7.4, examples 7-3 and 7-4,
chapter 13 entries 66-68, 89, 92-95, 119-120)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.controller.motion.pt import PtMode, PtPlanner, PtSegmentType
from gtecat.errors import CommandError, ParameterError

N, E, S = PtSegmentType.NORMAL, PtSegmentType.EVEN, PtSegmentType.STOP


# ------------------------------------------------------------- reference
def velocity_pieces(points, loops=1, dynamic=False):
    """Segments ``(t0, t1, vs, ve)`` from the 7.4.2 rules, written from the manual's text.

    NORMAL: first segment starts at 0, then at the previous end, ends at 2ΔP/ΔT - vs;
    EVEN: ΔP/ΔT throughout; STOP: starts at 2ΔP/ΔT, ends at 0.  Static loops
    repeat the points offset by the previous pass's end, first segment from 0.
    """
    out = []
    t_off = p_off = 0.0
    for _ in range(loops):
        t_prev, p_prev, v_prev = t_off, p_off, 0.0
        for k, (p, t, kind) in enumerate(points):
            t_end, p_end = t + t_off, p + p_off
            dt, dp = t_end - t_prev, p_end - p_prev
            if kind == E:
                vs = ve = dp / dt
            elif kind == S:
                vs, ve = 2 * dp / dt, 0.0
            else:
                vs = 0.0 if (k == 0 and not (dynamic and out)) else v_prev
                ve = 2 * dp / dt - vs
            out.append((t_prev, t_end, vs, ve))
            t_prev, p_prev, v_prev = t_end, p_end, ve
        t_off, p_off = t_prev, p_prev
    return out


def integrate(pieces, times):
    """Position at each time: sum of the areas under the linear velocity pieces (trapezoids)."""
    res = np.empty(len(times))
    for n, t in enumerate(times):
        pos = 0.0
        for t0, t1, vs, ve in pieces:
            if t <= t0:
                break
            hi = min(t, t1)
            v_hi = vs + (ve - vs) * (hi - t0) / (t1 - t0)
            pos += (vs + v_hi) / 2 * (hi - t0)
        res[n] = pos
    return res


def velocity_at(pieces, t):
    for t0, t1, vs, ve in pieces:
        if t0 <= t < t1:
            return vs + (ve - vs) * (t - t0) / (t1 - t0)
    return 0.0


def run(pt: PtPlanner, limit=1_000_000):
    out = []
    while not pt.done:
        out.append(pt.step())
        assert len(out) < limit
    return np.array(out).reshape(-1, 3)


def loaded(points, mode=PtMode.STATIC, fifo=0, cycle=1.0):
    pt = PtPlanner(mode, cycle)
    for p, t, kind in points:
        pt.data(p, t, kind, fifo)
    return pt


# ------------------------------------------------------------ example 7-3
EX_7_3 = [(1024, 1024, N), (3072, 2048, N), (4096, 3072, N)]


def test_example_7_3_trapezoid_matches_integrated_profile_sample_by_sample():
    """Example 7-3 / figure 7-8: three NORMAL segments make a trapezoid 0 → 2 → 2 → 0 pulse/ms."""
    pt = loaded(EX_7_3)
    pt.start(0, pos=100.0)
    out = run(pt)
    assert len(out) == 3072
    t = np.arange(1, 3073, dtype=float)
    ref = integrate(velocity_pieces(EX_7_3), t)
    np.testing.assert_allclose(out[:, 0], 100.0 + ref, rtol=0, atol=1e-9)
    assert out[-1].tolist() == [4196.0, 0.0, 0.0]
    # the figure's shape: ramp up to 2 at 1024 ms, flat to 2048 ms, ramp down to 0
    assert out[511, 1] == pytest.approx(1.0)
    assert np.all(np.abs(out[1023:2047, 1] - 2.0) < 1e-12)
    assert out[2559, 1] == pytest.approx(1.0)
    assert out[:, 1].max() == pytest.approx(2.0)
    # each pushed point is hit exactly at its time (positions are cumulative, 7.4.2 note)
    for p, tt, _ in EX_7_3:
        assert out[tt - 1, 0] == pytest.approx(100.0 + p, abs=1e-9)


def test_segment_velocities_follow_the_7_4_2_recurrence():
    """Figure 7-5: v1 = 2P1/T1, v2 = 2P2/T2 - v1, ... (P, T per segment)."""
    pts = [(300, 100, N), (900, 250, N), (1000, 400, N), (1200, 500, N)]
    pt = loaded(pts)
    pt.start()
    out = run(pt)
    v = 0.0
    prev_p = prev_t = 0
    for p, t, _ in pts[:-1]:
        v = 2 * (p - prev_p) / (t - prev_t) - v
        assert out[t - 1, 1] == pytest.approx(v, abs=1e-9)  # speed at the boundary
        prev_p, prev_t = p, t


def test_even_segment_keeps_displacement_over_time_and_hands_it_on():
    """Figure 7-6: EVEN speed = ΔP/ΔT throughout; a following NORMAL starts from it."""
    pts = [(500, 500, E), (1500, 1000, N), (1600, 1100, N)]
    pt = loaded(pts)
    pt.start()
    out = run(pt)
    assert np.all(np.abs(out[:499, 1] - 1.0) < 1e-12)
    assert out[499, 1] == pytest.approx(1.0)  # start of the NORMAL segment
    # NORMAL: vs = 1, ΔP = 1000, ΔT = 500 -> ve = 3
    assert out[998, 1] == pytest.approx(3.0 - 2.0 / 500, abs=1e-9)
    ref = integrate(velocity_pieces(pts), np.arange(1, len(out) + 1, dtype=float))
    np.testing.assert_allclose(out[:, 0], ref, atol=1e-9)


def test_stop_segment_starts_from_its_own_speed_and_ends_at_zero():
    """Figure 7-7: STOP starts at 2ΔP/ΔT whatever came before, ends at 0."""
    pts = [(1000, 1000, E), (1500, 1250, S)]
    pt = loaded(pts)
    pt.start()
    out = run(pt)
    assert len(out) == 1250
    assert out[999, 1] == pytest.approx(4.0)  # jump from 1 to 2*500/250
    assert out[-2, 1] == pytest.approx(4.0 / 250)
    assert out[-1].tolist() == [1500.0, 0.0, 0.0]
    ref = integrate(velocity_pieces(pts), np.arange(1, 1251, dtype=float))
    np.testing.assert_allclose(out[:, 0], ref, atol=1e-9)


@settings(max_examples=40, deadline=None)
@given(
    st.lists(
        st.tuples(st.integers(-2000, 2000), st.integers(1, 60), st.sampled_from([N, N, N, E, S])),
        min_size=1,
        max_size=8,
    ),
    st.sampled_from([1.0, 0.5, 2.0, 0.25]),
)
def test_random_sequences_match_the_integrated_reference(segs, cycle):
    """Any mix of segment types, any of the usual cycle times: positions equal the integral."""
    pts = []
    p = t = 0
    for dp, dt, kind in segs:
        p += dp
        t += dt
        pts.append((p, t, kind))
    pt = loaded(pts, cycle=cycle)
    pt.start()
    out = run(pt)
    assert len(out) == math.ceil(t / cycle - 1e-9)
    times = np.arange(1, len(out) + 1) * cycle
    ref = integrate(velocity_pieces(pts), times)
    ref[-1] = p  # the end sample is the last point exactly
    assert np.all(np.abs(out[:, 0] - ref) <= 1e-7 * (1 + np.abs(ref)))
    assert out[-1, 0] == p and out[-1, 1] == 0.0


# ---------------------------------------------------------------- loops
def test_static_loops_repeat_the_fifo_from_where_each_pass_ended():
    """GT_SetPtLoop(3): three passes of example 7-3, each from speed 0 (first FIFO segment)."""
    pt = loaded(EX_7_3)
    pt.set_loop(3)
    assert pt.loop == 3 and pt.loops_done == 0
    pt.start()
    seen = []
    out = []
    while not pt.done:
        out.append(pt.step())
        seen.append(pt.loops_done)
    out = np.array(out)
    assert len(out) == 3 * 3072
    ref = integrate(velocity_pieces(EX_7_3, loops=3), np.arange(1, len(out) + 1, dtype=float))
    np.testing.assert_allclose(out[:, 0], ref, atol=1e-8)
    assert out[3071, 0] == pytest.approx(4096) and out[6143, 0] == pytest.approx(8192)
    assert out[-1, 0] == 3 * 4096
    assert seen[3070] == 0 and seen[3072] == 1 and seen[6144] == 2 and pt.loops_done == 3
    assert len(pt.points(0)) == 3  # static data stays for reuse


def test_loop_zero_is_endless():
    pt = loaded([(100, 10, N), (200, 20, N)])
    pt.set_loop(0)
    pt.start()
    for _ in range(20 * 50):
        pt.step()
    assert pt.moving and pt.loops_done == 50
    assert pt.pos == pytest.approx(50 * 200)


# --------------------------------------------------------------- static FIFOs
def test_static_start_runs_the_fifo_the_option_bit_selects():
    pt = PtPlanner()
    pt.data(100, 100, N, 0)
    pt.data(-500, 50, E, 1)
    pt.start(1)
    assert pt.running_fifo == 1
    out = run(pt)
    assert len(out) == 50 and out[-1, 0] == -500 and np.allclose(out[:-1, 1], -10.0)
    pt.start(0)
    out = run(pt)
    assert len(out) == 100 and out[-1, 0] == -500 + 100


def test_static_clear_refuses_the_fifo_in_use_but_clears_the_other():
    """GT_PtClear return 1 (1): the FIFO in use while moving; the other one may be cleared."""
    pt = loaded([(100, 100, N)])
    pt.data(5, 10, N, 1)
    pt.start(0)
    pt.step()
    with pytest.raises(CommandError, match="in use"):
        pt.clear(0)
    pt.clear(1)
    assert pt.space(1) == 32
    run(pt)
    pt.clear(0)
    assert pt.space(0) == 32


def test_static_remainder_counts_segments_not_finished():
    pt = loaded([(10, 10, N), (30, 20, N), (40, 30, N)])
    assert pt.remainder == 3
    pt.start()
    assert pt.remainder == 3
    for _ in range(10):
        pt.step()
    assert pt.remainder == 2  # at t = 10 the second segment runs
    run(pt)
    assert pt.remainder == 3  # at rest: what a new start of FIFO1 would run


# -------------------------------------------------------------- dynamic FIFOs
def sine_stream(amp=50.0, period_s=1.0, delta_s=0.016, loops=2):
    """Example 7-4's host loop, as a generator of GT_PtData arguments (time rounded to ms)."""
    t = 0.0
    pos = vel_pre = 0.0
    loop = 1
    while loop <= loops:
        t += delta_s
        vel = amp * math.sin(2 * math.pi / period_s * t)
        pos += 1000 * (vel + vel_pre) * delta_s / 2
        vel_pre = vel
        if t < loop * period_s:
            yield pos, round(t * 1000), N
        else:
            yield 0.0, round(loop * period_s * 1000), S
            pos, t, vel_pre = 0.0, loop * period_s, 0.0
            loop += 1


def test_example_7_4_dynamic_sine_with_fifo_handover():
    """Example 7-4 / figure 7-9: fill both FIFOs, start, refill as FIFOs empty; 2 sine periods."""
    pt = PtPlanner(PtMode.DYNAMIC)
    stream = list(sine_stream())
    assert len(stream) > 64  # more than both FIFOs hold: the hand-over is needed
    pushed = 0
    spaces = []
    out = []
    while pushed < len(stream) and pt.space() > 0:
        pt.data(*stream[pushed])
        pushed += 1
    assert pushed == 64 and pt.space() == 0 and pt.remainder == 64
    pt.start()
    while not pt.done:
        spaces.append(pt.space())
        while pushed < len(stream) and pt.space() > 0:  # the host polls GT_PtSpace every cycle
            pt.data(*stream[pushed])
            pushed += 1
        out.append(pt.step())
    out = np.array(out)
    assert pushed == len(stream)
    assert spaces.count(32) > 0  # a used-up FIFO was cleared and offered again
    assert len(out) == 2000 and out[-1].tolist() == [0.0, 0.0, 0.0]
    pieces = velocity_pieces(stream, dynamic=True)
    ref = integrate(pieces, np.arange(1, 2001, dtype=float))
    ref[-1] = 0.0
    np.testing.assert_allclose(out[:, 0], ref, atol=1e-8)
    # the shape of figure 7-9: speed follows 50 sin(2πt/1s) within the 16 ms linearisation
    t = np.arange(1, 2001)
    sine = 50 * np.sin(2 * np.pi * t / 1000)
    assert np.max(np.abs(out[:-10, 1] - sine[:-10])) < 0.1
    assert out[999, 0] == pytest.approx(0.0, abs=1e-9)  # back at the start after one period
    assert pt.space() == 32 and pt.remainder == 0  # both FIFOs used up and cleared


def test_dynamic_mode_stops_when_both_fifos_run_dry():
    pt = PtPlanner(PtMode.DYNAMIC)
    for k in range(1, 41):
        pt.data(10 * k, 10 * k, E)
    assert pt.space() == 24  # FIFO1 full, FIFO2 holds 8
    pt.start()
    for _ in range(320):
        pt.step()
    assert pt.remainder == 8  # FIFO1 used up: it was cleared, FIFO2 runs
    for k in range(41, 65):
        pt.data(10 * k, 10 * k, E)
    assert pt.space() == 32  # FIFO2 full: the next segment goes into the emptied FIFO1
    pt.data(650, 650, E)
    assert pt.space() == 31 and pt.remainder == 8 + 24 + 1
    out = run(pt)
    assert len(out) == 650 - 320 and out[-1].tolist() == [650.0, 0.0, 0.0]
    assert pt.space() == 32 and pt.remainder == 0


def test_dynamic_stream_keeps_speed_across_the_fifo_boundary():
    """A NORMAL segment that opens FIFO2 starts from the speed FIFO1 ended with (stream)."""
    pt = PtPlanner(PtMode.DYNAMIC)
    pts = [(k * k, k * 10, N) for k in range(1, 34)]  # 33 points: the last opens FIFO2
    for p in pts:
        pt.data(*p)
    pt.start()
    out = run(pt)
    ref = integrate(velocity_pieces(pts, dynamic=True), np.arange(1, 331, dtype=float))
    ref[-1] = pts[-1][0]
    np.testing.assert_allclose(out[:, 0], ref, atol=1e-8)


def test_dynamic_data_can_be_appended_to_the_running_fifo():
    pt = PtPlanner(PtMode.DYNAMIC)
    pt.data(10, 10, E)
    pt.start()
    for _ in range(5):
        pt.step()
    pt.data(30, 20, E)
    out = run(pt)
    assert len(out) == 15 and out[-1, 0] == 30.0 and out[-2, 1] == pytest.approx(2.0)


def test_dynamic_time_base_runs_on_and_resets_after_the_motion():
    pt = PtPlanner(PtMode.DYNAMIC)
    pt.data(10, 10, N)
    with pytest.raises(ParameterError, match="time must be > 10"):
        pt.data(20, 10, N, 1)  # fifo ignored; times of the one stream must increase
    pt.start()
    run(pt)
    pt.data(5, 5, N)  # a new motion: its own time zero
    pt.start()
    assert run(pt)[-1, 0] == 15.0


# ------------------------------------------------------------ memory
def test_memory_flag_sizes_the_fifos_32_or_1024():
    pt = PtPlanner()
    assert pt.memory == 0 and pt.space(0) == 32 and pt.space(1) == 32
    for k in range(1, 33):
        pt.data(k, k, N)
    with pytest.raises(CommandError, match="full"):
        pt.data(33, 33, N)
    pt.set_memory(1)
    assert pt.memory == 1 and pt.space(0) == 1024 - 32 and pt.space(1) == 1024
    pt.data(33, 33, N)
    with pytest.raises(CommandError, match="clear it first"):
        pt.set_memory(0)
    pt.clear(0)
    pt.set_memory(0)
    assert pt.space(0) == 32


def test_dynamic_memory_1024_holds_2048_segments():
    pt = PtPlanner(PtMode.DYNAMIC)
    pt.set_memory(1)
    assert pt.space() == 1024
    for k in range(1, 2049):
        pt.data(k, k, N)
        assert pt.space() == (1024 if k == 1024 else (-k) % 1024)
    assert pt.space() == 0
    with pytest.raises(CommandError, match="both PT FIFOs are full"):
        pt.data(2049, 2049, N)


# ------------------------------------------------------------ stop, hold
def test_smooth_stop_brakes_with_the_given_deceleration():
    pt = loaded([(10000, 2000, E)])  # 5 pulse/ms
    pt.start()
    for _ in range(100):
        pt.step()
    pt.stop(0.5)
    out = run(pt)
    assert len(out) == 10
    assert out[-1, 0] == pytest.approx(500 + 25.0)  # v²/(2·dec)
    assert pt.remainder == 1 and len(pt.points(0)) == 1  # static data stays


def test_stopping_a_dynamic_stream_drops_its_data():
    pt = PtPlanner(PtMode.DYNAMIC)
    for k in range(1, 10):
        pt.data(k, k, N)
    pt.start()
    pt.step()
    pt.stop(1000.0, abrupt=True)
    run(pt)
    assert pt.space() == 32 and pt.remainder == 0


def test_hold_moves_the_rest_position_and_start_takes_it_as_origin():
    pt = loaded([(10, 10, E)])
    pt.hold(-3.0)
    pt.start()
    assert run(pt)[-1, 0] == 7.0


# ---------------------------------------------------- return 1 / return 7
def test_return_1_conditions_of_chapter_13():
    pt = PtPlanner()
    with pytest.raises(CommandError, match="no data"):
        pt.start(0)  # entry 95: FIFO has no data
    pt.data(100, 100, N)
    pt.start(0)
    with pytest.raises(CommandError, match="moving"):
        pt.start(0)
    with pytest.raises(CommandError, match="moving"):
        pt.set_memory(1)  # entry 120 (1)
    with pytest.raises(CommandError, match="moving"):
        pt.set_mode(PtMode.DYNAMIC)  # entry 89
    dyn = PtPlanner(PtMode.DYNAMIC)
    with pytest.raises(CommandError, match="dynamic"):
        dyn.set_loop(2)  # entry 119: not in dynamic mode
    with pytest.raises(CommandError, match="no data"):
        dyn.start()
    dyn.data(1, 1, N)
    dyn.start()
    with pytest.raises(CommandError, match="while moving"):
        dyn.clear()  # entry 92 (2)


@pytest.mark.parametrize(
    "call",
    [
        lambda pt: pt.data(1, 1, 3),  # bad segment type
        lambda pt: pt.data(1, 1, N, 2),  # bad fifo
        lambda pt: pt.data(1, 0, N),  # time must be > 0
        lambda pt: pt.data(float("nan"), 1, N),
        lambda pt: pt.space(-1),
        lambda pt: pt.clear(5),
        lambda pt: pt.set_loop(-1),
        lambda pt: pt.set_memory(2),
        lambda pt: pt.set_mode(2),
        lambda pt: pt.start(3),
    ],
)
def test_parameter_errors_return_7(call):
    pt = PtPlanner()
    pt.data(5, 5, N)
    with pytest.raises(ParameterError):
        call(pt)


def test_times_must_increase_within_a_static_fifo():
    pt = PtPlanner()
    pt.data(5, 5, N, 0)
    pt.data(5, 3, N, 1)  # the other FIFO has its own time base
    with pytest.raises(ParameterError, match="time must be > 5"):
        pt.data(10, 5, N, 0)


def test_set_mode_to_another_fifo_mode_empties_the_fifos():
    pt = PtPlanner()
    pt.data(5, 5, N)
    pt.set_mode(PtMode.STATIC)
    assert pt.space(0) == 31
    pt.set_mode(PtMode.DYNAMIC)
    assert pt.mode == PtMode.DYNAMIC and pt.space() == 32
