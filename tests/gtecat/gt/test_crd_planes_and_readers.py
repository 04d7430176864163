"""Coordinated motion in the YZ and ZX planes, helix by radius, rapid lines, buffered moves,
the path speed and the stop decelerations, and the axis velocity/acceleration readers, each
driven through ``gt`` as an application would (vendor header functions of the crd group,
manual table 10-2's neighbours; manual 7.2 for the readers)."""

from __future__ import annotations

import math
from ctypes import byref, c_double, c_int32, c_short

import pytest

from gtecat import gt


def card(dimension: int = 3) -> None:
    """A 4-axis pulse card in lockstep, axes on, a system of ``dimension`` axes 1..n."""
    assert gt.GT_Open(card="gts:4", clock="lockstep", log="") == 0, gt.GTE_GetLastError()
    for a in (1, 2, 3, 4):
        assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(20)
    prm = gt.TCrdPrm()
    prm.dimension, prm.synVelMax, prm.synAccMax = dimension, 50.0, 1.0
    for i in range(dimension):
        prm.profile[i] = i + 1
    assert gt.GT_SetCrdPrm(1, byref(prm)) == 0, gt.GTE_GetLastError()


def prf(axis: int) -> float:
    p = c_double()
    assert gt.GT_GetPrfPos(axis, byref(p)) == 0
    return p.value


def running() -> bool:
    run, seg = c_short(), c_int32()
    assert gt.GT_CrdStatus(1, byref(run), byref(seg)) == 0, gt.GTE_GetLastError()
    return bool(run.value)


def run_to_end(check=None, limit: int = 20_000) -> int:
    assert gt.GT_CrdStart(1, 0) == 0, gt.GTE_GetLastError()
    for n in range(limit):
        gt.GTE_Wait(1)
        if check is not None:
            check()
        if not running():
            return n
    raise AssertionError("the path never ended")


@pytest.mark.parametrize(
    ("fn", "plane", "still"),
    [("GT_ArcYZC", (2, 3), 1), ("GT_ArcZXC", (3, 1), 2)],
)
def test_arc_by_centre_in_the_other_planes_stays_on_its_circle(fn, plane, still):
    """A half circle of radius 1000 about (1000, 0) from the start, in the plane's own order
    (YZ: y then z; ZX: z then x); the third axis does not move."""
    card()
    assert getattr(gt, fn)(1, 2000, 0, 1000.0, 0.0, 0, 20.0, 0.5) == 0, gt.GTE_GetLastError()
    u, v = plane

    def on_circle() -> None:
        assert abs(math.hypot(prf(u) - 1000, prf(v)) - 1000) <= 0.5
        assert prf(still) == 0.0

    run_to_end(on_circle)
    assert (prf(u), prf(v)) == (2000.0, 0.0)


@pytest.mark.parametrize(("fn", "plane"), [("GT_ArcYZR", (2, 3)), ("GT_ArcZXR", (3, 1))])
def test_arc_by_radius_in_the_other_planes_ends_exactly(fn, plane):
    card()
    assert getattr(gt, fn)(1, 1000, 1000, 1000.0, 1, 20.0, 0.5) == 0, gt.GTE_GetLastError()
    u, v = plane

    def on_a_circle() -> None:  # one of the two centres the radius allows
        x, y = prf(u), prf(v)
        assert min(abs(math.hypot(x - 1000, y) - 1000), abs(math.hypot(x, y - 1000) - 1000)) < 1

    run_to_end(on_a_circle)
    assert (prf(u), prf(v)) == (1000.0, 1000.0)


