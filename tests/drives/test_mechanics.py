"""The motor/load model and its loop: lag, limits, no overshoot, torque consistency."""

from __future__ import annotations

import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from gtecat.drives.mechanics import Mechanics, MechanicsParams
from tests.conftest import examples

P = MechanicsParams()
CPR = P.counts_per_rev


def test_constant_speed_lag_is_a_few_counts() -> None:
    m = Mechanics(P)
    d, v = 0.0, 0.0
    for _ in range(3000):
        v = min(v + 5000.0, 500000.0)  # ramp at 5e6 counts/s² (within the torque limit)
        d += v * 0.001
        m.track(d, v, 0.001)
    lag = d - m.pos
    assert 0.0 < lag == pytest.approx((1 - P.kff) * 500000.0 / P.kp, rel=1e-3)
    assert lag < 10
    assert m.vel == pytest.approx(500000.0)
    # the torque at constant speed is friction only
    assert m.torque == pytest.approx(P.viscous_permille * 500000.0 / m.vmax, rel=1e-3)


@pytest.mark.parametrize("dt", [0.000125, 0.001, 0.004])
def test_stable_for_any_cycle_time(dt: float) -> None:
    m = Mechanics(P)
    for _ in range(int(0.5 / dt)):
        m.track(1000.0, 0.0, dt)
    assert m.pos == pytest.approx(1000.0, abs=0.01)


def test_velocity_and_acceleration_limits() -> None:
    m = Mechanics(P, max_torque=1000)
    m.track(1e9, 0.0, 0.001)
    assert m.acc == pytest.approx(m.a_rated)  # rated torque -> rated acceleration
    assert m.limited
    assert m.torque == pytest.approx(1000.0, rel=0.01)
    for _ in range(2000):
        m.track(1e9, 0.0, 0.001)
    assert m.vel == pytest.approx(m.vmax)
    m.set_max_torque(3000)
    assert m.amax == pytest.approx(3 * m.a_rated)


def test_large_step_settles_without_overshoot() -> None:
    m = Mechanics(P)
    peak = 0.0
    for _ in range(3000):
        m.track(200000.0, 0.0, 0.001)
        peak = max(peak, m.pos)
    assert m.pos == pytest.approx(200000.0, abs=0.5)
    assert peak < 200000.0 + 200  # braking bound: no wind-up overshoot


def test_torque_mode_accelerates_and_is_speed_limited() -> None:
    m = Mechanics(P)
    m.drive_torque(500.0, 0.001)
    assert m.acc == pytest.approx(0.5 * m.a_rated)
    assert m.torque == 500.0
    for _ in range(20000):
        m.drive_torque(3000.0, 0.001)
    assert m.vel == pytest.approx(m.vmax) and m.limited


def test_coasting_stops_with_friction() -> None:
    m = Mechanics(P)
    m.vel = 10000.0
    for _ in range(1000):
        m.coast(0.001)
    assert m.vel == 0.0 and m.torque == 0.0


@settings(max_examples=examples(50, 12), deadline=None)
@given(st.floats(-1e6, 1e6), st.floats(-400000, 400000))
# the closing speed measured to where the demand will be, not where it was a cycle ago
# (vff + vstop stepped past a 58-count demand and the landing braked at 9,001,000 > 9e6)
@example(58.0, 1.0)
# a demand running away faster than the axis is not landed on (it would brake at 1.5e7)
@example(-90.0, 59802.62335914802)
@example(90.0, 168953.41575622372)
def test_position_velocity_consistency(target: float, vff: float) -> None:
    m = Mechanics(P)
    for k in range(40):
        p0 = m.pos
        # a consistent CSP set-point: the demand moves at the feed-forward speed
        m.track(target + vff * 0.001 * k, vff, 0.001)
        assert m.pos - p0 == pytest.approx(m.vel * 0.001, abs=1e-6)
        assert abs(m.vel) <= m.vmax + 1e-6
        assert abs(m.acc) <= m.amax * (1 + 1e-9) + 1e-6
