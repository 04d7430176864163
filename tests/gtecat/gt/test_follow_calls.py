"""Follow (electronic cam) through ``from gtecat import gt`` (lockstep clock): manual 7.6, chapter
13 entries 19-23, 48-51, 86, 106-109.  The slave is compared sample by sample with the ratio
curve of 7.6.2 (5) integrated over the master positions the controller reports
(``tests/gtecat/motion/test_follow.py``'s ``cam`` / ``cam_at``, written from the manual)."""

from __future__ import annotations

from ctypes import byref, c_double, c_int32, c_long, c_short

import numpy as np
import pytest

from gtecat import gt
from tests.gtecat.controller.motion.test_follow import cam, cam_at

from .conftest import bring_up

N, E, S, C = (
    gt.FOLLOW_SEGMENT_NORMAL,
    gt.FOLLOW_SEGMENT_EVEN,
    gt.FOLLOW_SEGMENT_STOP,
    gt.FOLLOW_SEGMENT_CONTINUE,
)
MOVING = 1 << 10
TABLE_7_10 = [(20000, 10000, N), (40000, 30000, N), (60000, 40000, N)]


def up(eni: str = "manual_fig5_2.eni", axes: tuple[int, ...] = (1, 2)) -> None:
    bring_up(eni, clock="lockstep")
    for a in axes:
        assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()
        assert gt.GT_ZeroPos(a, 1) == 0, gt.GTE_GetLastError()


def pos(axis: int) -> float:
    v = c_double()
    assert gt.GT_GetPrfPos(axis, byref(v)) == 0
    return v.value


def moving(axis: int) -> bool:
    s = c_long()
    assert gt.GT_GetSts(axis, byref(s)) == 0
    return bool(s.value & MOVING)


def space(axis: int, fifo: int) -> int:
    s = c_short()
    assert gt.GT_FollowSpace(axis, byref(s), fifo) == 0, gt.GTE_GetLastError()
    return s.value


def loops(axis: int) -> int:
    n = c_long()
    assert gt.GT_GetFollowLoop(axis, byref(n)) == 0, gt.GTE_GetLastError()
    return n.value


def jog(axis: int, vel: float, acc: float = 1.0) -> None:
    assert gt.GT_PrfJog(axis) == 0, gt.GTE_GetLastError()
    prm = gt.TJogPrm()
    assert gt.GT_GetJogPrm(axis, byref(prm)) == 0
    prm.acc, prm.dec = acc, acc
    assert gt.GT_SetJogPrm(axis, byref(prm)) == 0
    assert gt.GT_SetVel(axis, vel) == 0
    assert gt.GT_Update(1 << (axis - 1)) == 0, gt.GTE_GetLastError()


def trap_to(axis: int, target: int, vel: float, acc: float) -> None:
    assert gt.GT_PrfTrap(axis) == 0, gt.GTE_GetLastError()
    prm = gt.TTrapPrm()
    assert gt.GT_GetTrapPrm(axis, byref(prm)) == 0
    prm.acc, prm.dec = acc, acc
    assert gt.GT_SetTrapPrm(axis, byref(prm)) == 0
    assert gt.GT_SetPos(axis, target) == 0 and gt.GT_SetVel(axis, vel) == 0
    assert gt.GT_Update(1 << (axis - 1)) == 0, gt.GTE_GetLastError()


def follow(slave: int, master: int, fifos=((), ()), loop: int = 1, dir: int = 0) -> None:
    assert gt.GT_PrfFollow(slave, dir) == 0, gt.GTE_GetLastError()
    assert gt.GT_SetFollowMaster(slave, master, gt.FOLLOW_MASTER_PROFILE, 0) == 0
    for fifo, points in enumerate(fifos):
        for m, s, kind in points:
            assert gt.GT_FollowData(slave, m, s, kind, fifo) == 0, gt.GTE_GetLastError()
    assert gt.GT_SetFollowLoop(slave, loop) == 0


def trace(n: int, axes=(1, 2), each=None) -> np.ndarray:
    rows = []
    for _ in range(n):
        gt.GTE_Wait(1)
        rows.append([pos(a) for a in axes])
        if each is not None:
            each()
    return np.array(rows)


def rc_reason(rc: int, expected: int, *words: str) -> None:
    reason = gt.GTE_GetLastError()
    assert rc == expected, reason
    for w in words:
        assert w in reason, reason


