"""Follow (electronic cam) planner: cam shapes, loops, pass events and FIFO switches, sample
by sample (manual 7.6, figures 7-13/7-14, examples 7-6, 7-7, 7-8; chapter 13 entries 19-23,
48-51, 86, 106-109)."""

from __future__ import annotations

import numpy as np
import pytest

from gtecat.controller.motion.follow import (
    FollowEvent,
    FollowPlanner,
    FollowSegmentType,
    FollowTrigger,
)
from gtecat.errors import CommandError, ParameterError

N, E, S, C = (
    FollowSegmentType.NORMAL,
    FollowSegmentType.EVEN,
    FollowSegmentType.STOP,
    FollowSegmentType.CONTINUE,
)


class FakeMaster:
    def __init__(self, pos: float = 0.0) -> None:
        self.pos = pos

    def __call__(self) -> float:
        return self.pos


def jog(t, acc, vel):
    """Jog master from rest: speed ramps with ``acc`` to ``vel`` (closed form)."""
    t = np.asarray(t, dtype=float)
    ta = vel / acc
    return np.where(t <= ta, 0.5 * acc * t * t, 0.5 * vel * ta + vel * (t - ta))


# ------------------------------------------------------------- reference
def cam(passes):
    """Pieces ``(x0, x1, s0, rs, re)`` of the ratio curve, from 7.6.2 (5) as written.

    ``passes``: the point lists in the order they run (one list per pass).  NORMAL
    starts a FIFO at ratio 0, CONTINUE at the ratio the curve had; later segments
    start where the previous one ended; EVEN keeps ΔS/ΔM; STOP goes 2ΔS/ΔM → 0.
    Slave positions come from the areas, not from the points.
    """
    pieces = []
    x_base = s = r = 0.0
    for points in passes:
        pm = ps = 0.0
        for k, (m, sl, kind) in enumerate(points):
            dm, ds = m - pm, sl - ps
            if kind == E:
                rs = re = ds / dm
            elif kind == S:
                rs, re = 2 * ds / dm, 0.0
            else:
                rs = r if (k > 0 or kind == C) else 0.0
                re = 2 * ds / dm - rs
            pieces.append((x_base + pm, x_base + m, s, rs, re))
            s += (rs + re) / 2 * dm
            r = re
            pm, ps = m, sl
        x_base += pm
    return pieces


def cam_at(pieces, xs):
    """Slave position after master travel x (clamped to the curve's ends)."""
    out = np.empty(len(xs))
    sign = 1.0 if pieces[0][1] > pieces[0][0] else -1.0
    for n, x in enumerate(xs):
        if (x - pieces[0][0]) * sign <= 0:
            out[n] = 0.0
            continue
        for x0, x1, s0, rs, re in pieces:
            if (x - x1) * sign <= 0:
                u = x - x0
                out[n] = s0 + (rs + rs + (re - rs) * u / (x1 - x0)) / 2 * u
                break
        else:
            x0, x1, s0, rs, re = pieces[-1]
            out[n] = s0 + (rs + re) / 2 * (x1 - x0)
    return out


def follower(master: FakeMaster, fifo0=(), fifo1=(), loop=1, dir=0) -> FollowPlanner:
    f = FollowPlanner(profile=2, dir=dir)
    f.set_master(1, 2, 1, source=master)
    for p in fifo0:
        f.data(*p, 0)
    for p in fifo1:
        f.data(*p, 1)
    f.set_loop(loop)
    return f


def drive(f: FollowPlanner, master: FakeMaster, positions, each=None) -> np.ndarray:
    out = []
    for p in positions:
        master.pos = float(p)
        out.append(f.step())
        if each is not None:
            each()
    return np.array(out).reshape(-1, 3)


