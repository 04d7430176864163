"""The soft-limit emergency stop starts in the cycle whose plan passes the limit (manual 9.2.2).

Rule (``gtecat.controller.resources``, "Soft limit, same cycle"): the stop ramp at
decAbruptStop (GT_SetStopDec, 1000 pulse/ms² by table 4-4) takes over where the plan
crosses the limit, inside the cycle, so the plan comes to rest at
``limit + v²/(2·decAbruptStop)`` with ``v`` the planned speed at the limit, and GT_GetSts
bit 5/6 (table 6-2) is set in that same cycle.  Every expectation below comes from the
closed form of a Trap move from rest (velStart 0, smoothTime 0: ``p = acc·t²/2`` up to
``vel``, then ``vel`` constant), computed here, not from the planner.
"""

from __future__ import annotations

import math
from ctypes import byref, c_double, c_long

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from gtecat import gt
from gtecat.controller.axis_status import AxisStatus
from gtecat.controller.core import Controller, Options
from gtecat.controller.motion import StopDecel, StopRamp, TrapParams, ramp_through
from gtecat.controller.resources import AxisResources, axis_resources
from gtecat.controller.safety import SOFT_NEGATIVE_OFF, SOFT_POSITIVE_OFF, limit_crossing
from tests.conftest import EXAMPLES
from tests.gtecat.gt.conftest import bring_up

POS_LIM, NEG_LIM, MOVING = (
    int(AxisStatus.POSITIVE_LIMIT),
    int(AxisStatus.NEGATIVE_LIMIT),
    int(AxisStatus.MOVING),
)
FAR = 1_000_000


# --- the closed form ----------------------------------------------------------------------------
def trap_from_rest(t: float, vel: float, acc: float) -> tuple[float, float]:
    """(distance, speed) of a Trap move from rest at time ``t`` (ms), before it brakes."""
    t1 = vel / acc
    if t <= t1:
        return 0.5 * acc * t * t, acc * t
    return 0.5 * vel * t1 + vel * (t - t1), vel


def expected_stop(limit: float, vel: float, acc: float, dec: float, cycle: float):
    """Distances from the start: crossing cycle k, the samples from k on, whether the
    acceleration corner falls inside cycle k (where the planner's in-cycle curve is an
    approximation)."""
    x1 = vel * vel / (2.0 * acc)
    t_cross = math.sqrt(2.0 * limit / acc) if limit <= x1 else vel / acc + (limit - x1) / vel
    k = math.floor(t_cross / cycle) + 1  # first sample strictly past the limit
    v = math.sqrt(2.0 * acc * limit) if limit <= x1 else vel  # planned speed at the limit
    final = limit + v * v / (2.0 * dec)
    samples = []
    tau = k * cycle - t_cross  # ramp time at sample k
    while tau < v / dec:
        samples.append(limit + v * tau - 0.5 * dec * tau * tau)
        tau += cycle
    samples.append(final)
    corner = (k - 1) * cycle < vel / acc < k * cycle
    return k, samples, final, corner, t_cross


# --- one controller for the whole module ------------------------------------------------------
@pytest.fixture(scope="module")
def ctl():
    c = Controller(Options(eni=str(EXAMPLES / "manual_fig5_2.eni"), clock="lockstep", log=""))
    c.init_ecat()
    assert c.clock.run_until(lambda: c.ready, 100)
    c.start_ecat()
    for n in (1, 2):
        ax = c.axis(n)
        assert c.clock.run_until(ax.enable_step, 200)
        ax.sync_to_actual()
        ax.servo_on = True
    yield c
    c.close()


def fresh(ctl: Controller, n: int, dec: float) -> AxisResources:
    """Axis ``n`` at rest at 0, nothing latched, limits off, decAbruptStop = ``dec``."""
    res = axis_resources(ctl, n)
    res.safety.set_soft_limits(SOFT_POSITIVE_OFF, SOFT_NEGATIVE_OFF)
    assert ctl.clock.run_until(lambda: not res.moving, 60_000)
    res.zero_pos()
    res.clear_flags()
    assert res.latched == 0
    res.profile.stop_dec = StopDecel(smooth=1.0, abrupt=dec)
    return res


