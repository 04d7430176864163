"""Coordinated motion through ``from gtecat import gt`` (lockstep clock, issue 19).

A line and an arc pushed with GT_LnXY / GT_ArcXYC are sampled every cycle through
GT_GetPrfPos and checked against independently computed closed forms: on the
line, on the circle (within 0.5 count), the direction of rotation, the vector speed
within synVel, the time of each segment from its trapezoid, the exact end, and
the segment count of GT_CrdStatus.
"""

from __future__ import annotations

import itertools
import math
from ctypes import byref, c_double, c_int32, c_short

import pytest

from gtecat import gt

from .conftest import bring_up

MOVING = 1 << 10


def up(axes=(1, 2), vmax=100.0, amax=2.0, even_time=0) -> None:
    bring_up("manual_fig5_2.eni", clock="lockstep")
    for a in axes:
        assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()
        assert gt.GT_ZeroPos(a, 1) == 0, gt.GTE_GetLastError()
    prm = gt.TCrdPrm()
    prm.dimension = len(axes)
    for c, a in enumerate(axes, 1):
        prm.profile[a - 1] = c
    prm.synVelMax, prm.synAccMax, prm.evenTime = vmax, amax, even_time
    assert gt.GT_SetCrdPrm(1, byref(prm)) == 0, gt.GTE_GetLastError()


def prf(axis: int) -> float:
    p = c_double()
    assert gt.GT_GetPrfPos(axis, byref(p)) == 0
    return p.value


def status(crd: int = 1, fifo: int = 0) -> tuple[int, int]:
    run, seg = c_short(), c_int32()
    assert gt.GT_CrdStatus(crd, byref(run), byref(seg), fifo) == 0, gt.GTE_GetLastError()
    return run.value, seg.value


def run_path(limit: int = 100_000) -> list[tuple[float, float, int]]:
    """(x, y, segments done) after every cycle until the system stands."""
    rows = []
    assert gt.GT_CrdStart(1, 0) == 0, gt.GTE_GetLastError()
    for _ in range(limit):
        gt.GTE_Wait(1)
        run, seg = status()
        rows.append((prf(1), prf(2), seg))
        if not run:
            return rows
    raise AssertionError("the path never ended")


def speeds(rows) -> list[float]:
    return [math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in itertools.pairwise(rows)]


@pytest.mark.long
def test_line_on_the_line_within_synvel_exact_end_closed_form_time():
    up()
    x1, y1, v, a = 30_000, -12_000, 40.0, 0.5
    assert gt.GT_LnXY(1, x1, y1, v, a) == 0, gt.GTE_GetLastError()
    rows = run_path()
    L = math.hypot(x1, y1)
    for x, y, _ in rows:
        assert abs(x * y1 - y * x1) / L < 1e-6  # distance from the line
        assert -1e-9 <= (x * x1 + y * y1) / L <= L + 1e-9
    sp = speeds([(0.0, 0.0, 0), *rows])
    assert max(sp) <= v + 1e-9
    assert max(sp) == pytest.approx(v)
    assert rows[-1][:2] == (x1, y1)  # exactly the target
    assert status() == (0, 1)
    t_closed = L / v + v / a  # rest to rest trapezoid reaching synVel
    assert len(rows) == math.ceil(t_closed)
    pos = (c_double * 2)()
    assert gt.GT_GetCrdPos(1, pos) == 0
    assert list(pos) == [x1, y1]