def test_helix_by_radius_and_a_rapid_line():
    card()
    assert gt.GT_HelixXYRZ(1, 2000, 0, 500, 1000.0, 0, 20.0, 0.5) == 0, gt.GTE_GetLastError()
    assert gt.GT_LnXYG0(1, 0, 0, 40.0, 1.0) == 0, gt.GTE_GetLastError()
    speeds = []

    def path_speed() -> None:
        v = c_double()
        assert gt.GT_GetCrdVel(1, byref(v)) == 0, gt.GTE_GetLastError()
        speeds.append(v.value)

    run_to_end(path_speed)
    assert (prf(1), prf(2), prf(3)) == (0.0, 0.0, 500.0)
    assert 0 < max(speeds) <= 40.0 + 1e-9  # the rapid line's synVel is the fastest
    v = c_double()
    assert gt.GT_GetCrdVel(1, byref(v)) == 0 and v.value == 0.0  # standing


def test_a_four_axis_line_ends_on_every_axis():
    card(dimension=4)
    assert gt.GT_LnXYZA(1, 1000, -2000, 3000, 400, 30.0, 1.0) == 0, gt.GTE_GetLastError()
    steps = []

    def on_the_line() -> None:  # every axis the same fraction of its way
        f = prf(3) / 3000
        steps.append(f)
        assert prf(1) == pytest.approx(1000 * f, abs=1e-6)
        assert prf(2) == pytest.approx(-2000 * f, abs=1e-6)
        assert prf(4) == pytest.approx(400 * f, abs=1e-6)

    run_to_end(on_the_line)
    assert [prf(a) for a in (1, 2, 3, 4)] == [1000.0, -2000.0, 3000.0, 400.0]
    assert steps == sorted(steps)  # forward only


def test_buffered_move_of_an_axis_outside_the_system():
    card(dimension=2)
    assert gt.GT_LnXY(1, 1000, 0, 20.0, 0.5) == 0
    assert gt.GT_BufMove(1, 4, 3000, 10.0, 0.5, 1) == 0, gt.GTE_GetLastError()  # modal
    assert gt.GT_LnXY(1, 1000, 1000, 20.0, 0.5) == 0
    run_to_end()
    assert (prf(1), prf(2), prf(4)) == (1000.0, 1000.0, 3000.0)
    assert gt.GT_BufMove(1, 1, 0, 10.0, 0.5, 0) == 7  # axis 1 belongs to the system
    assert "belongs to coordinate system 1" in gt.GTE_GetLastError()


def test_crd_stop_decelerations_round_trip():
    card(dimension=2)
    assert gt.GT_SetCrdStopDec(1, 0.5, 2.0) == 0, gt.GTE_GetLastError()
    smooth, abrupt = c_double(), c_double()
    assert gt.GT_GetCrdStopDec(1, byref(smooth), byref(abrupt)) == 0
    assert (smooth.value, abrupt.value) == (0.5, 2.0)


def test_axis_velocity_and_acceleration_readers_on_a_jog():
    """Manual 7.2: GT_GetAxisPrfVel/Acc are the planned ones, GT_GetAxisEncVel/Acc the
    encoder's (a pulse card's encoder follows the pulses)."""
    card(dimension=2)
    jog = gt.TJogPrm()
    jog.acc, jog.dec = 0.5, 0.5
    assert gt.GT_PrfJog(4) == 0 and gt.GT_SetJogPrm(4, byref(jog)) == 0
    assert gt.GT_SetVel(4, 10.0) == 0 and gt.GT_Update(1 << 3) == 0
    gt.GTE_Wait(5)
    vel, acc = c_double(), c_double()
    assert gt.GT_GetAxisPrfVel(4, byref(vel)) == 0 and 0 < vel.value < 10.0
    assert gt.GT_GetAxisPrfAcc(4, byref(acc)) == 0 and acc.value == pytest.approx(0.5)
    gt.GTE_Wait(100)
    assert gt.GT_GetAxisPrfVel(4, byref(vel)) == 0 and vel.value == pytest.approx(10.0)
    assert gt.GT_GetAxisPrfAcc(4, byref(acc)) == 0 and acc.value == pytest.approx(0.0)
    assert gt.GT_GetAxisEncVel(4, byref(vel)) == 0 and vel.value == pytest.approx(10.0, abs=1.0)
    assert gt.GT_GetAxisEncAcc(4, byref(acc)) == 0 and abs(acc.value) < 1.0