def start_trap(res: AxisResources, target: int, vel: float, acc: float) -> None:
    res.prf_trap()
    res.set_trap_prm(TrapParams(acc=acc, dec=acc))
    res.set_target(target)
    res.set_vel(vel)
    res.check_update()
    res.start()


def run_to_rest(ctl: Controller, axes: list[AxisResources]) -> dict[int, list[tuple[float, int]]]:
    """One (axis planned position, GT_GetSts word) per cycle and axis, until all stand."""
    log: dict[int, list[tuple[float, int]]] = {r.number: [] for r in axes}
    for _ in range(20_000):
        ctl.clock.cycle()
        for r in axes:
            log[r.number].append((r.axis_prf_pos, r.status()))
        if not any(r.moving for r in axes):
            return log
    raise AssertionError("still moving after 20 s")


def check(log, sign: float, limit: float, vel: float, acc: float, dec: float, cycle: float):
    k, samples, final, corner, _ = expected_stop(limit, vel, acc, dec, cycle)
    flag = POS_LIM if sign > 0 else NEG_LIM
    pos = [sign * p for p, _ in log]
    sts = [s for _, s in log]
    # cycle k (1-based) is log[k - 1]; before it the plan is the unconstrained Trap, inside
    for i in range(k - 1):
        assert pos[i] == pytest.approx(trap_from_rest((i + 1) * cycle, vel, acc)[0], abs=1e-6)
        assert pos[i] <= limit and not sts[i] & flag, f"cycle {i + 1}"
    assert sts[k - 1] & flag, "bit set in the cycle whose plan passes the limit"
    assert all(s & flag for s in sts[k - 1 :])  # and latched
    if corner:  # acceleration ends inside the crossing cycle: the speed there is approximate
        assert limit < pos[-1] <= limit + vel * vel / (2.0 * dec) + 1e-6
        return
    assert pos[k - 1 :] == pytest.approx(samples, rel=1e-9, abs=1e-6)
    assert pos[-1] == pytest.approx(final, rel=1e-12, abs=1e-9)
    assert not sts[-1] & MOVING and all(x & MOVING for x in sts[:-1])  # at rest at the end


# --- properties ---------------------------------------------------------------------------------
@settings(max_examples=25, deadline=None)
@given(
    limit=st.integers(1, 1500),
    vel=st.floats(1.0, 200.0),
    acc=st.floats(0.2, 20.0),
    dec=st.sampled_from([1.0, 3.5, 20.0, 125.0, 1000.0, 32767.0]),
)
def test_stop_starts_at_the_crossing_both_directions(ctl, limit, vel, acc, dec):
    """Axis 1 runs positive into +limit, axis 2 negative into -limit, the same profile."""
    cycle = axis_resources(ctl, 1).cycle_ms
    t_cross = expected_stop(limit, vel, acc, dec, cycle)[4]
    # not within float noise of a sample: which cycle crosses would depend on rounding
    assume(abs(t_cross / cycle - round(t_cross / cycle)) > 1e-6)
    up, down = fresh(ctl, 1, dec), fresh(ctl, 2, dec)
    up.safety.set_soft_limits(limit, SOFT_NEGATIVE_OFF)
    down.safety.set_soft_limits(SOFT_POSITIVE_OFF, -limit)
    start_trap(up, FAR, vel, acc)
    start_trap(down, -FAR, vel, acc)
    log = run_to_rest(ctl, [up, down])
    check(log[1], +1.0, limit, vel, acc, dec, cycle)
    check(log[2], -1.0, limit, vel, acc, dec, cycle)


