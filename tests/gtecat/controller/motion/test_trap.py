"""Trap planner against closed-form trapezoids (manual 7.2, GT_SetTrapPrm, GT_Update)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from gtecat.controller.motion import StopKind, TrapParams, TrapPlanner
from gtecat.errors import CommandError, ParameterError
from tests.conftest import examples

from .reference import Trapezoid


def run(tp: TrapPlanner, limit: int = 2_000_000) -> np.ndarray:
    """Step until done; rows are (pos, vel, acc) of each sample."""
    out = []
    while not tp.done:
        out.append(tp.step())
        assert len(out) < limit, "planner never finished"
    return np.array(out).reshape(-1, 3)


def move(dist, vel, acc, dec, vs=0.0, ts=0, cycle=1.0, start=0.0):
    tp = TrapPlanner(cycle, pos=start)
    tp.start(start, int(start + dist), vel, TrapParams(acc, dec, vs, ts))
    return tp, run(tp)


# ------------------------------------------------------------- closed form
def test_example_7_1_without_smoothing_matches_closed_form_sample_by_sample():
    """Example 7-1 (vel 50, acc 0.25, dec 0.125, 50000 pulses) with smoothTime 0: 1300 ms."""
    tp, out = move(50000, 50.0, 0.25, 0.125)
    ref = Trapezoid.plan(50000, 50.0, 0.25, 0.125)
    assert ref.duration == pytest.approx(1300.0)
    assert len(out) == 1300 and tp.t_end == pytest.approx(1300.0)
    t = np.arange(1, len(out) + 1, dtype=float)
    p, v, a = ref.at(t)
    np.testing.assert_allclose(out[:, 0], p, atol=1e-9)
    np.testing.assert_allclose(out[:, 1], v, atol=1e-12)
    np.testing.assert_allclose(out[:, 2], a, atol=1e-12)
    assert out[-1, 0] == 50000.0 and out[-1, 1] == 0.0
    assert out[199, 1] == 50.0 and out[0, 2] == 0.25 and out[-2, 2] == -0.125


@pytest.mark.parametrize("cycle", [0.25, 0.5, 1.0, 2.0])
@pytest.mark.parametrize("dist", [12345, -12345])
def test_trapezoid_any_cycle_and_direction(cycle, dist):
    _, out = move(dist, 20.0, 0.4, 0.1, cycle=cycle, start=1000.0)
    ref = Trapezoid.plan(dist, 20.0, 0.4, 0.1)
    assert len(out) == math.ceil(ref.duration / cycle - 1e-9)
    t = cycle * np.arange(1, len(out) + 1)
    p, v, _ = ref.at(t)
    np.testing.assert_allclose(out[:, 0], 1000.0 + p, atol=1e-8)
    np.testing.assert_allclose(out[:, 1], v, atol=1e-12)
    assert out[-1, 0] == 1000.0 + dist


def test_triangle_short_move_never_reaches_speed():
    """A move too short for the speed (7.2: short moves) peaks at sqrt(2·D·acc·dec/(acc+dec))."""
    _, out = move(1000, 100.0, 0.5, 0.25)
    vp = math.sqrt(2 * 1000 * 0.5 * 0.25 / 0.75)
    assert np.max(out[:, 1]) <= vp + 1e-12
    assert np.max(out[:, 1]) > vp - 0.5  # reached within one cycle's acceleration
    duration = vp / 0.5 + vp / 0.25
    assert len(out) == math.ceil(duration)
    ref = Trapezoid.plan(1000, 100.0, 0.5, 0.25)
    p, _, _ = ref.at(np.arange(1, len(out) + 1, dtype=float))
    np.testing.assert_allclose(out[:, 0], p, atol=1e-9)
    assert out[-1, 0] == 1000.0


def test_vel_start_jumps_to_start_speed_and_arrives_at_it():
    """velStart (GT_SetTrapPrm): the speed starts at velStart and ends there, then drops to 0."""
    _, out = move(10000, 40.0, 0.5, 0.5, vs=5.0)
    ref = Trapezoid.plan(10000, 40.0, 0.5, 0.5, vs=5.0)
    assert out[0, 1] == pytest.approx(5.0 + 0.5)  # one cycle after the jump
    assert out[0, 0] == pytest.approx(5.0 + 0.25)
    assert out[-2, 1] == pytest.approx(5.0, abs=0.5 + 1e-9)
    assert len(out) == math.ceil(ref.duration)
    p, v, _ = ref.at(np.arange(1, len(out) + 1, dtype=float))
    np.testing.assert_allclose(out[:, 0], p, atol=1e-9)
    np.testing.assert_allclose(out[:-1, 1], v[:-1], atol=1e-12)


def test_vel_start_above_speed_is_capped_at_speed():
    _, out = move(500, 10.0, 1.0, 1.0, vs=25.0)
    assert np.max(out[:, 1]) == 10.0
    assert len(out) == 50 and out[-1, 0] == 500.0


def test_zero_length_move_is_done_at_once():
    tp = TrapPlanner(1.0, pos=7.0)
    tp.start(7.0, 7, 10.0, TrapParams(1.0))
    assert tp.done and tp.step() == (7.0, 0.0, 0.0)


def test_fractional_start_ends_on_integer_target():
    tp = TrapPlanner(1.0)
    tp.start(0.3, 100, 10.0, TrapParams(1.0))
    out = run(tp)
    assert out[-1, 0] == 100.0 and np.all(np.diff(out[:, 0]) >= 0)


@pytest.mark.long
def test_far_from_zero_speed_stays_within_limit():
    """Near the GT_SetPos range end (±1073741823) the smoothed speed has no cancellation."""
    start = -1073741823 + 26650.25
    tp = TrapPlanner(0.25, pos=start)
    tp.start(start, -1073741823, 0.3747, TrapParams(0.42, 14.8, 0.083, 8), v0=0.32)
    out = run(tp)
    assert np.max(np.abs(out[:, 1])) <= 0.3747 * (1 + 1e-12)
    assert out[-1, 0] == -1073741823


# --------------------------------------------------------------- smoothing
@pytest.mark.long
def test_smoothing_is_the_moving_average_of_the_trapezoid():
    """Example 7-1 with smoothTime 25 (7.2.2: the time over which the acceleration changes):
    the moving average of the trapezoid over 25 ms, integrated numerically; 1325 ms."""
    ts = 25
    _, out = move(50000, 50.0, 0.25, 0.125, ts=ts)
    ref = Trapezoid.plan(50000, 50.0, 0.25, 0.125)
    assert len(out) == 1325 == math.ceil(ref.duration + ts)
    t = np.arange(1, len(out) + 1, dtype=float)
    p, v = ref.smoothed(t, ts)
    np.testing.assert_allclose(out[:, 0], p, atol=1e-6)
    np.testing.assert_allclose(out[:, 1], v, atol=1e-9)
    assert out[-1, 0] == 50000.0


@pytest.mark.parametrize("cycle", [0.25, 0.5, 2.0])
@pytest.mark.parametrize("vs", [0.0, 3.0])
def test_smoothing_any_cycle_matches_exact_moving_average(cycle, vs):
    ts = 17
    _, out = move(-8000, 30.0, 0.4, 0.2, vs=vs, ts=ts, cycle=cycle)
    ref = Trapezoid.plan(-8000, 30.0, 0.4, 0.2, vs)
    assert len(out) == math.ceil((ref.duration + ts) / cycle - 1e-9)
    t = cycle * np.arange(1, len(out) + 1)
    np.testing.assert_allclose(out[:, 0], ref.smoothed_exact(t, ts), atol=1e-7)
    assert out[-1, 0] == -8000.0


def test_smoothing_limits_jerk_and_keeps_acceleration_bounds():
    """Example 7-1 figure 7-2: acceleration ramps over 25 ms; jerk <= acc/Ts, |a| <= acc."""
    ts = 25
    _, out = move(50000, 50.0, 0.25, 0.125, ts=ts)
    acc = out[:, 2]
    jerk = np.diff(np.concatenate([[0.0], acc]))
    assert np.max(np.abs(jerk)) <= 0.25 / ts + 1e-12
    assert np.max(acc) == pytest.approx(0.25) and np.min(acc) == pytest.approx(-0.125)
    # the acceleration takes Ts to reach its plateau
    assert acc[ts - 2] < 0.25 and acc[ts - 1] == pytest.approx(0.25)
    assert np.max(out[:, 1]) <= 50.0 + 1e-12
    assert np.all(np.diff(out[:, 0]) >= 0) and np.max(out[:, 0]) == 50000.0


def test_smoothing_triangle_jerk_bound_is_acc_plus_dec_over_ts():
    ts = 50
    _, out = move(300, 100.0, 0.5, 0.25, ts=ts)
    jerk = np.diff(np.concatenate([[0.0], out[:, 2], [0.0]]))
    assert np.max(np.abs(jerk)) <= (0.5 + 0.25) / ts + 1e-12
    assert np.max(np.abs(out[:, 2])) <= 0.5 + 1e-12
    assert out[-1, 0] == 300.0 and np.max(out[:, 0]) <= 300.0


# ---------------------------------------------------------- GT_Update on the fly
def test_update_with_same_target_and_speed_changes_nothing():
    _, ref = move(20000, 30.0, 0.2, 0.1, ts=20)
    tp = TrapPlanner(1.0)
    tp.start(0.0, 20000, 30.0, TrapParams(0.2, 0.1, 0.0, 20))
    out = []
    while not tp.done:
        if len(out) in (50, 400, 700, 800):  # accelerating, cruising, braking
            tp.update(20000, 30.0)
        out.append(tp.step())
    np.testing.assert_allclose(np.array(out), ref, atol=1e-7)


def test_update_speed_during_cruise_brakes_with_dec_then_cruises():
    """GT_SetVel + GT_Update during motion: new speed from the current cycle on."""
    tp = TrapPlanner(1.0)
    tp.start(0.0, 100000, 50.0, TrapParams(0.25, 0.125))
    out = [tp.step() for _ in range(500)]  # cruising at 50 since t = 200
    tp.update(vel=25.0)
    out += list(run(tp))
    out = np.array(out)
    v = out[:, 1]
    assert v[499] == 50.0
    np.testing.assert_allclose(v[500:700], 50.0 - 0.125 * np.arange(1, 201))  # dec 0.125
    assert np.all(v[700:-201] == 25.0)
    # analytic duration: 200 + accel; cruise 50 to t=500; decel to 25 in 200 ms; decel 200 ms
    p500 = 5000 + 50 * 300
    d_slow = (50**2 - 25**2) / (2 * 0.125)
    d_end = 25**2 / (2 * 0.125)
    t_end = 500 + 200 + (100000 - p500 - d_slow - d_end) / 25 + 200
    assert len(out) == math.ceil(t_end) and out[-1, 0] == 100000.0


def test_update_farther_target_extends_move():
    tp = TrapPlanner(1.0)
    tp.start(0.0, 10000, 20.0, TrapParams(0.1))
    out = [tp.step() for _ in range(600)]  # braking began at 10000/20 - ... ≈ t=500
    assert out[-1][1] < 20.0
    tp.update(target=20000)
    out += list(run(tp))
    out = np.array(out)
    assert out[-1, 0] == 20000.0 and np.max(out[:, 1]) <= 20.0
    assert np.max(np.abs(np.diff(out[:, 1]))) <= 0.1 + 1e-12
    assert np.all(np.diff(out[:, 0]) >= 0)


def test_update_target_behind_reverses_within_dec_and_acc():
    """New target behind the axis: brake with dec, come back with acc (no jump)."""
    tp = TrapPlanner(1.0)
    prm = TrapParams(0.2, 0.1)
    tp.start(0.0, 50000, 40.0, prm)
    out = [tp.step() for _ in range(600)]
    p_update, v_update = out[-1][0], out[-1][1]
    tp.update(target=0)
    out += list(run(tp))
    out = np.array(out)
    assert out[-1, 0] == 0.0
    # the turning point is exactly the braking distance ahead
    turn = np.max(out[:, 0])
    assert turn == pytest.approx(p_update + v_update**2 / (2 * 0.1), abs=1e-6)
    dv = np.diff(np.concatenate([[0.0], out[:, 1]]))
    assert np.max(np.abs(dv)) <= 0.2 + 1e-12
    assert np.max(np.abs(out[:, 1])) <= 40.0 + 1e-12
    # braking uses dec (0.1) until the stop, then acc (0.2) toward 0
    k = int(np.argmax(out[:, 0]))
    assert np.all(out[601:k, 2] == -0.1)
    assert out[k + 2, 2] == -0.2


def test_update_target_just_behind_a_braking_axis_overshoots_and_returns():
    tp = TrapPlanner(1.0)
    tp.start(0.0, 1000, 10.0, TrapParams(0.1))
    for _ in range(50):
        tp.step()
    p = tp.pos
    tp.update(target=int(p) + 1)  # cannot stop within 1 pulse at speed 5
    out = run(tp)
    assert out[-1, 0] == int(p) + 1
    assert np.max(out[:, 0]) > int(p) + 1  # went past and came back


def test_update_during_smoothing_keeps_output_continuous():
    tp = TrapPlanner(1.0)
    tp.start(0.0, 30000, 30.0, TrapParams(0.3, 0.3, 0.0, 40))
    out = [tp.step() for _ in range(300)]
    tp.update(target=-5000, vel=45.0)
    out += list(run(tp))
    out = np.array(out)
    assert out[-1, 0] == -5000.0
    dv = np.diff(np.concatenate([[0.0], out[:, 1]]))
    assert np.max(np.abs(dv)) <= 0.3 + 1e-9
    da = np.diff(np.concatenate([[0.0], out[:, 2]]))
    assert np.max(np.abs(da)) <= 0.6 / 40 + 1e-9  # (acc + dec) / Ts


def test_update_during_the_smoothing_tail():
    """Raw profile arrived, output still averaging: same target keeps the end time, a new
    target moves on from the raw rest point."""
    _, ref = move(1000, 10.0, 1.0, 1.0, ts=30)
    tp = TrapPlanner(1.0)
    tp.start(0.0, 1000, 10.0, TrapParams(1.0, 1.0, 0.0, 30))
    out = [tp.step() for _ in range(115)]  # raw arrives at 110 ms, output at 140 ms
    tp.update(target=1000)
    out += list(run(tp))
    np.testing.assert_allclose(np.array(out), ref, atol=1e-9)
    tp.start(0.0, 1000, 10.0, TrapParams(1.0, 1.0, 0.0, 30))
    out = [tp.step() for _ in range(115)]
    tp.update(target=0)
    out += list(run(tp))
    out = np.array(out)
    assert out[-1, 0] == 0.0 and np.max(out[:, 0]) < 1000.0  # turned before the output arrived
    assert len(out) == 115 + 110 + 30  # re-planned at 115 ms from the raw rest point


def test_update_when_idle_starts_from_rest_with_last_parameters():
    tp = TrapPlanner(1.0)
    tp.start(0.0, 100, 10.0, TrapParams(1.0))
    run(tp)
    tp.update(target=0)
    out = run(tp)
    assert out[-1, 0] == 0.0 and len(out) == 20  # 10 ms each way at 1 pulse/ms²


def test_update_before_any_start_is_a_command_error():
    with pytest.raises(CommandError):
        TrapPlanner().update(target=5)


# -------------------------------------------------------------------- stops
@pytest.mark.parametrize("abrupt,dec", [(False, 1.0), (True, 1000.0)])
def test_stop_from_cruise(abrupt, dec):
    """GT_Stop: smooth stop with decSmoothStop, abrupt with decAbruptStop (9.4, table 4-4)."""
    tp = TrapPlanner(1.0)
    tp.start(0.0, 100000, 50.0, TrapParams(0.25, 0.125, 0.0, 10))
    for _ in range(400):
        tp.step()
    p0, v0 = tp.pos, tp.vel
    tp.stop(dec, abrupt=abrupt)
    assert tp.stopping == (StopKind.ABRUPT if abrupt else StopKind.SMOOTH)
    out = run(tp)
    assert len(out) == math.ceil(v0 / dec)
    assert out[-1, 0] == pytest.approx(p0 + v0**2 / (2 * dec))
    assert tp.done and tp.vel == 0.0


def test_stop_when_idle_does_nothing():
    tp = TrapPlanner(1.0, pos=3.0)
    tp.stop(1.0)
    assert tp.done and tp.stopping == StopKind.NONE and tp.pos == 3.0


def test_start_from_a_moving_state_continues_without_jump():
    """A Trap started while the axis still moves (e.g. after a stop ramp was interrupted)."""
    tp = TrapPlanner(1.0)
    tp.start(100.0, 5000, 20.0, TrapParams(0.5, 0.5, 0.0, 20), v0=10.0)
    first = tp.step()
    assert abs(first[0] - (100.0 + 10.0)) <= 0.5 * 0.5  # v0·T, plus at most acc·T²/2
    assert abs(first[1] - 10.0) <= 0.5  # at most acc·T
    out = run(tp)
    assert out[-1, 0] == 5000.0


# ---------------------------------------------------------------- arguments
@pytest.mark.parametrize(
    "kwargs",
    [
        {"acc": 0.0},
        {"acc": -1.0},
        {"acc": float("nan")},
        {"acc": 1.0, "dec": -0.5},
        {"acc": 1.0, "vel_start": -1.0},
        {"acc": 1.0, "smooth_time": 51},
        {"acc": 1.0, "smooth_time": -1},
        {"acc": 1.0, "smooth_time": 2.5},
        {"acc": True},
    ],
)
def test_trap_params_out_of_range_are_parameter_errors(kwargs):
    """GT_SetTrapPrm ranges (chapter 13): acc/dec > 0, velStart >= 0, smoothTime in [0, 50]."""
    with pytest.raises(ParameterError):
        TrapParams(**kwargs)


def test_unset_dec_is_acc():
    """GT_SetTrapPrm: "未设置减速度时，默认减速度和加速度相同"."""
    assert TrapParams(0.5).dec == 0.5 and TrapParams(0.5, 0.0, 0.0, 3).smooth_time == 3


@pytest.mark.parametrize("vel", [0.0, -5.0, float("inf")])
def test_trap_speed_must_be_positive(vel):
    with pytest.raises(ParameterError):
        TrapPlanner().start(0.0, 100, vel, TrapParams(1.0))


def test_non_integer_target_and_bad_cycle_are_refused():
    with pytest.raises(ParameterError):
        TrapPlanner().start(0.0, 10.5, 1.0, TrapParams(1.0))
    with pytest.raises(ParameterError):
        TrapPlanner(0.0)


# -------------------------------------------------------------- properties
cycles = st.sampled_from([0.25, 0.5, 1.0, 2.0])


@settings(max_examples=examples(60, 15), deadline=None)
@given(
    dist=st.integers(-30000, 30000),
    vel=st.floats(0.5, 100.0),
    acc=st.floats(0.02, 5.0),
    dec=st.floats(0.02, 5.0),
    vs_frac=st.sampled_from([0.0, 0.0, 0.3, 1.5]),
    ts=st.integers(0, 50),
    cycle=cycles,
)
def test_random_moves_end_exactly_on_target_within_limits(dist, vel, acc, dec, vs_frac, ts, cycle):
    vs = vs_frac * vel
    ref = Trapezoid.plan(dist, vel, acc, dec, vs)
    n_expected = math.ceil((ref.duration + ts) / cycle - 1e-9) if dist else 0
    assume(n_expected <= 8000)
    _, out = move(dist, vel, acc, dec, vs, ts, cycle, start=-77.0)
    target = -77.0 + dist
    assert len(out) == n_expected
    if not dist:
        return
    s = 1.0 if dist > 0 else -1.0
    assert out[-1, 0] == target and out[-1, 1] == 0.0
    assert np.all(s * out[:, 0] <= s * target)  # never past the target
    assert np.all(s * np.diff(np.concatenate([[-77.0], out[:, 0]])) >= -1e-9)  # monotone
    assert np.max(np.abs(out[:, 1])) <= vel * (1 + 1e-12)
    if vs == 0.0:  # no velocity jump: |a| and the sampled |Δv/Δt| stay within max(acc, dec)
        amax = max(acc, dec) * (1 + 1e-9) + 1e-12
        assert np.max(np.abs(out[:, 2])) <= amax
        # from rest (v = 0 before the first sample), as the position check starts at -77
        assert np.max(np.abs(np.diff(np.concatenate([[0.0], out[:, 1]])))) / cycle <= amax
    t = cycle * np.arange(1, len(out) + 1)
    if ts == 0:
        p, _, _ = ref.at(t)
    else:
        p = ref.smoothed_exact(t, ts)
    np.testing.assert_allclose(out[:, 0], -77.0 + p, atol=1e-6)


@settings(max_examples=examples(50, 12), deadline=None)
@given(
    first=st.integers(-20000, 20000),
    second=st.integers(-20000, 20000),
    vel=st.floats(1.0, 60.0),
    vel2=st.floats(1.0, 60.0),
    acc=st.floats(0.05, 3.0),
    dec=st.floats(0.05, 3.0),
    ts=st.sampled_from([0, 0, 7, 50]),
    at=st.integers(1, 3000),
    cycle=cycles,
)
def test_random_on_the_fly_updates_end_exactly_on_new_target(
    first, second, vel, vel2, acc, dec, ts, at, cycle
):
    tp = TrapPlanner(cycle)
    tp.start(0.0, first, vel, TrapParams(acc, dec, 0.0, ts))
    out = []
    for _ in range(at):
        if tp.done:
            break
        out.append(tp.step())
    tp.update(target=second, vel=vel2)
    while not tp.done:
        out.append(tp.step())
        assert len(out) < 200_000
    out = np.array(out).reshape(-1, 3)
    assert tp.pos == second
    if len(out):
        assert out[-1, 0] == second
        vmax = max(vel, vel2) * (1 + 1e-12)
        amax = max(acc, dec) * (1 + 1e-9) + 1e-12
        assert np.max(np.abs(out[:, 1])) <= vmax
        assert np.max(np.abs(out[:, 2])) <= amax
        v = np.concatenate([[0.0], out[:, 1]])
        assert np.max(np.abs(np.diff(v))) / cycle <= amax
        p = np.concatenate([[0.0], out[:, 0]])
        assert np.max(np.abs(np.diff(p))) <= vmax * cycle + 1e-9  # no position jump


def test_a_stop_that_has_ended_is_forgotten() -> None:
    """GT_Stop's ramp ends at rest: the planner is done and no longer stopping (as the PVT
    planner), so the next GT_Update starts afresh and nothing sees a stop that is over."""
    pl = TrapPlanner(1.0)
    pl.start(0.0, 10_000, 20.0, TrapParams(acc=0.5, dec=0.5))
    for _ in range(30):
        pl.step()
    pl.stop(0.5, abrupt=False)
    assert pl.stopping == StopKind.SMOOTH and not pl.done
    for _ in range(200):
        pl.step()
    assert pl.done and pl.stopping == StopKind.NONE
