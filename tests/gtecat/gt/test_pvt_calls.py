"""PVT motion as a dispenser or a pick-and-place head drives it: tables of time, position
and velocity, selected per profile, started together, looped, stopped."""

from __future__ import annotations

from ctypes import byref, c_double, c_long, c_short

from gtecat import gt


def arr(*v: float):
    return (c_double * len(v))(*v)


def prf(axis: int) -> float:
    p = c_double()
    assert gt.GT_GetPrfPos(axis, byref(p)) == 0
    return p.value


def vel(axis: int) -> float:
    p = c_double()
    assert gt.GT_GetPrfVel(axis, byref(p)) == 0
    return p.value


def moving(axis: int) -> bool:
    s = c_long()
    assert gt.GT_GetSts(axis, byref(s)) == 0
    return bool(s.value & 1 << 10)


def test_two_profiles_run_their_tables_together():
    assert gt.GT_Open(card="gts:4", clock="lockstep", log="") == 0
    for a in (1, 2, 3):
        assert gt.GT_AxisOn(a) == 0
        assert gt.GT_PrfPvt(a) == 0, gt.GTE_GetLastError()
    t, p, v = arr(0, 200, 400), arr(0, 2000, 4000), arr(0, 15, 0)
    assert gt.GT_PvtTable(1, 3, t, p, v) == 0
    assert gt.GT_PvtTableEx(2, 2, arr(0, 100), arr(0, 1000), arr(0, 0), arr(20, 0)) == 0
    a, b, c = arr(0, 0, 0, 0), arr(0, 0, 0, 0), arr(0, 0, 0, 0)
    tc, pc = arr(0, 100, 200, 300), arr(0, 500, 1500, 2000)
    assert gt.GT_PvtTableComplete(3, 4, tc, pc, a, b, c, 0.0, 0.0) == 0
    assert a[0] == 0.0 and a[3] == 0.0 and a[1] > 0 and c[3] == 0.0
    # the coefficients give the spline's own position at the end of each segment
    for k in range(3):
        h = tc[k + 1] - tc[k]
        assert abs(pc[k] + a[k] * h + b[k] * h * h + c[k] * h**3 - pc[k + 1]) < 1e-6
    assert gt.GT_PvtTableSelect(1, 1) == 0 and gt.GT_PvtTableSelect(2, 3) == 0
    assert gt.GT_PvtTableSelect(3, 2) == 0
    assert gt.GT_SetPvtLoop(1, 2) == 0
    assert gt.GT_PvtStart(0b111) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(200)
    assert abs(prf(1) - 2000.0) < 1e-6 and abs(vel(1) - 15.0) < 1e-6
    table, times = c_short(), arr(0, 0)
    assert gt.GT_PvtStatus(1, byref(table), times, 2) == 0
    assert table.value == 1 and times[0] == 200.0
    mode = c_long()
    assert gt.GT_GetPrfMode(1, byref(mode)) == 0 and mode.value == 6
    while moving(1) or moving(2) or moving(3):
        gt.GTE_Wait(10)
    assert (prf(1), prf(2), prf(3)) == (8000.0, 2000.0, 1000.0)  # axis 1 ran its table twice
    n, loop = c_long(), c_long()
    assert gt.GT_GetPvtLoop(1, byref(n), byref(loop)) == 0 and (n.value, loop.value) == (2, 2)


def test_stop_an_endless_table_and_the_refusals():
    assert gt.GT_Open(card="gts:2", clock="lockstep", log="") == 0
    assert gt.GT_AxisOn(1) == 0 and gt.GT_PrfPvt(1) == 0
    assert gt.GT_PvtStart(1) == 1  # no table selected
    assert gt.GT_PvtTable(5, 3, arr(0, 50, 100), arr(0, 500, 0), arr(0, 0, 0)) == 0
    assert gt.GT_PvtTableSelect(1, 5) == 0 and gt.GT_SetPvtLoop(1, 0) == 0
    assert gt.GT_PvtStart(1) == 0
    gt.GTE_Wait(1000)
    assert moving(1)  # endless
    assert gt.GT_PvtTableSelect(1, 5) == 1  # not while it runs
    assert gt.GT_Stop(1, 0) == 0
    while moving(1):
        gt.GTE_Wait(10)
    assert gt.GT_PvtTable(6, 2, arr(0, 0), arr(0, 1), arr(0, 0)) == 7  # times must rise
    assert gt.GT_PvtTable(33, 2, arr(0, 1), arr(0, 1), arr(0, 0)) == 7
    assert gt.GT_PvtTableClear(5) == 0 and gt.GT_PvtStart(1) == 1
    assert gt.GT_PrfPvt(2) == 0 and gt.GT_PvtStart(0b10) == 1  # axis 2 is off, no table
    assert gt.GT_PrfTrap(1) == 0 and gt.GT_PvtTableSelect(1, 5) == 1  # not in PVT mode