# -------------------------------------------------------- figure 7-13
def test_figure_7_13_pass_event_ramp_then_speed_sync_zone():
    """Slave starts when the master passes 1000, moves 250 while the master goes 1000→1500 (ratio
    0→1), then keeps ratio 1 until the position sync point at master 2250."""
    m = FakeMaster()
    pts = [(500, 250, N), (1250, 1000, E)]
    f = follower(m, pts)
    f.set_event(FollowEvent.PASS, 1, 1000)
    f.start(0, pos=40.0)
    assert f.waiting and f.moving
    t = np.arange(1, 301)
    master = 10.0 * t
    out = drive(f, m, master)
    expected = 40.0 + cam_at(cam([pts]), np.clip(master - 1000, 0, None))
    np.testing.assert_allclose(out[:, 0], expected, atol=1e-9)
    assert np.all(out[:100, 0] == 40.0)  # waiting until the crossing at t = 100
    assert out[149, 0] == pytest.approx(40 + 250)  # master at 1500
    assert np.all(out[150:224, 1] == 10.0)  # speed sync: slave speed = master speed
    assert out[224, 0] == 40 + 1000 and f.done  # position sync point, master 2250
    assert out[224, 1] == 0.0


# --------------------------------------------------------- example 7-7
TABLE_7_10 = [(20000, 10000, N), (40000, 30000, N), (60000, 40000, N)]


def test_example_7_7_single_fifo_endless_after_a_50000_pass():
    """Example 7-7 / figures 7-17, 7-18: master jogs at 50 pulse/ms, the slave starts after the
    master passes 50000 and repeats an accelerate/cruise/decelerate cam endlessly."""
    m = FakeMaster()
    f = follower(m, TABLE_7_10, loop=0)
    f.set_event(FollowEvent.PASS, 1, 50000)
    assert f.trigger == FollowTrigger(FollowEvent.PASS, 1, 50000)
    assert f.space(0) == 13
    f.start(0)
    t = np.arange(1, 7001)
    master = jog(t, 1.0, 50.0)
    loops = []
    out = drive(f, m, master, each=lambda: loops.append(f.loops_done))
    x = np.clip(master - 50000, 0, None)
    expected = cam_at(cam([TABLE_7_10] * 5), x)
    np.testing.assert_allclose(out[:, 0], expected, atol=1e-7)
    assert f.moving
    np.testing.assert_array_equal(loops, np.floor(x / 60000).astype(int))
    # shape of figure 7-18, per pass: ratio 0→1, 1, 1→0 (master speed is 50 by then)
    start = int(np.argmax(x > 0))
    cruise = (x % 60000 > 20000 + 50) & (x % 60000 < 40000 - 50) & (x > 0)
    assert np.all(np.abs(out[cruise, 1] - 50.0) < 1e-9)
    assert out[start, 1] < 0.5  # starts from ratio 0
    ends = (np.abs(x % 60000 - 60000) < 50) & (x > 0)
    assert np.all(out[ends, 1] < 1.0)  # back near ratio 0 at each pass end
    assert np.isclose(out[-1, 0], expected[-1])


def test_finite_loops_end_on_the_last_point_and_keep_the_data():
    m = FakeMaster()
    f = follower(m, TABLE_7_10, loop=2)
    f.start(0)
    out = drive(f, m, 100.0 * np.arange(1, 1300))
    assert f.done and f.loops_done == 2
    end = int(np.argmax(out[:, 0] == 80000))
    assert end == 1199 and out[end].tolist() == [80000.0, 0.0, 0.0]
    assert np.all(out[end:, 0] == 80000)
    assert f.points(0) and f.space(0) == 13


# ---------------------------------------------------- example 7-6 flying shear
REGION_1 = [(5000, 2500, N)]
REGION_2 = [(1000, 1000, C), (4000, 3400, N), (6000, 4600, N), (9000, 7000, N), (10000, 8000, N)]