@pytest.mark.parametrize("dec", [1000.0, 10.0, 0.5])
def test_limit_exactly_on_a_sample_is_crossed_at_the_next_cycle_start(ctl, dec):
    """acc 1, vel 50: samples at whole pulses; 20000 is sample 425 exactly (not past it:
    "大于"), so cycle 426 crosses at its start with 50 pulse/ms."""
    up, down = fresh(ctl, 1, dec), fresh(ctl, 2, dec)
    up.safety.set_soft_limits(20000, SOFT_NEGATIVE_OFF)
    down.safety.set_soft_limits(SOFT_POSITIVE_OFF, -20000)
    start_trap(up, FAR, 50.0, 1.0)
    start_trap(down, -FAR, 50.0, 1.0)
    log = run_to_rest(ctl, [up, down])
    for n, sign, flag in ((1, 1.0, POS_LIM), (2, -1.0, NEG_LIM)):
        pos = [sign * p for p, _ in log[n]]
        sts = [s for _, s in log[n]]
        assert pos[424] == 20000.0 and not sts[424] & flag  # on the limit, not past it
        assert sts[425] & flag
        assert pos[-1] == pytest.approx(20000 + 50.0**2 / (2 * dec))  # 20001.25 at 1000
        check(log[n], sign, 20000, 50.0, 1.0, dec, 1.0)


def test_a_move_whose_last_sample_passes_the_limit_is_stopped_too(ctl):
    """The Trap's final sample (its target) is the first past the limit: the planner has
    finished in that step, and the stop still replaces it (the old check let it stand)."""
    res = fresh(ctl, 1, 1000.0)
    start_trap(res, 1000, 10.0, 10.0)  # limits off: where the samples fall
    free = [p for p, _ in run_to_rest(ctl, [res])[1]]
    assert free[-1] == 1000 and free[-2] < 999
    limit = math.ceil(free[-2])
    res = fresh(ctl, 1, 1000.0)
    res.safety.set_soft_limits(limit, SOFT_NEGATIVE_OFF)
    start_trap(res, 1000, 10.0, 10.0)
    log = run_to_rest(ctl, [res])[1]
    assert len(log) == len(free) and log[-1][1] & POS_LIM
    assert limit < log[-1][0] <= limit + 10.0**2 / 2000 + 1e-9  # at most the stop distance


def test_moving_away_from_a_limit_behind_is_not_stopped(ctl):
    res = fresh(ctl, 1, 1000.0)
    res.safety.set_soft_limits(SOFT_POSITIVE_OFF, -10)
    start_trap(res, 500, 20.0, 2.0)  # the plan starts inside and moves away from -10
    log = run_to_rest(ctl, [res])[1]
    assert log[-1][0] == 500 and not any(s & NEG_LIM for _, s in log)


# --- the two helpers ----------------------------------------------------------------------------
@given(
    p0=st.floats(-1e6, 1e6),
    v0=st.floats(0.01, 500.0),
    a=st.floats(-5.0, 5.0),
    f=st.floats(0.01, 0.99),
)
def test_limit_crossing_is_exact_on_a_constant_acceleration_cycle(p0, v0, a, f):
    v1 = v0 + a
    assume(v1 > 0.01)
    p1 = p0 + v0 + 0.5 * a
    level = p0 + v0 * f + 0.5 * a * f * f
    assume(level - p0 > 1e-6 and p1 - level > 1e-6)
    got_f, at, v = limit_crossing(p0, v0, p1, v1, level, 1.0)
    assert at == level
    assert got_f == pytest.approx(f, abs=1e-6)
    assert v == pytest.approx(v0 + a * f, rel=1e-6, abs=1e-6)


def test_limit_crossing_when_already_past():
    assert limit_crossing(10.0, 5.0, 15.0, 5.0, 10.0, 1.0) == (0.0, 10.0, 5.0)
    assert limit_crossing(-10.0, -5.0, -15.0, -5.0, -9.0, 1.0) == (0.0, -10.0, -5.0)


