"""The axis bank and the emulated bus keep what follows from a claimed pattern (which drives
the bank runs) per pattern, for the few patterns an application goes back and forth between.
Their memory is a budget of rows, not of patterns: a large bus switched on axis by axis makes
a pattern per axis, and 256 kept patterns of 1,024 rows cost ~25 kB per axis at the peak
(the memory-per-axis figure of docs/performance.md)."""

from __future__ import annotations

from ctypes import byref, c_long
from pathlib import Path

from gtecat import gt
from tests.gtecat.gt.conftest import bring_up
from tools.gen_axes_eni import write_axes_eni

N = 160  # (a budget of 16,384 rows keeps 102 patterns of 160: more are made below)


def _core_axis(a: int) -> tuple[int, int]:
    return (a - 1) // 32 + 1, (a - 1) % 32 + 1


def test_patterns_kept_within_a_budget_of_rows(tmp_path: Path) -> None:
    bring_up(str(write_axes_eni(N, tmp_path / "bus.eni")), clock="lockstep")
    try:
        ctl = gt.GTE_Controller()
        bank, backend = ctl.bank, ctl.backend
        budget = bank._patterns_kept
        assert budget == 16_384 // N
        most = most_bus = 0
        for a in range(1, N + 1):  # a new claimed pattern at each axis
            assert gt.GTN_AxisOn(*_core_axis(a)) == 0
            assert gt.GTE_Wait(2) == 0
            most = max(most, len(bank._claimed_sets))
            most_bus = max(most_bus, len(backend._claimed_memo))
        assert most <= budget
        assert most_bus <= budget
        # what a pattern made again after its entry went is right: every axis the bank's,
        # enabled, and the bus answers every slave
        assert bank.n_alive == N
        sts = c_long()
        for a in (1, 77, N):
            assert gt.GTN_GetSts(*_core_axis(a), byref(sts), 1, None) == 0
            assert sts.value & 0x200  # servo on
        assert backend.steady()
    finally:
        gt.GT_Close()