def test_example_7_6_flying_shear_10000_master_to_8000_slave_per_cut():
    """Example 7-6 / figure 7-16, tables 7-8 and 7-9: region 1 (FIFO1) catches up 2500 over 5000,
    then region 2 (FIFO2, endless) turns the knife 8000 per 10000 of belt, with speed-synchronous
    zones (ratio exactly 1) 1000 either side of each cut."""
    m = FakeMaster()
    f = follower(m, REGION_1, REGION_2, loop=0)
    f.start(0)
    f.switch()  # region 1 runs once, then FIFO2 for ever
    assert f.switch_pending
    vm = 20.0
    t = np.arange(1, 3001)
    master = vm * t
    fifo0_space = []
    out = drive(f, m, master, each=lambda: fifo0_space.append(f.space(0)))
    expected = cam_at(cam([REGION_1] + [REGION_2] * 6), master)
    np.testing.assert_allclose(out[:, 0], expected, atol=1e-8)
    # region 1: the slave reaches 2500 with the master's speed (ratio 1) at master 5000
    assert out[249, 0] == pytest.approx(2500.0)
    assert out[249, 1] == pytest.approx(vm, abs=0.05)
    # at the end of region 1 FIFO1 is cleared and FIFO2 runs
    assert fifo0_space[248] == 15 and fifo0_space[250] == 16
    assert f.running_fifo == 1 and not f.switch_pending
    # every cut: master +10000 <-> slave +8000
    for k in range(1, 6):
        i = round((5000 + 10000 * k) / vm) - 1
        assert out[i, 0] == pytest.approx(2500 + 8000 * k)
    # speed-synchronous zones: slave speed == master speed exactly
    x2 = (master - 5000) % 10000
    sync = (master > 5000) & ((x2 > vm) & (x2 <= 1000) | (x2 > 9000 + vm))
    assert sync.sum() > 400
    assert np.all(np.abs(out[sync, 1] - vm) < 1e-9)
    # between them the knife slows to ratio 0.6 (table 7-9: 1200 over 2000)
    slow = (master > 5000) & (x2 > 4000 + vm) & (x2 <= 6000)
    assert np.all(np.abs(out[slow, 1] - 0.6 * vm) < 1e-9)


# --------------------------------------------------- example 7-8 double FIFO
TABLE_7_11 = [(20000, 10000, N), (40000, 30000, N), (60000, 40000, N)]
TABLE_7_12 = [(20000, 10000, C), (40000, 30000, N), (60000, 46000, N)]
TABLE_7_13 = [(20000, 16000, C), (40000, 36000, N), (60000, 52000, N)]


def test_example_7_8_double_fifo_switch_sample_by_sample():
    """Example 7-8 / figures 7-14, 7-19, 7-20: curve 1 (FIFO1, endless), transition curve 2
    (FIFO2, loaded and switched to while curve 1 runs), then curve 3 loaded into FIFO1 once the
    controller has cleared it.  Table 7-12's third master point is 20000 (the listing's
    ``masterPos+220000`` is a typo: the table and figure 7-20 say 20000)."""
    m = FakeMaster()
    f = follower(m, TABLE_7_11, loop=0)
    f.set_event(FollowEvent.START, 1, 0)
    f.start(0)
    stage = ["FIFO1"]

    def host():
        if stage[0] == "FIFO1" and f.master_travel > 30000:
            f.clear(1)
            for p in TABLE_7_12:
                f.data(*p, 1)
            f.switch()
            stage[0] = "TO_FIFO2"
        elif stage[0] == "TO_FIFO2" and f.space(0) == 16:
            for p in TABLE_7_13:
                f.data(*p, 0)
            f.switch()
            stage[0] = "TO_FIFO1"
        elif stage[0] == "TO_FIFO1" and f.space(1) == 16:
            stage[0] = "END"

    t = np.arange(1, 7001)
    master = jog(t, 1.0, 50.0)
    out = drive(f, m, master, each=host)
    assert stage[0] == "END"
    expected = cam_at(cam([TABLE_7_11, TABLE_7_12] + [TABLE_7_13] * 4), master)
    np.testing.assert_allclose(out[:, 0], expected, atol=1e-7)
    # figure 7-20: transition ends at ratio 0.6, then a 0.6 → 1 → 1 → 0.6 trapezoid for ever
    i_end = int(np.argmax(master >= 120000))
    assert out[i_end, 1] == pytest.approx(0.6 * 50, abs=0.3)
    later = (master > 120000 + 100) & ((master - 120000) % 60000 > 59000)
    assert np.all(np.abs(out[later, 1] / 50 - 0.6) < 0.02 + 1e-9)
    assert f.running_fifo == 0 and f.space(1) == 16


