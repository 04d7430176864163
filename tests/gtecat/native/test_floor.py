"""The wall floor (gtecat.native.floor): controller time never falls behind the wall, and a
polling program's own latency, which keeps it ahead, costs the look nothing."""

from __future__ import annotations

from gtecat.master.clock import Clock
from gtecat.native.floor import WallFloor


def _floor() -> tuple[Clock, WallFloor, list[int], list[int]]:
    ran: list[int] = []
    wall = [0]
    clock = Clock(lambda: ran.append(1), cycle_ns=1_000_000, mode="auto", call_latency_ns=50_000)
    return clock, WallFloor(clock, wall_ns=lambda: wall[0]), wall, ran


def test_calls_ahead_of_the_wall_run_nothing_and_leave_no_debt():
    clock, floor, wall, ran = _floor()
    for _ in range(100):  # 100 calls of 50 us each while 10 us of wall time pass per call
        clock.on_call()
        wall[0] += 10_000
        assert floor.look() == 0
    assert floor.debt_ns == 0
    assert len(ran) == 5  # only the calls' own latency: 5 ms of cycles
    assert clock.now_ns + clock._pending_ns == 100 * 50_000


def test_wall_time_beyond_the_calls_runs_the_cycles_it_covers():
    clock, floor, wall, ran = _floor()
    clock.on_call()  # 50 us charged
    wall[0] += 3_050_000  # then the program slept: 3 ms more than its calls charged
    assert floor.look() == 3
    assert floor.debt_ns == 0
    assert clock.now_ns + clock._pending_ns == 3_050_000
    wall[0] += 10_000  # a call's worth of wall, no call: the floor runs it as pending time
    assert floor.look() == 0
    assert clock.now_ns + clock._pending_ns == 3_060_000
    assert len(ran) == 3


def test_an_idle_controller_looks_every_ten_ms_and_at_once_while_in_debt():
    """Idle, the controller looks every IDLE_LOOK_S (a wait longer than a scheduler tick
    costs a polling client's calls nothing), or every cycle where cycles are longer; with a
    debt left over from a long sleep it looks again at once."""
    from gtecat.native.floor import IDLE_LOOK_S

    _, floor, wall, _ = _floor()
    assert floor.idle_timeout() == IDLE_LOOK_S == 0.01
    floor.budget_s = 0.0  # one cycle per look: a long sleep leaves a debt
    wall[0] += 5_000_000
    floor.look()
    assert floor.debt_ns > 0 and floor.idle_timeout() == 0.0
    slow = Clock(lambda: None, cycle_ns=20_000_000, mode="auto")
    assert WallFloor(slow, wall_ns=lambda: 0).idle_timeout() == 0.02
