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