@given(
    pos=st.floats(-1e5, 1e5),
    vel=st.floats(-500.0, 500.0),
    dec=st.floats(0.5, 32767.0),
    before=st.floats(0.0, 1.0),
)
def test_ramp_through_passes_the_state_and_ends_a_stopping_distance_on(pos, vel, dec, before):
    p0, v0 = ramp_through(pos, vel, dec, before)
    ramp = StopRamp(1.0)
    ramp.start(p0, v0, dec)
    assert ramp.end_pos == pytest.approx(pos + vel * abs(vel) / (2 * dec), rel=1e-9, abs=1e-6)
    if vel:
        assert ramp.t_end == pytest.approx(before + abs(vel) / dec)


# --- through the GT API: GT_GetSts and GT_GetPrfPos in the same cycle ---------------------------
@pytest.fixture
def gt_lockstep():
    gt.GT_Close()
    bring_up(clock="lockstep")
    yield
    gt.GT_Close()


@pytest.mark.parametrize("sign", [1, -1])
def test_gt_sts_shows_the_limit_in_the_cycle_the_plan_passes_it(gt_lockstep, sign):
    """The issue's case: Trap at 50 pulse/ms into a soft limit at 20000 used to stop at
    20051.25; the stop now starts in the crossing cycle and rests at 20001.25 (decAbruptStop
    1000 by table 4-4, never set here)."""
    assert gt.GT_AxisOn(1) == 0
    assert gt.GT_SetSoftLimit(1, 20000, -20000) == 0
    prm = gt.TTrapPrm()
    prm.acc, prm.dec = 1.0, 1.0
    assert gt.GT_PrfTrap(1) == 0 and gt.GT_SetTrapPrm(1, byref(prm)) == 0
    assert gt.GT_SetPos(1, sign * FAR) == 0 and gt.GT_SetVel(1, 50) == 0
    assert gt.GT_Update(1) == 0
    flag = POS_LIM if sign > 0 else NEG_LIM
    pos, sts = c_double(), c_long()
    trace = []
    for _ in range(1000):
        gt.GTE_Wait(1)
        assert gt.GT_GetPrfPos(1, byref(pos)) == 0 and gt.GT_GetSts(1, byref(sts)) == 0
        trace.append((sign * pos.value, sts.value))
        if not sts.value & MOVING:
            break
    first_past = next(i for i, (p, _) in enumerate(trace) if p > 20000)
    first_flag = next(i for i, (_, s) in enumerate(trace) if s & flag)
    assert first_past == first_flag  # GT_GetSts bit 5/6 in that very cycle (table 6-2)
    assert trace[first_past - 1][0] == 20000.0
    assert trace[first_past][0] == 20001.25 == trace[-1][0]  # 20000 + 50²/2000, at rest
    assert gt.GT_ClrSts(1) == 0
    assert gt.GT_GetSts(1, byref(sts)) == 0 and sts.value & flag  # still past: stays


@pytest.mark.parametrize("limit", [544, 576, 2048])
def test_both_axes_cross_where_the_bank_refills_their_trap_tables(ctl, limit):
    """The crossing cycle of both axes is one where the axis bank refills their Trap tables
    (every 32 samples compiled, 2048 in numpy): the first row's release must still find
    the second's last sample (it moves to the table's spare slot before the refill)."""
    up, down = fresh(ctl, 1, 20.0), fresh(ctl, 2, 20.0)
    up.safety.set_soft_limits(limit, SOFT_NEGATIVE_OFF)
    down.safety.set_soft_limits(SOFT_POSITIVE_OFF, -limit)
    start_trap(up, FAR, 1.0, 1.0)
    start_trap(down, -FAR, 1.0, 1.0)
    log = run_to_rest(ctl, [up, down])
    check(log[1], +1.0, limit, 1.0, 1.0, 20.0, 1.0)
    check(log[2], -1.0, limit, 1.0, 1.0, 20.0, 1.0)
