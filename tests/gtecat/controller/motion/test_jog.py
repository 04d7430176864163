"""Jog planner (manual 7.3, GT_SetJogPrm, GT_SetVel + GT_Update on the fly)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.controller.motion import JogParams, JogPlanner, StopKind
from gtecat.controller.motion.jog import ramp
from gtecat.errors import CommandError, ParameterError
from tests.conftest import examples


def steps(jp: JogPlanner, n: int) -> np.ndarray:
    return np.array([jp.step() for _ in range(n)]).reshape(-1, 3)


def run(jp: JogPlanner, limit: int = 1_000_000) -> np.ndarray:
    out = []
    while not jp.done:
        out.append(jp.step())
        assert len(out) < limit
    return np.array(out).reshape(-1, 3)


def test_example_7_2_speed_change_on_the_fly():
    """Example 7-2: acc = dec = 0.0625, 100 pulse/ms, then 50 pulse/ms once past 100000 pulse."""
    jp = JogPlanner(1.0)
    jp.start(0.0, 100.0, JogParams(0.0625, 0.0625))
    out = []
    while jp.pos <= 100000:
        out.append(jp.step())
    out = np.array(out)
    t = np.arange(1, len(out) + 1, dtype=float)
    v_ref = np.minimum(0.0625 * t, 100.0)
    p_ref = np.where(t <= 1600, 0.0625 * t**2 / 2, 80000 + 100 * (t - 1600))
    np.testing.assert_allclose(out[:, 1], v_ref, atol=1e-12)
    np.testing.assert_allclose(out[:, 0], p_ref, atol=1e-8)
    assert len(out) == 1801  # 80000 at 1600 ms, then 100 pulse/ms
    jp.update(50.0)
    out2 = steps(jp, 1000)
    np.testing.assert_allclose(out2[:800, 1], 100.0 - 0.0625 * np.arange(1, 801), atol=1e-12)
    assert np.all(out2[800:, 1] == 50.0) and np.all(out2[800:, 2] == 0.0)
    assert out2[0, 2] == -0.0625


def test_reversal_brakes_with_dec_then_accelerates_with_acc():
    jp = JogPlanner(1.0)
    jp.start(0.0, 10.0, JogParams(1.0, 0.5))
    steps(jp, 20)
    jp.update(-10.0)
    out = steps(jp, 40)
    v = out[:, 1]
    np.testing.assert_allclose(v[:20], 10.0 - 0.5 * np.arange(1, 21))  # dec down to 0
    np.testing.assert_allclose(v[20:30], -np.arange(1, 11, dtype=float))  # acc up to -10
    assert np.all(v[30:] == -10.0)
    # position: 10·10/2 + 10·10 accelerating+cruising, + 10²/(2·0.5) braking
    assert out[19, 0] == pytest.approx(50 + 100 + 100)


def test_ramp_end_inside_a_cycle_is_integrated_exactly():
    """A ramp that ends mid-cycle: position is the exact integral of the trapezoidal speed."""
    jp = JogPlanner(1.0)
    jp.start(0.0, 2.5, JogParams(1.0))
    out = steps(jp, 4)
    # v = t for t < 2.5, then 2.5: p(3) = 2.5²/2 + 2.5·0.5
    assert out[2, 0] == pytest.approx(3.125 + 1.25)
    assert out[2, 1] == 2.5 and out[3, 0] == pytest.approx(4.375 + 2.5)


def test_jog_stop_by_zero_speed_ends_done_at_the_closed_form_position():
    jp = JogPlanner(0.5)
    jp.start(100.0, -20.0, JogParams(2.0, 4.0))
    steps(jp, 40)  # 10 ms at 2 → cruising at -20 since 10 ms... (t=20 ms)
    p0 = jp.pos
    jp.update(0.0)
    out = run(jp)
    assert len(out) == 10  # 20 / 4 = 5 ms = 10 cycles
    assert out[-1, 0] == pytest.approx(p0 - 20**2 / (2 * 4.0))
    assert jp.done and jp.vel == 0.0


@pytest.mark.parametrize("smooth", [0.5, 0.9, 0.99])
def test_smooth_filter_bounds_speed_and_acceleration(smooth):
    """smooth in [0, 1) (7.3.2): smoother acceleration, never beyond the target speed or acc."""
    jp = JogPlanner(1.0)
    jp.start(0.0, 30.0, JogParams(0.5, 0.25, smooth))
    out = steps(jp, 400)
    v, a = out[:, 1], out[:, 2]
    assert np.max(v) <= 30.0 and np.all(np.diff(v) >= -1e-12)
    assert np.max(a) <= 0.5 + 1e-12
    tau = -1.0 / math.log(smooth)
    assert a[0] == pytest.approx(0.5 * (1 - math.exp(-1 / tau)))  # exponential rise
    assert np.max(np.abs(np.diff(np.concatenate([[0.0], a])))) <= 0.5 / tau + 1e-12  # jerk
    # position, speed and acceleration are each other's derivatives
    np.testing.assert_allclose(np.diff(v), (a[1:] + a[:-1]) / 2, atol=0.5 / tau**2)
    jp.update(0.0)
    out = run(jp)
    assert jp.done and out[-1, 1] == 0.0 and np.min(out[:, 1]) >= 0.0


def test_smooth_is_per_millisecond_whatever_the_cycle():
    """Same smooth coefficient, 1 ms and 0.25 ms cycles: same speed curve at the same times."""
    curves = {}
    for cycle in (1.0, 0.25):
        jp = JogPlanner(cycle)
        jp.start(0.0, 10.0, JogParams(1.0, 1.0, 0.8))
        out = steps(jp, int(60 / cycle))
        curves[cycle] = out[int(1 / cycle) - 1 :: int(1 / cycle)]
    np.testing.assert_allclose(curves[1.0], curves[0.25], atol=1e-9)
    assert curves[1.0][-1, 1] == pytest.approx(10.0, abs=1e-3)


def test_smoothed_stop_settles_far_from_zero():
    """At 8e8 pulse a float step is 1.2e-7: the filter's last lag must still count as settled."""
    jp = JogPlanner(0.5)
    jp.start(793480536.0, 50.0, JogParams(0.57, 0.05, 0.922))
    steps(jp, 2000)
    jp.update(0.0)
    out = run(jp, limit=200_000)
    assert jp.done and out[-1, 1] == 0.0


