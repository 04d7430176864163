"""Segment geometry and the vector speed trapezoid against closed forms (issue 19 item 3)."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from gtecat.controller.crd import Trapezoid, arc_center, make_arc
from gtecat.controller.crd.path import CCW, CW, Line
from gtecat.errors import ParameterError


def test_trapezoid_reaching_cruise_has_the_closed_form_time():
    # rest to rest: t = L/v + v/a
    tz = Trapezoid(10_000.0, 0.0, 50.0, 0.0, 0.5)
    assert tz.duration == pytest.approx(10_000 / 50 + 50 / 0.5)
    assert tz.s(100.0) == pytest.approx(0.5 * 0.5 * 100**2)
    assert tz.s(tz.duration) == 10_000.0
    assert tz.v(150.0) == 50.0


def test_triangle_when_too_short():
    tz = Trapezoid(1000.0, 0.0, 100.0, 0.0, 1.0)
    assert tz.vp == pytest.approx(math.sqrt(1000.0))
    assert tz.duration == pytest.approx(2 * math.sqrt(1000.0))


def test_even_time_lowers_the_peak_so_the_cruise_lasts():
    tz = Trapezoid(1000.0, 0.0, 100.0, 0.0, 1.0, even_time=10.0)
    assert tz.tc == pytest.approx(10.0)
    assert tz.vp * tz.vp / 1.0 + tz.vp * 10.0 == pytest.approx(1000.0)


def test_exit_speed_not_reachable_ends_at_what_it_reached():
    tz = Trapezoid(100.0, 0.0, 100.0, 50.0, 1.0)
    assert tz.v_end == pytest.approx(math.sqrt(200.0))
    assert tz.s(tz.duration) == 100.0


@given(
    length=st.floats(1.0, 1e6),
    v0=st.floats(0.0, 50.0),
    ve=st.floats(0.0, 50.0),
    vmax=st.floats(1.0, 100.0),
    acc=st.floats(0.01, 10.0),
    even=st.floats(0.0, 20.0),
)
def test_trapezoid_properties(length, v0, ve, vmax, acc, even):
    v0 = min(v0, vmax)
    tz = Trapezoid(length, v0, vmax, ve, acc, even)
    assert tz.vp <= vmax * (1 + 1e-12) + 1e-12 or tz.vp <= max(v0, ve)
    assert tz.s(tz.duration) == length
    n = 200
    last = 0.0
    for k in range(n + 1):
        t = tz.duration * k / n
        s = tz.s(t)
        assert s >= last - 1e-7 * length
        last = s
        assert tz.v(t) <= max(vmax, v0) * (1 + 1e-9) + 1e-9


def test_line_points_and_exact_end():
    ln = Line((0.0, 0.0), (3.0, 4.0))
    assert ln.length == 5.0
    assert ln.point(2.5) == (1.5, 2.0)
    assert ln.point(5.0) == (3.0, 4.0)
    assert ln.point(7.0) == (3.0, 4.0)


@pytest.mark.parametrize("direction", [CW, CCW])
@pytest.mark.parametrize("radius", [5000.0, -5000.0])
def test_arc_by_radius_centre_and_sweep(direction, radius):
    start, end = (0.0, 0.0), (6000.0, 0.0)
    c = arc_center(start, end, (0, 1), radius, direction)
    assert math.hypot(c[0], c[1]) == pytest.approx(5000.0)
    arc = make_arc(start, end, c, (0, 1), direction)
    minor = abs(arc.sweep) < math.pi
    assert minor == (radius > 0)
    assert (arc.sweep > 0) == (direction == CCW)
    assert arc.point(arc.length) == end
    for k in range(101):
        p = arc.point(arc.length * k / 100)
        assert math.hypot(p[0] - c[0], p[1] - c[1]) == pytest.approx(5000.0, abs=1e-6)


def test_full_circle_by_centre_and_errors():
    arc = make_arc((0.0, 0.0), (0.0, 0.0), (1000.0, 0.0), (0, 1), CCW)
    assert arc.sweep == pytest.approx(2 * math.pi)
    assert arc.length == pytest.approx(2 * math.pi * 1000)
    with pytest.raises(ParameterError):
        make_arc((0.0, 0.0), (5.0, 0.0), (1000.0, 0.0), (0, 1), CCW)  # end off the circle
    with pytest.raises(ParameterError):
        arc_center((0.0, 0.0), (10_000.0, 0.0), (0, 1), 100.0, CW)  # chord > diameter


def test_helix_rises_linearly():
    arc = make_arc((1000.0, 0.0, 0.0), (1000.0, 0.0, 600.0), (0.0, 0.0), (0, 1), CCW, axis3=2)
    assert arc.length == pytest.approx(math.hypot(2 * math.pi * 1000, 600))
    p = arc.point(arc.length / 4)
    assert p == pytest.approx((0.0, 1000.0, 150.0), abs=1e-6)