def test_points_too_close_or_too_large_are_7_with_the_reason_not_an_internal_error():
    """Points a nanosecond apart made the spline's acceleration (1/h²) a division by zero
    once h² left the doubles' range; the tables refuse them (module docstring)."""
    assert gt.GT_Open(card="gts:2", clock="lockstep", log="") == 0
    a, b, c = arr(0, 0), arr(0, 0), arr(0, 0)
    tiny = 5e-324  # the smallest double after 0: h * h is 0
    assert gt.GT_PvtTableComplete(1, 2, arr(0, tiny), arr(0, 1), a, b, c, 0.0, 0.0) == 7
    assert "ms or more after" in gt.GTE_GetLastError()
    assert gt.GT_PvtTable(1, 2, arr(0, tiny), arr(0, 1), arr(0, 0)) == 7
    assert gt.GT_PvtTable(1, 2, arr(0, 1), arr(0, 1e300), arr(0, 0)) == 7
    assert "beyond" in gt.GTE_GetLastError()
    # a microsecond apart is a table, and the spline's values are finite
    assert (
        gt.GT_PvtTableComplete(
            1,
            3,
            arr(0, 1e-3, 2e-3),
            arr(0, 1, 0),
            arr(0, 0, 0),
            b3 := arr(0, 0, 0),
            arr(0, 0, 0),
            0.0,
            0.0,
        )
        == 0
    )
    assert all(abs(v) < float("inf") for v in b3)


def test_an_endless_loop_over_a_table_shorter_than_half_a_cycle_is_refused():
    """Such a table's passes never ended a cycle: the controller hung in the cycle after
    GT_PvtStart.  A count of passes ends (all of them within that cycle)."""
    assert gt.GT_Open(card="gts:2", clock="lockstep", log="") == 0
    assert gt.GT_AxisOn(1) == 0 and gt.GT_PrfPvt(1) == 0
    assert gt.GT_PvtTable(1, 2, arr(0, 0.4), arr(0, 7), arr(0, 10)) == 0
    assert gt.GT_PvtTableSelect(1, 1) == 0 and gt.GT_SetPvtLoop(1, 0) == 0
    assert gt.GT_PvtStart(1) == 1
    assert "half a controller cycle" in gt.GTE_GetLastError()
    assert gt.GT_SetPvtLoop(1, 5) == 0 and gt.GT_PvtStart(1) == 0
    assert gt.GT_SetPvtLoop(1, 0) == 1  # (while it runs)
    gt.GTE_Wait(3)
    assert prf(1) == 35.0 and not moving(1)
    done, loop = c_long(), c_long()
    assert gt.GT_GetPvtLoop(1, byref(done), byref(loop)) == 0
    assert (done.value, loop.value) == (5, 5)
    # half a cycle or more: an endless loop runs
    assert gt.GT_PvtTable(2, 2, arr(0, 0.5), arr(0, 7), arr(0, 10)) == 0
    assert gt.GT_PvtTableSelect(1, 2) == 0 and gt.GT_SetPvtLoop(1, 0) == 0
    assert gt.GT_PvtStart(1) == 0
    gt.GTE_Wait(3)
    assert moving(1)


def test_each_core_holds_its_own_tables(tmp_path):
    """Core 2 of a bus of 40 axes (bus axes 33..40) writes its table 1 without touching core
    1's: each core of a multi-core controller holds its own PVT tables."""
    from tools.gen_axes_eni import write_axes_eni

    from .conftest import bring_up

    bring_up(str(write_axes_eni(40, tmp_path / "bus.eni")), clock="lockstep")
    try:
        assert gt.GT_AxisOn(1) == 0 and gt.GTN_AxisOn(2, 1) == 0
        gt.GTE_Wait(10)
        assert gt.GTN_PvtTable(1, 1, 2, arr(0, 100), arr(0, 1000), arr(0, 0)) == 0
        assert gt.GTN_PvtTable(2, 1, 2, arr(0, 100), arr(0, -555), arr(0, 0)) == 0
        for core in (1, 2):
            assert gt.GTN_PrfPvt(core, 1) == 0
            assert gt.GTN_PvtTableSelect(core, 1, 1) == 0
            assert gt.GTN_SetPvtLoop(core, 1, 1) == 0
            assert gt.GTN_PvtStart(core, 1) == 0, gt.GTE_GetLastError()
        gt.GTE_Wait(300)
        ends = []
        for core in (1, 2):
            p = c_double()
            assert gt.GTN_GetPrfPos(core, 1, byref(p), 1, None) == 0
            ends.append(p.value)
        assert ends == [1000.0, -555.0]
        assert gt.GTN_PvtTableClear(2, 1) == 0  # core 2's only
        assert gt.GTN_PvtStart(2, 1) == 1 and gt.GTN_PvtStart(1, 1) == 0
    finally:
        gt.GT_Close()