# --------------------------------------------------------- segment types
def test_even_and_stop_segments():
    """EVEN keeps ΔS/ΔM; STOP starts at 2ΔS/ΔM whatever came before and ends at ratio 0."""
    m = FakeMaster()
    pts = [(1000, 500, E), (2000, 1500, S)]
    f = follower(m, pts)
    f.start(0)
    out = drive(f, m, 10.0 * np.arange(1, 201))
    np.testing.assert_allclose(out[:, 0], cam_at(cam([pts]), 10.0 * np.arange(1, 201)), atol=1e-9)
    assert np.all(out[:100, 1] == 5.0)
    assert out[100, 1] == pytest.approx(10 * (2.0 + 1.98) / 2)  # STOP opens at 2·1000/1000
    assert out[-1].tolist() == [1500.0, 0.0, 0.0]


def test_continue_in_a_loop_carries_the_ratio_of_the_previous_pass():
    """CONTINUE opens each pass with the ratio the previous pass ended with; NORMAL with 0."""
    m = FakeMaster()
    pts = [(100, 100, C), (200, 180, N)]  # pass 1: ratio 0 → 2 → -0.4; pass 2: -0.4 → 2.4 ...
    f = follower(m, pts, loop=3)
    f.start(0)
    xs = 5.0 * np.arange(1, 121)
    out = drive(f, m, xs)
    np.testing.assert_allclose(out[:, 0], cam_at(cam([pts] * 3), xs), atol=1e-9)
    assert out[-1, 0] == 3 * 180 and f.loops_done == 3
    # ratio right after the second pass starts: close to -0.4 (continued), not 0
    assert out[40, 1] / 5.0 == pytest.approx(-0.4 + 2.8 * 2.5 / 100, abs=1e-9)
    m2 = FakeMaster()
    g = follower(m2, [(100, 100, N), (200, 180, N)], loop=2)
    g.start(0)
    out_n = drive(g, m2, xs[:41])
    assert out_n[40, 1] / 5.0 == pytest.approx(2.0 * 2.5 / 100, abs=1e-9)  # NORMAL: from 0


# ---------------------------------------------------------- directions
def test_negative_master_with_a_negative_pass_event():
    """masterDir -1: start when the master crosses -1000 going negative; points are negative."""
    m = FakeMaster(0.0)
    pts = [(-1000, -500, N), (-3000, -2500, N)]
    f = follower(m, pts)
    f.set_event(FollowEvent.PASS, -1, -1000)
    f.start(0)
    master = -7.0 * np.arange(1, 701)
    out = drive(f, m, master)
    x = np.minimum(master + 1000, 0)
    np.testing.assert_allclose(out[:, 0], cam_at(cam([pts]), x), atol=1e-9)
    assert f.done and out[-1, 0] == -2500


def test_pass_event_ignores_a_crossing_in_the_other_direction():
    m = FakeMaster(2000.0)
    f = follower(m, [(100, 100, E)])
    f.set_event(FollowEvent.PASS, 1, 1000)
    f.start(0)
    drive(f, m, [1500.0, 1000.0, 500.0])  # passes 1000 going down: not the event
    assert f.waiting and f.pos == 0.0
    out = drive(f, m, [990.0, 1010.0])  # crosses going up: starts with the 10 beyond
    assert not f.waiting and out[-1, 0] == pytest.approx(10.0)


@pytest.mark.parametrize(("dir", "expected_back"), [(0, 200.0), (1, 500.0)])
def test_master_moving_back(dir, expected_back):
    """dir 0: the slave goes back along the curve; dir 1: it waits for the master."""
    m = FakeMaster()
    pts = [(1000, 1000, E)]
    f = follower(m, pts, dir=dir)
    f.start(0)
    drive(f, m, [250.0, 500.0])
    out = drive(f, m, [350.0, 200.0, -100.0])
    assert out[1, 0] == pytest.approx(expected_back)
    assert out[2, 0] == (0.0 if dir == 0 else 500.0)  # not behind the start of the pass
    out = drive(f, m, [0.0, 300.0])  # dir 1 follows every positive increment, also from -100
    assert out[-1, 0] == pytest.approx(300.0 if dir == 0 else 900.0)


def test_points_appended_to_the_running_fifo_extend_the_pass():
    m = FakeMaster()
    f = follower(m, [(100, 100, E)])
    f.start(0)
    drive(f, m, [50.0])
    f.data(200, 150, E, 0)
    out = drive(f, m, [100.0, 150.0, 200.0, 250.0])
    assert out[:, 0].tolist() == [100.0, 125.0, 150.0, 150.0] and f.done


