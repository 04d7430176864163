"""Equivalent scaling (GT_ProfileScale / GT_EncScale, manual 4.3.1) and its affine link."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from gtecat.controller.scale import AffineLink, Scale
from gtecat.errors import ParameterError

nonzero = st.integers(-32766, 32766).filter(lambda x: x != 0)
positions = st.floats(-1e7, 1e7, allow_nan=False).map(lambda x: round(x, 3))


@st.composite
def scales(draw):
    a = draw(nonzero)
    b = draw(st.integers(-abs(a), abs(a)).filter(lambda x: x != 0))
    return Scale(a, b)


@pytest.mark.parametrize(("a", "b"), [(0, 1), (1, 0), (32767, 1), (1, -32767), (1, 2), (-3, 4)])
def test_out_of_range_or_beta_above_alpha_is_refused(a, b):
    with pytest.raises(ParameterError):
        Scale(a, b)


def test_checked_refuses_non_integers():
    with pytest.raises(ParameterError):
        Scale.checked(1.5, 1)
    assert Scale.checked(4, -2).ratio == -0.5


def test_default_is_the_identity_bit_for_bit():
    link = AffineLink()
    for x in (0.1, 50000.0, -1e-9, 123456.789):
        assert link.axis(x) == x and link.source(x) == x


@given(scales(), scales(), positions, positions)
def test_a_scale_change_never_moves_the_axis(s1, s2, source, later):
    link = AffineLink()
    link.set_scale(s1, source)
    here = link.axis(source)
    link.set_scale(s2, source)
    assert link.axis(source) == pytest.approx(here, abs=1e-6)
    # from there on the axis moves beta/alpha times the source
    assert link.axis(later) - link.axis(source) == pytest.approx(
        (later - source) * s2.beta / s2.alpha, abs=1e-6
    )
    # back to the source through alpha/beta: the axis position's rounding (a few ulp of a
    # position up to 1e7) comes back multiplied by alpha/beta
    lost = 4 * math.ulp(1e7) * abs(s2.alpha / s2.beta)
    assert link.source(link.axis(later)) == pytest.approx(later, abs=1e-5 + lost)


@given(scales(), positions, positions)
def test_anchor_then_synch(s, source, axis):
    link = AffineLink()
    link.set_scale(s, 0.0)
    link.anchor(source, axis)
    assert link.axis(source) == pytest.approx(axis, abs=1e-6)
    link.synch()
    assert link.axis(source) == pytest.approx(source * s.ratio, abs=1e-6)
