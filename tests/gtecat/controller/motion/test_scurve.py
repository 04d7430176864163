"""The pulse-card drive planner (motion/scurve.py) against closed forms.

Seed 004 chapter 5 ("速度曲线" 3.1-3.4) and seed 003 4.4 describe the curves: T ramps
with A (and D when asymmetric), S ramps whose acceleration grows with the jerk K to A
(partial S) or not (full S), start and end at SV.
"""

from __future__ import annotations

import itertools
import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.controller.motion.scurve import (
    SCurveParams,
    SCurvePlanner,
    plan_drive,
    ramp_distance,
    ramp_time,
)
from gtecat.errors import ParameterError
from tests.conftest import examples


def run(pl: SCurvePlanner, limit: int = 1_000_000) -> list[tuple[float, float, float]]:
    rows = [(pl.pos, pl.vel, pl.acc)]
    for _ in range(limit):
        rows.append(pl.step())
        if pl.done:
            return rows
    raise AssertionError("the drive never ended")


def drive(length: float, prm: SCurveParams, **kw) -> list[tuple[float, float, float]]:
    pl = SCurvePlanner(1.0)
    pl.start(0.0, length, prm, **kw)
    return run(pl)


def continuous_states(prof, dt: float = 0.01):
    t = 0.0
    while t < prof.duration:
        yield t, prof.state(t)
        t += dt


def test_partial_s_curve_limits_and_time_closed_form():
    """Seed 004 3.4: a (jerk K), b (A constant), c sections; V reached: cruise; mirrored down."""
    sv, v, a, k, length = 0.5, 10.0, 0.05, 0.001, 100_000.0
    prm = SCurveParams(sv, v, a, jerk=k)
    prof = plan_drive(length, prm)
    t_ramp = (v - sv) / a + a / k  # partial S: dv >= A²/K
    assert (v - sv) >= a * a / k
    d_ramp = 0.5 * (sv + v) * t_ramp
    assert prof.duration == pytest.approx(2 * t_ramp + (length - 2 * d_ramp) / v)
    for _, (_, vel, acc, jerk, _) in continuous_states(prof, 0.5):
        assert sv - 1e-9 <= vel <= v + 1e-9
        assert abs(acc) <= a + 1e-12
        assert abs(jerk) in (0.0, k)
    assert prof.state(prof.duration)[0] == length
    rows = drive(length, prm)
    assert rows[-1] == (length, 0.0, 0.0)  # exact end
    assert len(rows) - 1 == math.ceil(prof.duration)
    assert all(b[0] >= a_[0] for a_, b in itertools.pairwise(rows))  # never back
    assert max(r[0] for r in rows) == length  # never past


def test_full_s_curve_when_v_comes_before_a():
    """Seed 004 3.4: "b区间就消失" - acceleration never reaches A."""
    sv, v, a, k = 1.0, 3.0, 0.5, 0.001
    assert v - sv < a * a / k
    prof = plan_drive(50_000.0, SCurveParams(sv, v, a, jerk=k))
    peak = max(abs(s[2]) for _, s in continuous_states(prof, 0.25))
    assert peak == pytest.approx(math.sqrt((v - sv) * k), rel=1e-3)
    assert peak < a
    assert ramp_time(v - sv, a, k) == pytest.approx(2 * math.sqrt((v - sv) / k))


def test_t_curve_asymmetric_and_triangle_prevention():
    """Seed 004 3.2/3.3: T with A up, D down; a short move cruises over its middle half."""
    sv, v, a, d = 0.5, 10.0, 0.05, 0.02
    prof = plan_drive(100_000.0, SCurveParams(sv, v, a, d))
    up, down = (v - sv) / a, (v - sv) / d
    cruise = (100_000.0 - 0.5 * (sv + v) * (up + down)) / v
    assert prof.duration == pytest.approx(up + down + cruise)
    short = 1000.0
    tri = plan_drive(short, SCurveParams(sv, v, a, triangle=True))
    vp = max(s[1] for _, s in continuous_states(tri, 0.1))
    assert ramp_distance(sv, vp, a, math.inf) * 2 == pytest.approx(short / 2, rel=1e-6)
    rows = drive(short, SCurveParams(sv, v, a, triangle=True))
    assert rows[-1][0] == short


def test_constant_speed_drive_when_v_not_above_sv():
    """Seed 004 3.6: V below SV runs a constant-speed drive at V."""
    rows = drive(100.0, SCurveParams(4.0, 2.0))
    assert len(rows) - 1 == 50
    assert {round(r[1], 9) for r in rows[1:-1]} == {2.0}


