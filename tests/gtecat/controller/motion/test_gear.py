"""Electronic gear planner: ratios, clutch zones in master travel, direction (manual 7.5,
example 7-5, figure 7-10, chapter 13 entries 24, 53-54, 87, 110-111)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.controller.motion.gear import GearPlanner
from gtecat.controller.motion.master import MasterItem, MasterSpec, MasterType
from gtecat.errors import CommandError, ParameterError


class FakeMaster:
    """A master whose position the test sets before each slave cycle."""

    def __init__(self, pos: float = 0.0) -> None:
        self.pos = pos

    def __call__(self) -> float:
        return self.pos


def jog(t, acc, vel):
    """Jog master from rest (closed form): speed ramps with ``acc`` to ``vel``."""
    t = np.asarray(t, dtype=float)
    ta = vel / acc
    return np.where(t <= ta, 0.5 * acc * t * t, 0.5 * vel * ta + vel * (t - ta))


def clutch_reference(x, r_from, r_to, length):
    """Slave travel after master travel ``x`` when the ratio goes linearly r_from → r_to over
    ``length`` of master travel (area under the ratio, figure 7-10)."""
    x = np.asarray(x, dtype=float)
    if length == 0:
        return r_to * x
    inside = np.minimum(x, length)
    r_x = r_from + (r_to - r_from) * inside / length
    return (r_from + r_x) / 2 * inside + r_to * np.maximum(x - length, 0.0)


def geared(master: FakeMaster, me=2, se=1, slope=0, dir=0, cycle=1.0) -> GearPlanner:
    g = GearPlanner(profile=2, dir=dir, cycle_ms=cycle)
    g.set_master(1, MasterType.PROFILE, 0, source=master)
    g.set_ratio(me, se, slope)
    return g


def drive(g: GearPlanner, master: FakeMaster, positions) -> np.ndarray:
    out = []
    for p in positions:
        master.pos = float(p)
        out.append(g.step())
    return np.array(out)


# --------------------------------------------------------------- ratio
def test_ratio_without_clutch_is_slave_even_over_master_even_from_the_first_cycle():
    m = FakeMaster(1000.0)
    g = geared(m, 2, 1)
    g.start(pos=5.0)
    out = drive(g, m, 1000 + 100 * np.arange(1, 51))
    np.testing.assert_allclose(out[:, 0], 5 + 50 * np.arange(1, 51))
    assert np.all(out[:, 1] == 50.0)
    assert g.ratio == (2, 1, 0) and g.ratio_now == 0.5


def test_negative_slave_even_reverses_the_slave():
    m = FakeMaster()
    g = geared(m, 3, -2)
    g.start()
    out = drive(g, m, [30, 60, 90])
    np.testing.assert_allclose(out[:, 0], [-20, -40, -60])


def test_example_7_5_clutch_of_100000_master_pulses_sample_by_sample():
    """Example 7-5 / figures 7-11, 7-12: master jogs (acc 1, 100 pulse/ms), 2:1, clutch 100000.

    The slave ratio grows linearly with master travel and reaches 1/2 when the master
    has travelled 100000 pulses (t = 1050 ms); from then on slave speed = 50 pulse/ms.
    """
    m = FakeMaster()
    g = geared(m, 2, 1, 100000)
    g.start()
    t = np.arange(1, 3001)
    x = jog(t, 1.0, 100.0)
    out = drive(g, m, x)
    np.testing.assert_allclose(out[:, 0], clutch_reference(x, 0.0, 0.5, 100000), atol=1e-7)
    assert x[1049] == 100000  # end of the clutch zone
    assert out[1049, 0] == pytest.approx(25000.0)  # (0 + 1/2)/2 · 100000
    assert np.all(out[1050:, 1] == 50.0)
    assert np.all(np.diff(out[:1050, 1]) > 0)  # the slave speeds up through the clutch
    assert out[1000, 1] < 50.0
    assert not g.in_clutch


def test_figure_7_10_ratio_change_during_motion_uses_a_new_clutch_zone():
    """Figure 7-10: clutch 1 engages 4:3, clutch 2 moves to 2:1; both measured in master travel."""
    m = FakeMaster()
    g = geared(m, 4, 3, 4000)
    g.start()
    x1 = 10.0 * np.arange(1, 601)  # master 10 pulse/ms
    out1 = drive(g, m, x1)
    np.testing.assert_allclose(out1[:, 0], clutch_reference(x1, 0, 0.75, 4000), atol=1e-9)
    assert out1[-1, 1] == pytest.approx(7.5)
    g.set_ratio(2, 1, 2000)  # during motion: from 3/4 to 1/2 over 2000 master pulses
    assert g.in_clutch and g.ratio_now == 0.75
    x2 = 6000 + 10.0 * np.arange(1, 401)
    out2 = drive(g, m, x2)
    base = out1[-1, 0]
    np.testing.assert_allclose(
        out2[:, 0], base + clutch_reference(x2 - 6000, 0.75, 0.5, 2000), atol=1e-9
    )
    assert out2[199, 0] - base == pytest.approx((0.75 + 0.5) / 2 * 2000)
    assert np.all(np.abs(out2[200:, 1] - 5.0) < 1e-9)
    assert g.ratio == (2, 1, 2000)


def test_ratio_change_inside_a_clutch_starts_from_the_ratio_reached():
    m = FakeMaster()
    g = geared(m, 1, 1, 1000)
    g.start()
    drive(g, m, [250.0])  # a quarter through: ratio 1/4, slave 31.25
    assert g.ratio_now == pytest.approx(0.25) and g.pos == pytest.approx(31.25)
    g.set_ratio(1, 0, 500)  # go to 0 over 500
    out = drive(g, m, [500.0, 750.0, 1000.0])
    assert out[0, 0] == pytest.approx(31.25 + (0.25 + 0.125) / 2 * 250)
    assert out[1, 0] == pytest.approx(31.25 + 0.25 / 2 * 500)
    assert out[1, 0] == out[2, 0]  # ratio 0 reached: the slave stands although the master runs


@settings(max_examples=30, deadline=None)
@given(
    st.lists(st.floats(-50, 50, allow_nan=False), min_size=1, max_size=60),
    st.integers(1, 9),
    st.integers(-9, 9),
    st.sampled_from([0, 2, 37, 400]),
)
def test_clutch_displacement_is_the_area_under_the_ratio_in_master_travel(steps, me, se, slope):
    """Whatever the master does, the slave moves ∫ r(x) dx with x the travelled distance."""
    m = FakeMaster()
    g = geared(m, me, se, slope)
    g.start()
    pos = np.cumsum(steps)
    out = drive(g, m, pos)
    travel = np.cumsum(np.abs(steps))
    # slave increments = sign(step) · (area of the ratio over this cycle's travel)
    area = clutch_reference(np.concatenate([[0.0], travel]), 0.0, se / me, slope)
    expected = np.cumsum(np.sign(steps) * np.diff(area))
    np.testing.assert_allclose(out[:, 0], expected, atol=1e-8)


# ------------------------------------------------------------ direction
@pytest.mark.parametrize(
    ("dir", "expected"),
    [(0, [10, 20, 10, 0, 10]), (1, [10, 20, 20, 20, 30]), (-1, [0, 0, -10, -20, -20])],
)
def test_follow_direction_passes_only_that_way_of_master_motion(dir, expected):
    """GT_PrfGear dir: 0 both ways, 1 positive only, -1 negative only (one-way clutch)."""
    m = FakeMaster()
    g = geared(m, 1, 1, dir=dir)
    g.start()
    out = drive(g, m, [10, 20, 10, 0, 10])
    np.testing.assert_allclose(out[:, 0], expected)


def test_master_from_the_controller_is_sampled_at_start():
    m = FakeMaster(12345.0)
    g = geared(m, 1, 2)
    g.start()
    assert drive(g, m, [12345.0, 12346.0])[:, 0].tolist() == [0.0, 2.0]


def test_cycle_time_scales_speed_not_position():
    m = FakeMaster()
    g = geared(m, 1, 1, cycle=0.5)
    g.start()
    out = drive(g, m, [5.0, 10.0])
    assert out[:, 0].tolist() == [5.0, 10.0] and out[1, 1] == 10.0


# ----------------------------------------------------------- stop, hold
def test_smooth_stop_brakes_the_slave_and_drops_the_master():
    m = FakeMaster()
    g = geared(m, 1, 1)
    g.start()
    drive(g, m, [50.0, 100.0])
    g.stop(1.0)
    out = drive(g, m, 150.0 + 50 * np.arange(1, 60))
    assert g.done
    assert out[-1, 0] == pytest.approx(100 + 50 * 50 / 2)
    assert g.step() == (g.pos, 0.0, 0.0)


def test_gear_never_ends_by_itself():
    m = FakeMaster()
    g = geared(m, 1, 1)
    g.start()
    drive(g, m, np.zeros(100))
    assert g.moving and not g.done


# ---------------------------------------------------- return 1 / return 7
def test_gear_start_needs_master_and_ratio():
    """Entry 24 return 1: (2) master not set, (3) ratio not set."""
    g = GearPlanner(profile=2)
    with pytest.raises(CommandError, match="no master"):
        g.start()
    g.set_master(1)
    with pytest.raises(CommandError, match="no gear ratio"):
        g.start()
    g.set_ratio(1, 1)
    with pytest.raises(CommandError, match="source"):
        g.start()
    g.bind_master(FakeMaster())
    g.start()
    with pytest.raises(CommandError, match="moving"):
        g.start()


def test_master_and_mode_cannot_change_while_moving():
    """Entry 110 (1), entry 87 (1)/(2)."""
    m = FakeMaster()
    g = geared(m)
    assert g.master == MasterSpec(1, MasterType.PROFILE, MasterItem.PROFILE)
    with pytest.raises(CommandError, match="dir 0, not 1"):
        g.set_direction(1)
    g.set_direction(0)
    g.start()
    with pytest.raises(CommandError, match="moving"):
        g.set_master(3, MasterType.AXIS, 1)
    with pytest.raises(CommandError, match="moving"):
        g.set_direction(0)
    g.stop(1000.0, abrupt=True)
    drive(g, m, [0.0])
    g.set_master(3, MasterType.AXIS, 1)
    assert g.master == MasterSpec(3, MasterType.AXIS, MasterItem.ENCODER)


@pytest.mark.parametrize(
    "call",
    [
        lambda g: g.set_ratio(0, 1, 0),  # masterEven must be positive
        lambda g: g.set_ratio(-2, 1, 0),
        lambda g: g.set_ratio(2, 1, 1),  # masterSlope may not be 1
        lambda g: g.set_ratio(2, 1, -10),  # nor < 0
        lambda g: g.set_ratio(2.5, 1, 0),
        lambda g: g.set_master(2),  # master = the slave itself
        lambda g: g.set_master(0),
        lambda g: g.set_master(1, 4),
        lambda g: g.set_master(1, MasterType.AXIS, 2),
        lambda g: GearPlanner(dir=2),
    ],
)
def test_parameter_errors_return_7(call):
    g = GearPlanner(profile=2)
    with pytest.raises(ParameterError):
        call(g)