@pytest.mark.parametrize("abrupt,dec", [(False, 1.0), (True, 1000.0)])
def test_gt_stop_from_any_speed(abrupt, dec):
    jp = JogPlanner(1.0)
    jp.start(0.0, 50.0, JogParams(0.5, 0.5, 0.3))
    steps(jp, 300)
    p0, v0 = jp.pos, jp.vel
    jp.stop(dec, abrupt=abrupt)
    assert jp.stopping == (StopKind.ABRUPT if abrupt else StopKind.SMOOTH)
    out = run(jp)
    assert len(out) == math.ceil(v0 / dec)
    assert out[-1, 0] == pytest.approx(p0 + v0**2 / (2 * dec))


def test_update_when_idle_restarts_with_last_parameters_and_errors_before_start():
    with pytest.raises(CommandError):
        JogPlanner().update(5.0)
    jp = JogPlanner(1.0)
    jp.start(0.0, 0.0, JogParams(1.0))
    assert jp.done
    jp.update(3.0)
    out = steps(jp, 5)
    assert list(out[:, 1]) == [1.0, 2.0, 3.0, 3.0, 3.0] and not jp.done


@pytest.mark.parametrize(
    "kwargs",
    [
        {"acc": 0.0},
        {"acc": 1.0, "smooth": 1.0},
        {"acc": 1.0, "smooth": -0.1},
        {"acc": 1.0, "dec": -1.0},
        {"acc": float("inf")},
        {"acc": 1.0, "smooth": float("nan")},
    ],
)
def test_jog_params_out_of_range(kwargs):
    """GT_SetJogPrm (chapter 13): acc, dec > 0; smooth in [0, 1)."""
    with pytest.raises(ParameterError):
        JogParams(**kwargs)


def test_unset_dec_is_acc():
    assert JogParams(0.25).dec == 0.25


@settings(max_examples=examples(80, 20), deadline=None)
@given(
    v0=st.floats(-50, 50),
    goal=st.floats(-50, 50),
    acc=st.floats(0.01, 10),
    dec=st.floats(0.01, 10),
    dt=st.floats(0.0, 100),
)
def test_ramp_integrates_exactly(v0, goal, acc, dec, dt):
    """One ramp call over dt equals many small calls (exact piecewise integration)."""
    p1, v1, _ = ramp(0.0, v0, goal, acc, dec, dt)
    p2, v2 = 0.0, v0
    for _ in range(8):
        p2, v2, _ = ramp(p2, v2, goal, acc, dec, dt / 8)
    assert v1 == pytest.approx(v2, abs=1e-9)
    assert p1 == pytest.approx(p2, rel=1e-9, abs=1e-7)
    lo, hi = min(v0, goal, 0.0), max(v0, goal, 0.0)
    assert lo - 1e-12 <= v1 <= hi + 1e-12


@settings(max_examples=40, deadline=None)
@given(
    goals=st.lists(st.floats(-80, 80), min_size=1, max_size=4),
    acc=st.floats(0.05, 5),
    dec=st.floats(0.05, 5),
    smooth=st.sampled_from([0.0, 0.0, 0.5, 0.95]),
    hold=st.integers(1, 300),
    cycle=st.sampled_from([0.25, 0.5, 1.0, 2.0]),
)
def test_random_speed_changes_stay_within_limits_and_stop(goals, acc, dec, smooth, hold, cycle):
    jp = JogPlanner(cycle)
    jp.start(0.0, goals[0], JogParams(acc, dec, smooth))
    out = [steps(jp, hold)]
    for g in goals[1:]:
        jp.update(g)
        out.append(steps(jp, hold))
    jp.update(0.0)
    out.append(run(jp))
    out = np.concatenate(out)
    vmax = max(abs(g) for g in goals)
    amax = max(acc, dec) * (1 + 1e-9)
    assert np.max(np.abs(out[:, 1])) <= vmax + 1e-9
    assert np.max(np.abs(out[:, 2])) <= amax
    v = np.concatenate([[0.0], out[:, 1]])
    assert np.max(np.abs(np.diff(v))) / cycle <= amax + 1e-9
    assert jp.done and out[-1, 1] == 0.0