# ------------------------------------------------------------- memory
def test_memory_flag_sizes_the_fifos_16_or_512():
    f = FollowPlanner(profile=2)
    assert f.memory == 0 and f.space(0) == 16
    for k in range(1, 17):
        f.data(k, k, N, 1)
    with pytest.raises(CommandError, match="full"):
        f.data(17, 17, N, 1)
    f.set_memory(1)
    assert f.memory == 1 and f.space(1) == 512 - 16 and f.space(0) == 512


# ---------------------------------------------------------- stop
def test_smooth_stop_brakes_and_keeps_the_data():
    m = FakeMaster()
    f = follower(m, [(100000, 100000, E)])
    f.start(0)
    drive(f, m, [10.0, 20.0])
    f.stop(1.0)
    out = drive(f, m, 20.0 + 10 * np.arange(1, 20))
    assert f.done and out[-1, 0] == pytest.approx(20 + 50.0)
    assert len(f.points(0)) == 1


# ---------------------------------------------------- return 1 / return 7
def test_start_return_1_conditions():
    """Entry 22: (2) moving, (3) no master, (4) FIFO without data."""
    m = FakeMaster()
    f = FollowPlanner(profile=2)
    f.data(10, 10, N, 0)
    with pytest.raises(CommandError, match="no master"):
        f.start(0)
    f.set_master(1, source=m)
    with pytest.raises(CommandError, match="FIFO 1 holds no data"):
        f.start(1)
    f.start(0)
    with pytest.raises(CommandError, match="moving"):
        f.start(0)


def test_switch_return_1_conditions():
    """Entry 23: (2) only while moving, (3) the target FIFO must hold data."""
    m = FakeMaster()
    f = follower(m, [(10, 10, N)])
    with pytest.raises(CommandError, match="only a moving"):
        f.switch()
    f.start(0)
    with pytest.raises(CommandError, match="target FIFO 1 holds no data"):
        f.switch()
    f.data(10, 10, N, 1)
    f.switch()
    f.switch()  # asking again changes nothing
    assert f.switch_pending


def test_clear_return_1_conditions():
    """Entry 19 (2): not the FIFO in use while moving (nor the one a switch waits for)."""
    m = FakeMaster()
    f = follower(m, [(10, 10, N)], [(5, 5, N)])
    f.start(0)
    with pytest.raises(CommandError, match="in use"):
        f.clear(0)
    f.clear(1)
    f.data(5, 5, N, 1)
    f.switch()
    with pytest.raises(CommandError, match="pending"):
        f.clear(1)


def test_settings_refused_while_moving():
    """Entries 86 (1)/(2), 108 (1), 109 (1)."""
    m = FakeMaster()
    f = follower(m, [(10, 10, N)])
    with pytest.raises(CommandError, match="dir 0, not -1"):
        f.set_direction(-1)
    f.start(0)
    for call in (lambda: f.set_master(3), lambda: f.set_memory(1), lambda: f.set_direction(0)):
        with pytest.raises(CommandError, match="moving"):
            call()
    f.set_loop(5)  # allowed: not a return-1 condition
    assert f.loop == 5


@pytest.mark.parametrize(
    "call",
    [
        lambda f: f.data(10, 10, 4),  # bad segment type
        lambda f: f.data(10, 10, N, 2),  # bad fifo
        lambda f: f.data(0, 10, N, 1),  # first master point 0
        lambda f: f.data(10, 20, N, 0),  # master must move on from 10
        lambda f: f.data(5, 20, N, 0),
        lambda f: f.data(10.5, 20, N, 1),  # masterSegment is a long
        lambda f: f.set_loop(40000),
        lambda f: f.set_event(3),
        lambda f: f.set_event(FollowEvent.PASS, 0, 100),
        lambda f: f.set_memory(2),
        lambda f: f.set_master(2),  # the slave itself
        lambda f: f.set_master(1, 0),
        lambda f: f.space(2),
        lambda f: f.start(2),
        lambda f: FollowPlanner(dir=5),
    ],
)
def test_parameter_errors_return_7(call):
    f = FollowPlanner(profile=2)
    f.data(10, 10, N, 0)
    with pytest.raises(ParameterError):
        call(f)
