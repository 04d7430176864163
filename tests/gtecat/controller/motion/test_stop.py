"""Stop ramps (manual 9.4, GT_Stop, GT_SetStopDec ranges and table 4-4 defaults)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.controller.motion import StopDecel, StopRamp, stop_distance
from gtecat.errors import ParameterError
from tests.conftest import examples


def test_defaults_are_table_4_4():
    """Table 4-4: smooth stop 1 pulse/ms², emergency stop 1000 pulse/ms²."""
    d = StopDecel()
    assert (d.smooth, d.abrupt) == (1.0, 1000.0)
    assert d.for_kind(abrupt=False) == 1.0 and d.for_kind(abrupt=True) == 1000.0


@pytest.mark.parametrize(
    "smooth,abrupt", [(0.0, 1.0), (1.0, 0.0), (32767.5, 1.0), (1.0, -3.0), (float("nan"), 1.0)]
)
def test_gt_set_stop_dec_range(smooth, abrupt):
    """GT_SetStopDec: both decelerations in (0, 32767]."""
    with pytest.raises(ParameterError):
        StopDecel(smooth, abrupt)


def test_upper_bound_is_accepted():
    assert StopDecel(32767, 32767).abrupt == 32767.0


def test_ramp_is_the_closed_form_braking_parabola():
    r = StopRamp(1.0)
    r.start(100.0, -10.0, 0.5)
    out = []
    while not r.done:
        out.append(r.step())
    out = np.array(out)
    t = np.arange(1, len(out) + 1, dtype=float)
    assert len(out) == 20
    np.testing.assert_allclose(out[:-1, 0], (100.0 - 10.0 * t + 0.25 * t**2)[:-1])
    np.testing.assert_allclose(out[:-1, 1], (-10.0 + 0.5 * t)[:-1])
    assert tuple(out[-1]) == (100.0 - 100.0, 0.0, 0.0)
    assert np.all(out[:-1, 2] == 0.5)


def test_abrupt_stop_inside_one_cycle():
    r = StopRamp(1.0)
    r.start(0.0, 50.0, 1000.0)
    assert r.step() == (1.25, 0.0, 0.0) and r.done


def test_standing_still_is_done_at_once():
    r = StopRamp(0.5)
    r.start(3.5, 0.0, 1.0)
    assert r.done and r.step() == (3.5, 0.0, 0.0)


@pytest.mark.parametrize("dec", [0.0, -1.0, float("inf")])
def test_bad_deceleration(dec):
    with pytest.raises(ParameterError):
        StopRamp().start(0.0, 1.0, dec)


@settings(max_examples=examples(80, 20), deadline=None)
@given(
    # speeds a controller can hold: zero, or at least 1e-9 pulse/ms (denormals underflow
    # in the formula itself)
    v=st.one_of(st.just(0.0), st.floats(1e-9, 500), st.floats(-500, -1e-9)),
    dec=st.floats(0.1, 2000),
    cycle=st.sampled_from([0.25, 1.0, 2.0]),
)
def test_random_ramps_stop_where_and_when_the_formula_says(v, dec, cycle):
    r = StopRamp(cycle)
    r.start(10.0, v, dec)
    out = []
    while not r.done:
        out.append(r.step())
        assert len(out) <= 200_000
    assert len(out) == (math.ceil(abs(v) / (dec * cycle)) if v else 0)
    assert r.end_pos == pytest.approx(10.0 + stop_distance(v, dec))
    if out:
        out = np.array(out)
        assert out[-1, 0] == r.end_pos and out[-1, 1] == 0.0
        assert np.all(np.abs(out[:, 1]) <= abs(v)) and np.all(out[:, 1] * v >= 0)
