"""Cycle statistics maths and SOEM's bit packing, as properties."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from gtecat.master.backends.cycle_stats import (
    cycle_stats,
    nearest_rank,
    summarize_periods,
    summarize_values,
)
from gtecat.master.backends.pysoem_backend import BusStats, soem_bit_starts
from tests.conftest import EXAMPLES

periods = st.lists(st.integers(min_value=0, max_value=50_000_000), min_size=1, max_size=300)


@given(periods, st.integers(min_value=1, max_value=10_000_000))
def test_jitter_percentiles_are_ordered_real_samples(p, nominal):
    s = summarize_periods(p, nominal)
    jitter = {abs(x - nominal) for x in p}
    assert s.samples == len(p)
    assert 0 <= s.jitter_p50_ns <= s.jitter_p99_ns <= s.jitter_max_ns
    assert {s.jitter_p50_ns, s.jitter_p99_ns, s.jitter_max_ns} <= jitter
    assert s.min_ns <= s.mean_ns <= s.max_ns


@given(
    st.lists(st.integers(-1000, 1000), min_size=1, max_size=200),
    st.floats(min_value=0.01, max_value=1.0),
)
def test_nearest_rank_has_at_least_q_of_the_samples_at_or_below(values, q):
    v = np.sort(np.array(values))
    r = nearest_rank(v, q)
    assert np.count_nonzero(v <= r) >= q * len(v)
    assert np.count_nonzero(v < r) < q * len(v)


def test_known_values():
    s = summarize_periods([1_000_000] * 98 + [1_500_000, 3_000_000], 1_000_000)
    assert (s.jitter_p50_ns, s.jitter_p99_ns, s.jitter_max_ns) == (0, 500_000, 2_000_000)
    assert summarize_values([]) == {"samples": 0, "p50_ns": 0, "p99_ns": 0, "max_ns": 0}
    with pytest.raises(ValueError):
        summarize_periods([1], 0)


def _soem_packing(bits: list[int]) -> list[tuple[int, int] | None]:
    """SOEM's legacy mapping for one direction, written out: (first byte, start bit)."""
    addr, pos, out = 0, 0, []
    for b in bits:
        if b <= 0:
            out.append(None)
        elif b < 8:
            out.append((addr, pos))
            pos += b
            addr, pos = addr + pos // 8, pos % 8
        else:
            if pos:
                addr, pos = addr + 1, 0
            out.append((addr, 0))
            addr += (b + 7) // 8
    return out


@given(st.lists(st.integers(min_value=0, max_value=40), max_size=30))
def test_bit_starts_match_soem_and_flag_byte_straddling(bits):
    ours = soem_bit_starts(bits)
    for b, got, ref in zip(bits, ours, _soem_packing(bits), strict=True):
        if b == 0 or b > 7:
            assert got is None
        else:
            assert ref is not None and got is not None
            assert got[0] == ref[1]
            assert got[1] == (ref[1] + b > 8)


def test_bus_stats_ring_keeps_the_latest():
    s = BusStats(rtt_ns=np.zeros(4, dtype=np.int64))
    for k in range(6):
        s.add_rtt(k)
    assert sorted(s.rtt_samples().tolist()) == [2, 3, 4, 5]


def test_cycle_stats_of_an_emulated_controller_has_no_bus_part():
    from gtecat import gt

    gt.GT_Close()
    eni = str(EXAMPLES / "manual_fig5_2.eni")
    assert gt.GT_Open(eni=eni, clock="lockstep", log="") == 0
    try:
        gt.GT_InitEcatComm()
        gt.GTE_Wait(5)
        s = cycle_stats(gt.GTE_Controller())
        assert s["clock"] == "lockstep" and s["cycles"] == 5 and s["period"] is None
        assert s["bus"] is None and s["overruns"] == 0
    finally:
        gt.GT_Close()