# --- shapes -----------------------------------------------------------------------------------
@pytest.mark.long
def test_finite_loops_end_on_the_last_point_with_get_follow_loop_counting():
    up()
    jog(1, 100, acc=2)
    follow(2, 1, (TABLE_7_10, ()), loop=2)
    assert gt.GT_FollowStart(0b10, 0) == 0, gt.GTE_GetLastError()
    done, flags = [], []
    out = trace(1400, each=lambda: (done.append(loops(2)), flags.append(moving(2))))
    np.testing.assert_allclose(out[:, 1], cam_at(cam([TABLE_7_10] * 2), out[:, 0]), atol=1e-7)
    end = int(np.argmax(out[:, 0] >= 120000))
    assert out[end, 1] == 80000 and all(flags[:end]) and not any(flags[end:])
    assert np.all(out[end:, 1] == 80000)
    np.testing.assert_array_equal(done, np.minimum(out[:, 0] // 60000, 2).astype(int))
    assert space(2, 0) == 13  # the data stay


def test_negative_pass_event_starts_on_the_crossing_with_the_pass_point_as_zero():
    up()
    trap_to(1, -6000, vel=7, acc=1)
    pts = [(-1000, -500, N), (-3000, -2500, N)]
    follow(2, 1, (pts, ()))
    assert gt.GT_SetFollowEvent(2, gt.FOLLOW_EVENT_PASS, -1, -1000) == 0
    ev, md, p = c_short(), c_short(), c_long()
    assert gt.GT_GetFollowEvent(2, byref(ev), byref(md), byref(p)) == 0
    assert (ev.value, md.value, p.value) == (gt.FOLLOW_EVENT_PASS, -1, -1000)
    assert gt.GT_FollowStart(0b10) == 0
    assert moving(2)  # waiting for the master counts as motion
    out = trace(1000)
    x = np.minimum(out[:, 0] + 1000, 0)
    np.testing.assert_allclose(out[:, 1], cam_at(cam([pts]), x), atol=1e-9)
    first = int(np.argmax(out[:, 1] != 0))
    assert out[first - 1, 0] > -1000 >= out[first, 0]  # nothing before the crossing
    assert out[-1, 1] == -2500 and not moving(2)


def test_switch_takes_effect_at_the_end_of_the_pass_and_clears_the_used_fifo():
    """7.6.2 (6): FIFO1 endless; GT_FollowSwitch mid-pass: FIFO2 runs from the end of that pass
    (endless too: the loop count applies to each FIFO), FIFO1 is emptied."""
    up()
    jog(1, 50, acc=1)
    a = [(1000, 500, N), (2000, 1000, N)]
    b = [(500, 500, C), (1500, 2000, S)]
    follow(2, 1, (a, b), loop=0)
    assert gt.GT_FollowStart(0b10, 0) == 0
    first = trace(300)  # three passes of FIFO1 and a bit
    assert loops(2) == int(first[-1, 0] // 2000) and space(2, 0) == 14
    assert gt.GT_FollowSwitch(0b10) == 0, gt.GTE_GetLastError()
    rc_reason(gt.GT_FollowClear(2, 1), 1, "pending")
    spaces = []
    second = trace(300, each=lambda: spaces.append(space(2, 0)))
    out = np.vstack([first, second])
    n_a = int(first[-1, 0] // 2000) + 1
    expected = cam_at(cam([a] * n_a + [b] * 10), out[:, 0])
    np.testing.assert_allclose(out[:, 1], expected, atol=1e-8)
    k = int(np.argmax(second[:, 0] >= n_a * 2000))
    assert spaces[k - 1] == 14 and spaces[k] == 16  # cleared when the switch happened
    assert loops(2) == int((out[-1, 0] - n_a * 2000) // 1500)  # passes of FIFO2 only
    assert moving(2)


def test_option_bits_start_fifo2_and_one_mask_starts_two_followers():
    up(eni="twelve_axes.eni", axes=(1, 2, 3))
    jog(1, 40, acc=1)
    f1 = [(4000, 1000, E)]
    f2 = [(2000, 3000, N), (4000, 4000, S)]
    follow(2, 1, (f1, f2))
    follow(3, 1, (f1, f2))
    assert gt.GT_FollowStart(0b110, 0b100) == 0, gt.GTE_GetLastError()  # axis 3: FIFO2
    out = trace(200, axes=(1, 2, 3))
    np.testing.assert_allclose(out[:, 1], cam_at(cam([f1]), out[:, 0]), atol=1e-9)
    np.testing.assert_allclose(out[:, 2], cam_at(cam([f2]), out[:, 0]), atol=1e-9)
    assert out[-1, 1] == 1000 and out[-1, 2] == 4000


def test_master_moving_back_takes_the_slave_back_along_the_curve():
    up()
    trap_to(1, 3000, vel=20, acc=1)
    pts = [(10000, 5000, E)]
    follow(2, 1, (pts, ()))
    assert gt.GT_FollowStart(0b10) == 0
    rows = list(trace(200))
    trap_to(1, 1000, vel=20, acc=1)
    rows += list(trace(200))
    out = np.array(rows)
    np.testing.assert_allclose(out[:, 1], out[:, 0] / 2, atol=1e-9)
    assert out[-1, 1] == 500 and moving(2)


def test_gt_stop_brakes_the_follower_and_keeps_its_data():
    up()
    jog(1, 10, acc=10)
    follow(2, 1, ([(100000, 100000, E)], ()))
    assert gt.GT_FollowStart(0b10) == 0
    before = trace(20)
    assert gt.GT_SetStopDec(2, 1, 1000) == 0
    assert gt.GT_Stop(0b10, 0) == 0
    out = trace(15)
    assert not moving(2) and out[-1, 1] == pytest.approx(before[-1, 1] + 50)
    assert space(2, 0) == 15


# --- settings ----------------------------------------------------------------------------------
def test_settings_round_trip_defaults_and_memory():
    up()
    assert gt.GT_PrfFollow(2) == 0
    idx, typ, item = c_short(9), c_short(9), c_short(9)
    assert gt.GT_GetFollowMaster(2, byref(idx), byref(typ), byref(item)) == 0
    assert (idx.value, typ.value, item.value) == (0, gt.FOLLOW_MASTER_PROFILE, 0)
    ev, md, p = c_short(), c_short(), c_long(5)
    assert gt.GT_GetFollowEvent(2, byref(ev), byref(md), byref(p)) == 0
    assert (ev.value, md.value, p.value) == (gt.FOLLOW_EVENT_START, 1, 0)
    assert gt.GT_SetFollowMaster(2, 1, gt.FOLLOW_MASTER_AXIS, 1) == 0
    assert gt.GT_GetFollowMaster(2, byref(idx), byref(typ), byref(item)) == 0
    assert (idx.value, typ.value, item.value) == (1, gt.FOLLOW_MASTER_AXIS, 1)
    mem = c_short(9)
    assert gt.GT_GetFollowMemory(2, byref(mem)) == 0 and mem.value == 0
    assert space(2, 0) == 16 and space(2, 1) == 16
    assert gt.GT_SetFollowMemory(2, 1) == 0
    assert gt.GT_GetFollowMemory(2, byref(mem)) == 0 and mem.value == 1
    assert space(2, 0) == 512
    for k in range(1, 513):
        assert gt.GT_FollowData(2, k, k, N, 1) == 0
    rc_reason(gt.GT_FollowData(2, 513, 513, N, 1), 1, "full")
    assert gt.GT_SetFollowLoop(2, -5) == 0  # < 1: endless
    assert gt.GT_SetFollowEvent(2, gt.FOLLOW_EVENT_PASS, 1, 777) == 0
    assert gt.GT_PrfTrap(2) == 0
    assert gt.GT_PrfFollow(2, -1) == 0  # from another mode with another dir: settings kept
    assert gt.GT_GetFollowEvent(2, byref(ev), byref(md), byref(p)) == 0
    assert (ev.value, p.value) == (gt.FOLLOW_EVENT_PASS, 777)
    assert space(2, 1) == 0 and gt.GT_GetFollowMemory(2, byref(mem)) == 0 and mem.value == 1
    rc_reason(gt.GT_PrfFollow(2, 1), 1, "dir -1, not 1")  # entry 86 (2)
    assert gt.GTN_FollowSpace(1, 2, byref(mem), 0) == 0 and mem.value == 512


def test_a_float_master_segment_is_7_the_prototype_takes_a_long():
    """long masterSegment (entry 20): a float is refused, as ctypes refuses it for the DLL."""
    up()
    assert gt.GT_PrfFollow(2) == 0
    rc_reason(gt.GT_FollowData(2, 0.1 * 3 * 10000, 100.5), 7, "masterSegment", "integer")
    rc_reason(gt.GT_FollowData(2, 4000.5, 200), 7, "masterSegment")
    assert gt.GT_FollowData(2, round(0.1 * 3 * 10000), 100.5) == 0, gt.GTE_GetLastError()


# --- return codes ------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "call",
    [
        lambda: gt.GT_SetFollowMaster(2, 1, gt.FOLLOW_MASTER_PROFILE, 0),
        lambda: gt.GT_GetFollowMaster(2, byref(c_short()), byref(c_short()), byref(c_short())),
        lambda: gt.GT_SetFollowLoop(2, 1),
        lambda: gt.GT_GetFollowLoop(2, byref(c_int32())),
        lambda: gt.GT_SetFollowEvent(2, gt.FOLLOW_EVENT_START, 1, 0),
        lambda: gt.GT_GetFollowEvent(2, byref(c_short()), byref(c_short()), byref(c_int32())),
        lambda: gt.GT_FollowData(2, 10, 10, N, 0),
        lambda: gt.GT_FollowSpace(2, byref(c_short()), 0),
        lambda: gt.GT_FollowClear(2, 0),
        lambda: gt.GT_FollowStart(0b10, 0),
        lambda: gt.GT_FollowSwitch(0b10),
        lambda: gt.GT_SetFollowMemory(2, 1),
        lambda: gt.GT_GetFollowMemory(2, byref(c_short())),
    ],
)
def test_every_follow_call_returns_1_outside_follow_mode(call):
    up()
    rc_reason(call(), 1, "Trap mode", "GT_PrfFollow")


def test_start_and_switch_return_1_conditions():
    up()
    assert gt.GT_PrfFollow(2, 0) == 0
    assert gt.GT_FollowData(2, 1000, 1000, E, 0) == 0
    rc_reason(gt.GT_FollowStart(0b10, 0), 1, "no master")  # entry 22 (3)
    assert gt.GT_SetFollowMaster(2, 1) == 0
    rc_reason(gt.GT_FollowStart(0b10, 0b10), 1, "FIFO2", "no data")  # entry 22 (4)
    rc_reason(gt.GT_FollowStart(0, 0), 1, "selects no axis")  # entry 22 (5)
    rc_reason(gt.GT_FollowSwitch(0b10), 1, "only a moving")  # entry 23 (2)
    assert gt.GT_AxisOff(2) == 0
    rc_reason(gt.GT_FollowStart(0b10, 0), 1, "GT_AxisOn")
    assert gt.GT_AxisOn(2) == 0
    assert gt.GT_FollowStart(0b10, 0) == 0
    rc_reason(gt.GT_FollowStart(0b10, 0), 1, "moving")  # entry 22 (2)
    rc_reason(gt.GT_FollowSwitch(0b10), 1, "FIFO2", "no data")  # entry 23 (3)
    rc_reason(gt.GT_FollowSwitch(0), 1, "selects no axis")  # entry 23 (4)
    rc_reason(gt.GT_FollowClear(2, 0), 1, "in use")  # entry 19 (2)
    rc_reason(gt.GT_PrfFollow(2, 0), 1, "moving")  # entry 86 (1)
    rc_reason(gt.GT_SetFollowMaster(2, 1), 1, "moving")  # entry 108 (1)
    rc_reason(gt.GT_SetFollowMemory(2, 1), 1, "moving")  # entry 109 (1)
    assert gt.GT_FollowClear(2, 1) == 0
    assert gt.GT_SetFollowLoop(2, 3) == 0 and gt.GT_SetFollowEvent(2, 1, 1, 0) == 0


@pytest.mark.parametrize(
    ("call", "word"),
    [
        (lambda: gt.GT_PrfFollow(2, 5), "dir"),
        (lambda: gt.GT_SetFollowMaster(2, 2), "differ"),
        (lambda: gt.GT_SetFollowMaster(2, 3), "masterIndex=3"),
        (lambda: gt.GT_SetFollowMaster(2, 1, 0, 0), "masterType"),
        (lambda: gt.GT_SetFollowMaster(2, 1, gt.FOLLOW_MASTER_AXIS, 3), "masterItem"),
        (lambda: gt.GT_SetFollowLoop(2, 40000), "loop"),
        (lambda: gt.GT_SetFollowEvent(2, 3, 1, 0), "event"),
        (lambda: gt.GT_SetFollowEvent(2, gt.FOLLOW_EVENT_PASS, 0, 10), "masterDir"),
        (lambda: gt.GT_FollowData(2, 10, 10, 4, 0), "type"),
        (lambda: gt.GT_FollowData(2, 10, 10, N, 2), "fifo"),
        (lambda: gt.GT_FollowData(2, 0, 10, N, 1), "masterSegment"),
        (lambda: gt.GT_FollowData(2, 50, 10, N, 0), "masterSegment"),
        (lambda: gt.GT_FollowData(2, 200, float("inf"), N, 0), "slaveSegment"),
        (lambda: gt.GT_FollowSpace(2, byref(c_short()), 3), "fifo"),
        (lambda: gt.GT_FollowClear(2, -1), "fifo"),
        (lambda: gt.GT_SetFollowMemory(2, 2), "memory"),
        (lambda: gt.GT_FollowStart(1 << 6, 0), "axis 7"),
        (lambda: gt.GT_FollowSwitch(1 << 6), "axis 7"),
    ],
)
def test_bad_arguments_return_7(call, word):
    up()
    assert gt.GT_PrfFollow(2, 0) == 0
    assert gt.GT_FollowData(2, 100, 10, N, 0) == 0
    rc_reason(call(), 7, word)