@pytest.mark.parametrize("direction", [0, 1])
@pytest.mark.long
def test_arc_by_centre_on_the_circle_and_turning_the_right_way(direction):
    up()
    # half circle from (0, 0) to (20000, 0) around (10000, 0) (centre relative to the start)
    r, v, a = 10_000.0, 30.0, 0.4
    assert gt.GT_ArcXYC(1, 20_000, 0, r, 0.0, direction, v, a) == 0, gt.GTE_GetLastError()
    rows = run_path()
    cx, cy = r, 0.0
    for x, y, _ in rows:
        assert abs(math.hypot(x - cx, y - cy) - r) <= 0.5
        # the rounded command (607Ah) is within a count of the circle as well
        assert abs(math.hypot(round(x) - cx, round(y) - cy) - r) <= 1.0
    # clockwise from (0, 0) around (r, 0) goes up (y > 0), counter-clockwise down
    mid = rows[len(rows) // 2]
    assert (mid[1] > 0) == (direction == 0)
    angles = [math.atan2(y - cy, x - cx) for x, y, _ in rows[:-1]]
    turns = [math.remainder(b - a_, 2 * math.pi) for a_, b in itertools.pairwise(angles)]
    assert all((t > 0) == (direction == 1) for t in turns if abs(t) > 1e-12)
    assert max(speeds([(0.0, 0.0, 0), *rows])) <= v + 1e-6
    assert rows[-1][:2] == (20_000.0, 0.0)
    L = math.pi * r
    assert len(rows) == math.ceil(L / v + v / a)
    assert status() == (0, 1)


def test_line_then_arc_counts_segments_and_keeps_speed_through_velend():
    up()
    v, a = 20.0, 0.5
    assert gt.GT_LnXY(1, 10_000, 0, v, a, v) == 0  # velEnd = synVel: no stop at the joint
    assert gt.GT_ArcXYC(1, 10_000, 10_000, 0.0, 5_000.0, 1, v, a) == 0  # ccw half circle
    space = c_int32()
    assert gt.GT_CrdSpace(1, byref(space)) == 0 and space.value == gt.CRD_FIFO_MAX - 2
    rows = run_path()
    seg = [s for _, _, s in rows]
    first_done = seg.index(1)
    assert rows[-1][:2] == (10_000.0, 10_000.0) and seg[-1] == 2
    sp = speeds([(0.0, 0.0, 0), *rows])
    assert min(sp[first_done - 5 : first_done + 5]) == pytest.approx(v, rel=1e-3)
    for x, y, _s in rows[first_done + 1 :]:
        assert abs(math.hypot(x - 10_000, y - 5_000) - 5_000) <= 0.5
    # total time: one trapezoid over both lengths (the joint at full speed)
    total = 10_000 + math.pi * 5_000
    assert len(rows) == math.ceil(total / v + v / a)


@pytest.mark.long
def test_look_ahead_slows_a_right_angle_to_the_corner_limit():
    up(vmax=100.0, amax=1.0)
    t_corner, acc_max = 2.0, 1.0
    assert gt.GT_InitLookAhead(1, 0, t_corner, acc_max, 8, None) == 0, gt.GTE_GetLastError()
    assert gt.GT_LnXY(1, 20_000, 0, 50.0, 1.0) == 0
    assert gt.GT_LnXY(1, 20_000, 20_000, 50.0, 1.0) == 0
    rows = run_path()
    seg = [s for _, _, s in rows]
    k = seg.index(1)
    v_corner = acc_max * t_corner / math.sqrt(2.0)  # |t2 - t1| = sqrt(2) at 90°
    sp = speeds([(0.0, 0.0, 0), *rows])
    assert min(sp[k - 3 : k + 3]) == pytest.approx(v_corner, abs=0.5)
    assert sp[k - 20] > v_corner
    assert rows[-1][:2] == (20_000.0, 20_000.0)


def test_stop_of_one_axis_stops_the_system_along_its_path():
    up()
    assert gt.GT_SetCrdStopDec(1, 0.5, 5.0) == 0
    assert gt.GT_LnXY(1, 40_000, 30_000, 50.0, 1.0) == 0
    assert gt.GT_LnXY(1, 0, 0, 50.0, 1.0) == 0
    assert gt.GT_CrdStart(1, 0) == 0
    gt.GTE_Wait(300)
    assert gt.GT_Stop(1 << 1, 0) == 0  # a smooth stop of axis 2 only
    rows = []
    for _ in range(1000):
        gt.GTE_Wait(1)
        rows.append((prf(1), prf(2)))
        if not status()[0]:
            break
    assert status()[0] == 0
    for x, y in rows:
        assert abs(x * 30_000 - y * 40_000) / 50_000 < 1e-6
    sp = speeds(rows)
    assert all(b <= a + 1e-9 for a, b in itertools.pairwise(sp))
    assert len(rows) == pytest.approx(50.0 / 0.5, abs=2)
    for axis in (1, 2):
        sts = c_int32()
        gt.GT_GetSts(axis, byref(sts))
        assert not sts.value & MOVING


@pytest.mark.parametrize(("option", "dec"), [(0, 0.5), (1 << 12, 5.0)])
def test_gt_stop_mask_bit_12_stops_coordinate_system_1(option, dec):
    """Manual entry 131: mask bit 12 is coordinate system 1; the same option bit picks the
    abrupt deceleration (GT_SetCrdStopDec), clear the smooth one."""
    up()
    assert gt.GT_SetCrdStopDec(1, 0.5, 5.0) == 0
    assert gt.GT_LnXY(1, 40_000, 30_000, 50.0, 1.0) == 0
    assert gt.GT_CrdStart(1, 0) == 0
    gt.GTE_Wait(300)  # cruising at 50 pulse/ms
    assert gt.GT_Stop(1 << 13, 0) == 0  # coordinate system 2 only: this one keeps going
    gt.GTE_Wait(1)
    assert status()[0] == 1
    assert gt.GT_Stop(1 << 12, option) == 0
    rows = []
    for _ in range(1000):
        gt.GTE_Wait(1)
        rows.append((prf(1), prf(2)))
        if not status()[0]:
            break
    assert status() == (0, 0)  # stopped before the end of its only segment
    assert len(rows) == pytest.approx(50.0 / dec, abs=2)
    for x, y in rows:
        assert abs(x * 30_000 - y * 40_000) / 50_000 < 1e-6
    assert math.hypot(*rows[-1]) < 50_000


def test_errors():
    up()
    assert gt.GT_CrdStart(1, 0) == 1  # empty FIFO
    assert gt.GT_LnXYZ(1, 1, 2, 3, 10.0, 1.0) == 7  # 2-D system
    assert gt.GT_LnXY(1, 1, 2, 0.0, 1.0) == 7
    assert gt.GT_ArcXYR(1, 10_000, 0, 100.0, 0, 10.0, 1.0) == 7  # chord > diameter
    assert gt.GT_LnXY(3, 1, 2, 10.0, 1.0) == 7
    assert gt.GT_LnXY(2, 1, 2, 10.0, 1.0) == 1  # crd 2 has no parameters
    prm = gt.TCrdPrm()
    prm.dimension, prm.synVelMax, prm.synAccMax = 2, 10.0, 1.0
    prm.profile[0] = 1  # Y unmapped
    assert gt.GT_SetCrdPrm(2, byref(prm)) == 7
    back = gt.TCrdPrm()
    assert gt.GT_GetCrdPrm(1, byref(back)) == 0
    assert back.dimension == 2 and list(back.profile)[:3] == [1, 2, 0]
    assert gt.GTN_LnXY(1, 1, 100, 0, 10.0, 1.0) == 0
    assert gt.GT_CrdClear(1, 0) == 0
    assert gt.GT_CrdStart(1, 0) == 1


def test_buffered_delay_io_and_override():
    up()
    assert gt.GT_LnXY(1, 1000, 0, 10.0, 1.0) == 0
    assert gt.GT_BufIO(1, 12, 0x3, 0x1) == 0
    assert gt.GT_BufDelay(1, 50) == 0
    assert gt.GT_LnXY(1, 2000, 0, 10.0, 1.0) == 0
    assert gt.GT_SetOverride(1, 0.5) == 0
    rows = run_path()
    assert rows[-1][:2] == (2000.0, 0.0) and rows[-1][2] == 4
    assert max(speeds([(0.0, 0.0, 0), *rows])) <= 5.0 + 1e-9
    # two rest-to-rest lines at half speed (acc a quarter) plus the delay
    one = 1000 / 5.0 + 5.0 / 0.25
    assert len(rows) == pytest.approx(2 * one + 50, abs=2)


def test_helix_and_bufio_on_the_pulse_card():
    assert gt.GT_Open(card="gts:4", clock="lockstep", log="") == 0, gt.GTE_GetLastError()
    for a in (1, 2, 3):
        assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(20)
    prm = gt.TCrdPrm()
    prm.dimension, prm.synVelMax, prm.synAccMax = 3, 50.0, 1.0
    prm.profile[0], prm.profile[1], prm.profile[2] = 1, 2, 3
    assert gt.GT_SetCrdPrm(1, byref(prm)) == 0, gt.GTE_GetLastError()
    # one full ccw turn of radius 1000 around (1000, 0) while Z rises 3000
    assert gt.GT_HelixXYCZ(1, 0, 0, 3000, 1000.0, 0.0, 1, 20.0, 0.5) == 0, gt.GTE_GetLastError()
    assert gt.GT_BufIO(1, gt.MC_GPO, 0x0F, 0x05) == 0
    assert gt.GT_CrdStart(1, 0) == 0, gt.GTE_GetLastError()
    L = math.hypot(2 * math.pi * 1000, 3000)
    n = 0
    while status()[0]:
        gt.GTE_Wait(1)
        n += 1
        x, y, z = prf(1), prf(2), prf(3)
        assert abs(math.hypot(x - 1000, y) - 1000) <= 0.5
        phi = math.atan2(y, x - 1000) - math.pi  # from the start angle (pi), ccw
        assert z == pytest.approx(3000 * ((phi % (2 * math.pi)) / (2 * math.pi)), abs=1e-6) or (
            z in (0.0, 3000.0)
        )
    assert n == math.ceil(L / 20.0 + 20.0 / 0.5)
    pos = (c_double * 3)()
    assert gt.GT_GetCrdPos(1, pos) == 0 and list(pos) == [0.0, 0.0, 3000.0]
    assert status() == (0, 2)
    do = c_int32()
    assert gt.GT_GetDo(gt.MC_GPO, byref(do)) == 0 and do.value & 0x0F == 0x05


def test_the_axes_are_sent_the_end_point_of_the_path():
    """The cycle a path ends in still sends its end to the drives (GT_GetAxisPrfPos)."""
    up()
    assert gt.GT_LnXY(1, 12_345, -6_789, 20.0, 0.5) == 0
    run_path()
    gt.GTE_Wait(2)
    for axis, want in ((1, 12_345.0), (2, -6_789.0)):
        p = c_double()
        assert gt.GT_GetAxisPrfPos(axis, byref(p)) == 0
        assert p.value == want