def test_manual_deceleration_then_sv_to_the_end():
    """Seed 004 1.16 / 3.11: deceleration from the manual point, then SV to the last pulse."""
    prm = SCurveParams(1.0, 10.0, 0.1)
    rows = drive(20_000.0, prm, decel="manual", manual_dec=10_000.0)
    k = next(i for i, r in enumerate(rows) if r[0] > 10_000.0)
    assert rows[k - 1][1] == pytest.approx(10.0)
    assert rows[k + 100][1] == pytest.approx(1.0)
    assert rows[-1][0] == 20_000.0
    t_expected = 9 / 0.1 + (10_000 - 0.5 * 11 * 90) / 10 + 90 + (10_000 - 495) / 1.0
    assert len(rows) - 1 == pytest.approx(t_expected, abs=1)


def test_continuous_drive_decelerates_with_jerk_and_stops_at_sv():
    pl = SCurvePlanner(1.0)
    pl.start(0.0, None, SCurveParams(1.0, 10.0, 0.1, jerk=0.01))
    for _ in range(50):
        pl.step()
    v, a = pl.vel, pl.acc
    assert a == pytest.approx(0.1)
    pl.decelerate()
    rows = run(pl)
    accs = [r[2] for r in rows]
    assert all(abs(x - y) <= 0.01 + 1e-12 for x, y in itertools.pairwise(accs[:-1]))
    v_top = v + a * a / (2 * 0.01)  # the acceleration goes to 0 first
    assert max(r[1] for r in rows) == pytest.approx(v_top, abs=0.01)
    assert rows[-2][1] == pytest.approx(1.0, abs=0.01)


def test_speed_change_of_a_t_fixed_drive_keeps_the_target():
    """Seed 004 3.6: a new V during a drive; the drive still ends on its target."""
    pl = SCurvePlanner(1.0)
    pl.start(0.0, 50_000.0, SCurveParams(1.0, 10.0, 0.1))
    for _ in range(300):
        pl.step()
    assert pl.change_speed(20.0)
    rows = run(pl)
    assert max(r[1] for r in rows) == pytest.approx(20.0)
    assert rows[-1][0] == 50_000.0
    s_pl = SCurvePlanner(1.0)
    s_pl.start(0.0, 5000.0, SCurveParams(1.0, 10.0, 0.1, jerk=0.01))
    s_pl.step()
    assert not s_pl.change_speed(20.0)  # S fixed drive: "不能变更驱动速度"


def test_stop_ramp_and_hold():
    pl = SCurvePlanner(1.0)
    pl.start(0.0, None, SCurveParams(5.0, 5.0))
    pl.step()
    pl.stop(1.0)
    rows = run(pl)
    assert rows[-1][0] == pytest.approx(5.0 + 12.5)
    pl.start(0.0, 100.0, SCurveParams(1.0, 2.0, 0.1), direction=-1)
    assert run(pl)[-1][0] == -100.0


@pytest.mark.parametrize(
    "bad",
    [dict(vel=0.0), dict(vel_start=-1.0), dict(acc=0.0), dict(jerk=0.0), dict(jerk=math.nan)],
)
def test_bad_parameters_are_parameter_errors(bad):
    kw = dict(vel_start=1.0, vel=2.0, acc=1.0) | bad
    with pytest.raises(ParameterError):
        SCurveParams(**kw)


@settings(max_examples=examples(60, 15), deadline=None)
@given(
    length=st.integers(0, 40_000),
    sv=st.floats(0.05, 5.0),
    v=st.floats(0.1, 30.0),
    a=st.floats(0.005, 2.0),
    d=st.floats(0.0, 2.0),
    jerk=st.one_of(st.just(math.inf), st.floats(1e-4, 1.0)),
    direction=st.sampled_from([1, -1]),
)
def test_property_exact_end_within_limits(length, sv, v, a, d, jerk, direction):
    # a cruise of more than 5000 cycles adds nothing to check, only steps (v 0.1 over 40,000
    # pulses was 400,000 of them): long moves stay long at the speeds that reach them quickly
    length = min(length, int(5000 * v))
    prm = SCurveParams(sv, v, a, d, jerk, triangle=not math.isfinite(jerk))
    pl = SCurvePlanner(1.0)
    pl.start(100.0, length, prm, direction)
    rows = run(pl)
    target = 100.0 + direction * length
    assert rows[-1] == (target, 0.0, 0.0)
    top = max(v, sv) if v > sv else v
    for p, vel, acc in rows:
        assert abs(vel) <= top + 1e-6
        assert (p - target) * direction <= 1e-9
        assert abs(acc) <= max(a, d or a) + 1e-9
