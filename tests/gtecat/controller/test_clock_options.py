"""GT_Open's clock options, checked once (gtecat.controller.clock_options): every legal value
gives the nanoseconds it says, every other one a ParameterError naming the option, the value
and the legal range."""

from __future__ import annotations

import math
from decimal import Decimal
from fractions import Fraction

import pytest
from hypothesis import given
from hypothesis import strategies as st

from gtecat.controller import clock_options as co
from gtecat.controller.core import Options
from gtecat.eni.limits import CYCLE_NS
from gtecat.errors import ParameterError

LO_MS, HI_MS = CYCLE_NS.lo / 1e6, CYCLE_NS.hi / 1e6


def refused(fn, value, name: str, legal: str) -> str:
    with pytest.raises(ParameterError) as e:
        fn(value)
    text = str(e.value)
    assert text.startswith(f"{name}=") and f"legal is {legal}" in text, text
    return text


# --- cycle_ms -------------------------------------------------------------------------------
def test_the_cycle_range_is_the_eni_readers():
    """The same numbers as the ENI reader's CycleTime check, read from the one place."""
    assert co.CYCLE_MS_TEXT.startswith("0.03125..1000 ms")
    assert "31.25 us to 1 s" in co.CYCLE_MS_TEXT
    assert co.cycle_ns(LO_MS) == CYCLE_NS.lo and co.cycle_ns(HI_MS) == CYCLE_NS.hi
    assert co.cycle_ns(None) is None  # not given: the ENI's cycle, else 1 ms


@given(st.floats(min_value=LO_MS, max_value=HI_MS))
def test_a_legal_cycle_gives_its_nanoseconds(ms: float):
    ns = co.cycle_ns(ms)
    assert CYCLE_NS.lo <= ns <= CYCLE_NS.hi
    assert abs(ns - ms * 1e6) <= 0.5 + 1e-6 * ms


@given(
    st.one_of(
        st.floats(max_value=LO_MS, exclude_max=True),
        st.floats(min_value=HI_MS, exclude_min=True),
        st.integers(max_value=0),
        st.integers(min_value=1001),
    )
)
def test_a_cycle_out_of_range_is_refused(ms: float):
    text = refused(co.cycle_ns, ms, "cycle_ms", co.CYCLE_MS_TEXT)
    assert "out of range" in text or "not a number" in text  # (NaN: not a number)


@given(st.one_of(st.booleans(), st.text(max_size=5), st.lists(st.integers(), max_size=2)))
def test_what_is_no_number_is_no_cycle(v: object):
    text = refused(co.cycle_ns, v, "cycle_ms", co.CYCLE_MS_TEXT)
    assert "is not a number of milliseconds" in text


@pytest.mark.parametrize(
    "ms",
    [0, -1, 1e-9, 4e-7, 6e-7, "1", math.nan, math.inf, -math.inf, 1e20, 2**64, 1e9, True],
)
def test_the_outside_checks_cycles_are_refused(ms: object):
    refused(co.cycle_ns, ms, "cycle_ms", co.CYCLE_MS_TEXT)


def test_other_real_numbers_are_numbers():
    assert co.cycle_ns(Fraction(1, 2)) == 500_000
    assert co.call_latency_ns(Fraction(3, 2)) == 1500
    with pytest.raises(ParameterError, match="out of range"):
        co.cycle_ns(Fraction(10**400, 3))  # (beyond any float)
    assert co.cycle_ns(Decimal("0.5")) == 500_000
    with pytest.raises(ParameterError, match="not a number"):
        co.cycle_ns(Decimal("sNaN"))


def test_a_huge_value_is_shown_short():
    text = refused(co.cycle_ns, 7**9000, "cycle_ms", co.CYCLE_MS_TEXT)
    assert "characters)" in text and len(text) < 300


# --- call_latency_us ------------------------------------------------------------------------
@given(st.floats(min_value=0.001, max_value=1e6))
def test_a_legal_latency_gives_its_nanoseconds(us: float):
    ns = co.call_latency_ns(us)
    assert 1 <= ns <= co.MAX_CALL_LATENCY_NS
    assert abs(ns - us * 1000) <= 0.5 + 1e-9 * us


@given(
    st.one_of(
        st.floats(max_value=0, exclude_max=True),
        st.floats(min_value=0, max_value=0.001, exclude_min=True, exclude_max=True),
        st.floats(min_value=1e6, exclude_min=True),
        st.integers(max_value=-1),
        st.integers(min_value=10**6 + 1),
    )
)
def test_a_latency_out_of_range_is_refused(us: float):
    refused(co.call_latency_ns, us, "call_latency_us", co.CALL_LATENCY_US_TEXT)


@pytest.mark.parametrize(
    "us", ["abc", "50", None, [1], math.nan, math.inf, 1e30, 2**70, -5, -1e-3, 9.2e12, True]
)
def test_the_outside_checks_latencies_are_refused(us: object):
    refused(co.call_latency_ns, us, "call_latency_us", co.CALL_LATENCY_US_TEXT)


def test_zero_latency_is_legal():
    """0: calls cost no controller time (it moves only by waits, as in lockstep)."""
    assert co.call_latency_ns(0) == 0 and co.call_latency_ns(-0.0) == 0


def test_check_gives_plain_floats_and_refuses_the_first_bad_one():
    o = co.check(Options(cycle_ms=Fraction(1, 4), call_latency_us=20))
    assert o.cycle_ms == 0.25 and type(o.cycle_ms) is float
    assert o.call_latency_us == 20.0 and type(o.call_latency_us) is float
    assert co.check(Options()).cycle_ms is None
    with pytest.raises(ParameterError, match="cycle_ms=0 "):
        co.check(Options(cycle_ms=0, call_latency_us=-1))


def test_the_reference_states_the_ranges():
    from tests.conftest import ROOT

    text = (ROOT / "docs" / "reference" / "config-files.md").read_text(encoding="utf-8")
    cyc = co.CYCLE_MS_TEXT.split(" ms")[0]  # 0.03125..1000
    lat = co.CALL_LATENCY_US_TEXT.split(" us")[0].removeprefix("0 or ")  # 0.001..1000000
    assert "| `cycle_ms` |" in text and f"| {cyc} (" in text
    assert "| `call_latency_us` |" in text and f"or {lat} (" in text
